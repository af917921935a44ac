//! The dataset generator through its public API: samples depend only on (spec, seed, index)
//! — the same bytes for any job count, shard split or order, and after a resume —; a sample's
//! scene.toml re-renders it bit for bit; bad specs are refused naming the field.

mod common;

use std::collections::BTreeMap;
use std::path::Path;
use xbandsim_dataset::{generate, sample_dir, DatasetError, DatasetSpec, Format, Request, Shard};

const SPEC: &str = r#"
[dataset]
frames = 1

[scene.radar]
spokes = 60
max_range_m = 400.0
position_m = [0.0, 0.0, 6.0]

[scene.environment]
clutter = true

[scene.display]
image_size_px = 96

[vary]
"environment.sea_state" = { uniform = [1.0, 4.0] }
"radar.position_m[2]" = { uniform = [4.0, 10.0] }

[targets]
count = { uniform_int = [0, 3] }

[[targets.class]]
name = "buoy"
[targets.class.object]
shape = "cylinder"
radius_m = { uniform = [0.3, 1.0] }
height_m = 2.0

[[targets.class]]
name = "boat"
speed_kn = { uniform = [0.0, 20.0] }
[targets.class.object]
shape = "box"
size_m = [2.0, 6.0, 1.5]
"#;

fn spec() -> DatasetSpec {
    DatasetSpec::parse(SPEC, Path::new(".")).unwrap()
}

/// Every file under `dir` (relative path → bytes), leaving out nothing.
fn files(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else {
                let rel = p.strip_prefix(dir).unwrap().display().to_string();
                out.insert(rel, std::fs::read(&p).unwrap());
            }
        }
    }
    out
}

fn request(count: u64, seed: u64, shard: Shard, jobs: usize) -> Request {
    Request {
        count,
        seed,
        shard,
        jobs,
        format: Format::Dir,
        assemble: true,
    }
}

#[test]
fn samples_do_not_depend_on_jobs_shards_or_resumes() {
    let spec = spec();
    let tmp = tempfile::tempdir().unwrap();
    let whole = tmp.path().join("whole");
    let s = generate(&spec, &whole, &request(6, 11, Shard::ALL, 1), &|| {}).unwrap();
    assert_eq!((s.in_shard, s.skipped, s.made), (6, 0, 6));
    // Two shards made separately, with two jobs, into one folder.
    let sharded = tmp.path().join("sharded");
    for i in [1, 0] {
        let shard = Shard { index: i, count: 2 };
        let s = generate(&spec, &sharded, &request(6, 11, shard, 2), &|| {}).unwrap();
        assert_eq!((s.in_shard, s.made), (3, 3));
    }
    assert_eq!(files(&whole), files(&sharded));
    // A run stopped part-way: one shard done, a half-written sample left in .partial; the
    // same command again skips the finished samples and makes the rest.
    let resumed = tmp.path().join("resumed");
    generate(
        &spec,
        &resumed,
        &request(6, 11, Shard { index: 0, count: 3 }, 1),
        &|| {},
    )
    .unwrap();
    let stale = resumed.join(".partial").join(format!("{:09}", 4));
    std::fs::create_dir_all(&stale).unwrap();
    std::fs::write(stale.join("polar.npy"), b"half").unwrap();
    let s = generate(&spec, &resumed, &request(6, 11, Shard::ALL, 2), &|| {}).unwrap();
    assert_eq!((s.skipped, s.made), (2, 4));
    let mut got = files(&resumed);
    got.retain(|k, _| !k.starts_with(".partial"));
    assert_eq!(files(&whole), got);
    // Another seed gives other samples, and is refused in the same folder.
    let other = tmp.path().join("other");
    generate(&spec, &other, &request(6, 12, Shard::ALL, 1), &|| {}).unwrap();
    assert_ne!(files(&whole), files(&other));
    let err = generate(&spec, &whole, &request(6, 12, Shard::ALL, 1), &|| {}).unwrap_err();
    assert!(matches!(err, DatasetError::Mismatch { .. }), "{err}");
}

/// Shard runs with `assemble` off write their samples only; one run with it on afterwards
/// writes the index files, and the folder is byte for byte one run's. Runs assembling at the
/// same moment (shard runs finishing together) leave the same bytes too.
#[test]
fn index_files_left_to_one_run_or_written_by_several_at_once() {
    let spec = spec();
    let tmp = tempfile::tempdir().unwrap();
    let whole = tmp.path().join("whole");
    generate(&spec, &whole, &request(6, 11, Shard::ALL, 2), &|| {}).unwrap();
    let split = tmp.path().join("split");
    for i in 0..3 {
        let r = Request {
            assemble: false,
            ..request(6, 11, Shard { index: i, count: 3 }, 1)
        };
        let s = generate(&spec, &split, &r, &|| {}).unwrap();
        assert_eq!((s.made, s.missing), (2, 0));
        assert!(s.assembled.is_none());
        assert!(!split.join("annotations.json").exists() && !split.join("README.md").exists());
    }
    let s = generate(&spec, &split, &request(6, 11, Shard::ALL, 1), &|| {}).unwrap();
    assert_eq!((s.made, s.skipped), (0, 6));
    assert!(s.assembled.is_some());
    assert_eq!(files(&whole), files(&split));
    // Four assemblies at once, three times over (README.md removed so that each assembles).
    for _ in 0..3 {
        std::fs::remove_file(split.join("README.md")).unwrap();
        std::thread::scope(|scope| {
            for _ in 0..4 {
                scope.spawn(|| {
                    generate(&spec, &split, &request(6, 11, Shard::ALL, 1), &|| {}).unwrap()
                });
            }
        });
        assert_eq!(files(&whole), files(&split));
    }
}

/// A sample's scene.toml, rendered with the seed it names, gives the sample's polar record
/// byte for byte; its targets carry their class.
#[test]
fn a_sample_re_renders_from_its_scene_file() {
    let spec = spec();
    let tmp = tempfile::tempdir().unwrap();
    generate(&spec, tmp.path(), &request(4, 5, Shard::ALL, 1), &|| {}).unwrap();
    let mut with_targets = 0;
    for i in 0..4 {
        let dir = sample_dir(tmp.path(), i);
        let (seed, loaded) = common::sample_scene(&dir);
        let frame = xbandsim::Simulation::new(loaded.build().unwrap()).render(seed);
        let npy = xbandsim::products::output::npy_f32_bytes(
            &[frame.spokes, frame.range_bins],
            &frame.polar_db,
        );
        assert_eq!(
            npy,
            std::fs::read(dir.join("polar.npy")).unwrap(),
            "sample {i}"
        );
        let truth: serde_json::Value =
            serde_json::from_slice(&std::fs::read(dir.join("truth.json")).unwrap()).unwrap();
        for o in truth["objects"].as_array().unwrap() {
            with_targets += 1;
            assert!(["buoy", "boat"].contains(&o["class"].as_str().unwrap()));
        }
    }
    assert!(with_targets > 0);
}

/// Library classes (docs/targets.md): a sample's targets are the library's objects at drawn
/// sizes, labelled with the library's names; an unknown class or a size outside the class's
/// range is refused naming the field.
#[test]
fn library_classes_fill_samples() {
    let text = SPEC.replace(
        "[[targets.class]]\nname = \"buoy\"",
        "[[targets.class]]\nlibrary = \"rib\"\n\n[[targets.class]]\nlibrary = \"navigation_buoy\"\n\n[[targets.class]]\nname = \"buoy\"",
    );
    let spec = DatasetSpec::parse(&text, Path::new(".")).unwrap();
    let mut seen = std::collections::BTreeSet::new();
    for i in 0..40 {
        let s = spec.sample(3, i).unwrap();
        let scene: toml::Table = toml::from_str(&s.scene_toml).unwrap();
        for o in scene
            .get("object")
            .and_then(|o| o.as_array())
            .into_iter()
            .flatten()
        {
            let class = o["class"].as_str().unwrap().to_string();
            if class == "rib" {
                assert_eq!(o["shape"].as_str(), Some("vessel"));
                let l = o["length_m"].as_float().unwrap();
                let (lo, hi) = xbandsim::targets::TargetClass::Rib.size_range_m();
                assert!((lo..=hi).contains(&l), "{l}");
            }
            seen.insert(class);
        }
    }
    assert!(
        seen.contains("rib") && seen.contains("navigation_buoy"),
        "{seen:?}"
    );
    for (bad, field) in [
        ("library = \"rib\"", "library = \"submarine\""),
        (
            "library = \"rib\"",
            "library = \"rib\"\nsize_m = { uniform = [1.0, 900.0] }",
        ),
    ]
    .iter()
    .zip(["targets.class[0].library", "targets.class[0].size_m"])
    .map(|((from, to), field)| (text.replace(from, to), field))
    {
        let err = DatasetSpec::parse(&bad, Path::new("."))
            .unwrap_err()
            .to_string();
        assert!(err.contains(field), "{field}: {err}");
    }
}

#[test]
fn bad_specs_name_the_field() {
    let cases = [
        (SPEC.replace("frames = 1", "frames = 0"), "dataset.frames"),
        (
            SPEC.replace("[dataset]", "[dataset]\nimages = 3"),
            "dataset.images",
        ),
        (
            SPEC.replace(
                "radius_m = { uniform = [0.3, 1.0] }",
                "radius_m = { uniform = [-0.3, 1.0] }",
            ),
            "targets.class[0].object.radius_m",
        ),
        (
            SPEC.replace(
                "count = { uniform_int = [0, 3] }",
                "count = { choice = [] }",
            ),
            "targets.count.choice",
        ),
        (
            SPEC.replace(
                "count = { uniform_int = [0, 3] }",
                "count = { uniform_int = [-1, 3] }",
            ),
            "targets.count",
        ),
        (
            SPEC.replace(
                "speed_kn = { uniform = [0.0, 20.0] }",
                "speed_kn = { uniform = [-5.0, 20.0] }",
            ),
            "targets.class[1].speed_kn",
        ),
        (
            SPEC.replace(
                "\"environment.sea_state\" = { uniform = [1.0, 4.0] }",
                "\"environment.sea_state\" = { uniform = [1.0, 40.0] }",
            ),
            "vary.\"environment.sea_state\"",
        ),
        (
            SPEC.replace("shape = \"cylinder\"\n", ""),
            "targets.class[0].object.shape",
        ),
        (
            SPEC.replace("name = \"buoy\"\n", ""),
            "targets.class[0].name",
        ),
        (
            SPEC.replace(
                "height_m = 2.0",
                "height_m = 2.0\nposition_m = [1.0, 2.0, 3.0]",
            ),
            "targets.class[0].object.position_m",
        ),
    ];
    for (text, field) in cases {
        let err = DatasetSpec::parse(&text, Path::new("."))
            .unwrap_err()
            .to_string();
        assert!(err.contains(field), "{field}: {err}");
    }
    let tmp = tempfile::tempdir().unwrap();
    let err = generate(&spec(), tmp.path(), &request(0, 1, Shard::ALL, 1), &|| {})
        .unwrap_err()
        .to_string();
    assert!(err.contains("--count"), "{err}");
    // A shard of no samples is refused before anything is written.
    let mut zero = request(4, 1, Shard::ALL, 1);
    zero.format = Format::WebDataset {
        samples_per_shard: 0,
    };
    let err = generate(&spec(), &tmp.path().join("z"), &zero, &|| {})
        .unwrap_err()
        .to_string();
    assert!(err.contains("--shard-samples"), "{err}");
    assert!(!tmp.path().join("z").exists());
    // Bad image and threshold settings name their field.
    for (text, field) in [
        (
            SPEC.replace("frames = 1", "frames = 1\nimage = \"sepia\""),
            "dataset.image",
        ),
        (
            SPEC.replace("frames = 1", "frames = 1\nval_every = -1"),
            "dataset.val_every",
        ),
        (
            SPEC.replace("frames = 1", "frames = 1\nmask_threshold_db = \"high\""),
            "dataset.mask_threshold_db",
        ),
    ] {
        let err = DatasetSpec::parse(&text, Path::new("."))
            .unwrap_err()
            .to_string();
        assert!(err.contains(field), "{field}: {err}");
    }
    for bad in ["2/2", "1", "a/b", "0/0"] {
        // An argument of the run, not a field of the spec: named as the option it is.
        let err = Shard::parse(bad).unwrap_err().to_string();
        assert!(err.starts_with(&format!("--shard: {bad}: ")), "{err}");
    }
}

#[test]
fn shard_index_from_a_kubernetes_indexed_job_or_a_slurm_array() {
    let env = |vars: &'static [(&'static str, &'static str)]| {
        move |name: &str| {
            vars.iter()
                .find(|(k, _)| *k == name)
                .map(|(_, v)| v.to_string())
        }
    };
    let k8s = env(&[("JOB_COMPLETION_INDEX", "3")]);
    assert_eq!(
        Shard::resolve("k8s/8", &k8s).unwrap(),
        Shard { index: 3, count: 8 }
    );
    // Plain I/K ignores the environment.
    assert_eq!(
        Shard::resolve("1/4", &k8s).unwrap(),
        Shard { index: 1, count: 4 }
    );
    // The task id as it is: a resubmission of tasks 3 and 7 alone (MIN = 3) makes shards 3, 7.
    let slurm = env(&[("SLURM_ARRAY_TASK_ID", "7"), ("SLURM_ARRAY_TASK_MIN", "3")]);
    assert_eq!(
        Shard::resolve("slurm/16", &slurm).unwrap(),
        Shard {
            index: 7,
            count: 16
        }
    );
    for (text, vars, says) in [
        ("k8s/8", &[][..], "JOB_COMPLETION_INDEX is not set"),
        (
            "k8s/8",
            &[("JOB_COMPLETION_INDEX", "x")][..],
            "not a whole number",
        ),
        (
            "k8s/2",
            &[("JOB_COMPLETION_INDEX", "2")][..],
            "not below the shard count 2 (number the tasks 0 … 1)",
        ),
        ("slurm/4", &[][..], "SLURM_ARRAY_TASK_ID is not set"),
        (
            "k8s/x",
            &[("JOB_COMPLETION_INDEX", "3")][..],
            "the shard count \"x\" must be a whole number above 0",
        ),
        (
            "slurm/0",
            &[("SLURM_ARRAY_TASK_ID", "0")][..],
            "must be a whole number above 0",
        ),
    ] {
        let lookup = |name: &str| {
            vars.iter()
                .find(|(k, _)| *k == name)
                .map(|(_, v)| v.to_string())
        };
        let err = Shard::resolve(text, &lookup).unwrap_err().to_string();
        assert!(
            err.contains("--shard") && err.contains(says),
            "{text}: {err}"
        );
    }
}

/// Temporaries are removed by ownership, not age: a run removes at once (however fresh) what
/// runs that are gone left — their lock file under `.owners/` can be locked — and leaves a
/// live run's alone (its lock is held, here by this test), in `.partial/`, `shards/` and the
/// root. A finished dataset run again cleans up too.
#[test]
fn a_run_removes_what_dead_runs_left_and_keeps_a_live_runs() {
    let spec = spec();
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("ds");
    generate(&spec, &out, &request(2, 3, Shard::ALL, 1), &|| {}).unwrap();
    assert!(
        !out.join(".owners").exists(),
        "the finished run's lock stays"
    );
    let before = files(&out);
    let owners = out.join(".owners");
    std::fs::create_dir_all(&owners).unwrap();
    // Tags are <host>-<pid>-<nanos>: a dead and a live run of this host, and an unlocked
    // lock file of another host (its run may be alive where locks do not reach across
    // machines: its files go by age only).
    let own = xbandsim::products::output::temp_tag();
    let host = own.rsplitn(3, '-').nth(2).unwrap().to_string();
    let dead = format!("{host}-41-0000abcd");
    let live = format!("{host}-42-0000beef");
    let (dead, live) = (dead.as_str(), live.as_str());
    let (remote, remote_old) = ("otherhost-43-0000cafe", "otherhost-44-0000f00d");
    for tag in [dead, remote, remote_old] {
        std::fs::write(owners.join(format!("{tag}.lock")), b"").unwrap();
    }
    let live_lock = std::fs::OpenOptions::new()
        .create(true)
        .truncate(false)
        .write(true)
        .open(owners.join(format!("{live}.lock")))
        .unwrap();
    live_lock.try_lock().unwrap();
    let temporaries = |tag: &str| {
        [
            out.join(".partial").join(format!("000000001-{tag}-0")),
            out.join("shards")
                .join(format!("shard-000000.tar.partial-{tag}-1")),
            out.join(format!("annotations.partial-{tag}-2")),
            out.join(format!(".yolo.partial-{tag}-3")),
        ]
    };
    let eleven_minutes_ago = std::time::SystemTime::now() - std::time::Duration::from_secs(660);
    for tag in [dead, live, remote, remote_old] {
        for (k, t) in temporaries(tag).iter().enumerate() {
            std::fs::create_dir_all(t.parent().unwrap()).unwrap();
            let file = if k % 2 == 0 {
                std::fs::create_dir_all(t).unwrap();
                t.join("polar.npy")
            } else {
                t.clone()
            };
            std::fs::write(&file, b"half").unwrap();
            if tag == remote_old {
                for p in [&file, t] {
                    let f = std::fs::File::options()
                        .write(p.is_file())
                        .read(true)
                        .open(p)
                        .unwrap();
                    f.set_modified(eleven_minutes_ago).unwrap();
                }
            }
        }
    }
    let s = generate(&spec, &out, &request(2, 3, Shard::ALL, 1), &|| {}).unwrap();
    assert_eq!((s.skipped, s.made), (2, 0));
    for t in temporaries(dead) {
        assert!(!t.exists(), "{} of a dead run stays", t.display());
    }
    for t in temporaries(live).iter().chain(&temporaries(remote)) {
        assert!(t.exists(), "{} of a live run was removed", t.display());
    }
    for t in temporaries(remote_old) {
        assert!(
            !t.exists(),
            "{} untouched for 11 minutes stays",
            t.display()
        );
    }
    assert!(!owners.join(format!("{dead}.lock")).exists());
    assert!(owners.join(format!("{live}.lock")).exists());
    for t in temporaries(remote) {
        let _ = std::fs::remove_dir_all(&t);
        let _ = std::fs::remove_file(&t);
    }
    let _ = std::fs::remove_file(owners.join(format!("{remote}.lock")));
    let _ = std::fs::remove_file(owners.join(format!("{remote_old}.lock")));
    // The live run ends (its lock goes with its process; here the file is unlocked): the
    // next run removes the rest, and the folder is the finished dataset again.
    drop(live_lock);
    generate(&spec, &out, &request(2, 3, Shard::ALL, 1), &|| {}).unwrap();
    for t in temporaries(live) {
        assert!(!t.exists(), "{} stays after its run ended", t.display());
    }
    let _ = std::fs::remove_dir(out.join("shards"));
    assert_eq!(files(&out), before);
}

/// A run told to stop (Ctrl-C from Python) starts no sample after that, returns
/// `Interrupted`, and leaves whole samples only: the same request then resumes and finishes
/// with the bytes of an uninterrupted run, in folders and in tar shards.
#[test]
fn a_stopped_run_leaves_whole_samples_and_resumes() {
    use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
    let spec = spec();
    let tmp = tempfile::tempdir().unwrap();
    for format in [
        Format::Dir,
        Format::WebDataset {
            samples_per_shard: 2,
        },
    ] {
        let name = format!("{format:?}");
        let req = Request {
            format,
            ..request(8, 5, Shard::ALL, 1)
        };
        let whole = tmp.path().join(format!("whole-{name}"));
        generate(&spec, &whole, &req, &|| {}).unwrap();
        let stopped = tmp.path().join(format!("stopped-{name}"));
        let stop = AtomicBool::new(false);
        let done = AtomicU64::new(0);
        let err = xbandsim_dataset::generate_until(
            &spec,
            &stopped,
            &req,
            &|| {
                if done.fetch_add(1, Ordering::Relaxed) + 1 == 3 {
                    stop.store(true, Ordering::Relaxed);
                }
            },
            &stop,
        )
        .unwrap_err();
        assert!(
            matches!(err, DatasetError::Interrupted { .. }),
            "{name}: {err}"
        );
        let left = files(&stopped);
        assert!(
            left.keys()
                .all(|k| !k.contains("partial") && !k.starts_with(".owners")),
            "{name}: temporaries left: {:?}",
            left.keys().collect::<Vec<_>>()
        );
        assert!(!stopped.join("README.md").exists(), "{name}: assembled");
        let s = generate(&spec, &stopped, &req, &|| {}).unwrap();
        assert!(s.skipped >= 2 && s.made > 0, "{name}: {s:?}");
        let _ = std::fs::remove_dir(stopped.join(".partial"));
        let _ = std::fs::remove_dir(whole.join(".partial"));
        assert_eq!(files(&whole), files(&stopped), "{name}");
    }
}

/// Spec errors name the field at fault: the one the scene loader names, traced back to the
/// spec (not the first drawn field tried), and settings that only fail in some drawn scenes
/// or only when rendered are refused before the first sample.
#[test]
fn spec_errors_blame_the_field_at_fault() {
    let parse_err = |text: &str| {
        DatasetSpec::parse(text, Path::new("."))
            .unwrap_err()
            .to_string()
    };
    // A bad fixed size beside a drawn one: the bad one is named.
    let err = parse_err(
        &SPEC
            .replace("radius_m = { uniform = [0.3, 1.0] }", "radius_m = -1.0")
            .replace("height_m = 2.0", "height_m = { uniform = [1.0, 3.0] }"),
    );
    assert!(
        err.contains("targets.class[0].object.radius_m") && !err.contains("height_m:"),
        "{err}"
    );
    // A class's speed beyond any craft is the class's speed_kn.
    let err = parse_err(&SPEC.replace(
        "speed_kn = { uniform = [0.0, 20.0] }",
        "speed_kn = { uniform = [0.0, 400.0] }",
    ));
    assert!(
        err.contains("targets.class[1].speed_kn") && err.contains("300"),
        "{err}"
    );
    // A bad base-scene field is the base scene's, not a [vary] field's.
    let err = parse_err(&SPEC.replace("spokes = 60", "spokes = 0"));
    assert!(
        err.contains("scene.radar.spokes") && !err.contains("vary."),
        "{err}"
    );
    // A range-Doppler cube needs pulse mode.
    let err = parse_err(&SPEC.replace("frames = 1", "frames = 1\ndatacube = true"));
    assert!(
        err.contains("dataset.datacube") && err.contains("pulse"),
        "{err}"
    );
    DatasetSpec::parse(
        &SPEC
            .replace("frames = 1", "frames = 1\ndatacube = true")
            .replace(
                "[scene.display]",
                "[scene.processing]\nmode = \"pulse\"\n\n[scene.display]",
            ),
        Path::new("."),
    )
    .unwrap();
    // A fixed object named like a generated target.
    let err = parse_err(&SPEC.replace(
        "[vary]",
        "[[scene.object]]\nname = \"boat-0\"\nshape = \"sphere\"\nradius_m = 1.0\nposition_m = [0.0, 200.0, 2.0]\n\n[vary]",
    ));
    assert!(
        err.contains("scene.object[0].name") && err.contains("boat-0"),
        "{err}"
    );
    // Two drawn fields each fine at their extremes with the other at its middle, but not
    // together (a pulse and range too long for the repetition interval): some samples'
    // scenes are refused, and the run says so, naming the field the loader names, before
    // it writes a sample.
    let combined = SPEC.replace(
        "[vary]",
        "[vary]\n\"radar.prf_hz\" = { uniform = [1000.0, 30000.0] }\n\"radar.pulse_width_us\" = { uniform = [1.0, 40.0] }",
    );
    let spec = DatasetSpec::parse(&combined, Path::new(".")).unwrap();
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("ds");
    let err = generate(&spec, &out, &request(40, 1, Shard::ALL, 2), &|| {})
        .unwrap_err()
        .to_string();
    assert!(
        err.starts_with("dataset spec: ")
            && err.contains("draws a scene that is refused")
            && err.contains("prf_hz"),
        "{err}"
    );
    assert!(
        !out.join("samples").exists(),
        "samples were made before the error"
    );
}

/// `dataset stats` counts what is there and says when a dataset is unfinished (samples
/// missing, or the index files not written), in folders and tar shards; once complete, the
/// two formats' counts agree and cover every row of the dataset's targets.jsonl.
#[test]
fn stats_say_when_a_dataset_is_unfinished() {
    use xbandsim_dataset::stats::stats;
    let spec = spec();
    let tmp = tempfile::tempdir().unwrap();
    let mut complete = Vec::new();
    for (name, format, present) in [
        ("dir", Format::Dir, 3),
        (
            "tar",
            Format::WebDataset {
                samples_per_shard: 2,
            },
            4,
        ),
    ] {
        let out = tmp.path().join(name);
        let half = Request {
            format,
            assemble: false,
            ..request(6, 9, Shard { index: 0, count: 2 }, 1)
        };
        generate(&spec, &out, &half, &|| {}).unwrap();
        let s = stats(&out).unwrap();
        assert_eq!((s.count, s.samples), (6, present), "{name}");
        let note = s.unfinished().expect("unfinished");
        assert!(
            note.contains(&format!("{} of 6 samples are missing", 6 - present))
                && s.report().starts_with("unfinished: "),
            "{name}: {note}"
        );
        // Every sample there, the index files not yet: still unfinished.
        let other = Request {
            shard: Shard { index: 1, count: 2 },
            ..half.clone()
        };
        generate(&spec, &out, &other, &|| {}).unwrap();
        let s = stats(&out).unwrap();
        assert_eq!(s.samples, 6);
        assert!(s.unfinished().unwrap().contains("index files"), "{name}");
        let whole = Request {
            format,
            ..request(6, 9, Shard::ALL, 1)
        };
        generate(&spec, &out, &whole, &|| {}).unwrap();
        let s = stats(&out).unwrap();
        assert_eq!(s.unfinished(), None, "{name}");
        let rows = std::fs::read_to_string(out.join("targets.jsonl"))
            .unwrap()
            .lines()
            .count() as u64;
        assert_eq!(
            s.per_class.values().map(|v| v.0).sum::<u64>(),
            rows,
            "{name}"
        );
        complete.push(s);
    }
    assert_eq!(complete[0], complete[1]);
}

/// A spec can draw the transmitter: both kinds appear over a few samples, each sample's
/// scene says which, and every one renders.
#[test]
fn specs_draw_the_transmitter() {
    let text = SPEC.replace(
        "[vary]\n",
        "[vary]\n\"radar.transmitter\" = { choice = [\"solid_state\", \"magnetron\"] }\n",
    );
    let spec = DatasetSpec::parse(&text, Path::new(".")).unwrap();
    let mut seen = std::collections::BTreeSet::new();
    for i in 0..12 {
        let s = spec.sample(5, i).unwrap();
        let scene: toml::Table = toml::from_str(&s.scene_toml).unwrap();
        let t = scene["radar"]["transmitter"].as_str().unwrap().to_string();
        let built = xbandsim::model::Scene::from_toml_str(&s.scene_toml, "sample").unwrap();
        let magnetron = built.radar().transmitter() == xbandsim::model::Transmitter::Magnetron;
        assert_eq!(magnetron, t == "magnetron", "sample {i}");
        seen.insert(t);
    }
    assert_eq!(seen.len(), 2, "{seen:?}");
    let out = tempfile::tempdir().unwrap();
    xbandsim_dataset::make_sample(&spec, out.path(), 5, 0).unwrap();
}

/// A spec can draw the preset and the range scale: each sample's radar is the drawn preset on
/// the drawn scale, its targets lie inside that range, and a sample renders.
#[test]
fn specs_draw_presets_and_range_scales() {
    let text = SPEC.replace("max_range_m = 400.0\n", "").replace(
        "[vary]\n",
        "[vary]\n\"radar.preset\" = { choice = [\"drs4d-nxt\", \"magnetron-4kw-radome\"] }\n\
         \"radar.range_scale_nm\" = { choice = [0.125, 0.25] }\n",
    );
    let spec = DatasetSpec::parse(&text, Path::new(".")).unwrap();
    let mut seen = std::collections::BTreeSet::new();
    for i in 0..16 {
        let s = spec.sample(5, i).unwrap();
        let scene: toml::Table = toml::from_str(&s.scene_toml).unwrap();
        let preset = scene["radar"]["preset"].as_str().unwrap().to_string();
        let nm = scene["radar"]["range_scale_nm"].as_float().unwrap();
        let built = xbandsim::model::Scene::from_toml_str(&s.scene_toml, "sample").unwrap();
        let radar = built.radar();
        assert_eq!(radar.range_scale_nm(), Some(nm), "sample {i}");
        assert_eq!(radar.max_range_m(), nm * 1852.0);
        let magnetron = radar.transmitter() == xbandsim::model::Transmitter::Magnetron;
        assert_eq!(magnetron, preset == "magnetron-4kw-radome", "sample {i}");
        for o in built.objects() {
            let p = o.position_m();
            assert!(
                p.x.hypot(p.y) <= 0.95 * radar.max_range_m() + 1e-6,
                "sample {i}"
            );
        }
        seen.insert((preset, nm.to_bits()));
    }
    assert_eq!(seen.len(), 4, "{seen:?}");
    let out = tempfile::tempdir().unwrap();
    xbandsim_dataset::make_sample(&spec, out.path(), 5, 0).unwrap();
}

/// A spec can draw the receiver's controls and an artefact's settings: each sample's scene
/// has the drawn gain, sea clutter mode and interferer PRF, and a sample writes its video.
#[test]
fn specs_draw_receiver_controls_and_artefacts() {
    let text = SPEC
        .replace(
            "[scene.environment]",
            "[scene.receiver]\nvideo_spokes = 120\n\n\
         [[scene.artefacts.interferer]]\nposition_m = [300.0, 0.0, 6.0]\n\n[scene.environment]",
        )
        .replace(
            "[vary]\n",
            "[vary]\n\"receiver.gain_db\" = { uniform = [-6.0, 3.0] }\n\
         \"receiver.stc\" = { choice = [\"off\", \"auto\"] }\n\
         \"artefacts.interferer[0].prf_hz\" = { uniform = [900.0, 1900.0] }\n",
        );
    let spec = DatasetSpec::parse(&text, Path::new(".")).unwrap();
    let mut modes = std::collections::BTreeSet::new();
    for i in 0..12 {
        let s = spec.sample(5, i).unwrap();
        let built = xbandsim::model::Scene::from_toml_str(&s.scene_toml, "sample").unwrap();
        let r = built.receiver().expect("the base scene's [receiver]");
        assert!((-6.0..=3.0).contains(&r.gain_db), "{}", r.gain_db);
        modes.insert(format!("{:?}", r.stc));
        let prf = built.artefacts().interferers[0].prf_hz;
        assert!((900.0..=1900.0).contains(&prf), "{prf}");
    }
    assert_eq!(modes.len(), 2, "{modes:?}");
    let out = tempfile::tempdir().unwrap();
    xbandsim_dataset::make_sample(&spec, out.path(), 5, 0).unwrap();
    let dir = xbandsim_dataset::sample_dir(out.path(), 0);
    assert!(
        dir.join("video.npy").exists(),
        "{:?}",
        std::fs::read_dir(&dir).unwrap().collect::<Vec<_>>()
    );
}

/// `[dataset] artefact_labels`: the categories gain the seven artefact classes after the
/// targets', and a sample with an interferer nearby labels its pulses under
/// `artefact_interference` in COCO (one label per pulse, its mask the pixels of its box, no
/// track, its kind, source and level under `"artefact"`) and in YOLO, one line each; without
/// it none are labelled.
#[test]
fn artefact_labels_put_each_artefact_in_its_own_category() {
    let text = |on: bool| {
        SPEC.replace(
            "frames = 1\n",
            &format!("frames = 1\nartefact_labels = {on}\n"),
        )
        .replace(
            "[scene.environment]",
            "[[scene.artefacts.interferer]]\nposition_m = [300.0, 0.0, 6.0]\nprf_hz = 3100.0\n\n\
                 [scene.environment]",
        )
    };
    let spec = DatasetSpec::parse(&text(true), Path::new(".")).unwrap();
    let categories = spec.categories();
    let names: Vec<&str> = xbandsim_dataset::spec::ARTEFACT_CATEGORIES
        .iter()
        .map(|(_, n)| *n)
        .collect();
    assert_eq!(&categories[categories.len() - 7..], &names[..]);
    let interference_id = categories
        .iter()
        .position(|c| c == "artefact_interference")
        .unwrap()
        + 1;
    let out = tempfile::tempdir().unwrap();
    xbandsim_dataset::make_sample(&spec, out.path(), 5, 0).unwrap();
    let dir = xbandsim_dataset::sample_dir(out.path(), 0);
    let coco: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("coco.json")).unwrap()).unwrap();
    let truth: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("truth.json")).unwrap()).unwrap();
    let hits: Vec<&serde_json::Value> = coco["annotations"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|a| a["category_id"] == interference_id)
        .collect();
    let boxes_in_truth: usize = truth["artefacts"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|a| a["kind"] == "interference")
        .map(|a| {
            a["ppi_boxes_px"]
                .as_array()
                .unwrap()
                .iter()
                .filter(|b| !b.is_null())
                .count()
        })
        .sum();
    assert!(!hits.is_empty());
    assert!(
        hits.len() <= boxes_in_truth,
        "{} > {boxes_in_truth}",
        hits.len()
    );
    for a in &hits {
        assert_eq!(a["artefact"]["kind"], "interference");
        assert!(a["artefact"]["expected_level_db"].as_f64().unwrap() >= 6.0);
        assert!(a["segmentation"]["counts"].is_string());
        assert!(a["area"].as_u64().unwrap() > 0);
        assert!(a["track_id"].is_null());
    }
    let yolo = std::fs::read_to_string(dir.join("yolo.txt")).unwrap();
    let yolo_hits = yolo
        .lines()
        .filter(|l| l.starts_with(&format!("{} ", interference_id - 1)))
        .count();
    assert_eq!(yolo_hits, hits.len());
    // Off: the same sample labels no artefact.
    let spec = DatasetSpec::parse(&text(false), Path::new(".")).unwrap();
    assert!(!spec.categories().iter().any(|c| c.starts_with("artefact_")));
    let out = tempfile::tempdir().unwrap();
    xbandsim_dataset::make_sample(&spec, out.path(), 5, 0).unwrap();
    let coco: serde_json::Value = serde_json::from_slice(
        &std::fs::read(xbandsim_dataset::sample_dir(out.path(), 0).join("coco.json")).unwrap(),
    )
    .unwrap();
    assert!(coco["annotations"]
        .as_array()
        .unwrap()
        .iter()
        .all(|a| a.get("artefact").is_none()));
    // A target class may not take an artefact category's name.
    let clash = text(true).replace("name = \"buoy\"", "name = \"artefact_sidelobe\"");
    let e = DatasetSpec::parse(&clash, Path::new(".")).unwrap_err();
    assert!(e.to_string().contains("dataset.artefact_labels"), "{e}");
}

/// The classical baseline of a sequence dataset reads the same from sample folders, from tar
/// shards and from the assembled baseline.jsonl and targets.jsonl; it covers every frame,
/// tracks each sequence, and the card carries its scores.
#[test]
fn the_baseline_reads_the_same_however_the_dataset_is_stored() {
    use xbandsim_dataset::baseline::BaselineTally;
    use xbandsim_dataset::stats::stats;
    let spec =
        DatasetSpec::parse(&SPEC.replace("frames = 1", "frames = 5"), Path::new(".")).unwrap();
    let tmp = tempfile::tempdir().unwrap();
    let lines = |path: &Path| -> Vec<serde_json::Value> {
        std::fs::read_to_string(path)
            .unwrap()
            .lines()
            .map(|l| serde_json::from_str(l).unwrap())
            .collect()
    };
    let mut tallies = Vec::new();
    for (name, format) in [
        ("dir", Format::Dir),
        (
            "tar",
            Format::WebDataset {
                samples_per_shard: 2,
            },
        ),
    ] {
        let out = tmp.path().join(name);
        let samples_only = Request {
            format,
            assemble: false,
            ..request(5, 4, Shard::ALL, 1)
        };
        generate(&spec, &out, &samples_only, &|| {}).unwrap();
        let before = stats(&out).unwrap().baseline;
        let whole = Request {
            format,
            ..request(5, 4, Shard::ALL, 1)
        };
        generate(&spec, &out, &whole, &|| {}).unwrap();
        let after = stats(&out).unwrap().baseline;
        assert_eq!(before, after, "{name}");
        // The assembled tables say the same.
        let mut assembled = BaselineTally::default();
        for b in lines(&out.join("baseline.jsonl")) {
            assembled.add_sample(&b).unwrap();
        }
        for row in lines(&out.join("targets.jsonl")) {
            assembled.add_row(&row);
        }
        assert_eq!(assembled, after, "{name}");
        assert_eq!((after.samples, after.frames), (5, 25), "{name}");
        let tracking = after.tracking.clone().expect("sequences are tracked");
        assert_eq!((tracking.sequences, tracking.frames), (5, 25));
        assert!(tracking.matches > 0, "no track paired with an object");
        // False plots and cells per range band add up to those per sea state.
        let total = after.total();
        assert!(total.cells_tested > 0);
        assert_eq!(
            after.per_range.iter().map(|b| b.cells_tested).sum::<u64>(),
            total.cells_tested
        );
        assert_eq!(
            after.per_range.iter().map(|b| b.false_plots).sum::<u64>(),
            total.false_plots
        );
        let echoes: u64 = after.per_class.values().map(|v| v.echoes).sum();
        assert_eq!(echoes, tracking.objects, "{name}");
        let card = std::fs::read_to_string(out.join("README.md")).unwrap();
        let f = tracking.figures();
        let row = format!(
            "| {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {} | {} | {} |",
            f.mota.unwrap(),
            f.motp_m.unwrap(),
            f.hota,
            f.det_a,
            f.ass_a,
            f.loc_a,
            tracking.misses,
            tracking.false_positives,
            tracking.switches
        );
        assert!(
            card.contains("## Baseline: CFAR plots and ARPA tracks") && card.contains(&row),
            "{name}: {row} not in {card}"
        );
        tallies.push(after);
    }
    assert_eq!(tallies[0], tallies[1]);
    // `baseline = false` leaves the files and fields out, and stats say so.
    let off = DatasetSpec::parse(
        &SPEC.replace("frames = 1", "frames = 1\nbaseline = false"),
        Path::new("."),
    )
    .unwrap();
    let out = tmp.path().join("off");
    generate(&off, &out, &request(4, 4, Shard::ALL, 1), &|| {}).unwrap();
    assert!(!sample_dir(&out, 0).join("baseline.json").exists());
    let rows = lines(&out.join("targets.jsonl"));
    assert!(!rows.is_empty());
    for row in rows {
        assert!(row["baseline_detected"].is_null() && row["baseline_track_id"].is_null());
    }
    let s = stats(&out).unwrap();
    assert_eq!(s.baseline.samples, 0);
    assert!(s.report().contains("baseline: none"));
}
