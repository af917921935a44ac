//! Signal-chain checks: range bin of a point target, compressed-pulse width, nulls and
//! sidelobes per window, the noise floor, single-pulse SNR against the radar equation, the
//! calibration of a scattering object and eclipsing (docs/validation.md).

use crate::harness::*;
use crate::{check, Checks, Tolerance};
use xbandsim::constants::{linear_to_db, SPEED_OF_LIGHT_M_PER_S};
use xbandsim::scattering::rcs::{RcsSettings, RcsTarget};

/// A noise-free compressed profile of a 1 m² point target beyond c·T/2, finely sampled
/// (800 MHz: 0.19 m bins), with `window` and a 10 µs pulse (B·T = 500): (profile, bin m).
pub fn fine_profile(window: &str) -> (Vec<f32>, f64) {
    let fs_mhz = 800.0;
    let range = bin_range_m(12000.0, fs_mhz * 1e6);
    let text = format!(
        "{}{}",
        radar_block_no_noise(&format!("sample_rate_mhz = {fs_mhz}\npulse_width_us = 10.0\nwindow = \"{window}\"\nmax_range_m = 2400.0\nspokes = 90")),
        point_north("p", range, 1.0)
    );
    let (_, frame) = render_text(&text, 1);
    (spoke(&frame, 0).to_vec(), frame.range_bin_m)
}

/// A 10⁴ m² point target at 8.1 km on a bin centre: (radar-equation SNR with the window
/// loss, measured peak), dB. The peak is that of a noise-free render, in the record's unit
/// (the noise power: [`noise_mean_db`] checks that the noise has it), so the signal's
/// calibration is checked on its own: with noise on, one pulse's peak `|s + n|²` at this
/// SNR spreads by 0.34 dB rms from realisation to realisation (40 seeds), more than the
/// check's tolerance.
pub fn snr_error_db(window: &str, pulse_us: f64) -> (f64, f64) {
    let range_m = bin_range_m(5400.0, 100e6);
    let text = format!(
        "{}{}",
        radar_block_no_noise(&format!(
            "window = \"{window}\"\npulse_width_us = {pulse_us}\nmax_range_m = 9000.0"
        )),
        point_north("p", range_m, 1e4)
    );
    let (sim, frame) = render_text(&text, 1);
    let radar = sim.scene().radar();
    let expected = linear_to_db(
        radar.point_target_snr(1e4, range_m)
            * radar.window().snr_loss_linear(radar.chirp().num_samples()),
    );
    let (_, measured) = argmax(&spoke(&frame, 0)[5300..5500]);
    (expected, measured as f64)
}

/// Mean noise power over all spokes past the blanked interval, dB.
pub fn noise_mean_db(seed: u64) -> f64 {
    let (sim, frame) = render_text(&radar_block("max_range_m = 1500.0"), seed);
    let start = sim.compressor().pulse_len() + 2;
    let (mut sum, mut n) = (0.0, 0usize);
    for k in 0..frame.spokes {
        for &d in &spoke(&frame, k)[start..] {
            sum += 10f64.powf(d as f64 / 10.0);
            n += 1;
        }
    }
    linear_to_db(sum / n as f64)
}

/// Peak (dB) of a noise-free 1 m² point target at range bin `bin` with a 2 µs pulse and
/// the matched-filter `window`, and its truth.
pub fn eclipse_peak_db(
    bin: f64,
    blanking: bool,
    window: &str,
) -> (f32, xbandsim::products::labels::ObjectTruth) {
    let fs = 100e6;
    let range_m = bin_range_m(bin, fs);
    let text = format!(
        "{}{}",
        radar_block_no_noise(&format!(
            "pulse_width_us = 2.0\nmax_range_m = 600.0\nreceiver_blanking = {blanking}\nwindow = \"{window}\""
        )),
        point_north("p", range_m, 1.0)
    );
    let (_, frame) = render_text(&text, 1);
    let j = bin.round() as usize;
    (
        spoke(&frame, 0)[j - 2..=j + 2]
            .iter()
            .cloned()
            .fold(f32::MIN, f32::max),
        frame.truth[0].clone(),
    )
}

/// A free-space trihedral (edge 0.5 m) facing the radar on spoke 0 at a bin-centred range:
/// (radar-equation SNR with the RCS from `xbandsim rcs`'s code, measured peak), dB. Noise
/// off, as in [`snr_error_db`] (with it, the peak spreads by about 0.17 dB rms at 31 dB).
pub fn object_snr_db(two_way_attenuation_db_per_km: f64) -> (f64, f64) {
    let range_m = bin_range_m(1400.0, 100e6);
    let text = format!(
        "[environment]\nnoise = false\nmultipath = false\nclutter = false\ntwo_way_attenuation_db_per_km = {two_way_attenuation_db_per_km}\n[radar]\nposition_m = [0.0, 0.0, 4.0]\nmax_range_m = 2500.0\n[[object]]\nname = \"t\"\nshape = \"trihedral\"\nedge_m = 0.5\nposition_m = [0.0, {range_m}, 4.0]\nyaw_deg = 180.0\n"
    );
    let (sim, frame) = render_text(&text, 11);
    let scene = sim.scene();
    let radar = scene.radar();
    let obj = &scene.objects()[0];
    // Range and aspect of the reflector's phase reference: its RCS is computed with the
    // object alone under a plane wave from the radar's direction.
    let target = RcsTarget::new(obj);
    let rcs = target.rcs_m2(
        0.0,
        0.0,
        &RcsSettings {
            freq_hz: radar.carrier_freq_hz(),
            polarisation: radar.polarisation(),
            ray_spacing_wavelengths: scene.scattering().ray_spacing_wavelengths(),
            max_rays: scene.scattering().max_rays_per_object(),
            max_bounces: scene.scattering().max_bounces(),
        },
    );
    let centre_range = (obj.bounding_centre_m() - radar.position_m()).length();
    let expected = linear_to_db(
        radar.point_target_snr(rcs, centre_range)
            * scene.environment().attenuation_power(centre_range),
    );
    let row = spoke(&frame, 0);
    let j = (centre_range / radar.range_bin_m()).round() as usize;
    let measured = row[j - 3..j + 4].iter().cloned().fold(f32::MIN, f32::max) as f64;
    (expected, measured)
}

/// The checks of this area, in the order `xbandsim validate` prints them.
pub(crate) fn checks(out: &mut Checks) {
    let c = SPEED_OF_LIGHT_M_PER_S;
    let b = 50e6;
    const RICHARDS: &str = "Richards, Fundamentals of Radar Signal Processing, 2nd ed., §4.6";
    const SKOLNIK: &str = "Skolnik, Introduction to Radar Systems, 3rd ed., eq. 2.51";

    // Range bin of a point target.
    let range_m = 777.7;
    let text = format!(
        "{}{}",
        radar_block_no_noise("max_range_m = 1500.0"),
        point_north("p", range_m, 10.0)
    );
    let (sim, frame) = render_text(&text, 1);
    let expected_bin = 2.0 * range_m / c * sim.scene().radar().sample_rate_hz();
    out.push(check(
        "point target range bin (777.7 m)",
        expected_bin,
        argmax(spoke(&frame, 0)).0 as f64,
        "bin",
        Tolerance::Absolute(0.5),
        "τ = 2R/c, bin = τ·fs",
    ));

    // Compressed pulse: IRW, first null, PSLR.
    let (p, bin_m) = fine_profile("none");
    let (peak, _) = argmax(&p);
    out.push(check(
        "3-dB width 0.886·c/2B (B = 50 MHz)",
        0.886 * c / (2.0 * b),
        width_at_db(&p, peak, 3.0103) * bin_m,
        "m",
        Tolerance::Relative(0.03),
        RICHARDS,
    ));
    out.push(check(
        "first null at c/2B",
        c / (2.0 * b),
        first_null_bins(&p, peak) as f64 * bin_m,
        "m",
        Tolerance::Relative(0.03 + bin_m / (c / (2.0 * b))),
        RICHARDS,
    ));
    out.push(check(
        "PSLR, no window",
        -13.26,
        pslr_db(&p) as f64,
        "dB",
        Tolerance::Absolute(0.5),
        RICHARDS,
    ));
    let (p, _) = fine_profile("hamming");
    out.push(check(
        "PSLR, Hamming (window transform −42.7 dB)",
        -42.7,
        pslr_db(&p) as f64,
        "dB",
        Tolerance::AtMost(-40.0),
        "Harris, Proc. IEEE 66(1), 1978",
    ));
    let (p, _) = fine_profile("taylor");
    out.push(check(
        "PSLR, Taylor n̄=4, −35 dB",
        -35.0,
        pslr_db(&p) as f64,
        "dB",
        Tolerance::Absolute(0.5),
        "Carrara et al., Spotlight SAR, App. D",
    ));

    // Noise and SNR.
    out.push(check(
        "noise floor k·T0·F·fs (mean over noise)",
        0.0,
        noise_mean_db(7),
        "dB",
        Tolerance::Absolute(0.1),
        "Skolnik, Radar Handbook, 3rd ed., §2.3",
    ));
    for (w, t) in [("none", 1.0), ("hamming", 1.0), ("taylor", 5.0)] {
        let (e, m) = snr_error_db(w, t);
        out.push(check(
            &format!("single-pulse SNR = radar equation ({w}, {t} us, 10⁴ m², 8.1 km)"),
            e,
            m,
            "dB",
            Tolerance::Absolute(0.05),
            SKOLNIK,
        ));
    }

    // Calibration of a scattering object: SNR from the radar equation with its PO RCS.
    let (e, m) = object_snr_db(0.0);
    out.push(check(
        "trihedral (a = 0.5 m, 2.1 km) SNR = radar equation with its PO RCS",
        e,
        m,
        "dB",
        Tolerance::Absolute(0.05),
        SKOLNIK,
    ));
    let (e2, m2) = object_snr_db(1.5);
    out.push(check(
        "two-way attenuation 1.5 dB/km over 2.1 km",
        e2 - e,
        m2 - m,
        "dB",
        Tolerance::Absolute(0.1),
        "uniform specific attenuation",
    ));

    // Eclipsing: τ = T/2 keeps half the chirp → −6.02 dB; the label carries the loss.
    let (blanked, truth) = eclipse_peak_db(100.0, true, "none");
    let half = blanked - eclipse_peak_db(100.0, false, "none").0;
    out.push(check(
        "eclipsing loss at τ = T/2: 20·log10(τ/T)",
        -6.0206,
        half as f64,
        "dB",
        Tolerance::Absolute(0.02),
        "blanking while transmitting (docs/physics.md, Eclipsing)",
    ));
    out.push(check(
        "eclipse loss in the label = measured loss at τ = 0.3T, Hamming",
        {
            let (b, _) = eclipse_peak_db(60.0, true, "hamming");
            (eclipse_peak_db(60.0, false, "hamming").0 - b) as f64
        },
        eclipse_peak_db(60.0, true, "hamming")
            .1
            .losses_db
            .eclipse
            .unwrap_or(f64::NAN),
        "dB",
        Tolerance::Absolute(0.02),
        "Σ of the window over the received tail / Σ of the window",
    ));
    let _ = truth;
}
