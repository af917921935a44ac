//! Motion checks: targets and the own ship moving between revolutions, measured from the
//! polar record of the real pipeline against closed-form kinematics (docs/validation.md).

use crate::harness::*;
use crate::{check, Checks, Tolerance};
use std::f64::consts::TAU;
use xbandsim::engine::Request;
use xbandsim::model::motion::KNOT_M_PER_S;
use xbandsim::model::Scene;
use xbandsim::{Frame, Simulation};

/// Offset of the vertex of the parabola through (−1, a), (0, b), (1, c) from the middle
/// sample, in samples (0 when the three are not a peak).
fn parabolic_offset(a: f64, b: f64, c: f64) -> f64 {
    let den = a - 2.0 * b + c;
    if den < 0.0 {
        (0.5 * (a - c) / den).clamp(-0.5, 0.5)
    } else {
        0.0
    }
}

/// Where a noise-free point target's echo peaks in a frame, searched within `search_m` of
/// `near_range_m` and 10° of `near_az_deg`: (slant range m, nautical azimuth °), each by
/// parabolic interpolation of the dB record through the strongest cell and its neighbours.
pub fn measured_position(
    frame: &Frame,
    near_az_deg: f64,
    near_range_m: f64,
    search_m: f64,
) -> (f64, f64) {
    let spokes = frame.spokes as i64;
    let spoke_deg = 360.0 / spokes as f64;
    let bin_lo = ((near_range_m - search_m) / frame.range_bin_m).max(1.0) as usize;
    let bin_hi =
        (((near_range_m + search_m) / frame.range_bin_m) as usize).min(frame.range_bins - 2);
    let centre = (near_az_deg / spoke_deg).round() as i64;
    let span = (10.0 / spoke_deg).ceil() as i64;
    let row = |k: i64| spoke(frame, k.rem_euclid(spokes) as usize);
    let (mut best_k, mut best_j, mut best) = (centre, bin_lo, f32::MIN);
    for k in centre - span..=centre + span {
        let (j, v) = argmax(&row(k)[bin_lo..=bin_hi]);
        if v > best {
            (best_k, best_j, best) = (k, bin_lo + j, v);
        }
    }
    let r = row(best_k);
    let dj = parabolic_offset(r[best_j - 1] as f64, r[best_j] as f64, r[best_j + 1] as f64);
    let dk = parabolic_offset(
        row(best_k - 1)[best_j] as f64,
        best as f64,
        row(best_k + 1)[best_j] as f64,
    );
    (
        (best_j as f64 + dj) * frame.range_bin_m,
        ((best_k as f64 + dk) * spoke_deg).rem_euclid(360.0),
    )
}

/// The noise-free frames `frames` of scene TOML.
fn frames_of(text: &str, frames: &[u64]) -> (Simulation, Vec<Frame>) {
    let scene = Scene::from_toml_str(text, "validation").expect("validation scene is valid");
    let sim = Simulation::new(scene);
    let out = frames
        .iter()
        .map(|&k| {
            sim.run(&Request::new(1).frame(k))
                .expect("the scene's own scan runs")
        })
        .collect();
    (sim, out)
}

/// A 10 m/s point target opening on bearing 45° from 600 m: (measured range advance over
/// four revolutions m, four revolutions' travel v·4T m).
pub fn radial_advance_m() -> (f64, f64) {
    let v = 10.0;
    let (s, c) = (45f64.to_radians().sin(), 45f64.to_radians().cos());
    let text = format!(
        "{}[[object]]\nname = \"p\"\nshape = \"point\"\nrcs_m2 = 10.0\nposition_m = [{}, {}, 4.0]\nvelocity_mps = [{}, {}, 0.0]\n",
        radar_block_no_noise("spokes = 360\nmax_range_m = 1200.0"),
        600.0 * s,
        600.0 * c,
        v * s,
        v * c
    );
    let (sim, f) = frames_of(&text, &[0, 4]);
    let period_s = sim.scene().radar().scan().period_s();
    let (r0, _) = measured_position(&f[0], 45.0, 600.0, 20.0);
    let (r4, _) = measured_position(&f[1], 45.0, 600.0 + 4.0 * v * period_s, 20.0);
    (r4 - r0, 4.0 * v * period_s)
}

/// A point target on a steady starboard turn (8 kn, 3°/s, starting north-bound at
/// [300, 500] m): in revolution 5 its echo is measured at (range, azimuth); the beam points
/// at that azimuth at t = 5T + az/Ω, and the closed-form circle puts the target at p(t) then.
/// Returns (|measured position − p(t)| m, bearing of p(t) − measured azimuth, °).
pub fn turning_position_error() -> (f64, f64) {
    let speed = 8.0 * KNOT_M_PER_S;
    let omega_turn = 3f64.to_radians();
    let (e0, n0) = (300.0, 500.0);
    let text = format!(
        "{}[[object]]\nname = \"p\"\nshape = \"point\"\nrcs_m2 = 10.0\nposition_m = [{e0}, {n0}, 4.0]\nspeed_kn = 8.0\ncourse_deg = 0.0\nturn_rate_deg_per_s = 3.0\n",
        radar_block_no_noise("spokes = 360\nmax_range_m = 1200.0")
    );
    let (sim, f) = frames_of(&text, &[5]);
    let period_s = sim.scene().radar().scan().period_s();
    let radius = speed / omega_turn;
    // Course c(t) = ω·t; centre of the circle to starboard of the start: (e0 + R, n0).
    let at = |t: f64| {
        let c = omega_turn * t;
        (e0 + radius - radius * c.cos(), n0 + radius * c.sin())
    };
    // Where the truth says it is (to find the echo).
    let truth = &f[0].truth[0];
    let (range_m, az_deg) = measured_position(&f[0], truth.azimuth_deg, truth.range_m, 20.0);
    let t = 5.0 * period_s + az_deg.to_radians() / (TAU / period_s);
    let (e, n) = at(t);
    let measured = (
        range_m * az_deg.to_radians().sin(),
        range_m * az_deg.to_radians().cos(),
    );
    let miss = (measured.0 - e).hypot(measured.1 - n);
    let bearing = e.atan2(n).to_degrees().rem_euclid(360.0);
    (miss, bearing - az_deg)
}

/// A still point target at 900 m on bearing 30° and the own ship closing on it at 10 kn:
/// (measured range decrease over four revolutions m, v·4T m).
pub fn own_ship_closing_m() -> (f64, f64) {
    let (s, c) = (30f64.to_radians().sin(), 30f64.to_radians().cos());
    let text = format!(
        "{}[own_ship]\nspeed_kn = 10.0\ncourse_deg = 30.0\n[[object]]\nname = \"p\"\nshape = \"point\"\nrcs_m2 = 10.0\nposition_m = [{}, {}, 4.0]\n",
        radar_block_no_noise("spokes = 360\nmax_range_m = 1200.0"),
        900.0 * s,
        900.0 * c
    );
    let (sim, f) = frames_of(&text, &[0, 4]);
    let period_s = sim.scene().radar().scan().period_s();
    let travel = 4.0 * 10.0 * KNOT_M_PER_S * period_s;
    let (r0, _) = measured_position(&f[0], 30.0, 900.0, 20.0);
    let (r4, _) = measured_position(&f[1], 30.0, 900.0 - travel, 20.0);
    (r0 - r4, travel)
}

/// The checks of this area, in the order `xbandsim validate` prints them.
pub(crate) fn checks(out: &mut Checks) {
    const KINEMATICS: &str =
        "constant-velocity and constant-rate-turn kinematics (docs/physics.md, \"Motion\")";
    let (measured, expected) = radial_advance_m();
    out.push(check(
        "target opening at 10 m/s: range advance over 4 revolutions = v·4T",
        expected,
        measured,
        "m",
        Tolerance::Absolute(0.1),
        KINEMATICS,
    ));
    let (miss_m, bearing_deg) = turning_position_error();
    out.push(check(
        "target on a 3°/s turn: measured position vs the closed-form circle",
        0.0,
        miss_m,
        "m",
        Tolerance::AtMost(0.2),
        KINEMATICS,
    ));
    out.push(check(
        "target on a 3°/s turn: the beam's azimuth at the crossing time = the target's bearing",
        0.0,
        bearing_deg,
        "°",
        Tolerance::Absolute(0.01),
        KINEMATICS,
    ));
    let (measured, expected) = own_ship_closing_m();
    out.push(check(
        "own ship closing at 10 kn: range decrease over 4 revolutions = v·4T",
        expected,
        measured,
        "m",
        Tolerance::Absolute(0.1),
        KINEMATICS,
    ));
    const ROLL: &str = "deck attitude R = Rz(−heading)·Rx(pitch)·Ry(roll) (docs/formats.md, object frames): beam elevation asin(sin p·cos α − cos p·sin r·sin α), mast top at R·(0, 0, h); two-way elevation pattern Gn² (docs/physics.md §3)";
    let roll = own_ship_roll();
    out.push(check(
        "own ship rolling 15° (13.86° when the beam crosses a target abeam): peak over a level antenna at the same place = two-way elevation pattern 20·log10(Gn(el − δ)/Gn(el))",
        roll.expected_db,
        roll.measured_db,
        "dB",
        Tolerance::Absolute(0.02),
        ROLL,
    ));
    out.push(check(
        "own ship rolling: the target's range from the antenna swung out on its 4 m mast, h·sin(roll) = 0.958 m nearer",
        roll.expected_range_m,
        roll.measured_range_m,
        "m",
        Tolerance::Absolute(0.1),
        ROLL,
    ));
}

/// The own-ship roll check's figures.
pub struct RollCheck {
    /// Peak of the target abeam, rolling deck minus level deck at the same antenna place, dB.
    pub measured_db: f64,
    /// `20·log10(Gn(el − δ)/Gn(el))`, δ = −roll(t_b) toward starboard.
    pub expected_db: f64,
    /// Measured slant range of the peak, m.
    pub measured_range_m: f64,
    /// `|target − (h·sin r, 0, h·cos r)|`, m.
    pub expected_range_m: f64,
}

/// An own ship heading north, rolling 15° with a 10 s period and phase 90°
/// (roll = 15°·cos(2πt/10)), antenna on a 4 m mast, sees a 10 m² point 400 m due east
/// (starboard) at t_b = 0.625 s, when roll = 15°·cos(π/8): the beam toward starboard dips by
/// the roll and the mast top swings h·sin r toward the target. Compared with a level radar
/// placed where the mast top is then (same range, same sampling), the peak differs by the
/// two-way elevation pattern alone.
pub fn own_ship_roll() -> RollCheck {
    let h = 4.0;
    let amplitude = 15f64.to_radians();
    let t_b = 90.0 / 360.0 * 60.0 / 24.0;
    let r = amplitude * (TAU * t_b / 10.0 + std::f64::consts::FRAC_PI_2).sin();
    let antenna = [h * r.sin(), 0.0, h * r.cos()];
    let target = "[[object]]\nname = \"p\"\nshape = \"point\"\nrcs_m2 = 10.0\nposition_m = [400.0, 0.0, 4.0]\n";
    let head = |position: [f64; 3]| {
        format!("[environment]\nmultipath = false\nclutter = false\nnoise = false\n[radar]\nposition_m = [{}, {}, {}]\nspokes = 360\nmax_range_m = 600.0\n", position[0], position[1], position[2])
    };
    let rolling = format!("{}[own_ship]\nheading_deg = 0.0\nroll_amplitude_deg = 15.0\nmotion_period_s = 10.0\nmotion_phase_deg = 90.0\n{target}", head([0.0, 0.0, h]));
    let level = format!("{}{target}", head(antenna));
    let (_, rolled) = render_text(&rolling, 1);
    let (sim, flat) = render_text(&level, 1);
    let peak = |f: &Frame| {
        let row = spoke(f, 90);
        let (j, v) = argmax(&row[200..340]);
        (j + 200, v as f64)
    };
    let (j_roll, p_roll) = peak(&rolled);
    let (j_flat, p_flat) = peak(&flat);
    assert_eq!(j_roll, j_flat, "same range, same peak bin");
    let dx = 400.0 - antenna[0];
    let dz = 4.0 - antenna[2];
    let el = dz.atan2(dx);
    let bw = sim.scene().radar().antenna().el_beamwidth_rad;
    // Starboard (α = 90°) with pitch 0: δ = −sin(r) → asin(−sin r) = −r.
    let delta = (-r.sin()).asin();
    let gn = |x: f64| xbandsim::antenna::sinc2_pattern(x, bw);
    let (measured_range_m, _) = measured_position(&rolled, 90.0, 399.0, 10.0);
    RollCheck {
        measured_db: p_roll - p_flat,
        expected_db: 20.0 * (gn(el - delta) / gn(el)).log10(),
        measured_range_m,
        expected_range_m: dx.hypot(dz),
    }
}
