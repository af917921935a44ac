//! Combined pulse mode checks: a short pulse for the range bins inside the long pulse's
//! eclipse joined to the long LFM pulse beyond it, measured through the real pipeline against
//! the radar equation (docs/validation.md, docs/physics.md §11).

use crate::harness::*;
use crate::{check, Checks, Tolerance};
use xbandsim::constants::linear_to_db;

const RADAR_EQUATION: &str = "radar equation with pulse compression, SNR = Pt·τ·G²·λ²·σ/((4π)³·R⁴·k·T0·F·L) (Skolnik, Introduction to Radar Systems, 3rd ed., 2001, eq. 2.51); matched-filter peak gain Σw/√Σw² (Richards, Fundamentals of Radar Signal Processing, 2nd ed., 2014, §4.3)";

/// Combined-mode scene: rectangular window, 1 µs LFM long pulse (eclipse 150 m = bin 100),
/// 0.08 µs unmodulated short pulse, `spokes` spokes, noise on or off, and a 10 m² point target
/// at each `(bin, spoke)` at the antenna's height on that spoke's azimuth (36 spokes: 10°).
fn combined_scene(targets: &[(usize, usize)], noise: bool, spokes: usize) -> String {
    let radar = format!("spokes = {spokes}\nmax_range_m = 600.0\npulse_mode = \"combined\"\nshort_pulse_width_us = 0.08");
    let head = if noise {
        radar_block(&radar)
    } else {
        radar_block_no_noise(&radar)
    };
    let mut text = head;
    for (i, &(bin, k)) in targets.iter().enumerate() {
        let r = bin_range_m(bin as f64, 100e6);
        let az = (k as f64 * 10.0).to_radians();
        text.push_str(&format!(
            "[[object]]\nname = \"p{i}\"\nshape = \"point\"\nrcs_m2 = 10.0\nposition_m = [{}, {}, 4.0]\n",
            r * az.sin(),
            r * az.cos()
        ));
    }
    text
}

/// Measured peak minus the long pulse's radar-equation peak (window loss included), dB, for
/// point targets at bins 60 and 97 (short pulse) and 103 (long pulse): (short worst, long).
pub fn combined_calibration_error_db() -> (f64, f64) {
    let targets = [(60, 3), (97, 9), (103, 15)];
    let (sim, frame) = render_text(&combined_scene(&targets, false, 36), 1);
    let radar = sim.scene().radar();
    let n = radar.chirp().num_samples();
    let window_loss = radar.window().snr_loss_linear(n);
    let error = |&(bin, k): &(usize, usize)| {
        let r = bin_range_m(bin as f64, radar.sample_rate_hz());
        let expected = linear_to_db(radar.point_target_snr(10.0, r) * window_loss);
        spoke(&frame, k)[bin] as f64 - expected
    };
    let short = error(&targets[0]);
    let short2 = error(&targets[1]);
    let worst_short = if short.abs() > short2.abs() {
        short
    } else {
        short2
    };
    (worst_short, error(&targets[2]))
}

/// Mean noise power of the short pulse's bins over the long pulse's, dB, from a noise-only
/// combined-mode render (bins past each pulse's own blanking), and the closed form
/// `10·log10(N_long·L_long/(N_short·L_short))`. 4096 spokes: the short pulse's matched
/// filter correlates its noise over 8 bins, so its mean needs many cells (standard error
/// about 0.02 dB here).
pub fn combined_noise_step_db() -> (f64, f64) {
    let (sim, frame) = render_text(&combined_scene(&[], true, 4096), 3);
    let radar = sim.scene().radar();
    let short = radar.short_pulse().expect("combined mode");
    let n_short = short.chirp.num_samples();
    let n_long = radar.chirp().num_samples();
    let join = radar.join_bin();
    let mean = |lo: usize, hi: usize| {
        let mut sum = 0.0;
        let mut count = 0usize;
        for k in 0..frame.spokes {
            for &v in &spoke(&frame, k)[lo..hi] {
                sum += 10f64.powf(v as f64 / 10.0);
                count += 1;
            }
        }
        sum / count as f64
    };
    let measured = linear_to_db(mean(n_short, join) / mean(join + 1, frame.range_bins));
    let expected = linear_to_db(
        n_long as f64 * radar.window().snr_loss_linear(n_long)
            / (n_short as f64 * short.window.snr_loss_linear(n_short)),
    );
    (measured, expected)
}

/// The checks of this area, in the order `xbandsim validate` prints them.
pub(crate) fn checks(out: &mut Checks) {
    let (short, long) = combined_calibration_error_db();
    out.push(check(
        "combined pulse: point targets at 90 m and 145.5 m, inside the long pulse's 150 m eclipse, read the long pulse's radar-equation peak on the short pulse (no blind zone)",
        0.0,
        short,
        "dB",
        Tolerance::Absolute(0.05),
        RADAR_EQUATION,
    ));
    out.push(check(
        "combined pulse: a point target at 154.5 m, just past the join, reads the same calibration on the long pulse",
        0.0,
        long,
        "dB",
        Tolerance::Absolute(0.05),
        RADAR_EQUATION,
    ));
    let (measured, expected) = combined_noise_step_db();
    out.push(check(
        "combined pulse: noise of the short pulse's bins over the long pulse's, 10·log10(N_long·L_long/(N_short·L_short))",
        expected,
        measured,
        "dB",
        Tolerance::Absolute(0.1),
        RADAR_EQUATION,
    ));
}
