//! Raw I/Q, staggered PRF and combined pulse mode: the captured records compress to the
//! polar record through the naive matched filter; stagger times the pulses as its ratios say;
//! the short pulse removes the blind zone (labels included); bad settings are located errors
//! (docs/formats.md, docs/physics.md §10–§11).

use crate::common::scene;
use num_complex::{Complex32, Complex64};
use xbandsim::engine::Request;
use xbandsim::engine::{Outputs, Simulation};
use xbandsim::model::Scene;
use xbandsim::processing::direct_correlation;
use xbandsim::products::labels::{PulseChannel, Visibility};

const IQ_SPOKE: &str = "[radar]\nspokes = 36\nmax_range_m = 600.0\n[environment]\nclutter = false\nmultipath = false\n[[object]]\nname = \"t\"\nshape = \"point\"\nrcs_m2 = 5.0\nposition_m = [0.0, 300.0, 4.0]\n";

const IQ_PULSE: &str = "[radar]\nspokes = 90\nmax_range_m = 600.0\nprf_hz = 1200.0\n[environment]\nclutter = true\nsea_state = 3\nmultipath = false\n[processing]\nmode = \"pulse\"\n[[object]]\nname = \"t\"\nshape = \"point\"\nrcs_m2 = 5.0\nposition_m = [0.0, 300.0, 4.0]\nspeed_kn = 30.0\ncourse_deg = 180.0\n";

fn iq(outputs_sim: &Simulation) -> xbandsim::Frame {
    outputs_sim
        .run(&Request::new(2).outputs(Outputs {
            iq: true,
            ..Default::default()
        }))
        .expect("raw I/Q of a small scene")
}

/// Mean over the rows of spoke `k` of |naive matched filter|², against the polar record
/// (power in noise units), worst |difference| over the spoke relative to 1 + the power.
fn worst_mismatch(sim: &Simulation, frame: &xbandsim::Frame, k: usize) -> f64 {
    let radar = sim.scene().radar();
    let q = frame.iq.as_ref().unwrap();
    let bins = frame.range_bins;
    let mut power = vec![0f64; bins];
    let rows: Vec<usize> = (0..q.pulses).filter(|&r| q.spokes[r] == k).collect();
    for &r in &rows {
        let record: Vec<Complex64> = q.values[r * q.samples..(r + 1) * q.samples]
            .iter()
            .map(|c: &Complex32| Complex64::new(c.re as f64, c.im as f64))
            .collect();
        let y = direct_correlation(&record, radar.chirp(), radar.window(), bins);
        for (p, v) in power.iter_mut().zip(&y) {
            *p += v.norm_sqr() / rows.len() as f64;
        }
    }
    power
        .iter()
        .zip(&frame.polar_db[k * bins..(k + 1) * bins])
        .map(|(p, db)| (p - 10f64.powf(*db as f64 / 10.0)).abs() / (1.0 + p))
        .fold(0.0, f64::max)
}

/// Spoke mode: every spoke's captured record, compressed by the naive correlation, is the
/// polar record (the fused FFT path and the captured exact path agree to float32 rounding).
#[test]
fn raw_iq_compresses_to_the_polar_record() {
    let sim = Simulation::new(scene(IQ_SPOKE));
    let frame = iq(&sim);
    let q = frame.iq.as_ref().unwrap();
    assert_eq!(q.pulses, 36);
    assert_eq!(q.samples, sim.compressor().record_len());
    for k in [0, 1, 35] {
        let worst = worst_mismatch(&sim, &frame, k);
        assert!(worst < 1e-3, "spoke {k}: {worst}");
    }
    // Capturing changes nothing in the record beyond float32 rounding.
    let plain = sim.run(&Request::new(2)).unwrap();
    let worst = plain
        .polar_db
        .iter()
        .zip(&frame.polar_db)
        .map(|(a, b)| {
            (10f64.powf(*a as f64 / 10.0) - 10f64.powf(*b as f64 / 10.0)).abs()
                / (1.0 + 10f64.powf(*a as f64 / 10.0))
        })
        .fold(0.0, f64::max);
    assert!(worst < 1e-3, "{worst}");
}

/// Pulse mode with sea clutter and a moving target: each spoke's rows (its dwell's pulses),
/// compressed naively and averaged, give the non-coherently integrated spoke; rows carry
/// their pulses' times in fire order.
#[test]
fn pulse_mode_raw_iq_integrates_to_the_polar_record() {
    let sim = Simulation::new(scene(IQ_PULSE));
    let frame = iq(&sim);
    let q = frame.iq.as_ref().unwrap();
    assert_eq!(q.pulses, sim.scene().radar().scan().pulses_per_revolution());
    for w in q.times_s.windows(2).zip(q.spokes.windows(2)) {
        if w.1[0] == w.1[1] {
            assert!(w.0[1] > w.0[0], "rows of a dwell in fire order");
        }
    }
    for k in [0, 1, 45] {
        let worst = worst_mismatch(&sim, &frame, k);
        assert!(worst < 1e-3, "spoke {k}: {worst}");
    }
}

/// Raw I/Q over the size limit is refused before anything is rendered, naming the option.
#[test]
fn oversized_raw_iq_is_refused() {
    let sim = Simulation::new(scene(
        "[radar]\nmax_range_m = 60000.0\nprf_hz = 2000.0\n[processing]\nmode = \"pulse\"\n",
    ));
    let err = sim
        .check_outputs(Outputs {
            iq: true,
            ..Default::default()
        })
        .unwrap_err()
        .to_string();
    assert!(err.contains("--iq") && err.contains("short runs"), "{err}");
}

/// Staggered PRF: intervals cycle through r_i/mean(r)/prf, the mean rate stays the PRF.
#[test]
fn stagger_times_the_pulses() {
    let s = scene("[radar]\nprf_hz = 2000.0\nprf_stagger = [4.0, 5.0, 6.0]\n");
    let scan = s.radar().scan();
    let expected = [4.0 / 5.0 / 2000.0, 5.0 / 5.0 / 2000.0, 6.0 / 5.0 / 2000.0];
    for n in 0..30 {
        let dt = scan.pulse_time_s(n + 1) - scan.pulse_time_s(n);
        assert!((dt - expected[n % 3]).abs() < 1e-12, "{n}: {dt}");
    }
    let total = scan.pulses_per_revolution();
    assert!(scan.pulse_time_s(total - 1) < scan.period_s());
    assert!(scan.pulse_time_s(total) >= scan.period_s() - 1e-12);
    assert!(total.abs_diff(5000) <= 1, "{total}");
}

/// A staggered train runs on through the revolutions: across frames 0–2 every interval is
/// one of the stagger's (no short gap at a seam), every dwell holds at least the fewest
/// pulses the processing settings allow for, and pulse numbers run from 0 in fire order.
#[test]
fn staggered_train_is_continuous_across_revolutions() {
    let s = scene("[radar]\nprf_hz = 1000.0\nprf_stagger = [3.0, 4.0, 5.0]\nspokes = 180\n[processing]\nmode = \"pulse\"\n");
    let radar = s.radar();
    let intervals = radar.scan().stagger().intervals_s().to_vec();
    let fewest = xbandsim::model::processing::fewest_pulses_per_spoke(radar);
    let mut times = Vec::new();
    for frame in 0..3 {
        let schedule = xbandsim::engine::Schedule::pulse_scan(radar, frame);
        let mut numbers: Vec<(f64, u64)> = Vec::new();
        for d in schedule.dwells() {
            assert!(d.pulses.len() >= fewest, "{} < {fewest}", d.pulses.len());
            numbers.extend(d.pulses.iter().map(|p| (p.time_s, p.number)));
        }
        numbers.sort_by(|a, b| a.0.total_cmp(&b.0));
        for (n, (_, number)) in numbers.iter().enumerate() {
            assert_eq!(*number, n as u64);
        }
        times.extend(numbers.into_iter().map(|(t, _)| t));
    }
    for w in times.windows(2) {
        let dt = w[1] - w[0];
        assert!(
            intervals.iter().any(|i| (dt - i).abs() < 1e-9),
            "interval {dt} is not one of {intervals:?}"
        );
    }
}

fn error_of(text: &str) -> String {
    match Scene::from_toml_str(text, "t.toml") {
        Ok(_) => panic!("accepted:\n{text}"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn bad_stagger_and_combined_settings_are_located_errors() {
    for (text, field) in [
        ("[radar]\nprf_stagger = [1.0]\n", "radar.prf_stagger"),
        ("[radar]\nprf_stagger = [1.0, -2.0]\n", "radar.prf_stagger[1]"),
        ("[radar]\nprf_stagger = [1.0, nan]\n", "radar.prf_stagger[1]"),
        (
            "[radar]\nprf_hz = 2000.0\npulse_width_us = 100.0\nmax_range_m = 1000.0\nprf_stagger = [1.0, 9.0]\n",
            "radar.prf_stagger",
        ),
        ("[radar]\nshort_pulse_width_us = 0.1\n", "radar.short_pulse_width_us"),
        ("[radar]\nshort_bandwidth_mhz = 10.0\n", "radar.short_bandwidth_mhz"),
        (
            "[radar]\npulse_mode = \"combined\"\nshort_pulse_width_us = 2.0\n",
            "radar.short_pulse_width_us",
        ),
        (
            "[radar]\npulse_mode = \"combined\"\nshort_pulse_width_us = 0.01\n",
            "radar.short_pulse_width_us",
        ),
        (
            "[radar]\npulse_mode = \"combined\"\nshort_bandwidth_mhz = 500.0\n",
            "radar.short_bandwidth_mhz",
        ),
    ] {
        let err = error_of(text);
        assert!(err.contains(field), "{text}: {err}");
    }
}

/// A target inside the long pulse's eclipse is (partly) eclipsed with a single pulse and seen on the
/// short pulse in combined mode, its label saying which pulse and with the short pulse's SNR.
#[test]
fn combined_mode_sees_inside_the_eclipse() {
    let text = "[radar]\nspokes = 36\nmax_range_m = 600.0\n[environment]\nnoise = false\nclutter = false\nmultipath = false\n[[object]]\nname = \"near\"\nshape = \"point\"\nrcs_m2 = 10.0\nposition_m = [0.0, 60.0, 4.0]\n[[object]]\nname = \"far\"\nshape = \"point\"\nrcs_m2 = 10.0\nposition_m = [0.0, 400.0, 4.0]\n";
    let single = Simulation::new(scene(text)).render(1);
    assert_eq!(single.truth[0].visibility, Visibility::PartiallyEclipsed);
    assert!(single.truth[0].eclipse_received_fraction < 0.5);
    assert_eq!(single.truth[0].pulse, PulseChannel::Single);
    let combined_text = text.replace("[radar]\n", "[radar]\npulse_mode = \"combined\"\n");
    let sim = Simulation::new(scene(&combined_text));
    let frame = sim.render(1);
    let near = &frame.truth[0];
    assert_eq!(near.pulse, PulseChannel::Short);
    assert_eq!(near.visibility, Visibility::Visible);
    assert_eq!(near.eclipse_received_fraction, 1.0);
    assert_eq!(frame.truth[1].pulse, PulseChannel::Long);
    // The short pulse's SNR: the long pulse's less 10·log10(τ_long/τ_short) (both unwindowed).
    let radar = sim.scene().radar();
    let long_snr = 10.0 * radar.point_target_snr(10.0, near.range_m).log10();
    let short = radar.short_pulse().unwrap();
    let ratio_db = 10.0 * (radar.chirp().pulse_width_s / short.chirp.pulse_width_s).log10();
    let snr = near.expected_snr_db.unwrap();
    assert!((snr - (long_snr - ratio_db)).abs() < 1e-9, "{snr}");
    // The record shows it at its range with the long pulse's calibration.
    let j = (near.range_m / frame.range_bin_m).round() as usize;
    let peak = frame.polar_db[j] as f64;
    assert!((peak - long_snr).abs() < 0.05, "{peak} vs {long_snr}");
    // Its box holds the short pulse's triangle, ±c·τ/2 = ±12 m (8 bins) around it.
    let b = near.polar_box.as_ref().unwrap();
    assert!(
        b.bin_min + 8 <= j && b.bin_max >= j + 8,
        "{b:?} around bin {j}"
    );
    for k in [j - 7, j + 7] {
        assert!(
            frame.polar_db[k] > -60.0,
            "bin {k} of the triangle is in the box"
        );
    }
}

/// Combined pulse mode with Doppler colour: the short pulse's bins sit at its higher noise
/// floor in the record, but the colour threshold is over each channel's own noise, so noise
/// alone is not painted (it would be in about 40 % of those cells against the record's
/// value).
#[test]
fn combined_mode_noise_is_not_coloured() {
    let sim = Simulation::new(scene("[radar]\nspokes = 90\nmax_range_m = 300.0\nprf_hz = 1200.0\npulse_mode = \"combined\"\n[environment]\nclutter = false\nmultipath = false\n[processing]\nmode = \"pulse\"\n"));
    let frame = sim
        .run(&Request::new(4).outputs(Outputs {
            radial_velocity: true,
            ..Default::default()
        }))
        .unwrap();
    let v = frame.radial_velocity.as_ref().unwrap();
    let join = sim.scene().radar().join_bin();
    let mut coloured = 0;
    let mut cells = 0;
    for k in 0..frame.spokes {
        for j in 8..join {
            cells += 1;
            coloured += v.approaching(k * frame.range_bins + j, 10.0) as usize;
        }
    }
    assert!(
        (coloured as f64) < 0.01 * cells as f64,
        "{coloured} of {cells}"
    );
}
