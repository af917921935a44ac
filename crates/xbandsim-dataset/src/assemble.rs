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
//! With WebDataset shards the labels come from the shards' members, and there are no YOLO
//! trees (each sample's yolo.txt and yolo_obb.txt are in its shard).
//!
//! The YOLO trees hold hard links to the samples' images (copies where the file system
//! cannot link), named `<index>.png` or `<index>_<frame>.png`.

use crate::baseline::BaselineTally;
use crate::error::{at, invalid_data, Result};
use crate::layout::{
    coco_image_id, frame_of, frame_subdir, is_label_member, parse_member_name, sample_dir,
    shard_count, shard_path, shard_rel, Format, CARD,
};
use crate::spec::DatasetSpec;
use std::collections::BTreeMap;
use std::fmt::Write as _;
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
    /// Labelled objects by range scale (the display range, m, as its bits: exact) and class:
    /// how their hulls and echoes compare with the radar's resolution cell.
    pub resolution: BTreeMap<(u64, String), Resolution>,
    /// Free-space RCS by class over every row that has one.
    pub rcs: BTreeMap<String, RcsDistribution>,
    /// The RCS over the sea (the free-space RCS times the multipath gain) by class over
    /// every row that has one.
    pub rcs_over_sea: BTreeMap<String, RcsDistribution>,
    /// The classical baseline's results summed over the samples ([`crate::baseline`]).
    pub baseline: BaselineTally,
}

/// Bins of an RCS histogram: 0.1 dB wide from [`RCS_LOWEST_DBSM`] (values beyond either end
/// count in the end bins).
const RCS_BINS: usize = 2000;

/// The lower edge of the RCS histogram, dBsm.
const RCS_LOWEST_DBSM: f64 = -100.0;

/// How one class's free-space RCS (`rcs_dbsm`, at the aspects its targets were seen at) is
/// spread: a histogram in 0.1 dB bins, so that its percentiles are read to 0.1 dB whatever
/// the number of rows.
#[derive(Debug, Clone, PartialEq)]
pub struct RcsDistribution {
    /// Rows counted.
    pub rows: u64,
    bins: Vec<u64>,
}

impl Default for RcsDistribution {
    fn default() -> RcsDistribution {
        RcsDistribution {
            rows: 0,
            bins: vec![0; RCS_BINS],
        }
    }
}

impl RcsDistribution {
    /// Counts one RCS, dBsm.
    pub fn add(&mut self, rcs_dbsm: f64) {
        let bin = ((rcs_dbsm - RCS_LOWEST_DBSM) * 10.0).floor().max(0.0) as usize;
        self.bins[bin.min(RCS_BINS - 1)] += 1;
        self.rows += 1;
    }

    /// The `fraction` quantile (0–1), dBsm: the centre of the first bin at which the count
    /// so far reaches that fraction of the rows; None with no rows.
    pub fn quantile_dbsm(&self, fraction: f64) -> Option<f64> {
        let wanted = (fraction * self.rows as f64).max(1.0);
        let mut seen = 0;
        for (bin, n) in self.bins.iter().enumerate() {
            seen += n;
            if seen as f64 >= wanted {
                return Some(RCS_LOWEST_DBSM + (bin as f64 + 0.5) / 10.0);
            }
        }
        None
    }
}

/// Half-pixel bins of a length histogram, up to 1024 px (longer ones count in the last).
const LENGTH_BINS: usize = 2048;

/// How labelled objects of one class at one range scale compare with the radar's
/// resolution cell (the beamwidth times the range across, `c/(2B)` along).
#[derive(Debug, Clone, PartialEq)]
pub struct Resolution {
    /// Labelled objects.
    pub labels: u64,
    /// Those whose hull's longest side is longer than the cell's longer side: their echo
    /// can show the hull's length and shape.
    pub hull_resolved: u64,
    /// Histogram of the hull's longest side, half pixels.
    hull_px: Vec<u64>,
    /// Histogram of the echo's oriented box's longer side, half pixels.
    echo_px: Vec<u64>,
}

impl Default for Resolution {
    fn default() -> Resolution {
        Resolution {
            labels: 0,
            hull_resolved: 0,
            hull_px: vec![0; LENGTH_BINS],
            echo_px: vec![0; LENGTH_BINS],
        }
    }
}

impl Resolution {
    fn add(hist: &mut [u64], px: f64) {
        let bin = ((px * 2.0).max(0.0) as usize).min(LENGTH_BINS - 1);
        hist[bin] += 1;
    }

    /// The median of a half-pixel histogram, px (the middle bin's centre).
    fn median(hist: &[u64]) -> f64 {
        let total: u64 = hist.iter().sum();
        let mut seen = 0;
        for (bin, n) in hist.iter().enumerate() {
            seen += n;
            if 2 * seen >= total && total > 0 {
                return (bin as f64 + 0.5) / 2.0;
            }
        }
        0.0
    }

    /// Median hull length on the image, px.
    pub fn median_hull_px(&self) -> f64 {
        Resolution::median(&self.hull_px)
    }

    /// Median echo length (its oriented box's longer side), px.
    pub fn median_echo_px(&self) -> f64 {
        Resolution::median(&self.echo_px)
    }

    /// Counts a labelled targets-table row (at an image of `size_px`).
    fn count(&mut self, row: &serde_json::Value, size_px: f64) {
        let scale_m = row["range_scale_m"].as_f64().unwrap_or(0.0);
        if scale_m <= 0.0 || size_px <= 0.0 {
            return;
        }
        let metres_per_px = 2.0 * scale_m / size_px;
        let side = |i: usize| row["size_m"][i].as_f64().unwrap_or(0.0);
        let hull_m = side(0).max(side(1));
        let cell = |i: usize| row["resolution_cell_m"][i].as_f64().unwrap_or(0.0);
        self.labels += 1;
        self.hull_resolved += u64::from(hull_m > cell(0).max(cell(1)));
        Resolution::add(&mut self.hull_px, hull_m / metres_per_px);
        if let Some(c) = row["ppi_obb_px"].as_array() {
            let p = |k: usize, i: usize| c[k % 4][i].as_f64().unwrap_or(0.0);
            let len = |k: usize| (p(k + 1, 0) - p(k, 0)).hypot(p(k + 1, 1) - p(k, 1));
            Resolution::add(&mut self.echo_px, len(0).max(len(1)));
        }
    }
}

/// Writes `path` through a temporary file and a rename.
struct AtomicFile {
    path: PathBuf,
    tmp: PathBuf,
    file: std::io::BufWriter<std::fs::File>,
    renamed: bool,
}

impl Drop for AtomicFile {
    /// An assembly that fails part way removes its temporary file (a killed one leaves it to
    /// the stale-file cleanup of a later run).
    fn drop(&mut self) {
        if !self.renamed {
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}

impl AtomicFile {
    fn create(path: &Path) -> Result<AtomicFile> {
        let tmp = path.with_extension(format!(
            "partial-{}",
            xbandsim::products::output::temp_suffix()
        ));
        let file = at(&tmp, std::fs::File::create(&tmp))?;
        Ok(AtomicFile {
            path: path.to_path_buf(),
            tmp,
            file: std::io::BufWriter::new(file),
            renamed: false,
        })
    }

    fn write(&mut self, bytes: &[u8]) -> Result<()> {
        at(&self.tmp, self.file.write_all(bytes))
    }

    fn finish(mut self) -> Result<()> {
        at(&self.tmp, self.file.flush())?;
        at(&self.path, std::fs::rename(&self.tmp, &self.path))?;
        self.renamed = true;
        Ok(())
    }
}

fn link_or_copy(from: &Path, to: &Path) -> Result<()> {
    if std::fs::hard_link(from, to).is_err() {
        at(to, std::fs::copy(from, to))?;
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
        // A JSON string is a YAML double-quoted scalar: names like `no` or `a: b` stay names.
        y.push_str(&format!("  {i}: {}\n", serde_json::Value::from(c.as_str())));
    }
    y
}

/// The COCO file and the targets table being written, with the counts.
struct Writer {
    coco: AtomicFile,
    anns_path: PathBuf,
    anns: std::io::BufWriter<std::fs::File>,
    targets: AtomicFile,
    /// `baseline.jsonl`: each sample's baseline.json, one line each.
    baseline: AtomicFile,
    summary: Assembled,
    annotation_id: u64,
    /// The side of the last image added, px (its rows come after it).
    image_size_px: f64,
}

impl Writer {
    /// One frame's COCO fragment as image `image_id`, with `extra` fields on the image.
    fn add_coco(
        &mut self,
        path: &Path,
        bytes: &[u8],
        image_id: u64,
        extra: Option<(&str, serde_json::Value)>,
    ) -> Result<()> {
        let mut fragment: serde_json::Value =
            serde_json::from_slice(bytes).map_err(|e| invalid_data(path, e.to_string()))?;
        let mut image = fragment["image"].take();
        self.image_size_px = image["width"].as_f64().unwrap_or(0.0);
        image["id"] = image_id.into();
        if let Some((k, v)) = extra {
            image[k] = v;
        }
        if self.summary.images > 0 {
            self.coco.write(b",")?;
        }
        self.coco.write(image.to_string().as_bytes())?;
        self.summary.images += 1;
        if let Some(list) = fragment["annotations"].as_array_mut() {
            for a in list {
                self.annotation_id += 1;
                a["id"] = self.annotation_id.into();
                a["image_id"] = image_id.into();
                if let Some(c) = a["category_id"].as_u64() {
                    if let Some(entry) = self
                        .summary
                        .labelled_per_category
                        .get_mut((c as usize).wrapping_sub(1))
                    {
                        entry.1 += 1;
                    }
                }
                if self.annotation_id > 1 {
                    at(&self.anns_path, self.anns.write_all(b","))?;
                }
                at(
                    &self.anns_path,
                    self.anns.write_all(a.to_string().as_bytes()),
                )?;
            }
        }
        Ok(())
    }

    /// One frame's targets-table rows (after its COCO fragment).
    fn add_rows(&mut self, rows: &[u8]) -> Result<()> {
        let size_px = self.image_size_px;
        for line in rows.split(|&b| b == b'\n').filter(|l| !l.is_empty()) {
            self.summary.targets += 1;
            if let Ok(v) = serde_json::from_slice::<serde_json::Value>(line) {
                self.summary.baseline.add_row(&v);
                if let Some(class) = v["class"].as_str() {
                    for (key, table) in [
                        ("rcs_dbsm", &mut self.summary.rcs),
                        ("rcs_over_sea_dbsm", &mut self.summary.rcs_over_sea),
                    ] {
                        if let Some(dbsm) = v[key].as_f64() {
                            table.entry(class.to_string()).or_default().add(dbsm);
                        }
                    }
                }
                if let Some(reason) = v["visibility"].as_str() {
                    *self
                        .summary
                        .rows_per_visibility
                        .entry(reason.to_string())
                        .or_default() += 1;
                }
                if v["labelled"].as_bool() == Some(true) {
                    let scale = v["range_scale_m"].as_f64().unwrap_or(0.0).to_bits();
                    let class = v["class"].as_str().unwrap_or("?").to_string();
                    self.summary
                        .resolution
                        .entry((scale, class))
                        .or_default()
                        .count(&v, size_px);
                }
            }
        }
        self.targets.write(rows)
    }

    /// One sample's baseline.json (a line of JSON).
    fn add_baseline(&mut self, path: &Path, bytes: &[u8]) -> Result<()> {
        let v: serde_json::Value =
            serde_json::from_slice(bytes).map_err(|e| invalid_data(path, e.to_string()))?;
        self.summary
            .baseline
            .add_sample(&v)
            .map_err(|e| invalid_data(path, e))?;
        self.baseline.write(bytes)
    }

    fn finish(mut self) -> Result<Assembled> {
        self.summary.annotations = self.annotation_id;
        at(&self.anns_path, self.anns.flush())?;
        drop(self.anns);
        self.coco.write(b"],\"annotations\":[")?;
        let mut f = at(&self.anns_path, std::fs::File::open(&self.anns_path))?;
        at(&self.anns_path, std::io::copy(&mut f, &mut self.coco.file))?;
        at(&self.anns_path, std::fs::remove_file(&self.anns_path))?;
        self.coco.write(b"]}\n")?;
        self.coco.finish()?;
        self.targets.finish()?;
        self.baseline.finish()?;
        Ok(self.summary)
    }
}

/// Writes the index files of the complete dataset in `out` (made with `seed`, `count`
/// samples, stored as `format`). Every sample must be present. Tar shards get no YOLO trees
/// (their samples carry yolo.txt and yolo_obb.txt).
pub fn assemble(
    spec: &DatasetSpec,
    out: &Path,
    count: u64,
    seed: u64,
    format: Format,
) -> Result<Assembled> {
    let categories = spec.categories();
    // README.md, the dataset card, is the mark of a finished assembly: removed first, written
    // last (a run stopped in between leaves it missing, and the next run assembles again).
    let card_path = out.join(CARD);
    // Two runs may assemble at once (shard runs finishing together): every temporary name is
    // the process's own, what one removes the other may already have removed, and both
    // write the same bytes.
    remove_if_there(&card_path, std::fs::remove_file(&card_path))?;
    let anns_path = out.join(format!(
        "annotations.json.annotations-{}",
        xbandsim::products::output::temp_suffix()
    ));
    let mut w = Writer {
        coco: AtomicFile::create(&out.join("annotations.json"))?,
        anns: std::io::BufWriter::new(at(&anns_path, std::fs::File::create(&anns_path))?),
        anns_path,
        targets: AtomicFile::create(&out.join("targets.jsonl"))?,
        baseline: AtomicFile::create(&out.join("baseline.jsonl"))?,
        summary: Assembled {
            labelled_per_category: categories.iter().map(|c| (c.clone(), 0)).collect(),
            ..Default::default()
        },
        annotation_id: 0,
        image_size_px: 0.0,
    };
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
    w.coco.write(
        format!(
            "{{\"info\":{info},\"licenses\":[],\"categories\":{},\"images\":[",
            serde_json::Value::Array(cats)
        )
        .as_bytes(),
    )?;
    match format {
        Format::Dir => assemble_dirs(spec, out, count, seed, &categories, &mut w)?,
        Format::WebDataset { samples_per_shard } => {
            for t in 0..shard_count(count, samples_per_shard) {
                let shard = shard_path(out, t);
                let shard_name = shard_rel(t);
                crate::webdataset::for_each_member(
                    &shard,
                    &is_label_member,
                    &mut |name, bytes| {
                        // <index>[.frame_KKKK].coco.json
                        let (index, rel) = parse_member_name(&name).unwrap_or_default();
                        let frame = frame_of(&rel).unwrap_or(0);
                        if name.ends_with(".coco.json") {
                            w.add_coco(
                                &shard,
                                &bytes,
                                coco_image_id(index, spec.frames, frame),
                                Some(("shard", shard_name.clone().into())),
                            )
                        } else if name.ends_with(".baseline.json") {
                            w.add_baseline(&shard, &bytes)
                        } else {
                            w.add_rows(&bytes)
                        }
                    },
                )?;
            }
        }
    }
    if spec.baseline && w.summary.baseline.samples != count {
        return Err(invalid_data(
            out,
            format!(
                "{} of {count} samples have no baseline.json though the spec asks for one ([dataset] baseline): made by another version? Make the dataset again into a new folder",
                count - w.summary.baseline.samples
            ),
        ));
    }
    let summary = w.finish()?;
    let mut card = AtomicFile::create(&out.join(CARD))?;
    card.write(dataset_card(spec, count, seed, &summary, format).as_bytes())?;
    card.finish()?;
    Ok(summary)
}

/// Staged YOLO trees, deleted when dropped if still there (an assembly that fails part way;
/// a tree renamed into place is no longer at its staged path).
struct StagedTrees(Vec<PathBuf>);

impl Drop for StagedTrees {
    fn drop(&mut self) {
        for dir in &self.0 {
            let _ = std::fs::remove_dir_all(dir);
        }
    }
}

/// The sample folders' labels, and the YOLO trees.
fn assemble_dirs(
    spec: &DatasetSpec,
    out: &Path,
    count: u64,
    seed: u64,
    categories: &[String],
    w: &mut Writer,
) -> Result<()> {
    let trees = ["yolo", "yolo_obb"];
    let staged = StagedTrees(
        trees
            .iter()
            .map(|t| {
                out.join(format!(
                    ".{t}.partial-{}",
                    xbandsim::products::output::temp_suffix()
                ))
            })
            .collect(),
    );
    let staging = &staged.0;
    // Where file times are coarser than the clock, a tree another assembly finishes in the
    // tick this one starts counts as older and is replaced: more work, the same files.
    let started = std::time::SystemTime::now();
    let has_val = (0..count).any(|i| spec.is_validation(i));
    for dir in staging {
        for split in ["train", "val"] {
            for kind in ["images", "labels"] {
                let d = dir.join(kind).join(split);
                at(&d, std::fs::create_dir_all(&d))?;
            }
        }
    }
    for i in 0..count {
        let split = if spec.is_validation(i) {
            "val"
        } else {
            "train"
        };
        for k in 0..spec.frames {
            let frame_dir = sample_dir(out, i).join(frame_subdir(spec.frames, k));
            let coco_path = frame_dir.join("coco.json");
            let bytes = at(&coco_path, std::fs::read(&coco_path))?;
            w.add_coco(&coco_path, &bytes, coco_image_id(i, spec.frames, k), None)?;
            let rows_path = frame_dir.join("targets.jsonl");
            let rows = at(&rows_path, std::fs::read(&rows_path))?;
            w.add_rows(&rows)?;
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
                at(&to, std::fs::copy(&from, &to))?;
            }
        }
        let baseline_path = sample_dir(out, i).join("baseline.json");
        if baseline_path.is_file() {
            let bytes = at(&baseline_path, std::fs::read(&baseline_path))?;
            w.add_baseline(&baseline_path, &bytes)?;
        }
    }
    for ((tree, dir), kind) in trees.iter().zip(staging).zip(["detect", "oriented boxes"]) {
        let yaml = dir.join("data.yaml");
        at(
            &yaml,
            std::fs::write(&yaml, data_yaml(categories, has_val, kind, count, seed)),
        )?;
        put_tree_in_place(dir, &out.join(tree), started)?;
    }
    Ok(())
}

/// Renames the staged tree `staged` to `dest`, replacing what was there before this assembly
/// `started`. A tree whose `data.yaml` (written last into a staged tree) is newer than that
/// was put there meanwhile by another assembly of this same dataset running at once, and
/// holds the same files: it stays, and `staged` is deleted. So any number of assemblies at
/// once leave one whole tree, and one stopped part-way leaves the tree whole or absent.
fn put_tree_in_place(staged: &Path, dest: &Path, started: std::time::SystemTime) -> Result<()> {
    let put_there_meanwhile = || {
        std::fs::metadata(dest.join("data.yaml"))
            .and_then(|m| m.modified())
            .is_ok_and(|t| t >= started)
    };
    let mut last_error = None;
    for _ in 0..8 {
        match std::fs::rename(staged, dest) {
            Ok(()) => return Ok(()),
            Err(_) if put_there_meanwhile() => {
                return remove_if_there(staged, std::fs::remove_dir_all(staged));
            }
            Err(e) => {
                last_error = Some(e);
                // Where the system swaps two paths in one step, the new tree replaces the
                // old one without a moment with neither. The old one, now at the staged path,
                // is deleted; the new one is in place whatever that does (a deletion that
                // fails leaves a staged-looking folder, which a later assembly removes).
                if exchange(staged, dest).is_ok() {
                    let _ = if std::fs::symlink_metadata(staged).is_ok_and(|m| m.is_dir()) {
                        std::fs::remove_dir_all(staged)
                    } else {
                        std::fs::remove_file(staged)
                    };
                    return Ok(());
                }
                // Elsewhere (or on a file system that cannot swap), the old tree (or
                // whatever is there) is moved aside by one rename, then deleted; another
                // assembly may be doing the same: try again.
                let aside = dest.with_file_name(format!(
                    ".{}.old-{}",
                    dest.file_name().unwrap_or_default().to_string_lossy(),
                    xbandsim::products::output::temp_suffix()
                ));
                if std::fs::rename(dest, &aside).is_ok() {
                    let _ = std::fs::remove_dir_all(&aside);
                }
            }
        }
    }
    Err(crate::error::DatasetError::io(
        dest,
        last_error.unwrap_or_else(|| std::io::Error::other("could not be renamed into place")),
    ))
}

/// Swaps the paths `a` and `b` (both must exist) in one step.
#[cfg(target_os = "linux")]
fn exchange(a: &Path, b: &Path) -> std::io::Result<()> {
    use rustix::fs::{renameat_with, RenameFlags, CWD};
    renameat_with(CWD, a, CWD, b, RenameFlags::EXCHANGE).map_err(std::io::Error::from)
}

/// No one-step swap here: the caller moves the old tree aside first.
#[cfg(not(target_os = "linux"))]
fn exchange(_a: &Path, _b: &Path) -> std::io::Result<()> {
    Err(std::io::ErrorKind::Unsupported.into())
}

/// A removal's result, where "already gone" is success.
fn remove_if_there(path: &Path, result: std::io::Result<()>) -> Result<()> {
    match result {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        other => at(path, other),
    }
}

/// The dataset card: what the dataset is, how it was made and what it holds.
fn dataset_card(
    spec: &DatasetSpec,
    count: u64,
    seed: u64,
    s: &Assembled,
    format: Format,
) -> String {
    let format_args = format.cli_args();
    let storage = match format {
        Format::Dir => "a folder per sample under `samples/`; YOLO trees `yolo/` and `yolo_obb/`".to_string(),
        Format::WebDataset { samples_per_shard } => format!(
            "WebDataset tar shards of {samples_per_shard} samples under `shards/` (members `<index>.<file>`), each with a manifest of sha256; every sample carries its yolo.txt and yolo_obb.txt"
        ),
    };
    let mut c = format!(
        "# xbandsim radar dataset\n\n\
         Synthetic X-band marine radar PPI frames with ground truth, made by xbandsim {} \
         (`xbandsim dataset SPEC --count {count} --seed {seed}{format_args}`). Every sample re-renders bit for \
         bit from its `scene.toml` (`xbandsim render scene.toml --seed <its seed>`).\n\n\
         - samples: {count}, frames per sample: {}, images: {}\n\
         - storage: {storage}\n\
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
         (see xbandsim's docs/formats.md, \"Dataset labels\").\n",
    );
    c.push_str(&resolution_section(s));
    c.push_str(&rcs_section(s));
    c.push_str(&s.baseline.markdown());
    c.push_str("\n## Spec\n\n```toml\n");
    c.push_str(spec.text.trim_end());
    c.push_str("\n```\n");
    c
}

/// The card's section on what a detector can tell apart: per range scale and class, the
/// labelled objects' hull and echo lengths on the image and how many hulls are longer than
/// the radar's resolution cell where they are.
fn resolution_section(s: &Assembled) -> String {
    let mut c = String::from(
        "\n## What a detector can tell apart\n\n\
         An echo is smeared over the radar's resolution cell: the azimuth beamwidth times the \
         range across the line of sight, the compressed pulse's `c/(2B)` along it \
         (`resolution_cell_m` in `targets.jsonl`). A hull shorter than that cell leaves an echo \
         whose size and shape are the radar's, not the hull's: classes whose hulls are all \
         smaller than the cell at a range scale differ on that scale only in brightness (their \
         RCS, `rcs_dbsm`), in how the echo fluctuates and moves, and in where they are, not in \
         shape. Where few hulls are resolved, expect a detector to find such targets but not to \
         tell their classes apart; a coarse class set (vessel, buoy or marker, reflector: \
         xbandsim's `datasets/detection-coarse.toml`) is the realistic target there.\n\n\
         | range scale (m) | class | labels | median hull (px) | median echo (px) | hulls longer than the cell |\n\
         |---|---|---|---|---|---|\n",
    );
    for ((scale_bits, class), r) in &s.resolution {
        let _ = writeln!(
            c,
            "| {:.0} | {class} | {} | {:.1} | {:.1} | {:.0} % |",
            f64::from_bits(*scale_bits),
            r.labels,
            r.median_hull_px(),
            r.median_echo_px(),
            100.0 * r.hull_resolved as f64 / r.labels.max(1) as f64
        );
    }
    c
}

/// The card's section on how bright each class is: its free-space RCS over the aspects its
/// targets were seen at.
fn rcs_section(s: &Assembled) -> String {
    let mut c = String::from(
        "\n## RCS by class\n\n\
         Each class's free-space RCS at the aspects its targets were seen at (`rcs_dbsm` and \
         `aspect_deg` in `targets.jsonl`, every row that has one: a target with no free-space \
         return, shadowed or beyond the horizon, has none), read to 0.1 dB; and the median of \
         its RCS over the sea, the free-space RCS times the sea's multipath gain \
         (`rcs_over_sea_dbsm`), which is what the echo's power follows.\n\n\
         | class | rows | 10th percentile (dBsm) | median (dBsm) | 90th percentile (dBsm) | median over the sea (dBsm) |\n\
         |---|---|---|---|---|---|\n",
    );
    let dbsm = |d: &RcsDistribution, q: f64| {
        d.quantile_dbsm(q)
            .map_or_else(|| "-".to_string(), |v| format!("{v:.1}"))
    };
    for (class, d) in &s.rcs {
        let over_sea = s
            .rcs_over_sea
            .get(class)
            .map_or_else(|| "-".to_string(), |o| dbsm(o, 0.5));
        let _ = writeln!(
            c,
            "| {class} | {} | {} | {} | {} | {over_sea} |",
            d.rows,
            dbsm(d, 0.1),
            dbsm(d, 0.5),
            dbsm(d, 0.9)
        );
    }
    c
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The RCS histogram's quantiles against the sorted values they come from (0.1 dB bins:
    /// each quantile is the centre of the bin holding the value at that rank), ends included.
    #[test]
    fn rcs_quantiles_match_the_sorted_values() {
        let values: Vec<f64> = (0..997)
            .map(|i| -40.0 + 90.0 * ((i as f64 * 0.618_034).fract()))
            .chain([-250.0, 300.0])
            .collect();
        let mut d = RcsDistribution::default();
        for &v in &values {
            d.add(v);
        }
        let mut sorted = values.clone();
        sorted.sort_by(f64::total_cmp);
        for q in [0.1, 0.5, 0.9, 1.0] {
            let rank = ((q * sorted.len() as f64).ceil() as usize).max(1) - 1;
            let v = sorted[rank].clamp(
                RCS_LOWEST_DBSM,
                RCS_LOWEST_DBSM + RCS_BINS as f64 / 10.0 - 0.05,
            );
            let centre = RCS_LOWEST_DBSM + (((v - RCS_LOWEST_DBSM) * 10.0).floor() + 0.5) / 10.0;
            assert!(
                (d.quantile_dbsm(q).unwrap() - centre).abs() < 1e-9,
                "q {q}: {:?} against {centre}",
                d.quantile_dbsm(q)
            );
        }
        assert_eq!(
            d.quantile_dbsm(0.0),
            Some(RCS_LOWEST_DBSM + 0.05),
            "the lowest, clamped"
        );
        assert_eq!(RcsDistribution::default().quantile_dbsm(0.5), None);
    }

    /// On Linux the one-step swap exchanges two folders' contents (or says the file system
    /// cannot, and the caller moves the old tree aside instead).
    #[cfg(target_os = "linux")]
    #[test]
    fn exchange_swaps_two_folders() {
        let tmp = tempfile::tempdir().unwrap();
        let (a, b) = (tmp.path().join("a"), tmp.path().join("b"));
        for (dir, text) in [(&a, "new"), (&b, "old")] {
            std::fs::create_dir(dir).unwrap();
            std::fs::write(dir.join("data.yaml"), text).unwrap();
        }
        match exchange(&a, &b) {
            Ok(()) => {
                assert_eq!(std::fs::read_to_string(b.join("data.yaml")).unwrap(), "new");
                assert_eq!(std::fs::read_to_string(a.join("data.yaml")).unwrap(), "old");
            }
            Err(e) => assert!(
                matches!(
                    e.kind(),
                    std::io::ErrorKind::InvalidInput | std::io::ErrorKind::Unsupported
                ),
                "{e}"
            ),
        }
        // Nothing to swap with: an error, and nothing moved.
        assert!(exchange(&a, &tmp.path().join("missing")).is_err());
        assert!(a.join("data.yaml").exists());
    }
}
