//! Stage: scattering. Turns the scene into a list of complex scattering contributions
//! `(amplitude, two-way path, transmit and receive directions, object)`, traced once per scene
//! state and reused by every beam (docs/physics.md §5).
//!
//! Two amplitude models (swappable, chosen by `[scattering] model`):
//! - [`po`]: shooting-and-bouncing rays with physical-optics ray tubes (Ling, Chou & Lee,
//!   IEEE TAP 37(2), 1989), each tube giving a complex root-RCS `S` (m) such that an isolated
//!   object's RCS is `σ = |Σ S|²`, converted to volts with the radar equation
//!   (docs/physics.md §2).
//! - [`paper`]: the seed paper's law `A = 1/(1 + ℓ²/1000)` on a uniform az × el grid of rays
//!   (uncalibrated, kept to reproduce the paper's figures and for like-for-like benchmarks).

pub mod paper;
pub mod po;
pub mod rcs;
pub mod via_own_ship;

use crate::constants::SPEED_OF_LIGHT_M_PER_S;
use crate::geometry::{Bvh, Primitive};
use crate::model::{Environment, Radar, ScatteringModel, Scene, SceneObject};
use glam::{DMat3, DVec3};
use num_complex::Complex64;
use rayon::prelude::*;
use std::sync::Arc;

/// One scattering path, seen at the radar.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Contribution {
    /// Received voltage (V, across 1 Ω) at the antenna's peak gain, carrier phase included;
    /// the antenna pattern is applied per beam.
    pub amplitude_v: Complex64,
    /// Root-RCS `S` of this path (m, complex); zero for the `paper` model.
    pub root_rcs_m: Complex64,
    /// Total two-way path length ℓ (radar → … → radar), m.
    pub path_m: f64,
    /// Azimuth of the first (transmit) segment, rad.
    pub az_tx_rad: f64,
    /// Elevation of the first segment, rad.
    pub el_tx_rad: f64,
    /// Azimuth from the radar to the last hit (receive direction), rad.
    pub az_rx_rad: f64,
    /// Elevation from the radar to the last hit, rad.
    pub el_rx_rad: f64,
    /// Index of the scene object the path belongs to.
    pub object: u32,
    /// Number of reflections on objects along the path (0 for an ideal point scatterer).
    pub bounces: u8,
    /// Number of sea-surface reflections along the path (0 for the free-space path).
    pub sea_reflections: u8,
}

impl Contribution {
    /// Round-trip delay `ℓ/c`, s.
    #[inline]
    pub fn delay_s(&self) -> f64 {
        self.path_m / SPEED_OF_LIGHT_M_PER_S
    }
}

/// The contributions of one scene state, and how many rays it took.
#[derive(Debug, Clone, Default)]
pub struct ScatterSet {
    /// All contributions, in a deterministic order.
    pub contributions: Vec<Contribution>,
    /// Rays cast (including bounce and shadow rays) by the traces its contributions come
    /// from: a still object's trace kept from an earlier revolution counts the rays it cast
    /// then, so the count is the same whichever revolutions came before.
    pub rays_cast: u64,
    /// Per object (by index): the PO tube grid it was traced with; None for points, objects
    /// not traced (beyond the recorded range or the horizon) and the `paper` model. Empty
    /// when not recorded.
    pub tube_budgets: Vec<Option<po::TubeBudget>>,
    /// Per object (by index): how many of its contributions land took away ([`shade_by_land`]);
    /// empty without land.
    pub land_shadowed: Vec<u32>,
    /// Per object (by index): the kept trace its contributions are, when they are one
    /// ([`trace_scene_keeping`]); the same `Arc` in every revolution that reuses it, so what
    /// is made from an object's contributions can be kept with it. Empty when none is.
    pub kept: Vec<Option<Arc<po::KeptTrace>>>,
}

impl ScatterSet {
    /// Each object's coherent sums of root-RCS, in one pass over the contributions (each sum
    /// taken in the contributions' order): its RCS at its aspect and its multipath gain.
    pub fn object_sums(&self, num_objects: usize) -> Vec<ObjectSums> {
        let mut sums = vec![ObjectSums::default(); num_objects];
        for c in &self.contributions {
            if let Some(s) = sums.get_mut(c.object as usize) {
                if c.sea_reflections == 0 {
                    s.free_space_m += c.root_rcs_m;
                }
                s.all_m += c.root_rcs_m;
                s.returns += 1;
            }
        }
        sums
    }
}

/// One object's coherent sums of root-RCS over its contributions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ObjectSums {
    /// `Σ S` over the free-space contributions (no sea reflection), m.
    pub free_space_m: Complex64,
    /// `Σ S` over all its contributions, m.
    pub all_m: Complex64,
    /// How many contributions it has.
    pub returns: usize,
}

impl Default for ObjectSums {
    fn default() -> Self {
        ObjectSums {
            free_space_m: Complex64::new(0.0, 0.0),
            all_m: Complex64::new(0.0, 0.0),
            returns: 0,
        }
    }
}

impl ObjectSums {
    /// Coherent monostatic RCS at the object's aspect, `|Σ_free-space S|²`, m².
    pub fn rcs_m2(&self) -> f64 {
        self.free_space_m.norm_sqr()
    }

    /// Power gain of the sea paths, `|Σ_all S|²/|Σ_free-space S|²` (1 without a free-space
    /// return).
    pub fn multipath_gain(&self) -> f64 {
        let direct = self.free_space_m.norm_sqr();
        if direct > 0.0 {
            self.all_m.norm_sqr() / direct
        } else {
            1.0
        }
    }
}

/// A vector's components as bits: equal only for the same vector, bit for bit (a key for
/// values computed from it, and the test that two directions are one).
#[inline]
pub(crate) fn vector_bits(v: DVec3) -> [u64; 3] {
    v.to_array().map(f64::to_bits)
}

/// Nautical azimuth (0 = north = +y, clockwise) and elevation of a direction, rad: within a
/// few units in the last place of libm's `atan2` and `hypot` (`special::atan2_fast`; the
/// horizontal length as `√(x² + y²)`, for components between 10⁻¹⁵⁰ and 10¹⁵⁰ m).
#[inline]
pub fn azimuth_elevation_rad(dir: DVec3) -> (f64, f64) {
    let az = crate::special::rem_euclid_tau(crate::special::atan2_fast(dir.x, dir.y));
    let horizontal = (dir.x * dir.x + dir.y * dir.y).sqrt();
    let el = crate::special::atan2_fast(dir.z, horizontal);
    (az, el)
}

/// Unit direction for a nautical azimuth and elevation, rad.
#[inline]
pub fn direction_from_az_el(az_rad: f64, el_rad: f64) -> DVec3 {
    DVec3::new(
        az_rad.sin() * el_rad.cos(),
        az_rad.cos() * el_rad.cos(),
        el_rad.sin(),
    )
}

/// Radar-equation voltage factor `sqrt(Pt·G0²·λ²/((4π)³·L)) / (R_tx·R_rx)`, V per m of root-RCS
/// (docs/physics.md §2.4): multiplying a path's `S` by it gives its peak-gain voltage.
#[inline]
pub fn radar_equation_volts_per_root_m2(radar: &Radar, range_tx_m: f64, range_rx_m: f64) -> f64 {
    radar.radar_equation_constant_w_m2().sqrt() / (range_tx_m * range_rx_m)
}

/// Volts per m of root-RCS for a path, with the atmosphere's two-way loss over the mean of
/// the outgoing and returning ranges.
#[inline]
pub fn path_volts_per_root_m2(
    radar: &Radar,
    environment: &Environment,
    range_tx_m: f64,
    range_rx_m: f64,
) -> f64 {
    radar_equation_volts_per_root_m2(radar, range_tx_m, range_rx_m)
        * environment
            .attenuation_power(0.5 * (range_tx_m + range_rx_m))
            .sqrt()
}

/// Carrier phase term `exp(−j2πℓ/λ)`, computed so that f64 keeps the phase at long ranges.
#[inline]
pub fn carrier_phase(path_m: f64, wavelength_m: f64) -> Complex64 {
    let turns = path_m / wavelength_m;
    let cycles = turns - crate::special::trunc_exact(turns); // turns.fract()
    let (sin, cos) = crate::special::sin_cos_fast(-std::f64::consts::TAU * cycles);
    Complex64::new(cos, sin)
}

/// Builds the ray-tracing acceleration structure of a scene (all objects' primitives).
pub fn build_scene_bvh(objects: &[SceneObject]) -> Bvh {
    scene_bvh_of(objects, |_, _| true)
}

/// A mesh carried by at least this many objects...
const SHARED_MESH_MIN_COPIES: usize = 2;
/// ...of at least this many triangles has its hierarchy built once, in its own frame, and
/// placed in each of them.
const SHARED_MESH_MIN_TRIANGLES: usize = 256;

/// The BVH over the objects `keep(index, object)` takes, each primitive tagged with its
/// object's index: [`Bvh::build`] over [`scene_primitives_of`], except that a mesh shared by
/// several objects (one file at one scale: `model` loads it once) is built once and its
/// hierarchy placed in each copy ([`Bvh::build_with_copies`]; the same hits).
pub fn scene_bvh_of(
    objects: &[SceneObject],
    keep: impl Fn(usize, &SceneObject) -> bool + Sync,
) -> Bvh {
    use crate::geometry::{Aabb, BvhTemplate, PlacedCopy, ShapeGeometry, TriangleMesh};
    /// A shared mesh: its template and the triangle behind each of the template's primitives
    /// (a triangle of no area has none).
    struct Shared<'a> {
        mesh: &'a TriangleMesh,
        template: Arc<BvhTemplate>,
        triangles: Vec<u32>,
    }
    // The kept objects of each mesh, meshes in order of first use.
    let mut users: Vec<(&Arc<TriangleMesh>, Vec<usize>)> = Vec::new();
    let mut slot_of = std::collections::HashMap::new();
    for (i, o) in objects.iter().enumerate() {
        if let ShapeGeometry::Mesh { mesh } = o.shape() {
            if keep(i, o) && mesh.triangles.len() >= SHARED_MESH_MIN_TRIANGLES {
                let slot = *slot_of.entry(Arc::as_ptr(mesh)).or_insert_with(|| {
                    users.push((mesh, Vec::new()));
                    users.len() - 1
                });
                users[slot].1.push(i);
            }
        }
    }
    users.retain(|(_, objects)| objects.len() >= SHARED_MESH_MIN_COPIES);
    if users.is_empty() {
        return Bvh::build(scene_primitives_of(objects, keep));
    }
    let shared: Vec<Option<Shared>> = users
        .par_iter()
        .map(|(mesh, _)| {
            let (triangles, local): (Vec<u32>, Vec<Primitive>) = (0..mesh.triangles.len())
                .map(|t| {
                    (
                        t as u32,
                        mesh.placed_triangle(t, DVec3::ZERO, DMat3::IDENTITY, 0),
                    )
                })
                .filter(|(_, p)| !p.is_degenerate_triangle())
                .unzip();
            Some(Shared {
                mesh,
                template: Arc::new(BvhTemplate::build(&local)?),
                triangles,
            })
        })
        .collect();
    let mut shared_of = vec![None; objects.len()];
    for ((_, objects), s) in users.iter().zip(&shared) {
        for &i in objects {
            shared_of[i] = s.as_ref();
        }
    }
    // Each copy's box (its placed vertices'), where the triangles of no area the template
    // left out have none as placed either (else its primitives join the loose ones).
    let placements: Vec<Option<PlacedCopy>> = shared_of
        .par_iter()
        .enumerate()
        .map(|(i, s)| {
            let (s, o) = ((*s)?, &objects[i]);
            let (position_m, rotation) = (o.position_m(), o.rotation());
            let mut kept = s.triangles.iter().peekable();
            for t in 0..s.mesh.triangles.len() as u32 {
                if kept.next_if_eq(&&t).is_none()
                    && !s
                        .mesh
                        .placed_triangle(t as usize, position_m, rotation, 0)
                        .is_degenerate_triangle()
                {
                    return None;
                }
            }
            let bounds = s.mesh.vertices_m.iter().fold(Aabb::EMPTY, |b, &v| {
                let p = position_m + rotation * v;
                b.union(&Aabb { min: p, max: p })
            });
            let template = Arc::clone(&s.template);
            Some(PlacedCopy { template, bounds })
        })
        .collect();
    let copied: Vec<(usize, &Shared)> = placements
        .iter()
        .zip(&shared_of)
        .enumerate()
        .filter_map(|(i, (p, s))| p.as_ref().and(*s).map(|s| (i, s)))
        .collect();
    let copies: Vec<PlacedCopy> = placements.into_iter().flatten().collect();
    let loose = scene_primitives_of(objects, |i, o| {
        keep(i, o) && copied.binary_search_by_key(&i, |c| c.0).is_err()
    });
    // A template triangle that has no area where it is placed has no primitive in the
    // objects' own primitives: then one build over those.
    let lost_area = std::sync::atomic::AtomicBool::new(false);
    let placed = |c: usize, k: usize| {
        let (i, s) = copied[c];
        let o = &objects[i];
        let t = s.triangles[k] as usize;
        let p = s
            .mesh
            .placed_triangle(t, o.position_m(), o.rotation(), i as u32);
        if p.is_degenerate_triangle() {
            lost_area.store(true, std::sync::atomic::Ordering::Relaxed);
        }
        p
    };
    let bvh = Bvh::build_with_copies(loose, &copies, placed);
    if lost_area.into_inner() {
        return Bvh::build(scene_primitives_of(objects, keep));
    }
    bvh
}

/// The world-frame primitives of the objects `keep(index, object)` takes, each tagged with
/// its index in `objects`.
pub fn scene_primitives_of(
    objects: &[SceneObject],
    keep: impl Fn(usize, &SceneObject) -> bool + Sync,
) -> Vec<Primitive> {
    // In parallel by object; collected in the objects' order.
    objects
        .par_iter()
        .enumerate()
        .filter(|(i, o)| keep(*i, o))
        .flat_map_iter(|(i, o)| o.shape().primitives(o.position_m(), o.rotation(), i as u32))
        .collect()
}

/// Traces the scene with its configured model, then applies the two-way rain attenuation
/// along each contribution's outgoing and returning directions (ITU-R P.838-3, docs/physics.md).
pub fn trace_scene(scene: &Scene, bvh: &Bvh) -> ScatterSet {
    trace_scene_keeping(scene, bvh, None)
}

/// [`trace_scene`], the PO model reusing and keeping the traces of `still`'s objects where no
/// moving object meets their rays (`po::still`): the same bytes as [`trace_scene`].
pub fn trace_scene_keeping(
    scene: &Scene,
    bvh: &Bvh,
    still: Option<&po::StillTraces>,
) -> ScatterSet {
    let po_model = scene.scattering().model() == ScatteringModel::PhysicalOptics;
    let Some(still) = still.filter(|_| po_model) else {
        let mut set = match scene.scattering().model() {
            ScatteringModel::PhysicalOptics => po::trace(scene, bvh),
            ScatteringModel::Paper => paper::trace(scene, bvh),
        };
        land_and_rain(scene, &mut set);
        return set;
    };
    let objects = scene.objects();
    // The bounding spheres of what may meet a still object's rays: every extended object
    // that moves.
    let movers: Vec<(DVec3, f64)> = objects
        .iter()
        .enumerate()
        .filter(|(i, o)| !still.is_still(*i) && !o.shape().is_point())
        .map(|(_, o)| (o.bounding_centre_m(), o.shape().bounding_radius_m()))
        .collect();
    let met = |reach: &po::ObjectReach| movers.iter().any(|&(c, r)| reach.met_by(c, r));
    let kept: Vec<Option<Arc<po::KeptTrace>>> = (0..objects.len())
        .map(|i| {
            let kept = still.get(i).filter(|k| !met(&k.reach));
            if kept.is_some() {
                still.count_reuse();
            }
            kept
        })
        .collect();
    let select: Vec<po::Selection> = (0..objects.len())
        .map(|i| {
            match (
                &kept[i],
                still.is_still(i) && !objects[i].shape().is_point(),
            ) {
                (Some(_), _) => po::Selection::Skip,
                (None, true) => po::Selection::TraceRecording,
                (None, false) => po::Selection::Trace,
            }
        })
        .collect();
    let (mut fresh, mut rays) = po::trace_selected(scene, bvh, &select);
    land_and_rain(scene, &mut fresh);
    // The kept objects' runs in among the new ones, in object order (each object's
    // contributions are one run of either).
    let mut set = ScatterSet {
        contributions: Vec::with_capacity(
            fresh.contributions.len()
                + kept
                    .iter()
                    .flatten()
                    .map(|k| k.contributions.len())
                    .sum::<usize>(),
        ),
        rays_cast: 0,
        tube_budgets: fresh.tube_budgets,
        land_shadowed: fresh.land_shadowed,
        kept: Vec::new(),
    };
    let mut next = 0;
    for (i, kept) in kept.iter().enumerate() {
        if let Some(k) = kept {
            set.contributions.extend_from_slice(&k.contributions);
            set.rays_cast += k.rays;
            set.tube_budgets[i] = k.budget;
            if let Some(n) = set.land_shadowed.get_mut(i) {
                *n = k.land_shadowed;
            }
            continue;
        }
        let start = next;
        while next < fresh.contributions.len() && fresh.contributions[next].object as usize == i {
            next += 1;
        }
        let run = &fresh.contributions[start..next];
        set.contributions.extend_from_slice(run);
        set.rays_cast += rays[i].rays;
        // A still object's trace is kept when no moving object met its rays: it is then the
        // trace of the world without them.
        if let Some(reach) = rays[i].reach.take() {
            if !met(&reach) {
                still.keep(
                    i,
                    Arc::new(po::KeptTrace {
                        contributions: run.to_vec(),
                        rays: rays[i].rays,
                        budget: set.tube_budgets[i],
                        land_shadowed: set.land_shadowed.get(i).copied().unwrap_or(0),
                        reach,
                    }),
                );
            }
        }
    }
    if kept.iter().any(Option::is_some) {
        set.kept = kept;
    }
    set
}

/// Land's shadows ([`shade_by_land`]) and the two-way rain attenuation of every contribution.
fn land_and_rain(scene: &Scene, set: &mut ScatterSet) {
    if !scene.environment().land().is_empty() {
        shade_by_land(scene, set);
    }
    if let Some(rain) = scene.environment().rain() {
        let radar = scene.radar();
        let from = radar.position_m().truncate();
        let freq_ghz = radar.carrier_freq_hz() / 1e9;
        let horizontal = radar.polarisation() == crate::model::Polarisation::Hh;
        // The specific attenuations (ITU-R P.838-3) once per scene, not per contribution.
        let attenuator = rain.attenuator(freq_ghz, horizontal);
        // A leg's attenuation: γ integrated along its track on the ground through the rain
        // columns, times the slant length over the track length (1/cos el), over the part of
        // the leg below the rain top, so that a slant leg through uniform rain loses γ·R
        // (docs/physics.md §2.7; the labels' `losses.rain` uses the same function). A leg
        // via the sea runs to the object's image below it: that line folded at the sea is the
        // real path, and `one_way_db_path` charges its stretch with |z| ≤ top, the real
        // path's under the top.
        let radar_z_m = radar.position_m().z;
        // A leg's direction as (sin az, cos az, cos el, sin el).
        let trig = |az: f64, el: f64| {
            let ((sin_az, cos_az), (sin_el, cos_el)) = (
                crate::special::sin_cos_fast(az),
                crate::special::sin_cos_fast(el),
            );
            (sin_az, cos_az, cos_el, sin_el)
        };
        let leg_db = |(sin_az, cos_az, cos_el, sin_el): (f64, f64, f64, f64), range_m: f64| {
            attenuator.one_way_db_path(
                from,
                glam::DVec2::new(sin_az, cos_az),
                range_m * cos_el,
                range_m,
                radar_z_m,
                radar_z_m + range_m * sin_el,
            )
        };
        // A tube's returns share their outgoing direction, and most return along it: each
        // direction's sines and cosines are kept for the next contribution (the same values).
        let mut tx_trig = crate::special::LastCall::new();
        let mut rx_trig = crate::special::LastCall::new();
        for c in &mut set.contributions {
            // Each leg's length: half the path for a monostatic single bounce is exact; for
            // multi-bounce paths the legs are close to it at the ranges where rain matters.
            let half = 0.5 * c.path_m;
            let tx_key = (c.az_tx_rad.to_bits(), c.el_tx_rad.to_bits());
            let rx_key = (c.az_rx_rad.to_bits(), c.el_rx_rad.to_bits());
            let tx = tx_trig.get_or(tx_key, || trig(c.az_tx_rad, c.el_tx_rad));
            let rx = if rx_key == tx_key {
                tx
            } else {
                rx_trig.get_or(rx_key, || trig(c.az_rx_rad, c.el_rx_rad))
            };
            let db = leg_db(tx, half) + leg_db(rx, half);
            // Outside the rain both legs lose exactly 0 dB: 10^0 = 1 leaves the amplitude as is.
            if db != 0.0 {
                c.amplitude_v *= 10f64.powf(-db / 20.0);
            }
        }
    }
}

/// Takes away the contributions that land hides (docs/physics.md §16). A contribution's
/// legs run from the antenna (height h) to its scatterer at range R (half its path) on
/// their bearings. A leg arriving at elevation `el` comes straight from a point
/// `h + R·sin el` high, or via the sea from the image of a point `−(h + R·sin el)` high;
/// which of the two it is follows from the object's height extent (its bounding sphere's).
/// A straight leg is hidden when it passes below the land's highest elevation on its
/// bearing nearer than the scatterer; a leg via the sea when its specular point (ground
/// range `g·h/(h + z)`) lies on land — the sea reflects only over water — or land rises
/// above either of its pieces, down to the sea and up to the scatterer. Counts what it took
/// per object in `set.land_shadowed`.
pub fn shade_by_land(scene: &Scene, set: &mut ScatterSet) {
    let radar = scene.radar();
    let env = scene.environment();
    let land = env.land();
    let antenna = radar.position_m();
    let view = crate::land::profile::LandView::new(land, antenna.truncate());
    let curvature = env.earth_curvature();
    let h = antenna.z;
    let heights: Vec<(f64, f64)> = scene
        .objects()
        .iter()
        .map(|o| {
            let (c, r) = (o.bounding_centre_m().z, o.shape().bounding_radius_m());
            (c - r - 1.0, c + r + 1.0)
        })
        .collect();
    let mut shadowed = vec![0u32; scene.objects().len()];
    // A ray's crossings are kept for the next leg on the same bearing (a tube's returns and
    // an object's contributions share their bearings).
    let mut crossings: Vec<crate::land::profile::Crossing> = Vec::new();
    let mut crossings_az = f64::NAN;
    let mut hidden = |az: f64, el: f64, range_m: f64, (lo, hi): (f64, f64)| -> bool {
        if view.clear_bearing(az) {
            return false;
        }
        if az.to_bits() != crossings_az.to_bits() {
            view.crossings(az, &mut crossings);
            crossings_az = az;
        }
        let ground = range_m * el.cos();
        let straight_z = h + range_m * el.sin();
        let via_sea = !(lo..=hi).contains(&straight_z) && (lo..=hi).contains(&-straight_z);
        if !via_sea {
            let seen_at = crate::land::profile::elevation_rad(straight_z, ground, h, curvature);
            return view
                .max_land_elevation_along(az, &crossings, ground, h, curvature)
                .is_some_and(|top| top > seen_at);
        }
        let z = -straight_z;
        let specular = ground * h / (h + z.max(0.0)).max(1e-9);
        if view.walk(az, &crossings).at(specular).is_some() {
            return true;
        }
        view.blocks_segment_along(az, &crossings, (0.0, h), (specular, 0.0))
            || view.blocks_segment_along(az, &crossings, (specular, 0.0), (ground, z))
    };
    set.contributions.retain(|c| {
        let range = 0.5 * c.path_m;
        let extent = heights
            .get(c.object as usize)
            .copied()
            .unwrap_or((f64::NEG_INFINITY, f64::INFINITY));
        let same_leg = c.az_tx_rad.to_bits() == c.az_rx_rad.to_bits()
            && c.el_tx_rad.to_bits() == c.el_rx_rad.to_bits();
        let gone = hidden(c.az_tx_rad, c.el_tx_rad, range, extent)
            || (!same_leg && hidden(c.az_rx_rad, c.el_rx_rad, range, extent));
        if gone {
            if let Some(n) = shadowed.get_mut(c.object as usize) {
                *n += 1;
            }
        }
        !gone
    });
    set.land_shadowed = shadowed;
}
