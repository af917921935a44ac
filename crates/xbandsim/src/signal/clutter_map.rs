//! Sea and rain clutter of one antenna revolution as distributed scatterers entering the
//! echo before the matched filter (docs/physics.md, Sea clutter and Rain).
//!
//! The sea within the record is cut into patches: one azimuth step δ = 2π/spokes wide (at the
//! spokes' azimuths) and one range sample Δr = c/(2fs) deep. A patch at slant range R,
//! ground range g and grazing angle ψ has area `A = g·δ·Δr·sec ψ` and mean power
//! (in noise units) `m = σ0(ψ, wind)·A·Pt·G0²·λ²·Gn_el(−ψ)²/((4π)³·R⁴·L·N)`, times the two-way
//! rain and atmospheric attenuation. Rain adds `η·V` with `V = R²·δ·Δr·∫Gn_el²(θ)dθ` over the
//! elevations filled with rain. Because speckle is independent pulse to pulse, the echo of
//! spoke k in sample n is complex Gaussian with variance
//! `P_k[n] = T_k[n]·Σ_j Gn²(j·δ)·m_{k+j}[n] + Σ_j Gn²(j·δ)·rain_{k+j}[n]` — the same in
//! distribution as summing every patch's scatterers weighted by the two-way azimuth pattern,
//! at the cost of one draw per sample. The weights are scaled so that Σ_j Gn²(jδ)
//! equals the two-way beam integral `∫Gn²(θ)dθ = (2π/3)·θ3dB/2.783 = 0.753·θ3dB`, so that the
//! mean clutter power of a cell equals the radar equation with `σ = σ0·A_c`,
//! `A_c = R·(0.753·θ3dB)·(c/2B)·sec ψ` after the matched filter.
//!
//! **Texture of a cell.** `T_k[n]` is the texture of the output cell at spoke k's beam centre
//! and range sample n: the spatially correlated field's value there (drifting with the
//! waves), mapped to the documented marginal. It multiplies the beam-weighted mean rather than
//! each patch, because the shape parameters describe resolution cells (Ward's empirical ν
//! is fitted to cells of area A_c): texturing patches and then averaging them over the beam
//! would dilute the spikiness a second time. The matched filter then only mixes samples within
//! the compressed pulse (c/2B, a few metres against the field's tens of metres), so output
//! cells keep the marginal (`E[I²]/E[I]²` checked in `xbandsim validate`) while neighbouring
//! cells stay correlated over the field's correlation length.
//!
//! Grazing angle over the 4/3 earth: `sin ψ = h/R − R/(2a_e)`; patches with ψ ≤ 0 are beyond
//! the horizon and return nothing.

use crate::antenna::SINC_BEAMWIDTH_FACTOR;
use crate::cache::KeptLast;
use crate::environment::clutter::{
    git_sigma0_db, k_shape_log10, lognormal_texture, nrl_sigma0_db, weibull_texture_quantile,
    ClutterDistribution, GammaQuantile, GaussianField, Sigma0Model,
};
use crate::environment::rain::volume_reflectivity_m2_per_m3;
use crate::model::{Environment, Polarisation, Radar};
use crate::propagation::sin_grazing;
use crate::rng::{normal_pair, FrameKey, RngKey, Stream};
use crate::special::bessel_i0;
use glam::DVec2;
use num_complex::Complex32;
use rand_pcg::Pcg64Mcg;
use rayon::prelude::*;
use std::sync::Arc;

/// The clutter of one revolution: mean powers of every (spoke, sample) patch before azimuth
/// weighting, and the texture of every output cell.
pub struct ClutterMap {
    spokes: usize,
    samples: usize,
    /// Texture-free mean sea power per patch, noise units, one row of samples per spoke.
    sea: Vec<Vec<f32>>,
    /// Rain power per patch (rows empty without rain).
    rain: Vec<Vec<f32>>,
    /// Texture of each output cell (rows empty for Rayleigh clutter).
    texture: Vec<Vec<f32>>,
    /// Azimuth weights Gn²(jδ) for j = −J..=J, scaled to sum to the beam integral / δ.
    weights: Vec<f32>,
    distribution: ClutterDistribution,
}

/// Reusable buffers of one spoke's texture in [`ClutterMap::with_beam_tilts`].
#[derive(Debug, Default)]
struct TextureScratch {
    /// Sample index and field coordinates (m) of each sea cell.
    cells: Vec<(usize, f64, f64)>,
    /// The field's normalised value at each cell.
    values: Vec<f64>,
}

/// A Gaussian Doppler spectrum: mean and standard deviation, Hz.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GaussianDoppler {
    /// Mean (centroid), Hz.
    pub mean_hz: f64,
    /// Standard deviation, Hz (0: a single line).
    pub spread_hz: f64,
}

/// Reusable buffers of [`ClutterMap::add_dwell`].
#[derive(Debug, Default)]
pub struct DwellClutterScratch {
    sea: Vec<f32>,
    rain: Vec<f32>,
    lines: Vec<(f64, f32)>,
    phasors: Vec<Complex32>,
    coefficients: Vec<Complex32>,
}

/// Most spectral lines per process.
pub const MAX_DOPPLER_LINES: usize = 48;

/// Appends the lines `(f_b, a_b)` that synthesise `spectrum` over a dwell of `duration_s`:
/// spacing `Δf = min(σ/2, 1/(2D))` (so the line set's period `1/Δf` is at least twice the
/// dwell and the spectrum is resolved), lines within ±3σ of the mean (at most
/// [`MAX_DOPPLER_LINES`], widening Δf), amplitudes `a_b ∝ exp(−(f_b − f̄)²/(4σ²))` with
/// `Σ a_b² = 1`. A zero spread gives one line at the mean.
pub fn doppler_lines(spectrum: GaussianDoppler, duration_s: f64, lines: &mut Vec<(f64, f32)>) {
    let sigma = spectrum.spread_hz;
    if sigma <= 0.0 {
        lines.push((spectrum.mean_hz, 1.0));
        return;
    }
    let mut df = (sigma / 2.0).min(0.5 / duration_s.max(1e-9));
    let half_max = (MAX_DOPPLER_LINES - 1) / 2;
    if (3.0 * sigma / df).ceil() as usize > half_max {
        df = 3.0 * sigma / half_max as f64;
    }
    let half = (3.0 * sigma / df).ceil() as i64;
    let start = lines.len();
    let mut total = 0.0;
    for b in -half..=half {
        let f = spectrum.mean_hz + b as f64 * df;
        let p = (-(b as f64 * df).powi(2) / (2.0 * sigma * sigma)).exp();
        total += p;
        lines.push((f, p as f32));
    }
    for l in &mut lines[start..] {
        l.1 = (l.1 as f64 / total).sqrt() as f32;
    }
}

/// Two-way azimuth beam integral `∫Gn²(θ)dθ` of the sinc² pattern, rad.
pub fn two_way_beam_integral_rad(beamwidth_3db_rad: f64) -> f64 {
    (2.0 * std::f64::consts::PI / 3.0) * beamwidth_3db_rad / SINC_BEAMWIDTH_FACTOR
}

/// Two-way power loss `10^(−2·A/10)` of a one-way rain attenuation `A` (dB).
#[inline]
fn two_way_rain_loss(one_way_db: f64) -> f64 {
    (-2.0 * one_way_db / 10.0 * std::f64::consts::LN_10).exp()
}

/// The texture field of scene seed `seed` over `extent_m` with correlation length
/// `correlation_m`: a pure function of the three (its own random stream), so the few made
/// last are kept and shared — every frame of a run drifts the same field, and making one takes
/// longer than the rest of a small clutter map. At most [`FIELD_CACHE_LEN`] fields and
/// [`FIELD_CACHE_BYTES`] of values are kept.
pub(crate) fn texture_field(seed: u64, extent_m: f64, correlation_m: f64) -> Arc<GaussianField> {
    TEXTURE_FIELDS.get_or_make(
        (seed, extent_m.to_bits(), correlation_m.to_bits()),
        || {
            let mut rng = FrameKey::new(seed, 0).texture().rng();
            Arc::new(GaussianField::new(&mut rng, extent_m, correlation_m))
        },
        |f| f.bytes(),
    )
}

/// The texture fields made last ([`FIELD_CACHE_LEN`], [`FIELD_CACHE_BYTES`]).
pub(crate) static TEXTURE_FIELDS: KeptLast<FieldKey, Arc<GaussianField>> =
    KeptLast::new(FIELD_CACHE_LEN, FIELD_CACHE_BYTES);

/// A texture field's inputs: seed, extent and correlation length (their bits).
type FieldKey = (u64, u64, u64);

/// Texture fields kept by [`texture_field`].
const FIELD_CACHE_LEN: usize = 8;

/// Bytes of texture-field values kept (a 2048² field, the largest, takes 16 MB).
const FIELD_CACHE_BYTES: usize = 64 << 20;

impl ClutterMap {
    /// The clutter of revolution `key` (the texture drifts with time `frame × rotation period`)
    /// for records of `samples` samples; None when there is neither sea clutter nor rain.
    pub fn new(
        radar: &Radar,
        env: &Environment,
        key: FrameKey,
        samples: usize,
    ) -> Option<ClutterMap> {
        ClutterMap::with_beam_tilts(radar, env, key, samples, &[])
    }

    /// As [`ClutterMap::new`], with spoke k's beam axis raised by `beam_tilt_rad[k]` (the own
    /// ship's roll and pitch when the beam passes it; an empty slice for a level deck): the
    /// sea's elevation gain `Gn²(ψ_d − tilt − δ)` and the rain's elevation integral
    /// `∫_{lo−δ}^{hi−δ} Gn²` = the level integral `+ ∫_{lo−δ}^{lo} − ∫_{hi−δ}^{hi}` (each edge
    /// by an 8-point midpoint rule).
    pub fn with_beam_tilts(
        radar: &Radar,
        env: &Environment,
        key: FrameKey,
        samples: usize,
        beam_tilt_rad: &[f64],
    ) -> Option<ClutterMap> {
        let FrameKey { seed, frame } = key;
        if env.clutter().is_none() && env.rain().is_none() {
            return None;
        }
        let spokes = radar.spokes();
        let h = radar.position_m().z.max(0.0);
        let dr = radar.range_bin_m();
        let lambda = radar.wavelength_m();
        let freq_ghz = radar.carrier_freq_hz() / 1e9;
        let horizontal = radar.polarisation() == Polarisation::Hh;
        let ant = &radar.antenna();
        let delta = std::f64::consts::TAU / spokes as f64;
        // Radar equation over the noise power: P_r/N per m² of σ at 1 m.
        let k_noise = radar.radar_equation_constant_w_m2() / radar.noise_power_w();
        let resolution_m = radar.range_resolution_m();
        let beam_integral = two_way_beam_integral_rad(ant.az_beamwidth_rad);
        // Azimuth weights over ±2 first nulls.
        let null = std::f64::consts::PI * ant.az_beamwidth_rad / SINC_BEAMWIDTH_FACTOR;
        let half = ((2.0 * null / delta).ceil() as usize).min(spokes / 2);
        let raw: Vec<f64> = (-(half as isize)..=half as isize)
            .map(|j| ant.azimuth_pattern(j as f64 * delta).powi(2))
            .collect();
        let sum: f64 = raw.iter().sum();
        // Σ w_j·δ = beam integral (w carries Gn², the patch carries δ).
        let weights: Vec<f32> = raw
            .iter()
            .map(|w| (w / sum * beam_integral / delta) as f32)
            .collect();
        // Per-sample geometry and mean power factors (independent of azimuth).
        struct Row {
            ground_m: f64,
            /// Slant range r, m: the rain loss is charged along it, not along the ground
            /// track (docs/physics.md §2.7).
            slant_m: f64,
            grazing_rad: f64,
            sea_factor: f64,
            sigma0_nrl: f64,
            /// Upwind-factor exponent b and 1/I0(b) (see `wind_direction_factor`).
            dir_b: f64,
            dir_norm: f64,
            /// log10 ν of the empirical K shape without the swell-direction term.
            log_nu_row: f64,
            rain_volume_factor: f64,
            /// For a tilted beam: the depression angle, the sea factor without its elevation
            /// gain, the rain factor without its elevation integral and that integral's
            /// limits (rad).
            depression: f64,
            sea_factor_per_gain: f64,
            rain_per_integral: f64,
            rain_limits: (f64, f64),
        }
        let rows: Vec<Option<Row>> = (0..samples)
            .map(|n| {
                let r = n as f64 * dr;
                if r <= h || n == 0 {
                    return None;
                }
                let ground_m = (r * r - h * h).sqrt();
                let sin_psi = sin_grazing(h, r, env.earth_curvature());
                if sin_psi <= 0.0 {
                    return None;
                }
                let grazing_rad = sin_psi.asin();
                let depression = -(h / r).asin();
                let el_gain = ant.elevation_pattern(depression).powi(2);
                let atmos = env.attenuation_power(r);
                let sea_factor =
                    ground_m * dr / grazing_rad.cos() * k_noise / r.powi(4) * el_gain * atmos;
                let sigma0_nrl = 10f64.powf(
                    nrl_sigma0_db(
                        freq_ghz,
                        env.clutter().as_ref().map_or(0.0, |c| c.sea_state()),
                        horizontal,
                        grazing_rad.to_degrees(),
                    ) / 10.0,
                );
                let sea_factor_per_gain =
                    ground_m * dr / grazing_rad.cos() * k_noise / r.powi(4) * atmos;
                let rain_per_integral = r * r * dr * k_noise / r.powi(4) * atmos;
                let rain_limits = env.rain().as_ref().map_or((0.0, 0.0), |rain| {
                    (depression, ((rain.top_m - h) / r).clamp(-1.0, 1.0).asin())
                });
                // Rain: elevations from the sea up to the rain top, two-way elevation pattern.
                let rain_volume_factor = env.rain().as_ref().map_or(0.0, |rain| {
                    let lo = depression;
                    let hi = ((rain.top_m - h) / r).clamp(-1.0, 1.0).asin();
                    let steps = 48;
                    let integral: f64 = (0..steps)
                        .map(|i| lo + (hi - lo) * (i as f64 + 0.5) / steps as f64)
                        .map(|e| ant.elevation_pattern(e).powi(2))
                        .sum::<f64>()
                        * (hi - lo)
                        / steps as f64;
                    r * r * dr * integral.max(0.0) * k_noise / r.powi(4) * atmos
                });
                let cell_area_m2 =
                    ground_m * ant.az_beamwidth_rad * resolution_m / grazing_rad.cos();
                let dir_b = 0.2 * (1.0 - 2.8 * grazing_rad) * (lambda + 0.015).powf(-0.4);
                // exp(b·cos φ) averages to I0(b) over φ: divide by it for a unit mean.
                let dir_norm = 1.0 / bessel_i0(dir_b);
                // k_shape_default at a 45° swell angle has cos(2θ) = 0: the row part alone
                // (the swell-direction term −cos(2θ_sw)/3 is added per spoke).
                // Unclamped: the clamp to 0.1…20 applies after the swell term.
                let log_nu_row = k_shape_log10(
                    grazing_rad.to_degrees(),
                    cell_area_m2,
                    horizontal,
                    std::f64::consts::FRAC_PI_4,
                );
                Some(Row {
                    ground_m,
                    slant_m: r,
                    grazing_rad,
                    sea_factor,
                    sigma0_nrl,
                    dir_b,
                    dir_norm,
                    log_nu_row,
                    rain_volume_factor,
                    depression,
                    sea_factor_per_gain,
                    rain_per_integral,
                    rain_limits,
                })
            })
            .collect();
        let clutter = env.clutter();
        let distribution = clutter.map_or(ClutterDistribution::Rayleigh, |c| c.distribution());
        let textured = clutter.is_some() && distribution != ClutterDistribution::Rayleigh;
        // Texture field (per scene seed), drifting downwind with time.
        let max_ground = rows
            .iter()
            .rev()
            .find_map(|r| r.as_ref().map(|r| r.ground_m))
            .unwrap_or(1.0);
        let field = match clutter {
            Some(c) if textured => Some(texture_field(
                seed,
                2.0 * max_ground + 4.0 * c.correlation_m(),
                c.correlation_m(),
            )),
            _ => None,
        };
        let fixed_gamma = match distribution {
            ClutterDistribution::K { shape_nu: Some(nu) } if textured => {
                Some(GammaQuantile::for_shape(nu))
            }
            _ => None,
        };
        let weibull = match distribution {
            ClutterDistribution::Weibull { shape } if textured => {
                Some(weibull_texture_quantile(shape))
            }
            _ => None,
        };
        let t_s = frame as f64 * 60.0 / radar.rotation_rpm();
        let drift = clutter.map_or(DVec2::ZERO, |c| {
            // Downwind is opposite to where the wind comes from.
            let to = c.wind_from_rad() + std::f64::consts::PI;
            DVec2::new(to.sin(), to.cos()) * c.drift_m_per_s() * t_s
        });
        let radar_xy = radar.position_m().truncate();
        let attenuator = env
            .rain()
            .as_ref()
            .map(|r| r.attenuator(freq_ghz, horizontal));
        let has_rain = env.rain().is_some();
        // Two-way rain loss of each row along a spoke that crosses no rain cell (the uniform
        // rain alone: the same for every such spoke), so once per map, not once per spoke.
        let uniform_rain_loss: Vec<f64> = attenuator.as_ref().map_or_else(Vec::new, |a| {
            rows.iter()
                .map(|r| {
                    r.as_ref().map_or(1.0, |r| {
                        two_way_rain_loss(a.one_way_db_path_along(
                            &[],
                            r.ground_m,
                            r.slant_m,
                            h,
                            0.0,
                        ))
                    })
                })
                .collect()
        });
        // The quantile tables of the per-cell K shapes (empty unless that is the
        // distribution), fetched from the process-wide cache once per map, not per spoke.
        let per_cell_levels = fixed_gamma.is_none() && textured;
        let tables: Vec<std::sync::OnceLock<std::sync::Arc<GammaQuantile>>> = (0
            ..if per_cell_levels {
                GammaQuantile::LEVELS
            } else {
                0
            })
            .map(|_| std::sync::OnceLock::new())
            .collect();
        // One spoke's rows of sea mean, rain and texture.
        let spoke_rows = |scratch: &mut TextureScratch,
                          k: usize|
         -> (Vec<f32>, Vec<f32>, Vec<f32>) {
            let textured_cells = &mut scratch.cells;
            textured_cells.clear();
            let mut sea_row = vec![0f32; samples];
            let mut rain_row = vec![0f32; if has_rain { samples } else { 0 }];
            let mut texture_row = vec![0f32; if textured { samples } else { 0 }];
            let az = radar.spoke_azimuth_rad(k);
            let dir = DVec2::new(az.sin(), az.cos());
            // Rain attenuation intervals along this spoke (one-way dB as a function of ground range).
            let chords = attenuator
                .as_ref()
                .map(|a| a.chords(radar_xy, dir))
                .unwrap_or_default();
            let rain_db = |g: f64, r: f64| {
                attenuator
                    .as_ref()
                    .map_or(0.0, |a| a.one_way_db_path_along(&chords, g, r, h, 0.0))
            };
            let wind_rel = clutter.map_or(0.0, |c| az - c.wind_from_rad());
            let swell_rel = clutter.map_or(0.0, |c| az - c.swell_from_rad());
            let cos_rel = wind_rel.cos();
            let cos_2swell = (2.0 * swell_rel).cos();
            let tilt = beam_tilt_rad.get(k).copied().unwrap_or(0.0);
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
            for (n, row) in rows.iter().enumerate() {
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
                        uniform_rain_loss[n]
                    } else {
                        two_way_rain_loss(rain_db(row.ground_m, row.slant_m))
                    }
                } else {
                    1.0
                };
                if let Some(c) = clutter {
                    let sigma0 = match c.model() {
                        // exp(b·cos φ)/I0(b): wind_direction_factor with per-row constants.
                        Sigma0Model::Nrl => {
                            row.sigma0_nrl * (row.dir_b * cos_rel).exp() * row.dir_norm
                        }
                        Sigma0Model::Git => 10f64.powf(
                            git_sigma0_db(
                                freq_ghz,
                                c.sea_state(),
                                horizontal,
                                row.grazing_rad,
                                wind_rel,
                            ) / 10.0,
                        ),
                    };
                    let mean = sigma0 * sea_factor;
                    sea_row[n] = (mean * rain_loss * delta) as f32;
                    if field.is_some() {
                        let x = p - drift;
                        textured_cells.push((n, x.x, x.y));
                    }
                }
                if let Some(rain) = &env.rain() {
                    // η changes only at cell edges along a spoke: recomputed when the rate does.
                    let rate = rain.rate_at(p);
                    if rate.to_bits() != last_rain.0.to_bits() {
                        last_rain = (rate, volume_reflectivity_m2_per_m3(rate, lambda));
                    }
                    rain_row[n] = (last_rain.1 * rain_volume_factor * rain_loss * delta) as f32;
                }
            }
            if let (Some(f), Some(c)) = (&field, clutter) {
                // The texture in two passes over the spoke's cells: the field's normalised
                // values (a loop of its own, whose iterations overlap), then the marginal.
                let values = &mut scratch.values;
                f.at_each(textured_cells, values);
                let cells = textured_cells.iter().zip(values.iter());
                match c.distribution() {
                    ClutterDistribution::K { .. } => match &fixed_gamma {
                        Some(q) => {
                            for (&(n, _, _), &g) in cells {
                                texture_row[n] = q.of_normal(g) as f32;
                            }
                        }
                        None => {
                            // Consecutive cells mostly share a shape level: each run of one
                            // level looks its table up once.
                            let level_of = |i: usize| {
                                let n = textured_cells[i].0;
                                let log_nu = rows[n].as_ref().map_or(0.0, |r| r.log_nu_row);
                                GammaQuantile::level_from_log10(log_nu - cos_2swell / 3.0)
                            };
                            let mut start = 0;
                            while start < values.len() {
                                let level = level_of(start);
                                let mut end = start + 1;
                                while end < values.len() && level_of(end) == level {
                                    end += 1;
                                }
                                tables[level]
                                    .get_or_init(|| GammaQuantile::for_level(level))
                                    .of_normal_each(&values[start..end], |i, t| {
                                        texture_row[textured_cells[start + i].0] = t as f32;
                                    });
                                start = end;
                            }
                        }
                    },
                    ClutterDistribution::Weibull { .. } => {
                        for (&(n, _, _), &g) in cells {
                            texture_row[n] =
                                weibull.as_ref().map_or(1.0, |q| q.of_normal(g)) as f32;
                        }
                    }
                    ClutterDistribution::LogNormal { sigma_db } => {
                        for (&(n, _, _), &g) in cells {
                            texture_row[n] = lognormal_texture(g, sigma_db) as f32;
                        }
                    }
                    // Rayleigh clutter has no texture field, so no cells here.
                    ClutterDistribution::Rayleigh => {}
                }
            }
            (sea_row, rain_row, texture_row)
        };
        let per_spoke: Vec<(Vec<f32>, Vec<f32>, Vec<f32>)> = (0..spokes)
            .into_par_iter()
            .map_init(TextureScratch::default, spoke_rows)
            .collect();
        let mut sea = Vec::with_capacity(spokes);
        let mut rain = Vec::with_capacity(spokes);
        let mut texture = Vec::with_capacity(spokes);
        for (s_row, r_row, t_row) in per_spoke {
            sea.push(s_row);
            rain.push(r_row);
            texture.push(t_row);
        }
        Some(ClutterMap {
            spokes,
            samples,
            sea,
            rain,
            texture,
            weights,
            distribution,
        })
    }

    /// Spoke index `k + t − J` wrapped around the revolution.
    #[inline]
    fn neighbour(&self, k: usize, t: usize) -> usize {
        let half = (self.weights.len() / 2) as isize;
        (k as isize + t as isize - half).rem_euclid(self.spokes as isize) as usize
    }

    /// Texture-free mean clutter power (sea and rain) of spoke `k`, sample `n`, after
    /// azimuth weighting (noise units).
    pub fn mean_power(&self, k: usize, n: usize) -> f32 {
        let (sea, rain) = self.weighted(k, n);
        sea + rain
    }

    /// Beam-weighted sea and rain power of spoke `k`, sample `n`.
    #[inline]
    fn weighted(&self, k: usize, n: usize) -> (f32, f32) {
        let (mut sea, mut rain) = (0f32, 0f32);
        for (t, w) in self.weights.iter().enumerate() {
            let j = self.neighbour(k, t);
            sea += w * self.sea[j][n];
            if let Some(r) = self.rain[j].get(n) {
                rain += w * r;
            }
        }
        (sea, rain)
    }

    /// The texture of output cell (spoke `k`, sample `n`); 1 for Rayleigh clutter.
    pub fn texture(&self, k: usize, n: usize) -> f32 {
        self.texture[k].get(n).copied().unwrap_or(1.0)
    }

    /// Clutter power of spoke `k`, sample `n` with its texture (noise units).
    #[inline]
    pub fn power(&self, k: usize, n: usize) -> f32 {
        let (sea, rain) = self.weighted(k, n);
        self.texture(k, n) * sea + rain
    }

    /// The amplitude statistics.
    pub fn distribution(&self) -> ClutterDistribution {
        self.distribution
    }

    /// Adds the clutter echo of one pulse with the beam at spoke `k` to `impulse_response`
    /// (noise-rms units): complex Gaussian speckle with the cell's power, drawn from the
    /// pulse's `speckle` stream. `sea` and `rain` are the caller's buffers for the spoke's
    /// beam-weighted powers (what they held before does not matter).
    pub fn add_to_spoke(
        &self,
        k: usize,
        speckle: RngKey,
        sea: &mut Vec<f32>,
        rain: &mut Vec<f32>,
        impulse_response: &mut [Complex32],
    ) {
        debug_assert_eq!(speckle.stream, Stream::ClutterSpeckle);
        let mut rng: Pcg64Mcg = speckle.rng();
        let n_max = self.samples.min(impulse_response.len());
        // Beam-weighted sea and rain power of this spoke, accumulated row by row (contiguous,
        // vectorisable) into the caller's two buffers.
        let has_rain = !self.rain[k].is_empty();
        sea.clear();
        sea.resize(n_max, 0.0);
        rain.clear();
        rain.resize(if has_rain { n_max } else { 0 }, 0.0);
        for (t, &w) in self.weights.iter().enumerate() {
            let j = self.neighbour(k, t);
            for (acc, &v) in sea.iter_mut().zip(&self.sea[j][..n_max]) {
                *acc += w * v;
            }
            if has_rain {
                for (acc, &v) in rain.iter_mut().zip(&self.rain[j][..n_max]) {
                    *acc += w * v;
                }
            }
        }
        let texture = (!self.texture[k].is_empty()).then(|| &self.texture[k][..n_max]);
        for n in 0..n_max {
            let mut p = texture.map_or(sea[n], |t| t[n] * sea[n]);
            if has_rain {
                p += rain[n];
            }
            if p <= 0.0 {
                continue;
            }
            let s = (p * 0.5).sqrt();
            let (re, im) = normal_pair(&mut rng);
            impulse_response[n] += Complex32::new(re * s, im * s);
        }
    }

    /// Adds the Doppler-coloured clutter of one pulse-mode dwell of spoke `k` into `out`
    /// (pulse m's record at `out[m·stride ..][..samples]`, noise-rms units): for every cell a
    /// sea and a rain process, each complex Gaussian with the cell's power and a Gaussian
    /// Doppler spectrum (`sea`, `rain`), evaluated at the pulses' `times_s`. Each process is a
    /// sum of spectral lines `Σ_b a_b·ξ_b·exp(j2π·f_b·(t − t_0))` with independent complex
    /// Gaussian ξ_b ([`doppler_lines`]), so the marginal stays Gaussian (times the cell's
    /// texture, constant over the dwell: it evolves over seconds, frame to frame) and the
    /// correlation between pulses is the Gaussian spectrum's.
    #[allow(clippy::too_many_arguments)]
    pub fn add_dwell(
        &self,
        k: usize,
        times_s: &[f64],
        sea: GaussianDoppler,
        rain: GaussianDoppler,
        key: RngKey,
        scratch: &mut DwellClutterScratch,
        out: &mut [Complex32],
        stride: usize,
    ) {
        debug_assert_eq!(key.stream, Stream::ClutterDwell);
        let mut rng: Pcg64Mcg = key.rng();
        let n_max = self.samples.min(stride);
        let pulses = times_s.len();
        let has_rain = !self.rain[k].is_empty();
        let s = scratch;
        s.sea.clear();
        s.sea.resize(n_max, 0.0);
        s.rain.clear();
        s.rain.resize(if has_rain { n_max } else { 0 }, 0.0);
        for (t, &w) in self.weights.iter().enumerate() {
            let j = self.neighbour(k, t);
            for (acc, &v) in s.sea.iter_mut().zip(&self.sea[j][..n_max]) {
                *acc += w * v;
            }
            if has_rain {
                for (acc, &v) in s.rain.iter_mut().zip(&self.rain[j][..n_max]) {
                    *acc += w * v;
                }
            }
        }
        let duration =
            times_s.last().copied().unwrap_or(0.0) - times_s.first().copied().unwrap_or(0.0);
        let t0 = times_s.first().copied().unwrap_or(0.0);
        // Lines and their phasors at every pulse, sea first then rain.
        s.lines.clear();
        doppler_lines(sea, duration, &mut s.lines);
        let sea_lines = s.lines.len();
        if has_rain {
            doppler_lines(rain, duration, &mut s.lines);
        }
        let lines = s.lines.len();
        s.phasors.clear();
        for &t in times_s {
            for &(f, _) in &s.lines {
                let ph = std::f64::consts::TAU * f * (t - t0);
                s.phasors
                    .push(Complex32::new(ph.cos() as f32, ph.sin() as f32));
            }
        }
        s.coefficients.resize(lines, Complex32::new(0.0, 0.0));
        let texture = (!self.texture[k].is_empty()).then(|| &self.texture[k][..n_max]);
        for n in 0..n_max {
            let p_sea = texture.map_or(s.sea[n], |t| t[n] * s.sea[n]);
            let p_rain = if has_rain { s.rain[n] } else { 0.0 };
            if p_sea <= 0.0 && p_rain <= 0.0 {
                continue;
            }
            for (b, c) in s.coefficients.iter_mut().enumerate() {
                let (p, a) = if b < sea_lines {
                    (p_sea, s.lines[b].1)
                } else {
                    (p_rain, s.lines[b].1)
                };
                let scale = (p.max(0.0) * 0.5).sqrt() * a;
                let (re, im) = normal_pair(&mut rng);
                *c = Complex32::new(re * scale, im * scale);
            }
            for m in 0..pulses {
                let row = &s.phasors[m * lines..(m + 1) * lines];
                let mut acc = Complex32::new(0.0, 0.0);
                for (c, ph) in s.coefficients.iter().zip(row) {
                    acc += c * ph;
                }
                out[m * stride + n] += acc;
            }
        }
    }

    /// Spokes × samples of the map.
    pub fn shape(&self) -> (usize, usize) {
        (self.spokes, self.samples)
    }
}
