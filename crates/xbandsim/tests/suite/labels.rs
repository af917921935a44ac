//! Ground-truth labels: every loss of the echo is in its label, visibility flags name the
//! physical reason, and nothing is labelled with a sentinel number or boxed where there is
//! no echo.

use super::common::*;
use xbandsim::products::labels::Visibility;
use xbandsim_validate::{bin_range_m, radar_block_no_noise};

/// A point target behind a rain cell: the label's rain loss equals 2·γ·(chord through the
/// cell) with ITU-R P.838-3's γ, and its expected SNR equals the measured matched-filter
/// peak (target on an output bin, noise off) within 0.05 dB. Radar and target are at 4 m in a
/// rain layer 5 m deep (attenuation counts only the path below the top); the target's
/// 10⁴ m² keep the rain's own echo in its cell from moving the peak.
#[test]
fn rain_on_the_path_is_in_the_label() {
    let range_m = bin_range_m(1800.0, 100e6);
    let text = format!(
        "[environment]\nnoise = false\nclutter = false\nmultipath = false\nrain_top_m = 5.0\n\
         [[environment.rain_cell]]\ncentre_m = [0.0, 1400.0]\nradius_m = 400.0\nrate_mm_per_h = 40.0\n\
         [radar]\nposition_m = [0.0, 0.0, 4.0]\nmax_range_m = 3000.0\n{}",
        point_north("p", range_m, 1e4)
    );
    let (_, frame) = render(&text, 1);
    let t = &frame.truth[0];
    let gamma = xbandsim::propagation::specific_attenuation_db_per_km(9.41, 40.0, true);
    let expected_rain_db = 2.0 * gamma * 0.8;
    assert!(
        (t.losses_db.rain - expected_rain_db).abs() < 0.01,
        "label rain loss {:.3} dB, 2γ·800 m = {expected_rain_db:.3} dB",
        t.losses_db.rain
    );
    label_snr_is_the_peak(&frame, 1800);
    assert!(
        expected_rain_db > 1.0,
        "rain too weak to test: {expected_rain_db}"
    );
}

/// A 10⁴ m² point target 30° above a radar at 4 m (beam tilted onto it) on the output bin 700
/// (1049 m), noise off, in the rain of `rain` (environment lines): its frame, slant range and
/// ground range.
fn target_30_degrees_up_in(rain: &str) -> (xbandsim::Frame, f64, f64) {
    let range_m = bin_range_m(700.0, 100e6);
    let el = 30f64.to_radians();
    let (ground_m, height_m) = (range_m * el.cos(), 4.0 + range_m * el.sin());
    let text = format!(
        "[environment]\nnoise = false\nclutter = false\nmultipath = false\n{rain}\n\
         [radar]\nposition_m = [0.0, 0.0, 4.0]\nmax_range_m = 1500.0\ntilt_deg = 30.0\n\
         [[object]]\nname = \"p\"\nshape = \"point\"\nrcs_m2 = 1e4\n\
         position_m = [0.0, {ground_m}, {height_m}]\n"
    );
    let (_, frame) = render(&text, 1);
    (frame, range_m, ground_m)
}

/// A target 30° above the radar inside a rain column: the echo and the label both lose
/// 2·γ·R over the slant path R, not over its ground track (docs/physics.md §2.7; the label
/// once used the track alone, 0.3 dB less here), and the expected SNR equals the measured
/// peak (noise off; the beam tilted onto the target) within 0.05 dB.
#[test]
fn rain_on_a_slant_path_is_in_the_label() {
    let (frame, range_m, ground_m) = target_30_degrees_up_in(
        "rain_top_m = 2000.0\n[[environment.rain_cell]]\ncentre_m = [0.0, 450.0]\n\
         radius_m = 600.0\nrate_mm_per_h = 40.0",
    );
    let t = &frame.truth[0];
    let gamma = xbandsim::propagation::specific_attenuation_db_per_km(9.41, 40.0, true);
    let slant_db = 2.0 * gamma * range_m / 1000.0;
    let track_db = 2.0 * gamma * ground_m / 1000.0;
    assert!(
        (t.losses_db.rain - slant_db).abs() < 0.01,
        "label rain loss {:.3} dB, 2γR = {slant_db:.3} dB (ground track: {track_db:.3} dB)",
        t.losses_db.rain
    );
    assert!(slant_db - track_db > 0.2, "{slant_db} {track_db}");
    label_snr_is_the_peak(&frame, 700);
}

/// A target 30° above the radar, above a rain layer 100 m deep: the path loses γ over its
/// part below the rain top alone, (100 − 4 m)/sin 30° = 192 m of 1049 m, in the echo and in
/// the label (attenuation once ignored the top and charged the whole path: 1.9 dB more
/// here), and the expected SNR equals the measured peak within 0.05 dB.
#[test]
fn rain_above_the_rain_top_is_not_charged() {
    let (frame, range_m, _) =
        target_30_degrees_up_in("rain_top_m = 100.0\nrain_rate_mm_per_h = 40.0");
    let t = &frame.truth[0];
    let gamma = xbandsim::propagation::specific_attenuation_db_per_km(9.41, 40.0, true);
    let below_m = (100.0 - 4.0) / 30f64.to_radians().sin();
    let expected_db = 2.0 * gamma * below_m / 1000.0;
    let whole_db = 2.0 * gamma * range_m / 1000.0;
    assert!(
        (t.losses_db.rain - expected_db).abs() < 0.01,
        "label rain loss {:.3} dB, 2γ·{below_m:.0} m = {expected_db:.3} dB (whole path: \
         {whole_db:.3} dB)",
        t.losses_db.rain
    );
    assert!(whole_db - expected_db > 1.0, "{whole_db} {expected_db}");
    label_snr_is_the_peak(&frame, 700);
}

/// The first object's expected SNR equals spoke 0's peak within 2 bins of `bin` (a target
/// on an output bin, noise off) within 0.05 dB.
fn label_snr_is_the_peak(frame: &xbandsim::Frame, bin: usize) {
    let peak = spoke(frame, 0)[bin - 2..=bin + 2]
        .iter()
        .cloned()
        .fold(f32::MIN, f32::max) as f64;
    let snr = frame.truth[0].expected_snr_db.unwrap();
    assert!(
        (snr - peak).abs() < 0.05,
        "label {snr:.3} dB, peak {peak:.3} dB"
    );
}

/// No sentinels and no boxes around nothing: an edge-on plate returns nothing (null RCS and
/// SNR, `no_return`), an object behind a wall is `shadowed`, one past the maximum range is
/// `beyond_max_range`; none of them gets a box, and the JSON says null.
#[test]
fn objects_without_an_echo_have_null_values_and_no_box() {
    let text = format!(
        "{}{}",
        radar_block_no_noise("max_range_m = 1500.0"),
        r#"[[object]]
name = "edge-on"
shape = "plate"
width_m = 2.0
height_m = 1.0
position_m = [500.0, 0.0, 4.0]
yaw_deg = 0.0
[[object]]
name = "wall"
shape = "box"
size_m = [20.0, 2.0, 12.0]
position_m = [0.0, 300.0, 4.0]
[[object]]
name = "hidden"
shape = "sphere"
radius_m = 1.0
position_m = [0.0, 700.0, 4.0]
[[object]]
name = "far"
shape = "sphere"
radius_m = 1.0
position_m = [-2500.0, 0.0, 4.0]
# PO alone: the edge-on plate's faces return nothing. (Its near edge's first-order fringe
# in HH is zero as well, Keller's and PO's coefficients cancelling, but in floating point
# it comes out near 1e-33 m², a return below the noise rather than none.)
[scattering]
edge_diffraction = false
"#
    );
    let (sim, frame) = render(&text, 1);
    // Pixel boxes are the PPI product's: absent from the frame's truth until an image labels it.
    assert!(frame.truth.iter().all(|t| t.ppi_box_px.is_none()));
    let mut truth = frame.truth.clone();
    xbandsim::products::ppi::PpiGeometry {
        size_px: 512,
        display_range_m: sim.scene().radar().max_range_m(),
        up_azimuth_rad: 0.0,
        radar_offset_m: [0.0, 0.0],
    }
    .label(&mut truth);
    let by = |n: &str| truth.iter().find(|t| t.name == n).unwrap().clone();
    let edge = by("edge-on");
    assert_eq!(edge.visibility, Visibility::NoReturn, "{edge:?}");
    assert!(edge.rcs_m2.is_none() && edge.rcs_dbsm.is_none() && edge.expected_snr_db.is_none());
    let hidden = by("hidden");
    assert_eq!(hidden.visibility, Visibility::Shadowed, "{hidden:?}");
    let far = by("far");
    assert_eq!(far.visibility, Visibility::BeyondMaxRange);
    for t in [&edge, &hidden, &far] {
        assert!(t.polar_box.is_none() && t.ppi_box_px.is_none(), "{t:?}");
        let json = serde_json::to_string(t).unwrap();
        assert!(
            json.contains("\"polar_box\":null") && !json.contains("-300"),
            "{json}"
        );
    }
    let wall = by("wall");
    assert_eq!(wall.visibility, Visibility::Visible);
    assert!(wall.polar_box.is_some() && wall.ppi_box_px.is_some());
}

/// The `paper` model's uniform grid can pass between the rows around a small object; that
/// is labelled as the model's grid missing it, not as a shadow; a real shadow stays one.
#[test]
fn paper_grid_misses_are_not_shadows() {
    let text = format!(
        "{}{}",
        radar_block_no_noise("max_range_m = 1500.0").replace(
            "[radar]",
            "[scattering]\nmodel = \"paper\"\npaper_rays_elevation = 5\n[radar]"
        ),
        r#"[[object]]
name = "small"
shape = "sphere"
radius_m = 0.05
position_m = [0.0, 800.0, 4.5]
[[object]]
name = "wall"
shape = "box"
size_m = [30.0, 2.0, 30.0]
position_m = [300.0, 0.0, 4.0]
[[object]]
name = "behind"
shape = "sphere"
radius_m = 0.5
position_m = [900.0, 0.0, 4.0]
"#
    );
    let (_, frame) = render(&text, 1);
    assert_eq!(
        frame.truth[0].visibility,
        Visibility::MissedByRayGrid,
        "{:?}",
        frame.truth[0]
    );
    assert_eq!(
        frame.truth[2].visibility,
        Visibility::Shadowed,
        "{:?}",
        frame.truth[2]
    );
    assert!(frame.truth[0].polar_box.is_none());
}

/// Each label's aspect is where the radar lies in the object's own frame: bow-on, on either
/// beam, and with the deck pitched or rolled the elevation above the deck plane, against the
/// geometry worked by hand (the radar 15 m up, the objects 1000 m off at sea level: the
/// radar at atan(15/1000) = 0.859° above the horizontal from them).
#[test]
fn the_aspect_is_the_radars_direction_in_the_objects_frame() {
    let up_deg = 15f64.atan2(1000.0).to_degrees();
    // (position, yaw, pitch, roll) → (aspect azimuth, aspect elevation), degrees.
    let cases = [
        ([0.0, 1000.0], 180.0, 0.0, 0.0, 0.0, up_deg),
        ([0.0, 1000.0], 90.0, 0.0, 0.0, 90.0, up_deg),
        ([0.0, 1000.0], 270.0, 0.0, 0.0, 270.0, up_deg),
        ([1000.0, 0.0], 0.0, 0.0, 0.0, 270.0, up_deg),
        ([0.0, 1000.0], 0.0, 0.0, 0.0, 180.0, up_deg),
        ([0.0, -1000.0], 0.0, 0.0, 0.0, 0.0, up_deg),
        // Bow toward the radar and raised 10°: the radar is 10° lower over the deck.
        ([0.0, 1000.0], 180.0, 10.0, 0.0, 0.0, up_deg - 10.0),
        // The radar on the starboard beam, starboard rolled 10° down: 10° higher.
        ([0.0, 1000.0], 90.0, 0.0, 10.0, 90.0, up_deg + 10.0),
    ];
    let mut text = String::from(
        "[environment]\nnoise = false\nclutter = false\nmultipath = false\n\
         [radar]\nposition_m = [0.0, 0.0, 15.0]\nmax_range_m = 1500.0\n",
    );
    for (i, ([x, y], yaw, pitch, roll, _, _)) in cases.iter().enumerate() {
        text.push_str(&format!(
            "[[object]]\nname = \"b{i}\"\nshape = \"box\"\nsize_m = [4.0, 12.0, 3.0]\n\
             position_m = [{x}, {y}, 0.0]\nyaw_deg = {yaw}\npitch_deg = {pitch}\nroll_deg = {roll}\n"
        ));
    }
    let (_, frame) = render(&text, 1);
    for (t, (_, _, _, _, az, el)) in frame.truth.iter().zip(cases) {
        assert!(
            (t.aspect_azimuth_deg - az).abs() < 1e-6 && (t.aspect_elevation_deg - el).abs() < 1e-6,
            "{}: aspect ({}, {}), expected ({az}, {el})",
            t.name,
            t.aspect_azimuth_deg,
            t.aspect_elevation_deg
        );
    }
}
