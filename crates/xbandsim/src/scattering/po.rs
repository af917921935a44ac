//! Shooting-and-bouncing rays with physical-optics ray tubes (the default model).
//!
//! For each object that is not a point, square ray tubes of side δ (`ray_spacing_wavelengths`·λ,
//! grown if the object would need more than `max_rays_per_object`) are launched from the radar
//! phase centre toward a grid over the disk that covers the object's bounding sphere, seen
//! from the radar. A tube whose first hit is on another object is shadowed and dropped (that
//! object has tubes of its own). At every hit the tube's PO integral toward the radar gives
//! (PHYSICS-NOTES §2; Ling, Chou & Lee 1989; Knott, Shaeffer & Tuley, *Radar Cross Section*,
//! 2nd ed., ch. 5):
//!
//! `S = (√(4π)/λ) · A⊥ · P · F · exp(−j2πℓ/λ)`
//!
//! - `A⊥` the tube's cross-section (δ² scaled by (t/R)² for the spherical spread to the object),
//! - `P = E_r · p̂_rx`, with the field reflected at each perfect-conductor hit as
//!   `E_r = 2(n̂·E_i)n̂ − E_i` starting from the transmit polarisation `p̂_tx`,
//! - `F = (n̂·ŝ)/|n̂·k̂_i| · sinc(q·e₁/2)·sinc(q·e₂/2)`, `q = k(ŝ − k̂_r)`, the exact PO integral
//!   over the tube's parallelogram footprint `e₁, e₂` on its facet (sinc x = sin x / x),
//! - `ℓ` the whole path radar → hits → radar (f64).
//!
//! The exit path back to the radar must be clear (shadow ray) for bounces after the first.
//! Ideal `point` objects give one contribution `S = √σ·exp(−j2πℓ/λ)` if in line of sight.

use super::{
    azimuth_elevation_rad, carrier_phase, radar_equation_volts_per_root_m2, Contribution,
    ScatterSet,
};
use crate::geometry::{Bvh, Ray, ShapeGeometry};
use crate::scene::{Polarisation, Scene};
use glam::DVec3;
use num_complex::Complex64;
use rayon::prelude::*;

/// Offset from a surface when launching the next segment, m.
const SURFACE_OFFSET_M: f64 = 1e-6;

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
        x.sin() / x
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

/// A grid of square ray tubes covering one object's bounding sphere as seen by the radar.
#[derive(Debug, Clone, Copy)]
pub struct TubeGrid {
    /// Illumination.
    pub illumination: Illumination,
    /// Centre of the object's bounding sphere, m.
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
    /// Plane-wave mode: the launch/reference plane's point on the axis, m.
    plane_origin_m: DVec3,
}

impl TubeGrid {
    /// Grid over the bounding sphere (`centre_m`, `radius_m`) for `illumination`.
    pub fn new(
        illumination: Illumination,
        centre_m: DVec3,
        radius_m: f64,
        spacing_m: f64,
        max_rays: usize,
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
        let mut cells = ((2.0 * radius_m / spacing_m).ceil() as usize).max(1);
        // Only cells inside the disk are traced: about π/4 of the square.
        let max_side = ((max_rays as f64 * 4.0 / std::f64::consts::PI)
            .sqrt()
            .floor() as usize)
            .max(1);
        if cells > max_side {
            cells = max_side;
        }
        TubeGrid {
            illumination,
            centre_m,
            axis_u,
            axis_v,
            spacing_m: 2.0 * radius_m / cells as f64,
            cells_per_side: cells,
            radius_m,
            plane_origin_m: centre_m + toward * (radius_m + 1.0),
        }
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

    /// Launch of tube (i, j): origin, unit direction, the tube's unit transverse axes, and the
    /// distance at which its side equals `spacing_m` (None for parallel tubes).
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
    /// Maximum bounces.
    pub max_bounces: usize,
    /// Tube spacing, m.
    pub spacing_m: f64,
    /// Cap on rays per object.
    pub max_rays: usize,
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
    /// Unit direction from the receiver to the last hit.
    pub rx_dir: DVec3,
    /// Launch to first hit, m.
    pub range_tx_m: f64,
    /// Last hit back to the receiver, m.
    pub range_rx_m: f64,
    /// Bounces.
    pub bounces: u8,
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
    let Some((launch, k0, eu0, ev0, spread_ref_m)) = grid.launch(i, j) else {
        return 0;
    };
    let wavenumber = std::f64::consts::TAU / s.wavelength_m;
    let root_4pi_over_lambda = (4.0 * std::f64::consts::PI).sqrt() / s.wavelength_m;
    let mut e_field = polarisation_vector(k0, s.polarisation);
    let mut origin = launch;
    let mut k = k0;
    let mut path_m = 0.0;
    let mut range_tx_m = 0.0;
    let mut edge_u = DVec3::ZERO;
    let mut edge_v = DVec3::ZERO;
    let mut rays = 0u64;
    for bounce in 1..=s.max_bounces {
        rays += 1;
        let Some(hit) = bvh.closest_hit(
            &Ray {
                origin_m: origin,
                dir: k,
            },
            f64::INFINITY,
        ) else {
            break;
        };
        if bounce == 1 {
            if hit.object != target {
                break; // shadowed by another object, which traces its own tubes
            }
            range_tx_m = hit.t_m;
            let side = spread_ref_m.map_or(s.spacing_m, |r| s.spacing_m * hit.t_m / r);
            edge_u = eu0 * side;
            edge_v = ev0 * side;
        }
        let hit_p = origin + k * hit.t_m;
        path_m += hit.t_m;
        let n = if hit.normal.dot(k) < 0.0 {
            hit.normal
        } else {
            -hit.normal
        };
        let n_dot_k = n.dot(k); // < 0
        let k_r = k - n * (2.0 * n_dot_k);
        let e_r = n * (2.0 * n.dot(e_field)) - e_field;
        let (s_hat, range_rx_m) = grid.return_path(hit_p);
        let n_dot_s = n.dot(s_hat);
        if n_dot_s > 0.0 && n_dot_k.abs() > 1e-9 {
            let visible = bounce == 1 || {
                rays += 1;
                !bvh.any_hit(
                    &Ray {
                        origin_m: hit_p + n * SURFACE_OFFSET_M,
                        dir: s_hat,
                    },
                    range_rx_m - SURFACE_OFFSET_M,
                )
            };
            if visible {
                // Footprint edges: the tube's edges projected along k onto the facet.
                let f1 = edge_u - k * (n.dot(edge_u) / n_dot_k);
                let f2 = edge_v - k * (n.dot(edge_v) / n_dot_k);
                let q = (s_hat - k_r) * wavenumber;
                let footprint =
                    n_dot_s / n_dot_k.abs() * sinc(0.5 * q.dot(f1)) * sinc(0.5 * q.dot(f2));
                let area_perp = edge_u.cross(edge_v).length();
                let pol = e_r.dot(polarisation_vector(-s_hat, s.polarisation));
                let total_path = path_m + range_rx_m;
                let mag = root_4pi_over_lambda * area_perp * footprint * pol;
                if mag != 0.0 {
                    out.push(TubeReturn {
                        root_rcs_m: carrier_phase(total_path, s.wavelength_m) * mag,
                        path_m: total_path,
                        tx_dir: k0,
                        rx_dir: -s_hat,
                        range_tx_m,
                        range_rx_m,
                        bounces: bounce as u8,
                    });
                }
            }
        }
        // Continue along the reflected ray; mirror the tube edges and the field.
        edge_u -= n * (2.0 * n.dot(edge_u));
        edge_v -= n * (2.0 * n.dot(edge_v));
        e_field = e_r;
        k = k_r;
        origin = hit_p + n * SURFACE_OFFSET_M;
    }
    rays
}

/// All returns of one object lit by `illumination` (rows traced in parallel, collected in
/// order so the result does not depend on the thread count).
pub fn trace_object(
    bvh: &Bvh,
    illumination: Illumination,
    centre_m: DVec3,
    radius_m: f64,
    index: u32,
    s: &SbrSettings,
) -> (Vec<TubeReturn>, u64) {
    let grid = TubeGrid::new(illumination, centre_m, radius_m, s.spacing_m, s.max_rays);
    let rows: Vec<(Vec<TubeReturn>, u64)> = (0..grid.cells_per_side)
        .into_par_iter()
        .map(|j| {
            let mut out = Vec::new();
            let mut rays = 0;
            for i in 0..grid.cells_per_side {
                rays += trace_tube(bvh, &grid, i, j, index, s, &mut out);
            }
            (out, rays)
        })
        .collect();
    let rays = rows.iter().map(|r| r.1).sum();
    let returns = rows.into_iter().flat_map(|r| r.0).collect();
    (returns, rays)
}

/// Monostatic RCS of everything in `bvh` tagged `index`, lit by a plane wave from
/// `toward_radar` (unit, object → radar): `σ = |Σ S|²`, m².
pub fn plane_wave_rcs_m2(
    bvh: &Bvh,
    toward_radar: DVec3,
    centre_m: DVec3,
    radius_m: f64,
    index: u32,
    s: &SbrSettings,
) -> f64 {
    let (returns, _) = trace_object(
        bvh,
        Illumination::PlaneWave { toward_radar },
        centre_m,
        radius_m,
        index,
        s,
    );
    returns
        .iter()
        .map(|r| r.root_rcs_m)
        .sum::<Complex64>()
        .norm_sqr()
}

/// SBR settings of a scene.
pub fn settings_for(scene: &Scene) -> SbrSettings {
    let lambda = scene.radar.wavelength_m();
    SbrSettings {
        wavelength_m: lambda,
        polarisation: scene.radar.polarisation,
        max_bounces: scene.scattering.max_bounces,
        spacing_m: scene.scattering.ray_spacing_wavelengths * lambda,
        max_rays: scene.scattering.max_rays_per_object,
    }
}

/// Traces every object of the scene with SBR/PO and converts to volts.
pub fn trace(scene: &Scene, bvh: &Bvh) -> ScatterSet {
    let radar = &scene.radar;
    let s = settings_for(scene);
    let mut set = ScatterSet::default();
    for (idx, obj) in scene.objects.iter().enumerate() {
        let index = idx as u32;
        if let ShapeGeometry::Point { rcs_m2 } = obj.shape {
            let to_obj = obj.position_m - radar.position_m;
            let range_m = to_obj.length();
            let dir = to_obj / range_m;
            set.rays_cast += 1;
            if bvh.any_hit(
                &Ray {
                    origin_m: radar.position_m,
                    dir,
                },
                range_m,
            ) {
                continue;
            }
            let path_m = 2.0 * range_m;
            let root = carrier_phase(path_m, s.wavelength_m) * rcs_m2.sqrt();
            let (az, el) = azimuth_elevation_rad(dir);
            set.contributions.push(Contribution {
                amplitude_v: root * radar_equation_volts_per_root_m2(radar, range_m, range_m),
                root_rcs_m: root,
                path_m,
                az_tx_rad: az,
                el_tx_rad: el,
                az_rx_rad: az,
                el_rx_rad: el,
                object: index,
                bounces: 0,
            });
            continue;
        }
        let illumination = Illumination::FromPoint {
            radar_m: radar.position_m,
        };
        let (returns, rays) = trace_object(
            bvh,
            illumination,
            obj.bounding_centre_m(),
            obj.shape.bounding_radius_m(),
            index,
            &s,
        );
        set.rays_cast += rays;
        set.contributions.extend(returns.iter().map(|r| {
            let (az_tx, el_tx) = azimuth_elevation_rad(r.tx_dir);
            let (az_rx, el_rx) = azimuth_elevation_rad(r.rx_dir);
            Contribution {
                amplitude_v: r.root_rcs_m
                    * radar_equation_volts_per_root_m2(radar, r.range_tx_m, r.range_rx_m),
                root_rcs_m: r.root_rcs_m,
                path_m: r.path_m,
                az_tx_rad: az_tx,
                el_tx_rad: el_tx,
                az_rx_rad: az_rx,
                el_rx_rad: el_rx,
                object: index,
                bounces: r.bounces,
            }
        }));
    }
    set
}
