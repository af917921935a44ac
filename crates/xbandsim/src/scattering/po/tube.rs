//! Ray tubes: the tube grid aimed at an object (or its mirror image below the sea), one tube's
//! bounces with the physical-optics integral at every hit, the field's polarisation through
//! perfect-conductor and sea reflections, and the shadow rays of the return paths
//! (docs/physics.md §2.2, §2.5; the formula is in the parent module's documentation).

use super::super::{carrier_phase, vector_bits};
use crate::geometry::{Aabb, Bvh, Primitive, PrimitiveKind, Ray};
use crate::model::Polarisation;
use crate::propagation::SeaSurface;
use glam::DVec3;
use num_complex::Complex64;
use std::ops::Range;

/// Offset from a surface when launching the next segment, m.
const SURFACE_OFFSET_M: f64 = 1e-6;

/// A complex field vector `re + j·im`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ComplexVec3 {
    /// Real part.
    pub re: DVec3,
    /// Imaginary part.
    pub im: DVec3,
}

impl ComplexVec3 {
    /// A real vector.
    pub fn real(v: DVec3) -> Self {
        ComplexVec3 {
            re: v,
            im: DVec3::ZERO,
        }
    }

    /// `self · v` for a real `v`.
    #[inline]
    pub fn dot(&self, v: DVec3) -> Complex64 {
        Complex64::new(self.re.dot(v), self.im.dot(v))
    }

    /// `c · v` for a complex scalar and a real vector.
    #[inline]
    pub fn scaled(v: DVec3, c: Complex64) -> Self {
        ComplexVec3 {
            re: v * c.re,
            im: v * c.im,
        }
    }

    /// `c · self` for a complex scalar.
    #[inline]
    pub fn times(self, c: Complex64) -> Self {
        ComplexVec3 {
            re: self.re * c.re - self.im * c.im,
            im: self.re * c.im + self.im * c.re,
        }
    }

    /// Sum.
    #[inline]
    pub fn plus(self, o: Self) -> Self {
        ComplexVec3 {
            re: self.re + o.re,
            im: self.im + o.im,
        }
    }

    /// The far field toward `s_hat` of the physical-optics current `J = 2n̂ × H` that this
    /// incident field (travelling along `k`, `H = k̂ × E / Z`) drives on a perfect conductor
    /// of normal `n` (facing the incoming wave), times `n̂·ŝ` and in the units of `E`:
    /// `−[(n̂·E)k̂ − (n̂·k̂)E]⊥`, the part across `ŝ` (Knott, Shaeffer & Tuley, *Radar Cross
    /// Section*, 2nd ed., eq. 5.37; docs/physics.md §2.2). In the specular direction it is
    /// `(n̂·ŝ)·(2(n̂·E)n̂ − E)`, the reflected field; off it, it keeps the polarisation
    /// independence of PO (a plate's backscatter `∝ cos θ` in both planes), which projecting
    /// the reflected field would not (that gives `cos 2θ` for E in the plane of incidence).
    #[inline]
    pub fn po_radiated(self, n: DVec3, k: DVec3, s_hat: DVec3) -> Self {
        let n_dot_k = n.dot(k);
        let across = |e: DVec3| {
            let w = k * n.dot(e) - e * n_dot_k;
            s_hat * s_hat.dot(w) - w
        };
        ComplexVec3 {
            re: across(self.re),
            im: across(self.im),
        }
    }

    /// Perfect-conductor reflection `2(n̂·E)n̂ − E`.
    #[inline]
    pub fn pec_reflect(self, n: DVec3) -> Self {
        ComplexVec3 {
            re: n * (2.0 * n.dot(self.re)) - self.re,
            im: n * (2.0 * n.dot(self.im)) - self.im,
        }
    }
}

/// The mirror image of a point or direction in the sea plane z = 0.
#[inline]
pub fn sea_mirror(v: DVec3) -> DVec3 {
    DVec3::new(v.x, v.y, -v.z)
}

/// Reflection of field `e` travelling along `k` (downward) off the sea: the horizontal part
/// scaled by Γ_H, the vertical part by Γ_V and carried onto the reflected direction's basis.
/// Returns the reflected field and direction.
pub fn sea_reflect(
    e: ComplexVec3,
    k: DVec3,
    sea: &SeaSurface,
    wavelength_m: f64,
) -> (ComplexVec3, DVec3) {
    let (gh, gv) = sea.reflection_sin((-k.z).clamp(-1.0, 1.0), wavelength_m);
    let mut h = k.cross(DVec3::Z);
    if h.length_squared() < 1e-24 {
        h = DVec3::X;
    }
    let h = h.normalize();
    let v_in = h.cross(k);
    let k_r = sea_mirror(k);
    let v_out = h.cross(k_r);
    let e_r =
        ComplexVec3::scaled(h, gh * e.dot(h)).plus(ComplexVec3::scaled(v_out, gv * e.dot(v_in)));
    (e_r, k_r)
}

/// Distance along `k` from `origin` to the sea plane z = 0, if the ray goes down into it.
#[inline]
fn sea_distance(origin: DVec3, k: DVec3) -> Option<f64> {
    (k.z < -1e-12 && origin.z > 0.0).then(|| -origin.z / k.z)
}

/// Polarisation unit vector for a line of sight `dir` (radar outward): horizontal
/// `ĥ = ẑ×d/|ẑ×d|`, vertical `v̂ = d×ĥ`. Both transmit and receive use this basis
/// (backscatter alignment).
#[inline]
pub fn polarisation_vector(dir: DVec3, pol: Polarisation) -> DVec3 {
    let mut h = DVec3::Z.cross(dir);
    if h.length_squared() < 1e-24 {
        h = DVec3::X;
    }
    let h = h.normalize();
    match pol {
        Polarisation::Hh => h,
        Polarisation::Vv => dir.cross(h).normalize(),
    }
}

#[inline]
fn sinc(x: f64) -> f64 {
    if x.abs() < 1e-9 {
        1.0
    } else {
        crate::special::sin_fast(x) / x
    }
}

/// How the object is lit and where the echo is received.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Illumination {
    /// Spherical wave from the radar phase centre (scene rendering): rays diverge from it and
    /// each path's length is measured to it exactly.
    FromPoint {
        /// Radar phase centre, m.
        radar_m: DVec3,
    },
    /// Plane wave (far-field RCS): parallel rays arriving along `−toward_radar`; path lengths
    /// are measured from a reference plane perpendicular to it.
    PlaneWave {
        /// Unit vector from the object toward the (distant) radar.
        toward_radar: DVec3,
    },
}

/// A grid of square ray tubes covering one object's bounding sphere as seen by the radar
/// (or, for `via_sea`, its mirror image below the sea).
#[derive(Debug, Clone, Copy)]
pub struct TubeGrid {
    /// Illumination.
    pub illumination: Illumination,
    /// Centre of the bounding sphere aimed at (mirrored for `via_sea`), m.
    pub centre_m: DVec3,
    /// Transverse unit axes of the grid plane.
    pub axis_u: DVec3,
    /// Second transverse axis.
    pub axis_v: DVec3,
    /// Tube side at the grid plane, m.
    pub spacing_m: f64,
    /// Tubes per side.
    pub cells_per_side: usize,
    /// Bounding radius covered, m.
    pub radius_m: f64,
    /// The tubes reach the object after a sea reflection.
    pub via_sea: bool,
    /// The ray budget bound: `spacing_m` is wider than the requested spacing.
    pub capped: bool,
    /// Plane-wave mode: the launch/reference plane's point on the axis, m.
    plane_origin_m: DVec3,
}

/// The tubes of a grid that may meet one object ([`TubeGrid::coverage`]).
#[derive(Debug, Clone)]
pub struct TubeCoverage {
    /// Columns of the object's window.
    pub columns: Range<usize>,
    /// Rows of the object's window.
    pub rows: Range<usize>,
    /// Row-major over the window: whether the tube may meet the object.
    covered: Vec<bool>,
}

impl TubeCoverage {
    /// Whether tube (i, j) may meet the object (false outside the window).
    #[inline]
    pub fn covers(&self, i: usize, j: usize) -> bool {
        self.columns.contains(&i)
            && self.rows.contains(&j)
            && self.covered[(j - self.rows.start) * self.columns.len() + i - self.columns.start]
    }
}

impl TubeGrid {
    /// Grid over the bounding sphere (`centre_m`, `radius_m`) for `illumination`.
    pub fn new(
        illumination: Illumination,
        centre_m: DVec3,
        radius_m: f64,
        spacing_m: f64,
        max_rays: usize,
        via_sea: bool,
    ) -> TubeGrid {
        let toward = match illumination {
            Illumination::FromPoint { radar_m } => (radar_m - centre_m).normalize(),
            Illumination::PlaneWave { toward_radar } => toward_radar.normalize(),
        };
        let d = -toward;
        let mut u = d.cross(DVec3::Z);
        if u.length_squared() < 1e-24 {
            u = DVec3::X;
        }
        let axis_u = u.normalize();
        let axis_v = axis_u.cross(d).normalize();
        let (cells, capped) = crate::model::tube_grid_cells(radius_m, spacing_m, max_rays);
        // Every tube is sized with this spacing (not the requested one), so that the tubes
        // tile the disk whatever the budget: a wider spacing costs accuracy, never energy.
        TubeGrid {
            illumination,
            centre_m,
            axis_u,
            axis_v,
            spacing_m: 2.0 * radius_m / cells as f64,
            cells_per_side: cells,
            radius_m,
            via_sea,
            capped,
            plane_origin_m: centre_m + toward * (radius_m + 1.0),
        }
    }

    /// Plane-wave mode: the reference plane's point on the axis that paths are measured
    /// from, m.
    pub fn plane_origin_m(&self) -> DVec3 {
        self.plane_origin_m
    }

    /// Grid point of cell (i, j) on the plane through the centre, if inside the covered disk
    /// (with half a cell of margin).
    #[inline]
    pub fn point(&self, i: usize, j: usize) -> Option<DVec3> {
        let x = (i as f64 + 0.5) * self.spacing_m - self.radius_m;
        let y = (j as f64 + 0.5) * self.spacing_m - self.radius_m;
        let r_max = self.radius_m + 0.71 * self.spacing_m;
        (x * x + y * y <= r_max * r_max).then(|| self.centre_m + self.axis_u * x + self.axis_v * y)
    }

    /// The tubes (columns `i`, rows `j`) whose rays can meet `bounds` (for a `via_sea` grid,
    /// after the sea reflection): every other tube misses the box, so its first object hit
    /// cannot be on what the box holds. A tube contributes only if its first object hit is
    /// its target (the parent module), so tracing just these tubes gives the same returns.
    ///
    /// The box's corners are projected onto the grid plane along the rays (from the radar
    /// for a point source, parallel for a plane wave; mirrored in z for a via-sea grid, whose
    /// reflected rays continue the straight line to the image). Rays are a projection, so a
    /// ray that meets the box crosses the plane inside the corners' bounding rectangle; one
    /// cell of margin covers rounding. If a corner is not in front of the radar, every tube.
    pub fn window(&self, bounds: &Aabb) -> (Range<usize>, Range<usize>) {
        if !(bounds.min.cmple(bounds.max).all()) {
            return (0..0, 0..0);
        }
        self.window_of_points(&bounds.corners())
    }

    /// As [`TubeGrid::window`] for anything inside the convex hull of `points` (a ray that
    /// meets it crosses the grid plane inside the projected points' bounding rectangle).
    /// No points give every tube (unlike an empty box, which gives none).
    pub fn window_of_points(&self, points: &[DVec3]) -> (Range<usize>, Range<usize>) {
        let all = (0..self.cells_per_side, 0..self.cells_per_side);
        let (mut x_lo, mut x_hi, mut y_lo, mut y_hi) = (
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        );
        for &point in points {
            // Via-sea tubes: the reflected rays continue the straight line to the image.
            let p = if self.via_sea {
                sea_mirror(point)
            } else {
                point
            };
            let on_plane = match self.illumination {
                Illumination::FromPoint { radar_m } => {
                    let axis = self.centre_m - radar_m;
                    let depth = (p - radar_m).dot(axis);
                    // Not in front of the radar (or NaN): cull nothing.
                    if depth.is_nan() || depth <= 1e-6 * axis.length_squared() {
                        return all;
                    }
                    radar_m + (p - radar_m) * (axis.length_squared() / depth)
                }
                Illumination::PlaneWave { .. } => p,
            };
            let x = (on_plane - self.centre_m).dot(self.axis_u);
            let y = (on_plane - self.centre_m).dot(self.axis_v);
            x_lo = x_lo.min(x);
            x_hi = x_hi.max(x);
            y_lo = y_lo.min(y);
            y_hi = y_hi.max(y);
        }
        // Cell i's point is at (i + 1/2)·δ − r.
        let cells = |lo: f64, hi: f64| {
            let first = ((lo - self.spacing_m + self.radius_m) / self.spacing_m - 0.5).floor();
            let last = ((hi + self.spacing_m + self.radius_m) / self.spacing_m - 0.5).ceil();
            if !(first.is_finite() && last.is_finite()) {
                return 0..self.cells_per_side;
            }
            let first = first.clamp(0.0, self.cells_per_side as f64) as usize;
            let end = (last + 1.0).clamp(0.0, self.cells_per_side as f64) as usize;
            first..end.max(first)
        };
        (cells(x_lo, x_hi), cells(y_lo, y_hi))
    }

    /// The tubes that may meet an object made of `parts` (each primitive's hull points,
    /// [`Primitive::hull_points`](crate::geometry::Primitive::hull_points)) within `bounds`
    /// (the object's box): the union of the parts' windows, inside the object's window. A
    /// tube counts only if its ray meets the object, so one of its parts, so it crosses the
    /// grid plane inside that part's window ([`TubeGrid::window_of_points`]); the others
    /// return nothing. Tighter than the object's window alone for objects whose box is much
    /// larger than their silhouette (a hull seen obliquely, a mast above a deck).
    pub fn coverage(
        &self,
        bounds: &Aabb,
        parts: impl IntoIterator<Item = ([DVec3; 8], usize)>,
    ) -> TubeCoverage {
        let (columns, rows) = self.window(bounds);
        let width = columns.len();
        let mut covered = vec![false; width * rows.len()];
        for (points, n) in parts {
            let (c, r) = self.window_of_points(&points[..n]);
            let c = c.start.max(columns.start)..c.end.min(columns.end);
            let r = r.start.max(rows.start)..r.end.min(rows.end);
            if c.is_empty() {
                continue;
            }
            for j in r {
                let row = (j - rows.start) * width;
                covered[row + c.start - columns.start..row + c.end - columns.start].fill(true);
            }
        }
        TubeCoverage {
            columns,
            rows,
            covered,
        }
    }

    /// Launch of tube (i, j): origin, unit direction, the tube's unit transverse axes, and the
    /// path length at which its side equals `spacing_m` (None for parallel tubes).
    #[inline]
    fn launch(&self, i: usize, j: usize) -> Option<(DVec3, DVec3, DVec3, DVec3, Option<f64>)> {
        let p = self.point(i, j)?;
        match self.illumination {
            Illumination::FromPoint { radar_m } => {
                let to_p = p - radar_m;
                let r = to_p.length();
                let k = to_p / r;
                let eu = (self.axis_u - k * self.axis_u.dot(k)).normalize();
                Some((radar_m, k, eu, k.cross(eu), Some(r)))
            }
            Illumination::PlaneWave { toward_radar } => {
                let origin = p + (self.plane_origin_m - self.centre_m);
                Some((origin, -toward_radar, self.axis_u, self.axis_v, None))
            }
        }
    }

    /// Unit vector from `p` back toward the receiver and the distance to it (for a plane
    /// wave, to the reference plane).
    #[inline]
    fn return_path(&self, p: DVec3) -> (DVec3, f64) {
        match self.illumination {
            Illumination::FromPoint { radar_m } => {
                let v = radar_m - p;
                let d = v.length();
                (v / d, d)
            }
            Illumination::PlaneWave { toward_radar } => {
                (toward_radar, (self.plane_origin_m - p).dot(toward_radar))
            }
        }
    }
}

/// Settings for one SBR trace, taken from the scene or given by the RCS tool.
#[derive(Debug, Clone, Copy)]
pub struct SbrSettings {
    /// Carrier wavelength, m.
    pub wavelength_m: f64,
    /// Polarisation.
    pub polarisation: Polarisation,
    /// Maximum bounces on objects.
    pub max_bounces: usize,
    /// Tube spacing, m.
    pub spacing_m: f64,
    /// Cap on rays per object (per grid).
    pub max_rays: usize,
    /// The reflecting sea surface, if any (scene rendering only).
    pub sea: Option<SeaSurface>,
    /// Hide hits below the radar horizon of the 4/3 earth (scene rendering only).
    pub earth_curvature: bool,
    /// Add the PTD fringe returns of the objects' wedge edges (`edges`).
    pub edge_diffraction: bool,
}

impl SbrSettings {
    /// These settings as a trace from `illumination` uses them: the sea for a radar's point
    /// source, none for a plane wave (the RCS tool's free space).
    #[inline]
    pub fn seen_from(&self, illumination: Illumination) -> SbrSettings {
        let sea = match illumination {
            Illumination::FromPoint { .. } => self.sea,
            Illumination::PlaneWave { .. } => None,
        };
        SbrSettings { sea, ..*self }
    }
}

/// Per-ray result: contributions as root-RCS with geometry, before the volt conversion.
#[derive(Debug, Clone, Copy)]
pub struct TubeReturn {
    /// Root-RCS `S`, m.
    pub root_rcs_m: Complex64,
    /// Two-way path, m.
    pub path_m: f64,
    /// Unit direction of the first segment.
    pub tx_dir: DVec3,
    /// Unit direction from the receiver toward where the echo arrives from.
    pub rx_dir: DVec3,
    /// Path from the radar to the first object hit, m.
    pub range_tx_m: f64,
    /// Path from the last hit back to the receiver, m.
    pub range_rx_m: f64,
    /// Bounces on objects.
    pub bounces: u8,
    /// Sea reflections along the path.
    pub sea_reflections: u8,
}

/// One return of a hit toward the receiver.
struct Exit {
    s_hat: DVec3,
    rx_dir: DVec3,
    range_rx_m: f64,
    via_sea: bool,
}

/// Where a trace's rays went: every ray cast is handed over as a segment — its origin, unit
/// direction and the length searched (∞ for a ray that met nothing) — so that a caller can
/// tell later whether something placed elsewhere would have met one of them.
pub trait RaySink {
    /// One ray's segment.
    fn segment(&mut self, origin_m: DVec3, dir: DVec3, length_m: f64);
}

/// No record kept.
impl RaySink for () {
    #[inline(always)]
    fn segment(&mut self, _: DVec3, _: DVec3, _: f64) {}
}

/// How a curved primitive's surface bends: its radius of curvature, m, and for a cylinder
/// wall the straight span along which it does not bend; `None` for flat primitives.
fn curved_surface(p: &Primitive) -> Option<(f64, Option<AxialSpan>)> {
    match p.kind {
        PrimitiveKind::Sphere { radius_m, .. } => Some((radius_m, None)),
        PrimitiveKind::Cylinder {
            base,
            axis,
            radius_m,
            height_m,
        } => Some((
            radius_m,
            Some(AxialSpan {
                base,
                axis,
                height_m,
            }),
        )),
        _ => None,
    }
}

/// A cylinder wall's axis (unit) and the span of it, from `base` for `height_m`, that the
/// wall covers.
#[derive(Clone, Copy)]
struct AxialSpan {
    base: DVec3,
    axis: DVec3,
    height_m: f64,
}

impl AxialSpan {
    /// Whether every sub-ray of a tube travelling along `k` with cross-section edges
    /// `edge_u`, `edge_v` centred on `hit_p` (on a wall of radius `radius_m`) meets the wall,
    /// if at all, within its span. A sub-ray passes through `hit_p + offset`, the offset
    /// within `½(|e_u·â| + |e_v·â|)` of it along the axis and `ρ = ½(|e_u⊥| + |e_v⊥|)` across
    /// it; its hits lie within R of the axis and that point within R + ρ, so they are at
    /// most `(2R + ρ)/|k̂⊥|` from it along k̂, and `|k̂·â|` times that along the axis. (The
    /// footprint on the tangent plane would not do: near grazing that plane meets the rays
    /// metres from the surface.)
    fn holds_tube(
        self,
        hit_p: DVec3,
        (edge_u, edge_v): (DVec3, DVec3),
        k: DVec3,
        radius_m: f64,
    ) -> bool {
        let a = self.axis;
        let k_along = k.dot(a).abs();
        let k_across = (1.0 - k_along * k_along).max(0.0).sqrt();
        let across_m = |e: DVec3| (e - a * e.dot(a)).length();
        let rho_m = 0.5 * (across_m(edge_u) + across_m(edge_v));
        let shift_m = k_along * (2.0 * radius_m + rho_m) / k_across;
        let centre_m = (hit_p - self.base).dot(a);
        let half_span_m = 0.5 * (edge_u.dot(a).abs() + edge_v.dot(a).abs()) + shift_m;
        // A tube along the axis (k̂⊥ = 0) has an infinite shift, or NaN: held by no span.
        centre_m - half_span_m >= 0.0 && centre_m + half_span_m <= self.height_m
    }
}

/// The most sub-tubes a side that a tube on a curved surface is cut into.
pub const MAX_CURVED_SUBDIVISIONS: usize = 32;

/// Largest phase, rad, that the surface's bend from its tangent plane may add across a
/// footprint before the tube is cut into sub-tubes (π/32: a sphere's RCS then stays within
/// 0.3 dB of its exact PO value at ka ≥ 20 with tubes of λ/4, 0.5 dB with λ/2).
const CURVED_SAG_PHASE_RAD: f64 = std::f64::consts::PI / 32.0;

/// Sub-tubes a side for a footprint whose sag adds `sag_phase` rad at its corners: the sag
/// goes as the footprint's length squared, so cutting each side in m divides it by m².
fn curved_subdivisions(sag_phase: f64) -> usize {
    if sag_phase.is_nan() || sag_phase <= CURVED_SAG_PHASE_RAD {
        return 1;
    }
    ((sag_phase / CURVED_SAG_PHASE_RAD).sqrt().ceil() as usize).min(MAX_CURVED_SUBDIVISIONS)
}

/// The field a tube of cross-section edges `edges` radiates toward `s_hat` from the curved
/// `primitive` it hit at `hit_p` (travelling along `k` with field `e_field`), with its
/// footprint integral: the sum over m_u × m_v sub-tubes (each edge cut for the sag across
/// its own length: along a cylinder's axis, one), each met on the surface itself (one
/// that misses it, past its silhouette, adds nothing), with its own normal, its own tangent
/// plane's footprint integral and its path's phase relative to the tube's centre. The
/// tangent plane of a single footprint misses the surface's bend near a silhouette, where
/// footprints grow long (`δ/|n̂·k̂|`) and their phase curves: there, unrefined, the tubes of a
/// sphere add a false terminator term that swings its RCS by up to ±2 dB at ka = 20
/// (docs/physics.md §2.2).
#[allow(clippy::too_many_arguments)]
fn radiated_over_sub_tubes(
    primitive: &Primitive,
    hit_p: DVec3,
    k: DVec3,
    e_field: ComplexVec3,
    s_hat: DVec3,
    (edge_u, edge_v): (DVec3, DVec3),
    (m_u, m_v): (usize, usize),
    wavenumber: f64,
) -> ComplexVec3 {
    let (sub_u, sub_v) = (edge_u / m_u as f64, edge_v / m_v as f64);
    // Far enough back along −k that every sub-ray starts outside the primitive's box.
    let bounds = primitive.bounds();
    let back_m = (bounds.max - bounds.min).length() + edge_u.length() + edge_v.length();
    let weight = 1.0 / (m_u * m_v) as f64;
    let mut sum = ComplexVec3::real(DVec3::ZERO);
    for a in 0..m_u {
        for b in 0..m_v {
            let offset = sub_u * (a as f64 + 0.5 - 0.5 * m_u as f64)
                + sub_v * (b as f64 + 0.5 - 0.5 * m_v as f64);
            let ray = Ray {
                origin_m: hit_p + offset - k * back_m,
                dir: k,
            };
            let Some((t, normal)) = primitive.intersect(&ray, 2.0 * back_m) else {
                continue;
            };
            let p = ray.at(t);
            let n = if normal.dot(k) < 0.0 { normal } else { -normal };
            let n_dot_k = n.dot(k);
            if n.dot(s_hat) <= 0.0 || n_dot_k >= 0.0 {
                continue;
            }
            let k_r = k - n * (2.0 * n_dot_k);
            let q = (s_hat - k_r) * wavenumber;
            let f1 = sub_u - k * (n.dot(sub_u) / n_dot_k);
            let f2 = sub_v - k * (n.dot(sub_v) / n_dot_k);
            let footprint = sinc(0.5 * q.dot(f1)) * sinc(0.5 * q.dot(f2)) / n_dot_k.abs();
            // Path relative to the centre's: longer in along k, shorter out along ŝ.
            let extra_path_m = (p - hit_p).dot(k - s_hat);
            let phase = Complex64::from_polar(weight * footprint, -wavenumber * extra_path_m);
            sum = sum.plus(e_field.po_radiated(n, k, s_hat).times(phase));
        }
    }
    sum
}

/// Traces tube (i, j) of `grid` aimed at object `target` and pushes its returns into `out`.
/// Returns the number of rays cast.
pub fn trace_tube(
    bvh: &Bvh,
    grid: &TubeGrid,
    i: usize,
    j: usize,
    target: u32,
    s: &SbrSettings,
    out: &mut Vec<TubeReturn>,
) -> u64 {
    trace_tube_with(bvh, grid, i, j, target, s, out, &mut ())
}

/// [`trace_tube`], handing every ray it casts to `rays`.
#[allow(clippy::too_many_arguments)]
pub fn trace_tube_with(
    bvh: &Bvh,
    grid: &TubeGrid,
    i: usize,
    j: usize,
    target: u32,
    s: &SbrSettings,
    out: &mut Vec<TubeReturn>,
    rays_met: &mut impl RaySink,
) -> u64 {
    let Some((launch, k0, mut unit_u, mut unit_v, spread_ref_m)) = grid.launch(i, j) else {
        return 0;
    };
    let wavenumber = std::f64::consts::TAU / s.wavelength_m;
    let root_4pi_over_lambda = (4.0 * std::f64::consts::PI).sqrt() / s.wavelength_m;
    let sea = s.seen_from(grid.illumination).sea;
    let pol_k0 = polarisation_vector(k0, s.polarisation);
    let mut e_field = ComplexVec3::real(pol_k0);
    let mut origin = launch;
    let mut k = k0;
    let mut path_m = 0.0;
    let mut range_tx_m = 0.0;
    let mut edge_u = DVec3::ZERO;
    let mut edge_v = DVec3::ZERO;
    let mut rays = 0u64;
    let mut object_hits = 0usize;
    let mut sea_hits = 0u8;
    // A sea reflection whose field is not computed yet: the field and direction before it.
    let mut pending_sea: Option<(ComplexVec3, DVec3)> = None;
    let max_interactions = s.max_bounces + usize::from(grid.via_sea);
    for interaction in 1..=max_interactions {
        rays += 1;
        // The sea first: an object hit beyond it cannot be the first, so the search stops
        // there (a hit exactly at the sea's distance counts as the sea's).
        let sea_t = sea.and_then(|_| sea_distance(origin, k));
        let hit = bvh.closest_hit(
            &Ray {
                origin_m: origin,
                dir: k,
            },
            sea_t.unwrap_or(f64::INFINITY),
        );
        let curvature_m = hit
            .and_then(|h| bvh.hit_primitive(&h))
            .and_then(curved_surface);
        let (t, normal, object) = match (hit, sea_t) {
            (Some(h), _) => (h.t_m, h.normal, Some(h.object)),
            (None, Some(ts)) => (ts, DVec3::Z, None),
            (None, None) => {
                rays_met.segment(origin, k, f64::INFINITY);
                break;
            }
        };
        rays_met.segment(origin, k, t);
        // Direct tubes must reach their object first; via-sea tubes the sea, then the object.
        let wanted = match (grid.via_sea, interaction) {
            (false, 1) => object == Some(target),
            (true, 1) => object.is_none(),
            (true, 2) => object == Some(target),
            _ => true,
        };
        if !wanted {
            break;
        }
        let hit_p = origin + k * t;
        path_m += t;
        let Some(_) = object else {
            // Sea reflection: no return of its own (that is clutter), the tube carries on.
            // Its Fresnel coefficients wait until the reflected ray meets an object it
            // returns from (past the horizon check): many via-sea tubes miss their object,
            // and the direction does not depend on them.
            let sea = sea.expect("sea hit only when the sea is on");
            if let Some((e, k_in)) = pending_sea.take() {
                e_field = sea_reflect(e, k_in, &sea, s.wavelength_m).0;
            }
            pending_sea = Some((e_field, k));
            sea_hits += 1;
            unit_u = sea_mirror(unit_u);
            unit_v = sea_mirror(unit_v);
            edge_u = sea_mirror(edge_u);
            edge_v = sea_mirror(edge_v);
            k = sea_mirror(k);
            origin = hit_p + DVec3::Z * SURFACE_OFFSET_M;
            continue;
        };
        if let (true, Illumination::FromPoint { radar_m }) = (s.earth_curvature, grid.illumination)
        {
            let ground = (hit_p - radar_m).truncate().length();
            if !crate::propagation::above_horizon(radar_m.z, ground, hit_p.z) {
                break; // below the radar horizon
            }
        }
        if let (Some((e, k_in)), Some(sea)) = (pending_sea.take(), sea) {
            e_field = sea_reflect(e, k_in, &sea, s.wavelength_m).0;
        }
        object_hits += 1;
        if object_hits == 1 {
            range_tx_m = path_m;
            let side = spread_ref_m.map_or(grid.spacing_m, |r| grid.spacing_m * path_m / r);
            edge_u = unit_u * side;
            edge_v = unit_v * side;
        }
        let n = if normal.dot(k) < 0.0 { normal } else { -normal };
        let n_dot_k = n.dot(k); // < 0
        let k_r = k - n * (2.0 * n_dot_k);
        let e_r = e_field.pec_reflect(n);
        let lift = hit_p + n * SURFACE_OFFSET_M;
        // A tube's first object hit returns along the way it came in, which its own searches
        // found clear: a direct tube's straight back, a via-sea tube's via the same sea point
        // (the line from the hit to the radar's image meets the sea where the tube reflected).
        // Those returns need no shadow rays (docs/physics.md §2.2).
        let first_hit = object_hits == 1 && interaction == 1 + usize::from(grid.via_sea);
        let retraces = first_hit && !grid.via_sea;
        let retraces_via_sea = first_hit && grid.via_sea;
        // Direct return.
        let (s_hat, range_rx_m) = grid.return_path(hit_p);
        let mut exits: [Option<Exit>; 2] = [None, None];
        if n.dot(s_hat) > 0.0 {
            let clear = retraces || {
                rays += 1;
                rays_met.segment(lift, s_hat, range_rx_m - SURFACE_OFFSET_M);
                !bvh.any_hit(
                    &Ray {
                        origin_m: lift,
                        dir: s_hat,
                    },
                    range_rx_m - SURFACE_OFFSET_M,
                )
            };
            if clear {
                exits[0] = Some(Exit {
                    s_hat,
                    // A first hit's echo comes back along its launch ray: its direction is
                    // the launch direction (−ŝ to within rounding), taken as is so that the
                    // return's angles and patterns are the launch's (docs/physics.md §2.2).
                    rx_dir: if retraces { k0 } else { -s_hat },
                    range_rx_m,
                    via_sea: false,
                });
            }
        }
        // Return via the sea, toward the radar's image below z = 0.
        if let (Some(_), Illumination::FromPoint { radar_m }) = (sea, grid.illumination) {
            if hit_p.z > 0.0 && radar_m.z > 0.0 {
                let image = sea_mirror(radar_m);
                let v = image - hit_p;
                let dist = v.length();
                let s2 = v / dist;
                if n.dot(s2) > 0.0 && s2.z < 0.0 {
                    let t_sea = hit_p.z / -s2.z;
                    let sea_pt = hit_p + s2 * t_sea;
                    let up = radar_m - sea_pt;
                    let up_len = up.length();
                    let clear = retraces_via_sea || {
                        rays += 2;
                        rays_met.segment(lift, s2, t_sea);
                        rays_met.segment(sea_pt, up / up_len, up_len);
                        !bvh.any_hit(
                            &Ray {
                                origin_m: lift,
                                dir: s2,
                            },
                            t_sea,
                        ) && !bvh.any_hit(
                            &Ray {
                                origin_m: sea_pt,
                                dir: up / up_len,
                            },
                            up_len,
                        )
                    };
                    if clear {
                        exits[1] = Some(Exit {
                            s_hat: s2,
                            rx_dir: -up / up_len,
                            range_rx_m: dist,
                            via_sea: true,
                        });
                    }
                }
            }
        }
        let area_perp = edge_u.cross(edge_v).length();
        // On a cylinder whose straight span holds all the tube's sub-rays, each edge is cut
        // for its own sag. Elsewhere both edges are cut alike: on a sphere, whose bend is the
        // same both ways, and where a cylinder's end may cut the tube, so that each sub-ray
        // past the end is met where it lands, if anywhere.
        let edges_cut_apart = curvature_m.is_some_and(|(radius_m, span)| {
            span.is_some_and(|s| s.holds_tube(hit_p, (edge_u, edge_v), k, radius_m))
        });
        for exit in exits.iter().flatten() {
            // Footprint edges: the tube's edges projected along k onto the facet.
            let f1 = edge_u - k * (n.dot(edge_u) / n_dot_k);
            let f2 = edge_v - k * (n.dot(edge_v) / n_dot_k);
            let q = (exit.s_hat - k_r) * wavenumber;
            // The field radiated toward ŝ times the footprint's integral (n̂·ŝ is in
            // `po_radiated`); on a curved surface whose bend over the footprint the tangent
            // plane would miss, summed over sub-tubes on the surface itself.
            let subdivisions = curvature_m.map_or((1, 1), |(radius_m, span)| {
                // Each footprint edge's extent across the bend (a cylinder is straight along
                // its axis), and the sag h = ℓ²/(8R) off the tangent plane over it, which
                // lengthens the path in along k by h/|n̂·k̂| and shortens the one out along ŝ
                // by (h/|n̂·k̂|)·(k̂·ŝ).
                let sag_phase_per_m2 =
                    wavenumber * (1.0 - k.dot(exit.s_hat)) / (8.0 * radius_m * n_dot_k.abs());
                let edge_subdivisions = |f: DVec3| {
                    let across_m = span.map_or(f, |s| f - s.axis * f.dot(s.axis)).length();
                    curved_subdivisions(sag_phase_per_m2 * across_m * across_m)
                };
                let (m_u, m_v) = (edge_subdivisions(f1), edge_subdivisions(f2));
                if edges_cut_apart {
                    (m_u, m_v)
                } else {
                    (m_u.max(m_v), m_u.max(m_v))
                }
            });
            let mut radiated = if subdivisions == (1, 1) {
                let footprint = sinc(0.5 * q.dot(f1)) * sinc(0.5 * q.dot(f2)) / n_dot_k.abs();
                e_field
                    .po_radiated(n, k, exit.s_hat)
                    .times(Complex64::new(footprint, 0.0))
            } else {
                let primitive = hit
                    .and_then(|h| bvh.hit_primitive(&h))
                    .expect("a curved hit has its primitive");
                radiated_over_sub_tubes(
                    primitive,
                    hit_p,
                    k,
                    e_field,
                    exit.s_hat,
                    (edge_u, edge_v),
                    subdivisions,
                    wavenumber,
                )
            };
            if exit.via_sea {
                let sea = sea.expect("an exit via the sea only when the sea is on");
                radiated = sea_reflect(radiated, exit.s_hat, &sea, s.wavelength_m).0;
            }
            // A retraced exit's receive direction is k0 itself: its launch vector, the same.
            let rx_pol = if vector_bits(exit.rx_dir) == vector_bits(k0) {
                pol_k0
            } else {
                polarisation_vector(exit.rx_dir, s.polarisation)
            };
            let pol = radiated.dot(rx_pol);
            let total_path = path_m + exit.range_rx_m;
            let amplitude = pol * (root_4pi_over_lambda * area_perp);
            if amplitude.norm_sqr() > 0.0 {
                out.push(TubeReturn {
                    root_rcs_m: carrier_phase(total_path, s.wavelength_m) * amplitude,
                    path_m: total_path,
                    tx_dir: k0,
                    rx_dir: exit.rx_dir,
                    range_tx_m,
                    range_rx_m: exit.range_rx_m,
                    bounces: object_hits as u8,
                    sea_reflections: sea_hits + u8::from(exit.via_sea),
                });
            }
        }
        if object_hits >= s.max_bounces {
            break;
        }
        // Continue along the reflected ray; mirror the tube edges and the field.
        edge_u -= n * (2.0 * n.dot(edge_u));
        edge_v -= n * (2.0 * n.dot(edge_v));
        e_field = e_r;
        k = k_r;
        origin = lift;
    }
    rays
}

#[cfg(test)]
mod tests {
    use super::*;

    const WAVENUMBER: f64 = std::f64::consts::TAU / 0.0319;

    /// A vertical cylinder wall of radius 2 m from z = 0 to 10 m, and a tube of side 0.1 m
    /// arriving along `k` (2.9° below the horizon) at the wall 1.2 rad round from the point
    /// facing it, at height `z_m`: the wall, the hit, `k` and the tube's edges, one
    /// horizontal and one in the vertical plane of `k`, whose footprint is along the axis.
    fn cylinder_tube(z_m: f64) -> (Primitive, DVec3, DVec3, (DVec3, DVec3)) {
        let wall = Primitive {
            kind: PrimitiveKind::Cylinder {
                base: DVec3::ZERO,
                axis: DVec3::Z,
                radius_m: 2.0,
                height_m: 10.0,
            },
            object: 0,
        };
        let phi = 1.2f64;
        let hit_p = DVec3::new(2.0 * phi.cos(), 2.0 * phi.sin(), z_m);
        let k = DVec3::new(-1.0, 0.0, -0.05).normalize();
        let edge_u = k.cross(DVec3::Z).normalize() * 0.1;
        let edge_v = edge_u.cross(k).normalize() * 0.1;
        (wall, hit_p, k, (edge_u, edge_v))
    }

    fn radiated(z_m: f64, cuts: (usize, usize)) -> ComplexVec3 {
        let (wall, hit_p, k, edges) = cylinder_tube(z_m);
        let e_field = ComplexVec3::real(polarisation_vector(k, Polarisation::Hh));
        radiated_over_sub_tubes(&wall, hit_p, k, e_field, -k, edges, cuts, WAVENUMBER)
    }

    fn distance(a: ComplexVec3, b: ComplexVec3) -> f64 {
        ((a.re - b.re).length_squared() + (a.im - b.im).length_squared()).sqrt()
    }

    fn norm(a: ComplexVec3) -> f64 {
        (a.re.length_squared() + a.im.length_squared()).sqrt()
    }

    /// Along a cylinder's axis its wall is flat, so cutting a footprint there changes
    /// nothing: the m sub-footprints' integrals of a linear phase sum to the whole one's
    /// (Σ_b e^{−jθ(b−(m−1)/2)}·sinc(θ/2)/m = sinc(mθ/2)), so one cut along the axis gives
    /// the m × m sum to rounding. Near the wall's end the cuts along the axis matter, and
    /// the wall's span then does not hold the tube.
    #[test]
    fn a_cylinders_straight_span_needs_no_cuts_along_its_axis() {
        for m in [2, 7, 16] {
            let full = radiated(5.0, (m, m));
            let across_only = radiated(5.0, (m, 1));
            assert!(norm(full) > 1e-3, "m = {m}: the tube radiates");
            let error = distance(full, across_only) / norm(full);
            assert!(error < 1e-9, "m = {m}: relative difference {error:e}");
        }
        // The cuts across the bend do matter there.
        let uncut = radiated(5.0, (1, 1));
        let cut = radiated(5.0, (16, 1));
        assert!(distance(cut, uncut) / norm(cut) > 0.01);
        let (wall, hit_p, k, edges) = cylinder_tube(5.0);
        let n = (hit_p - DVec3::new(0.0, 0.0, hit_p.z)).normalize();
        let footprint_v = edges.1 - k * (n.dot(edges.1) / n.dot(k));
        assert!(
            footprint_v.cross(DVec3::Z).length() < 1e-12,
            "the second edge's footprint is axial"
        );
        let (span, radius_m) = span_of(&wall);
        assert!(span.holds_tube(hit_p, edges, k, radius_m));
        // 3 cm below the top the tube (0.1 m along the axis) crosses the end.
        let near_top = DVec3::new(hit_p.x, hit_p.y, 9.97);
        assert!(!span.holds_tube(near_top, edges, k, radius_m));
        let (full, across_only) = (radiated(9.97, (16, 16)), radiated(9.97, (16, 1)));
        assert!(distance(full, across_only) / norm(full) > 0.1);
        // Along the axis itself no span holds a tube (k̂⊥ = 0).
        assert!(!span.holds_tube(hit_p, edges, DVec3::NEG_Z, radius_m));
    }

    fn span_of(wall: &Primitive) -> (AxialSpan, f64) {
        let PrimitiveKind::Cylinder {
            base,
            axis,
            radius_m,
            height_m,
        } = wall.kind
        else {
            unreachable!()
        };
        let span = AxialSpan {
            base,
            axis,
            height_m,
        };
        (span, radius_m)
    }

    /// Where a span holds a tube, every ray of a 17 × 17 grid over its cross-section
    /// (corners included) meets the wall, extended without end, only within the span:
    /// random walls (R 2 cm–2 m), tubes (sides 5 mm–0.2 m, turned at random), directions
    /// (elevation ±60°) and hits, grazing ones included, and a tube 0.3° from grazing 1 cm
    /// under a thin wall's top, whose footprint on the tangent plane has almost no extent
    /// along the axis though its rays reach past the top.
    #[test]
    fn a_span_holds_a_tube_only_where_all_its_rays_land_on_it() {
        let mut draws = 0u64;
        let mut uniform = move || {
            draws += 1;
            crate::rng::unit_f64(crate::rng::splitmix64(draws))
        };
        // The wall from z = 0 to height_m, and the same wall without end.
        let meets_only_within = |radius_m: f64, height_m: f64, hit_p, edges, k| {
            let (edge_u, edge_v): (DVec3, DVec3) = edges;
            let endless = Primitive {
                kind: PrimitiveKind::Cylinder {
                    base: DVec3::new(0.0, 0.0, -1e3),
                    axis: DVec3::Z,
                    radius_m,
                    height_m: 2e3,
                },
                object: 0,
            };
            let back_m = 10.0 * (radius_m + edge_u.length() + edge_v.length());
            (0..=16).all(|a| {
                (0..=16).all(|b| {
                    let offset =
                        edge_u * (a as f64 / 16.0 - 0.5) + edge_v * (b as f64 / 16.0 - 0.5);
                    let mut origin = hit_p + offset - k * back_m;
                    // Both of the ray's crossings of the wall, near and far.
                    let mut inside = true;
                    while let Some((t, _)) = endless.intersect(
                        &Ray {
                            origin_m: origin,
                            dir: k,
                        },
                        1e9,
                    ) {
                        let z = origin.z + t * k.z;
                        inside &= (-1e-9..=height_m + 1e-9).contains(&z);
                        origin += k * t;
                    }
                    inside
                })
            })
        };
        let mut held = 0;
        let cases = 4000;
        for case in 0..cases {
            let radius_m = 0.02 * 100f64.powf(uniform());
            let height_m = radius_m * (0.5 + 20.0 * uniform());
            let side_m = 0.005 * 40f64.powf(uniform());
            let elevation = (uniform() - 0.5) * 2.0 * 60f64.to_radians();
            let k = -DVec3::new(elevation.cos(), 0.0, elevation.sin());
            // Lit side of the wall, from facing the ray to grazing it.
            let phi = (uniform() - 0.5) * std::f64::consts::PI * 0.9999;
            let hit_p = DVec3::new(
                radius_m * phi.cos(),
                radius_m * phi.sin(),
                height_m * uniform(),
            );
            let turn = uniform() * std::f64::consts::TAU;
            let u0 = k.cross(DVec3::Z).normalize();
            let v0 = u0.cross(k);
            let edge_u = (u0 * turn.cos() + v0 * turn.sin()) * side_m;
            let edge_v = (v0 * turn.cos() - u0 * turn.sin()) * side_m;
            let span = AxialSpan {
                base: DVec3::ZERO,
                axis: DVec3::Z,
                height_m,
            };
            if span.holds_tube(hit_p, (edge_u, edge_v), k, radius_m) {
                held += 1;
                assert!(
                    meets_only_within(radius_m, height_m, hit_p, (edge_u, edge_v), k),
                    "case {case}: R {radius_m} m, H {height_m} m, side {side_m} m, el {elevation}, phi {phi}, z {}",
                    hit_p.z
                );
            }
        }
        assert!(held > cases / 5, "the span holds {held} of {cases} tubes");
        // The thin wall's grazing tube near its top: some of its rays pass the top.
        let (radius_m, height_m) = (0.05, 2.0);
        let k = DVec3::new(-(1.0 - 0.0029f64 * 0.0029).sqrt(), 0.0, 0.0029);
        let phi = (0.005 / k.x.abs()).acos();
        let hit_p = DVec3::new(
            radius_m * phi.cos(),
            radius_m * phi.sin(),
            height_m - 0.0096,
        );
        let u0 = k.cross(DVec3::Z).normalize();
        let v0 = u0.cross(k);
        let turn = 60f64.to_radians();
        let edges = (
            (u0 * turn.cos() + v0 * turn.sin()) * 0.016,
            (v0 * turn.cos() - u0 * turn.sin()) * 0.016,
        );
        assert!(!meets_only_within(radius_m, height_m, hit_p, edges, k));
        let span = AxialSpan {
            base: DVec3::ZERO,
            axis: DVec3::Z,
            height_m,
        };
        assert!(!span.holds_tube(hit_p, edges, k, radius_m));
    }
}
