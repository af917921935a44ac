//! Pulse-mode and Doppler checks: the range-Doppler cube, blind speeds, Doppler resolution,
//! the LFM range–Doppler coupling, integration gains and the rotating beam's azimuth spread,
//! measured through the real pipeline against closed forms (docs/validation.md).

use crate::harness::*;
use crate::{check, Checks, Tolerance};
use xbandsim::antenna::sinc2_pattern;
use xbandsim::constants::{linear_to_db, SPEED_OF_LIGHT_M_PER_S};
use xbandsim::engine::Request;
use xbandsim::engine::{Outputs, Schedule};
use xbandsim::model::Scene;
use xbandsim::{Frame, Simulation};

/// A noise-free pulse-mode scene head: no sea, 360 spokes, PRF `prf_hz`, `extra` radar and
/// processing lines.
fn pulse_head(prf_hz: f64, radar_extra: &str, processing: &str) -> String {
    format!("[environment]\nmultipath = false\nclutter = false\nnoise = false\n[radar]\npreset = \"drs4d-nxt\"\nposition_m = [0.0, 0.0, 4.0]\nspokes = 360\nprf_hz = {prf_hz}\n{radar_extra}\n[processing]\nmode = \"pulse\"\n{processing}\n")
}

/// A point target at `range_m` on bearing `az_deg`, radial velocity `radial_mps` (positive
/// opening), at the antenna's height.
fn point_at(range_m: f64, az_deg: f64, radial_mps: f64) -> String {
    let (s, c) = (az_deg.to_radians().sin(), az_deg.to_radians().cos());
    format!("[[object]]\nname = \"p\"\nshape = \"point\"\nrcs_m2 = 10.0\nposition_m = [{}, {}, 4.0]\nvelocity_mps = [{}, {}, 0.0]\n", range_m * s, range_m * c, radial_mps * s, radial_mps * c)
}

/// Renders frame 0 of scene TOML with the Doppler cube.
pub fn render_pulse(text: &str) -> (Simulation, Frame) {
    let scene = Scene::from_toml_str(text, "validation").expect("validation scene is valid");
    let sim = Simulation::new(scene);
    let frame = sim
        .run(&Request::new(1).outputs(Outputs {
            doppler_cube: true,
            ..Default::default()
        }))
        .expect("pulse mode gives a cube");
    (sim, frame)
}

/// Vertex offset of the parabola through three samples around a peak.
fn vertex(a: f64, b: f64, c: f64) -> f64 {
    let den = a - 2.0 * b + c;
    if den < 0.0 {
        (0.5 * (a - c) / den).clamp(-0.5, 0.5)
    } else {
        0.0
    }
}

/// The strongest polar cell near the object's truth position: (spoke, bin).
fn target_cell(frame: &Frame) -> (usize, usize) {
    let t = &frame.truth[0];
    let k0 = (t.azimuth_deg / (360.0 / frame.spokes as f64)).round() as i64;
    let j0 = (t.range_m / frame.range_bin_m).round() as usize;
    let mut best = (0, 0, f32::MIN);
    for k in k0 - 3..=k0 + 3 {
        let k = k.rem_euclid(frame.spokes as i64) as usize;
        let row = spoke(frame, k);
        for (j, &v) in row
            .iter()
            .enumerate()
            .take(j0 + 20)
            .skip(j0.saturating_sub(20))
        {
            if v > best.2 {
                best = (k, j, v);
            }
        }
    }
    (best.0, best.1)
}

/// Measured Doppler of the target (parabolic interpolation of the dB spectrum, circular), Hz,
/// and the truth's Doppler, Hz.
pub fn measured_doppler_hz(frame: &Frame) -> (f64, f64) {
    let cube = frame.doppler_cube.as_ref().expect("cube");
    let (k, j) = target_cell(frame);
    let s = cube.spectrum(k, j);
    let m = s.len();
    let d = s
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(b.1))
        .map(|(i, _)| i)
        .unwrap();
    let off = vertex(
        s[(d + m - 1) % m] as f64,
        s[d] as f64,
        s[(d + 1) % m] as f64,
    );
    (
        cube.doppler_hz(d) + off * cube.doppler_bin_hz,
        frame.truth[0].doppler_hz,
    )
}

/// The aliased frequency of `f` in [−PRF/2, PRF/2).
pub fn alias_hz(f: f64, prf_hz: f64) -> f64 {
    (f + prf_hz / 2.0).rem_euclid(prf_hz) - prf_hz / 2.0
}

/// Slant range of the compressed peak of the target's spoke, by parabolic interpolation, m.
fn peak_range_m(frame: &Frame) -> f64 {
    let (k, j) = target_cell(frame);
    let r = spoke(frame, k);
    (j as f64 + vertex(r[j - 1] as f64, r[j] as f64, r[j + 1] as f64)) * frame.range_bin_m
}

/// LFM range–Doppler coupling with B = 5 MHz, T = 20 µs, a target closing at 30 m/s at
/// 4.5 km: (measured shift of its compressed peak against a still target's, m; the closed
/// form −c·f_D·T/(2B), m).
pub fn lfm_coupling_shift_m() -> (f64, f64) {
    let radar = "bandwidth_mhz = 5.0\npulse_width_us = 20.0\nmax_range_m = 6000.0";
    let shift = |v: f64| {
        let text = format!(
            "{}{}",
            pulse_head(2000.0, radar, "integration = \"none\""),
            point_at(4500.0, 45.0, v)
        );
        let (_, f) = render_pulse(&text);
        (peak_range_m(&f) - f.truth[0].range_m, f.truth[0].doppler_hz)
    };
    let (still, _) = shift(0.0);
    let (moving, f_d) = shift(-30.0);
    (
        moving - still,
        SPEED_OF_LIGHT_M_PER_S / 2.0 * lfm_peak_delay_s(f_d, 5e6, 20e-6),
    )
}

/// Delay of the peak of the LFM ambiguity function at Doppler `f_d` (bandwidth `b_hz`,
/// duration `t_s`, up-chirp): the τ that maximises
/// `|χ(τ, f_D)| = (1 − |τ|/T)·|sinc((f_D + kτ)(T − |τ|))|`, k = B/T (Richards 2014, §4.6).
/// On the ridge τ ≈ −f_D/k; the triangle factor pulls the peak slightly toward 0. Found by
/// golden-section search within ±1/B of −f_D/k.
pub fn lfm_peak_delay_s(f_d: f64, b_hz: f64, t_s: f64) -> f64 {
    let k = b_hz / t_s;
    let chi = |tau: f64| {
        let x = std::f64::consts::PI * (f_d + k * tau) * (t_s - tau.abs());
        let sinc = if x.abs() < 1e-12 { 1.0 } else { x.sin() / x };
        (1.0 - tau.abs() / t_s) * sinc.abs()
    };
    let (mut lo, mut hi) = (-f_d / k - 1.0 / b_hz, -f_d / k + 1.0 / b_hz);
    let r = (5f64.sqrt() - 1.0) / 2.0;
    for _ in 0..200 {
        let a = hi - r * (hi - lo);
        let b = lo + r * (hi - lo);
        if chi(a) < chi(b) {
            lo = a;
        } else {
            hi = b;
        }
    }
    0.5 * (lo + hi)
}

/// The two-way azimuth pattern (power) of the pulses of `spoke`'s dwell on a still target at
/// bearing `az_rad`: `g_m = sinc²(az_m − az)` one way, squared.
fn dwell_pattern(sim: &Simulation, spoke_k: usize, az_rad: f64) -> Vec<f64> {
    let radar = sim.scene().radar();
    let bw = radar.antenna().az_beamwidth_rad;
    let schedule = Schedule::pulse_scan(radar, 0);
    let dwell = schedule
        .dwells()
        .iter()
        .find(|d| d.spoke == spoke_k)
        .unwrap();
    dwell
        .pulses
        .iter()
        .map(|p| {
            sinc2_pattern(
                xbandsim::antenna::wrap_angle_rad(p.azimuth_rad - az_rad),
                bw,
            )
            .powi(2)
        })
        .collect()
}

/// A target closing at `factor·λ·PRF/2` (PRF 1 kHz, `stagger` radar line) on bearing 45°,
/// coherently integrated: its peak over the same target still, dB, measured and expected
/// `|Σ√g_m·e^{jφ_m}|²/|Σ√g_m|²` (`φ_m = 4π·v·t_m/λ` at the dwell's pulse times). The target
/// starts where it reaches 600 m when the beam crosses it, so both are at the same range.
pub fn stagger_coherent_response_db(stagger: &str, factor: f64) -> (f64, f64) {
    let lambda = SPEED_OF_LIGHT_M_PER_S / 9.41e9;
    let prf = 1000.0;
    let v = -factor * lambda * prf / 2.0;
    let beam_time_s = 45.0 / 360.0 * 60.0 / 24.0;
    let radar = format!(
        "max_range_m = 1200.0
{stagger}"
    );
    let coherent = "integration = \"coherent\"";
    let (sim, moving) = render_pulse(&format!(
        "{}{}",
        pulse_head(prf, &radar, coherent),
        point_at(600.0 - v * beam_time_s, 45.0, v)
    ));
    let (_, still) = render_pulse(&format!(
        "{}{}",
        pulse_head(prf, &radar, coherent),
        point_at(600.0, 45.0, 0.0)
    ));
    let (k, j) = target_cell(&still);
    let (km, jm) = target_cell(&moving);
    let measured = (spoke(&moving, km)[jm] - spoke(&still, k)[j]) as f64;
    let scan = sim.scene().radar();
    let schedule = Schedule::pulse_scan(scan, 0);
    let dwell = schedule.dwells().iter().find(|d| d.spoke == k).unwrap();
    let g = dwell_pattern(&sim, k, 45f64.to_radians());
    let mut sum = num_complex::Complex64::new(0.0, 0.0);
    for (p, gm) in dwell.pulses.iter().zip(&g) {
        let phase = -2.0 * std::f64::consts::TAU * v * p.time_s / lambda;
        sum += num_complex::Complex64::from_polar(gm.sqrt(), phase);
    }
    let still_sum: f64 = g.iter().map(|x| x.sqrt()).sum();
    (
        measured,
        linear_to_db(sum.norm_sqr() / (still_sum * still_sum)),
    )
}

/// Sea clutter's Doppler spectrum looking upwind (sea state 4, HH, Rayleigh, no noise; 3 rpm
/// so that a 128-pulse CPI resolves it): (measured centroid Hz, width Hz; expected centroid Hz,
/// width Hz). Measured: the power-weighted mean and standard deviation of the Doppler axis over
/// the cube's spectra averaged over 3 spokes × 200 range cells. Expected: the same moments of
/// the expected periodogram `E|Y_d|² = Σ_{m,m'} w_m·w_m'·R((m − m')·PRI)·e^{−j2πd(m−m')/M}` of
/// a Gaussian spectrum, `R(τ) = exp(j2π·f̄·τ − 2π²σ_f²τ²)`, f̄ = 2·v̄/λ, σ_f = 2σ_v/λ.
pub fn sea_clutter_doppler_moments() -> ((f64, f64), (f64, f64)) {
    let text = "[environment]
multipath = false
noise = false
sea_state = 4
wind_direction_deg = 88.0
clutter_distribution = \"rayleigh\"
[radar]
position_m = [0.0, 0.0, 10.0]
spokes = 90
rotation_rpm = 3.0
prf_hz = 1000.0
max_range_m = 450.0
[processing]
mode = \"pulse\"
doppler_pulses = 128
";
    let (sim, frame) = render_pulse(text);
    let cube = frame.doppler_cube.as_ref().unwrap();
    let m = cube.doppler_bins;
    let mut mean_spectrum = vec![0f64; m];
    for k in 21..=23 {
        for j in 100..300 {
            for (acc, v) in mean_spectrum.iter_mut().zip(cube.spectrum(k, j)) {
                *acc += 10f64.powf(v as f64 / 10.0);
            }
        }
    }
    let moments = |p: &[f64]| {
        let total: f64 = p.iter().sum();
        let c: f64 = p
            .iter()
            .enumerate()
            .map(|(d, v)| cube.doppler_hz(d) * v)
            .sum::<f64>()
            / total;
        let var: f64 = p
            .iter()
            .enumerate()
            .map(|(d, v)| (cube.doppler_hz(d) - c).powi(2) * v)
            .sum::<f64>()
            / total;
        (c, var.sqrt())
    };
    let doppler = sim.scene().environment().clutter_doppler();
    let lambda = sim.scene().radar().wavelength_m();
    let (f_mean, f_sigma) = (
        2.0 * doppler.sea_velocity_mps / lambda,
        2.0 * doppler.sea_spread_mps / lambda,
    );
    let pri = 1.0 / 1000.0;
    let w = sim.scene().processing().doppler_window().coefficients(m);
    let expected: Vec<f64> = (0..m)
        .map(|d| {
            let f_d = cube.doppler_hz(d);
            let mut acc = num_complex::Complex64::new(0.0, 0.0);
            for a in 0..m {
                for b in 0..m {
                    let tau = (a as f64 - b as f64) * pri;
                    let r = num_complex::Complex64::from_polar(
                        (-2.0 * std::f64::consts::PI.powi(2) * f_sigma * f_sigma * tau * tau).exp(),
                        std::f64::consts::TAU * (f_mean - f_d) * tau,
                    );
                    acc += r * w[a] * w[b];
                }
            }
            acc.re
        })
        .collect();
    (moments(&mean_spectrum), moments(&expected))
}

/// The checks of this area, in the order `xbandsim validate` prints them.
pub(crate) fn checks(out: &mut Checks) {
    const RICHARDS: &str = "Richards, Fundamentals of Radar Signal Processing, 2nd ed., 2014, §2.7 (f_D = 2v/λ), §5.2 (Doppler sampling, blind speeds), §4.6 (LFM range–Doppler coupling)";
    const HARRIS: &str =
        "Harris, Proc. IEEE 66(1), 1978: scalloping loss of the rectangular window −3.92 dB";
    const SKOLNIK: &str =
        "Skolnik, Introduction to Radar Systems, 3rd ed., 2001, §2.6 (integration of pulses)";

    // Doppler of a moving point target.
    let text = format!(
        "{}{}",
        pulse_head(3000.0, "max_range_m = 1200.0", "doppler_pulses = 16"),
        point_at(600.0, 45.0, -8.0)
    );
    let (_, frame) = render_pulse(&text);
    let (measured, expected) = measured_doppler_hz(&frame);
    let bin_hz = frame.doppler_cube.as_ref().unwrap().doppler_bin_hz;
    out.push(check(
        "Doppler of a point target closing at 8 m/s, 2·v/λ (cube, 16 pulses, Hamming)",
        expected,
        measured,
        "Hz",
        Tolerance::Absolute(0.1 * bin_hz),
        RICHARDS,
    ));

    // First blind speed λ·PRF/2: the target's Doppler aliases to zero.
    let lambda = SPEED_OF_LIGHT_M_PER_S / 9.41e9;
    let blind = lambda * 3000.0 / 2.0;
    let text = format!(
        "{}{}",
        pulse_head(3000.0, "max_range_m = 1200.0", "doppler_pulses = 16"),
        point_at(600.0, 45.0, -blind)
    );
    let (_, frame) = render_pulse(&text);
    let (measured, _) = measured_doppler_hz(&frame);
    out.push(check(
        "target at the first blind speed λ·PRF/2 = 47.8 m/s (PRF 3 kHz): its Doppler aliases to 0",
        0.0,
        measured,
        "Hz",
        Tolerance::Absolute(0.1 * bin_hz),
        RICHARDS,
    ));

    // Doppler resolution 1/(M·PRI): half a bin off, the rectangular window scallops by
    // −3.92 dB.
    let on_bin = 3.0 * 3000.0 / 16.0 * lambda / 2.0;
    let half = 3.5 * 3000.0 / 16.0 * lambda / 2.0;
    let peak = |v: f64| {
        let text = format!(
            "{}{}",
            pulse_head(
                3000.0,
                "max_range_m = 1200.0",
                "doppler_pulses = 16\ndoppler_window = \"none\""
            ),
            point_at(600.0, 45.0, -v)
        );
        let (_, frame) = render_pulse(&text);
        let (k, j) = target_cell(&frame);
        // Peak over the spectrum's total power (Parseval: the total does not depend on the
        // tone's frequency, and the range straddle of the two renders cancels).
        let s = frame.doppler_cube.as_ref().unwrap().spectrum(k, j);
        let lin: Vec<f64> = s.iter().map(|&x| 10f64.powf(x as f64 / 10.0)).collect();
        linear_to_db(lin.iter().cloned().fold(0.0, f64::max) / lin.iter().sum::<f64>())
    };
    out.push(check(
        "Doppler bins 1/(M·PRI) apart: a tone half a bin off loses −3.92 dB (rectangular)",
        linear_to_db(1.0 / (16.0 * (std::f64::consts::PI / 32.0).sin()).powi(2)),
        peak(half) - peak(on_bin),
        "dB",
        Tolerance::Absolute(0.1),
        HARRIS,
    ));

    // LFM range–Doppler coupling.
    let (measured, expected) = lfm_coupling_shift_m();
    out.push(check(
        "LFM range–Doppler coupling: peak shift on the ambiguity ridge, ≈ −c·f_D·T/(2B) = −1.13 m (B = 5 MHz, T = 20 µs, 30 m/s)",
        expected,
        measured,
        "m",
        Tolerance::Absolute(0.03),
        RICHARDS,
    ));

    // Pulse mode on a still target: non-coherent integration keeps the single-pulse SNR
    // less the scan loss of the dwell; coherent integration adds 10·log10 M; the rotating
    // beam spreads the target over the spokes as the pattern predicts.
    let spoke_text = format!(
        "{}{}",
        radar_block_no_noise("spokes = 360\nprf_hz = 2000.0\nmax_range_m = 1200.0"),
        point_at(600.0, 45.0, 0.0)
    );
    let (_, spoke_frame) = render_text(&spoke_text, 1);
    let pulse_text = format!(
        "{}{}",
        pulse_head(2000.0, "max_range_m = 1200.0", ""),
        point_at(600.0, 45.0, 0.0)
    );
    let (sim, pulse_frame) = render_pulse(&pulse_text);
    let (k, j) = target_cell(&spoke_frame);
    let g = dwell_pattern(&sim, k, 45f64.to_radians());
    let m = g.len() as f64;
    let mean_g2: f64 = g.iter().sum::<f64>() / m;
    out.push(check(
        "pulse mode, non-coherent: peak − spoke mode's = scan loss 10·log10(mean G²) of the dwell",
        linear_to_db(mean_g2),
        (spoke(&pulse_frame, k)[j] - spoke(&spoke_frame, k)[j]) as f64,
        "dB",
        Tolerance::Absolute(0.02),
        SKOLNIK,
    ));
    let coherent_text = pulse_text.replace(
        "[processing]\n",
        "[processing]\nintegration = \"coherent\"\n",
    );
    let (_, coherent_frame) = render_pulse(&coherent_text);
    let mean_g: f64 = g.iter().map(|x| x.sqrt()).sum::<f64>() / m;
    out.push(check(
        &format!("coherent over non-coherent integration of M = {m} pulses: 10·log10(M·mean(G)²/mean(G²)) ≈ 10·log10 M = {:.2} dB", 10.0 * m.log10()),
        linear_to_db(m * mean_g * mean_g / mean_g2),
        (spoke(&coherent_frame, k)[j] - spoke(&pulse_frame, k)[j]) as f64,
        "dB",
        Tolerance::Absolute(0.02),
        SKOLNIK,
    ));
    // Blind speeds with and without a staggered PRF: coherent integration of a target at
    // the speed v against the same target still, |Σ√g_m·e^{jφ_m}|²/|Σ√g_m|² with
    // φ_m = 4π·v·t_m/λ over the dwell's pulse times t_m.
    for (stagger, factor, name) in [
        ("", 1.0, "no stagger, at the blind speed λ·PRF/2 = 15.9 m/s: blind (the same response as a still target)"),
        ("prf_stagger = [2.0, 3.0]", 1.0, "PRF stagger 2:3, at λ·PRF/2 = 15.9 m/s: no longer blind"),
        ("prf_stagger = [2.0, 3.0]", 2.5, "PRF stagger 2:3, at 2.5·λ·PRF/2 = 39.8 m/s, where both intervals are whole Doppler periods: blind"),
    ] {
        let (measured, expected) = stagger_coherent_response_db(stagger, factor);
        out.push(check(
            &format!("coherent response of a closing target over a still one: {name}"),
            expected,
            measured,
            "dB",
            Tolerance::Absolute(0.05),
            RICHARDS,
        ));
    }
    const WTW: &str = "Gaussian clutter spectrum with mean 2v̄/λ and spread 2σ_v/λ (Ward, Tough & Watts, Sea Clutter, 2nd ed., 2013, §2.6), windowed periodogram (Harris 1978)";
    let ((c_meas, w_meas), (c_exp, w_exp)) = sea_clutter_doppler_moments();
    out.push(check(
        "sea clutter looking upwind (sea state 4, HH): Doppler centroid 2·v̄/λ through the window",
        c_exp,
        c_meas,
        "Hz",
        Tolerance::Absolute(3.0),
        WTW,
    ));
    out.push(check(
        "sea clutter looking upwind: Doppler spectrum width, 2σ_v/λ through the window",
        w_exp,
        w_meas,
        "Hz",
        Tolerance::Relative(0.03),
        WTW,
    ));
    let peak_db = spoke(&pulse_frame, k)[j] as f64;
    let worst = (k - 4..=k + 4)
        .map(|kk| {
            let g = dwell_pattern(&sim, kk, 45f64.to_radians());
            let predicted = linear_to_db(g.iter().sum::<f64>() / g.len() as f64)
                + (spoke(&spoke_frame, k)[j] as f64);
            let measured = spoke(&pulse_frame, kk)[j] as f64;
            if measured > peak_db - 30.0 {
                (measured - predicted).abs()
            } else {
                0.0
            }
        })
        .fold(0.0, f64::max);
    out.push(check(
        "rotating beam: a still target's power over ±4 spokes = mean two-way pattern of each dwell (worst spoke)",
        0.0,
        worst,
        "dB",
        Tolerance::AtMost(0.05),
        "Balanis, Antenna Theory, 4th ed., §12.5 (sinc² pattern), averaged over each dwell's pulses",
    ));
}
