//! Clutter map, stages σ0 and rain along one spoke. Each sea patch's mean power is
//! `σ0(ψ, wind)·A·Pt·G0²·λ²·Gn_el(−ψ)²/((4π)³·R⁴·L·N)` (its radar-equation factor from the
//! cell geometry, σ0 from the NRL or GIT model at the spoke's angle to the wind), each rain
//! patch's `η·V` with the rain rate where the patch lies; both times the two-way rain loss
//! along the slant path to them (docs/physics.md, "Sea clutter", "Rain", §2.7). A deck that
//! rolls and pitches raises the spoke's beam: the elevation gain and the rain's elevation
//! integral are then taken on the tilted pattern.

use super::geometry::{CellGeometry, MapGeometry};
use crate::environment::clutter::{git_sigma0_db, Sigma0Model};
use crate::environment::rain::volume_reflectivity_m2_per_m3;
use crate::land::profile::{rise_m, seen_lower, Crossing, LandView};
use crate::model::{Environment, Radar};
use crate::propagation::rain_attenuation::RainAttenuator;
use glam::DVec2;

/// Two-way power loss `10^(−2·A/10)` of a one-way rain attenuation `A` (dB).
#[inline]
fn two_way_rain_loss(one_way_db: f64) -> f64 {
    (-2.0 * one_way_db / 10.0 * std::f64::consts::LN_10).exp()
}

/// What every spoke of a map shares for its σ0 and rain rows.
pub(super) struct SpokeStage<'a> {
    geometry: &'a MapGeometry,
    cells: &'a [Option<CellGeometry>],
    env: &'a Environment,
    radar: &'a Radar,
    attenuator: Option<RainAttenuator<'a>>,
    /// Two-way rain loss of each row along a spoke that crosses no rain cell (the uniform
    /// rain alone: the same for every such spoke), so once per map, not once per spoke.
    uniform_rain_loss: Vec<f64>,
    beam_tilt_rad: &'a [f64],
}

impl<'a> SpokeStage<'a> {
    /// The stage of a map with spoke k's beam raised by `beam_tilt_rad[k]`.
    pub(super) fn new(
        radar: &'a Radar,
        env: &'a Environment,
        geometry: &'a MapGeometry,
        cells: &'a [Option<CellGeometry>],
        beam_tilt_rad: &'a [f64],
    ) -> SpokeStage<'a> {
        let attenuator = env
            .rain()
            .as_ref()
            .map(|r| r.attenuator(geometry.freq_ghz, geometry.horizontal));
        let uniform_rain_loss: Vec<f64> = attenuator.as_ref().map_or_else(Vec::new, |a| {
            cells
                .iter()
                .map(|r| {
                    r.as_ref().map_or(1.0, |r| {
                        two_way_rain_loss(a.one_way_db_path_along(
                            &[],
                            r.ground_m,
                            r.slant_m,
                            geometry.h,
                            0.0,
                        ))
                    })
                })
                .collect()
        });
        SpokeStage {
            geometry,
            cells,
            env,
            radar,
            attenuator,
            uniform_rain_loss,
            beam_tilt_rad,
        }
    }

    /// The rain cells' chords along the line from `radar_xy` in direction `dir` (empty
    /// without rain): one-way dB as a function of ground range.
    fn rain_chords(&self, radar_xy: DVec2, dir: DVec2) -> Vec<(f64, f64, f64)> {
        self.attenuator
            .as_ref()
            .map(|a| a.chords(radar_xy, dir))
            .unwrap_or_default()
    }

    /// Spoke k's texture-free sea and rain power per patch (noise units, the rain row empty
    /// without rain) into `sea_row` and `rain_row`.
    pub(super) fn fill_rows(&self, k: usize, sea_row: &mut [f32], rain_row: &mut [f32]) {
        let g = self.geometry;
        let (h, lambda, delta, ant) = (g.h, g.lambda, g.delta, &g.ant);
        let clutter = self.env.clutter();
        let has_rain = self.env.rain().is_some();
        let radar_xy = self.radar.position_m().truncate();
        let az = self.radar.spoke_azimuth_rad(k);
        let dir = DVec2::new(az.sin(), az.cos());
        // Rain attenuation intervals along this spoke (one-way dB as a function of ground
        // range).
        let chords = self.rain_chords(radar_xy, dir);
        let rain_db = |g: f64, r: f64| {
            self.attenuator
                .as_ref()
                .map_or(0.0, |a| a.one_way_db_path_along(&chords, g, r, h, 0.0))
        };
        let wind_rel = clutter.map_or(0.0, |c| az - c.wind_from_rad());
        let cos_rel = wind_rel.cos();
        let tilt = self.beam_tilt_rad.get(k).copied().unwrap_or(0.0);
        let tilted = ant.tilted_by(tilt);
        // ∫_{x−δ}^{x} Gn²(e) de on the level antenna's pattern (8-point midpoint rule).
        let edge = |x: f64| {
            let steps = 8;
            (0..steps)
                .map(|i| x - tilt + tilt * (i as f64 + 0.5) / steps as f64)
                .map(|e| ant.elevation_pattern(e).powi(2))
                .sum::<f64>()
                * tilt
                / steps as f64
        };
        let mut last_rain = (f64::NAN, 0.0);
        for (n, row) in self.cells.iter().enumerate() {
            let Some(row) = row else { continue };
            let (sea_factor, rain_volume_factor) = if tilt == 0.0 {
                (row.sea_factor, row.rain_volume_factor)
            } else {
                let (lo, hi) = row.rain_limits;
                let level = row.rain_volume_factor / row.rain_per_integral;
                (
                    row.sea_factor_per_gain * tilted.elevation_pattern(row.depression).powi(2),
                    row.rain_per_integral * (level + edge(lo) - edge(hi)).max(0.0),
                )
            };
            let p = radar_xy + dir * row.ground_m;
            let rain_loss = if has_rain {
                if chords.is_empty() {
                    self.uniform_rain_loss[n]
                } else {
                    two_way_rain_loss(rain_db(row.ground_m, row.slant_m))
                }
            } else {
                1.0
            };
            if let Some(c) = clutter {
                let sigma0 = match c.model() {
                    // exp(b·cos φ)/I0(b): wind_direction_factor with per-row constants.
                    Sigma0Model::Nrl => row.sigma0_nrl * (row.dir_b * cos_rel).exp() * row.dir_norm,
                    Sigma0Model::Git => 10f64.powf(
                        git_sigma0_db(
                            g.freq_ghz,
                            c.sea_state(),
                            g.horizontal,
                            row.grazing_rad,
                            wind_rel,
                        ) / 10.0,
                    ),
                };
                let mean = sigma0 * sea_factor;
                sea_row[n] = (mean * rain_loss * delta) as f32;
            }
            if let Some(rain) = &self.env.rain() {
                // η changes only at cell edges along a spoke: recomputed when the rate does.
                let rate = rain.rate_at(p);
                if rate.to_bits() != last_rain.0.to_bits() {
                    last_rain = (rate, volume_reflectivity_m2_per_m3(rate, lambda));
                }
                rain_row[n] = (last_rain.1 * rain_volume_factor * rain_loss * delta) as f32;
            }
        }
    }
}

/// No land polygon: the value of a polygon row where the patch is water or land in shadow.
pub(super) const NO_POLYGON: u32 = u32::MAX;

impl SpokeStage<'_> {
    /// Spoke k's land (docs/physics.md §16). Walking out along the spoke, each sample's
    /// surface point (ground range `g = √(r² − h²)`, the land's height or the sea's 0) is seen
    /// at the elevation α ([`crate::land::profile::elevation_rad`]); it is seen when α is
    /// above every nearer point's (running maximum M; compared by slope,
    /// [`crate::land::profile::seen_lower`], the same decisions). A visible land patch subtends `Δα = α − M` in elevation and δ in
    /// azimuth: with the constant-γ model its RCS is `γ·r²·cos α·Δα·δ` — γ times the area the
    /// patch shows the radar, which is `A·sin ψ` for a flat patch of area A at grazing ψ
    /// (`σ0 = γ·sin ψ`), and the visible face for a cliff — and its mean power that times
    /// `Pt·G0²·λ²·Gn_el(α)²/((4π)³·r⁴·L·N)`, the atmosphere and the rain (as the sea's). Its
    /// power goes to `land_row[n]` and its polygon to `polygon_row[n]`; `seen_row[n]` turns
    /// false where the surface is in shadow, and the sea row is zeroed where the patch is
    /// land or in shadow. Returns whether the spoke meets any land.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn fill_land_row(
        &self,
        k: usize,
        view: &LandView,
        crossings: &mut Vec<Crossing>,
        land_row: &mut [f32],
        polygon_row: &mut [u32],
        seen_row: &mut [bool],
        sea_row: &mut [f32],
    ) -> bool {
        let g = self.geometry;
        let (h, delta) = (g.h, g.delta);
        let az = self.radar.spoke_azimuth_rad(k);
        view.crossings(az, crossings);
        if crossings.is_empty() && view.starts_at_sea() {
            return false;
        }
        let curvature = self.env.earth_curvature();
        let tilt = self.beam_tilt_rad.get(k).copied().unwrap_or(0.0);
        let tilted = g.ant.tilted_by(tilt);
        let radar_xy = self.radar.position_m().truncate();
        let dir = DVec2::new(az.sin(), az.cos());
        let chords = self.rain_chords(radar_xy, dir);
        let polygons = view.polygons();
        let mut walk = view.walk(az, crossings);
        // The highest point so far, as its (rise, ground): compared by slope, and its
        // elevation taken only where a visible land patch needs it (`seen_lower`).
        let mut highest: Option<(f64, f64)> = None;
        let mut any = false;
        let mut gamma = (usize::MAX, 0.0);
        for n in 1..land_row.len() {
            let r = n as f64 * g.dr;
            if r <= h {
                continue;
            }
            let ground = (r * r - h * h).sqrt();
            let here = walk.at(ground);
            let z = here.map_or(0.0, |x| x.1);
            let rise = rise_m(z, ground, h, curvature);
            if here.is_some() {
                any = true;
                if let Some(v) = sea_row.get_mut(n) {
                    *v = 0.0;
                }
            }
            let Some((rise_max, ground_max)) = highest else {
                highest = Some((rise, ground));
                continue;
            };
            if seen_lower(rise, ground, rise_max, ground_max) {
                // In shadow: neither sea nor land is seen.
                if let Some(v) = sea_row.get_mut(n) {
                    *v = 0.0;
                }
                seen_row[n] = false;
                continue;
            }
            highest = Some((rise, ground));
            let Some((p, _)) = here else { continue };
            let poly = &polygons[p];
            if poly.structure.is_some() {
                // A structure's footprint: its echo is traced (PO), it only hides what lies
                // behind it; its cells are marked its.
                polygon_row[n] = p as u32;
                continue;
            }
            // γ changes only where the polygon does: recomputed then.
            if gamma.0 != p {
                gamma = (p, poly.gamma_linear(g.freq_ghz));
            }
            let gamma = gamma.1;
            // The elevations as `elevation_rad` gives them (only here: a visible land patch).
            let (alpha, m) = (rise.atan2(ground), rise_max.atan2(ground_max));
            let rain_loss = self.attenuator.as_ref().map_or(1.0, |a| {
                two_way_rain_loss(a.one_way_db_path_along(&chords, ground, r, h, z))
            });
            let sigma_m2 = gamma * r * r * alpha.cos() * (alpha - m) * delta;
            let power = sigma_m2 * g.k_noise / r.powi(4)
                * tilted.elevation_pattern(alpha).powi(2)
                * self.env.attenuation_power(r)
                * rain_loss;
            land_row[n] = power as f32;
            polygon_row[n] = p as u32;
        }
        any
    }
}
