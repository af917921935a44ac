//! `xbandsim dataset verify DIR`: which samples of a dataset folder are missing or corrupt.
//! A sample is whole when its folder holds `files.sha256`, every file that list names has
//! that sha256, and the files every frame needs are among them (docs/formats.md, "Dataset
//! directory").

use crate::error::Result;
use crate::layout::{
    frame_file, manifest_line, manifest_path, read_record, sample_dir, sha256_hex, shard_count,
    shard_samples, Format, MANIFEST,
};
use rayon::prelude::*;
use std::path::Path;

/// What `verify` found.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct VerifyReport {
    /// Samples the dataset should hold.
    pub count: u64,
    /// Tar shards (WebDataset format; 0 for sample folders): `missing` and `corrupt` then
    /// name shards, not samples.
    pub shards: u64,
    /// Frames per sample.
    pub frames: u64,
    /// Samples whose folder is missing.
    pub missing: Vec<u64>,
    /// Samples whose files are damaged, with what is wrong.
    pub corrupt: Vec<(u64, String)>,
    /// Index files (annotations.json, targets.jsonl, yolo/, yolo_obb/, README.md) that are
    /// not there.
    pub missing_index_files: Vec<String>,
}

impl VerifyReport {
    /// Every sample and index file in place and whole.
    pub fn is_complete(&self) -> bool {
        self.missing.is_empty() && self.corrupt.is_empty() && self.missing_index_files.is_empty()
    }
}

// Names this module's users reach through it ([`crate::layout`] defines them).
pub use crate::layout::{FRAME_FILES, INDEX_FILES};

/// What is wrong with sample `index` in `out`, if anything (`Ok(None)`: whole).
pub fn check_sample(out: &Path, index: u64, frames: u64) -> Option<String> {
    let dir = sample_dir(out, index);
    let manifest = match std::fs::read_to_string(dir.join(MANIFEST)) {
        Ok(m) => m,
        Err(e) => return Some(format!("{MANIFEST}: {e}")),
    };
    let mut listed = Vec::new();
    for line in manifest.lines() {
        let Some((hash, file)) = manifest_line(line) else {
            return Some(format!("{MANIFEST}: malformed line {line:?}"));
        };
        match std::fs::read(dir.join(file)) {
            Ok(bytes) if sha256_hex(&bytes) == hash => listed.push(file.to_string()),
            Ok(_) => return Some(format!("{file}: sha256 differs from {MANIFEST}")),
            Err(e) => return Some(format!("{file}: {e}")),
        }
    }
    if !listed.iter().any(|f| f == "scene.toml") {
        return Some("scene.toml is not in the sample".into());
    }
    for k in 0..frames {
        let name = |f: &str| frame_file(frames, k, f);
        for f in FRAME_FILES {
            if !listed.contains(&name(f)) {
                return Some(format!("{} is not in the sample", name(f)));
            }
        }
        if !listed.contains(&name("ppi_gray.png")) && !listed.contains(&name("ppi.png")) {
            return Some(format!("{} has no PPI image", name("")));
        }
    }
    None
}

/// Checks every sample of the dataset in `out` (in parallel), calling `sample_done` after
/// each.
pub fn verify(out: &Path, sample_done: &(dyn Fn() + Sync)) -> Result<VerifyReport> {
    let record = read_record(out)?;
    let (count, frames, format) = (record.count, record.frames, record.format);
    if let Format::WebDataset {
        samples_per_shard: per_shard,
    } = format
    {
        let shards = shard_count(count, per_shard);
        let mut report = VerifyReport {
            count,
            shards,
            frames,
            ..Default::default()
        };
        let results: Vec<(u64, Option<Option<String>>)> = (0..shards)
            .into_par_iter()
            .map(|t| {
                let r = manifest_path(out, t)
                    .is_file()
                    .then(|| crate::webdataset::check_shard(out, t));
                for _ in shard_samples(t, per_shard, count) {
                    sample_done();
                }
                (t, r)
            })
            .collect();
        for (t, r) in results {
            match r {
                None => report.missing.push(t),
                Some(Some(problem)) => report.corrupt.push((t, problem)),
                Some(None) => {}
            }
        }
        report.missing_index_files = format
            .index_files()
            .iter()
            .filter(|f| !out.join(f).is_file())
            .map(|f| f.to_string())
            .collect();
        return Ok(report);
    }
    let results: Vec<(u64, Option<Option<String>>)> = (0..count)
        .into_par_iter()
        .map(|i| {
            let r = if sample_dir(out, i).is_dir() {
                Some(check_sample(out, i, frames))
            } else {
                None
            };
            sample_done();
            (i, r)
        })
        .collect();
    let mut report = VerifyReport {
        count,
        frames,
        ..Default::default()
    };
    for (i, r) in results {
        match r {
            None => report.missing.push(i),
            Some(Some(problem)) => report.corrupt.push((i, problem)),
            Some(None) => {}
        }
    }
    report.missing_index_files = format
        .index_files()
        .iter()
        .filter(|f| !out.join(f).is_file())
        .map(|f| f.to_string())
        .collect();
    Ok(report)
}
