//! `xbandsim dataset stats DIR`: what a dataset holds (objects and labels per class, the
//! expected-SNR histogram, visibility fractions) from its samples' targets tables, and a
//! contact sheet of random samples with their boxes drawn.

use crate::baseline::BaselineTally;
use crate::error::{invalid_data, DatasetError, Result};
use crate::layout::{
    frame_file, manifest_path, member_name, missing_samples, read_record, sample_dir, shard_count,
    shard_path, shard_samples, Format, CARD,
};
use rand::seq::SliceRandom;
use rand::SeedableRng;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

/// Lower edges of the SNR histogram's bins, dB (the first bin holds everything below 0 dB,
/// the last everything from 60 dB up).
pub const SNR_BIN_EDGES_DB: [f64; 7] = [0.0, 10.0, 20.0, 30.0, 40.0, 50.0, 60.0];

/// Counts over a dataset's targets tables.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Stats {
    /// Samples in the whole dataset (its record's count).
    pub count: u64,
    /// Samples present (all of them once the dataset is complete).
    pub samples: u64,
    /// Whether the index files are written (README.md, the last of them, is there): with
    /// every sample present, the dataset is complete.
    pub indexed: bool,
    /// Frames read.
    pub frames: u64,
    /// Per class: (objects, detection labels).
    pub per_class: BTreeMap<String, (u64, u64)>,
    /// Objects per visibility reason.
    pub per_visibility: BTreeMap<String, u64>,
    /// Expected SNR histogram: below 0 dB, then one bin per [`SNR_BIN_EDGES_DB`] edge.
    pub snr_histogram: [u64; 8],
    /// Objects without an expected SNR (no calibrated return).
    pub snr_null: u64,
    /// Frames with no detection label.
    pub empty_frames: u64,
    /// The classical baseline's results ([`crate::baseline`]).
    pub baseline: BaselineTally,
}

impl Stats {
    /// The report `xbandsim dataset stats` prints.
    pub fn report(&self) -> String {
        let objects: u64 = self.per_class.values().map(|v| v.0).sum();
        let labelled: u64 = self.per_class.values().map(|v| v.1).sum();
        let mut s = String::new();
        if let Some(note) = self.unfinished() {
            let _ = writeln!(s, "{note}\n");
        }
        let _ = write!(
            s,
            "{} samples, {} frames ({} with no detection label), {objects} objects, {labelled} labelled\n\nclass                 objects  labelled\n",
            self.samples, self.frames, self.empty_frames
        );
        for (c, (n, l)) in &self.per_class {
            let _ = writeln!(s, "{c:<20} {n:>8} {l:>9}");
        }
        s.push_str("\nvisibility              objects  fraction\n");
        for (v, n) in &self.per_visibility {
            let _ = writeln!(
                s,
                "{v:<20} {n:>10} {:>9.3}",
                *n as f64 / objects.max(1) as f64
            );
        }
        s.push_str("\nexpected SNR, dB        objects\n");
        let peak = self.snr_histogram.iter().copied().max().unwrap_or(0).max(1);
        for (i, n) in self.snr_histogram.iter().enumerate() {
            let label = match i {
                0 => "< 0".to_string(),
                7 => ">= 60".to_string(),
                _ => format!(
                    "{:.0} to {:.0}",
                    SNR_BIN_EDGES_DB[i - 1],
                    SNR_BIN_EDGES_DB[i]
                ),
            };
            let bar = "#".repeat((40 * n / peak) as usize);
            let _ = writeln!(s, "{label:<14} {n:>10}  {bar}");
        }
        let _ = writeln!(s, "{:<14} {:>10}", "null", self.snr_null);
        s.push('\n');
        if self.baseline.samples > 0 && self.baseline.samples < self.samples {
            let _ = writeln!(
                s,
                "(the baseline below covers the {} of the {} samples present that have a baseline.json)",
                self.baseline.samples, self.samples
            );
        }
        s.push_str(&self.baseline.report());
        s
    }
}

impl Stats {
    /// What is unfinished about the dataset, if anything: the samples missing, or the index
    /// files, and how to finish it (the same command again resumes it).
    pub fn unfinished(&self) -> Option<String> {
        let missing = self.count.saturating_sub(self.samples);
        if missing > 0 {
            let index = if self.indexed {
                "the index files are from before they went"
            } else {
                "the index files are not written"
            };
            Some(format!(
                "unfinished: {missing} of {} samples are missing and {index}; these figures cover the {} samples present (to finish it, run `xbandsim dataset` with its spec, --out, --count and --seed again, without --shard and --no-assemble, or the same xbandsim.dataset.generate call)",
                self.count, self.samples
            ))
        } else if !self.indexed {
            Some("unfinished: every sample is there but the index files (annotations.json, targets.jsonl, README.md) are not written (run `xbandsim dataset` with its spec, --out, --count and --seed again, without --no-assemble, to write them)".to_string())
        } else {
            None
        }
    }
}

/// The sample count and frames per sample of the dataset in `out`, from its dataset.json
/// ([`read_record`]).
pub fn record(out: &Path) -> Result<(u64, u64)> {
    record_format(out).map(|(c, f, _)| (c, f))
}

/// The sample count, frames per sample and storage format of the dataset in `out`
/// ([`read_record`]).
pub fn record_format(out: &Path) -> Result<(u64, u64, Format)> {
    read_record(out).map(|r| (r.count, r.frames, r.format))
}

impl Stats {
    fn add_rows(&mut self, path: &Path, text: &str) -> Result<bool> {
        let mut any = false;
        for line in text.lines().filter(|l| !l.is_empty()) {
            let row: serde_json::Value =
                serde_json::from_str(line).map_err(|e| invalid_data(path, e.to_string()))?;
            self.baseline.add_row(&row);
            let labelled = row["labelled"].as_bool().unwrap_or(false);
            any |= labelled;
            let entry = self
                .per_class
                .entry(row["class"].as_str().unwrap_or("?").to_string())
                .or_default();
            entry.0 += 1;
            entry.1 += u64::from(labelled);
            *self
                .per_visibility
                .entry(row["visibility"].as_str().unwrap_or("?").to_string())
                .or_default() += 1;
            match row["expected_snr_db"].as_f64() {
                None => self.snr_null += 1,
                Some(snr) => {
                    let bin = SNR_BIN_EDGES_DB.iter().filter(|&&e| snr >= e).count();
                    self.snr_histogram[bin] += 1;
                }
            }
        }
        Ok(any)
    }
}

impl Stats {
    /// Adds baseline.json lines (one sample's file, or baseline.jsonl's lines).
    fn add_baselines(&mut self, path: &Path, text: &str) -> Result<()> {
        for line in text.lines().filter(|l| !l.is_empty()) {
            let v: serde_json::Value =
                serde_json::from_str(line).map_err(|e| invalid_data(path, e.to_string()))?;
            self.baseline
                .add_sample(&v)
                .map_err(|e| invalid_data(path, e))?;
        }
        Ok(())
    }
}

/// Counts over every present sample of the dataset in `out` (tar shards: over the targets
/// tables of the finished shards), saying how many samples are missing
/// ([`Stats::unfinished`]).
pub fn stats(out: &Path) -> Result<Stats> {
    let (count, frames_per_sample, format) = record_format(out)?;
    let frames = frames_per_sample;
    let mut s = Stats {
        count,
        indexed: out.join(CARD).is_file(),
        ..Stats::default()
    };
    let add_frame = |s: &mut Stats, path: &Path, text: &str| -> Result<()> {
        s.frames += 1;
        if !s.add_rows(path, text)? {
            s.empty_frames += 1;
        }
        Ok(())
    };
    match format {
        // A finished dataset's table holds every row: read it, not the shards.
        Format::WebDataset { samples_per_shard }
            if s.indexed && missing_samples(out, count, samples_per_shard) == 0 =>
        {
            let path = out.join("targets.jsonl");
            let text = std::fs::read_to_string(&path).map_err(|e| DatasetError::io(&path, e))?;
            let mut frames: BTreeMap<(u64, u64), String> = BTreeMap::new();
            for line in text.lines().filter(|l| !l.is_empty()) {
                let row: serde_json::Value =
                    serde_json::from_str(line).map_err(|e| invalid_data(&path, e.to_string()))?;
                let key = (
                    row["sample"].as_u64().unwrap_or(0),
                    row["frame"].as_u64().unwrap_or(0),
                );
                let rows = frames.entry(key).or_default();
                rows.push_str(line);
                rows.push('\n');
            }
            let path = out.join("baseline.jsonl");
            if path.is_file() {
                let text =
                    std::fs::read_to_string(&path).map_err(|e| DatasetError::io(&path, e))?;
                s.add_baselines(&path, &text)?;
            }
            let path = out.join("targets.jsonl");
            s.samples = count;
            for sample in 0..count {
                for k in 0..frames_per_sample {
                    let rows = frames.remove(&(sample, k)).unwrap_or_default();
                    add_frame(&mut s, &path, &rows)?;
                }
            }
        }
        Format::WebDataset { samples_per_shard } => {
            let shards = shard_count(count, samples_per_shard);
            for t in 0..shards {
                if !manifest_path(out, t).is_file() {
                    continue;
                }
                let path = shard_path(out, t);
                s.samples += shard_samples(t, samples_per_shard, count).count() as u64;
                crate::webdataset::for_each_member(
                    &path,
                    &|name| name.ends_with(".targets.jsonl") || name.ends_with(".baseline.json"),
                    &mut |name, bytes| {
                        let text = String::from_utf8_lossy(&bytes);
                        if name.ends_with(".baseline.json") {
                            s.add_baselines(&path, &text)
                        } else {
                            add_frame(&mut s, &path, &text)
                        }
                    },
                )?;
            }
        }
        Format::Dir => {
            for i in 0..count {
                let dir = sample_dir(out, i);
                if !dir.is_dir() {
                    continue;
                }
                s.samples += 1;
                let path = dir.join("baseline.json");
                if path.is_file() {
                    let text =
                        std::fs::read_to_string(&path).map_err(|e| DatasetError::io(&path, e))?;
                    s.add_baselines(&path, &text)?;
                }
                for k in 0..frames {
                    let path = dir.join(frame_file(frames, k, "targets.jsonl"));
                    let text =
                        std::fs::read_to_string(&path).map_err(|e| DatasetError::io(&path, e))?;
                    add_frame(&mut s, &path, &text)?;
                }
            }
        }
    }
    Ok(s)
}

/// A colour per category for boxes.
fn category_colour(category: u64) -> [u8; 3] {
    const PALETTE: [[u8; 3]; 8] = [
        [255, 64, 64],
        [64, 255, 64],
        [80, 140, 255],
        [255, 220, 0],
        [255, 64, 255],
        [0, 230, 230],
        [255, 150, 40],
        [200, 200, 200],
    ];
    PALETTE[(category as usize) % PALETTE.len()]
}

/// Decodes an 8-bit gray or RGB PNG (`path` names it in errors) into RGB.
fn read_rgb(path: &Path, png_bytes: &[u8]) -> Result<(usize, usize, Vec<u8>)> {
    let mut reader = png::Decoder::new(std::io::Cursor::new(png_bytes))
        .read_info()
        .map_err(|e| invalid_data(path, e.to_string()))?;
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader
        .next_frame(&mut buf)
        .map_err(|e| invalid_data(path, e.to_string()))?;
    let (w, h) = (info.width as usize, info.height as usize);
    let rgb = match (info.color_type, info.bit_depth) {
        (png::ColorType::Grayscale, png::BitDepth::Eight) => {
            buf[..w * h].iter().flat_map(|&g| [g, g, g]).collect()
        }
        (png::ColorType::Rgb, png::BitDepth::Eight) => buf[..w * h * 3].to_vec(),
        other => {
            return Err(invalid_data(
                path,
                format!("unexpected PNG format {other:?}"),
            ))
        }
    };
    Ok((w, h, rgb))
}

/// Draws a contact sheet of `n` samples of `out` chosen at random (`seed`), frame 0 of each,
/// with every detection box in its category's colour, tiles of `tile_px`, into PNG bytes.
/// Returns the bytes and the samples shown.
pub fn contact_sheet(
    out: &Path,
    n: usize,
    tile_px: usize,
    seed: u64,
) -> Result<(Vec<u8>, Vec<u64>)> {
    let (count, frames, format) = record_format(out)?;
    let mut present: Vec<u64> = match format {
        Format::Dir => (0..count)
            .filter(|&i| sample_dir(out, i).is_dir())
            .collect(),
        Format::WebDataset { samples_per_shard } => (0..count)
            .filter(|&i| manifest_path(out, i / samples_per_shard).is_file())
            .collect(),
    };
    present.shuffle(&mut rand_pcg::Pcg64Mcg::seed_from_u64(seed));
    present.truncate(n.max(1));
    present.sort_unstable();
    // Each chosen sample's first frame: its coco.json fragment and image bytes.
    let rel = |f: &str| frame_file(frames, 0, f);
    let mut inputs: Vec<(u64, Vec<u8>, Option<Vec<u8>>)> = Vec::new();
    match format {
        Format::Dir => {
            for &i in &present {
                let p = sample_dir(out, i).join(rel("coco.json"));
                let coco = std::fs::read(&p).map_err(|e| DatasetError::io(&p, e))?;
                inputs.push((i, coco, None));
            }
        }
        Format::WebDataset { samples_per_shard } => {
            let mut by_shard: BTreeMap<u64, Vec<u64>> = BTreeMap::new();
            for &i in &present {
                by_shard.entry(i / samples_per_shard).or_default().push(i);
            }
            for (t, list) in by_shard {
                let names: Vec<String> = list
                    .iter()
                    .map(|&i| member_name(i, &rel("coco.json")))
                    .collect();
                let mut cocos: BTreeMap<String, Vec<u8>> = BTreeMap::new();
                let shard = shard_path(out, t);
                crate::webdataset::for_each_member(
                    &shard,
                    &|m| names.iter().any(|n| n == m),
                    &mut |name, bytes| {
                        cocos.insert(name, bytes);
                        Ok(())
                    },
                )?;
                let mut images: BTreeMap<String, Vec<u8>> = BTreeMap::new();
                let wanted: Vec<String> = cocos
                    .values()
                    .filter_map(|b| serde_json::from_slice::<serde_json::Value>(b).ok())
                    .filter_map(|v| v["image"]["file_name"].as_str().map(String::from))
                    .collect();
                crate::webdataset::for_each_member(
                    &shard,
                    &|m| wanted.iter().any(|n| n == m),
                    &mut |name, bytes| {
                        images.insert(name, bytes);
                        Ok(())
                    },
                )?;
                for (&i, name) in list.iter().zip(&names) {
                    let coco = cocos.remove(name).ok_or_else(|| {
                        invalid_data(&shard, format!("{name} is not in the shard"))
                    })?;
                    let image = serde_json::from_slice::<serde_json::Value>(&coco)
                        .ok()
                        .and_then(|v| v["image"]["file_name"].as_str().map(String::from))
                        .and_then(|f| images.remove(&f));
                    inputs.push((i, coco, image));
                }
            }
        }
    }
    let cols = (present.len() as f64).sqrt().ceil().max(1.0) as usize;
    let rows = present.len().div_ceil(cols).max(1);
    let (sw, sh) = (cols * tile_px, rows * tile_px);
    let mut sheet = vec![0u8; sw * sh * 3];
    for (t, (i, coco, image_bytes)) in inputs.into_iter().enumerate() {
        let fragment_path = sample_dir(out, i).join(rel("coco.json"));
        let fragment: serde_json::Value = serde_json::from_slice(&coco)
            .map_err(|e| invalid_data(&fragment_path, e.to_string()))?;
        let image = fragment["image"]["file_name"].as_str().unwrap_or_default();
        let image_path = out.join(image);
        let bytes = match image_bytes {
            Some(b) => b,
            None => std::fs::read(&image_path).map_err(|e| DatasetError::io(&image_path, e))?,
        };
        let (w, h, rgb) = read_rgb(&image_path, &bytes)?;
        let (ox, oy) = ((t % cols) * tile_px, (t / cols) * tile_px);
        let scale = w.max(h) as f64 / tile_px as f64;
        // Nearest-pixel scaling of the image into its tile.
        for y in 0..tile_px {
            for x in 0..tile_px {
                let (sx, sy) = ((x as f64 * scale) as usize, (y as f64 * scale) as usize);
                if sx < w && sy < h {
                    let src = (sy * w + sx) * 3;
                    let dst = ((oy + y) * sw + ox + x) * 3;
                    sheet[dst..dst + 3].copy_from_slice(&rgb[src..src + 3]);
                }
            }
        }
        let mut put = |x: f64, y: f64, c: [u8; 3]| {
            let (x, y) = ((x / scale) as isize, (y / scale) as isize);
            if (0..tile_px as isize).contains(&x) && (0..tile_px as isize).contains(&y) {
                let dst = ((oy + y as usize) * sw + ox + x as usize) * 3;
                sheet[dst..dst + 3].copy_from_slice(&c);
            }
        };
        for a in fragment["annotations"].as_array().into_iter().flatten() {
            let c = category_colour(a["category_id"].as_u64().unwrap_or(0));
            let b: Vec<f64> = a["bbox"]
                .as_array()
                .into_iter()
                .flatten()
                .filter_map(|v| v.as_f64())
                .collect();
            if b.len() != 4 {
                continue;
            }
            // One tile pixel outside the box, so the echo stays visible.
            let pad = scale;
            let (x0, y0, x1, y1) = (b[0] - pad, b[1] - pad, b[0] + b[2] + pad, b[1] + b[3] + pad);
            let steps = ((x1 - x0).max(y1 - y0) / scale * 2.0).ceil().max(2.0) as usize;
            for s in 0..=steps {
                let f = s as f64 / steps as f64;
                put(x0 + f * (x1 - x0), y0, c);
                put(x0 + f * (x1 - x0), y1, c);
                put(x0, y0 + f * (y1 - y0), c);
                put(x1, y0 + f * (y1 - y0), c);
            }
        }
        // A one-pixel gray frame between tiles.
        for k in 0..tile_px {
            for (x, y) in [(ox + k, oy), (ox, oy + k)] {
                let dst = (y * sw + x) * 3;
                sheet[dst..dst + 3].copy_from_slice(&[90, 90, 90]);
            }
        }
    }
    let png = xbandsim::products::output::png_bytes(
        &out.join("contact_sheet.png"),
        sw as u32,
        sh as u32,
        3,
        &sheet,
    )
    .map_err(|e| invalid_data(&out.join("contact_sheet.png"), e.to_string()))?;
    Ok((png, present))
}
