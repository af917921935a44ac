//! Stage: scattering (PO), the traces of still objects kept across a moving scene's
//! revolutions (docs/architecture.md, "Traced world and receive chain").
//!
//! A still object's returns change from one revolution to the next only if a moving object
//! meets one of the rays its trace casts: a tube ray, a bounce ray, a shadow ray. Every such
//! ray lies in one of three cones, or it is kept as a segment:
//! - the cone from the radar that holds the object's bounding sphere (every tube ray up to
//!   the object, every bounce between two of its hits, every shadow ray back to the radar);
//! - with the sea, the cone from the radar that holds the sphere's mirror image (a via-sea
//!   tube's leg down to the sea, the leg up from the sea of a return via the sea), and the
//!   cone from the radar's image that holds the sphere (the legs between the sea and the
//!   object);
//! - each cone ends at the sphere's far side; a ray that leaves them (a bounce that escapes or
//!   meets another object, a tube that misses the object and runs on) is kept whole.
//!
//! A trace is kept only when no moving object's bounding sphere meets its cones or segments,
//! so it is the trace of a world without the moving objects; it is reused in a revolution
//! whose moving objects meet none of them either, where the same rays meet the same
//! primitives: the reused returns are the bytes a new trace would give, whichever revolutions
//! came before.

use super::super::Contribution;
use super::{sea_mirror, RaySink, TubeBudget};
use glam::DVec3;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

/// Relative margin on the spheres and cones, against rounding (1 part in 10⁹, plus 1 µm).
const MARGIN: f64 = 1e-9;
const MARGIN_M: f64 = 1e-6;
/// A point this close to a cone's apex counts as in the cone: shadow rays end a surface
/// offset (1 µm) off the radar, in any direction from it. A segment from a point in the cone
/// to one within this of the apex stays within this of the cone, so a moving object's sphere
/// is grown by it before it is tested against the cones.
const APEX_SLACK_M: f64 = 1e-5;

/// The rays of one object's trace, as cones and the segments that leave them.
#[derive(Debug, Clone, Default)]
pub struct ObjectReach {
    cones: Vec<Cone>,
    segments: Vec<Segment>,
}

/// A cone from `apex` around unit `axis`, up to `reach_m` from its apex.
#[derive(Debug, Clone, Copy)]
struct Cone {
    apex: DVec3,
    axis: DVec3,
    half_angle_rad: f64,
    cos_half_angle: f64,
    reach_m: f64,
}

/// A ray's segment: from `origin` along unit `dir` for `length_m` (∞ for a ray that met
/// nothing).
#[derive(Debug, Clone, Copy)]
struct Segment {
    origin: DVec3,
    dir: DVec3,
    length_m: f64,
}

impl Cone {
    /// The cone from `apex` that holds the sphere (`centre`, `radius_m`), to its far side.
    fn holding(apex: DVec3, centre: DVec3, radius_m: f64) -> Cone {
        let radius_m = radius_m * (1.0 + MARGIN) + MARGIN_M;
        let to_centre = centre - apex;
        let d = to_centre.length();
        let half_angle_rad = if d > radius_m {
            (radius_m / d).asin()
        } else {
            std::f64::consts::PI
        };
        Cone {
            apex,
            axis: if d > 0.0 { to_centre / d } else { DVec3::Z },
            half_angle_rad,
            cos_half_angle: half_angle_rad.cos(),
            reach_m: d + radius_m,
        }
    }

    /// Whether point `p` lies in the cone, or within [`APEX_SLACK_M`] of its apex.
    fn holds(&self, p: DVec3) -> bool {
        let v = p - self.apex;
        let len = v.length();
        len <= APEX_SLACK_M
            || (len <= self.reach_m && v.dot(self.axis) >= len * self.cos_half_angle)
    }

    /// Whether the sphere (`centre`, `radius_m`) may meet the cone (never false when it
    /// does: its angular radius is added to the cone's).
    fn may_meet(&self, centre: DVec3, radius_m: f64) -> bool {
        let w = centre - self.apex;
        let dist = w.length();
        if dist <= radius_m {
            return true;
        }
        if dist - radius_m > self.reach_m {
            return false;
        }
        let off_axis = (w.dot(self.axis) / dist).clamp(-1.0, 1.0).acos();
        off_axis <= self.half_angle_rad + (radius_m / dist).asin()
    }
}

impl Segment {
    /// Whether the segment passes within `radius_m` of `centre`.
    fn passes_within(&self, centre: DVec3, radius_m: f64) -> bool {
        let t = (centre - self.origin)
            .dot(self.dir)
            .clamp(0.0, self.length_m);
        (self.origin + self.dir * t - centre).length_squared() <= radius_m * radius_m
    }
}

impl ObjectReach {
    /// The cones of the trace of the object in the sphere (`centre`, `radius_m`) lit from
    /// `radar_m` (above the sea when `sea`): none of its segments yet.
    pub fn new(radar_m: DVec3, centre: DVec3, radius_m: f64, sea: bool) -> ObjectReach {
        let mut cones = vec![Cone::holding(radar_m, centre, radius_m)];
        if sea {
            cones.push(Cone::holding(radar_m, sea_mirror(centre), radius_m));
            cones.push(Cone::holding(sea_mirror(radar_m), centre, radius_m));
        }
        ObjectReach {
            cones,
            segments: Vec::new(),
        }
    }

    /// The same cones, no segments (a sink for one run of rows).
    pub fn same_cones(&self) -> ObjectReach {
        ObjectReach {
            cones: self.cones.clone(),
            segments: Vec::new(),
        }
    }

    /// Adds the segments of `others` (the runs of one trace).
    pub fn absorb(&mut self, others: impl IntoIterator<Item = ObjectReach>) {
        for o in others {
            self.segments.extend(o.segments);
        }
    }

    /// Segments kept (those that leave the cones).
    pub fn num_segments(&self) -> usize {
        self.segments.len()
    }

    /// Whether a sphere (`centre`, `radius_m`) may meet one of the trace's rays (never false
    /// when it does).
    pub fn met_by(&self, centre: DVec3, radius_m: f64) -> bool {
        let radius_m = radius_m * (1.0 + MARGIN) + MARGIN_M;
        self.cones
            .iter()
            .any(|c| c.may_meet(centre, radius_m + APEX_SLACK_M))
            || self
                .segments
                .iter()
                .any(|s| s.passes_within(centre, radius_m))
    }
}

impl RaySink for ObjectReach {
    #[inline]
    fn segment(&mut self, origin_m: DVec3, dir: DVec3, length_m: f64) {
        let end = origin_m + dir * length_m;
        let held =
            length_m.is_finite() && self.cones.iter().any(|c| c.holds(origin_m) && c.holds(end));
        if !held {
            self.segments.push(Segment {
                origin: origin_m,
                dir,
                length_m,
            });
        }
    }
}

/// One still object's trace, kept: its contributions as the scene's trace gave them (land's
/// shadows and the rain applied), the rays it cast, its tube budget, how many contributions
/// land took away and where its rays went.
#[derive(Debug)]
pub struct KeptTrace {
    pub contributions: Vec<Contribution>,
    pub rays: u64,
    pub budget: Option<TubeBudget>,
    pub land_shadowed: u32,
    pub reach: ObjectReach,
}

/// The kept traces of a moving scene's still objects (safe to share between threads).
#[derive(Debug)]
pub struct StillTraces {
    /// Per object: whether its trace may be kept (it has no motion).
    still: Vec<bool>,
    kept: Mutex<Vec<Option<Arc<KeptTrace>>>>,
    reused: AtomicU64,
}

impl StillTraces {
    /// Kept traces for a scene whose objects `still[i]` have no motion (none kept yet).
    pub fn new(still: Vec<bool>) -> StillTraces {
        let n = still.len();
        StillTraces {
            still,
            kept: Mutex::new(vec![None; n]),
            reused: AtomicU64::new(0),
        }
    }

    /// Whether object `index`'s trace may be kept.
    pub(crate) fn is_still(&self, index: usize) -> bool {
        self.still.get(index).copied().unwrap_or(false)
    }

    /// Object `index`'s kept trace, if there is one.
    pub(crate) fn get(&self, index: usize) -> Option<Arc<KeptTrace>> {
        self.kept
            .lock()
            .expect("the kept traces")
            .get(index)?
            .clone()
    }

    /// Keeps object `index`'s trace.
    pub(crate) fn keep(&self, index: usize, trace: Arc<KeptTrace>) {
        if let Some(slot) = self.kept.lock().expect("the kept traces").get_mut(index) {
            *slot = Some(trace);
        }
    }

    /// Counts one reuse.
    pub(crate) fn count_reuse(&self) {
        self.reused.fetch_add(1, Ordering::Relaxed);
    }

    /// How many object traces were reused so far.
    pub fn reused(&self) -> u64 {
        self.reused.load(Ordering::Relaxed)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The cone test and the segment test against points and spheres placed by hand.
    #[test]
    fn cones_and_segments_hold_and_meet_what_they_should() {
        let radar = DVec3::new(0.0, 0.0, 10.0);
        let reach = ObjectReach::new(radar, DVec3::new(100.0, 0.0, 5.0), 5.0, false);
        let cone = reach.cones[0];
        assert!(cone.holds(DVec3::new(50.0, 0.0, 7.5)));
        assert!(cone.holds(DVec3::new(104.9, 0.0, 5.0)));
        assert!(
            !cone.holds(DVec3::new(106.0, 0.0, 5.0)),
            "beyond the far side"
        );
        assert!(!cone.holds(DVec3::new(50.0, 5.0, 7.5)), "off the axis");
        // A sphere beside the line of sight, just clear of the cone, and just touching it.
        let half = cone.half_angle_rad;
        let side = |r: f64| DVec3::new(50.0, 50.0 * (half.tan() + r / 50.0 / half.cos()), 7.5);
        assert!(!cone.may_meet(side(1.05), 1.0));
        assert!(cone.may_meet(side(0.95), 1.0));
        let mut r = reach.same_cones();
        r.segment(DVec3::new(100.0, 0.0, 10.0), DVec3::Z, f64::INFINITY);
        r.segment(DVec3::new(99.0, 0.0, 5.0), DVec3::X, 2.0);
        // A shadow ray back to the radar, ending a surface offset off it, sideways.
        let from = DVec3::new(96.0, 1.0, 6.0);
        let end = radar + DVec3::new(0.0, -1e-6, 1e-6);
        r.segment(from, (end - from).normalize(), (end - from).length());
        assert_eq!(
            r.num_segments(),
            1,
            "the escaping ray kept, the bounce inside and the shadow ray not"
        );
        assert!(r.met_by(DVec3::new(100.0, 2.9, 500.0), 3.0));
        assert!(!r.met_by(DVec3::new(100.0, 3.1, 500.0), 3.0));
    }
}
