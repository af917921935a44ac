//! Artefacts through the pipeline, each against its label: another radar's pulses land where
//! the interference label says, at its level, walk in range from sweep to sweep, and the
//! receiver's interference rejection removes them.

use crate::common::{radar_block_no_noise, render};
use xbandsim::products::artefacts::{ArtefactKind, SIDELOBE_LABEL_DB};

/// The artefacts of `kind` in frame `f`.
fn of_kind(
    f: &xbandsim::Frame,
    kind: ArtefactKind,
) -> Vec<&xbandsim::products::artefacts::ArtefactTruth> {
    f.artefacts.iter().filter(|a| a.kind == kind).collect()
}

/// A magnetron set (unmodulated 0.3 µs pulse, 2000 Hz, 3 km recorded) and a 4 kW set 3 km
/// east firing 0.3 µs pulses at 1173.7 Hz, turning at 22 rpm.
fn scene(receiver: &str) -> String {
    format!(
        "{}[[artefacts.interferer]]\nname = \"ferry radar\"\nposition_m = [3000.0, 0.0, 10.0]\n\
         prf_hz = 1173.7\npulse_width_us = 0.3\nrotation_rpm = 22.0\n{receiver}",
        radar_block_no_noise(
            "transmitter = \"magnetron\"\npulse_width_us = 0.3\nprf_hz = 2000.0\nspokes = 360\n\
             max_range_m = 3000.0\nsample_rate_mhz = 20.0"
        )
    )
}

/// With noise off, every cell of the record at 6 dB or more lies in one of the interference
/// label's boxes, and each box's peak is its pulse's expected level within 0.1 dB (a pulse
/// matched to the receiver's unmodulated one); the hits walk in range from spoke to spoke.
#[test]
fn interference_lands_where_its_label_says() {
    let (sim, f) = render(&scene(""), 1);
    // The target-only render (the dataset's masks) has no other transmitters.
    let quiet = sim.targets_only().render(1);
    assert!(quiet
        .polar_db
        .iter()
        .all(|&v| f64::from(v) < SIDELOBE_LABEL_DB));
    let a = of_kind(&f, ArtefactKind::Interference);
    assert_eq!(a.len(), 1);
    let a = a[0];
    assert_eq!(a.source, "ferry radar");
    // A spoke's one pulse records 20 µs of a 1173.7 Hz train: 360 × 20 µs × 1173.7 ≈ 8 hits.
    assert!(
        (5..=12).contains(&a.polar_boxes.len()),
        "{} hits",
        a.polar_boxes.len()
    );
    let bins = f.range_bins;
    let mut in_box = vec![false; f.spokes * bins];
    for b in &a.polar_boxes {
        for j in b.bin_min..=b.bin_max {
            in_box[b.spoke_min * bins + j] = true;
        }
    }
    for (i, &v) in f.polar_db.iter().enumerate() {
        if f64::from(v) >= SIDELOBE_LABEL_DB {
            assert!(
                in_box[i],
                "cell {} of spoke {} at {v:.1} dB unlabelled",
                i % bins,
                i / bins
            );
        }
    }
    // Hit after hit lands at another range (the PRFs differ: the pulses walk).
    let firsts: Vec<(usize, usize)> = a
        .polar_boxes
        .iter()
        .map(|b| (b.spoke_min, b.bin_min))
        .collect();
    let moved = firsts.windows(2).filter(|w| w[0].1 != w[1].1).count();
    assert_eq!(moved + 1, firsts.len(), "{firsts:?}");
    // The strongest hit's peak against the label's level.
    let peak = a
        .polar_boxes
        .iter()
        .map(|b| {
            (b.bin_min..=b.bin_max)
                .map(|j| f.polar_db[b.spoke_min * bins + j])
                .fold(f32::MIN, f32::max)
        })
        .fold(f32::MIN, f32::max);
    assert!(
        (f64::from(peak) - a.expected_level_db.unwrap()).abs() < 0.1,
        "peak {peak:.2} dB, label {:?} dB",
        a.expected_level_db
    );
}

/// The receiver's interference rejection at "high" clears the interference from the video:
/// under 5 % of its labelled spokes keep a non-zero sample, where without it most do.
#[test]
fn interference_rejection_clears_the_labelled_interference() {
    let hits = |level: &str| {
        let text = scene(&format!(
            "[receiver]\nvideo_spokes = 360\nvideo_samples = 400\ninterference_rejection = \"{level}\"\n"
        ));
        let (_, f) = render(&text, 1);
        let v = f.video.as_ref().unwrap();
        let a = f
            .artefacts
            .iter()
            .find(|a| a.kind == ArtefactKind::Interference)
            .unwrap();
        let lit = a
            .polar_boxes
            .iter()
            .filter(|b| {
                let sample = |j: usize| {
                    ((j as f64 * f.range_bin_m / v.sample_m) as usize).min(v.samples - 1)
                };
                (sample(b.bin_min)..=sample(b.bin_max))
                    .any(|j| v.levels[b.spoke_min * v.samples + j] > 0)
            })
            .count();
        lit as f64 / a.polar_boxes.len() as f64
    };
    let off = hits("off");
    let high = hits("high");
    assert!(off > 0.5, "without rejection {off:.2} of the hits show");
    assert!(high < 0.05, "with rejection {high:.2} of the hits show");
}

/// The runs of spoke `k`'s cells at 6 dB or more beyond bin `from`: (first bin, length).
fn runs(f: &xbandsim::Frame, k: usize, from: usize) -> Vec<(usize, usize)> {
    let row = &f.polar_db[k * f.range_bins..(k + 1) * f.range_bins];
    let mut out: Vec<(usize, usize)> = Vec::new();
    for j in from..f.range_bins {
        if f64::from(row[j]) >= SIDELOBE_LABEL_DB {
            match out.last_mut() {
                Some((s, n)) if *s + *n == j => *n += 1,
                _ => out.push((j, 1)),
            }
        }
    }
    out
}

fn beacon_scene(table: &str) -> String {
    format!(
        "{}{table}",
        radar_block_no_noise(
            "transmitter = \"magnetron\"\npulse_width_us = 0.3\nprf_hz = 2000.0\nspokes = 360\n\
             max_range_m = 3000.0\nsample_rate_mhz = 20.0"
        )
    )
}

/// A racon 600 m north sending K (−·−) over 1 NM after 0.5 µs: on the spokes its beam
/// triggers, three marks beyond it whose lengths go 3 : 1 : 3 (a dash three dots; ITU-R
/// M.1677-1), the first 75 m (0.5 µs) behind it; every cell at 6 dB or more in the racon's
/// label, whose level is the marks' peak within 0.1 dB; no answer where the beam is away.
#[test]
fn a_racon_answers_with_its_morse_letter_where_its_label_says() {
    let (_, f) = render(
        &beacon_scene("[[artefacts.racon]]\nname = \"fairway\"\nposition_m = [0.0, 600.0, 5.0]\nmorse = \"K\"\n"),
        1,
    );
    let a = of_kind(&f, ArtefactKind::Racon);
    assert_eq!(a.len(), 1);
    let a = a[0];
    assert_eq!(a.source, "fairway");
    let marks = runs(&f, 0, 0);
    assert_eq!(marks.len(), 3, "{marks:?}");
    let bin_m = f.range_bin_m;
    // The matched filter widens each mark by about N_T − 1 = 5 bins.
    let widths: Vec<f64> = marks.iter().map(|m| m.1 as f64 - 5.0).collect();
    assert!((widths[0] / widths[1] - 3.0).abs() < 0.3, "{widths:?}");
    assert!((widths[2] / widths[1] - 3.0).abs() < 0.3, "{widths:?}");
    // The output starts N_T − 1 = 5 bins before the mark does.
    let start_m = (marks[0].0 as f64 + 5.0) * bin_m;
    assert!((start_m - 675.0).abs() < 2.0 * bin_m, "{start_m}");
    let bins = f.range_bins;
    let mut in_box = vec![false; f.spokes * bins];
    for b in &a.polar_boxes {
        for j in b.bin_min..=b.bin_max {
            in_box[b.spoke_min * bins + j] = true;
        }
    }
    let mut peak = f32::MIN;
    for (i, &v) in f.polar_db.iter().enumerate() {
        if f64::from(v) >= SIDELOBE_LABEL_DB {
            assert!(
                in_box[i],
                "cell {} of spoke {} at {v:.1} dB unlabelled",
                i % bins,
                i / bins
            );
            peak = peak.max(v);
        }
    }
    assert!(
        (f64::from(peak) - a.expected_level_db.unwrap()).abs() < 0.1,
        "{peak} vs {:?}",
        a.expected_level_db
    );
    assert!(runs(&f, 180, 0).is_empty());
}

/// A SART 500 m north: dots every 7.5 µs (1124.2 m) outward from it, within a bin, and
/// labelled; SART settings a racon has are refused naming the field.
#[test]
fn a_sart_answers_with_dots_every_seven_and_a_half_microseconds() {
    let (_, f) = render(
        &beacon_scene("[[artefacts.sart]]\nposition_m = [0.0, 500.0, 2.0]\n"),
        1,
    );
    assert!(f
        .artefacts
        .iter()
        .any(|a| a.kind == ArtefactKind::Sart && a.source == "sart-0"));
    let dots = runs(&f, 0, 0);
    assert_eq!(dots.len(), 3, "{dots:?}");
    for w in dots.windows(2) {
        let spacing_m = (w[1].0 as f64 - w[0].0 as f64) * f.range_bin_m;
        assert!((spacing_m - 1124.2).abs() <= f.range_bin_m, "{spacing_m}");
    }
    let e = xbandsim::model::Scene::from_toml_str(
        &beacon_scene("[[artefacts.sart]]\nposition_m = [0.0, 500.0, 2.0]\nmorse = \"K\"\n"),
        "test",
    )
    .unwrap_err();
    assert_eq!(e.field(), Some("artefacts.sart[0].morse"), "{e}");
    let e = xbandsim::model::Scene::from_toml_str(
        &beacon_scene("[[artefacts.racon]]\nposition_m = [0.0, 500.0, 2.0]\nmorse = \"KK\"\n"),
        "test",
    )
    .unwrap_err();
    assert_eq!(e.field(), Some("artefacts.racon[0].morse"), "{e}");
}

/// Second-trace echoes: at 20 kHz (unambiguous range c/(2·PRF) = 7494.8 m) a target 9 km
/// north, beyond the 3 km record, echoes at `R − c/(2·PRF)` = 1505.2 m within one bin with
/// `[artefacts] second_trace`, labelled there as a `second_trace` artefact; without it there
/// is no echo and no label.
#[test]
fn second_trace_echoes_land_at_r_minus_the_unambiguous_range() {
    let text = |on: bool| {
        format!(
            "{}[artefacts]\nsecond_trace = {on}\n{}",
            radar_block_no_noise("prf_hz = 20000.0\nspokes = 90\nmax_range_m = 3000.0"),
            crate::common::point_north("far", 9000.0, 1.0e4)
        )
    };
    let (_, f) = render(&text(true), 1);
    let row = &f.polar_db[..f.range_bins];
    let peak = (0..f.range_bins)
        .max_by(|&a, &b| row[a].total_cmp(&row[b]))
        .unwrap();
    let expect_m = 9000.0 - 299_792_458.0 / (2.0 * 20_000.0);
    assert!(
        (peak as f64 * f.range_bin_m - expect_m).abs() <= f.range_bin_m,
        "peak at {} m, expected {expect_m} m",
        peak as f64 * f.range_bin_m
    );
    assert!(row[peak] > 20.0, "{}", row[peak]);
    let a = of_kind(&f, ArtefactKind::SecondTrace);
    assert_eq!(a.len(), 1);
    let b = a[0].polar_boxes[0];
    assert!(b.bin_min <= peak && peak <= b.bin_max, "{b:?} vs {peak}");
    assert!(b.spoke_indices(f.spokes).any(|k| k == 0));
    let (_, off) = render(&text(false), 1);
    assert!(off.polar_db[..off.range_bins]
        .iter()
        .all(|&v| f64::from(v) < SIDELOBE_LABEL_DB));
    assert!(off
        .artefacts
        .iter()
        .all(|a| a.kind != ArtefactKind::SecondTrace));
}

/// A blind sector behind the own ship's mast, 170°–190° off the bow, on a ship heading 90°
/// (east): a target due west (270° true, 180° off the bow) loses the
/// sector's 20 dB two-way, in the record and in its label (`losses.blind_sector`, expected
/// SNR), within 0.05 dB; a target outside the sector loses nothing; the sector is labelled.
#[test]
fn a_blind_sector_weakens_echoes_behind_the_mast_as_labelled() {
    let text = |sector: bool| {
        format!(
            "{}[own_ship]\nheading_deg = 90.0\ncourse_deg = 90.0\n{}\
             [[object]]\nname = \"west\"\nshape = \"point\"\nrcs_m2 = 10.0\nposition_m = [-800.0, 0.0, 4.0]\n\
             [[object]]\nname = \"north\"\nshape = \"point\"\nrcs_m2 = 10.0\nposition_m = [0.0, 800.0, 4.0]\n",
            radar_block_no_noise("spokes = 360\nmax_range_m = 1500.0"),
            if sector {
                "[[own_ship.structure]]\nname = \"mast\"\nfrom_deg = 170.0\nto_deg = 190.0\nloss_db = 20.0\n"
            } else {
                ""
            }
        )
    };
    let peak = |f: &xbandsim::Frame, k: usize| {
        f.polar_db[k * f.range_bins..(k + 1) * f.range_bins]
            .iter()
            .copied()
            .fold(f32::MIN, f32::max) as f64
    };
    let (_, open) = render(&text(false), 1);
    let (_, blind) = render(&text(true), 1);
    assert!((peak(&open, 270) - peak(&blind, 270) - 20.0).abs() < 0.05);
    assert!((peak(&open, 0) - peak(&blind, 0)).abs() < 1e-9);
    let label =
        |f: &xbandsim::Frame, name: &str| f.truth.iter().find(|o| o.name == name).unwrap().clone();
    let (w_open, w_blind) = (label(&open, "west"), label(&blind, "west"));
    assert_eq!(w_blind.losses_db.blind_sector, 20.0);
    assert_eq!(label(&blind, "north").losses_db.blind_sector, 0.0);
    let drop = w_open.expected_snr_db.unwrap() - w_blind.expected_snr_db.unwrap();
    assert!((drop - 20.0).abs() < 1e-9, "{drop}");
    let a = of_kind(&blind, ArtefactKind::BlindSector);
    assert_eq!(a.len(), 1);
    assert_eq!(a[0].source, "mast");
    let spokes: Vec<usize> = a[0].polar_boxes[0].spoke_indices(360).collect();
    // 260°–280° true; the far edge's spoke may fall either side in floating point, the
    // same for the chain and the label (both ask BlindSector::contains).
    assert_eq!(spokes[0], 260, "{spokes:?}");
    assert!((20..=21).contains(&spokes.len()), "{spokes:?}");
}

/// The strongest cell of spoke `k`: (bin, dB).
fn spoke_peak(f: &xbandsim::Frame, k: usize, bins: std::ops::Range<usize>) -> (usize, f64) {
    let row = &f.polar_db[k * f.range_bins..(k + 1) * f.range_bins];
    let j = bins.max_by(|&a, &b| row[a].total_cmp(&row[b])).unwrap();
    (j, f64::from(row[j]))
}

/// A staggered train's second trace: PRF 20 kHz staggered 1.0 : 1.1 : 0.9 (intervals 50, 55
/// and 45 µs) folds a target 9 km north to `R − c·T_k/2` = 1505.2, 755.7 and 2254.7 m, each
/// within one bin; each fold carries a third of the power, so its peak is the unstaggered
/// fold's less `10·log10 3` = 4.77 dB (0.2 dB: the fractional sample position differs), and
/// each is labelled there at that level.
#[test]
fn a_staggered_train_smears_the_second_trace_over_its_intervals() {
    let text = |stagger: &str| {
        format!(
            "{}[artefacts]\nsecond_trace = true\n{}",
            radar_block_no_noise(&format!(
                "prf_hz = 20000.0\n{stagger}spokes = 90\nmax_range_m = 3000.0"
            )),
            crate::common::point_north("far", 9000.0, 1.0e4)
        )
    };
    let (_, plain) = render(&text(""), 1);
    let (_, staggered) = render(&text("prf_stagger = [1.0, 1.1, 0.9]\n"), 1);
    let (_, plain_db) = spoke_peak(&plain, 0, 0..plain.range_bins);
    let c = 299_792_458.0;
    let folds = of_kind(&staggered, ArtefactKind::SecondTrace);
    assert_eq!(folds.len(), 3);
    let plain_label = plain
        .artefacts
        .iter()
        .find(|a| a.kind == ArtefactKind::SecondTrace)
        .unwrap()
        .expected_level_db
        .unwrap();
    for (t_s, a) in [50e-6, 55e-6, 45e-6].iter().zip(&folds) {
        let expect_m = 9000.0 - c * t_s / 2.0;
        let bin = (expect_m / staggered.range_bin_m).round() as usize;
        let (peak, db) = spoke_peak(&staggered, 0, bin - 3..bin + 4);
        assert!(
            (peak as f64 * staggered.range_bin_m - expect_m).abs() <= staggered.range_bin_m,
            "fold at {} m, expected {expect_m} m",
            peak as f64 * staggered.range_bin_m
        );
        let share_db = 10.0 * 3f64.log10();
        assert!((plain_db - db - share_db).abs() < 0.2, "{plain_db} vs {db}");
        let b = a.polar_boxes[0];
        assert!(b.bin_min <= peak && peak <= b.bin_max, "{b:?} vs {peak}");
        let level = a.expected_level_db.unwrap();
        assert!((plain_label - level - share_db).abs() < 1e-9);
    }
}

/// Multiple echoes (`xbandsim_validate::receiver::multiple_echo_scene`): a 10⁴ m² target due
/// east of an own ship heading north (abeam, and its bow north: parallel) shows again at 2R
/// and 3R on its bearing, `20·log10 n + (n−1)·6` dB weaker (6.02 + 6 and 9.54 + 12 dB) within
/// 0.1 dB, each labelled there at that level; the same target due north (ahead) shows none.
#[test]
fn a_ship_abeam_shows_multiple_echoes_at_multiples_of_its_range() {
    use xbandsim_validate::receiver::{multiple_echo_drop_db, multiple_echo_scene};
    let (_, f) = render(&multiple_echo_scene(true), 1);
    let (direct_bin, _) = spoke_peak(&f, 90, 0..f.range_bins);
    assert_eq!(direct_bin, 250);
    assert_eq!(f.truth[0].losses_db.eclipse, Some(0.0));
    let a = of_kind(&f, ArtefactKind::MultipleEcho);
    assert_eq!(a.len(), 2);
    for (n, a) in [2usize, 3].into_iter().zip(a) {
        let (bin, _) = spoke_peak(&f, 90, 250 * n - 3..250 * n + 4);
        assert_eq!(bin, 250 * n);
        let (want, drop) = multiple_echo_drop_db(n);
        assert!(
            (drop - want).abs() < 0.1,
            "order {n}: {drop} dB, want {want}"
        );
        let b = a.polar_boxes[0];
        assert!(b.bin_min <= bin && bin <= b.bin_max, "{b:?} vs {bin}");
        assert!(b.spoke_indices(360).any(|k| k == 90));
        let snr = f.truth[0].expected_snr_db.unwrap();
        assert!((snr - a.expected_level_db.unwrap() - want).abs() < 1e-9);
        assert_eq!(a.source, "tanker");
    }
    // Ahead: no second echo, no label.
    let (_, ahead) = render(&multiple_echo_scene(false), 1);
    let (_, db) = spoke_peak(&ahead, 0, 490..510);
    assert!(db < SIDELOBE_LABEL_DB, "{db}");
    assert!(ahead
        .artefacts
        .iter()
        .all(|a| a.kind != ArtefactKind::MultipleEcho));
}

/// Indirect echoes (`xbandsim_validate::receiver::indirect_echo_scene`): a funnel 10 bins aft
/// (sector 170°–190°, `indirect_db = −10`) on an own ship heading north shows a target dead
/// ahead at 100 bins on the funnel's bearing 180°, at `d + |P − S|` = R + 2d = 120 bins, with
/// the direct echo's peak less 2 × 10 dB within 0.1 dB; the label's box holds it at that
/// level; away from both bearings there is nothing.
#[test]
fn a_funnel_shows_indirect_echoes_on_its_bearing() {
    use xbandsim_validate::receiver::{indirect_echo_drop_db, indirect_echo_scene};
    let (sim, f) = render(&indirect_echo_scene(), 1);
    let (direct_bin, _) = spoke_peak(&f, 0, 0..f.range_bins);
    assert_eq!(direct_bin, 100);
    let (bin, _) = spoke_peak(&f, 180, 0..f.range_bins);
    assert_eq!(bin, 120);
    let (want, drop) = indirect_echo_drop_db();
    assert!((drop - want).abs() < 0.1, "{drop} dB, want {want}");
    let a = of_kind(&f, ArtefactKind::IndirectEcho);
    assert_eq!(a.len(), 1);
    let b = a[0].polar_boxes[0];
    assert!(b.bin_min <= bin && bin <= b.bin_max, "{b:?} vs {bin}");
    assert!(b.spoke_indices(360).any(|k| k == 180), "{b:?}");
    let level = a[0].expected_level_db.unwrap();
    assert!(
        (f.truth[0].expected_snr_db.unwrap() - level - 20.0).abs() < 1e-9,
        "{level}"
    );
    let (_, db) = spoke_peak(&f, 90, 0..f.range_bins);
    assert!(db < SIDELOBE_LABEL_DB, "{db}");
    // Through the sidelobes, inside the sector (8° off the funnel) and outside it (15° off),
    // the indirect echo is `20·log10 Gn(Δaz)` under its peak within 0.1 dB — the blind
    // sector's loss applies to neither (the echo comes from the funnel, not through it) —
    // and a sidelobe label holds it.
    let (direct_db, indirect_db) = (
        spoke_peak(&f, 0, 95..106).1,
        spoke_peak(&f, 180, 115..126).1,
    );
    let pattern = sim.scene().radar().antenna().azimuth();
    for off in [8usize, 15] {
        let k = 180 + off;
        let (bin, db) = spoke_peak(&f, k, 115..126);
        let want = indirect_db + 20.0 * pattern.value((off as f64).to_radians()).log10();
        assert!((db - want).abs() < 0.1, "{off}°: {db} dB, want {want}");
        assert!(direct_db - db > 20.0);
        let labelled = f.artefacts.iter().any(|a| {
            a.kind == ArtefactKind::Sidelobe
                && a.polar_boxes.iter().any(|b| {
                    b.spoke_indices(360).any(|s| s == k) && b.bin_min <= bin && bin <= b.bin_max
                })
        });
        assert!(
            labelled || db < SIDELOBE_LABEL_DB,
            "{off}°: {db} dB unlabelled"
        );
    }
}

/// Bad multiple-echo and indirect-echo values are refused naming the field.
#[test]
fn bad_own_ship_path_values_are_refused() {
    for (table, field) in [
        (
            "[artefacts.multiple_echoes]\nmax_order = 1\n",
            "artefacts.multiple_echoes.max_order",
        ),
        (
            "[artefacts.multiple_echoes]\nround_trip_loss_db = -3.0\n",
            "artefacts.multiple_echoes.round_trip_loss_db",
        ),
        (
            "[[own_ship.structure]]\nfrom_deg = 170.0\nto_deg = 190.0\nindirect_db = -10.0\n",
            "own_ship.structure[0].distance_m",
        ),
        (
            "[[own_ship.structure]]\nfrom_deg = 170.0\nto_deg = 190.0\nindirect_db = 3.0\ndistance_m = 10.0\n",
            "own_ship.structure[0].indirect_db",
        ),
    ] {
        let text = format!("{}[own_ship]\n{table}", radar_block_no_noise(""));
        let e = xbandsim::Scene::from_toml_str(&text, "test").unwrap_err();
        assert_eq!(e.field(), Some(field), "{e}");
    }
    // Multiple echoes need an own ship's side.
    let text = format!("{}[artefacts.multiple_echoes]\n", radar_block_no_noise(""));
    let e = xbandsim::Scene::from_toml_str(&text, "test").unwrap_err();
    assert_eq!(e.field(), Some("artefacts.multiple_echoes"), "{e}");
}
