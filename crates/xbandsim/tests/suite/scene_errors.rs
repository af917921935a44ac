//! Bad input gets a clear error naming the field and the value, never a panic.

use xbandsim::scene::Scene;

const OK_OBJECT: &str = "[[object]]\nname = \"a\"\nshape = \"sphere\"\nradius_m = 1.0\nposition_m = [0.0, 300.0, 2.0]\n";

fn error_of(text: &str) -> String {
    match Scene::from_toml_str(text, "scene.toml") {
        Ok(_) => panic!("accepted:\n{text}"),
        Err(e) => e.to_string(),
    }
}

fn assert_mentions(text: &str, needles: &[&str]) {
    let msg = error_of(text);
    for n in needles {
        assert!(msg.contains(n), "error {msg:?} does not mention {n:?}");
    }
}

#[test]
fn valid_scene_is_accepted() {
    let s = Scene::from_toml_str(&format!("[radar]\n{OK_OBJECT}"), "t").unwrap();
    assert_eq!(s.objects.len(), 1);
    assert_eq!(s.radar.spokes, 360);
}

#[test]
fn malformed_toml_names_file_and_line() {
    assert_mentions("[radar]\npulse_width_us = = 3\n", &["scene.toml", "line 2"]);
}

#[test]
fn unknown_field_is_named() {
    assert_mentions("[radar]\npulse_widht_us = 3.0\n", &["pulse_widht_us"]);
}

#[test]
fn wrong_type_is_reported() {
    assert_mentions("[radar]\nspokes = \"many\"\n", &["spokes"]);
}

#[test]
fn unknown_shape() {
    assert_mentions(
        "[[object]]\nname = \"x\"\nshape = \"torus\"\nposition_m = [0.0, 100.0, 0.0]\n",
        &["object \"x\".shape", "\"torus\"", "sphere"],
    );
}

#[test]
fn missing_size_field() {
    assert_mentions(
        "[[object]]\nname = \"x\"\nshape = \"sphere\"\nposition_m = [0.0, 100.0, 0.0]\n",
        &["object \"x\".radius_m", "missing"],
    );
    assert_mentions(
        "[[object]]\nname = \"x\"\nshape = \"sphere\"\nradius_m = 1.0\n",
        &["object \"x\".position_m", "missing"],
    );
    assert_mentions(
        "[[object]]\nname = \"x\"\nradius_m = 1.0\nposition_m = [0.0, 100.0, 0.0]\n",
        &["object \"x\".shape"],
    );
}

#[test]
fn negative_and_zero_sizes() {
    assert_mentions("[[object]]\nname = \"x\"\nshape = \"plate\"\nwidth_m = -2.0\nheight_m = 1.0\nposition_m = [0.0, 100.0, 0.0]\n", &["object \"x\".width_m", "-2"]);
    assert_mentions("[[object]]\nname = \"x\"\nshape = \"trihedral\"\nedge_m = 0.0\nposition_m = [0.0, 100.0, 0.0]\n", &["object \"x\".edge_m", "0"]);
    assert_mentions("[[object]]\nname = \"x\"\nshape = \"box\"\nsize_m = [1.0, 0.0, 1.0]\nposition_m = [0.0, 100.0, 0.0]\n", &["object \"x\".size_m"]);
    assert_mentions(
        "[radar]\npeak_power_w = -25.0\n",
        &["radar.peak_power_w", "-25"],
    );
}

#[test]
fn nan_and_infinity() {
    assert_mentions(
        "[radar]\npulse_width_us = nan\n",
        &["radar.pulse_width_us", "NaN"],
    );
    assert_mentions("[[object]]\nname = \"x\"\nshape = \"sphere\"\nradius_m = inf\nposition_m = [0.0, 100.0, 0.0]\n", &["object \"x\".radius_m", "inf"]);
    assert_mentions("[[object]]\nname = \"x\"\nshape = \"sphere\"\nradius_m = 1.0\nposition_m = [0.0, nan, 0.0]\n", &["object \"x\".position_m"]);
}

#[test]
fn pulse_not_shorter_than_pri() {
    assert_mentions(
        "[radar]\nprf_hz = 20000.0\npulse_width_us = 50.0\n",
        &["radar.pulse_width_us", "50", "pulse repetition interval"],
    );
    assert_mentions(
        "[radar]\nprf_hz = 100000.0\npulse_width_us = 10.0\n",
        &["radar.pulse_width_us", "10"],
    );
}

#[test]
fn object_at_radar_position() {
    assert_mentions("[radar]\nposition_m = [0.0, 0.0, 4.0]\n[[object]]\nname = \"x\"\nshape = \"point\"\nrcs_m2 = 1.0\nposition_m = [0.0, 0.0, 4.0]\n", &["object \"x\".position_m", "radar"]);
    assert_mentions("[radar]\nposition_m = [0.0, 0.0, 4.0]\n[[object]]\nname = \"x\"\nshape = \"sphere\"\nradius_m = 5.0\nposition_m = [1.0, 2.0, 3.0]\n", &["object \"x\".position_m"]);
}

#[test]
fn other_bad_values() {
    assert_mentions(
        "[radar]\nwindow = \"blackman\"\n",
        &["radar.window", "blackman"],
    );
    assert_mentions("[radar]\nspokes = 0\n", &["radar.spokes", "0"]);
    assert_mentions("[radar]\nspokes = 9000\n", &["radar.spokes", "9000"]);
    assert_mentions(
        "[radar]\npreset = \"x-band-9000\"\n",
        &["radar.preset", "x-band-9000"],
    );
    assert_mentions(
        "[radar]\nbandwidth_mhz = 200.0\n",
        &["radar.bandwidth_mhz", "200"],
    );
    assert_mentions(
        "[scattering]\nmodel = \"mom\"\n",
        &["scattering.model", "mom"],
    );
    assert_mentions(
        "[radar]\npolarisation = \"HV\"\n",
        &["radar.polarisation", "HV"],
    );
    assert_mentions(&format!("{OK_OBJECT}{OK_OBJECT}"), &["name", "\"a\""]);
    assert_mentions("[[object]]\nname = \"x\"\nshape = \"sphere\"\nradius_m = 1.0\nwidth_m = 2.0\nposition_m = [0.0, 100.0, 0.0]\n", &["object \"x\".width_m"]);
}

#[test]
fn missing_file_names_the_path() {
    let msg = Scene::load(std::path::Path::new("/nonexistent/scene.toml"))
        .unwrap_err()
        .to_string();
    assert!(msg.contains("/nonexistent/scene.toml"), "{msg}");
}

/// A radar at or below the sea surface, objects wholly under it, ranges beyond the
/// unambiguous range, outputs far too large and antenna gains no aperture with the given
/// beamwidths can have are refused with the field named.
#[test]
fn physically_impossible_setups_are_refused() {
    assert_mentions(
        &format!("[radar]\nposition_m = [0.0, 0.0, -2.0]\n{OK_OBJECT}"),
        &["radar.position_m", "-2", "above the sea"],
    );
    assert_mentions(
        "[[object]]\nname = \"sub\"\nshape = \"box\"\nsize_m = [4.0, 4.0, 1.0]\nposition_m = [0.0, 300.0, -1.5]\n",
        &["object \"sub\".position_m", "below the sea"],
    );
    assert_mentions(
        "[[object]]\nname = \"p\"\nshape = \"point\"\nrcs_m2 = 1.0\nposition_m = [0.0, 300.0, -0.1]\n",
        &["object \"p\".position_m", "below the sea"],
    );
    // c/(2·PRF) = 75 km at 2 kHz.
    assert_mentions(
        &format!("[radar]\nprf_hz = 2000.0\nmax_range_m = 80000.0\nspokes = 16\n{OK_OBJECT}"),
        &["radar.max_range_m", "80000", "unambiguous", "74.9 km"],
    );
    assert_mentions(
        &format!("[radar]\nprf_hz = 20.0\nmax_range_m = 7000000.0\nspokes = 4\n{OK_OBJECT}"),
        &["radar.max_range_m", "4 million range bins"],
    );
    assert_mentions(
        &format!("[radar]\nprf_hz = 200.0\nmax_range_m = 400000.0\nspokes = 720\n{OK_OBJECT}"),
        &["radar.max_range_m", "M cells", "limit"],
    );
    assert_mentions(
        &format!("[radar]\ngain_dbi = 55.0\n{OK_OBJECT}"),
        &["radar.gain_dbi", "55", "implausible", "3.9° × 25°"],
    );
    assert_mentions(
        &format!("[radar]\ngain_dbi = -3.0\n{OK_OBJECT}"),
        &["radar.gain_dbi", "-3"],
    );
    // A plausible gain is kept.
    let s = Scene::from_toml_str(&format!("[radar]\ngain_dbi = 27.0\n{OK_OBJECT}"), "t").unwrap();
    assert!((10.0 * s.radar.antenna.peak_gain_linear.log10() - 27.0).abs() < 1e-9);
}
