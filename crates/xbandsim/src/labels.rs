//! Stage: labels. Ground truth for every object, from the scene and the traced physics, not
//! from detection: position, range, azimuth, aspect RCS, expected SNR, visibility, and boxes in
//! polar (spoke, bin) and PPI pixel coordinates.

use crate::constants::linear_to_db;
use crate::ppi::PpiGeometry;
use crate::scattering::azimuth_elevation_rad;
use crate::scene::Scene;
use serde::Serialize;

/// Why an object can or cannot be seen in this frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Visibility {
    /// Returns an echo above the noise.
    Visible,
    /// Nearer than c·T/2 while the receiver is blanked.
    Eclipsed,
    /// Farther than the radar's maximum range.
    BeyondMaxRange,
    /// Below the radar horizon of the 4/3 earth: no echo.
    BeyondHorizon,
    /// No ray reaches it (hidden behind other objects).
    Shadowed,
    /// Its expected single-pulse SNR is below 0 dB.
    BelowNoise,
}

/// A box in polar coordinates; `spoke_min > spoke_max` means it wraps through north.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PolarBox {
    /// First spoke.
    pub spoke_min: usize,
    /// Last spoke (inclusive).
    pub spoke_max: usize,
    /// First range bin.
    pub bin_min: usize,
    /// Last range bin (inclusive).
    pub bin_max: usize,
}

/// Ground truth of one object in one frame.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ObjectTruth {
    /// Index in the scene.
    pub id: u32,
    /// Name.
    pub name: String,
    /// Class label.
    pub class: String,
    /// Shape name.
    pub shape: String,
    /// Position, ENU m.
    pub position_m: [f64; 3],
    /// Slant range from the antenna phase centre, m.
    pub range_m: f64,
    /// Horizontal range, m.
    pub ground_range_m: f64,
    /// Nautical azimuth from the radar, degrees (0 = north, clockwise).
    pub azimuth_deg: f64,
    /// Elevation from the radar, degrees.
    pub elevation_deg: f64,
    /// Monostatic RCS at this aspect from the scattering model, m² (null for `paper`).
    pub rcs_m2: Option<f64>,
    /// The same in dBsm.
    pub rcs_dbsm: Option<f64>,
    /// Power gain of the sea paths over free space, `|Σ all paths|²/|Σ direct|²`, dB
    /// (0 without multipath; null for `paper`).
    pub multipath_gain_db: Option<f64>,
    /// Radar-equation single-pulse SNR on the beam axis with that RCS, after the window,
    /// elevation-pattern, atmospheric and multipath factors, dB (null for `paper`).
    pub expected_snr_db: Option<f64>,
    /// Whether and why it is or is not seen.
    pub visibility: Visibility,
    /// Box in polar coordinates.
    pub polar_box: PolarBox,
    /// Box in PPI pixels `[x_min, y_min, x_max, y_max]`, clamped to the image.
    pub ppi_box_px: [f64; 4],
}

/// Builds the truth of every object. `rcs_m2[i]` is the traced free-space RCS and
/// `multipath_gain[i]` the sea paths' power gain (None for uncalibrated models);
/// `has_returns[i]` whether any ray reached object i.
pub fn object_truth(
    scene: &Scene,
    rcs_m2: Option<&[f64]>,
    multipath_gain: Option<&[f64]>,
    has_returns: &[bool],
    ppi: &PpiGeometry,
) -> Vec<ObjectTruth> {
    let radar = &scene.radar;
    let ant = &radar.antenna;
    let window_loss = radar.window.snr_loss_linear(radar.chirp.num_samples());
    let bin_m = radar.range_bin_m();
    let spokes = radar.spokes;
    let spoke_rad = std::f64::consts::TAU / spokes as f64;
    let resolution_m = crate::constants::SPEED_OF_LIGHT_M_PER_S / (2.0 * radar.chirp.bandwidth_hz);
    scene
        .objects
        .iter()
        .enumerate()
        .map(|(i, o)| {
            let rel = o.position_m - radar.position_m;
            let range_m = rel.length();
            let ground_range_m = rel.x.hypot(rel.y);
            let (az, el) = azimuth_elevation_rad(rel);
            let rcs = rcs_m2.map(|r| r[i]);
            let gain = multipath_gain.map(|g| g[i]);
            let snr = rcs.map(|s| {
                radar.point_target_snr(s, range_m)
                    * window_loss
                    * ant.elevation_pattern(el).powi(2)
                    * scene.environment.attenuation_power(range_m)
                    * gain.unwrap_or(1.0)
            });
            let eclipsed = radar.receiver_blanking && range_m < radar.eclipse_range_m();
            let top_m = o.bounding_centre_m().z + o.shape.bounding_radius_m();
            let beyond_horizon = scene.environment.earth_curvature
                && !crate::environment::above_horizon(radar.position_m.z, ground_range_m, top_m);
            let visibility = if beyond_horizon {
                Visibility::BeyondHorizon
            } else if range_m > radar.max_range_m {
                Visibility::BeyondMaxRange
            } else if eclipsed {
                Visibility::Eclipsed
            } else if !has_returns[i] {
                Visibility::Shadowed
            } else if snr.is_some_and(|s| s < 1.0) {
                Visibility::BelowNoise
            } else {
                Visibility::Visible
            };
            let r_b = o.shape.bounding_radius_m();
            let centre_range = (o.bounding_centre_m() - radar.position_m).length();
            let r_lo = (centre_range - r_b).max(0.0);
            let r_hi = centre_range + r_b + resolution_m;
            let half_az = (r_b / ground_range_m.max(1e-9)).atan() + ant.az_beamwidth_rad / 2.0;
            let half_az = half_az.min(std::f64::consts::PI);
            let max_bin = radar.num_range_bins() - 1;
            let bin_min = ((r_lo / bin_m).floor() as usize).min(max_bin);
            let bin_max = ((r_hi / bin_m).ceil() as usize).min(max_bin);
            let s_lo = ((az - half_az) / spoke_rad).round() as i64;
            let s_hi = ((az + half_az) / spoke_rad).round() as i64;
            let (spoke_min, spoke_max) = if s_hi - s_lo + 1 >= spokes as i64 {
                (0, spokes - 1)
            } else {
                (
                    s_lo.rem_euclid(spokes as i64) as usize,
                    s_hi.rem_euclid(spokes as i64) as usize,
                )
            };
            // PPI box: bound the polar sector by sampling its outline (ground ranges).
            let g_lo = (r_lo * r_lo - rel.z * rel.z).max(0.0).sqrt();
            let g_hi = (r_hi * r_hi - rel.z * rel.z).max(0.0).sqrt();
            let mut bx = [
                f64::INFINITY,
                f64::INFINITY,
                f64::NEG_INFINITY,
                f64::NEG_INFINITY,
            ];
            for k in 0..=32 {
                let a = az - half_az + 2.0 * half_az * k as f64 / 32.0;
                for g in [g_lo, g_hi] {
                    let (px, py) = ppi.pixel_of(g * a.sin(), g * a.cos());
                    bx = [bx[0].min(px), bx[1].min(py), bx[2].max(px), bx[3].max(py)];
                }
            }
            let size = ppi.size_px as f64;
            let ppi_box_px = [
                bx[0].clamp(0.0, size),
                bx[1].clamp(0.0, size),
                bx[2].clamp(0.0, size),
                bx[3].clamp(0.0, size),
            ];
            ObjectTruth {
                id: i as u32,
                name: o.name.clone(),
                class: o.class.clone(),
                shape: o.shape_name.clone(),
                position_m: o.position_m.to_array(),
                range_m,
                ground_range_m,
                azimuth_deg: az.to_degrees(),
                elevation_deg: el.to_degrees(),
                rcs_m2: rcs,
                rcs_dbsm: rcs.map(|r| linear_to_db(r.max(1e-30))),
                multipath_gain_db: gain.map(|g| linear_to_db(g.max(1e-30))),
                expected_snr_db: snr.map(|s| linear_to_db(s.max(1e-30))),
                visibility,
                polar_box: PolarBox {
                    spoke_min,
                    spoke_max,
                    bin_min,
                    bin_max,
                },
                ppi_box_px,
            }
        })
        .collect()
}
