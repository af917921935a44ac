//! Antenna pattern against closed forms, alone and through the rotating-beam pipeline.

use super::common::*;
use xbandsim::antenna::{sinc2_pattern, uniform_aperture_gain, SINC_BEAMWIDTH_FACTOR};
use xbandsim::constants::linear_to_db;

/// −3 dB at ±θ3dB/2, first null at π·θ3dB/2.783, first sidelobe −13.26 dB (sinc², e.g.
/// Balanis, *Antenna Theory*, 4th ed., §12.5; docs/physics.md §3).
#[test]
fn sinc2_pattern_landmarks() {
    for bw_deg in [3.9, 25.0, 1.2] {
        let bw = f64::to_radians(bw_deg);
        for sign in [-1.0, 1.0] {
            let g = linear_to_db(sinc2_pattern(sign * bw / 2.0, bw));
            assert!(
                (g + 3.0103).abs() < 0.01,
                "{bw_deg} deg: {g} dB at half beamwidth"
            );
        }
        let null = std::f64::consts::PI * bw / SINC_BEAMWIDTH_FACTOR;
        assert!(sinc2_pattern(null, bw) < 1e-12);
        // First sidelobe: maximum between the first and second nulls.
        let peak = (0..=2000)
            .map(|i| null * (1.0 + i as f64 / 2000.0))
            .map(|t| sinc2_pattern(t, bw))
            .fold(0.0, f64::max);
        assert!(
            (linear_to_db(peak) + 13.26).abs() < 0.02,
            "first sidelobe {} dB",
            linear_to_db(peak)
        );
    }
}

/// Peak gain of a uniform aperture with 3.9° × 25° beams: 25.2 dBi (issue #2).
#[test]
fn peak_gain_from_beamwidths() {
    let g = linear_to_db(uniform_aperture_gain(
        3.9f64.to_radians(),
        25f64.to_radians(),
    ));
    assert!((g - 25.2).abs() < 0.05, "{g} dBi");
}

/// Through the pipeline: a point target half a beamwidth off a spoke comes back at the
/// two-way pattern, −6.02 dB (power ∝ Gn²), and one first-null away it vanishes into noise.
#[test]
fn rotating_beam_applies_two_way_pattern() {
    let bw_deg = 3.9;
    let range_m = bin_range_m(600.0, 100e6);
    let at = |az_deg: f64| {
        let (x, y) = (
            range_m * az_deg.to_radians().sin(),
            range_m * az_deg.to_radians().cos(),
        );
        let text = format!(
            "{}[[object]]\nname = \"p\"\nshape = \"point\"\nrcs_m2 = 100.0\nposition_m = [{x}, {y}, 4.0]\n",
            radar_block_no_noise("spokes = 360\nmax_range_m = 1200.0")
        );
        let (_, frame) = render(&text, 1);
        let (_, v) = argmax(spoke(&frame, 0));
        v as f64
    };
    let on_axis = at(0.0);
    let half = at(bw_deg / 2.0);
    assert!(
        (half - on_axis + 6.02).abs() < 0.1,
        "two-way loss at half beamwidth {} dB",
        half - on_axis
    );
    let null_deg = 180.0 * bw_deg / SINC_BEAMWIDTH_FACTOR;
    let at_null = at(null_deg);
    assert!(
        at_null < on_axis - 60.0,
        "first null {} dB below peak",
        on_axis - at_null
    );
}

/// A tapered array's sidelobes through the pipeline: a strong point target due north shows on
/// every spoke at the two-way pattern `Gn(Δaz)²` relative to its peak — in the near sidelobes,
/// on the far-sidelobe floor and in the back lobe — within 0.05 dB (noise off; spoke k at
/// exactly k°). The sidelobe arcs a real set draws round a strong echo near it.
#[test]
fn sidelobe_echoes_follow_the_two_way_pattern_round_the_circle() {
    let text = format!(
        "{}{}",
        radar_block_no_noise(
            "spokes = 360\nmax_range_m = 1500.0\nazimuth_beamwidth_deg = 1.1\n\
             antenna_pattern = \"taylor\"\nsidelobe_db = -23.0\nfar_sidelobe_db = -30.0\n\
             back_lobe_db = -35.0"
        ),
        point_north("ship", 600.0, 1.0e5)
    );
    let (sim, f) = render(&text, 1);
    let pattern = sim.scene().radar().antenna().azimuth();
    let peak = |k: usize| {
        f.polar_db[k * f.range_bins..(k + 1) * f.range_bins]
            .iter()
            .copied()
            .fold(f32::MIN, f32::max)
    };
    let on_axis = f64::from(peak(0));
    assert!(on_axis > 80.0, "{on_axis}");
    for k in [2usize, 5, 10, 20, 45, 90, 120, 180, 270, 355] {
        let off = f64::to_radians(k as f64);
        let expect = 2.0 * linear_to_db(pattern.value(off));
        let got = f64::from(peak(k)) - on_axis;
        assert!(
            (got - expect).abs() < 0.05,
            "spoke {k}: {got:.3} dB under the peak, pattern {expect:.3} dB"
        );
    }
    // The back lobe is the two-way −70 dB; the far sidelobes the −60 dB floor.
    assert!((f64::from(peak(180)) - on_axis + 70.0).abs() < 0.05);
    assert!((f64::from(peak(45)) - on_axis + 60.0).abs() < 0.05);
}

/// Sidelobe echoes are labelled where they are: with noise off, every spoke outside the main
/// lobe whose echo peaks at 6 dB or more lies in a `sidelobe` artefact's polar box of the
/// target, and every labelled spoke's echo peaks there within 0.05 dB of the label's level
/// or above 6 dB.
#[test]
fn sidelobe_echoes_are_labelled_as_artefacts() {
    use xbandsim::products::artefacts::{ArtefactKind, SIDELOBE_LABEL_DB};
    let text = format!(
        "{}{}",
        radar_block_no_noise(
            "spokes = 360\nmax_range_m = 1500.0\nazimuth_beamwidth_deg = 1.1\n\
             antenna_pattern = \"taylor\"\nsidelobe_db = -23.0\nfar_sidelobe_db = -30.0"
        ),
        point_north("ship", 600.0, 300.0)
    );
    let (sim, f) = render(&text, 1);
    let null_deg = sim
        .scene()
        .radar()
        .antenna()
        .azimuth()
        .first_null_rad()
        .to_degrees();
    assert!(!f.artefacts.is_empty());
    let mut labelled = vec![false; 360];
    for a in &f.artefacts {
        assert_eq!(a.kind, ArtefactKind::Sidelobe);
        assert_eq!(a.source, "ship");
        for b in &a.polar_boxes {
            for k in b.spoke_indices(360) {
                labelled[k] = true;
            }
            assert!(b.bin_min <= 400 && b.bin_max >= 400, "{b:?}");
        }
    }
    let peak = |k: usize| {
        f.polar_db[k * f.range_bins..(k + 1) * f.range_bins]
            .iter()
            .copied()
            .fold(f32::MIN, f32::max) as f64
    };
    for k in 0..360 {
        let off = (k as f64).min(360.0 - k as f64);
        if off <= null_deg + 1.0 {
            continue;
        }
        let p = peak(k);
        if labelled[k] {
            assert!(
                p >= SIDELOBE_LABEL_DB - 0.05,
                "spoke {k}: labelled, peak {p:.2} dB"
            );
        } else {
            assert!(
                p < SIDELOBE_LABEL_DB + 0.05,
                "spoke {k}: peak {p:.2} dB not labelled"
            );
        }
    }
    assert!(labelled.iter().filter(|&&l| l).count() >= 4);
}

/// A measured azimuth cut from a CSV file (here the Taylor −23 dB pattern written out at
/// 0.05° rows, as a range would measure it): the radar takes its beamwidth from it, and a
/// strong target's echo off its bearing follows the cut's two-way level within 0.05 dB.
/// A beamwidth given beside the file, or a file that is not a cut, is refused naming the
/// field.
#[test]
fn a_measured_pattern_cut_from_csv_shapes_the_echoes() {
    use xbandsim::antenna::Tapered;
    let taylor = Tapered::new(f64::to_radians(1.1), -23.0, 5, -30.0, -35.0);
    let mut csv = String::from("# a measured azimuth cut\nangle_deg,gain_db\n");
    for i in 0..=7200 {
        let a = -180.0 + i as f64 * 0.05;
        csv.push_str(&format!(
            "{a},{}\n",
            10.0 * taylor.value(a.to_radians()).log10()
        ));
    }
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("cut.csv"), &csv).unwrap();
    std::fs::write(dir.path().join("bad.csv"), "angle,gain\n0,0\n").unwrap();
    let scene_text = |extra: &str| {
        format!(
            "{}{}",
            radar_block_no_noise(&format!(
                "spokes = 360\nmax_range_m = 1500.0\nazimuth_pattern_file = \"cut.csv\"\n{extra}"
            )),
            point_north("ship", 600.0, 1.0e5)
        )
    };
    let load = |text: &str| {
        xbandsim::LoadedSpec::from_toml(text, "test", dir.path()).and_then(|s| s.build())
    };
    let scene = load(&scene_text("")).unwrap();
    let bw = scene.radar().antenna().az_beamwidth_rad.to_degrees();
    assert!((bw - 1.1).abs() < 0.02, "{bw}");
    let pattern = scene.radar().antenna().azimuth();
    let sim = xbandsim::Simulation::new(scene);
    let f = sim.render(1);
    let peak = |k: usize| {
        f64::from(
            f.polar_db[k * f.range_bins..(k + 1) * f.range_bins]
                .iter()
                .copied()
                .fold(f32::MIN, f32::max),
        )
    };
    for k in [3usize, 10, 40, 180] {
        let expect = 2.0 * linear_to_db(pattern.value(f64::to_radians(k as f64)));
        let got = peak(k) - peak(0);
        assert!(
            (got - expect).abs() < 0.05,
            "spoke {k}: {got:.3} vs {expect:.3}"
        );
    }
    let e = load(&scene_text("azimuth_beamwidth_deg = 2.0")).unwrap_err();
    assert_eq!(e.field(), Some("radar.azimuth_beamwidth_deg"), "{e}");
    let e = load(&scene_text("").replace("cut.csv", "bad.csv")).unwrap_err();
    assert_eq!(e.field(), Some("radar.azimuth_pattern_file"), "{e}");
    let e = load(&scene_text("").replace("cut.csv", "missing.csv")).unwrap_err();
    assert_eq!(e.field(), Some("radar.azimuth_pattern_file"), "{e}");
}
