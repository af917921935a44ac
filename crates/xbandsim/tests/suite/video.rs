//! The receiver's video chain through the real pipeline (docs/physics.md §12): the calibrated
//! record is untouched by it, the STC follows its law, the log amplifier and threshold pass
//! the noise fraction their transfer curve predicts, the FTC clears rain and keeps a target
//! in it, interference rejection removes a lone sweep's pulse and keeps a painted echo, and
//! bad controls are refused naming the field.

use crate::common::{point_north, radar_block, radar_block_no_noise, render, scene};
use xbandsim::model::receiver::VideoSettings;
use xbandsim::receiver::video_chain::{self, manual_stc_db, PolarRecord};
use xbandsim::scene::ReceiverSpec;
use xbandsim::Problem;

/// A `[receiver]` table adds the video and changes nothing of the calibrated record.
#[test]
fn the_calibrated_record_is_the_same_with_the_chain_on() {
    let base = format!(
        "{}{}",
        radar_block("spokes = 90\nmax_range_m = 1200.0"),
        point_north("p", 700.0, 10.0)
    );
    let (_, plain) = render(&base, 11);
    let with = format!("{base}\n[receiver]\nstc = \"auto\"\nftc_time_constant_us = 0.5\n");
    let (_, video) = render(&with, 11);
    assert!(plain.video.is_none());
    assert_eq!(plain.polar_db, video.polar_db);
    let v = video.video.expect("a [receiver] table makes video");
    assert_eq!((v.spokes, v.samples, v.bits), (2048, 512, 4));
    assert_eq!(v.levels.len(), 2048 * 512);
    assert!(v.levels.iter().all(|&l| l <= 15));
}

/// The manual STC's attenuation at a point target, measured as the drop of its video level
/// (8 bits over 20 dB: 0.078 dB a level), equals `min(level, 10·k·log10(R_stc/R))` at the
/// peak sample within 0.1 dB, for targets inside and beyond the STC's range.
#[test]
fn stc_attenuates_by_its_law() {
    for (range_m, rcs) in [(300.0, 1.0), (600.0, 3.0), (900.0, 10.0), (1300.0, 30.0)] {
        let base = format!(
            "{}{}",
            radar_block_no_noise("spokes = 360\nmax_range_m = 1500.0"),
            point_north("p", range_m, rcs)
        );
        // The threshold 16 dB under the echo's calibrated peak: both videos inside the span.
        let (_, calibrated) = render(&base, 3);
        let echo_db = calibrated.polar_db[..calibrated.range_bins]
            .iter()
            .copied()
            .fold(f32::MIN, f32::max);
        let gain_db = 6.0 - (echo_db - 16.0);
        let receiver = |stc: &str| {
            format!(
                "[receiver]\nvideo_bits = 8\nvideo_samples = 1000\nvideo_spokes = 360\n\
                 gain_db = {gain_db}\nvideo_span_db = 20.0\n{stc}"
            )
        };
        let peak = |text: &str| {
            let (_, f) = render(text, 3);
            let v = f.video.unwrap();
            let row = &v.levels[..v.samples];
            let j = (0..v.samples).max_by_key(|&j| row[j]).unwrap();
            (j, f32::from(row[j]) * v.level_step_db, v.sample_m)
        };
        let (j_off, off_db, _) = peak(&format!("{base}{}", receiver("")));
        let (j, on_db, sample_m) = peak(&format!(
            "{base}{}",
            receiver(
                "stc = \"manual\"\nstc_level_db = 12.0\nstc_range_m = 1000.0\nstc_law = 3.0\n"
            )
        ));
        assert_eq!(j, j_off, "R = {range_m} m");
        let law = manual_stc_db((j as f64 + 0.5) * sample_m, 12.0, 1000.0, 3.0);
        let measured = off_db - on_db;
        assert!(
            (measured - law).abs() <= 0.1,
            "R = {range_m} m: attenuation {measured:.3} dB, law {law:.3} dB"
        );
    }
}

/// Noise alone through the log amplifier: `v = 10·log10(1 + x)` of an exponential x reaches
/// the threshold 6 dB − gain with probability `exp(−(10^{t/10} − 1))`: 5.07 % at gain 0, 37 %
/// at +3 dB. Measured over 360 × 1000 samples (one bin a sample) within ±6 % of that.
#[test]
fn noise_reaches_the_threshold_as_the_log_transfer_predicts() {
    for gain_db in [0.0f64, 3.0] {
        let text = format!(
            "{}[receiver]\nvideo_spokes = 360\nvideo_samples = 1001\ngain_db = {gain_db}\n",
            radar_block("spokes = 360\nmax_range_m = 1500.0")
        );
        let (_, f) = render(&text, 5);
        assert_eq!(f.range_bins, 1001);
        let v = f.video.unwrap();
        // Beyond the blanked first bins.
        let cells: Vec<u8> = (0..v.spokes)
            .flat_map(|s| v.levels[s * v.samples + 200..(s + 1) * v.samples].to_vec())
            .collect();
        let fraction = cells.iter().filter(|&&l| l > 0).count() as f64 / cells.len() as f64;
        let t = 6.0 - gain_db;
        let expect = (-(10f64.powf(t / 10.0) - 1.0)).exp();
        assert!(
            (fraction / expect - 1.0).abs() < 0.06,
            "gain {gain_db} dB: {fraction:.4} of noise over the threshold, expected {expect:.4}"
        );
    }
}

/// A rain cell fills the video without FTC; the FTC differentiator clears most of it and keeps
/// a strong point target inside it.
#[test]
fn ftc_clears_rain_and_keeps_a_target_in_it() {
    let base = format!(
        "{}{}[[environment.rain_cell]]\ncentre_m = [0.0, 800.0]\nradius_m = 300.0\nrate_mm_per_h = 16.0\n",
        radar_block("spokes = 180\nmax_range_m = 1500.0"),
        point_north("p", 800.0, 300.0)
    );
    let count = |ftc: &str| {
        let text = format!("{base}[receiver]\nvideo_spokes = 180\n{ftc}");
        let (_, f) = render(&text, 2);
        let v = f.video.unwrap();
        // The rain's samples off the target's spokes (spoke 20, 40° east), 600–1000 m.
        let row = |s: usize| &v.levels[s * v.samples..(s + 1) * v.samples];
        let j = |m: f64| (m / v.sample_m) as usize;
        let rain = row(170)[j(650.0)..j(950.0)]
            .iter()
            .chain(&row(10)[j(650.0)..j(950.0)])
            .filter(|&&l| l > 0)
            .count() as f64
            / (2 * (j(950.0) - j(650.0))) as f64;
        let target = *row(0)[j(780.0)..j(820.0)].iter().max().unwrap();
        (rain, target)
    };
    let (rain_off, target_off) = count("");
    let (rain_on, target_on) = count("ftc_time_constant_us = 0.3\n");
    assert!(rain_off > 0.5, "rain fills {rain_off:.2} of its samples");
    assert!(
        rain_on < 0.2,
        "FTC leaves {rain_on:.2} of the rain's samples"
    );
    assert!(
        target_off >= 10 && target_on >= 8,
        "{target_off} {target_on}"
    );
}

/// Interference rejection on a record with a steady echo painted on five sweeps and one
/// sweep's interference pulse: at medium and high the pulse drops below the threshold and the
/// echo's peak keeps its level within 2 dB.
#[test]
fn interference_rejection_removes_a_lone_pulse_and_keeps_an_echo() {
    let (spokes, bins) = (64, 400);
    let mut db = vec![0f32; spokes * bins];
    for (k, level) in [(8, 37.0), (9, 39.0), (10, 40.0), (11, 39.0), (12, 37.0)] {
        db[k * bins + 100] = level;
    }
    db[30 * bins + 250] = 35.0;
    let record = PolarRecord {
        db: &db,
        spokes,
        bins,
        bin_m: 3.0,
        range_m: 1200.0,
    };
    for (level, expect_pulse_removed) in [("off", false), ("medium", true), ("high", true)] {
        let spec: ReceiverSpec = toml::from_str(&format!(
            "video_spokes = 64\nvideo_samples = 400\nvideo_bits = 8\ninterference_rejection = \"{level}\""
        ))
        .unwrap();
        let s = VideoSettings::from_spec(&spec).unwrap();
        let v = video_chain::run(&s, &record, None);
        let pulse = v.levels[30 * 400 + 250];
        assert_eq!(
            pulse == 0,
            expect_pulse_removed,
            "{level}: pulse level {pulse}"
        );
        let echo = f32::from(v.levels[10 * 400 + 100]) * v.level_step_db + v.threshold_db;
        assert!(echo > 38.0, "{level}: echo {echo:.1} dB");
    }
}

/// Bad controls are refused naming the field.
#[test]
fn bad_controls_are_refused_naming_the_field() {
    for (line, field, problem) in [
        (
            "video_bits = 12",
            "receiver.video_bits",
            Problem::OutOfRange,
        ),
        (
            "video_spokes = 0",
            "receiver.video_spokes",
            Problem::OutOfRange,
        ),
        ("gain_db = 20.0", "receiver.gain_db", Problem::OutOfRange),
        (
            "ftc_time_constant_us = -1.0",
            "receiver.ftc_time_constant_us",
            Problem::OutOfRange,
        ),
        (
            "stc_level_db = 10.0",
            "receiver.stc_level_db",
            Problem::Conflict,
        ),
        (
            "stc = \"auto\"\nstc_law = 4.0",
            "receiver.stc_law",
            Problem::Conflict,
        ),
        (
            "echo_average_scans = 0",
            "receiver.echo_average_scans",
            Problem::OutOfRange,
        ),
        (
            "stc = \"auto\"\nstc_auto_level_db = 0.0",
            "receiver.stc_auto_level_db",
            Problem::OutOfRange,
        ),
    ] {
        let text = format!("{}[receiver]\n{line}\n", radar_block(""));
        let e = xbandsim::model::Scene::from_toml_str(&text, "test").unwrap_err();
        assert_eq!(e.field(), Some(field), "{e}");
        assert_eq!(e.problem(), Some(problem), "{e}");
    }
    let text = format!(
        "{}[receiver]\ninterference_rejection = \"max\"\n",
        radar_block("")
    );
    let e = xbandsim::model::Scene::from_toml_str(&text, "test").unwrap_err();
    assert!(e.to_string().contains("interference_rejection"), "{e}");
    let _ = scene(&radar_block(""));
}

/// Auto STC on sea clutter (sea state 5, 8 m mast): at each range it attenuates by
/// `A_j = max_{j' ≥ j} 10·log10(p_med(j')/(10^{0.3} − 1))` (the median power over the sweeps
/// brought to 3 dB of log video, never more attenuation far than near), so the median log
/// video over the sweeps is `10·log10(1 + p_med·10^{−A_j/10})`: 3 dB where the sample's own
/// clutter sets A_j, less where a farther sample's does. Recomputed here from the calibrated
/// record and compared with the chain's 8-bit video (0.078 dB a level) within 0.1 dB, from
/// 30 m to 1500 m; the far, clutter-free samples are left as they were.
#[test]
fn auto_stc_brings_the_clutter_down_to_its_level() {
    // Gain 6 dB: level 1 starts at the noise's 0 dB; 8 bits over 20 dB. One bin a sample.
    let base = "[environment]\nmultipath = false\nsea_state = 5\n[radar]\nposition_m = [0.0, 0.0, 8.0]\n\
                spokes = 360\nmax_range_m = 1500.0\n[receiver]\nvideo_spokes = 360\nvideo_samples = 1001\n\
                video_bits = 8\nvideo_span_db = 20.0\ngain_db = 6.0\nstc = \"auto\"\n";
    let (_, f) = render(base, 9);
    assert_eq!(f.range_bins, 1001);
    let v = f.video.as_ref().unwrap();
    let n = v.samples;
    let median = |mut column: Vec<f32>| {
        column.sort_by(f32::total_cmp);
        column[column.len() / 2]
    };
    let p_med: Vec<f64> = (0..n)
        .map(|j| {
            let c = (0..f.spokes)
                .map(|k| 10f32.powf(0.1 * f.polar_db[k * n + j]))
                .collect();
            f64::from(median(c))
        })
        .collect();
    let target = 10f64.powf(0.3) - 1.0;
    let mut attenuation: Vec<f64> = p_med
        .iter()
        .map(|&p| {
            if p > target {
                10.0 * (p / target).log10()
            } else {
                0.0
            }
        })
        .collect();
    for j in (0..n - 1).rev() {
        attenuation[j] = attenuation[j].max(attenuation[j + 1]);
    }
    let mut own = 0;
    for j in (30.0 / v.sample_m) as usize..n {
        let expect = 10.0 * (1.0 + p_med[j] * 10f64.powf(-attenuation[j] / 10.0)).log10();
        let c = (0..v.spokes)
            .map(|s| f32::from(v.levels[s * n + j]))
            .collect();
        let got = f64::from(median(c) * v.level_step_db);
        // Level 0 holds everything under 0 dB.
        if expect > 0.1 {
            assert!(
                (got - expect).abs() <= 0.1,
                "sample {j}: median {got:.3} dB, expected {expect:.3} dB"
            );
        }
        own += usize::from(attenuation[j] > 0.0 && (expect - 3.0).abs() < 1e-9);
    }
    assert!(
        own > 50,
        "the clutter sets its own attenuation at {own} samples"
    );
}

/// Echo averaging over scans: four scans of noise averaged in log video leave under a tenth
/// as many samples over the threshold as one scan (the mean of four `10·log10(1 + x)` is about
/// 2.5 dB, the threshold 6 dB), where one scan leaves 5–10 % (a sample is the peak of two
/// bins); a steady target keeps its level. Without a history each scan stands alone.
#[test]
fn echo_averaging_smooths_noise_and_keeps_a_steady_echo() {
    use std::sync::Mutex;
    use xbandsim::engine::{Request, Simulation};
    use xbandsim::receiver::video_chain::EchoHistory;
    let text = format!(
        "{}{}[receiver]\nvideo_spokes = 180\nvideo_samples = 500\necho_average_scans = 4\n",
        radar_block("spokes = 180\nmax_range_m = 1500.0"),
        point_north("p", 900.0, 10.0)
    );
    let sim = Simulation::new(scene(&text));
    let noise_fraction = |v: &video_chain::Video| {
        let far: Vec<u8> = (10..170)
            .flat_map(|s| v.levels[s * v.samples + 100..(s + 1) * v.samples].to_vec())
            .collect();
        far.iter().filter(|&&l| l > 0).count() as f64 / far.len() as f64
    };
    let history = Mutex::new(EchoHistory::default());
    let mut last = None;
    for k in 0..4 {
        let f = sim
            .run(&Request::new(4).frame(k).echo_history(&history))
            .unwrap();
        last = f.video;
    }
    assert_eq!(history.lock().unwrap().scans(), 4);
    let averaged = last.unwrap();
    let alone = sim.run(&Request::new(4).frame(3)).unwrap().video.unwrap();
    let (a, b) = (noise_fraction(&alone), noise_fraction(&averaged));
    assert!((0.05..0.12).contains(&a), "one scan: {a:.4}");
    assert!(b < a / 10.0, "four scans averaged: {b:.4}, one scan {a:.4}");
    let peak = |v: &video_chain::Video| *v.levels[..v.samples].iter().max().unwrap();
    assert!(
        peak(&averaged) + 1 >= peak(&alone),
        "{} {}",
        peak(&averaged),
        peak(&alone)
    );
}
