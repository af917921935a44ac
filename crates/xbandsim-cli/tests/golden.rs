//! Golden hashes: every output of the example scenes, byte for byte.
//!
//! The restructuring of docs/architecture.md had to leave behaviour untouched, so the SHA-256 of
//! each output below was recorded once (`tests/golden/hashes.txt`) and is checked on every test
//! run: the polar data, both PPI images and truth.json of every example scene (three
//! revolutions of the moving scenes/crossing.toml), the JSON of
//! `xbandsim rcs` for plates, corners, spheres and the mesh vessel, and the figures of
//! `xbandsim validate --json`. A change of physics on purpose updates the file (run this test
//! with `XBANDSIM_BLESS_GOLDEN=1` and commit the new hashes with the reason); anything else that
//! changes a hash is a bug.
//!
//! Bit-identical results hold for the same instruction set: RustFFT picks AVX/FMA kernels at run
//! time, whose rounding differs from its SSE and scalar kernels. The hashes were recorded on
//! x86_64 with AVX2 and FMA; on another platform the test says so and checks nothing (the
//! determinism tests in the library suite still check thread-count and run-to-run identity).

use sha2::{Digest, Sha256};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

const HASH_FILE: &str = "tests/golden/hashes.txt";

fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn run(args: &[&str]) -> Vec<u8> {
    let out = Command::new(env!("CARGO_BIN_EXE_xbandsim"))
        .current_dir(repo_root())
        .args(args)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "xbandsim {}: {}",
        args.join(" "),
        String::from_utf8_lossy(&out.stderr)
    );
    out.stdout
}

fn sha256(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// The platform the hashes hold for (see the module doc).
fn platform() -> &'static str {
    #[cfg(target_arch = "x86_64")]
    {
        if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
        {
            return "x86_64-avx2-fma";
        }
        "x86_64-other"
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        "other"
    }
}

/// Renders, RCS sweeps and validation figures, each output named `case/file`.
fn outputs() -> BTreeMap<String, String> {
    let mut hashes = BTreeMap::new();
    let renders: [(&str, &str, &[&str]); 6] = [
        ("paper", "scenes/paper.toml", &[]),
        ("paper-seed-7", "scenes/paper.toml", &["--seed", "7"]),
        (
            "paper-model",
            "scenes/paper.toml",
            &["--model", "paper", "--seed", "1"],
        ),
        ("harbour-calm", "scenes/harbour-calm.toml", &[]),
        ("sea-state-4-rain", "scenes/sea-state-4-rain.toml", &[]),
        ("vessel", "scenes/vessel.toml", &[]),
    ];
    let dir = tempfile::tempdir().unwrap();
    for (case, scene, extra) in renders {
        let out = dir.path().join(case);
        let mut args = vec!["render", scene, "--out", out.to_str().unwrap()];
        args.extend_from_slice(extra);
        run(&args);
        for file in ["polar.npy", "ppi.png", "ppi_gray.png", "truth.json"] {
            let bytes = std::fs::read(out.join(file)).unwrap();
            hashes.insert(format!("render-{case}/{file}"), sha256(&bytes));
        }
        // The land's files, in the scenes with land.
        for file in ["land_mask.npy", "land_polygon.npy"] {
            if let Ok(bytes) = std::fs::read(out.join(file)) {
                hashes.insert(format!("render-{case}/{file}"), sha256(&bytes));
            }
        }
    }
    // Three revolutions of the moving scene, every frame's files.
    let out = dir.path().join("crossing");
    run(&[
        "render",
        "scenes/crossing.toml",
        "--frames",
        "3",
        "--out",
        out.to_str().unwrap(),
    ]);
    for k in 0..3 {
        for file in ["polar.npy", "ppi.png", "ppi_gray.png", "truth.json"] {
            let bytes = std::fs::read(out.join(format!("frame_{k:04}")).join(file)).unwrap();
            hashes.insert(
                format!("render-crossing-frames/frame_{k:04}/{file}"),
                sha256(&bytes),
            );
        }
    }
    let sweeps: [(&str, &str, &str, &str); 5] = [
        ("reflector-1", "scenes/paper.toml", "-45:45:5", "0"),
        ("ship-plate", "scenes/paper.toml", "-30:30:2", "0"),
        ("dome", "scenes/paper.toml", "0:90:45", "10"),
        ("buoy", "scenes/paper.toml", "0:90:30", "0"),
        ("vessel", "scenes/vessel.toml", "0:330:30", "0"),
    ];
    for (object, scene, az, el) in sweeps {
        let json = run(&[
            "rcs", scene, "--object", object, "--az-deg", az, "--el-deg", el, "--json",
        ]);
        hashes.insert(format!("rcs-{object}/stdout.json"), sha256(&json));
    }
    let validate = run(&["validate", "--json"]);
    hashes.insert("validate/stdout.json".into(), sha256(&validate));
    hashes
}

fn read_golden(path: &Path) -> (String, BTreeMap<String, String>) {
    let text = std::fs::read_to_string(path).unwrap_or_default();
    let mut platform = String::new();
    let mut map = BTreeMap::new();
    for line in text
        .lines()
        .filter(|l| !l.starts_with('#') && !l.is_empty())
    {
        let mut words = line.split_whitespace();
        match (words.next(), words.next()) {
            (Some("platform"), Some(p)) => platform = p.to_string(),
            (Some(name), Some(hash)) => {
                map.insert(name.to_string(), hash.to_string());
            }
            _ => panic!("{}: malformed line {line:?}", path.display()),
        }
    }
    (platform, map)
}

#[test]
fn example_scene_outputs_match_the_golden_hashes() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(HASH_FILE);
    let (recorded_platform, golden) = read_golden(&path);
    if std::env::var_os("XBANDSIM_BLESS_GOLDEN").is_some() {
        let mut text = String::from(
            "# SHA-256 of the example scenes' outputs; see tests/golden.rs. Regenerate only when\n\
             # physics changes on purpose: XBANDSIM_BLESS_GOLDEN=1 cargo test -p xbandsim-cli --test golden\n",
        );
        text.push_str(&format!("platform {}\n", platform()));
        for (name, hash) in outputs() {
            text.push_str(&format!("{name} {hash}\n"));
        }
        std::fs::write(&path, text).unwrap();
        return;
    }
    if recorded_platform != platform() {
        eprintln!(
            "golden hashes were recorded on {recorded_platform}, this is {}: not compared",
            platform()
        );
        return;
    }
    assert!(!golden.is_empty(), "{} holds no hashes", path.display());
    let now = outputs();
    let mut differ = Vec::new();
    for (name, hash) in &golden {
        match now.get(name) {
            Some(h) if h == hash => {}
            Some(h) => differ.push(format!("{name}: {h} (golden {hash})")),
            None => differ.push(format!("{name}: no longer produced")),
        }
    }
    for name in now.keys().filter(|n| !golden.contains_key(*n)) {
        differ.push(format!("{name}: not in the golden file"));
    }
    assert!(
        differ.is_empty(),
        "outputs differ from the golden hashes:\n{}",
        differ.join("\n")
    );
}
