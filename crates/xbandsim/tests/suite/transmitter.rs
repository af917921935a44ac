//! Transmitters: a magnetron's unmodulated pulse of random start phase beside the solid-state
//! set's coherent chirp (docs/physics.md §4).

use crate::common::{point_north, radar_block_no_noise, scene};
use xbandsim::engine::{Request, Simulation};
use xbandsim::Problem;

/// The peak power of the target's echo on spokes 0 and 1 of each frame (dB over noise), for
/// integration `integration` of a magnetron or a solid-state set's dwells.
fn target_peaks(transmitter: &str, integration: &str, frames: u64) -> Vec<f64> {
    let text = format!(
        "{}[processing]\nmode = \"pulse\"\nintegration = \"{integration}\"\n{}",
        radar_block_no_noise(&format!(
            "transmitter = \"{transmitter}\"\npulse_width_us = 0.5\nmax_range_m = 1500.0\n\
             spokes = 90\nprf_hz = 2400.0"
        )),
        point_north("p", 900.0, 100.0)
    );
    let sim = Simulation::new(scene(&text));
    let mut peaks = Vec::new();
    for frame in 0..frames {
        let f = sim.run(&Request::new(7).frame(frame)).unwrap();
        for k in [0usize, 1] {
            let row = &f.polar_db[k * f.range_bins..(k + 1) * f.range_bins];
            let peak = row.iter().copied().fold(f32::MIN, f32::max);
            peaks.push(f64::from(peak));
        }
    }
    peaks
}

fn mean_linear(db: &[f64]) -> f64 {
    db.iter().map(|d| 10f64.powf(d / 10.0)).sum::<f64>() / db.len() as f64
}

/// Pulses of random start phase do not add coherently: the mean of `|Σ y_m|²/M` over dwells
/// is the mean pulse power `Σ|y_m|²/M` (the cross terms average to zero, `E[e^{j(φ_m − φ_n)}] =
/// 0`), where the solid-state set's coherent pulses gain about M (Richards, *Fundamentals of
/// Radar Signal Processing*, 2nd ed., 2014: the coherent integration gain). 2 spokes × 48 frames:
/// the magnetron's ratio is 1 within ±1.5 dB (about ±4σ of a mean of 96 exponential draws).
#[test]
fn magnetron_pulses_do_not_integrate_coherently() {
    let frames = 48;
    let m_coherent = mean_linear(&target_peaks("magnetron", "coherent", frames));
    let m_power = mean_linear(&target_peaks("magnetron", "noncoherent", frames));
    let ratio_db = 10.0 * (m_coherent / m_power).log10();
    assert!(
        ratio_db.abs() < 1.5,
        "magnetron coherent/noncoherent = {ratio_db:.2} dB"
    );
    let s_coherent = mean_linear(&target_peaks("solid_state", "coherent", 2));
    let s_power = mean_linear(&target_peaks("solid_state", "noncoherent", 2));
    // 2400 Hz at 24 rpm over 90 spokes: about 67 pulses a dwell, 18 dB; the beam's scan over
    // the dwell costs a little of it.
    let gain_db = 10.0 * (s_coherent / s_power).log10();
    assert!(gain_db > 15.0, "solid-state coherent gain {gain_db:.2} dB");
}

/// A magnetron's pulse is unmodulated: its range resolution is its length c·T/2, and a swept
/// bandwidth or the combined pulse mode is refused naming the field.
#[test]
fn magnetron_fields_are_checked() {
    let ok = scene(&radar_block_no_noise(
        "transmitter = \"magnetron\"\npulse_width_us = 0.5",
    ));
    assert!((ok.radar().range_resolution_m() - 74.9481145).abs() < 1e-6);
    assert_eq!(ok.radar().chirp().bandwidth_hz, 0.0);
    for (extra, field) in [
        ("bandwidth_mhz = 20.0", "radar.bandwidth_mhz"),
        ("pulse_mode = \"combined\"", "radar.pulse_mode"),
    ] {
        let text = radar_block_no_noise(&format!("transmitter = \"magnetron\"\n{extra}"));
        let e = xbandsim::model::Scene::from_toml_str(&text, "test").unwrap_err();
        assert_eq!(e.field(), Some(field), "{e}");
        assert_eq!(e.problem(), Some(Problem::Conflict), "{e}");
    }
    let text = radar_block_no_noise("transmitter = \"klystron\"");
    let e = xbandsim::model::Scene::from_toml_str(&text, "test").unwrap_err();
    assert!(e.to_string().contains("transmitter"), "{e}");
}
