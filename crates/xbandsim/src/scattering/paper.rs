//! The seed paper's scattering law (paper §III.E, eq. 4), kept as the named model `paper`.
//!
//! Rays leave the radar on a uniform grid: `rays_per_degree_az × 360` azimuths by
//! `rays_elevation` elevations across the elevation beamwidth (the paper's 360 beams × 100 × 100
//! = 3.6 M rays). Each ray's first hit at one-way distance ℓ gives a contribution of amplitude
//! `V_ref · A(ℓ)`, `A = 1/(1 + ℓ²/1000)`, delay `2ℓ/c` and carrier phase `exp(−j4πℓ/λ)`.
//! It is not calibrated: `V_ref` (`paper_reference_voltage_uv`) sets the level against noise.

use super::{azimuth_elevation_rad, carrier_phase, direction_from_az_el, Contribution, ScatterSet};
use crate::antenna::Antenna;
use crate::geometry::{Bvh, Ray};
use crate::model::{ScatteringConfig, Scene};
use num_complex::Complex64;
use rayon::prelude::*;

/// The paper's amplitude law `A = 1/(1 + ℓ²/1000)`, ℓ one-way path in metres.
#[inline]
pub fn paper_amplitude(one_way_path_m: f64) -> f64 {
    1.0 / (1.0 + one_way_path_m * one_way_path_m / 1000.0)
}

/// Directions of the paper's uniform scan grid, azimuth-major: (az, el) for `index`.
pub fn grid_direction(settings: &ScatteringConfig, ant: &Antenna, index: usize) -> (f64, f64) {
    let n_el = settings.paper_rays_elevation();
    let n_az = settings.paper_rays_per_degree_az() * 360;
    let (ia, ie) = (index / n_el, index % n_el);
    let az = std::f64::consts::TAU * (ia as f64 + 0.5) / n_az as f64;
    let el = ant.tilt_rad - ant.el_beamwidth_rad / 2.0
        + ant.el_beamwidth_rad * (ie as f64 + 0.5) / n_el as f64;
    (az, el)
}

/// Number of rays in the paper's grid.
pub fn grid_size(settings: &ScatteringConfig) -> usize {
    settings.paper_rays_per_degree_az() * 360 * settings.paper_rays_elevation()
}

/// Traces the uniform grid and applies the paper's amplitude law.
pub fn trace(scene: &Scene, bvh: &Bvh) -> ScatterSet {
    let radar = scene.radar();
    let lambda = radar.wavelength_m();
    let v_ref = scene.scattering().paper_reference_voltage_v();
    let n_el = scene.scattering().paper_rays_elevation();
    let n_az = scene.scattering().paper_rays_per_degree_az() * 360;
    let origin = radar.position_m();
    // Azimuth culling: a column of rays can only hit an object whose bounding sphere it
    // passes, so only the columns inside some object's azimuth span are cast (the others
    // would all miss; `xbandsim bench` measures raw casting separately).
    let mut live = vec![false; n_az];
    let column_rad = std::f64::consts::TAU / n_az as f64;
    for o in scene.objects() {
        let rel = o.bounding_centre_m() - origin;
        let ground = rel.truncate().length();
        let r = o.shape().bounding_radius_m();
        if ground <= r {
            live.iter_mut().for_each(|l| *l = true);
            break;
        }
        let (az_c, _) = azimuth_elevation_rad(rel);
        let half = (r / ground).asin() + column_rad;
        let (lo, hi) = (
            ((az_c - half) / column_rad).floor() as i64,
            ((az_c + half) / column_rad).ceil() as i64,
        );
        for i in lo..=hi {
            live[i.rem_euclid(n_az as i64) as usize] = true;
        }
    }
    let columns: Vec<usize> = (0..n_az).filter(|&i| live[i]).collect();
    // Each live column's rays traced as packets ([`Bvh::closest_hits`]); the columns in runs
    // per task, each run's contributions in one vector, collected in order.
    let runs: Vec<Vec<Contribution>> = columns
        .par_iter()
        .with_min_len(4)
        .fold(
            || {
                (
                    Vec::new(),
                    vec![f64::INFINITY; n_el],
                    vec![None; n_el],
                    Vec::new(),
                )
            },
            |(mut rays, t_max, mut hits, mut out), &ia| {
                rays.clear();
                rays.extend((0..n_el).map(|ie| {
                    let (az, el) =
                        grid_direction(scene.scattering(), radar.antenna(), ia * n_el + ie);
                    Ray {
                        origin_m: origin,
                        dir: direction_from_az_el(az, el),
                    }
                }));
                bvh.closest_hits(&rays, &t_max, &mut hits);
                for (ie, hit) in hits.iter().enumerate() {
                    let Some(hit) = hit else { continue };
                    // The ray's own grid angles, not read back from its direction (which only
                    // adds rounding; where a grid azimuth falls on an echo group's cell edge, a
                    // last bit decides the group).
                    let (az_h, el_h) =
                        grid_direction(scene.scattering(), radar.antenna(), ia * n_el + ie);
                    let path_m = 2.0 * hit.t_m;
                    out.push(Contribution {
                        amplitude_v: carrier_phase(path_m, lambda)
                            * (v_ref * paper_amplitude(hit.t_m)),
                        root_rcs_m: Complex64::new(0.0, 0.0),
                        path_m,
                        az_tx_rad: az_h,
                        el_tx_rad: el_h,
                        az_rx_rad: az_h,
                        el_rx_rad: el_h,
                        object: hit.object,
                        bounces: 1,
                        sea_reflections: 0,
                    });
                }
                (rays, t_max, hits, out)
            },
        )
        .map(|(_, _, _, out)| out)
        .collect();
    let mut contributions: Vec<Contribution> = runs.concat();
    contributions.shrink_to_fit();
    ScatterSet {
        contributions,
        rays_cast: (columns.len() * n_el) as u64,
        tube_budgets: Vec::new(),
        land_shadowed: Vec::new(),
        kept: Vec::new(),
    }
}
