//! Stage: scattering — the paths an echo takes via the own ship (docs/physics.md §14), added
//! to a traced state's contributions before they are grouped into echoes.
//!
//! **Indirect echoes.** With the beam on a mast or funnel (an `[[own_ship.structure]]` with
//! `indirect_db` and `distance_m`), the structure scatters a power fraction ρ of the beam
//! toward every other bearing and back: every object's echo also arrives along the
//! structure's bearing θs, over the path antenna → structure → object → structure → antenna. Each contribution of length
//! ℓ at apparent range r = ℓ/2 gets a copy with transmit and receive azimuth θs (its
//! elevations kept: the structure and the echoes that matter both lie near the horizon), path
//! `ℓ' = ℓ + 2·(d + |P − S| − r)` (d the structure's distance, S its position, P the
//! contribution's point at range r along its receive direction) and amplitude
//! `a·ρ·exp(−j2π(ℓ'−ℓ)/λ)` (and the atmosphere's attenuation over `ℓ' − ℓ`, as for every path
//! here), ρ in power on each of the two passes. These contributions are marked
//! ([`INDIRECT_OBJECT_FLAG`]): the receive chain adds them past the blind sectors' loss, since
//! they come from the structure, not through it.
//! (JRC JMA-3300 series manual, §3.4 "False echoes": the secondary reflection from a funnel
//! shows on the funnel's bearing at about the target's range.)
//!
//! **Multiple echoes.** A ship abeam with its side parallel to the own ship's side
//! (`MultipleEchoes::applies`) sends part of its echo back from the own ship's side, which it
//! returns again: the `n`-th echo travels `n·ℓ` on the same bearing. Both sides are flat
//! plates far inside each other's far-field distance `2D²/λ` (14 km for a 15 m-high side at
//! 3.2 cm), so they act as mirrors and the image method gives the
//! spreading of a path `n` times as long, `1/n²` in power, with each extra round trip losing
//! the two reflections' `L_rt` dB: amplitude `a·10^{−(n−1)·L_rt/20}/n·exp(−j2π(n−1)ℓ/λ)`
//! (JRC JMA-3300 series manual, §3.4.4 "False echo by multiple reflection": echoes at equal
//! intervals on the target's bearing, the nearest the true one).

use super::Contribution;
use crate::model::artefacts::{Artefacts, MultipleEchoes};
use crate::model::Scene;
use num_complex::Complex64;

/// Marks an indirect echo's contributions (their `object` is the traced object's index with
/// this bit set): the receive chain adds them past the blind sectors' loss, since they come
/// from the structure rather than through it, and the target-only render leaves them out.
pub const INDIRECT_OBJECT_FLAG: u32 = 1 << 23;

/// Marks a multiple echo's contributions, as [`INDIRECT_OBJECT_FLAG`] (the target-only render
/// leaves them out; they take the blind sectors' loss like any echo on their bearing).
pub const MULTIPLE_OBJECT_FLAG: u32 = 1 << 22;

/// The traced object a contribution's `object` comes from (its flags taken off).
pub fn traced_object(object: u32) -> u32 {
    object & !(INDIRECT_OBJECT_FLAG | MULTIPLE_OBJECT_FLAG)
}

/// Whether `object` marks an echo made by a path via the own ship.
pub fn is_own_ship_path(object: u32) -> bool {
    object & (INDIRECT_OBJECT_FLAG | MULTIPLE_OBJECT_FLAG) != 0
}

/// What the paths via the own ship need of the revolution.
#[derive(Debug, Clone, Copy)]
pub struct OwnShipView<'a> {
    /// The own ship's heading, rad (0 without `[own_ship]`).
    pub heading_rad: f64,
    /// The scene's artefacts (its blind sectors and multiple echoes).
    pub artefacts: &'a Artefacts,
    /// For each object, whether its echo bounces between the two sides
    /// ([`abeam_objects`]).
    pub abeam: &'a [bool],
    /// The radar's wavelength, m.
    pub wavelength_m: f64,
    /// The atmosphere's two-way attenuation, dB/km, also taken over each path's extra length.
    pub two_way_attenuation_db_per_km: f64,
}

/// For each object of `scene` (a revolution's still scene), whether `multiple` applies to it
/// seen from the antenna with the own ship heading `heading_rad`: abeam, parallel and long
/// enough (objects whose bow points straight up or down have no side, and none do).
pub fn abeam_objects(scene: &Scene, heading_rad: f64, multiple: &MultipleEchoes) -> Vec<bool> {
    let antenna = scene.radar().position_m();
    scene
        .objects()
        .iter()
        .map(|o| {
            let Some(heading) = crate::model::motion::heading_of(o.rotation()) else {
                return false;
            };
            let d = o.position_m() - antenna;
            let bounds = o.local_bounds();
            let length_m = if bounds.min.is_finite() && bounds.max.is_finite() {
                bounds.max.y - bounds.min.y
            } else {
                0.0
            };
            multiple.applies(heading_rad, d.x.atan2(d.y), heading, length_m)
        })
        .collect()
}

/// The contributions the paths via the own ship add to `contributions` (none when the scene
/// has neither indirect nor multiple echoes).
pub fn paths_via_own_ship(contributions: &[Contribution], view: &OwnShipView) -> Vec<Contribution> {
    let mut out = Vec::new();
    let tau = std::f64::consts::TAU;
    // The carrier phase and the atmosphere's attenuation over a path's extra length.
    let phase = |extra_path_m: f64| {
        let cycles = extra_path_m / view.wavelength_m;
        let attenuation =
            10f64.powf(-view.two_way_attenuation_db_per_km * extra_path_m / 2000.0 / 20.0);
        Complex64::from_polar(attenuation, -tau * (cycles - cycles.floor()))
    };
    for sector in &view.artefacts.blind_sectors {
        let Some(indirect) = sector.indirect else {
            continue;
        };
        let theta = (view.heading_rad + sector.centre_rad()).rem_euclid(tau);
        let (sin_s, cos_s) = theta.sin_cos();
        let structure = glam::DVec2::new(sin_s, cos_s) * indirect.distance_m;
        let scale = 10f64.powf(indirect.power_db / 10.0);
        for c in contributions {
            let r = 0.5 * c.path_m;
            let (sin_el, cos_el) = c.el_rx_rad.sin_cos();
            let (sin_az, cos_az) = c.az_rx_rad.sin_cos();
            let horizontal = glam::DVec2::new(sin_az, cos_az) * (r * cos_el) - structure;
            let from_structure_m = horizontal.length().hypot(r * sin_el);
            let extra_m = 2.0 * (indirect.distance_m + from_structure_m - r);
            out.push(Contribution {
                amplitude_v: c.amplitude_v * phase(extra_m) * scale,
                path_m: c.path_m + extra_m,
                az_tx_rad: theta,
                az_rx_rad: theta,
                object: c.object | INDIRECT_OBJECT_FLAG,
                ..*c
            });
        }
    }
    if let Some(multiple) = &view.artefacts.multiple_echoes {
        for c in contributions {
            if !view.abeam.get(c.object as usize).copied().unwrap_or(false) {
                continue;
            }
            for n in 2..=multiple.max_order {
                let extra_m = (n - 1) as f64 * c.path_m;
                let scale = 10f64.powf(multiple.relative_level_db(n) / 20.0);
                out.push(Contribution {
                    amplitude_v: c.amplitude_v * phase(extra_m) * scale,
                    path_m: c.path_m + extra_m,
                    object: c.object | MULTIPLE_OBJECT_FLAG,
                    ..*c
                });
            }
        }
    }
    out
}

/// A staggered train's second-trace echoes (docs/physics.md §14): the echo of a contribution
/// whose delay falls at or beyond the record (`record_s`) arrives after the next pulse, one
/// interval `T_k` later than it left, and the interval before a pulse cycles through the
/// train's `intervals_s`: over the cycle the echo shows at each `τ − T_k` on one pulse in
/// `L`. Each is drawn on every pulse with `1/L` of its power (the cycle's mean, what
/// non-coherent integration over whole cycles keeps); equal intervals are one fold with their
/// share. Returns `contributions` with each such contribution replaced by its folds (a fold
/// that still lands beyond the record is dropped when the echoes are grouped).
pub fn fold_staggered(
    contributions: &[Contribution],
    record_s: f64,
    intervals_s: &[f64],
) -> Vec<Contribution> {
    let c0 = crate::constants::SPEED_OF_LIGHT_M_PER_S;
    let folds = stagger_folds(intervals_s);
    let mut out = Vec::with_capacity(contributions.len());
    for c in contributions {
        if c.delay_s() < record_s {
            out.push(*c);
            continue;
        }
        for &(t, share) in &folds {
            out.push(Contribution {
                amplitude_v: c.amplitude_v * share.sqrt(),
                path_m: c.path_m - c0 * t,
                ..*c
            });
        }
    }
    out
}

/// The folds of a pulse train with the intervals `intervals_s` (one cycle): each distinct
/// interval, s, with the share of the pulses it precedes (equal intervals are one fold).
pub fn stagger_folds(intervals_s: &[f64]) -> Vec<(f64, f64)> {
    let mut folds: Vec<(f64, f64)> = Vec::new();
    let share = 1.0 / intervals_s.len() as f64;
    for &t in intervals_s {
        match folds.iter_mut().find(|(u, _)| *u == t) {
            Some(f) => f.1 += share,
            None => folds.push((t, share)),
        }
    }
    folds
}

#[cfg(test)]
mod tests {
    use super::*;

    fn contribution(path_m: f64, az_rad: f64) -> Contribution {
        Contribution {
            amplitude_v: Complex64::new(1.0, 0.0),
            root_rcs_m: Complex64::new(1.0, 0.0),
            path_m,
            az_tx_rad: az_rad,
            el_tx_rad: 0.0,
            az_rx_rad: az_rad,
            el_rx_rad: 0.0,
            object: 0,
            bounces: 1,
            sea_reflections: 0,
        }
    }

    #[test]
    fn multiple_echoes_fall_as_the_image_method_says() {
        let m = MultipleEchoes {
            round_trip_loss_db: 6.0,
            max_order: 3,
            abeam_tolerance_rad: 0.1,
            min_length_m: 30.0,
        };
        let artefacts = Artefacts {
            multiple_echoes: Some(m.clone()),
            ..Default::default()
        };
        let view = OwnShipView {
            heading_rad: 0.0,
            artefacts: &artefacts,
            abeam: &[true],
            wavelength_m: 0.032,
            two_way_attenuation_db_per_km: 0.0,
        };
        let out = paths_via_own_ship(&[contribution(400.0, 1.5)], &view);
        assert_eq!(out.len(), 2);
        for (k, c) in out.iter().enumerate() {
            let n = (k + 2) as f64;
            assert!((c.path_m - 400.0 * n).abs() < 1e-9);
            let want_db = -20.0 * n.log10() - (n - 1.0) * 6.0;
            assert!((20.0 * c.amplitude_v.norm().log10() - want_db).abs() < 1e-9);
            assert_eq!(c.az_rx_rad, 1.5);
        }
        // Not abeam: none.
        let view = OwnShipView {
            abeam: &[false],
            ..view
        };
        assert!(paths_via_own_ship(&[contribution(400.0, 1.5)], &view).is_empty());
    }

    #[test]
    fn abeam_means_both_sides_parallel_and_long_enough() {
        let m = MultipleEchoes {
            round_trip_loss_db: 6.0,
            max_order: 3,
            abeam_tolerance_rad: 10f64.to_radians(),
            min_length_m: 30.0,
        };
        let deg = f64::to_radians;
        // Own ship heading north, target due east heading north: abeam and parallel.
        assert!(m.applies(0.0, deg(90.0), 0.0, 100.0));
        assert!(m.applies(0.0, deg(270.0), deg(180.0), 100.0));
        assert!(m.applies(0.0, deg(99.0), deg(5.0), 100.0));
        // Ahead, or end on, or short: no.
        assert!(!m.applies(0.0, deg(45.0), 0.0, 100.0));
        assert!(!m.applies(0.0, deg(90.0), deg(90.0), 100.0));
        assert!(!m.applies(0.0, deg(90.0), 0.0, 20.0));
    }

    #[test]
    fn staggered_folds_split_the_power_over_the_intervals() {
        let c0 = crate::constants::SPEED_OF_LIGHT_M_PER_S;
        let intervals = [1.0e-3, 1.1e-3, 0.9e-3];
        let far = contribution(c0 * 1.2e-3, 0.0);
        let near = contribution(c0 * 0.1e-3, 0.0);
        let out = fold_staggered(&[near, far], 0.5e-3, &intervals);
        assert_eq!(out.len(), 4);
        assert_eq!(out[0], near);
        for (c, t) in out[1..].iter().zip(intervals) {
            assert!((c.delay_s() - (1.2e-3 - t)).abs() < 1e-15);
            assert!((c.amplitude_v.norm_sqr() - 1.0 / 3.0).abs() < 1e-12);
        }
        // Equal intervals are one fold with their share: no coherent sum of copies.
        let out = fold_staggered(&[far], 0.5e-3, &[1.0e-3, 1.0e-3, 1.1e-3]);
        assert_eq!(out.len(), 2);
        assert!((out[0].amplitude_v.norm_sqr() - 2.0 / 3.0).abs() < 1e-12);
        assert!((out[1].amplitude_v.norm_sqr() - 1.0 / 3.0).abs() < 1e-12);
    }
}
