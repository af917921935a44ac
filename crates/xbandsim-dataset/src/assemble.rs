//! The index files of a complete dataset (docs/formats.md, "Dataset directory"), written
//! once every sample is in place, from the samples' own label files in index order, so the
//! same spec and seed give the same bytes however the samples were made (shards, jobs,
//! resumes):
//!
//! ```text
//! DIR/annotations.json      COCO: categories, every frame's image, annotations with RLE masks
//! DIR/targets.jsonl         every object of every frame, labelled or not, with its flags
//! DIR/yolo/data.yaml        ultralytics detect: images/{train,val}/, labels/{train,val}/
//! DIR/yolo_obb/data.yaml    ultralytics oriented boxes, the same layout
//! DIR/README.md             the dataset card: spec, seed, version, counts
//! ```
//!
//! The YOLO trees hold hard links to the samples' images (copies where the file system
//! cannot link), named `<index>.png` or `<index>_<frame>.png`.

use crate::error::{DatasetError, Result};
use crate::generate::{frame_subdir, sample_dir};
use crate::spec::DatasetSpec;
use std::collections::BTreeMap;
use std::io::Write;
use std::path::{Path, PathBuf};

/// What the assembled files hold.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Assembled {
    /// Images (frames) in the dataset.
    pub images: u64,
    /// Detection labels (COCO annotations).
    pub annotations: u64,
    /// Rows of the targets table (every object of every frame).
    pub targets: u64,
    /// Detection labels per category, in category order.
    pub labelled_per_category: Vec<(String, u64)>,
    /// Rows per visibility reason.
    pub rows_per_visibility: BTreeMap<String, u64>,
}

fn io<T>(path: &Path, r: std::io::Result<T>) -> Result<T> {
    r.map_err(|e| DatasetError::io(path, e))
}

fn read_json(path: &Path) -> Result<serde_json::Value> {
    let bytes = io(path, std::fs::read(path))?;
    serde_json::from_slice(&bytes).map_err(|e| {
        DatasetError::io(
            path,
            std::io::Error::new(std::io::ErrorKind::InvalidData, e.to_string()),
        )
    })
}

/// Writes `path` through a temporary file and a rename.
struct AtomicFile {
    path: PathBuf,
    tmp: PathBuf,
    file: std::io::BufWriter<std::fs::File>,
}

impl AtomicFile {
    fn create(path: &Path) -> Result<AtomicFile> {
        let tmp = path.with_extension("partial");
        let file = io(&tmp, std::fs::File::create(&tmp))?;
        Ok(AtomicFile {
            path: path.to_path_buf(),
            tmp,
            file: std::io::BufWriter::new(file),
        })
    }

    fn write(&mut self, bytes: &[u8]) -> Result<()> {
        io(&self.tmp, self.file.write_all(bytes))
    }

    fn finish(mut self) -> Result<()> {
        io(&self.tmp, self.file.flush())?;
        io(&self.path, std::fs::rename(&self.tmp, &self.path))
    }
}

fn link_or_copy(from: &Path, to: &Path) -> Result<()> {
    if std::fs::hard_link(from, to).is_err() {
        io(to, std::fs::copy(from, to))?;
    }
    Ok(())
}

fn data_yaml(categories: &[String], has_val: bool, kind: &str, count: u64, seed: u64) -> String {
    let mut y = format!(
        "# xbandsim dataset ({kind}; {count} samples, seed {seed}); ultralytics format: labels sit\n\
         # beside images/ in labels/. `path` is left out, so it is this file's folder.\n\
         train: images/train\nval: images/{}\nnc: {}\nnames:\n",
        if has_val { "val" } else { "train" },
        categories.len()
    );
    for (i, c) in categories.iter().enumerate() {
        y.push_str(&format!("  {i}: {c}\n"));
    }
    y
}

/// Writes the index files of the complete dataset in `out` (made with `seed`, `count`
/// samples). Every sample must be present.
pub fn assemble(spec: &DatasetSpec, out: &Path, count: u64, seed: u64) -> Result<Assembled> {
    let categories = spec.categories();
    let mut summary = Assembled {
        labelled_per_category: categories.iter().map(|c| (c.clone(), 0)).collect(),
        ..Default::default()
    };
    // COCO: images streamed to the file, annotations to a second one appended after.
    let mut coco = AtomicFile::create(&out.join("annotations.json"))?;
    let anns_path = out.join("annotations.json.annotations");
    let mut anns = std::io::BufWriter::new(io(&anns_path, std::fs::File::create(&anns_path))?);
    let mut targets = AtomicFile::create(&out.join("targets.jsonl"))?;
    let cats: Vec<serde_json::Value> = categories
        .iter()
        .enumerate()
        .map(|(i, c)| serde_json::json!({"id": i + 1, "name": c, "supercategory": "marine"}))
        .collect();
    let info = serde_json::json!({
        "description": "xbandsim synthetic X-band marine radar PPI dataset",
        "version": env!("CARGO_PKG_VERSION"),
        "seed": seed,
        "samples": count,
        "frames_per_sample": spec.frames,
    });
    coco.write(
        format!(
            "{{\"info\":{info},\"licenses\":[],\"categories\":{},\"images\":[",
            serde_json::Value::Array(cats)
        )
        .as_bytes(),
    )?;
    let trees = ["yolo", "yolo_obb"];
    let staging: Vec<PathBuf> = trees
        .iter()
        .map(|t| out.join(format!(".{t}.partial")))
        .collect();
    let has_val = (0..count).any(|i| spec.is_validation(i));
    for dir in &staging {
        if dir.exists() {
            io(dir, std::fs::remove_dir_all(dir))?;
        }
        for split in ["train", "val"] {
            for kind in ["images", "labels"] {
                let d = dir.join(kind).join(split);
                io(&d, std::fs::create_dir_all(&d))?;
            }
        }
    }
    let mut annotation_id = 0u64;
    for i in 0..count {
        let split = if spec.is_validation(i) {
            "val"
        } else {
            "train"
        };
        for k in 0..spec.frames {
            let frame_dir = sample_dir(out, i).join(frame_subdir(spec.frames, k));
            let image_id = i * spec.frames + k + 1;
            let mut fragment = read_json(&frame_dir.join("coco.json"))?;
            let mut image = fragment["image"].take();
            image["id"] = image_id.into();
            if image_id > 1 {
                coco.write(b",")?;
            }
            coco.write(image.to_string().as_bytes())?;
            if let Some(list) = fragment["annotations"].as_array_mut() {
                for a in list {
                    annotation_id += 1;
                    a["id"] = annotation_id.into();
                    a["image_id"] = image_id.into();
                    if let Some(c) = a["category_id"].as_u64() {
                        if let Some(entry) = summary.labelled_per_category.get_mut(c as usize - 1) {
                            entry.1 += 1;
                        }
                    }
                    if annotation_id > 1 {
                        io(&anns_path, anns.write_all(b","))?;
                    }
                    io(&anns_path, anns.write_all(a.to_string().as_bytes()))?;
                }
            }
            let rows_path = frame_dir.join("targets.jsonl");
            let rows = io(&rows_path, std::fs::read(&rows_path))?;
            for line in rows.split(|&b| b == b'\n').filter(|l| !l.is_empty()) {
                summary.targets += 1;
                if let Ok(v) = serde_json::from_slice::<serde_json::Value>(line) {
                    if let Some(reason) = v["visibility"].as_str() {
                        *summary
                            .rows_per_visibility
                            .entry(reason.to_string())
                            .or_default() += 1;
                    }
                }
            }
            targets.write(&rows)?;
            let stem = if spec.frames == 1 {
                format!("{i:09}")
            } else {
                format!("{i:09}_{k:04}")
            };
            let image_file = frame_dir.join(spec.image.labelled_file());
            for (dir, labels) in staging.iter().zip(["yolo.txt", "yolo_obb.txt"]) {
                link_or_copy(
                    &image_file,
                    &dir.join("images").join(split).join(format!("{stem}.png")),
                )?;
                let from = frame_dir.join(labels);
                let to = dir.join("labels").join(split).join(format!("{stem}.txt"));
                io(&to, std::fs::copy(&from, &to))?;
            }
            summary.images += 1;
        }
    }
    summary.annotations = annotation_id;
    io(&anns_path, anns.flush())?;
    drop(anns);
    coco.write(b"],\"annotations\":[")?;
    let mut f = io(&anns_path, std::fs::File::open(&anns_path))?;
    io(&anns_path, std::io::copy(&mut f, &mut coco.file))?;
    io(&anns_path, std::fs::remove_file(&anns_path))?;
    coco.write(b"]}\n")?;
    coco.finish()?;
    targets.finish()?;
    for ((tree, dir), kind) in trees.iter().zip(&staging).zip(["detect", "oriented boxes"]) {
        let yaml = dir.join("data.yaml");
        io(
            &yaml,
            std::fs::write(&yaml, data_yaml(&categories, has_val, kind, count, seed)),
        )?;
        let dest = out.join(tree);
        if dest.exists() {
            io(&dest, std::fs::remove_dir_all(&dest))?;
        }
        io(&dest, std::fs::rename(dir, &dest))?;
    }
    let mut card = AtomicFile::create(&out.join("README.md"))?;
    card.write(dataset_card(spec, count, seed, &summary).as_bytes())?;
    card.finish()?;
    Ok(summary)
}

/// The dataset card: what the dataset is, how it was made and what it holds.
fn dataset_card(spec: &DatasetSpec, count: u64, seed: u64, s: &Assembled) -> String {
    let mut c = format!(
        "# xbandsim radar dataset\n\n\
         Synthetic X-band marine radar PPI frames with ground truth, made by xbandsim {} \
         (`xbandsim dataset SPEC --count {count} --seed {seed}`). Every sample re-renders bit for \
         bit from its `scene.toml` (`xbandsim render scene.toml --seed <its seed>`).\n\n\
         - samples: {count}, frames per sample: {}, images: {}\n\
         - image: `{}` ({}), one per frame\n\
         - detection labels: {} (COCO `annotations.json`, YOLO `yolo/`, oriented boxes \
         `yolo_obb/`); every object of every frame: {} rows in `targets.jsonl`\n\
         - validation split: {}\n\
         - mask threshold: {} dB over the mean noise in the target-only render\n\n\
         ## Labels per class\n\n| class | COCO id | YOLO class | labels |\n|---|---|---|---|\n",
        env!("CARGO_PKG_VERSION"),
        spec.frames,
        s.images,
        spec.image.labelled_file(),
        if spec.image.labelled_file() == "ppi.png" {
            "colour"
        } else {
            "8-bit grayscale"
        },
        s.annotations,
        s.targets,
        if spec.val_every == 0 {
            "none".to_string()
        } else {
            format!(
                "every {}th sample (index mod {} = {})",
                spec.val_every,
                spec.val_every,
                spec.val_every - 1
            )
        },
        spec.mask_threshold_db,
    );
    for (i, (name, n)) in s.labelled_per_category.iter().enumerate() {
        c.push_str(&format!("| {name} | {} | {i} | {n} |\n", i + 1));
    }
    c.push_str("\n## Objects by visibility\n\n| visibility | rows |\n|---|---|\n");
    for (reason, n) in &s.rows_per_visibility {
        c.push_str(&format!("| {reason} | {n} |\n"));
    }
    c.push_str(
        "\nA labelled object is `visible` or `partially_eclipsed`, has a box in the image and a \
         non-empty mask; the others stay in `targets.jsonl` with their reason \
         (see xbandsim's docs/formats.md, \"Dataset labels\").\n\n## Spec\n\n```toml\n",
    );
    c.push_str(spec.text.trim_end());
    c.push_str("\n```\n");
    c
}
