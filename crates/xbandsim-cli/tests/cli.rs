//! The `xbandsim` binary as a user runs it.

use std::path::Path;
use std::process::Command;

fn xbandsim() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_xbandsim"));
    c.current_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join("../.."));
    c
}

#[test]
fn render_writes_the_four_outputs() {
    let dir = tempfile::tempdir().unwrap();
    let out = xbandsim()
        .args([
            "render",
            "scenes/paper.toml",
            "--seed",
            "3",
            "--spokes",
            "720",
            "--out",
        ])
        .arg(dir.path())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("5 objects") && stdout.contains("rays"),
        "{stdout}"
    );
    for f in ["ppi.png", "ppi_gray.png", "polar.npy", "truth.json"] {
        assert!(dir.path().join(f).is_file(), "{f} missing");
    }
    let (shape, data) =
        xbandsim::products::output::read_npy_f32(&dir.path().join("polar.npy")).unwrap();
    assert_eq!(shape[0], 720);
    assert_eq!(shape[1], 1000 * 2 * 100_000_000 / 299_792_458 + 1);
    assert!(data.iter().all(|v| v.is_finite()));
    let truth: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("truth.json")).unwrap()).unwrap();
    let objects = truth["objects"].as_array().unwrap();
    assert_eq!(objects.len(), 5);
    for key in ["name", "class", "position_m", "range_m", "azimuth_deg"] {
        assert!(
            objects.iter().all(|o| !o[key].is_null()),
            "truth lacks {key}"
        );
    }
    // No temporary files are left behind.
    let leftovers: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().contains(".tmp"))
        .collect();
    assert!(leftovers.is_empty());
}

/// `--frames N` writes N revolutions of a moving scene, one folder each, and refuses 0.
#[test]
fn frames_writes_consecutive_revolutions() {
    let dir = tempfile::tempdir().unwrap();
    let out = xbandsim()
        .args([
            "render",
            "scenes/crossing.toml",
            "--frames",
            "2",
            "--spokes",
            "90",
            "--out",
        ])
        .arg(dir.path())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(String::from_utf8_lossy(&out.stdout).contains("2 frames"));
    let truth = |k: u64| -> serde_json::Value {
        let path = dir.path().join(format!("frame_{k:04}")).join("truth.json");
        serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap()
    };
    let (t0, t1) = (truth(0), truth(1));
    assert_eq!(t0["frame"], 0);
    assert_eq!(t1["frame"], 1);
    assert_eq!(t1["frame_start_time_s"], 2.5);
    assert!(t1["own_ship"]["speed_kn"].as_f64().unwrap() > 5.9);
    for f in ["ppi.png", "ppi_gray.png", "polar.npy"] {
        assert!(
            dir.path().join("frame_0001").join(f).is_file(),
            "{f} missing"
        );
    }
    assert!(
        !dir.path().join("truth.json").exists(),
        "no flat files with --frames"
    );
    // The crossing ship moved east by about its speed times the revolution period.
    let east = |t: &serde_json::Value| t["objects"][0]["position_m"][0].as_f64().unwrap();
    let moved = east(&t1) - east(&t0);
    assert!(
        (moved - 12.0 * 1852.0 / 3600.0 * 2.5).abs() < 0.5,
        "moved {moved} m"
    );
    assert_eq!(t0["objects"][0]["track_id"], t1["objects"][0]["track_id"]);

    let out = xbandsim()
        .args(["render", "scenes/crossing.toml", "--frames", "0", "--out"])
        .arg(dir.path().join("none"))
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("--frames 0"));
}

/// `--datacube` writes doppler_cube.npy in pulse mode, with its axes in truth.json, and is
/// refused in spoke mode.
#[test]
fn datacube_is_written_in_pulse_mode() {
    let dir = tempfile::tempdir().unwrap();
    let args = |mode: &str| {
        vec![
            "render".to_string(),
            "scenes/paper.toml".into(),
            "--datacube".into(),
            "--spokes".into(),
            "90".into(),
            "--set".into(),
            format!("processing.mode={mode}"),
            "--out".into(),
        ]
    };
    let out = xbandsim()
        .args(args("pulse"))
        .arg(dir.path())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let (shape, data) =
        xbandsim::products::output::read_npy_f32(&dir.path().join("doppler_cube.npy")).unwrap();
    // 1200 Hz × 2.5 s = 3000 pulses over 90 spokes: at least 33 a spoke.
    assert_eq!(shape[0], 90);
    assert_eq!(shape[1], 33);
    assert!(data.iter().all(|v| v.is_finite()));
    let truth: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("truth.json")).unwrap()).unwrap();
    assert_eq!(truth["doppler_cube"]["zero_doppler_bin"], 16);
    let out = xbandsim()
        .args(args("spoke"))
        .arg(dir.path().join("spoke"))
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("--datacube") && err.contains("pulse"), "{err}");
    assert!(!dir.path().join("spoke").exists());
}

/// `--iq` writes iq.npy (complex64, pulses × samples) and iq_pulses.npy (float64, pulses × 3)
/// with their axes in truth.json; oversized captures are refused before anything is written.
#[test]
fn raw_iq_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let out = xbandsim()
        .args([
            "render",
            "scenes/paper.toml",
            "--iq",
            "--spokes",
            "90",
            "--set",
            "radar.max_range_m=600",
            "--out",
        ])
        .arg(dir.path())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let truth: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("truth.json")).unwrap()).unwrap();
    let samples = truth["iq"]["shape"][1].as_u64().unwrap() as usize;
    assert_eq!(truth["iq"]["shape"][0], 90);
    // 600 m at 1.499 m a bin: 401 bins, plus the 1 µs pulse's 100 samples less one.
    assert_eq!(samples, 401 + 100 - 1);
    let iq = std::fs::read(dir.path().join("iq.npy")).unwrap();
    let header = String::from_utf8_lossy(&iq[10..128]).to_string();
    assert!(
        header.contains("'<c8'") && header.contains("(90, 500)"),
        "{header}"
    );
    let header_len = u16::from_le_bytes([iq[8], iq[9]]) as usize;
    assert_eq!(iq.len(), 10 + header_len + 90 * samples * 8);
    let pulses = std::fs::read(dir.path().join("iq_pulses.npy")).unwrap();
    let header = String::from_utf8_lossy(&pulses[10..128]).to_string();
    assert!(
        header.contains("'<f8'") && header.contains("(90, 3)"),
        "{header}"
    );
    let out = xbandsim()
        .args([
            "render",
            "scenes/paper.toml",
            "--iq",
            "--set",
            "processing.mode=pulse",
            "--set",
            "radar.max_range_m=60000",
            "--set",
            "radar.prf_hz=2000",
            "--out",
        ])
        .arg(dir.path().join("big"))
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("--iq") && err.contains("short runs"), "{err}");
    assert!(!dir.path().join("big").exists());
}

#[test]
fn bad_scene_gives_a_clear_error_and_no_output() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("bad.toml");
    std::fs::write(&scene, "[[object]]\nname = \"buoy\"\nshape = \"cylinder\"\nradius_m = -0.3\nheight_m = 1.0\nposition_m = [0.0, 100.0, 0.0]\n").unwrap();
    let out_dir = dir.path().join("out");
    let out = xbandsim()
        .args(["render"])
        .arg(&scene)
        .arg("--out")
        .arg(&out_dir)
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("object \"buoy\".radius_m") && err.contains("-0.3"),
        "{err}"
    );
    assert!(!err.contains("panicked"), "{err}");
    assert!(!out_dir.exists(), "output written for a bad scene");
    let out = xbandsim()
        .args(["render", "/nonexistent.toml", "--out"])
        .arg(&out_dir)
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("/nonexistent.toml"));
    let out = xbandsim()
        .args([
            "render",
            "scenes/paper.toml",
            "--pulse-width-us",
            "2000",
            "--out",
        ])
        .arg(&out_dir)
        .output()
        .unwrap();
    assert!(String::from_utf8_lossy(&out.stderr).contains("radar.pulse_width_us"));
}

#[test]
fn schema_is_json_and_covers_the_format() {
    let out = xbandsim().arg("schema").output().unwrap();
    assert!(out.status.success());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let text = v.to_string();
    for field in [
        "pulse_width_us",
        "position_m",
        "edge_m",
        "rcs_m2",
        "range_ring_spacing_m",
        "speed_kn",
        "turn_rate_deg_per_s",
        "track",
        "motion_period_s",
        "own_ship",
    ] {
        assert!(text.contains(field), "schema lacks {field}");
    }
    // Every choice is listed as an enumeration, not typed as a free string.
    let defs = &v["$defs"];
    let choices = |name: &str| -> Vec<String> {
        let def = &defs[name];
        let list: Vec<serde_json::Value> = match def.get("enum") {
            Some(e) => e.as_array().unwrap().clone(),
            None => def["oneOf"]
                .as_array()
                .unwrap_or_else(|| panic!("{name} is not an enumeration: {def}"))
                .iter()
                .map(|v| {
                    v.get("const")
                        .or(v.get("enum").and_then(|e| e.get(0)))
                        .cloned()
                        .unwrap()
                })
                .collect(),
        };
        list.iter()
            .map(|v| v.as_str().unwrap().to_string())
            .collect()
    };
    assert_eq!(
        choices("ShapeName"),
        [
            "point",
            "sphere",
            "plate",
            "trihedral",
            "dihedral",
            "cylinder",
            "box",
            "mesh",
            "vessel",
            "buoy"
        ]
    );
    assert_eq!(choices("WindowName"), ["none", "hamming", "taylor"]);
    assert_eq!(choices("Polarisation"), ["HH", "VV"]);
    assert_eq!(choices("SeaRoughness"), ["miller-brown-vegh", "ament"]);
    assert_eq!(choices("Sigma0Model"), ["nrl", "git"]);
    assert_eq!(
        choices("ClutterDistributionName"),
        ["k", "weibull", "lognormal", "rayleigh"]
    );
    assert_eq!(choices("Colormap"), ["viridis", "green", "gray"]);
    assert_eq!(choices("ScatteringModel"), ["po", "paper"]);
    assert_eq!(choices("MeshUnit"), ["m", "cm", "mm", "ft", "in"]);
    assert_eq!(
        choices("RadarPreset"),
        [
            "drs4d-nxt",
            "magnetron-4kw-radome",
            "magnetron-25kw-open-array",
            "s-band-30kw",
            "solid-state-open-array"
        ]
    );
    assert_eq!(choices("StcMode"), ["off", "manual", "auto"]);
    assert_eq!(
        choices("InterferenceRejection"),
        ["off", "low", "medium", "high"]
    );
    assert_eq!(choices("PulseLength"), ["short", "medium", "long"]);
}

#[test]
fn set_overrides_any_field_and_errors_name_the_line() {
    let dir = tempfile::tempdir().unwrap();
    let out = xbandsim()
        .args([
            "render",
            "scenes/paper.toml",
            "--set",
            "radar.spokes=90",
            "--set",
        ])
        .arg("object[4].yaw_deg=10")
        .args(["--set", "display.colormap=green", "--out"])
        .arg(dir.path())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let truth: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.path().join("truth.json")).unwrap()).unwrap();
    assert_eq!(truth["spokes"], 90);
    // A value in the file that the model refuses is named with its file, line and column.
    let scene = dir.path().join("bad.toml");
    std::fs::write(
        &scene,
        "[radar]\nmax_range_m = 1000.0\n\n[display]\nmin_db = 10.0\nmax_db = 5.0\n",
    )
    .unwrap();
    let out = xbandsim()
        .arg("render")
        .arg(&scene)
        .arg("--out")
        .arg(dir.path().join("o"))
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains(&format!(
            "{}:6:10: invalid `display.max_db` = 5",
            scene.display()
        )),
        "{err}"
    );
    let out = xbandsim()
        .args([
            "render",
            "scenes/paper.toml",
            "--set",
            "radar.pulse_widht_us=2",
            "--out",
        ])
        .arg(dir.path().join("o"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("unknown field `pulse_widht_us`"),
        "{err}"
    );
    assert!(!dir.path().join("o").exists());
}

#[test]
fn figures_are_drawn() {
    let dir = tempfile::tempdir().unwrap();
    let out = xbandsim()
        .args(["figures", "--out"])
        .arg(dir.path())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    for f in [
        "fig2_antenna_pattern.png",
        "fig3_signal_chain.png",
        "fig4_ppi_pulse_widths.png",
        "fig6_receiver_video.png",
        "target_rcs_by_class.png",
    ] {
        let bytes = std::fs::read(dir.path().join(f)).unwrap();
        assert!(bytes.starts_with(b"\x89PNG") && bytes.len() > 10_000, "{f}");
    }
}

#[test]
fn rcs_prints_json_and_plots() {
    let dir = tempfile::tempdir().unwrap();
    let plot = dir.path().join("rcs.png");
    let out = xbandsim()
        .args([
            "rcs",
            "scenes/paper.toml",
            "--object",
            "reflector-1",
            "--az-deg",
            "-10:10:5",
            "--json",
            "--plot",
        ])
        .arg(&plot)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let rows: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let rows = rows.as_array().unwrap();
    assert_eq!(rows.len(), 5);
    // Trihedral a = 0.5 m at 9.41 GHz: 4πa⁴/(3λ²) = 24.1 dBsm on its axis.
    let on_axis = rows[2]["rcs_dbsm"].as_f64().unwrap();
    assert!((on_axis - 24.1).abs() < 1.5, "{on_axis}");
    for key in ["az_deg", "el_deg", "rcs_m2", "rcs_dbsm"] {
        assert!(rows[0][key].is_number());
    }
    assert!(std::fs::read(&plot).unwrap().starts_with(b"\x89PNG"));
    let out = xbandsim()
        .args(["rcs", "scenes/paper.toml", "--object", "nope"])
        .output()
        .unwrap();
    assert!(!out.status.success() && String::from_utf8_lossy(&out.stderr).contains("reflector-1"));
}

#[test]
fn validate_passes_and_prints_a_table() {
    let out = xbandsim().args(["validate"]).output().unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        stdout.contains("expected") && stdout.contains("measured") && stdout.contains("tolerance")
    );
    assert!(stdout.contains("0 failed"));
}

/// Negative numbers reach the scene validation (which names the field), bad counts are
/// refused, and OS errors are printed once.
#[test]
fn command_line_values_get_real_messages() {
    let run = |args: &[&str]| {
        let o = xbandsim().args(args).output().unwrap();
        assert!(!o.status.success(), "{args:?} succeeded");
        String::from_utf8_lossy(&o.stderr).into_owned()
    };
    let e = run(&[
        "render",
        "scenes/paper.toml",
        "--out",
        "/tmp/xb-neg",
        "--max-range-m",
        "-5",
    ]);
    assert!(e.contains("radar.max_range_m") && e.contains("-5"), "{e}");
    let e = run(&[
        "rcs",
        "scenes/paper.toml",
        "--object",
        "dome",
        "--max-rays",
        "0",
    ]);
    assert!(e.contains("--max-rays 0"), "{e}");
    let e = run(&["bench", "--repeats", "0"]);
    assert!(e.contains("--repeats 0"), "{e}");
    let e = run(&["render", "no-such-scene.toml", "--out", "/tmp/xb-none"]);
    assert_eq!(e.matches("No such file").count(), 1, "{e}");
}

/// Every option of every command (as `--help` lists it) is documented in the README's
/// command table.
#[test]
fn readme_lists_every_option() {
    let readme =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../../README.md"))
            .unwrap();
    for cmd in [
        "render",
        "detect",
        "track",
        "figures",
        "rcs",
        "validate",
        "make-vessel",
        "schema",
        "bench",
        "dataset",
    ] {
        let help = xbandsim().args([cmd, "--help"]).output().unwrap();
        let text = String::from_utf8_lossy(&help.stdout);
        let row = readme
            .lines()
            .find(|l| l.starts_with(&format!("| `xbandsim {cmd}")))
            .unwrap_or_else(|| panic!("README has no row for `xbandsim {cmd}`"));
        for word in text.split_whitespace() {
            let flag = word.trim_matches(|c: char| !(c.is_ascii_alphanumeric() || c == '-'));
            if flag.starts_with("--") && flag.len() > 2 && flag != "--help" {
                assert!(
                    row.contains(flag),
                    "README's `xbandsim {cmd}` row lacks {flag}"
                );
            }
        }
    }
}

/// Messages a user meets with bad values: a negative or fractional count or seed says it
/// must be a whole number (no `-- -1` tip), a NaN range names the field as not finite (not a
/// type error), a cause is printed once, a speed beyond any craft is refused, and options
/// that take negative numbers take them.
#[test]
fn messages_for_bad_values() {
    let dir = tempfile::tempdir().unwrap();
    let run = |args: &[&str]| {
        let out = xbandsim().args(args).output().unwrap();
        (
            out.status.success(),
            String::from_utf8_lossy(&out.stderr).to_string(),
        )
    };
    let out = dir.path().join("x");
    let out = out.to_str().unwrap();
    for (args, wanted) in [
        (
            vec!["render", "scenes/paper.toml", "--seed", "-1", "--out", out],
            "\"-1\" must be a whole number of 0 or more",
        ),
        (
            vec![
                "dataset",
                "datasets/detection.toml",
                "--count",
                "2.5",
                "--out",
                out,
            ],
            "\"2.5\" must be a whole number of 0 or more",
        ),
        (
            vec![
                "render",
                "scenes/paper.toml",
                "--max-range-m",
                "nan",
                "--out",
                out,
            ],
            "error: the command line: invalid `radar.max_range_m` = NaN: must be a finite number",
        ),
        (
            vec![
                "render",
                "scenes/crossing.toml",
                "--set",
                "object[0].speed_kn=1e9",
                "--out",
                out,
            ],
            "error: the command line: invalid `object \"crossing-ship\".speed_kn` = 1000000000: must be at most 300 kn",
        ),
    ] {
        let (ok, stderr) = run(&args);
        assert!(!ok && stderr.contains(wanted), "{args:?}: {stderr}");
        assert!(
            !stderr.contains("-- -1") && !stderr.contains("invalid type"),
            "{args:?}: {stderr}"
        );
    }
    // A cause is printed once: the path's error is in the library's message already.
    let file = dir.path().join("a-file");
    std::fs::write(&file, b"").unwrap();
    let inside = file.join("sub");
    let inside = inside.to_str().unwrap();
    let (ok, stderr) = run(&[
        "dataset",
        "datasets/detection.toml",
        "--count",
        "1",
        "--out",
        inside,
    ]);
    assert!(!ok, "{stderr}");
    let error = stderr.lines().find(|l| l.starts_with("error:")).unwrap();
    assert_eq!(error.matches("(os error").count(), 1, "{error}");
    assert_eq!(error.matches(inside).count(), 1, "{error}");
    // render says so before rendering.
    let (ok, stderr) = run(&["render", "scenes/paper.toml", "--out", inside]);
    assert!(
        !ok && stderr.contains("is a file, not a folder"),
        "{stderr}"
    );
    // Negative values where an option takes them.
    let (ok, stderr) = run(&[
        "rcs",
        "scenes/paper.toml",
        "--object",
        "ship-plate",
        "--el-deg",
        "-5",
        "--az-deg",
        "-1:1:1",
        "--max-rays",
        "2000",
    ]);
    assert!(ok, "{stderr}");
}

/// `xbandsim detect` writes the plots of each revolution scored against the truth, with its
/// settings; bad detector settings are refused naming the field or the option, and nothing
/// is written.
#[test]
fn detect_writes_scored_plots_and_refuses_bad_settings() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("plots.json");
    let status = xbandsim()
        .args(["detect", "scenes/paper.toml", "--frames", "2", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        status.status.success(),
        "{}",
        String::from_utf8_lossy(&status.stderr)
    );
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    assert_eq!(v["settings"]["cfar"], "ca");
    assert_eq!(v["frames"].as_array().unwrap().len(), 2);
    let summary = &v["summary"];
    assert_eq!(summary["objects_in_view"], 10);
    assert_eq!(summary["objects_detected"], 10);
    // Pd per class and per quarter of the range: every object echo counted once in each.
    let in_view = |scores: Vec<&serde_json::Value>| {
        scores
            .iter()
            .map(|c| c["in_view"].as_u64().unwrap())
            .sum::<u64>()
    };
    let classes: Vec<_> = summary["per_class"].as_object().unwrap().values().collect();
    let bands: Vec<_> = summary["per_range"].as_array().unwrap().iter().collect();
    assert_eq!((in_view(classes), in_view(bands.clone())), (10, 10));
    assert_eq!(bands.len(), 4);
    assert!(summary["sea_state"].is_number() || summary["sea_state"].is_null());
    for frame in v["frames"].as_array().unwrap() {
        for plot in frame["plots"].as_array().unwrap() {
            let kind = plot["source"]["kind"].as_str().unwrap();
            assert!(
                ["object", "artefact", "land", "none"].contains(&kind),
                "{plot}"
            );
            assert!(plot["range_m"].as_f64().unwrap() > 0.0);
        }
    }
    for (args, wanted) in [
        (vec!["--cfar", "xx"], "invalid --cfar \"xx\""),
        (vec!["--pfa", "0.7"], "cfar.pfa"),
        (vec!["--training-cells", "0"], "cfar.training_cells"),
        (vec!["--cfar", "os", "--rank", "40"], "cfar.rank"),
        (vec!["--rank", "3"], "--rank is the ordered statistic's"),
        (vec!["--min-cells", "0"], "plots.min_cells"),
        (vec!["--scan", "3/2"], "plots.scan_hits"),
        (vec!["--scan", "two"], "invalid --scan \"two\""),
        (vec!["--input", "video"], "needs a [receiver] table"),
        (vec!["--input", "ppi"], "invalid --input \"ppi\""),
    ] {
        assert_refused_writing_nothing("detect", &args, wanted);
    }
}

/// `xbandsim track` follows the crossing scene's vessels: after 16 scans the crossing ship's
/// track has its course within 5° and its speed within 1.5 kn of the truth, the moored buoy's
/// track stands still; bad tracker settings are refused naming the field.
#[test]
fn track_follows_vessels_and_refuses_bad_settings() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("tracks.json");
    let picture = dir.path().join("tracked.png");
    let status = xbandsim()
        .args(["track", "scenes/crossing.toml", "--frames", "40", "--out"])
        .arg(&out)
        .arg("--ppi")
        .arg(&picture)
        .output()
        .unwrap();
    assert!(
        status.status.success(),
        "{}",
        String::from_utf8_lossy(&status.stderr)
    );
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    let last = &v["scans"].as_array().unwrap()[39];
    let track_of = |name: &str| {
        last["tracks"]
            .as_array()
            .unwrap()
            .iter()
            .find(|t| t["truth"]["name"] == name)
            .unwrap_or_else(|| panic!("no track on {name}: {last}"))
            .clone()
    };
    let ship = track_of("crossing-ship");
    assert!(
        ship["truth"]["course_error_deg"].as_f64().unwrap().abs() < 5.0,
        "{ship}"
    );
    assert!(
        ship["truth"]["speed_error_kn"].as_f64().unwrap().abs() < 1.5,
        "{ship}"
    );
    assert!(ship["tcpa_s"].is_number() && ship["cpa_m"].is_number());
    let buoy = track_of("buoy");
    assert!(buoy["speed_kn"].as_f64().unwrap() < 1.0, "{buoy}");
    // The IMO table's 1-minute row (MSC.192(79) §5.25.4.7.1) is met on the steady targets.
    let one_minute = &v["summary"]["accuracy"][0];
    for figure in ["relative_course_deg", "relative_speed_kn", "cpa_m"] {
        assert!(
            one_minute[figure]["samples"].as_u64().unwrap() >= 20
                && one_minute[figure]["meets_standard"] == true,
            "{figure}: {one_minute}"
        );
    }
    // The tracked PPI: the scene's 1024-pixel image, its tracks drawn in yellow.
    let png = std::fs::read(&picture).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    assert_eq!(u32::from_be_bytes(png[16..20].try_into().unwrap()), 1024);
    // Every plot the tracker saw, as it measured it (what a peer tracker is fed).
    assert_eq!(
        last["measurements"].as_array().unwrap().len() as u64,
        last["plots"].as_u64().unwrap()
    );
    for (args, wanted) in [
        (vec!["--initiation", "5/4"], "tracker.initiation_hits"),
        (vec!["--initiation", "x"], "invalid --initiation \"x\""),
        (vec!["--gate", "-1"], "tracker.gate"),
        (
            vec!["--sigma-bearing-deg", "0"],
            "tracker.sigma_bearing_deg",
        ),
        (vec!["--lost-after", "0"], "tracker.lost_after_misses"),
        (vec!["--truth-gate-m", "nan"], "invalid --truth-gate-m"),
        (vec!["--pfa", "2"], "cfar.pfa"),
        (
            vec!["--false-track-probability", "1"],
            "tracker.false_track_probability",
        ),
        (
            vec!["--false-track-probability", "0.99"],
            "tracker.false_track_probability",
        ),
        (
            vec!["--detection-probability", "0"],
            "tracker.detection_probability",
        ),
        (
            vec!["--ppi", "/nonexistent-folder/tracked.png"],
            "invalid --ppi /nonexistent-folder/tracked.png",
        ),
        (
            vec!["--sidelobe-margin-db", "-3"],
            "invalid --sidelobe-margin-db \"-3\"",
        ),
    ] {
        assert_refused_writing_nothing("track", &args, wanted);
    }
}

/// `xbandsim CMD scenes/paper.toml ARGS --out FILE` fails saying `wanted` and writes nothing.
fn assert_refused_writing_nothing(cmd: &str, args: &[&str], wanted: &str) {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.json");
    let o = xbandsim()
        .args([cmd, "scenes/paper.toml"])
        .args(args)
        .arg("--out")
        .arg(&bad)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        !o.status.success() && stderr.contains(wanted),
        "{cmd} {args:?}: {stderr}"
    );
    assert!(!bad.exists(), "{cmd} {args:?} wrote {}", bad.display());
}

/// The dataset baseline is `xbandsim track` with its defaults (docs/tracking.md, "Dataset
/// baseline"): a tracking-spec sample's scene, tracked with the frames and render seed its
/// scene.toml names, gives baseline.json's confirmed tracks, position for position, and the
/// same scores.
#[test]
fn a_samples_baseline_is_what_track_gives_on_its_scene() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("data");
    let out = xbandsim()
        .args([
            "dataset",
            "datasets/tracking.toml",
            "--count",
            "2",
            "--seed",
            "5",
        ])
        .arg("--out")
        .arg(&data)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let mut compared = 0;
    for i in 0..2u64 {
        let sample = data.join(format!("samples/000000/{i:09}"));
        let scene = std::fs::read_to_string(sample.join("scene.toml")).unwrap();
        // "#   xbandsim render scene.toml --seed S --frames F"
        let words: Vec<&str> = scene.lines().nth(1).unwrap().split_whitespace().collect();
        let after = |flag: &str| words[words.iter().position(|w| *w == flag).unwrap() + 1];
        let tracks_json = dir.path().join(format!("tracks-{i}.json"));
        let out = xbandsim()
            .arg("track")
            .arg(sample.join("scene.toml"))
            .args(["--seed", after("--seed"), "--frames", after("--frames")])
            .arg("--out")
            .arg(&tracks_json)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let tracked: serde_json::Value =
            serde_json::from_slice(&std::fs::read(&tracks_json).unwrap()).unwrap();
        let baseline: serde_json::Value =
            serde_json::from_slice(&std::fs::read(sample.join("baseline.json")).unwrap()).unwrap();
        let scans = tracked["scans"].as_array().unwrap();
        let frames = baseline["frames"].as_array().unwrap();
        assert_eq!(scans.len(), frames.len());
        for (scan, frame) in scans.iter().zip(frames) {
            assert_eq!(scan["plots"], frame["plots"]);
            let ours: Vec<(u64, String)> = frame["tracks"]
                .as_array()
                .unwrap()
                .iter()
                .map(|t| (t["id"].as_u64().unwrap(), t["position_m"].to_string()))
                .collect();
            let theirs: Vec<(u64, String)> = scan["tracks"]
                .as_array()
                .unwrap()
                .iter()
                .map(|t| (t["id"].as_u64().unwrap(), t["position_m"].to_string()))
                .collect();
            assert_eq!(ours, theirs, "sample {i} frame {}", frame["frame"]);
            compared += ours.len();
        }
        assert_eq!(
            tracked["summary"]["scores"]["figures"],
            baseline["tracking"]["figures"]
        );
    }
    assert!(compared > 0, "no confirmed track to compare");
}

/// `xbandsim nmea` writes the crossing scene's own-ship and AIS sentences, each with a good
/// checksum, and refuses bad input naming the field: a scene without `[geo]`, an MMSI out of
/// range or given twice, `ais_class` without `mmsi`, a bad start time or duration.
#[test]
fn nmea_writes_checked_sentences_and_refuses_bad_input() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("c.nmea");
    let out = xbandsim()
        .args([
            "nmea",
            "scenes/crossing.toml",
            "--duration-s",
            "30",
            "--out",
        ])
        .arg(&log)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(&log).unwrap();
    let lines: Vec<&str> = text.split_terminator("\r\n").collect();
    // 31 fixes of 4 sentences; class A static (2 fragments) and reports every 10 s or less.
    assert_eq!(lines.iter().filter(|l| l.starts_with("$GPGGA")).count(), 31);
    assert!(lines.iter().filter(|l| l.starts_with("!AIVDM")).count() >= 12);
    for line in &lines {
        let (body, sum) = line[1..].split_once('*').unwrap();
        let x = body.bytes().fold(0u8, |c, b| c ^ b);
        assert_eq!(format!("{x:02X}"), sum, "{line}");
    }
    for (args, field) in [
        (vec!["--set", "geo.origin_lat_deg=95"], "geo.origin_lat_deg"),
        (vec!["--set", "object[0].mmsi=1000000000"], "mmsi"),
        (vec!["--set", "object[1].mmsi=235000001"], "mmsi"),
        (vec!["--set", "object[3].ais_class=\"B\""], "ais_class"),
        (vec!["--start-utc", "2026-01-01 00:00"], "--start-utc"),
        (vec!["--duration-s", "0"], "--duration-s"),
    ] {
        let out = xbandsim()
            .args(["nmea", "scenes/crossing.toml", "--out"])
            .arg(dir.path().join("bad.nmea"))
            .args(&args)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            !out.status.success() && err.contains(field),
            "{args:?}: {err}"
        );
    }
    let out = xbandsim()
        .args(["nmea", "scenes/paper.toml", "--out"])
        .arg(dir.path().join("bad.nmea"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && err.contains("[geo]"), "{err}");
    assert!(!dir.path().join("bad.nmea").exists());
}

/// `xbandsim serve` and `replay` refuse bad input naming the option or field, before they
/// listen: a speed out of range, an NMEA feed for a scene without `[geo]`, a duration that
/// is not positive, a start time that is not one, an address already taken; and a file that
/// is not a recording.
#[test]
fn serve_and_replay_refuse_bad_input() {
    let dir = tempfile::tempdir().unwrap();
    let taken = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let taken_addr = taken.local_addr().unwrap().to_string();
    for (args, says) in [
        (vec!["scenes/crossing.toml", "--speed", "0"], "speed 0"),
        (
            vec!["scenes/crossing.toml", "--speed", "1000"],
            "speed 1000",
        ),
        (
            vec!["scenes/paper.toml", "--nmea-udp", "127.0.0.1:10110"],
            "[geo]",
        ),
        (
            vec!["scenes/crossing.toml", "--duration-s", "-1"],
            "--duration-s",
        ),
        (
            vec!["scenes/crossing.toml", "--start-utc", "noon"],
            "--start-utc",
        ),
        (
            vec!["scenes/crossing.toml", "--listen", taken_addr.as_str()],
            "--listen",
        ),
        (
            vec!["scenes/crossing.toml", "--set", "receiver.video_bits=9"],
            "video_bits",
        ),
    ] {
        let out = xbandsim()
            .arg("serve")
            .args(&args)
            .args(
                ["--duration-s", "1"]
                    .iter()
                    .filter(|_| !args.contains(&"--duration-s")),
            )
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            !out.status.success() && err.contains(says),
            "{args:?}: {err}"
        );
    }
    let not_one = dir.path().join("not.xbsrec");
    std::fs::write(&not_one, b"hello").unwrap();
    let out = xbandsim().arg("replay").arg(&not_one).output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && err.contains("not an xbandsim recording"),
        "{err}"
    );
}
