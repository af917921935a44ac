//! Motion: kinematics against closed forms, the motion labels, moving frames through the
//! engine, and bad motion inputs (docs/physics.md, "Motion"; docs/formats.md, "Motion").

use crate::common::{radar_block_no_noise, scene};
use glam::DVec3;
use std::f64::consts::TAU;
use std::sync::Arc;
use xbandsim::engine::Request;
use xbandsim::model::motion::KNOT_M_PER_S;
use xbandsim::model::revolution::beam_crossing_time_s;
use xbandsim::products::labels::{RadialMotion, RADIAL_CLASS_THRESHOLD_MPS};
use xbandsim::Simulation;

const HEAD: &str = "[radar]\nspokes = 90\nmax_range_m = 1500.0\n[environment]\nclutter = false\nmultipath = false\nnoise = false\n";

fn object(extra: &str) -> String {
    format!("{HEAD}[[object]]\nname = \"a\"\nshape = \"sphere\"\nradius_m = 1.0\n{extra}\n")
}

/// Steady course: p(t) = p0 + v·t with v from speed (knots) and nautical course.
#[test]
fn steady_course_moves_in_a_straight_line() {
    let s = scene(&object(
        "position_m = [100.0, 200.0, 2.0]\nspeed_kn = 20.0\ncourse_deg = 135.0",
    ));
    let o = &s.objects()[0];
    let v = 20.0 * 1852.0 / 3600.0;
    let dir = DVec3::new(135f64.to_radians().sin(), 135f64.to_radians().cos(), 0.0);
    for t in [0.0, 1.5, 7.25, 100.0] {
        let k = o.kinematics(t);
        let expected = DVec3::new(100.0, 200.0, 2.0) + dir * v * t;
        assert!((k.position_m - expected).length() < 1e-9, "t = {t}");
        assert!((k.velocity_mps - dir * v).length() < 1e-12);
        assert!(
            (k.heading_rad.to_degrees() - 135.0).abs() < 1e-9,
            "heading follows course"
        );
        assert!((k.course_rad().unwrap().to_degrees() - 135.0).abs() < 1e-9);
    }
}

/// Constant-rate turn: the position stays on the circle of radius s/ω centred to starboard,
/// the course advances by ω·t, and the velocity is the position's time derivative (central
/// differences).
#[test]
fn constant_rate_turn_follows_the_circle() {
    let s = scene(&object(
        "position_m = [0.0, 500.0, 2.0]\nspeed_kn = 10.0\ncourse_deg = 90.0\nturn_rate_deg_per_s = 2.0",
    ));
    let o = &s.objects()[0];
    let speed = 10.0 * KNOT_M_PER_S;
    let w = 2f64.to_radians();
    let radius = speed / w;
    // Heading east, turning to starboard: the centre is south of the start.
    let centre = DVec3::new(0.0, 500.0 - radius, 2.0);
    for t in [0.0, 3.0, 45.0, 90.0, 180.0, 400.0] {
        let k = o.kinematics(t);
        assert!(
            ((k.position_m - centre).length() - radius).abs() < 1e-9,
            "t = {t}"
        );
        let course = (90.0 + 2.0 * t).rem_euclid(360.0);
        let heading = k.heading_rad.to_degrees();
        let d = (heading - course + 180.0).rem_euclid(360.0) - 180.0;
        assert!(
            d.abs() < 1e-9,
            "t = {t}: heading {heading}, course {course}"
        );
        let h = 1e-4;
        let numeric = (o.kinematics(t + h).position_m - o.kinematics(t - h).position_m) / (2.0 * h);
        assert!((numeric - k.velocity_mps).length() < 1e-6, "t = {t}");
        assert!((k.speed_mps() - speed).abs() < 1e-12);
    }
    // After half a circle (90 s at 2°/s) it is diametrically opposite the start.
    let half = o.kinematics(90.0).position_m;
    assert!((half - (2.0 * centre - DVec3::new(0.0, 500.0, 2.0))).length() < 1e-9);
}

/// Track: linear between waypoints, at rest before the first and after the last, heading
/// along the leg (a pause keeps the previous leg's course).
#[test]
fn track_interpolates_its_waypoints() {
    let s = scene(&object(
        "track = [[0.0, 0.0, 300.0], [10.0, 100.0, 300.0], [20.0, 100.0, 300.0], [30.0, 100.0, 200.0]]\nposition_m = [0.0, 300.0, 3.0]",
    ));
    let o = &s.objects()[0];
    let k = o.kinematics(4.0);
    assert!((k.position_m - DVec3::new(40.0, 300.0, 3.0)).length() < 1e-12);
    assert!((k.velocity_mps - DVec3::new(10.0, 0.0, 0.0)).length() < 1e-12);
    assert!((k.heading_rad.to_degrees() - 90.0).abs() < 1e-9);
    // The pause: no velocity, no course, heading kept from the leg before.
    let k = o.kinematics(15.0);
    assert_eq!(k.velocity_mps, DVec3::ZERO);
    assert!(k.course_rad().is_none());
    assert!((k.heading_rad.to_degrees() - 90.0).abs() < 1e-9);
    let k = o.kinematics(25.0);
    assert!((k.position_m - DVec3::new(100.0, 250.0, 3.0)).length() < 1e-12);
    assert!((k.heading_rad.to_degrees() - 180.0).abs() < 1e-9);
    // Before the first and after the last waypoint it rests there.
    assert_eq!(o.kinematics(-5.0).position_m, DVec3::new(0.0, 300.0, 3.0));
    assert_eq!(o.kinematics(99.0).position_m, DVec3::new(100.0, 200.0, 3.0));
    assert_eq!(o.kinematics(99.0).velocity_mps, DVec3::ZERO);
    // Without position_m the track starts at height 0.
    let t = scene(&format!("{HEAD}[[object]]\nname = \"b\"\nshape = \"point\"\nrcs_m2 = 1.0\ntrack = [[0.0, 10.0, 300.0], [5.0, 10.0, 350.0]]\n"));
    assert_eq!(t.objects()[0].position_m(), DVec3::new(10.0, 300.0, 0.0));
}

/// Wave-induced motion: heave z0 + A·sin(2πt/T + φ) with its derivative as the vertical
/// velocity; the mast (the object's +z) leans from the vertical by θ with
/// cos θ = cos(roll)·cos(pitch), roll = A_r·sin(2πt/T + φ), pitch = A_p·cos(2πt/T + φ).
#[test]
fn wave_motion_heaves_rolls_and_pitches() {
    let s = scene(&object(
        "position_m = [0.0, 400.0, 2.0]\nheave_amplitude_m = 0.5\nroll_amplitude_deg = 10.0\npitch_amplitude_deg = 4.0\nmotion_period_s = 6.0\nmotion_phase_deg = 30.0",
    ));
    let o = &s.objects()[0];
    for t in [0.0, 0.7, 2.0, 4.4] {
        let phase = TAU * t / 6.0 + 30f64.to_radians();
        let k = o.kinematics(t);
        assert!((k.position_m.z - (2.0 + 0.5 * phase.sin())).abs() < 1e-12);
        assert!((k.velocity_mps.z - 0.5 * TAU / 6.0 * phase.cos()).abs() < 1e-12);
        assert_eq!(k.position_m.truncate(), glam::DVec2::new(0.0, 400.0));
        let roll = 10f64.to_radians() * phase.sin();
        let pitch = 4f64.to_radians() * phase.cos();
        let up = k.rotation * DVec3::Z;
        assert!((up.z - roll.cos() * pitch.cos()).abs() < 1e-12, "t = {t}");
        // Only wave motion: the heading stays at yaw_deg (default 0) and nothing drifts.
        assert!(k.heading_rad.abs() < 1e-12 || (k.heading_rad - TAU).abs() < 1e-12);
    }
}

/// The beam crosses a still object at start + β/Ω exactly, and a moving one when the
/// antenna's azimuth equals its bearing at that time.
#[test]
fn beam_crossing_time_solves_the_scan_equation() {
    let period = 2.5;
    let still = DVec3::new(300.0, -300.0, 0.0); // bearing 135°
    let t = beam_crossing_time_s(10.0, period, |_| still);
    assert_eq!(t, 10.0 + 0.375 * period);
    // A fast target crossing the beam's path tangentially.
    let moving = |t: f64| DVec3::new(200.0 + 30.0 * t, 100.0 - 10.0 * t, 0.0);
    let t = beam_crossing_time_s(0.0, period, moving);
    let p = moving(t);
    let bearing = p.x.atan2(p.y).rem_euclid(TAU);
    assert!((bearing - TAU * t / period).abs() < 1e-9, "t = {t}");
    assert!((0.0..period).contains(&t));
}

/// The labels of a moving frame: velocity, speed, course, heading, range rate against the
/// own ship, Doppler −2·ṙ/λ and the approaching/receding class at 3 kn.
#[test]
fn truth_carries_the_motion() {
    let text = format!(
        "{}[own_ship]\nspeed_kn = 10.0\ncourse_deg = 0.0\nheading_deg = 5.0\n[[object]]\nname = \"p\"\nshape = \"point\"\nrcs_m2 = 10.0\nposition_m = [0.0, 800.0, 4.0]\nvelocity_mps = [3.0, -4.0, 0.0]\nyaw_deg = 200.0\n",
        radar_block_no_noise("spokes = 90\nmax_range_m = 1500.0")
    );
    let sim = Simulation::new(scene(&text));
    let frame = sim.run(&Request::new(1).frame(2)).unwrap();
    let lambda = sim.scene().radar().wavelength_m();
    let own = frame.own_ship.expect("own ship state");
    assert!((own.antenna_position_m.y - 10.0 * KNOT_M_PER_S * 5.0).abs() < 1e-9);
    let o = &frame.truth[0];
    assert_eq!(o.track_id, 0);
    let t = o.beam_time_s;
    assert!((5.0..7.5).contains(&t), "beam time {t} in revolution 2");
    let p = DVec3::new(3.0 * t, 800.0 - 4.0 * t, 4.0);
    assert!((DVec3::from_array(o.position_m) - p).length() < 1e-9);
    assert_eq!(o.velocity_mps, [3.0, -4.0, 0.0]);
    assert!((o.speed_kn - 5.0 / KNOT_M_PER_S).abs() < 1e-9);
    assert!((o.course_deg.unwrap() - 3f64.atan2(-4.0).to_degrees().rem_euclid(360.0)).abs() < 1e-9);
    assert!(
        (o.heading_deg.unwrap() - 200.0).abs() < 1e-9,
        "yaw_deg fixes the heading"
    );
    // Range rate: relative velocity along the line of sight from the antenna at time t.
    let antenna = DVec3::new(0.0, 10.0 * KNOT_M_PER_S * t, 4.0);
    let los = (p - antenna).normalize();
    let rel_v = DVec3::new(3.0, -4.0 - 10.0 * KNOT_M_PER_S, 0.0);
    assert!((o.radial_velocity_mps - rel_v.dot(los)).abs() < 1e-9);
    assert!((o.range_m - (p - antenna).length()).abs() < 1e-9);
    assert!((o.doppler_hz + 2.0 * o.radial_velocity_mps / lambda).abs() < 1e-9);
    assert_eq!(o.radial_motion, RadialMotion::Approaching);
    // The class threshold: 3 kn either way.
    assert!((RADIAL_CLASS_THRESHOLD_MPS - 3.0 * 1852.0 / 3600.0).abs() < 1e-15);
    assert_eq!(RadialMotion::of(-1.6), RadialMotion::Approaching);
    assert_eq!(RadialMotion::of(1.6), RadialMotion::Receding);
    assert_eq!(RadialMotion::of(1.5), RadialMotion::Stationary);
    assert_eq!(RadialMotion::of(-1.5), RadialMotion::Stationary);
}

/// A still scene's truth has zero velocity, no course, the heading of yaw_deg, and a beam
/// time of frame start + bearing/Ω.
#[test]
fn still_objects_are_labelled_still() {
    let s = scene(&object("position_m = [300.0, 0.0, 2.0]\nyaw_deg = 75.0"));
    assert!(s.is_still());
    let sim = Simulation::new(s);
    // Frame 0 first: frame 3 reuses its trace but has its own beam times.
    assert!((sim.run(&Request::new(0)).unwrap().truth[0].beam_time_s - 0.25 * 2.5).abs() < 1e-12);
    let frame = sim.run(&Request::new(0).frame(3)).unwrap();
    let o = &frame.truth[0];
    assert_eq!(o.velocity_mps, [0.0; 3]);
    assert_eq!(o.speed_kn, 0.0);
    assert_eq!(o.course_deg, None);
    assert!((o.heading_deg.unwrap() - 75.0).abs() < 1e-9);
    assert_eq!(o.radial_velocity_mps, 0.0);
    assert_eq!(o.radial_motion, RadialMotion::Stationary);
    assert_eq!(frame.start_time_s, 7.5);
    assert!((o.beam_time_s - (7.5 + 0.25 * 2.5)).abs() < 1e-12);
}

/// A moving scene is traced once per revolution (cached by start time); rendering frames in
/// any order gives the same bytes as a fresh simulation, and two runs give the same bytes.
#[test]
fn moving_frames_are_traced_per_revolution_and_deterministic() {
    let text = format!(
        "{}[[object]]\nname = \"p\"\nshape = \"trihedral\"\nedge_m = 0.5\nposition_m = [200.0, 600.0, 2.0]\nspeed_kn = 15.0\ncourse_deg = 250.0\n",
        HEAD.replace("noise = false\n", "")
    );
    let sim = Simulation::new(scene(&text));
    assert!(!sim.scene().is_still());
    let a = sim.traced(0.0);
    let b = sim.traced(2.5);
    assert!(!Arc::ptr_eq(&a, &b));
    assert!(Arc::ptr_eq(&a, &sim.traced(0.0)));
    let f2 = sim.run(&Request::new(7).frame(2)).unwrap();
    let f0 = sim.run(&Request::new(7)).unwrap();
    let fresh = Simulation::new(scene(&text));
    assert_eq!(fresh.run(&Request::new(7)).unwrap().polar_db, f0.polar_db);
    let again = fresh.run(&Request::new(7).frame(2)).unwrap();
    assert_eq!(again.polar_db, f2.polar_db);
    assert_eq!(again.truth, f2.truth);
    assert_ne!(f0.truth[0].position_m, f2.truth[0].position_m);
}

fn error_of(text: &str) -> String {
    match xbandsim::model::Scene::from_toml_str(text, "scene.toml") {
        Ok(_) => panic!("accepted:\n{text}"),
        Err(e) => e.to_string(),
    }
}

/// Bad motion inputs are clear errors naming the field.
#[test]
fn bad_motion_is_refused_by_field() {
    let at = "position_m = [0.0, 300.0, 2.0]\n";
    let cases: &[(&str, &[&str])] = &[
        ("track = [[0.0, 1.0, 300.0]]", &["object \"a\".track", "at least two waypoints"]),
        (
            "track = [[0.0, 0.0, 300.0], [10.0, 5.0, 300.0], [5.0, 9.0, 300.0]]",
            &["object \"a\".track[2]", "increasing time", "t = 5 s"],
        ),
        ("track = [[0.0, 0.0, 300.0], [0.0, 5.0, 300.0]]", &["track[1]", "increasing time"]),
        ("track = [[0.0, nan, 300.0], [1.0, 5.0, 300.0]]", &["track[0]", "finite"]),
        (&format!("{at}speed_kn = nan\ncourse_deg = 10.0"), &["object \"a\".speed_kn", "finite"]),
        (&format!("{at}speed_kn = -3.0\ncourse_deg = 10.0"), &["speed_kn", "0 or more"]),
        (&format!("{at}speed_kn = 3.0"), &["course_deg", "speed_kn needs course_deg"]),
        (&format!("{at}course_deg = 3.0"), &["speed_kn"]),
        (&format!("{at}speed_kn = 3.0\ncourse_deg = 1.0\nvelocity_mps = [1.0, 0.0, 0.0]"), &["speed_kn", "velocity_mps", "not both"]),
        (&format!("{at}velocity_mps = [1.0, inf, 0.0]"), &["velocity_mps", "finite"]),
        (&format!("{at}turn_rate_deg_per_s = 2.0"), &["speed_kn", "turn_rate_deg_per_s needs a speed"]),
        (&format!("{at}speed_kn = 0.0\ncourse_deg = 0.0\nturn_rate_deg_per_s = 2.0"), &["turn_rate_deg_per_s", "horizontal speed"]),
        (&format!("{at}speed_kn = 1.0\ncourse_deg = 0.0\ntrack = [[0.0, 0.0, 300.0], [1.0, 0.0, 301.0]]"), &["speed_kn", "track", "not both"]),
        ("position_m = [50.0, 300.0, 2.0]\ntrack = [[0.0, 0.0, 300.0], [1.0, 0.0, 301.0]]", &["position_m", "track puts the object"]),
        (&format!("{at}heave_amplitude_m = 1.0"), &["motion_period_s", "needs motion_period_s"]),
        (&format!("{at}roll_amplitude_deg = 5.0\nmotion_period_s = 0.0"), &["motion_period_s", "above zero"]),
        (&format!("{at}roll_amplitude_deg = 95.0\nmotion_period_s = 6.0"), &["roll_amplitude_deg", "from 0 to 60"]),
        (&format!("{at}heave_amplitude_m = -1.0\nmotion_period_s = 6.0"), &["heave_amplitude_m"]),
        (&format!("{at}motion_period_s = 6.0"), &["motion_period_s", "needs a wave-induced motion"]),
    ];
    for (extra, needles) in cases {
        let msg = error_of(&object(extra));
        for n in *needles {
            assert!(
                msg.contains(n),
                "{extra}: error {msg:?} does not mention {n:?}"
            );
        }
    }
    for (own, needle) in [
        ("speed_kn = -1.0", "own_ship.speed_kn"),
        ("speed_kn = nan", "own_ship.speed_kn"),
        ("course_deg = inf", "own_ship.course_deg"),
        ("heading_deg = nan", "own_ship.heading_deg"),
        ("speed = 3.0", "speed"),
    ] {
        let msg = error_of(&format!("{HEAD}[own_ship]\n{own}\n"));
        assert!(msg.contains(needle), "{own}: {msg}");
    }
}

/// Head-up: the own ship's heading points up; a target dead ahead shows straight above the
/// centre, in the picture and in its pixel box. Course-up follows the course. Head-up without
/// an own ship is refused.
#[test]
fn head_up_and_course_up_turn_the_picture() {
    use xbandsim::products::ppi::Orientation;
    use xbandsim::scene::LoadedSpec;
    let text = format!(
        "{}[own_ship]\nspeed_kn = 4.0\ncourse_deg = 45.0\nheading_deg = 90.0\n[display]\norientation = \"head-up\"\nimage_size_px = 256\n[[object]]\nname = \"p\"\nshape = \"point\"\nrcs_m2 = 100.0\nposition_m = [600.0, 0.0, 4.0]\n",
        radar_block_no_noise("spokes = 360\nmax_range_m = 1000.0")
    );
    let spec = LoadedSpec::from_toml(&text, "t", std::path::Path::new(".")).unwrap();
    let settings = spec.ppi_settings().unwrap();
    assert_eq!(settings.orientation, Orientation::HeadUp);
    let sim = Simulation::new(spec.build().unwrap());
    let frame = sim.run(&Request::new(0)).unwrap();
    let up = settings.up_azimuth_rad(frame.own_ship.as_ref());
    assert!((up.to_degrees() - 90.0).abs() < 1e-9);
    let conv = settings.oriented_scan_converter(sim.scene().radar(), up);
    let mut image = vec![0f32; 256 * 256];
    conv.convert(&frame.polar_db, f32::NAN, &mut image);
    let (best, _) = image
        .iter()
        .enumerate()
        .filter(|(_, v)| v.is_finite())
        .fold((0, f32::MIN), |b, (i, &v)| if v > b.1 { (i, v) } else { b });
    let (col, row) = (best % 256, best / 256);
    // Dead ahead (true bearing ≈ 90° from the antenna), straight up from the centre.
    let t = &frame.truth[0];
    let px_m = 2000.0 / 256.0;
    assert!((col as f64 + 0.5 - 128.0).abs() <= 2.0, "col {col}");
    assert!(
        ((128.0 - row as f64 - 0.5) - t.ground_range_m / px_m).abs() <= 2.0,
        "row {row}"
    );
    let mut truth = frame.truth.clone();
    conv.geometry().label(&mut truth);
    let b = truth[0].ppi_box_px.unwrap();
    assert!(b[0] <= col as f64 && col as f64 <= b[2] && b[1] <= row as f64 && row as f64 <= b[3]);
    // Course-up: the course (45°) is up.
    let course = text.replace("head-up", "course-up");
    let spec = LoadedSpec::from_toml(&course, "t", std::path::Path::new(".")).unwrap();
    let up = spec
        .ppi_settings()
        .unwrap()
        .up_azimuth_rad(frame.own_ship.as_ref());
    assert!((up.to_degrees() - 45.0).abs() < 1e-9);
    // Head-up needs an own ship.
    let lone = text.replace(
        "[own_ship]\nspeed_kn = 4.0\ncourse_deg = 45.0\nheading_deg = 90.0\n",
        "",
    );
    let err = LoadedSpec::from_toml(&lone, "t", std::path::Path::new("."))
        .unwrap()
        .build()
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("display.orientation") && err.contains("own_ship"),
        "{err}"
    );
}

/// The own ship's beam tilt is the closed form `asin(sin p·cos α − cos p·sin r·sin α)` for
/// the deck attitude `Rz(−heading)·Rx(pitch)·Ry(roll)`, and the mast top swings to
/// `R·(0, 0, h)`; roll and pitch follow `A_r·sin(ωt + φ)`, `A_p·cos(ωt + φ)`.
#[test]
fn own_ship_roll_and_pitch_tilt_the_beam() {
    let ship = xbandsim::model::OwnShip::new(0.0, 30.0, 30.0)
        .unwrap()
        .rolling(12.0, 5.0, 8.0, 40.0, 6.0)
        .unwrap();
    for t in [0.0, 0.7, 3.1, 5.9] {
        let phase = std::f64::consts::TAU * t / 8.0 + 40f64.to_radians();
        let r = 12f64.to_radians() * phase.sin();
        let p = 5f64.to_radians() * phase.cos();
        let (roll, pitch) = ship.roll_pitch_rad(t);
        assert!((roll - r).abs() < 1e-12 && (pitch - p).abs() < 1e-12);
        for az_deg in [0.0, 30.0, 75.0, 120.0, 210.0, 300.0] {
            let a = (az_deg - 30.0f64).to_radians();
            let expected = (p.sin() * a.cos() - p.cos() * r.sin() * a.sin()).asin();
            let tilt = ship.beam_tilt_rad(t, az_deg.to_radians());
            assert!(
                (tilt - expected).abs() < 1e-12,
                "{t} {az_deg}: {tilt} {expected}"
            );
        }
        // Mast top: 6 m up the deck's normal.
        let top = ship.antenna_offset_m(t) + glam::DVec3::new(0.0, 0.0, 6.0);
        let normal = ship.rotation(t) * glam::DVec3::Z;
        assert!((top - normal * 6.0).length() < 1e-12);
        // Its velocity is the derivative of its place.
        let h = 1e-4;
        let numeric = (ship.antenna_offset_m(t + h) - ship.antenna_offset_m(t - h)) / (2.0 * h);
        assert!((numeric - ship.antenna_velocity_mps(t)).length() < 1e-6);
    }
    // A level ship does not tilt the beam or swing the antenna.
    let level = xbandsim::model::OwnShip::new(5.0, 0.0, 0.0).unwrap();
    assert_eq!(level.beam_tilt_rad(1.0, 1.0), 0.0);
    assert_eq!(level.antenna_offset_m(2.0), level.displacement_m(2.0));
}

/// A rolling own ship: the truth header carries roll and pitch, each object's elevation loss
/// is that of the tilted beam; bad roll settings are located errors.
#[test]
fn rolling_own_ship_labels_and_errors() {
    let text = "[radar]\nspokes = 36\nmax_range_m = 600.0\n[environment]\nnoise = false\nclutter = false\nmultipath = false\n[own_ship]\nroll_amplitude_deg = 20.0\nmotion_period_s = 9.0\nmotion_phase_deg = 90.0\n[[object]]\nname = \"p\"\nshape = \"point\"\nrcs_m2 = 10.0\nposition_m = [300.0, 0.0, 4.0]\n";
    let sim = Simulation::new(crate::common::scene(text));
    let frame = sim.render(1);
    let ship = frame.own_ship.unwrap();
    assert!((ship.roll_rad - 20f64.to_radians()).abs() < 1e-12);
    let level = Simulation::new(crate::common::scene(&text.replace(
        "roll_amplitude_deg = 20.0\nmotion_period_s = 9.0\nmotion_phase_deg = 90.0\n",
        "",
    )))
    .render(1);
    assert!(
        frame.truth[0].losses_db.elevation_pattern
            > level.truth[0].losses_db.elevation_pattern + 3.0,
        "{:?} vs {:?}",
        frame.truth[0].losses_db,
        level.truth[0].losses_db
    );
    for (extra, field) in [
        ("roll_amplitude_deg = 5.0\n", "own_ship.motion_period_s"),
        ("motion_period_s = 8.0\n", "own_ship.motion_period_s"),
        (
            "roll_amplitude_deg = 70.0\nmotion_period_s = 8.0\n",
            "own_ship.roll_amplitude_deg",
        ),
        (
            "pitch_amplitude_deg = 5.0\nmotion_period_s = 0.0\n",
            "own_ship.motion_period_s",
        ),
        (
            "pitch_amplitude_deg = nan\nmotion_period_s = 8.0\n",
            "own_ship.pitch_amplitude_deg",
        ),
    ] {
        let err = error_of(&format!("[own_ship]\nspeed_kn = 3.0\n{extra}"));
        assert!(err.contains(field), "{extra}: {err}");
    }
}

/// Sea and rain clutter with every spoke's beam raised by δ (the rolling deck's path) equal
/// the clutter of a radar tilted by δ (the level path): the sea to float32 rounding; rain to
/// the quadratures' error (both elevation integrals are midpoint sums: the level one has 48
/// steps over up to 65°, good to about 1e-3; the shift's edges 8 steps each). Raising the
/// beam the wrong way misses by tens of per cent.
#[test]
fn tilted_clutter_matches_a_tilted_radar() {
    let text = |tilt: f64, sea: bool, rain: bool| {
        format!("[radar]\nspokes = 36\nmax_range_m = 1500.0\ntilt_deg = {tilt}\n[environment]\nsea_state = 4\nclutter = {sea}\nrain = {rain}\nrain_rate_mm_per_h = 8.0\nclutter_distribution = \"rayleigh\"\n")
    };
    let delta_deg = -7.0;
    let samples = 1000;
    let worst = |sea: bool, rain: bool, sign: f64| {
        let level = crate::common::scene(&text(0.0, sea, rain));
        let tilted = crate::common::scene(&text(delta_deg, sea, rain));
        let tilts = vec![sign * delta_deg.to_radians(); 36];
        let via_spokes = xbandsim::signal::clutter_map::ClutterMap::with_beam_tilts(
            level.radar(),
            level.environment(),
            xbandsim::rng::FrameKey::new(1, 0),
            samples,
            &tilts,
        )
        .unwrap();
        let via_radar = xbandsim::signal::clutter_map::ClutterMap::new(
            tilted.radar(),
            tilted.environment(),
            xbandsim::rng::FrameKey::new(1, 0),
            samples,
        )
        .unwrap();
        let mut worst = 0f64;
        for k in [0, 9, 20] {
            for n in (5..samples).step_by(7) {
                let a = via_spokes.mean_power(k, n) as f64;
                let b = via_radar.mean_power(k, n) as f64;
                if b > 0.0 {
                    worst = worst.max((a / b - 1.0).abs());
                }
            }
        }
        worst
    };
    let sea = worst(true, false, 1.0);
    assert!(sea < 1e-5, "sea {sea}");
    let rain = worst(false, true, 1.0);
    assert!(rain < 5e-3, "rain {rain}");
    let wrong_way = worst(false, true, -1.0);
    assert!(wrong_way > 0.1, "wrong way {wrong_way}");
}

/// True motion: the picture is fixed to the ground. Over three revolutions of an own ship
/// under way, a buoy's pixel box (and its brightest pixel) stays put while the antenna's pixel
/// moves by speed·T_rot per frame, starting at the centre; in relative motion the buoy's box
/// moves instead. truth.json tells where the radar is (`ppi_radar_px`). A bad `motion` value
/// is an error naming the field.
#[test]
fn true_motion_keeps_the_ground_still() {
    use xbandsim::products::frame_files::write_frame_files;
    use xbandsim::products::ppi::{Motion, PpiSettings};
    use xbandsim::scene::LoadedSpec;
    let text = format!(
        "{}[own_ship]\nspeed_kn = 20.0\ncourse_deg = 60.0\n[display]\nmotion = \"true\"\nimage_size_px = 256\n[[object]]\nname = \"buoy\"\nshape = \"point\"\nrcs_m2 = 100.0\nposition_m = [-300.0, 520.0, 4.0]\n",
        radar_block_no_noise("spokes = 360\nmax_range_m = 1000.0")
    );
    let spec = LoadedSpec::from_toml(&text, "t", std::path::Path::new(".")).unwrap();
    let settings = spec.ppi_settings().unwrap();
    assert_eq!(settings.motion, Motion::True);
    let relative = PpiSettings {
        motion: Motion::Relative,
        ..settings.clone()
    };
    let sim = Simulation::new(spec.build().unwrap());
    let radar = sim.scene().radar();
    let px_m = 2000.0 / 256.0;
    let step_px = 20.0 * KNOT_M_PER_S * radar.scan().period_s() / px_m;
    let (sin_c, cos_c) = 60f64.to_radians().sin_cos();
    let dir = tempfile::tempdir().unwrap();
    let (mut boxes, mut peaks, mut relative_boxes) = (vec![], vec![], vec![]);
    for k in 0..3u64 {
        let frame = sim.run(&Request::new(0).frame(k)).unwrap();
        let own = frame.own_ship.as_ref();
        let g = settings.frame_geometry(radar, own);
        let (x, y) = g.radar_px();
        let moved = step_px * k as f64;
        assert!(
            (x - 128.0 - moved * sin_c).abs() < 1e-6 && (y - 128.0 + moved * cos_c).abs() < 1e-6,
            "frame {k}: radar at ({x}, {y})"
        );
        let mut truth = frame.truth.clone();
        g.label(&mut truth);
        boxes.push(truth[0].ppi_box_px.unwrap());
        let conv = settings.frame_scan_converter(radar, own);
        let mut image = vec![0f32; 256 * 256];
        conv.convert(&frame.polar_db, f32::NAN, &mut image);
        let best = (0..image.len())
            .filter(|&i| image[i].is_finite())
            .max_by(|&a, &b| image[a].total_cmp(&image[b]))
            .unwrap();
        peaks.push(((best % 256) as f64, (best / 256) as f64));
        let mut truth = frame.truth.clone();
        relative.frame_geometry(radar, own).label(&mut truth);
        relative_boxes.push(truth[0].ppi_box_px.unwrap());
        // The files say where the radar is.
        write_frame_files(radar, &settings, &frame, dir.path(), "t", 0).unwrap();
        let json: serde_json::Value =
            serde_json::from_slice(&std::fs::read(dir.path().join("truth.json")).unwrap()).unwrap();
        let p = &json["ppi_radar_px"];
        assert!(
            (p[0].as_f64().unwrap() - x).abs() < 1e-9 && (p[1].as_f64().unwrap() - y).abs() < 1e-9
        );
        assert_eq!(
            json["objects"][0]["ppi_box_px"][0].as_f64(),
            Some(boxes[k as usize][0])
        );
    }
    for k in 1..3 {
        let drift = (0..4)
            .map(|i| (boxes[k][i] - boxes[0][i]).abs())
            .fold(0.0, f64::max);
        assert!(
            drift < 0.3,
            "frame {k}: the buoy's box drifted {drift} px: {boxes:?}"
        );
        let (dx, dy) = (peaks[k].0 - peaks[0].0, peaks[k].1 - peaks[0].1);
        assert!(dx.abs() <= 1.0 && dy.abs() <= 1.0, "peaks {peaks:?}");
        // Relative motion: the buoy moves against the own ship's track.
        let centre = |b: [f64; 4]| ((b[0] + b[2]) / 2.0, (b[1] + b[3]) / 2.0);
        let (c0, ck) = (centre(relative_boxes[0]), centre(relative_boxes[k]));
        let moved = step_px * k as f64;
        assert!(
            (ck.0 - c0.0 + moved * sin_c).abs() < 0.5 && (ck.1 - c0.1 - moved * cos_c).abs() < 0.5,
            "relative motion: {c0:?} -> {ck:?}"
        );
    }
    // Head-up in true motion: the picture turns about the image centre, the antenna stays
    // its displacement from it, and the buoy's brightest pixel stays inside its box.
    let head_up = PpiSettings {
        orientation: xbandsim::products::ppi::Orientation::HeadUp,
        ..settings.clone()
    };
    let frame = sim.run(&Request::new(0).frame(2)).unwrap();
    let own = frame.own_ship.as_ref();
    let g = head_up.frame_geometry(radar, own);
    let (x, y) = g.radar_px();
    assert!(((x - 128.0).hypot(y - 128.0) - 2.0 * step_px).abs() < 1e-6);
    assert!(
        (x - 128.0).abs() < 1e-6 && y < 128.0,
        "dead ahead is up: ({x}, {y})"
    );
    let mut truth = frame.truth.clone();
    g.label(&mut truth);
    let b = truth[0].ppi_box_px.unwrap();
    let mut image = vec![0f32; 256 * 256];
    head_up
        .frame_scan_converter(radar, own)
        .convert(&frame.polar_db, f32::NAN, &mut image);
    let best = (0..image.len())
        .filter(|&i| image[i].is_finite())
        .max_by(|&a, &b| image[a].total_cmp(&image[b]))
        .unwrap();
    let (col, row) = ((best % 256) as f64 + 0.5, (best / 256) as f64 + 0.5);
    assert!(
        b[0] - 1.0 <= col && col <= b[2] + 1.0 && b[1] - 1.0 <= row && row <= b[3] + 1.0,
        "peak ({col}, {row}) outside {b:?}"
    );
    // A bad value names the field.
    let bad = text.replace("motion = \"true\"", "motion = \"sideways\"");
    let err = LoadedSpec::from_toml(&bad, "t", std::path::Path::new("."))
        .map(|_| ())
        .unwrap_err()
        .to_string();
    assert!(err.contains("motion") && err.contains("sideways"), "{err}");
}

/// `motion = "true"`, and the booleans `true`/`false` that `--set display.motion=true` writes,
/// read as true and relative motion; an unknown word names the allowed ones.
#[test]
fn display_motion_reads_words_and_booleans() {
    use xbandsim::products::ppi::Motion;
    let motion = |value: &str| {
        let text = format!("[display]\nmotion = {value}\n");
        xbandsim::LoadedSpec::from_toml(&text, "t", std::path::Path::new("."))
            .and_then(|s| s.ppi_settings())
            .map(|p| p.motion)
    };
    assert_eq!(motion("\"true\"").unwrap(), Motion::True);
    assert_eq!(motion("true").unwrap(), Motion::True);
    assert_eq!(motion("false").unwrap(), Motion::Relative);
    assert_eq!(motion("\"relative\"").unwrap(), Motion::Relative);
    let err = motion("\"sideways\"").map(|_| ()).unwrap_err().to_string();
    assert!(
        err.contains("sideways") && err.contains("relative"),
        "{err}"
    );
    let set = xbandsim::LoadedSpec::from_toml("[display]\n", "t", std::path::Path::new("."))
        .unwrap()
        .with_overrides(&["display.motion=true"])
        .unwrap();
    assert_eq!(set.ppi_settings().unwrap().motion, Motion::True);
}

/// A moving scene's still objects keep their traces between revolutions only where no moving
/// object meets their rays, so every revolution's trace is, byte for byte, the one a world
/// that traced nothing before gives: here a ship crosses the line of sight to a moored
/// vessel (whose trace is then traced anew) while another stays clear (kept).
#[test]
fn kept_still_traces_match_a_fresh_trace_every_revolution() {
    let dir = std::env::temp_dir().join(format!("xbandsim-kept-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mesh = dir.join("vessel.obj");
    std::fs::write(
        &mesh,
        xbandsim::geometry::mesh::vessel(30.0, 128).to_obj("vessel"),
    )
    .unwrap();
    let mesh = mesh.display().to_string();
    let text = format!(
        "[radar]\nspokes = 90\nmax_range_m = 1500.0\nrotation_rpm = 60.0\n\
         [environment]\nclutter = false\nmultipath = true\nnoise = false\n\
         [[object]]\nname = \"moored-north\"\nshape = \"mesh\"\nmesh_file = {mesh:?}\n\
         position_m = [0.0, 600.0, 0.0]\nyaw_deg = 90.0\n\
         [[object]]\nname = \"moored-east\"\nshape = \"mesh\"\nmesh_file = {mesh:?}\n\
         position_m = [500.0, -200.0, 0.0]\n\
         [[object]]\nname = \"crossing\"\nshape = \"box\"\nsize_m = [20.0, 6.0, 8.0]\n\
         position_m = [-60.0, 300.0, 4.0]\nspeed_kn = 30.0\ncourse_deg = 90.0\n"
    );
    let scene = Arc::new(crate::common::scene(&text));
    let period_s = scene.radar().scan().period_s();
    let world = xbandsim::engine::World::new(Arc::clone(&scene));
    for k in 0..8 {
        let t_s = k as f64 * period_s;
        let (kept, _) = world.traced(t_s, 0.0);
        let (fresh, _) = xbandsim::engine::World::new(Arc::clone(&scene)).traced(t_s, 0.0);
        assert_eq!(
            kept.set.contributions, fresh.set.contributions,
            "revolution {k}"
        );
        assert_eq!(kept.set.rays_cast, fresh.set.rays_cast, "revolution {k}");
        assert_eq!(
            kept.set.tube_budgets, fresh.set.tube_budgets,
            "revolution {k}"
        );
    }
    // Kept: the eastern vessel every revolution after the first, the northern one while the
    // ship is clear of its rays (it crosses its line of sight at 30 kn, 15 m a revolution,
    // from 60 m west of it): fewer than all 14, and most.
    let reused = world.still_traces_reused();
    assert!((8..14).contains(&reused), "{reused} traces reused");
    // A simulation run revolution after revolution (kept traces, their echo groups kept
    // with them) renders what a fresh one renders for each revolution alone.
    let running = Simulation::new((*scene).clone());
    for frame in 0..5 {
        let request = Request::new(3).frame(frame);
        let kept = running.run(&request).unwrap();
        let fresh = Simulation::new((*scene).clone()).run(&request).unwrap();
        assert_eq!(
            kept.stats.echo_groups, fresh.stats.echo_groups,
            "frame {frame}"
        );
        assert!(
            kept.polar_db == fresh.polar_db,
            "frame {frame}: the records differ"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}
