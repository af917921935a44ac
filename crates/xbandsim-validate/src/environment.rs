//! Environment checks: sea-clutter mean power against σ0·A_c, clutter-cell statistics
//! against the configured distribution, rain attenuation and rain clutter (docs/validation.md).

use crate::harness::*;
use crate::{check, Checks, Tolerance};
use serde::Serialize;
use xbandsim::antenna::Pattern;
use xbandsim::constants::{linear_to_db, SPEED_OF_LIGHT_M_PER_S};
use xbandsim::engine::Request;
use xbandsim::engine::Simulation;
use xbandsim::model::{Polarisation, Scene};
use xbandsim::rng::FrameKey;

/// Mean sea-clutter power (dB over noise) in the matched-filter output around `range_m`
/// (±40 bins, 4 frames of 2048 spokes, Rayleigh clutter, HH, radar at 10 m)
/// against the radar equation with `σ = σ0·A_c` bin by bin, `A_c = R·(0.753·θ3dB)·(c/2B)·sec ψ`,
/// the elevation pattern at the depression angle and σ0 from the NRL model (its azimuth
/// mean: the wind-direction factor averages to one). Returns (expected, measured), each the
/// mean over the bins of the dB ratio's linear value.
pub fn clutter_mean_power_db(sea_state: f64, range_m: f64) -> (f64, f64) {
    let text = format!("[environment]\nnoise = false\nmultipath = false\nsea_state = {sea_state}\nwind_direction_deg = 33.0\nclutter_distribution = \"rayleigh\"\n[radar]\nposition_m = [0.0, 0.0, 10.0]\nspokes = 2048\nmax_range_m = {}\n", range_m + 200.0);
    let scene = Scene::from_toml_str(&text, "validation").expect("validation scene is valid");
    let sim = Simulation::new(scene);
    let radar = sim.scene().radar();
    let groups = sim.echo_groups(&sim.trace());
    let centre = (range_m / radar.range_bin_m()).round() as usize;
    let bins: Vec<usize> = (centre - 40..=centre + 40).collect();
    let h = radar.position_m().z;
    let expected_at = |bin: usize| {
        let r = bin as f64 * radar.range_bin_m();
        let psi = (h / r - r / (2.0 * xbandsim::propagation::EFFECTIVE_EARTH_RADIUS_M)).asin();
        let sigma0 = 10f64.powf(
            xbandsim::environment::clutter::nrl_sigma0_db(
                radar.carrier_freq_hz() / 1e9,
                sea_state,
                true,
                psi.to_degrees(),
            ) / 10.0,
        );
        let ground = (r * r - h * h).sqrt();
        let area = ground
            * two_way_beam_integral_rad(radar.antenna().az_beamwidth_rad)
            * SPEED_OF_LIGHT_M_PER_S
            / (2.0 * radar.chirp().bandwidth_hz)
            / psi.cos();
        let el_gain = radar.antenna().elevation_pattern(-(h / r).asin()).powi(2);
        radar.point_target_snr(sigma0 * area, r) * el_gain
    };
    let frames = 4u64;
    let mut ratio = 0.0;
    for frame in 0..frames {
        let request = Request::new(21).frame(frame);
        let clutter = sim.clutter_map(FrameKey::new(21, frame));
        let polar = sim
            .synthesize(&groups, clutter.as_ref(), &request)
            .expect("the frozen scan of this radar");
        let row = radar.num_range_bins();
        for &bin in &bins {
            let e = expected_at(bin);
            let m: f64 = (0..radar.spokes())
                .map(|k| 10f64.powf(polar[k * row + bin] as f64 / 10.0))
                .sum::<f64>()
                / radar.spokes() as f64;
            ratio += m / e;
        }
    }
    ratio /= (frames as usize * bins.len()) as f64;
    (0.0, linear_to_db(ratio))
}

/// Frames (seeds) over which the clutter-cell statistics are measured.
pub const CLUTTER_FRAMES: u64 = 40;

/// Relative tolerance on `E[I²]/E[I]²` of clutter cells: 8 % (docs/validation.md), about
/// three standard errors of the estimate over `CLUTTER_FRAMES` frames for ν = 1.5 (the
/// texture field gives a few thousand independent values per frame).
pub const CLUTTER_MOMENT_TOLERANCE: f64 = 0.08;

/// Statistics of sea-clutter intensity in matched-filter output cells.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct ClutterCellStats {
    /// `E[I²]/E[I]²` the documented distribution gives (averaged over the cells' own ν for
    /// the empirical K shape).
    pub expected_moment: f64,
    /// Measured `E[X²]/E[X]²` of `X = I/mean`, each cell's output power over its texture-free
    /// mean (which varies with range and look direction).
    pub measured_moment: f64,
    /// Correlation coefficient of X between cells 15 m apart in range (texture shared).
    pub correlation_15_m: f64,
    /// The same 300 m apart (the texture has decorrelated).
    pub correlation_300_m: f64,
    /// Cells used.
    pub cells: usize,
}

/// Renders sea clutter with the default radar and environment plus `environment_lines`
/// (noise off) for `frames` seeds, and measures the output cells from 200 m to 1400 m.
pub fn clutter_cell_statistics(environment_lines: &str, frames: u64) -> ClutterCellStats {
    use xbandsim::environment::clutter::{k_shape_default, ClutterDistribution};
    let text = format!("[environment]\nnoise = false\nmultipath = false\n{environment_lines}\n");
    let scene = Scene::from_toml_str(&text, "validation").expect("validation scene is valid");
    let sim = Simulation::new(scene);
    let scene = sim.scene();
    let radar = scene.radar();
    let clutter = scene.environment().clutter().expect("clutter is on");
    let groups = sim.echo_groups(&sim.trace());
    let bin_m = radar.range_bin_m();
    let (first, last) = ((200.0 / bin_m) as usize, (1400.0 / bin_m) as usize);
    let row = radar.num_range_bins();
    let h = radar.position_m().z;
    let resolution_m = SPEED_OF_LIGHT_M_PER_S / (2.0 * radar.chirp().bandwidth_hz);
    // Each cell's expected moment (closed form; ν from Ward's formula where it is the default).
    let expected_moment_at = |k: usize, n: usize| {
        let r = n as f64 * bin_m;
        let psi = (h / r - r / (2.0 * xbandsim::propagation::EFFECTIVE_EARTH_RADIUS_M)).asin();
        let ground = (r * r - h * h).sqrt();
        let area = ground * radar.antenna().az_beamwidth_rad * resolution_m / psi.cos();
        let swell_rel = radar.spoke_azimuth_rad(k) - clutter.swell_from_rad();
        let nu = k_shape_default(
            psi.to_degrees(),
            area,
            radar.polarisation() == Polarisation::Hh,
            swell_rel,
        );
        clutter.distribution().intensity_second_moment(nu)
    };
    let lag_near = (15.0 / bin_m).round() as usize;
    let lag_far = (300.0 / bin_m).round() as usize;
    let (mut s1, mut s2, mut expected, mut cells) = (0.0, 0.0, 0.0, 0usize);
    // Pairs (x, y) sums for the two lags: Σx, Σy, Σx², Σy², Σxy, count.
    let mut near = [0f64; 6];
    let mut far = [0f64; 6];
    let add = |acc: &mut [f64; 6], x: f64, y: f64| {
        acc[0] += x;
        acc[1] += y;
        acc[2] += x * x;
        acc[3] += y * y;
        acc[4] += x * y;
        acc[5] += 1.0;
    };
    let pearson = |a: &[f64; 6]| {
        let n = a[5];
        let cov = a[4] / n - a[0] / n * a[1] / n;
        let vx = a[2] / n - (a[0] / n).powi(2);
        let vy = a[3] / n - (a[1] / n).powi(2);
        cov / (vx * vy).sqrt()
    };
    for frame in 0..frames {
        let seed = 100 + frame;
        let map = sim
            .clutter_map(FrameKey::new(seed, 0))
            .expect("clutter is on");
        let polar = sim
            .synthesize(&groups, Some(&map), &Request::new(seed))
            .expect("the frozen scan of this radar");
        for k in 0..radar.spokes() {
            let x: Vec<f64> = (first..=last)
                .map(|n| 10f64.powf(polar[k * row + n] as f64 / 10.0) / map.mean_power(k, n) as f64)
                .collect();
            for (i, &v) in x.iter().enumerate() {
                s1 += v;
                s2 += v * v;
                cells += 1;
                if frame == 0 {
                    expected += expected_moment_at(k, first + i);
                }
                if let Some(&y) = x.get(i + lag_near) {
                    add(&mut near, v, y);
                }
                if let Some(&y) = x.get(i + lag_far) {
                    add(&mut far, v, y);
                }
            }
        }
    }
    let m1 = s1 / cells as f64;
    let _ = ClutterDistribution::Rayleigh;
    ClutterCellStats {
        expected_moment: expected / (cells as f64 / frames as f64),
        measured_moment: s2 / cells as f64 / (m1 * m1),
        correlation_15_m: pearson(&near),
        correlation_300_m: pearson(&far),
        cells,
    }
}

/// Power loss (dB) of a point target at 3 km behind uniform rain of `rate` mm/h, against
/// the same scene without rain: (expected −2·γ·R, measured). Radar and target are at 4 m
/// inside a rain layer 5 m deep; the target's 10⁴ m² keep the rain's own echo in its cell
/// (the layer's volume, 50 dB or more below the target) from moving the peak by more than
/// 0.03 dB.
pub fn rain_attenuation_db(rate_mm_per_h: f64) -> (f64, f64) {
    let range_m = bin_range_m(2000.0, 100e6);
    let run = |rain: f64| {
        let text = format!("[environment]\nnoise = false\nclutter = false\nmultipath = false\nrain_rate_mm_per_h = {rain}\nrain_top_m = 5.0\n[radar]\nposition_m = [0.0, 0.0, 4.0]\nmax_range_m = 3200.0\n{}", point_north("p", range_m, 1e4));
        let (_, frame) = render_text(&text, 1);
        spoke(&frame, 0)[1998..2003]
            .iter()
            .cloned()
            .fold(f32::MIN, f32::max) as f64
    };
    let gamma = xbandsim::propagation::specific_attenuation_db_per_km(9.41, rate_mm_per_h, true);
    (
        -2.0 * gamma * range_m / 1000.0,
        run(rate_mm_per_h) - run(0.0),
    )
}

/// Mean rain clutter-to-noise (dB) around bin `bin` for a radar 1 km up inside uniform rain
/// (the whole beam filled), against `η·V` with `V = R²·(0.753θaz)(0.753θel)·(c/2B)` and the
/// two-way path attenuation: (expected at `bin`, measured at `bin`). The measured figure is
/// the expected one times the mean of measured/expected over the 41 bins `bin ± 20` and all
/// spokes: one bin's mean over 1024 spokes of exponentially distributed speckle spreads by
/// 0.14 dB rms, the 41 bins' (correlated over a few bins by the compressed pulse) by about
/// a quarter of that.
pub fn rain_clutter_power_db(rate_mm_per_h: f64, bin: usize) -> (f64, f64) {
    let text = format!("[environment]\nnoise = false\nclutter = false\nmultipath = false\nearth_curvature = false\nrain_rate_mm_per_h = {rate_mm_per_h}\nrain_top_m = 20000.0\n[radar]\nposition_m = [0.0, 0.0, 1000.0]\nspokes = 1024\nmax_range_m = 1500.0\n");
    let (sim, frame) = render_text(&text, 3);
    let radar = sim.scene().radar();
    let ant = &radar.antenna();
    let beam = |bw: f64| two_way_beam_integral_rad(bw);
    let eta = xbandsim::environment::rain::volume_reflectivity_m2_per_m3(
        rate_mm_per_h,
        radar.wavelength_m(),
    );
    let gamma = xbandsim::propagation::specific_attenuation_db_per_km(
        radar.carrier_freq_hz() / 1e9,
        rate_mm_per_h,
        true,
    );
    let expected_db = |n: usize| {
        let r = n as f64 * radar.range_bin_m();
        let volume = r
            * r
            * beam(ant.az_beamwidth_rad)
            * beam(ant.el_beamwidth_rad)
            * SPEED_OF_LIGHT_M_PER_S
            / (2.0 * radar.chirp().bandwidth_hz);
        linear_to_db(radar.point_target_snr(eta * volume, r)) - 2.0 * gamma * r / 1000.0
    };
    assert!(
        bin >= 20,
        "rain_clutter_power_db averages bins bin ± 20: bin {bin} is too near"
    );
    let bins = bin - 20..=bin + 20;
    let ratio = bins
        .clone()
        .map(|n| {
            let mean = (0..frame.spokes)
                .map(|k| 10f64.powf(spoke(&frame, k)[n] as f64 / 10.0))
                .sum::<f64>()
                / frame.spokes as f64;
            mean / 10f64.powf(expected_db(n) / 10.0)
        })
        .sum::<f64>()
        / bins.count() as f64;
    (expected_db(bin), expected_db(bin) + linear_to_db(ratio))
}

/// Whether a point target (h 9 m, radar 16 m) at `ground_range_m` returns an echo and is
/// labelled visible.
pub fn horizon_echo(ground_range_m: f64) -> (bool, xbandsim::products::labels::Visibility) {
    let text = format!("[environment]\nnoise = false\nclutter = false\nmultipath = false\n[radar]\nposition_m = [0.0, 0.0, 16.0]\nmax_range_m = 31000.0\nspokes = 4\nsample_rate_mhz = 50.0\nbandwidth_mhz = 25.0\n[[object]]\nname = \"p\"\nshape = \"point\"\nrcs_m2 = 1e6\nposition_m = [0.0, {ground_range_m}, 9.0]\n");
    let (sim, frame) = render_text(&text, 1);
    (
        !sim.trace().contributions.is_empty(),
        frame.truth[0].visibility,
    )
}

/// The checks of this area, in the order `xbandsim validate` prints them.
pub(crate) fn checks(out: &mut Checks) {
    // Sea clutter and rain.
    out.push(check(
        "NRL σ0 check value: SS 2, 10°, 30 GHz, HH",
        -36.66,
        xbandsim::environment::clutter::nrl_sigma0_db(30.0, 2.0, true, 10.0),
        "dB",
        Tolerance::Absolute(0.01),
        "Gregers-Hansen & Mital, IEEE TAES 48(4), 2012",
    ));
    for range_m in [600.0, 1200.0] {
        let (e, m) = clutter_mean_power_db(3.0, range_m);
        out.push(check(
            &format!("mean clutter power = σ0·A_c·radar equation ({range_m:.0} m, SS 3)"),
            e,
            m,
            "dB",
            Tolerance::Absolute(0.3),
            "radar equation with σ = σ0·A_c (Skolnik 2001, §7.4)",
        ));
    }
    for (label, lines, source) in [
        (
            "K, ν = 1.5: 2(1+1/ν)",
            "clutter_shape_nu = 1.5",
            "Ward, Tough & Watts, Sea Clutter, 2006, §6",
        ),
        (
            "K, default ν (Ward's empirical ν per cell): 2(1+⟨1/ν⟩)",
            "",
            "Ward, Tough & Watts, Sea Clutter, 2006, §6",
        ),
        (
            "Weibull amplitude c = 1.5: Γ(1+4/c)/Γ(1+2/c)²",
            "clutter_distribution = \"weibull\"\nclutter_weibull_shape = 1.5",
            "Sekine & Mao, Weibull Radar Clutter, 1990",
        ),
        (
            "log-normal texture 3 dB: 2·exp(s²)",
            "clutter_distribution = \"lognormal\"\nclutter_lognormal_sigma_db = 3.0",
            "compound log-normal texture × speckle",
        ),
    ] {
        let st = clutter_cell_statistics(lines, CLUTTER_FRAMES);
        out.push(check(
            &format!(
                "clutter cells after the matched filter, defaults, {label} ({:.1} M cells)",
                st.cells as f64 / 1e6
            ),
            st.expected_moment,
            st.measured_moment,
            "",
            Tolerance::Relative(CLUTTER_MOMENT_TOLERANCE),
            source,
        ));
    }
    let (kh, ah, _, _) = xbandsim::propagation::itu_p838_coefficients(10.0);
    out.push(check(
        "ITU-R P.838-3 k_H at 10 GHz",
        0.01217,
        kh,
        "",
        Tolerance::Relative(0.005),
        "ITU-R P.838-3, Table 5",
    ));
    out.push(check(
        "ITU-R P.838-3 α_H at 10 GHz",
        1.2571,
        ah,
        "",
        Tolerance::Relative(0.001),
        "ITU-R P.838-3, Table 5",
    ));
    let (e, m) = rain_attenuation_db(16.0);
    out.push(check(
        "two-way rain attenuation 2γR, 16 mm/h, 3 km",
        e,
        m,
        "dB",
        Tolerance::Absolute(0.05),
        "ITU-R P.838-3",
    ));
    let (e, m) = rain_clutter_power_db(8.0, 700);
    out.push(check(
        "rain clutter power = η·V·radar equation (8 mm/h, 1 km)",
        e,
        m,
        "dB",
        Tolerance::Absolute(0.15),
        "Doviak & Zrnić, eq. 4.34; Z = 200R^1.6",
    ));
    let horizon_km = 4.12 * (16f64.sqrt() + 9f64.sqrt());
    let (echo_in, vis_in) = horizon_echo(horizon_km * 1000.0 * 0.98);
    let (echo_out, vis_out) = horizon_echo(horizon_km * 1000.0 * 1.02);
    let both = echo_in
        && !echo_out
        && vis_in == xbandsim::products::labels::Visibility::Visible
        && vis_out == xbandsim::products::labels::Visibility::BeyondHorizon;
    out.push(check(
        "horizon 4.12(√h1+√h2) km: echo at 0.98×, none at 1.02× (h 16 m / 9 m)",
        1.0,
        if both { 1.0 } else { 0.0 },
        "",
        Tolerance::Absolute(0.0),
        "Skolnik 2001, §8.2 (4/3 earth)",
    ));
    out.push(check(
        "radar horizon of a 16 m mast",
        4.12 * 4.0,
        xbandsim::propagation::horizon_distance_m(16.0) / 1000.0,
        "km",
        Tolerance::Relative(0.002),
        "Skolnik 2001, §8.2",
    ));
}

/// The two-way azimuth integral `∫Gn²(θ)dθ` of the sinc² pattern of beamwidth `bw`, rad.
fn two_way_beam_integral_rad(bw: f64) -> f64 {
    Pattern::sinc2(bw).two_way_integral_rad()
}
