//! The dataset's labels against what they describe (docs/formats.md, "Dataset labels"):
//! masks are exactly the target-only render's pixels at or above the threshold inside each
//! target's polar box, boxes are the masks' tight boxes, and on echoes of the image itself; the visibility
//! rule; the COCO file's structure and RLE; the YOLO files against the ultralytics format
//! (a checker written here from its documentation: one `class x y w h` or
//! `class x1 y1 … x4 y4` line per object, class an integer below `nc`, coordinates
//! normalised to [0, 1]; labels/ beside images/ with the same stems; data.yaml's names);
//! `verify` finds missing and damaged samples.

mod common;

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;
use xbandsim_dataset::{generate, sample_dir, DatasetSpec, Format, Request, Shard};

const SPEC: &str = r#"
[dataset]
val_every = 3

[scene.radar]
spokes = 180
max_range_m = 750.0
position_m = [0.0, 0.0, 8.0]

[scene.environment]
clutter = true
sea_state = 2.0

[scene.display]
image_size_px = 192

[targets]
count = { uniform_int = [2, 5] }
range_fraction = { uniform = [0.15, 0.9] }
min_separation_m = 60.0

[[targets.class]]
library = "navigation_buoy"

[[targets.class]]
library = "fishing_vessel"

[[targets.class]]
library = "lobster_pot"
"#;

fn make(dir: &Path, count: u64) -> DatasetSpec {
    let spec = DatasetSpec::parse(SPEC, Path::new(".")).unwrap();
    let request = Request {
        count,
        seed: 3,
        shard: Shard::ALL,
        jobs: 2,
        format: Format::Dir,
        assemble: true,
    };
    let s = generate(&spec, dir, &request, &|| {}).unwrap();
    assert!(s.assembled.is_some());
    spec
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap()
}

/// pycocotools' rleFrString, rewritten from its description: six-bit characters from 48,
/// five value bits and a continuation bit, sign-extended; counts from the third on are
/// differences from the count two before.
fn rle_decode(s: &str, height: usize, width: usize) -> Vec<bool> {
    let bytes = s.as_bytes();
    let mut counts: Vec<i64> = Vec::new();
    let mut p = 0;
    while p < bytes.len() {
        let (mut x, mut k) = (0i64, 0);
        loop {
            let c = (bytes[p] - 48) as i64;
            x |= (c & 0x1f) << (5 * k);
            p += 1;
            k += 1;
            if c & 0x20 == 0 {
                if c & 0x10 != 0 {
                    x |= -1i64 << (5 * k);
                }
                break;
            }
        }
        if counts.len() > 2 {
            x += counts[counts.len() - 2];
        }
        counts.push(x);
    }
    // Column-major runs, zeros first, into a row-major mask.
    let mut mask = vec![false; height * width];
    let (mut at, mut value) = (0usize, false);
    for c in counts {
        for i in at..at + c as usize {
            let (x, y) = (i / height, i % height);
            mask[y * width + x] = value;
        }
        at += c as usize;
        value = !value;
    }
    assert_eq!(at, height * width, "RLE covers the image");
    mask
}

fn read_gray(path: &Path) -> (usize, Vec<u8>) {
    let decoder = png::Decoder::new(std::fs::File::open(path).unwrap());
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!(info.color_type, png::ColorType::Grayscale);
    (info.width as usize, buf)
}

/// Masks are the target-only render's pixels at or above 0 dB inside the object's polar box,
/// all inside the object's box; masks of one frame do not overlap; the image is brighter on
/// the mask than around it; objects below the noise get no label but stay in the table.
#[test]
fn masks_and_boxes_land_on_the_targets() {
    let tmp = tempfile::tempdir().unwrap();
    make(tmp.path(), 6);
    let coco = json(&tmp.path().join("annotations.json"));
    let mut labelled = 0;
    let mut brighter = 0;
    for i in 0..6 {
        let dir = sample_dir(tmp.path(), i);
        // The target-only render of the sample's scene, on its own.
        let (seed, loaded) = common::sample_scene(&dir);
        let sim = xbandsim::Simulation::new(loaded.build().unwrap());
        let quiet = sim.targets_only().render(seed);
        let display = loaded.ppi_settings().unwrap();
        let conv = display.frame_scan_converter(sim.scene().radar(), quiet.own_ship.as_ref());
        let size = conv.size_px() as usize;
        let mut ppi = vec![0f32; size * size];
        conv.convert(&quiet.polar_db, f32::NAN, &mut ppi);
        let truth = json(&dir.join("truth.json"));
        let objects = truth["objects"].as_array().unwrap();
        let fragment = json(&dir.join("coco.json"));
        let (_, image) = read_gray(&dir.join("ppi_gray.png"));
        let mut union = vec![false; size * size];
        let obb_text = std::fs::read_to_string(dir.join("yolo_obb.txt")).unwrap();
        let obb_lines: Vec<&str> = obb_text.lines().collect();
        assert_eq!(
            obb_lines.len(),
            fragment["annotations"].as_array().unwrap().len(),
            "sample {i}: every labelled echo has an oriented box"
        );
        for (n, a) in fragment["annotations"]
            .as_array()
            .unwrap()
            .iter()
            .enumerate()
        {
            labelled += 1;
            let track = a["track_id"].as_u64().unwrap() as usize;
            let o = &objects[track];
            assert!(["visible", "partially_eclipsed"].contains(&o["visibility"].as_str().unwrap()));
            let seg = &a["segmentation"];
            let mask = rle_decode(seg["counts"].as_str().unwrap(), size, size);
            let area = mask.iter().filter(|&&m| m).count();
            assert_eq!(a["area"].as_u64().unwrap() as usize, area);
            assert!(area > 0);
            let b: Vec<f64> = a["bbox"]
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_f64().unwrap())
                .collect();
            // The oriented box is the echo's: a rectangle around every mask pixel, no
            // larger than the axis box and no smaller than the mask.
            let v: Vec<f64> = obb_lines[n]
                .split(' ')
                .skip(1)
                .map(|x| x.parse::<f64>().unwrap() * size as f64)
                .collect();
            let r: Vec<[f64; 2]> = v.chunks(2).map(|c| [c[0], c[1]]).collect();
            let cross = |k: usize, p: [f64; 2]| {
                let (a, b) = (r[k], r[(k + 1) % 4]);
                (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])
            };
            let rect_area = 0.5
                * (0..4)
                    .map(|k| r[k][0] * r[(k + 1) % 4][1] - r[(k + 1) % 4][0] * r[k][1])
                    .sum::<f64>()
                    .abs();
            assert!(
                rect_area <= b[2] * b[3] + 1e-3,
                "sample {i}: {rect_area} > box {b:?}"
            );
            assert!(
                rect_area >= area as f64 - 1e-3,
                "sample {i}: {rect_area} < mask {area}"
            );
            for p in (0..size * size).filter(|&p| mask[p]) {
                let c = [(p % size) as f64 + 0.5, (p / size) as f64 + 0.5];
                let signs: Vec<f64> = (0..4).map(|k| cross(k, c)).collect();
                assert!(
                    signs.iter().all(|&x| x >= -1e-3) || signs.iter().all(|&x| x <= 1e-3),
                    "sample {i} track {track}: mask pixel {c:?} outside its oriented box {r:?}"
                );
            }
            let pb = &o["polar_box"];
            let (s0, s1) = (
                pb["spoke_min"].as_u64().unwrap() as usize,
                pb["spoke_max"].as_u64().unwrap() as usize,
            );
            let (b0, b1) = (
                pb["bin_min"].as_u64().unwrap() as usize,
                pb["bin_max"].as_u64().unwrap() as usize,
            );
            let bins = quiet.range_bins;
            let (mut on, mut on_n) = (0f64, 0usize);
            let mut bounds = [f64::INFINITY, f64::INFINITY, 0.0, 0.0];
            for p in 0..size * size {
                let (x, y) = ((p % size) as f64, (p / size) as f64);
                let cell = conv.nearest_cell(p);
                let in_polar_box = cell.is_some_and(|c| {
                    let (s, r) = (c / bins, c % bins);
                    let in_s = if s0 <= s1 {
                        (s0..=s1).contains(&s)
                    } else {
                        s >= s0 || s <= s1
                    };
                    in_s && (b0..=b1).contains(&r)
                });
                if mask[p] {
                    // On the target-only render at the threshold, in its polar box and box.
                    assert!(
                        ppi[p] >= 0.0,
                        "sample {i} track {track}: mask pixel at {} dB",
                        ppi[p]
                    );
                    assert!(in_polar_box);
                    assert!(
                        x >= b[0] && x + 1.0 <= b[0] + b[2] && y >= b[1] && y + 1.0 <= b[1] + b[3],
                        "sample {i} track {track}: mask pixel ({x}, {y}) outside box {b:?}"
                    );
                    bounds = [
                        bounds[0].min(x),
                        bounds[1].min(y),
                        bounds[2].max(x + 1.0),
                        bounds[3].max(y + 1.0),
                    ];
                    assert!(!union[p], "masks overlap");
                    union[p] = true;
                    on += image[p] as f64;
                    on_n += 1;
                }
            }
            // The box is the mask's tight box.
            assert_eq!(bounds, [b[0], b[1], b[0] + b[2], b[1] + b[3]]);
            // The image itself is brighter on the mask than over the whole picture.
            let mean_all = image.iter().map(|&v| v as f64).sum::<f64>() / image.len() as f64;
            if on / on_n as f64 > mean_all {
                brighter += 1;
            }
        }
        // Every pixel at or above the threshold inside some labelled object's polar box is in
        // a mask (nothing of a target's own echo is left out).
        let labelled_tracks: BTreeSet<u64> = fragment["annotations"]
            .as_array()
            .unwrap()
            .iter()
            .map(|a| a["track_id"].as_u64().unwrap())
            .collect();
        for p in 0..size * size {
            if ppi[p].is_nan() || ppi[p] < 0.0 || union[p] {
                continue;
            }
            let Some(c) = conv.nearest_cell(p) else {
                continue;
            };
            let (s, r) = (c / quiet.range_bins, c % quiet.range_bins);
            for o in objects {
                let Some(pb) = o["polar_box"].as_object() else {
                    continue;
                };
                let (s0, s1) = (
                    pb["spoke_min"].as_u64().unwrap() as usize,
                    pb["spoke_max"].as_u64().unwrap() as usize,
                );
                let in_s = if s0 <= s1 {
                    (s0..=s1).contains(&s)
                } else {
                    s >= s0 || s <= s1
                };
                let inside = in_s
                    && (pb["bin_min"].as_u64().unwrap() as usize
                        ..=pb["bin_max"].as_u64().unwrap() as usize)
                        .contains(&r);
                assert!(
                    !(inside && labelled_tracks.contains(&o["track_id"].as_u64().unwrap())),
                    "sample {i}: pixel {p} of track {} left out of its mask",
                    o["track_id"]
                );
            }
        }
        // The table holds every object; the unlabelled ones say why.
        let rows: Vec<serde_json::Value> = std::fs::read_to_string(dir.join("targets.jsonl"))
            .unwrap()
            .lines()
            .map(|l| serde_json::from_str(l).unwrap())
            .collect();
        assert_eq!(rows.len(), objects.len());
        for r in &rows {
            let seen =
                ["visible", "partially_eclipsed"].contains(&r["visibility"].as_str().unwrap());
            if r["labelled"].as_bool().unwrap() {
                assert!(seen);
            } else {
                assert!(r["mask_area_px"].is_null());
            }
            if r["visibility"] == "below_noise" {
                assert_eq!(r["flags"]["below_noise"], true);
                assert_eq!(r["labelled"], false);
            }
        }
    }
    assert!(labelled >= 6, "only {labelled} labels in 6 samples");
    assert_eq!(
        brighter, labelled,
        "every labelled echo is brighter than the picture's mean"
    );
    assert_eq!(coco["annotations"].as_array().unwrap().len(), labelled);
}

/// The COCO file: unique ids, every annotation on an image and a category, images named by
/// existing files, categories in the spec's order.
#[test]
fn coco_file_is_consistent() {
    let tmp = tempfile::tempdir().unwrap();
    make(tmp.path(), 5);
    let coco = json(&tmp.path().join("annotations.json"));
    let names: Vec<&str> = coco["categories"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["navigation_buoy", "fishing_vessel", "lobster_pot"]);
    let images: BTreeMap<u64, &serde_json::Value> = coco["images"]
        .as_array()
        .unwrap()
        .iter()
        .map(|im| (im["id"].as_u64().unwrap(), im))
        .collect();
    assert_eq!(images.len(), 5);
    for im in images.values() {
        assert!(tmp.path().join(im["file_name"].as_str().unwrap()).is_file());
    }
    let mut ids = BTreeSet::new();
    for a in coco["annotations"].as_array().unwrap() {
        assert!(ids.insert(a["id"].as_u64().unwrap()), "duplicate id");
        assert!(images.contains_key(&a["image_id"].as_u64().unwrap()));
        let c = a["category_id"].as_u64().unwrap();
        assert!((1..=3).contains(&c));
        assert_eq!(a["iscrowd"], 0);
        let b = a["bbox"].as_array().unwrap();
        assert!(b[2].as_f64().unwrap() > 0.0 && b[3].as_f64().unwrap() > 0.0);
    }
}

/// Checks a YOLO tree against the ultralytics format; returns the label lines.
fn check_yolo_tree(root: &Path, numbers_per_line: usize, nc: usize) -> usize {
    let yaml = std::fs::read_to_string(root.join("data.yaml")).unwrap();
    assert!(yaml.contains("train: images/train"));
    assert!(yaml.contains(&format!("nc: {nc}")));
    for i in 0..nc {
        assert!(yaml.contains(&format!("  {i}: ")), "names lacks {i}");
    }
    let mut lines = 0;
    for split in ["train", "val"] {
        let images: BTreeSet<String> = std::fs::read_dir(root.join("images").join(split))
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().replace(".png", ""))
            .collect();
        let labels: BTreeSet<String> = std::fs::read_dir(root.join("labels").join(split))
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().replace(".txt", ""))
            .collect();
        assert_eq!(images, labels, "{split}: every image has its label file");
        for stem in &labels {
            let text = std::fs::read_to_string(
                root.join("labels").join(split).join(format!("{stem}.txt")),
            )
            .unwrap();
            for line in text.lines() {
                lines += 1;
                let f: Vec<&str> = line.split(' ').collect();
                assert_eq!(f.len(), 1 + numbers_per_line, "{line}");
                let class: usize = f[0].parse().expect("integer class");
                assert!(class < nc);
                let v: Vec<f64> = f[1..].iter().map(|x| x.parse().unwrap()).collect();
                assert!(v.iter().all(|x| (0.0..=1.0).contains(x)), "{line}");
                if numbers_per_line == 4 {
                    assert!(v[2] > 0.0 && v[3] > 0.0, "{line}");
                }
            }
        }
    }
    lines
}

/// The YOLO detect and oriented-box trees follow the ultralytics layout and line formats;
/// the split follows `val_every`; every COCO annotation is a detect line.
#[test]
fn yolo_trees_follow_the_ultralytics_format() {
    let tmp = tempfile::tempdir().unwrap();
    make(tmp.path(), 6);
    let detect = check_yolo_tree(&tmp.path().join("yolo"), 4, 3);
    let oriented = check_yolo_tree(&tmp.path().join("yolo_obb"), 8, 3);
    let coco = json(&tmp.path().join("annotations.json"));
    assert_eq!(detect, coco["annotations"].as_array().unwrap().len());
    assert_eq!(oriented, detect, "every labelled echo has an oriented box");
    // val_every = 3: samples 2 and 5.
    let val: BTreeSet<String> = std::fs::read_dir(tmp.path().join("yolo/images/val"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .collect();
    assert_eq!(
        val,
        BTreeSet::from(["000000002.png".into(), "000000005.png".into()])
    );
    let card = std::fs::read_to_string(tmp.path().join("README.md")).unwrap();
    assert!(card.contains("| fishing_vessel | 2 | 1 |"), "{card}");
    let yaml = std::fs::read_to_string(tmp.path().join("yolo/data.yaml")).unwrap();
    assert!(yaml.contains("  1: \"fishing_vessel\""), "{yaml}");
    // An assembly stopped part-way (README.md, written last, missing; targets.jsonl gone and
    // yolo/ half-removed): the same command with nothing left to make assembles again, to
    // the same bytes.
    let before: Vec<Vec<u8>> = ["annotations.json", "targets.jsonl", "README.md"]
        .iter()
        .map(|f| std::fs::read(tmp.path().join(f)).unwrap())
        .collect();
    std::fs::remove_file(tmp.path().join("README.md")).unwrap();
    std::fs::remove_file(tmp.path().join("targets.jsonl")).unwrap();
    std::fs::remove_dir_all(tmp.path().join("yolo/labels")).unwrap();
    let spec = DatasetSpec::parse(SPEC, Path::new(".")).unwrap();
    let request = Request {
        count: 6,
        seed: 3,
        shard: Shard::ALL,
        jobs: 1,
        format: Format::Dir,
        assemble: true,
    };
    let s = generate(&spec, tmp.path(), &request, &|| {}).unwrap();
    assert_eq!(s.made, 0);
    assert!(s.assembled.is_some());
    let after: Vec<Vec<u8>> = ["annotations.json", "targets.jsonl", "README.md"]
        .iter()
        .map(|f| std::fs::read(tmp.path().join(f)).unwrap())
        .collect();
    assert_eq!(before, after);
    assert_eq!(check_yolo_tree(&tmp.path().join("yolo"), 4, 3), detect);
    // The old trees were swapped out and deleted: nothing staged or set aside is left.
    let left: Vec<String> = std::fs::read_dir(tmp.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(".yolo"))
        .collect();
    assert!(left.is_empty(), "{left:?}");
}

/// `verify` passes a whole dataset and names missing and damaged samples.
#[test]
fn verify_finds_missing_and_corrupt_samples() {
    let tmp = tempfile::tempdir().unwrap();
    make(tmp.path(), 4);
    let r = xbandsim_dataset::verify::verify(tmp.path(), &|| {}).unwrap();
    assert!(r.is_complete(), "{r:?}");
    std::fs::remove_dir_all(sample_dir(tmp.path(), 1)).unwrap();
    let polar = sample_dir(tmp.path(), 2).join("polar.npy");
    let mut bytes = std::fs::read(&polar).unwrap();
    let n = bytes.len();
    bytes[n - 1] ^= 1;
    std::fs::write(&polar, bytes).unwrap();
    std::fs::remove_file(sample_dir(tmp.path(), 3).join("yolo.txt")).unwrap();
    let r = xbandsim_dataset::verify::verify(tmp.path(), &|| {}).unwrap();
    assert_eq!(r.missing, [1]);
    assert_eq!(r.corrupt.len(), 2);
    assert!(r.corrupt[0].1.contains("polar.npy"), "{:?}", r.corrupt);
    assert!(r.corrupt[1].1.contains("yolo.txt"), "{:?}", r.corrupt);
    assert!(!r.is_complete());
}

/// WebDataset shards: two shard runs equal one run byte for byte; the samples' members are
/// the sample folders' files (the labels naming the image as the shard stores it); a stale
/// partial tar is redone; `verify` passes whole shards and names a damaged one.
#[test]
fn webdataset_shards_hold_the_same_samples() {
    let spec = DatasetSpec::parse(SPEC, Path::new(".")).unwrap();
    let tmp = tempfile::tempdir().unwrap();
    let format = Format::WebDataset {
        samples_per_shard: 2,
    };
    let request = |shard| Request {
        count: 5,
        seed: 3,
        shard,
        jobs: 2,
        format,
        assemble: true,
    };
    let one = tmp.path().join("one");
    let s = generate(&spec, &one, &request(Shard::ALL), &|| {}).unwrap();
    assert_eq!((s.in_shard, s.made), (5, 5));
    let two = tmp.path().join("two");
    // Temporary files of killed runs, untouched for 20 minutes, are deleted by the run that
    // assembles; one touched a moment ago may be a live run's and stays.
    std::fs::create_dir_all(two.join("shards")).unwrap();
    std::fs::create_dir_all(two.join(".yolo.partial-deadhost-1-0-3/images")).unwrap();
    let long_ago = std::time::SystemTime::now() - std::time::Duration::from_secs(1200);
    let dead = [
        "shards/shard-000001.tar.partial-deadhost-1-0-0",
        "annotations.partial-deadhost-1-0-1",
        "annotations.json.annotations-deadhost-1-0-2",
        ".yolo.partial-deadhost-1-0-3/images/000000001.png",
    ];
    for name in dead {
        std::fs::write(two.join(name), b"half").unwrap();
        let f = std::fs::File::options()
            .write(true)
            .open(two.join(name))
            .unwrap();
        f.set_modified(long_ago).unwrap();
    }
    for dir in [
        ".yolo.partial-deadhost-1-0-3/images",
        ".yolo.partial-deadhost-1-0-3",
    ] {
        std::fs::File::open(two.join(dir))
            .unwrap()
            .set_modified(long_ago)
            .unwrap();
    }
    let live = "shards/shard-000002.tar.partial-livehost-7-0-0";
    std::fs::write(two.join(live), b"being written").unwrap();
    for i in [1, 0] {
        let s = generate(&spec, &two, &request(Shard { index: i, count: 2 }), &|| {}).unwrap();
        assert_eq!(s.in_shard, if i == 0 { 3 } else { 2 });
    }
    for name in dead {
        assert!(!two.join(name).exists(), "{name} should be deleted");
    }
    assert!(!two.join(".yolo.partial-deadhost-1-0-3").exists());
    assert!(two.join(live).is_file(), "a live run's file was deleted");
    std::fs::remove_file(two.join(live)).unwrap();
    let read = |dir: &Path| {
        let mut m = BTreeMap::new();
        for t in 0..3 {
            let p = xbandsim_dataset::webdataset::shard_path(dir, t);
            m.insert(format!("shard {t}"), std::fs::read(&p).unwrap());
            let p = xbandsim_dataset::webdataset::manifest_path(dir, t);
            m.insert(format!("manifest {t}"), std::fs::read(&p).unwrap());
        }
        for f in [
            "annotations.json",
            "targets.jsonl",
            "README.md",
            "dataset.json",
        ] {
            m.insert(f.to_string(), std::fs::read(dir.join(f)).unwrap());
        }
        m
    };
    assert_eq!(read(&one), read(&two));
    // The same samples as folders: every member equals the folder's file, but for the
    // image's name in the labels.
    let dirs = tmp.path().join("dirs");
    make(&dirs, 5);
    let mut members = 0;
    for t in 0..3 {
        xbandsim_dataset::webdataset::for_each_member(
            &xbandsim_dataset::webdataset::shard_path(&one, t),
            &|_| true,
            &mut |name, bytes| {
                let (index, file) = name.split_once('.').unwrap();
                let i: u64 = index.parse().unwrap();
                let folder = std::fs::read(sample_dir(&dirs, i).join(file)).unwrap();
                let member = String::from_utf8_lossy(&bytes).replace(
                    &format!("{index}.ppi_gray.png"),
                    &format!("samples/000000/{index}/ppi_gray.png"),
                );
                if file.ends_with(".json") || file.ends_with(".jsonl") {
                    assert_eq!(member.as_bytes(), folder.as_slice(), "{name}");
                } else {
                    assert_eq!(bytes, folder, "{name}");
                }
                members += 1;
                Ok(())
            },
        )
        .unwrap();
    }
    assert_eq!(members, 5 * 9);
    let r = xbandsim_dataset::verify::verify(&one, &|| {}).unwrap();
    assert!(r.is_complete(), "{r:?}");
    assert_eq!(r.shards, 3);
    let p = xbandsim_dataset::webdataset::shard_path(&one, 1);
    let mut bytes = std::fs::read(&p).unwrap();
    bytes[700] ^= 1;
    std::fs::write(&p, bytes).unwrap();
    let r = xbandsim_dataset::verify::verify(&one, &|| {}).unwrap();
    assert_eq!(r.corrupt.len(), 1, "{r:?}");
    assert_eq!(r.corrupt[0].0, 1);
}

/// Combined pulse mode: inside the join the noise is the short pulse's, so mask pixels there
/// hold the target-only render at or above `short_pulse_noise_db`, not just 0 dB.
#[test]
fn combined_pulse_masks_use_the_short_pulse_noise() {
    let text = SPEC
        .replace("val_every = 3", "val_every = 0")
        .replace(
            "position_m = [0.0, 0.0, 8.0]",
            "position_m = [0.0, 0.0, 8.0]\npulse_width_us = 1.0\npulse_mode = \"combined\"",
        )
        .replace("uniform = [0.15, 0.9]", "uniform = [0.08, 0.2]")
        .replace("min_separation_m = 60.0", "min_separation_m = 20.0");
    let spec = DatasetSpec::parse(&text, Path::new(".")).unwrap();
    let tmp = tempfile::tempdir().unwrap();
    let request = Request {
        count: 3,
        seed: 5,
        shard: Shard::ALL,
        jobs: 2,
        format: Format::Dir,
        assemble: true,
    };
    generate(&spec, tmp.path(), &request, &|| {}).unwrap();
    let mut inside_join = 0;
    for i in 0..3 {
        let dir = sample_dir(tmp.path(), i);
        let (seed, loaded) = common::sample_scene(&dir);
        let sim = xbandsim::Simulation::new(loaded.build().unwrap());
        let radar = sim.scene().radar();
        let (join, noise_db) = (radar.join_bin(), radar.short_pulse_noise_db().unwrap());
        let quiet = sim.targets_only().render(seed);
        let conv = loaded
            .ppi_settings()
            .unwrap()
            .frame_scan_converter(radar, quiet.own_ship.as_ref());
        let size = conv.size_px() as usize;
        let mut ppi = vec![0f32; size * size];
        conv.convert(&quiet.polar_db, f32::NAN, &mut ppi);
        let fragment = json(&dir.join("coco.json"));
        for a in fragment["annotations"].as_array().unwrap() {
            let mask = rle_decode(a["segmentation"]["counts"].as_str().unwrap(), size, size);
            for p in (0..size * size).filter(|&p| mask[p]) {
                let bin = conv.nearest_cell(p).unwrap() % quiet.range_bins;
                if bin < join {
                    inside_join += 1;
                    assert!(ppi[p] >= noise_db as f32, "{} < {noise_db}", ppi[p]);
                }
            }
        }
    }
    assert!(
        inside_join > 0,
        "no mask pixel inside the join: the test saw nothing"
    );
}

/// The coarse detection spec draws the fine spec's scenes and labels them in three classes:
/// the same boxes, each fine class mapped to its coarse one. Both cards say, per range scale
/// and class, how many labelled hulls are longer than the radar's resolution cell, as the
/// targets table's rows give it.
#[test]
fn coarse_spec_relabels_the_fine_specs_scenes() {
    let datasets = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../datasets");
    let tmp = tempfile::tempdir().unwrap();
    let make = |name: &str| {
        let spec = DatasetSpec::read(&datasets.join(name)).unwrap();
        let out = tmp.path().join(name);
        let request = Request {
            count: 4,
            seed: 21,
            shard: Shard::ALL,
            jobs: 2,
            format: Format::Dir,
            assemble: true,
        };
        generate(&spec, &out, &request, &|| {}).unwrap();
        (spec, out)
    };
    let (fine_spec, fine) = make("detection.toml");
    let (coarse_spec, coarse) = make("detection-coarse.toml");
    assert_eq!(
        coarse_spec.categories(),
        ["buoy_or_marker", "reflector", "vessel"]
    );
    let coarse_of = |class: &str| match class {
        "navigation_buoy" | "lobster_pot" | "channel_marker" => "buoy_or_marker",
        "corner_reflector" => "reflector",
        _ => "vessel",
    };
    let (a, b) = (
        json(&fine.join("annotations.json")),
        json(&coarse.join("annotations.json")),
    );
    let (fa, ca) = (
        a["annotations"].as_array().unwrap(),
        b["annotations"].as_array().unwrap(),
    );
    assert!(!fa.is_empty());
    assert_eq!(fa.len(), ca.len());
    let fine_names = fine_spec.categories();
    let coarse_names = coarse_spec.categories();
    for (f, c) in fa.iter().zip(ca) {
        assert_eq!(f["bbox"], c["bbox"]);
        assert_eq!(f["segmentation"], c["segmentation"]);
        let fine_class = &fine_names[f["category_id"].as_u64().unwrap() as usize - 1];
        let coarse_class = &coarse_names[c["category_id"].as_u64().unwrap() as usize - 1];
        assert_eq!(coarse_of(fine_class), coarse_class);
    }
    // The card's resolution table, row by row, from the targets table.
    for out in [&fine, &coarse] {
        let card = std::fs::read_to_string(out.join("README.md")).unwrap();
        assert!(card.contains("## What a detector can tell apart"), "{card}");
        let mut rows: std::collections::BTreeMap<(String, String), (u64, u64)> = Default::default();
        for line in std::fs::read_to_string(out.join("targets.jsonl"))
            .unwrap()
            .lines()
        {
            let v: serde_json::Value = serde_json::from_str(line).unwrap();
            if v["labelled"] != true {
                continue;
            }
            let hull = v["size_m"][0]
                .as_f64()
                .unwrap()
                .max(v["size_m"][1].as_f64().unwrap());
            let cell = v["resolution_cell_m"][0]
                .as_f64()
                .unwrap()
                .max(v["resolution_cell_m"][1].as_f64().unwrap());
            let e = rows
                .entry((
                    format!("{:.0}", v["range_scale_m"].as_f64().unwrap()),
                    v["class"].as_str().unwrap().to_string(),
                ))
                .or_default();
            e.0 += 1;
            e.1 += u64::from(hull > cell);
        }
        assert!(!rows.is_empty());
        for ((scale, class), (n, resolved)) in rows {
            let start = format!("| {scale} | {class} | {n} | ");
            let row = card
                .lines()
                .find(|l| l.starts_with(&start))
                .unwrap_or_else(|| panic!("no row {start} in {card}"));
            let percent = format!("| {:.0} % |", 100.0 * resolved as f64 / n as f64);
            assert!(row.ends_with(&percent), "{row} vs {percent}");
        }
    }
}

/// A spec with `[coast]` labels land: the `land` category last, one `iscrowd` annotation
/// (track null, the polygons it shows) for each frame with a `land_mask.npy` and none for
/// one without, its RLE decoding to its `area` pixels, and no YOLO line for it.
#[test]
fn coast_samples_label_their_land_as_a_region() {
    let text = format!(
        "{SPEC}\n[coast]\nprobability = 1.0\nlayout = \"harbour\"\ndistance_fraction = {{ uniform = [0.4, 0.6] }}\n"
    );
    let spec = DatasetSpec::parse(&text, Path::new(".")).unwrap();
    let cats = spec.categories();
    assert_eq!(cats.last().map(String::as_str), Some("land"));
    let land_id = cats.len() as u64;
    let dir = tempfile::tempdir().unwrap();
    let request = Request {
        count: 3,
        seed: 9,
        shard: Shard::ALL,
        jobs: 2,
        format: Format::Dir,
        assemble: true,
    };
    generate(&spec, dir.path(), &request, &|| {}).unwrap();
    let mut regions = 0;
    for i in 0..3u64 {
        let sample = sample_dir(dir.path(), i);
        let coco = json(&sample.join("coco.json"));
        let lands: Vec<&serde_json::Value> = coco["annotations"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|a| a["category_id"].as_u64() == Some(land_id))
            .collect();
        let mask_file = sample.join("land_mask.npy");
        if !mask_file.exists() {
            assert!(lands.is_empty());
            continue;
        }
        assert_eq!(lands.len(), 1, "sample {i}");
        let a = lands[0];
        assert_eq!(a["iscrowd"], 1);
        assert!(a["track_id"].is_null());
        assert!(!a["land"]["polygons"].as_array().unwrap().is_empty());
        let size = a["segmentation"]["size"][0].as_u64().unwrap() as usize;
        let mask = rle_decode(a["segmentation"]["counts"].as_str().unwrap(), size, size);
        assert_eq!(
            mask.iter().filter(|&&p| p).count() as u64,
            a["area"].as_u64().unwrap()
        );
        assert!(a["area"].as_u64().unwrap() > 0);
        // YOLO lines name only target classes.
        let yolo = std::fs::read_to_string(sample.join("yolo.txt")).unwrap();
        for line in yolo.lines() {
            let class: u64 = line.split_whitespace().next().unwrap().parse().unwrap();
            assert!(class < land_id - 1, "a YOLO line for land: {line}");
        }
        regions += 1;
    }
    assert!(
        regions >= 2,
        "{regions} of 3 harbour samples show their land"
    );
    let index = json(&dir.path().join("annotations.json"));
    let names: Vec<&str> = index["categories"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["name"].as_str().unwrap())
        .collect();
    assert_eq!(names.last(), Some(&"land"));
}

/// The card's "RCS by class" rows are the targets table's: per class, the rows with an
/// `rcs_dbsm` and their 10th percentile, median and 90th percentile, each the centre of the
/// 0.1 dB bin that holds the value of that rank; every row carries its aspect.
#[test]
fn the_card_reports_each_class_rcs_from_the_targets_table() {
    let tmp = tempfile::tempdir().unwrap();
    make(tmp.path(), 6);
    let text = std::fs::read_to_string(tmp.path().join("targets.jsonl")).unwrap();
    let mut per_class: std::collections::BTreeMap<String, Vec<f64>> = Default::default();
    let mut over_sea: std::collections::BTreeMap<String, Vec<f64>> = Default::default();
    for line in text.lines() {
        let row: serde_json::Value = serde_json::from_str(line).unwrap();
        let aspect = row["aspect_deg"].as_array().expect("aspect_deg");
        let (az, el) = (aspect[0].as_f64().unwrap(), aspect[1].as_f64().unwrap());
        assert!(
            (0.0..360.0).contains(&az) && (-90.0..=90.0).contains(&el),
            "{line}"
        );
        let class = row["class"].as_str().unwrap().to_string();
        if let Some(rcs) = row["rcs_dbsm"].as_f64() {
            per_class.entry(class.clone()).or_default().push(rcs);
        }
        if let Some(rcs) = row["rcs_over_sea_dbsm"].as_f64() {
            over_sea.entry(class).or_default().push(rcs);
        }
    }
    assert!(!per_class.is_empty());
    let card = std::fs::read_to_string(tmp.path().join("README.md")).unwrap();
    let section = card
        .split("## RCS by class")
        .nth(1)
        .expect("an RCS section");
    let quantile = |values: &[f64], q: f64| {
        let v = values[((q * values.len() as f64).ceil() as usize).max(1) - 1];
        format!(
            "{:.1}",
            -100.0 + (((v + 100.0) * 10.0).floor() + 0.5) / 10.0
        )
    };
    for (class, mut values) in per_class {
        values.sort_by(f64::total_cmp);
        let at = |q: f64| quantile(&values, q);
        let sea = over_sea.get_mut(&class).map_or("-".to_string(), |v| {
            v.sort_by(f64::total_cmp);
            quantile(v, 0.5)
        });
        let row = format!(
            "| {class} | {} | {} | {} | {} | {sea} |\n",
            values.len(),
            at(0.1),
            at(0.5),
            at(0.9)
        );
        assert!(section.contains(&row), "{row} not in {section}");
    }
}
