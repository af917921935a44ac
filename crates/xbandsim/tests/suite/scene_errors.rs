//! Bad input gets a clear error naming the field and the value, never a panic.

use xbandsim::model::Scene;

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
    assert_eq!(s.objects().len(), 1);
    assert_eq!(s.radar().spokes(), 360);
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
        &["scene.toml", "line 3", "torus", "sphere", "mesh"],
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
        &["scene.toml", "line 2", "blackman", "hamming", "taylor"],
    );
    assert_mentions("[radar]\nspokes = 0\n", &["radar.spokes", "0"]);
    assert_mentions("[radar]\nspokes = 9000\n", &["radar.spokes", "9000"]);
    assert_mentions(
        "[radar]\npreset = \"x-band-9000\"\n",
        &["line 2", "x-band-9000", "drs4d-nxt"],
    );
    assert_mentions(
        "[radar]\nbandwidth_mhz = 200.0\n",
        &["radar.bandwidth_mhz", "200"],
    );
    assert_mentions(
        "[scattering]\nmodel = \"mom\"\n",
        &["line 2", "mom", "paper"],
    );
    assert_mentions("[radar]\npolarisation = \"HV\"\n", &["line 2", "HV", "VV"]);
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
    assert!((10.0 * s.radar().antenna().peak_gain_linear.log10() - 27.0).abs() < 1e-9);
}

/// Errors found while building the model name the file, line and column of the value, and
/// say what kind of problem it is.
#[test]
fn semantic_errors_carry_file_line_and_kind() {
    use xbandsim::error::Problem;
    let text = format!("[radar]\nspokes = 99999\n{OK_OBJECT}");
    let e = Scene::from_toml_str(&text, "scene.toml").unwrap_err();
    assert_eq!(e.problem(), Some(Problem::OutOfRange));
    assert_eq!(e.field(), Some("radar.spokes"));
    assert_eq!(e.location().unwrap().line_column, Some((2, 10)));
    assert!(e
        .to_string()
        .starts_with("scene.toml:2:10: invalid `radar.spokes` = 99999"));

    let text = "[[object]]\nname = \"a\"\nshape = \"sphere\"\nposition_m = [0.0, 300.0, 2.0]\nradius_m = -3.0\n";
    let e = Scene::from_toml_str(text, "s.toml").unwrap_err();
    assert_eq!(e.location().unwrap().to_string(), "s.toml:5:12");
    assert_eq!(e.problem(), Some(Problem::OutOfRange));

    let e = Scene::from_toml_str("[environment]\nsea_state = nan\n", "s.toml").unwrap_err();
    assert_eq!(e.problem(), Some(Problem::NotFinite));
    assert_eq!(e.location().unwrap().line_column, Some((2, 13)));

    let text = format!(
        "[radar]\npolarisation = \"VV\"\n[environment]\npolarisation = \"HH\"\n{OK_OBJECT}"
    );
    let e = Scene::from_toml_str(&text, "s.toml").unwrap_err();
    assert_eq!(e.problem(), Some(Problem::Conflict));
    assert_eq!(e.location().unwrap().line_column, Some((4, 16)));

    let e = Scene::from_toml_str(
        "[[object]]\nname = \"a\"\nshape = \"sphere\"\nradius_m = 1.0\n",
        "s.toml",
    )
    .unwrap_err();
    assert_eq!(e.problem(), Some(Problem::Missing));
    assert_eq!(e.field(), Some("object \"a\".position_m"));
    // A default value that is wrong has no line: the file alone is named.
    let e = Scene::from_toml_str("[radar]\nprf_hz = 100000.0\n", "s.toml").unwrap_err();
    assert!(
        e.to_string()
            .starts_with("s.toml: invalid `radar.max_range_m`"),
        "{e}"
    );
}

/// `locate` finds values by dotted path, objects by index or by name, rain cells by index.
#[test]
fn locate_finds_values_by_field_path() {
    use xbandsim::scene::locate;
    let text = "[radar]\nspokes = 4\n\n[[environment.rain_cell]]\nradius_m = 5.0\n[[object]]\nname = \"b\"\nyaw_deg = 3.0\n";
    assert_eq!(locate(text, "radar.spokes"), Some((2, 10)));
    assert_eq!(
        locate(text, "environment.rain_cell[0].radius_m"),
        Some((5, 12))
    );
    assert_eq!(locate(text, "object[0].name"), Some((7, 8)));
    assert_eq!(locate(text, "object \"b\".yaw_deg"), Some((8, 11)));
    assert_eq!(locate(text, "object \"c\".yaw_deg"), None);
    assert_eq!(locate(text, "radar.max_range_m"), None);
    assert_eq!(locate("not toml [", "radar.spokes"), None);
}

/// `--set FIELD=VALUE` overrides go through the same loader and the same checks.
#[test]
fn overrides_set_fields_by_path() {
    use xbandsim::scene::LoadedSpec;
    let dir = std::path::Path::new(".");
    let text = format!("[radar]\nspokes = 4\n{OK_OBJECT}");
    let spec = LoadedSpec::from_toml(&text, "s.toml", dir).unwrap();
    let overridden = spec
        .clone()
        .with_overrides(&[
            "radar.spokes=16",
            "object[0].radius_m=2.5",
            "display.colormap=green",
            "environment.noise = false",
        ])
        .unwrap();
    let scene = overridden.build().unwrap();
    assert_eq!(scene.radar().spokes(), 16);
    assert_eq!(
        overridden.ppi_settings().unwrap().colormap,
        xbandsim::products::ppi::Colormap::Green
    );
    assert!(!scene.environment().noise());
    match scene.objects()[0].shape() {
        xbandsim::geometry::ShapeGeometry::Sphere { radius_m } => assert_eq!(*radius_m, 2.5),
        _ => panic!("not a sphere"),
    }
    // A bad value set on the command line is located there, not in the file.
    let e = spec
        .clone()
        .with_overrides(&["radar.spokes=0"])
        .unwrap()
        .build()
        .unwrap_err();
    assert_eq!(
        e.to_string(),
        "--set: invalid `radar.spokes` = 0: must be between 1 and 8192"
    );
    // Also an object's field, which errors name by the object's name and overrides by its
    // index, and an element of an array set whole.
    for (set, field) in [
        ("object[0].radius_m=-1", "`object \"a\".radius_m` = -1"),
        ("radar.position_m=[0.0, 0.0, nan]", "`radar.position_m`"),
    ] {
        let e = spec
            .clone()
            .with_overrides(&[set])
            .unwrap()
            .build()
            .unwrap_err();
        let msg = e.to_string();
        assert!(
            msg.starts_with("--set: invalid ") && msg.contains(field),
            "{set}: {msg}"
        );
    }
    for (set, needle) in [
        ("radar.spokes", "no `=`"),
        ("=3", "no field"),
        ("radar.spokez=3", "unknown field `spokez`"),
        ("radar.window=blackman", "unknown variant `blackman`"),
        ("radar.spokes=\"many\"", "invalid type"),
        ("object[3].yaw_deg=1", "numbered from 0"),
        ("radar.spokes.x=1", "not a table"),
    ] {
        let e = spec.clone().with_overrides(&[set]).unwrap_err().to_string();
        assert!(e.contains(needle), "{set}: {e}");
    }
}

/// Property: random specs never panic. Each case sets a random handful of fields (through the
/// `--set` path, so the loader is exercised too) to values drawn from the awkward corners —
/// NaN, ±infinity, negative, zero, tiny, huge, wrong types — on top of a valid scene, and
/// building the model must return `Ok` or an error naming a field, never panic.
#[test]
fn random_specs_never_panic() {
    use rand::{Rng, SeedableRng};
    use xbandsim::scene::LoadedSpec;
    const FLOATS: &[&str] = &[
        "radar.frequency_ghz",
        "radar.bandwidth_mhz",
        "radar.pulse_width_us",
        "radar.taylor_sidelobe_db",
        "radar.peak_power_w",
        "radar.noise_figure_db",
        "radar.system_loss_db",
        "radar.gain_dbi",
        "radar.azimuth_beamwidth_deg",
        "radar.elevation_beamwidth_deg",
        "radar.tilt_deg",
        "radar.sample_rate_mhz",
        "radar.prf_hz",
        "radar.rotation_rpm",
        "radar.max_range_m",
        "environment.sea_temperature_c",
        "environment.sea_salinity_psu",
        "environment.sea_rms_height_m",
        "environment.two_way_attenuation_db_per_km",
        "environment.sea_state",
        "environment.wind_direction_deg",
        "environment.swell_direction_deg",
        "environment.clutter_shape_nu",
        "environment.clutter_weibull_shape",
        "environment.clutter_lognormal_sigma_db",
        "environment.clutter_correlation_m",
        "environment.clutter_drift_m_per_s",
        "environment.rain_rate_mm_per_h",
        "environment.rain_top_m",
        "display.range_ring_spacing_m",
        "display.min_db",
        "display.max_db",
        "scattering.ray_spacing_wavelengths",
        "scattering.paper_reference_voltage_uv",
        "object[0].yaw_deg",
        "object[0].pitch_deg",
        "object[0].roll_deg",
        "object[0].rcs_m2",
        "object[0].radius_m",
        "object[0].width_m",
        "object[0].height_m",
        "object[0].edge_m",
        "object[0].speed_kn",
        "object[0].course_deg",
        "object[0].turn_rate_deg_per_s",
        "object[0].heave_amplitude_m",
        "object[0].roll_amplitude_deg",
        "object[0].pitch_amplitude_deg",
        "object[0].motion_period_s",
        "object[0].motion_phase_deg",
        "own_ship.speed_kn",
        "own_ship.course_deg",
        "own_ship.heading_deg",
    ];
    const COUNTS: &[&str] = &[
        "radar.spokes",
        "radar.taylor_nbar",
        "display.image_size_px",
        "scattering.max_rays_per_object",
        "scattering.max_bounces",
        "scattering.paper_rays_per_degree_az",
        "scattering.paper_rays_elevation",
    ];
    const CHOICES: &[(&str, &[&str])] = &[
        ("radar.window", &["none", "hamming", "taylor", "x"]),
        ("radar.polarisation", &["HH", "VV", "hv"]),
        ("environment.polarisation", &["HH", "VV"]),
        (
            "environment.clutter_distribution",
            &["k", "weibull", "lognormal", "rayleigh"],
        ),
        ("environment.clutter_model", &["nrl", "git"]),
        ("environment.sea_roughness", &["ament", "miller-brown-vegh"]),
        ("scattering.model", &["po", "paper"]),
        (
            "object[0].shape",
            &[
                "point",
                "sphere",
                "plate",
                "trihedral",
                "dihedral",
                "cylinder",
                "box",
            ],
        ),
    ];
    const NUMBERS: &[&str] = &[
        "nan",
        "inf",
        "-inf",
        "-1.0",
        "0.0",
        "1e-12",
        "0.5",
        "1.0",
        "3.0",
        "45.0",
        "1000.0",
        "1e9",
        "1e300",
        "-1e300",
        "\"text\"",
        "true",
        "[1.0, 2.0]",
    ];
    const INTEGERS: &[&str] = &["0", "1", "2", "7", "360", "9000", "100000", "-5", "1.5"];
    let base = "[radar]\nspokes = 8\nmax_range_m = 600.0\n[environment]\nrain_rate_mm_per_h = 1.0\n[[environment.rain_cell]]\ncentre_m = [100.0, 100.0]\nradius_m = 50.0\nrate_mm_per_h = 4.0\n[[object]]\nname = \"a\"\nshape = \"sphere\"\nradius_m = 1.0\nposition_m = [0.0, 300.0, 2.0]\n";
    let spec = LoadedSpec::from_toml(base, "base.toml", std::path::Path::new(".")).unwrap();
    assert!(spec.build().is_ok());
    let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(2026);
    let (mut ok, mut refused) = (0, 0);
    for case in 0..400 {
        let mut sets = Vec::new();
        for _ in 0..rng.random_range(1..6) {
            let set = match rng.random_range(0..4) {
                0 | 1 => {
                    let f = FLOATS[rng.random_range(0..FLOATS.len())];
                    format!("{f}={}", NUMBERS[rng.random_range(0..NUMBERS.len())])
                }
                2 => {
                    let f = COUNTS[rng.random_range(0..COUNTS.len())];
                    format!("{f}={}", INTEGERS[rng.random_range(0..INTEGERS.len())])
                }
                _ => {
                    let (f, names) = CHOICES[rng.random_range(0..CHOICES.len())];
                    format!("{f}={}", names[rng.random_range(0..names.len())])
                }
            };
            sets.push(set);
        }
        let result =
            std::panic::catch_unwind(|| spec.clone().with_overrides(&sets).and_then(|s| s.build()));
        match result {
            Ok(Ok(_)) => ok += 1,
            Ok(Err(e)) => {
                refused += 1;
                let msg = e.to_string();
                assert!(!msg.is_empty(), "case {case} {sets:?}: empty message");
                if let Some(field) = e.field() {
                    assert!(msg.contains(field), "case {case} {sets:?}: {msg}");
                }
            }
            Err(_) => panic!("case {case}: building panicked with --set {sets:?}"),
        }
    }
    // Both outcomes occur: the generator reaches valid and invalid scenes.
    eprintln!("{ok} accepted, {refused} refused");
    assert!(ok > 20 && refused > 20, "{ok} accepted, {refused} refused");
}

/// Objects made in code go through the same kind of checks as objects from a file: sizes,
/// position, rotation and name are refused with the field and the kind.
#[test]
fn objects_made_in_code_are_checked() {
    use glam::{DMat3, DVec3};
    use xbandsim::geometry::ShapeGeometry;
    use xbandsim::model::SceneObject;
    let sphere = |r: f64| ShapeGeometry::Sphere { radius_m: r };
    let at = DVec3::new(0.0, 100.0, 1.0);
    assert!(SceneObject::new("ok", "buoy", sphere(1.0), at, DMat3::IDENTITY).is_ok());
    let cases = [
        SceneObject::new("neg", "x", sphere(-1.0), at, DMat3::IDENTITY),
        SceneObject::new("nan", "x", sphere(f64::NAN), at, DMat3::IDENTITY),
        SceneObject::new(
            "box",
            "x",
            ShapeGeometry::Box {
                size_m: DVec3::new(1.0, 0.0, 1.0),
            },
            at,
            DMat3::IDENTITY,
        ),
        SceneObject::new(
            "pos",
            "x",
            sphere(1.0),
            DVec3::new(f64::INFINITY, 0.0, 0.0),
            DMat3::IDENTITY,
        ),
        SceneObject::new(
            "scaled",
            "x",
            sphere(1.0),
            at,
            DMat3::from_diagonal(DVec3::splat(2.0)),
        ),
        SceneObject::new(
            "mirror",
            "x",
            sphere(1.0),
            at,
            DMat3::from_diagonal(DVec3::new(1.0, 1.0, -1.0)),
        ),
        SceneObject::new(" ", "x", sphere(1.0), at, DMat3::IDENTITY),
    ];
    let fields = [
        "\"neg\".shape",
        "\"nan\".shape",
        "\"box\".shape",
        "\"pos\".position_m",
        "\"scaled\".rotation",
        "\"mirror\".rotation",
        "object.name",
    ];
    for (result, field) in cases.into_iter().zip(fields) {
        let e = result.expect_err(field);
        assert!(e.to_string().contains(field), "{field}: {e}");
        assert!(e.problem().is_some(), "{e}");
    }
}

/// A bad `[display]` table is refused by every loader, though the display is not part of the
/// model.
#[test]
fn bad_display_is_refused_by_every_loader() {
    let text = format!("[display]\nimage_size_px = 3\n{OK_OBJECT}");
    let e = Scene::from_toml_str(&text, "d.toml").unwrap_err();
    assert!(e.to_string().contains("display.image_size_px"), "{e}");
}

/// An object so large that it encloses the radar is not said to be "at the radar's
/// position": the message gives its distance and bounding radius.
#[test]
fn object_enclosing_the_radar() {
    let msg = error_of("[radar]\nposition_m = [0.0, 0.0, 10.0]\n[[object]]\nname = \"x\"\nshape = \"sphere\"\nradius_m = 1e7\nposition_m = [0.0, 500.0, 5.0]\n");
    assert!(
        msg.contains("object \"x\".position_m")
            && msg.contains("inside the object's bounding sphere")
            && msg.contains("10000000.0 m")
            && !msg.contains("at the radar's position"),
        "{msg}"
    );
}

/// A ray budget whose trace would not fit in memory is refused before anything is traced,
/// naming the field that sets the grid: the spacing where the budget does not bind (a 10 m
/// sphere at 0.01 wavelengths with a huge budget: 3e9 tubes), the budget where it does (a
/// billion tubes for a 1 km sphere, twice with the sea on).
#[test]
fn ray_budgets_that_would_not_fit_in_memory() {
    let sphere = "[[object]]\nname = \"x\"\nshape = \"sphere\"\nradius_m = 10.0\nposition_m = [0.0, 500.0, 12.0]\n";
    assert_mentions(
        &format!("[scattering]\nray_spacing_wavelengths = 0.01\nmax_rays_per_object = 1000000000000\n{sphere}"),
        &["scattering.ray_spacing_wavelengths", "0.01", "GB of memory", "limit is 4 GB"],
    );
    assert_mentions(
        "[scattering]\nmax_rays_per_object = 1000000000\n[environment]\nsea_state = 3\n[[object]]\nname = \"x\"\nshape = \"sphere\"\nradius_m = 1000.0\nposition_m = [0.0, 5000.0, 12.0]\n",
        &["scattering.max_rays_per_object", "1000000000", "GB of memory"],
    );
    // The default budget fits with hundreds of ship-sized objects; the paper model has no
    // tubes.
    let mut many = String::new();
    for i in 0..200 {
        many.push_str(&format!("[[object]]\nname = \"s{i}\"\nshape = \"box\"\nsize_m = [8.0, 60.0, 12.0]\nposition_m = [{}.0, 2000.0, 6.0]\n", 100 * i));
    }
    Scene::from_toml_str(&many, "t").unwrap();
    Scene::from_toml_str(
        &format!("[scattering]\nmodel = \"paper\"\nray_spacing_wavelengths = 0.01\nmax_rays_per_object = 1000000000000\n{sphere}"),
        "t",
    )
    .unwrap();
}

/// [`xbandsim::model::BYTES_PER_TUBE`] holds at least a tube's return and its contribution.
#[test]
fn bytes_per_tube_covers_a_return_and_a_contribution() {
    let bytes = std::mem::size_of::<xbandsim::scattering::po::TubeReturn>()
        + std::mem::size_of::<xbandsim::scattering::Contribution>();
    assert!(
        (bytes as f64) <= xbandsim::model::BYTES_PER_TUBE,
        "{bytes} bytes"
    );
}
