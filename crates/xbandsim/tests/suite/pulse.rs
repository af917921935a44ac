//! Pulse mode: moving echoes advanced pulse to pulse from one trace per revolution match a
//! scene traced again at every pulse; the Doppler cube's axes and noise calibration; the
//! processing settings are checked (docs/physics.md §10).

use crate::common::scene;
use num_complex::Complex32;
use xbandsim::engine::Request;
use xbandsim::engine::{Outputs, Schedule, Simulation};
use xbandsim::model::Scene;

const MOVING: &str = "[radar]\nspokes = 360\nmax_range_m = 900.0\nprf_hz = 1200.0\n[environment]\nnoise = false\nclutter = false\nmultipath = false\n[processing]\nmode = \"pulse\"\nintegration = \"coherent\"\n[[object]]\nname = \"t\"\nshape = \"point\"\nrcs_m2 = 5.0\nposition_m = [300.0, 420.0, 2.0]\nspeed_kn = 25.0\ncourse_deg = 250.0\n";

/// The re-trace rule (one trace per revolution at the beam crossing, phase and delay advanced
/// by the range rate to each pulse) against the reference that poses and traces the scene
/// again for every pulse: coherent integration (phase-sensitive) over the spokes around a
/// point target at 25 kn agrees within 0.03 dB within 6 dB of the peak, and within 3e-3 of
/// the peak power everywhere around it (the reference's own floor: it quantises each pulse's
/// fractional delay to 1/512 sample; leaving out the r̈ term alone gives 0.06 dB).
#[test]
fn moving_echo_matches_a_per_pulse_trace() {
    let sim = Simulation::new(scene(MOVING));
    let frame = sim.run(&Request::new(3)).unwrap();
    let truth = &frame.truth[0];
    let radar = sim.scene().radar();
    let bins = frame.range_bins;
    let k0 = truth.azimuth_deg.round() as usize;
    let j0 = (truth.range_m / frame.range_bin_m).round() as usize;
    let schedule = Schedule::pulse_scan(radar, 0);
    let object = &sim.scene().objects()[0];
    let base = sim.scene();
    let peak = frame.polar_db[k0 * bins + j0 - 3..k0 * bins + j0 + 4]
        .iter()
        .cloned()
        .fold(f32::MIN, f32::max);
    let (mut worst, mut worst_power) = (0f32, 0f32);
    for k in k0 - 3..=k0 + 3 {
        let dwell = schedule.dwells().iter().find(|d| d.spoke == k).unwrap();
        let mut sum = vec![Complex32::new(0.0, 0.0); bins];
        for pulse in &dwell.pulses {
            let posed = Scene::new(
                base.radar().clone(),
                base.environment().clone(),
                base.scattering().clone(),
                vec![object.posed_at(pulse.time_s, glam::DVec3::ZERO)],
            )
            .unwrap();
            let reference = Simulation::new(posed);
            let traced = reference.traced(0.0);
            let mut scratch = reference.compressor().scratch();
            reference.compress_pulse(
                None,
                &traced.groups,
                k,
                pulse,
                xbandsim::rng::FrameKey::new(3, 0),
                &mut scratch,
            );
            for (s, y) in sum.iter_mut().zip(&scratch.buffer[..bins]) {
                *s += y;
            }
        }
        let m = dwell.pulses.len() as f32;
        for j in j0 - 6..=j0 + 6 {
            let reference_db = 10.0 * (sum[j].norm_sqr() / m).log10();
            let engine_db = frame.polar_db[k * bins + j];
            // Within 6 dB of the peak: dB against dB. Everywhere: the power difference
            // against the peak's power (cells where the coherent sum nearly cancels magnify
            // the reference's own error: it quantises each pulse's fractional delay to 1/512
            // of a sample, where the engine shifts the echo exactly).
            if reference_db > peak - 6.0 {
                worst = worst.max((reference_db - engine_db).abs());
            }
            let to_lin = |db: f32| 10f32.powf(db / 10.0);
            worst_power =
                worst_power.max((to_lin(reference_db) - to_lin(engine_db)).abs() / to_lin(peak));
        }
    }
    assert!(
        worst < 0.03,
        "pulse mode differs from a per-pulse trace by {worst} dB"
    );
    assert!(
        worst_power < 3e-3,
        "power difference {worst_power} of the peak's"
    );
    assert!(
        truth.radial_velocity_mps.abs() > 5.0,
        "the target must move fast"
    );
}

/// The cube: shape and Doppler axis; an approaching target lands above the zero-Doppler row;
/// noise alone averages 0 dB (|Y|²/Σw² of noise of unit power).
#[test]
fn doppler_cube_axes_and_noise_calibration() {
    let text = MOVING
        .replace("noise = false\n", "")
        .replace("integration = \"coherent\"\n", "doppler_pulses = 8\n");
    let sim = Simulation::new(scene(&text));
    let frame = sim
        .run(&Request::new(1).outputs(Outputs {
            doppler_cube: true,
            ..Default::default()
        }))
        .expect("pulse mode gives a cube");
    let cube = frame.doppler_cube.as_ref().unwrap();
    assert_eq!(
        (cube.spokes, cube.doppler_bins, cube.range_bins),
        (360, 8, frame.range_bins)
    );
    assert_eq!(cube.doppler_bin_hz, 1200.0 / 8.0);
    assert_eq!(cube.doppler_hz(4), 0.0);
    assert_eq!(cube.doppler_hz(0), -600.0);
    assert_eq!(cube.values_db.len(), 360 * 8 * frame.range_bins);
    // Noise: mean linear power over far-off cells (no target) is 1 (0 dB) within 2 %.
    let mut acc = 0.0f64;
    let mut n = 0usize;
    for k in 180..360 {
        for d in 0..8 {
            for j in 100..400 {
                let v = cube.values_db[(k * 8 + d) * cube.range_bins + j];
                acc += 10f64.powf(v as f64 / 10.0);
                n += 1;
            }
        }
    }
    let mean = acc / n as f64;
    assert!((mean - 1.0).abs() < 0.02, "cube noise mean {mean}");
    // The closing target's Doppler.
    let t = &frame.truth[0];
    assert!(t.doppler_hz > 0.0);
    let k = t.azimuth_deg.round() as usize;
    let j = (t.range_m / frame.range_bin_m).round() as usize;
    let spectrum: Vec<f32> = (j - 2..=j + 2)
        .map(|jj| cube.spectrum(k, jj))
        .fold(vec![f32::MIN; 8], |a, s| {
            a.iter().zip(&s).map(|(x, y)| x.max(*y)).collect()
        });
    let best = (0..8)
        .max_by(|a, b| spectrum[*a].total_cmp(&spectrum[*b]))
        .unwrap();
    let expected = ((t.doppler_hz + 600.0).rem_euclid(1200.0) - 600.0) / 150.0 + 4.0;
    assert!(
        (best as f64 - expected).abs() <= 0.5,
        "bin {best}, expected {expected}"
    );
}

fn error_of(text: &str) -> String {
    match Scene::from_toml_str(text, "scene.toml") {
        Ok(_) => panic!("accepted:\n{text}"),
        Err(e) => e.to_string(),
    }
}

/// Processing settings that cannot work are refused by field.
#[test]
fn processing_settings_are_checked() {
    let msg = error_of("[processing]\ndoppler_pulses = 8\n");
    assert!(
        msg.contains("processing.doppler_pulses") && msg.contains("pulse"),
        "{msg}"
    );
    let msg = error_of("[radar]\nprf_hz = 100.0\n[processing]\nmode = \"pulse\"\n");
    assert!(
        msg.contains("processing.mode") && msg.contains("250 pulses"),
        "{msg}"
    );
    let msg =
        error_of("[radar]\nprf_hz = 1200.0\n[processing]\nmode = \"pulse\"\ndoppler_pulses = 9\n");
    assert!(
        msg.contains("processing.doppler_pulses") && msg.contains("8 here"),
        "{msg}"
    );
    let msg = error_of("[processing]\nmode = \"burst\"\n");
    assert!(msg.contains("mode"), "{msg}");
    let msg = error_of("[processing]\nintegration = \"magic\"\n");
    assert!(msg.contains("integration"), "{msg}");
    assert!(Scene::from_toml_str("[processing]\nmode = \"pulse\"\n", "ok").is_ok());
}

/// Spoke 0 straddles north: its pulses from before north are fired at the end of the
/// previous revolution, so its dwell is evenly spaced in time; a target moving just west of
/// north, seen before north, is drawn once, at its labelled range, on both sides of north
/// (not again where it will be a revolution later).
#[test]
fn spoke_zero_is_continuous_across_north() {
    let sim = Simulation::new(scene(&MOVING.replace(
        "position_m = [300.0, 420.0, 2.0]",
        "position_m = [-1.0, 520.0, 2.0]",
    )));
    let radar = sim.scene().radar();
    let schedule = Schedule::pulse_scan(radar, 3);
    let d0 = &schedule.dwells()[0];
    assert!(d0.pulses.len() > 2);
    for w in d0.pulses.windows(2) {
        assert!(
            ((w[1].time_s - w[0].time_s) - 1.0 / 1200.0).abs() < 1e-9,
            "{w:?}"
        );
    }
    assert!(d0.pulses[0].time_s < 3.0 * 2.5 && d0.pulses.last().unwrap().time_s > 3.0 * 2.5);
    let frame = sim.run(&Request::new(1)).unwrap();
    let t = &frame.truth[0];
    assert!(t.beam_time_s < 0.0, "seen before north: {}", t.beam_time_s);
    assert!(t.azimuth_deg > 359.0, "bearing {}", t.azimuth_deg);
    let bins = frame.range_bins;
    let j_truth = t.range_m / frame.range_bin_m;
    for k in [359usize, 0, 1] {
        let row = &frame.polar_db[k * bins..(k + 1) * bins];
        let (j, _) = row
            .iter()
            .enumerate()
            .fold((0, f32::MIN), |b, (j, &v)| if v > b.1 { (j, v) } else { b });
        assert!(
            (j as f64 - j_truth).abs() <= 1.0,
            "spoke {k}: peak at bin {j}, truth {j_truth}"
        );
    }
}

/// Doppler colour (the pulse-pair estimator, docs/physics.md §10): of two 10 kn targets, one
/// closing and one opening, the closing one's peak cell reads its truth radial velocity within
/// 0.5 m/s and is drawn red on ppi.png; the opening one's cells are not; radial_velocity.npy
/// is written. Doppler colour in spoke mode is refused by field.
#[test]
fn doppler_colour_marks_approaching_echoes() {
    use xbandsim::products::frame_files::write_frame_files;
    use xbandsim::products::ppi::APPROACHING_RGB;
    use xbandsim::scene::LoadedSpec;
    let text = "[radar]\nspokes = 180\nmax_range_m = 900.0\nprf_hz = 1200.0\n[environment]\nnoise = true\nclutter = false\nmultipath = false\n[processing]\nmode = \"pulse\"\n[display]\ndoppler_colour = true\nimage_size_px = 1024\n[[object]]\nname = \"closing\"\nshape = \"point\"\nrcs_m2 = 10.0\nposition_m = [0.0, 500.0, 4.0]\nspeed_kn = 10.0\ncourse_deg = 180.0\n[[object]]\nname = \"opening\"\nshape = \"point\"\nrcs_m2 = 10.0\nposition_m = [500.0, -200.0, 4.0]\nspeed_kn = 10.0\ncourse_deg = 112.0\n";
    let spec = LoadedSpec::from_toml(text, "t", std::path::Path::new(".")).unwrap();
    let settings = spec.ppi_settings().unwrap();
    assert!(settings.doppler_colour && settings.doppler_colour_threshold_db == 10.0);
    let sim = Simulation::new(spec.build().unwrap());
    let outputs = Outputs {
        radial_velocity: true,
        ..Default::default()
    };
    let frame = sim
        .run(&Request::new(5).outputs(outputs))
        .expect("pulse mode gives radial velocities");
    let v = frame.radial_velocity.as_ref().unwrap();
    let bins = frame.range_bins;
    let lambda = sim.scene().radar().wavelength_m();
    assert!((v.unambiguous_mps - lambda * 1200.0 / 4.0).abs() < 1e-12);
    let peak_of = |name: &str| {
        let t = frame.truth.iter().find(|t| t.name == name).unwrap();
        let b = t.polar_box.unwrap();
        let mut best = (0, f32::MIN);
        // The box may wrap through north (spoke_min > spoke_max).
        let n = (b.spoke_max + frame.spokes - b.spoke_min) % frame.spokes;
        for k in (0..=n).map(|d| (b.spoke_min + d) % frame.spokes) {
            for j in b.bin_min..=b.bin_max {
                let i = k * bins + j;
                if frame.polar_db[i] > best.1 {
                    best = (i, frame.polar_db[i]);
                }
            }
        }
        (t.clone(), best.0)
    };
    let (closing, ci) = peak_of("closing");
    let (opening, oi) = peak_of("opening");
    assert!(closing.radial_velocity_mps < -5.0 && opening.radial_velocity_mps > 5.0);
    assert!(
        frame.polar_db[ci] > 20.0 && frame.polar_db[oi] > 20.0,
        "{} {} {:?} {:?}",
        frame.polar_db[ci],
        frame.polar_db[oi],
        closing.expected_snr_db,
        opening.expected_snr_db
    );
    for (t, i) in [(&closing, ci), (&opening, oi)] {
        assert!(v.estimated[i]);
        let err = (v.velocity_mps[i] as f64 - t.radial_velocity_mps).abs();
        assert!(
            err < 0.5,
            "{}: estimate {} m/s, truth {} m/s",
            t.name,
            v.velocity_mps[i],
            t.radial_velocity_mps
        );
    }
    assert!(v.approaching(ci, 10.0) && !v.approaching(oi, 10.0));
    // Noise alone (10 dB below the threshold) is never coloured.
    let coloured = (0..v.velocity_mps.len())
        .filter(|&i| v.approaching(i, 10.0))
        .count();
    assert!(coloured > 0);
    // The image: red pixels in the closing target's box, none in the opening one's.
    let dir = tempfile::tempdir().unwrap();
    write_frame_files(sim.scene().radar(), &settings, &frame, dir.path(), "t", 5).unwrap();
    let decoder = png::Decoder::new(std::io::BufReader::new(
        std::fs::File::open(dir.path().join("ppi.png")).unwrap(),
    ));
    let mut reader = decoder.read_info().unwrap();
    let mut rgb = vec![0u8; reader.output_buffer_size()];
    reader.next_frame(&mut rgb).unwrap();
    let truth: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("truth.json")).unwrap()).unwrap();
    let red_in = |id: usize| {
        let b = &truth["objects"][id]["ppi_box_px"];
        let b: Vec<usize> = (0..4).map(|i| b[i].as_f64().unwrap() as usize).collect();
        let mut n = 0;
        for row in b[1]..=b[3].min(1023) {
            for col in b[0]..=b[2].min(1023) {
                let p = (row * 1024 + col) * 3;
                n += usize::from(rgb[p..p + 3] == APPROACHING_RGB);
            }
        }
        n
    };
    assert!(red_in(0) > 0, "the closing target is not coloured");
    assert_eq!(red_in(1), 0, "the opening target is coloured");
    let npy = std::fs::read(dir.path().join("radial_velocity.npy")).unwrap();
    assert_eq!(npy.len(), 128 + 4 * frame.spokes * bins);
    // Spoke mode has no pulses to compare: refused, naming the field.
    let spoke = text.replace("mode = \"pulse\"\n", "");
    let err = LoadedSpec::from_toml(&spoke, "t", std::path::Path::new("."))
        .unwrap()
        .build()
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("display.doppler_colour") && err.contains("pulse"),
        "{err}"
    );
}
