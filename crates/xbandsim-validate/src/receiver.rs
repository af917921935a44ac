//! Checks of the receiver's video chain and the artefacts (docs/physics.md §13, §14) through
//! the real pipeline: the STC's attenuation against its law, the FTC's step response, the log
//! amplifier and threshold against the noise's exceedance, a sidelobe echo against the
//! two-way pattern, an interferer's pulse against its label, interference rejection, and the
//! levels of multiple and indirect echoes.

use crate::harness::{argmax, point_north, radar_block, radar_block_no_noise, render_text, spoke};
use crate::{check, Checks, Tolerance};
use xbandsim::products::artefacts::ArtefactKind;
use xbandsim::receiver::stages::Ftc;
use xbandsim::receiver::video_chain::manual_stc_db;

const BOLE: &str = "Bole, Wall & Norris, Radar and ARPA Manual, 3rd ed., 2014 (receiver controls); docs/physics.md §13";

/// The peak of spoke `k`'s row of a frame's record, dB.
fn row_peak(frame: &xbandsim::Frame, k: usize) -> f64 {
    f64::from(argmax(spoke(frame, k)).1)
}

/// Manual STC's attenuation of a point target at `range_m` measured in 8-bit video (0.078 dB
/// levels) against its law `min(12, 30·log10(1000/R))` at the peak sample: (law, measured), dB.
pub fn stc_attenuation_db(range_m: f64) -> (f64, f64) {
    let base = format!(
        "{}{}",
        radar_block_no_noise("spokes = 360\nmax_range_m = 1500.0"),
        point_north("p", range_m, 3.0)
    );
    let (_, calibrated) = render_text(&base, 3);
    let echo_db = row_peak(&calibrated, 0);
    let gain_db = 6.0 - (echo_db - 16.0);
    let video = |stc: &str| {
        let text = format!(
            "{base}[receiver]\nvideo_bits = 8\nvideo_samples = 1000\nvideo_spokes = 360\n\
             gain_db = {gain_db}\nvideo_span_db = 20.0\n{stc}"
        );
        let (_, f) = render_text(&text, 3);
        let v = f.video.expect("a [receiver] table makes video");
        let row = &v.levels[..v.samples];
        let j = (0..v.samples).max_by_key(|&j| row[j]).unwrap_or(0);
        (
            j,
            f64::from(row[j]) * f64::from(v.level_step_db),
            v.sample_m,
        )
    };
    let (_, off_db, _) = video("");
    let (j, on_db, sample_m) =
        video("stc = \"manual\"\nstc_level_db = 12.0\nstc_range_m = 1000.0\nstc_law = 3.0\n");
    let law = manual_stc_db((j as f64 + 0.5) * sample_m, 12.0, 1000.0, 3.0);
    (f64::from(law), off_db - on_db)
}

/// The FTC's step response at sample 10 of a 20 dB step (τ = 0.5 µs, 50 ns samples):
/// (closed form `20·a¹¹`, measured), dB of log video.
pub fn ftc_step_db() -> (f64, f64) {
    let ftc = Ftc::new(0.5e-6, 0.05e-6);
    let mut v = vec![20f32; 32];
    ftc.apply(&mut v);
    let a = 0.5 / 0.55f64;
    (20.0 * a.powi(11), f64::from(v[10]))
}

/// The share of noise-only video samples at or over the threshold `6 − gain` dB (one bin a
/// sample, 360 × 800 samples) against `exp(−(10^{T/10} − 1))`: (expected, measured).
pub fn noise_over_threshold(gain_db: f64) -> (f64, f64) {
    let text = format!(
        "{}[receiver]\nvideo_spokes = 360\nvideo_samples = 1001\ngain_db = {gain_db}\n",
        radar_block("spokes = 360\nmax_range_m = 1500.0")
    );
    let (_, f) = render_text(&text, 5);
    let v = f.video.expect("a [receiver] table makes video");
    let (mut over, mut all) = (0usize, 0usize);
    for s in 0..v.spokes {
        for &l in &v.levels[s * v.samples + 200..(s + 1) * v.samples] {
            over += usize::from(l > 0);
            all += 1;
        }
    }
    let t = 6.0 - gain_db;
    (
        (-(10f64.powf(t / 10.0) - 1.0)).exp(),
        over as f64 / all as f64,
    )
}

/// A 10⁵ m² target's echo on the spoke `off_deg` off it, under its peak, for the open-array
/// Taylor pattern (−23 dB, floor −30 dB): (two-way pattern `20·log10 Gn`, measured), dB.
pub fn sidelobe_echo_db(off_deg: usize) -> (f64, f64) {
    let text = format!(
        "{}{}",
        radar_block_no_noise(
            "spokes = 360\nmax_range_m = 1500.0\nazimuth_beamwidth_deg = 1.1\n\
             antenna_pattern = \"taylor\"\nsidelobe_db = -23.0\nfar_sidelobe_db = -30.0"
        ),
        point_north("ship", 600.0, 1.0e5)
    );
    let (sim, f) = render_text(&text, 1);
    let pattern = sim.scene().radar().antenna().azimuth();
    let expect = 20.0 * pattern.value((off_deg as f64).to_radians()).log10();
    let measured = row_peak(&f, off_deg) - row_peak(&f, 0);
    (expect, measured)
}

/// A magnetron set with an interferer 3 km east (0.3 µs at 1173.7 Hz) and `receiver` lines:
/// its frame.
fn interfered(receiver: &str) -> xbandsim::Frame {
    let text = format!(
        "{}[[artefacts.interferer]]\nname = \"ferry radar\"\nposition_m = [3000.0, 0.0, 10.0]\n\
         prf_hz = 1173.7\npulse_width_us = 0.3\nrotation_rpm = 22.0\n{receiver}",
        radar_block_no_noise(
            "transmitter = \"magnetron\"\npulse_width_us = 0.3\nprf_hz = 2000.0\nspokes = 360\n\
             max_range_m = 3000.0\nsample_rate_mhz = 20.0"
        )
    );
    render_text(&text, 1).1
}

/// The strongest interfering pulse's peak in the record against its label's level:
/// (label, measured), dB over the noise.
pub fn interference_level_db() -> (f64, f64) {
    let f = interfered("");
    let Some(a) = f
        .artefacts
        .iter()
        .find(|a| a.kind == ArtefactKind::Interference)
    else {
        return (0.0, f64::NAN);
    };
    let peak = a
        .polar_boxes
        .iter()
        .map(|b| {
            (b.bin_min..=b.bin_max)
                .map(|j| f.polar_db[b.spoke_min * f.range_bins + j])
                .fold(f32::MIN, f32::max)
        })
        .fold(f32::MIN, f32::max);
    (a.expected_level_db.unwrap_or(f64::NAN), f64::from(peak))
}

/// The share of an interferer's labelled pulses still in the video after interference
/// rejection `level`.
pub fn interference_left(level: &str) -> f64 {
    let f = interfered(&format!(
        "[receiver]\nvideo_spokes = 360\nvideo_samples = 400\ninterference_rejection = \"{level}\"\n"
    ));
    let Some(v) = f.video.as_ref() else {
        return f64::NAN;
    };
    let Some(a) = f
        .artefacts
        .iter()
        .find(|a| a.kind == ArtefactKind::Interference)
    else {
        return f64::NAN;
    };
    let sample = |j: usize| ((j as f64 * f.range_bin_m / v.sample_m) as usize).min(v.samples - 1);
    let lit = a
        .polar_boxes
        .iter()
        .filter(|b| {
            (sample(b.bin_min)..=sample(b.bin_max))
                .any(|j| v.levels[b.spoke_min * v.samples + j] > 0)
        })
        .count();
    lit as f64 / a.polar_boxes.len() as f64
}

/// A target 9 km north at 20 kHz (unambiguous range 7494.8 m) with second-trace echoes on:
/// (expected `R − c/(2·PRF)`, measured peak range, the bin), m.
pub fn second_trace_range_m() -> (f64, f64, f64) {
    let text = format!(
        "{}[artefacts]\nsecond_trace = true\n{}",
        radar_block_no_noise("prf_hz = 20000.0\nspokes = 90\nmax_range_m = 3000.0"),
        point_north("far", 9000.0, 1.0e4)
    );
    let (_, f) = render_text(&text, 1);
    let (peak, _) = argmax(spoke(&f, 0));
    let expect = 9000.0 - xbandsim::constants::SPEED_OF_LIGHT_M_PER_S / (2.0 * 20_000.0);
    (expect, peak as f64 * f.range_bin_m, f.range_bin_m)
}

/// The radar of the own-ship path scenes: 360 spokes, 1.5 km, noise off.
const OWN_SHIP_RADAR: &str = "spokes = 360\nmax_range_m = 1500.0";

/// The range bin of the own-ship path scenes' radar, m.
pub fn own_ship_paths_bin_m() -> f64 {
    xbandsim::model::Scene::from_toml_str(&radar_block_no_noise(OWN_SHIP_RADAR), "validation")
        .expect("validation scene is valid")
        .radar()
        .range_bin_m()
}

/// A 10⁴ m² target 250 bins due east (`east`, abeam and parallel: a point's bow points north)
/// or due north (ahead) of an own ship heading north, with multiple echoes on (6 dB per round
/// trip, up to order 3, any length).
pub fn multiple_echo_scene(east: bool) -> String {
    let r_m = 250.0 * own_ship_paths_bin_m();
    let (x, y) = if east { (r_m, 0.0) } else { (0.0, r_m) };
    format!(
        "{}[own_ship]\nheading_deg = 0.0\ncourse_deg = 0.0\n\
         [artefacts.multiple_echoes]\nround_trip_loss_db = 6.0\nmax_order = 3\nmin_length_m = 0.0\n\
         [[object]]\nname = \"tanker\"\nshape = \"point\"\nrcs_m2 = 1.0e4\nposition_m = [{x}, {y}, 4.0]\n",
        radar_block_no_noise(OWN_SHIP_RADAR)
    )
}

/// The order-`n` multiple echo of [`multiple_echo_scene`]: (`20·log10 n + (n−1)·6`, the
/// measured drop from the direct echo's peak at 250 bins to the peak near `250·n`), dB.
pub fn multiple_echo_drop_db(n: usize) -> (f64, f64) {
    let (_, f) = render_text(&multiple_echo_scene(true), 1);
    let row = spoke(&f, 90);
    let direct = f64::from(row[250]);
    let (_, peak) = argmax(&row[250 * n - 3..250 * n + 4]);
    let expected = 20.0 * (n as f64).log10() + (n - 1) as f64 * 6.0;
    (expected, direct - f64::from(peak))
}

/// A 100 m² target 100 bins dead ahead of an own ship heading north whose funnel, 10 bins aft
/// (sector 170°–190°, 20 dB), scatters `indirect_db = −10` dB of the beam each way.
pub fn indirect_echo_scene() -> String {
    let bin_m = own_ship_paths_bin_m();
    format!(
        "{}[own_ship]\nheading_deg = 0.0\ncourse_deg = 0.0\n\
         [[own_ship.structure]]\nname = \"funnel\"\nfrom_deg = 170.0\nto_deg = 190.0\n\
         loss_db = 20.0\nindirect_db = -10.0\ndistance_m = {}\n{}",
        radar_block_no_noise(OWN_SHIP_RADAR),
        10.0 * bin_m,
        point_north("buoy", 100.0 * bin_m, 100.0)
    )
}

/// The indirect echo of [`indirect_echo_scene`]: (2 × 10 dB, the measured drop from the
/// direct echo's peak at bin 100 on spoke 0 to the peak at bin 120, `R + 2d`, on spoke 180),
/// dB.
pub fn indirect_echo_drop_db() -> (f64, f64) {
    let (_, f) = render_text(&indirect_echo_scene(), 1);
    let direct = f64::from(spoke(&f, 0)[100]);
    let (_, peak) = argmax(&spoke(&f, 180)[117..124]);
    (20.0, direct - f64::from(peak))
}

pub(crate) fn checks(out: &mut Checks) {
    for n in [2usize, 3] {
        let (e, m) = multiple_echo_drop_db(n);
        out.push(check(
            &format!("artefacts: multiple echo of order {n} of a ship abeam, below the direct echo"),
            e,
            m,
            "dB",
            Tolerance::Absolute(0.1),
            "image method for two parallel mirror sides; JRC JMA-3300 manual §3.4.4; docs/physics.md §14",
        ));
    }
    let (e, m) = indirect_echo_drop_db();
    out.push(check(
        "artefacts: indirect echo via a funnel (indirect_db −10) below the direct echo",
        e,
        m,
        "dB",
        Tolerance::Absolute(0.1),
        "two passes via the structure; JRC JMA-3300 manual §3.4; docs/physics.md §14",
    ));
    let (e, m, bin) = second_trace_range_m();
    out.push(check(
        "artefacts: second-trace echo of a target at 9 km at R − c/(2·PRF) (PRF 20 kHz)",
        e,
        m,
        "m",
        Tolerance::Absolute(bin),
        "Skolnik, Introduction to Radar Systems, 3rd ed., ch. 1 (unambiguous range); docs/physics.md §14",
    ));
    for r in [300.0, 900.0, 1300.0] {
        let (e, m) = stc_attenuation_db(r);
        out.push(check(
            &format!("receiver: manual STC attenuation = its law (point target at {r} m)"),
            e,
            m,
            "dB",
            Tolerance::Absolute(0.1),
            BOLE,
        ));
    }
    let (e, m) = ftc_step_db();
    out.push(check(
        "receiver: FTC step response = 20·a¹¹ at sample 10 (τ = 0.5 µs, 50 ns samples)",
        e,
        m,
        "dB",
        Tolerance::Absolute(1e-4),
        BOLE,
    ));
    for g in [0.0, 3.0] {
        let (e, m) = noise_over_threshold(g);
        out.push(check(
            &format!(
                "receiver: noise over the video threshold at gain {g} dB = exp(−(10^(T/10) − 1))"
            ),
            e,
            m,
            "",
            Tolerance::Relative(0.06),
            BOLE,
        ));
    }
    for off in [5usize, 30, 180] {
        let (e, m) = sidelobe_echo_db(off);
        out.push(check(
            &format!("antenna: sidelobe echo {off}° off a 10⁵ m² target = two-way Taylor pattern"),
            e,
            m,
            "dB",
            Tolerance::Absolute(1.0),
            "Balanis, Antenna Theory, 4th ed., §7.6 (Taylor line source); docs/physics.md §3",
        ));
    }
    let (e, m) = interference_level_db();
    out.push(check(
        "artefacts: an interferer's pulse peaks at its label's level",
        e,
        m,
        "dB",
        Tolerance::Absolute(0.1),
        "Friis one-way power; docs/physics.md §14",
    ));
    let m = interference_left("high");
    out.push(check(
        "receiver: interference rejection (high) leaves an interferer's pulses",
        0.0,
        m,
        "",
        Tolerance::AtMost(0.05),
        BOLE,
    ));
}
