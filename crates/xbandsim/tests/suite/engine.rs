//! The engine: schedules, the trace cache and non-coherent integration of a dwell's pulses.

use crate::common::scene;
use std::sync::Arc;
use xbandsim::engine::Request;
use xbandsim::engine::{Dwell, Pulse, Schedule, Simulation};
use xbandsim::Problem;

const PAPER: &str = include_str!("../../../../scenes/paper.toml");

/// Free space with noise only: no objects, no clutter, no rain, no multipath.
const NOISE_ONLY: &str = "[radar]\nspokes = 64\nmax_range_m = 1200.0\n\
[environment]\nclutter = false\nrain = false\nmultipath = false\n";

/// The trace cache traces a static scene once; a cached render of frame 1 has the same bytes
/// as a fresh simulation's.
#[test]
fn trace_cache_traces_once_and_changes_nothing() {
    let text = PAPER.replace("scenes/", "");
    let cached = Simulation::new(scene(&text));
    let f0 = cached.run(&Request::new(3)).unwrap();
    let f1 = cached.run(&Request::new(3).frame(1)).unwrap();
    assert!(f0.stats.rays_cast > 0);
    assert_eq!(f1.stats.trace_s, 0.0, "frame 1 must come from the cache");
    assert_eq!(f1.stats.rays_cast, f0.stats.rays_cast);
    assert!(Arc::ptr_eq(&cached.traced(0.0), &cached.traced(17.5)));
    let fresh = Simulation::new(scene(&text))
        .run(&Request::new(3).frame(1))
        .unwrap();
    assert_eq!(fresh.polar_db, f1.polar_db);
    assert_eq!(fresh.truth, f1.truth);
}

/// A simulation made by `with_scene` for another waveform shares the traced world: it traces
/// nothing again (for a still and for a moving scene), and its frames have the bytes of a
/// fresh simulation of that scene. Another pulse length is shared only by point targets (an
/// extended object's trace depends on the range it can be seen to); a scene with another
/// world is refused, naming the radar.
#[test]
fn another_waveform_shares_the_traced_world_and_changes_nothing() {
    let points = "[[object]]\nname = \"boat\"\nshape = \"point\"\nrcs_m2 = 50.0\n\
        position_m = [0.0, 600.0, 2.0]\nspeed_kn = 12.0\ncourse_deg = 90.0\n\
        [[object]]\nname = \"buoy\"\nshape = \"point\"\nrcs_m2 = 5.0\n\
        position_m = [300.0, 200.0, 1.0]\n";
    let paper = PAPER.replace("scenes/", "");
    for (text, change) in [
        (paper.clone(), "radar.window=\"hamming\""),
        (
            format!("[radar]\nspokes = 90\nmax_range_m = 1200.0\n{points}"),
            "radar.pulse_width_us=0.2",
        ),
    ] {
        let with = |set: &[&str]| {
            let sets: Vec<String> = set.iter().map(|s| s.to_string()).collect();
            xbandsim::LoadedSpec::from_toml(&text, "test", std::path::Path::new("."))
                .and_then(|l| l.with_overrides(&sets))
                .and_then(|l| l.build())
                .unwrap()
        };
        let first = Simulation::new(with(&[]));
        let before = first.run(&Request::new(4)).unwrap();
        assert!(before.stats.rays_cast > 0 || text.contains("point"));
        let shared = first.with_scene(with(&[change])).unwrap();
        assert!(Arc::ptr_eq(shared.world(), first.world()));
        let frame = shared.run(&Request::new(4)).unwrap();
        assert!(
            Arc::ptr_eq(&shared.traced(0.0).set, &first.traced(0.0).set),
            "{change}: the world's trace must be shared, not traced again"
        );
        let fresh = Simulation::new(with(&[change]))
            .run(&Request::new(4))
            .unwrap();
        assert_ne!(fresh.polar_db, before.polar_db, "{change} must matter");
        assert_eq!(fresh.polar_db, frame.polar_db, "{change}");
        assert_eq!(fresh.truth, frame.truth, "{change}");
        let Err(e) = first.with_scene(with(&["radar.position_m=[0.0, 0.0, 20.0]"])) else {
            panic!("a radar moved elsewhere sees another world");
        };
        assert_eq!(e.problem(), Some(Problem::Conflict), "{e}");
        assert!(e.to_string().contains("radar"), "{e}");
    }
    // Extended objects and another pulse length: refused (what is beyond max range + c·T/2
    // is not traced, and T differs).
    let paper_sim = Simulation::new(scene(&paper));
    let longer = xbandsim::LoadedSpec::from_toml(&paper, "test", std::path::Path::new("."))
        .and_then(|l| l.with_overrides(&["radar.pulse_width_us=2.0".to_string()]))
        .and_then(|l| l.build())
        .unwrap();
    assert!(!paper_sim.world().serves(&longer));
    assert!(paper_sim.with_scene(longer).is_err());
}

/// A render of some spokes (`only_spokes`, what the dataset's masks read) has those spokes'
/// bytes from the full frame and the floor everywhere else, with clutter and noise on and in
/// the target-only render (including a slice shorter than the revolution).
#[test]
fn only_spokes_renders_those_spokes_bit_for_bit() {
    let text = PAPER.replace("scenes/", "");
    let sim = Simulation::new(scene(&text));
    let spokes = sim.scene().radar().spokes();
    let mut wanted = vec![false; spokes - 3];
    for k in [0, 1, 7, spokes / 2, spokes / 2 + 1, spokes - 4] {
        wanted[k] = true;
    }
    for sim in [sim.clone(), sim.targets_only()] {
        let full = sim.run(&Request::new(5)).unwrap();
        let part = sim.only_spokes(&wanted).run(&Request::new(5)).unwrap();
        let bins = full.range_bins;
        assert_eq!(part.truth, full.truth);
        for k in 0..spokes {
            let (a, b) = (
                &full.polar_db[k * bins..(k + 1) * bins],
                &part.polar_db[k * bins..(k + 1) * bins],
            );
            if wanted.get(k).copied().unwrap_or(false) {
                assert_eq!(a, b, "spoke {k}");
            } else {
                assert!(
                    b.iter().all(|&v| v == xbandsim::engine::POLAR_FLOOR_DB),
                    "spoke {k}"
                );
            }
        }
        assert!(
            full.polar_db.iter().any(|&v| v > 20.0),
            "the scene has echoes"
        );
    }
}

/// Today's render is the frozen-scan schedule, and the same schedule built by hand through
/// the validating constructor gives the same bytes.
#[test]
fn frozen_scan_is_a_schedule_like_any_other() {
    let sim = Simulation::new(scene(NOISE_ONLY));
    let radar = sim.scene().radar();
    let frozen = Schedule::frozen_scan(radar, 2);
    let period_s = 60.0 / radar.rotation_rpm();
    assert_eq!(frozen.dwells().len(), 64);
    assert_eq!(frozen.scene_time_s(), 2.0 * period_s);
    let d = &frozen.dwells()[16];
    assert_eq!(d.spoke, 16);
    assert_eq!(d.pulses.len(), 1);
    assert!((d.pulses[0].time_s - 2.25 * period_s).abs() < 1e-12);
    assert!((d.pulses[0].azimuth_rad - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
    // Dwells in reverse order, same pulses.
    let by_hand = Schedule::new(
        radar,
        2,
        frozen.scene_time_s(),
        frozen.dwells().iter().rev().cloned().collect(),
    )
    .unwrap();
    let a = sim.run(&Request::new(9).schedule(&frozen)).unwrap();
    let b = sim.run(&Request::new(9).schedule(&by_hand)).unwrap();
    assert_eq!(a.polar_db, b.polar_db);
    assert_eq!(
        a.polar_db,
        sim.run(&Request::new(9).frame(2)).unwrap().polar_db
    );
}

/// Schedules that cannot be run are refused with the field and the reason.
#[test]
fn bad_schedules_are_refused() {
    let sim = Simulation::new(scene(NOISE_ONLY));
    let radar = sim.scene().radar();
    let good = Schedule::frozen_scan(radar, 0).dwells().to_vec();
    let check = |dwells: Vec<Dwell>, time: f64, problem: Problem, field: &str| {
        let e = Schedule::new(radar, 0, time, dwells).unwrap_err();
        assert_eq!(e.problem(), Some(problem), "{e}");
        assert!(e.to_string().contains(field), "{e}");
    };
    check(
        good[1..].to_vec(),
        0.0,
        Problem::Conflict,
        "schedule.dwells",
    );
    let mut twice = good.clone();
    twice[1].spoke = 0;
    check(twice, 0.0, Problem::Conflict, "schedule.dwells[1].spoke");
    let mut empty = good.clone();
    empty[5].pulses.clear();
    check(empty, 0.0, Problem::Missing, "schedule.dwells[5].pulses");
    let mut same_number = good.clone();
    same_number[7].pulses[0].number = 3;
    check(
        same_number,
        0.0,
        Problem::Conflict,
        "schedule.dwells[7].pulses",
    );
    let mut nan = good.clone();
    nan[2].pulses[0].azimuth_rad = f64::NAN;
    check(nan, 0.0, Problem::NotFinite, "schedule.dwells[2].pulses");
    check(
        good,
        f64::INFINITY,
        Problem::NotFinite,
        "schedule.scene_time_s",
    );
}

/// Non-coherent integration of N pulses of noise: the mean of N independent exponential
/// powers has normalised variance `var/mean² = 1/N` (a Gamma(N) variable; Richards,
/// *Fundamentals of Radar Signal Processing*, 2nd ed., §6.3), so the dwell's independent
/// noise streams and the averaging are checked together. Measured over 64 spokes × ~790 bins
/// (neighbouring bins correlate over fs/B = 2 samples): ±10 %.
#[test]
fn noncoherent_integration_averages_independent_pulses() {
    let sim = Simulation::new(scene(NOISE_ONLY));
    let radar = sim.scene().radar();
    let skip_bins = 2 * sim.compressor().pulse_len();
    for pulses_per_dwell in [1u64, 4, 16] {
        let dwells = (0..radar.spokes())
            .map(|k| Dwell {
                spoke: k,
                pulses: (0..pulses_per_dwell)
                    .map(|p| Pulse {
                        number: k as u64 * pulses_per_dwell + p,
                        time_s: 0.0,
                        azimuth_rad: radar.spoke_azimuth_rad(k),
                    })
                    .collect(),
            })
            .collect();
        let schedule = Schedule::new(radar, 0, 0.0, dwells).unwrap();
        let frame = sim.run(&Request::new(5).schedule(&schedule)).unwrap();
        let powers: Vec<f64> = frame
            .polar_db
            .chunks(frame.range_bins)
            .flat_map(|row| row[skip_bins..].iter())
            .map(|&db| 10f64.powf(db as f64 / 10.0))
            .collect();
        let n = powers.len() as f64;
        let mean = powers.iter().sum::<f64>() / n;
        let var = powers.iter().map(|p| (p - mean).powi(2)).sum::<f64>() / n;
        let normalised = var / (mean * mean);
        let want = 1.0 / pulses_per_dwell as f64;
        assert!(
            (normalised / want - 1.0).abs() < 0.1,
            "{pulses_per_dwell} pulses: var/mean² = {normalised:.4}, want {want:.4}"
        );
        assert!((mean - 1.0).abs() < 0.05, "mean noise power {mean}");
    }
}

/// Gain and STC on the compressed signal, before detection: every bin of a noise-free frame
/// rises by the gain and, inside the STC's reach, falls by `10·k·log10(R_stc/R)` (Skolnik,
/// *Radar Handbook*, 3rd ed., §2.9), against the same frame without them (to 10⁻³ dB); the
/// neutral setting leaves the bytes as they were.
#[test]
fn gain_and_stc_act_on_the_compressed_signal() {
    let text = format!(
        "{}[environment]\nnoise = false\nclutter = false\nmultipath = false\n\
         [[object]]\nname = \"near\"\nshape = \"point\"\nrcs_m2 = 10.0\nposition_m = [0.0, 400.0, 4.0]\n\
         [[object]]\nname = \"far\"\nshape = \"point\"\nrcs_m2 = 10.0\nposition_m = [0.0, 1100.0, 4.0]\n",
        "[radar]\nspokes = 64\nmax_range_m = 1500.0\n"
    );
    let sim = Simulation::new(scene(&text));
    let plain = sim.run(&Request::new(1)).unwrap();
    let range_bin_m = sim.scene().radar().range_bin_m();
    let stage = |gain_db: f32, stc_law: f32| xbandsim::receiver::stages::GainStc {
        gain_db,
        stc_law,
        stc_reach_m: 1000.0,
        range_bin_m,
    };
    let neutral = sim
        .with_gain_stc(stage(0.0, 0.0))
        .run(&Request::new(1))
        .unwrap();
    assert_eq!(neutral.polar_db, plain.polar_db);
    let shaped = sim
        .with_gain_stc(stage(6.0, 3.0))
        .run(&Request::new(1))
        .unwrap();
    let bins = plain.range_bins;
    let mut near_and_far = [0usize; 2];
    for (i, (&a, &b)) in plain.polar_db.iter().zip(&shaped.polar_db).enumerate() {
        if a < -60.0 {
            continue;
        }
        let r = (i % bins) as f64 * range_bin_m;
        let stc = if r < 1000.0 {
            30.0 * (1000.0 / r.max(1.0)).log10()
        } else {
            0.0
        };
        let want = f64::from(a) + 6.0 - stc;
        assert!(
            (f64::from(b) - want).abs() < 1e-3,
            "bin {} at {r:.0} m: {b} vs {want}",
            i % bins
        );
        near_and_far[usize::from(r >= 1000.0)] += 1;
    }
    assert!(
        near_and_far[0] > 0 && near_and_far[1] > 0,
        "{near_and_far:?}"
    );
}
