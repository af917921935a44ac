//! Generating a dataset into a directory (docs/formats.md, "Dataset directory"):
//!
//! ```text
//! DIR/dataset.json                       the spec, seed, count and software version
//! DIR/samples/000000/000000042/          sample 42 (groups of 1000 samples per folder)
//!     scene.toml                         the scene that renders it, with its render seed
//!     polar.npy ppi.png ppi_gray.png truth.json [doppler_cube.npy]   (one frame), or
//!     frame_0000/ frame_0001/ …          (a sequence, `dataset.frames` > 1)
//! ```
//!
//! A sample is rendered into `DIR/.partial/<index>/` and renamed into place when complete,
//! so a sample folder is either whole or absent: a run stopped at any moment (Ctrl-C,
//! kill -9) and started again skips the finished samples and redoes the rest. Sample i's
//! bytes depend only on (spec, seed, i), so shards, job counts and order do not change them.

use crate::error::{DatasetError, Result};
use crate::spec::DatasetSpec;
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use xbandsim::engine::Outputs;
use xbandsim::products::frame_files::write_frame_files;
use xbandsim::Simulation;

/// Samples per group folder under `samples/`.
pub const SAMPLES_PER_GROUP: u64 = 1000;

/// Which samples a run makes: those with `index % count == index_of_shard`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// This shard, `0..count`.
    pub index: u64,
    /// Number of shards.
    pub count: u64,
}

impl Shard {
    /// The whole dataset.
    pub const ALL: Shard = Shard { index: 0, count: 1 };

    /// Reads `I/K` (0 ≤ I < K).
    pub fn parse(text: &str) -> Result<Shard> {
        let bad = || {
            DatasetError::spec(
                "--shard",
                format!("{text}: expected I/K with 0 <= I < K, e.g. 0/4"),
            )
        };
        let (i, k) = text.split_once('/').ok_or_else(bad)?;
        let index: u64 = i.trim().parse().map_err(|_| bad())?;
        let count: u64 = k.trim().parse().map_err(|_| bad())?;
        if count == 0 || index >= count {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }

    /// Whether sample `i` is this shard's.
    pub fn holds(&self, i: u64) -> bool {
        i % self.count == self.index
    }
}

/// What a run is asked to make.
#[derive(Debug, Clone)]
pub struct Request {
    /// Samples in the whole dataset.
    pub count: u64,
    /// The dataset's seed.
    pub seed: u64,
    /// The part of the dataset this run makes.
    pub shard: Shard,
    /// Samples rendered at once (threads of the run's pool); 0: one per core.
    pub jobs: usize,
}

/// What a run did.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Summary {
    /// Samples of this shard.
    pub in_shard: u64,
    /// Already there from an earlier run, skipped.
    pub skipped: u64,
    /// Made now.
    pub made: u64,
}

/// Folder of sample `index` under `out`.
pub fn sample_dir(out: &Path, index: u64) -> PathBuf {
    out.join("samples")
        .join(format!("{:06}", index / SAMPLES_PER_GROUP))
        .join(format!("{index:09}"))
}

/// The record of what the dataset is, `dataset.json`: the same spec, seed and count give the
/// same bytes, so separate shard runs into one folder agree.
fn dataset_record(spec: &DatasetSpec, request: &Request) -> Result<Vec<u8>> {
    let record = serde_json::json!({
        "generator": format!("xbandsim {}", env!("CARGO_PKG_VERSION")),
        "count": request.count,
        "seed": request.seed,
        "frames_per_sample": spec.frames,
        "layout": "samples/<index / 1000 as 6 digits>/<index as 9 digits>/",
        "spec": spec.text,
    });
    serde_json::to_vec_pretty(&record)
        .map(|mut v| {
            v.push(b'\n');
            v
        })
        .map_err(|e| DatasetError::spec("(record)", e.to_string()))
}

fn write_new(path: &Path, bytes: &[u8]) -> Result<()> {
    xbandsim::products::output::write_atomic(path, bytes).map_err(|e| match e {
        xbandsim::Error::Io { error, .. } => DatasetError::io(path, error),
        other => DatasetError::io(path, std::io::Error::other(other.to_string())),
    })
}

/// Makes the samples of `request.shard` that are not in `out` yet, `request.jobs` at a time,
/// calling `sample_done` after each (from the workers). Refuses a folder that holds another
/// dataset (different spec, seed or count).
pub fn generate(
    spec: &DatasetSpec,
    out: &Path,
    request: &Request,
    sample_done: &(dyn Fn() + Sync),
) -> Result<Summary> {
    if request.count == 0 {
        return Err(DatasetError::spec(
            "--count",
            "0: a dataset needs at least one sample".into(),
        ));
    }
    std::fs::create_dir_all(out).map_err(|e| DatasetError::io(out, e))?;
    let record = dataset_record(spec, request)?;
    let record_path = out.join("dataset.json");
    match std::fs::read(&record_path) {
        Ok(existing) if existing != record => {
            return Err(DatasetError::Mismatch {
                path: record_path,
                message: "this folder holds a dataset made with another spec, seed or count; use a new --out folder (or delete this one)".into(),
            })
        }
        Ok(_) => {}
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => write_new(&record_path, &record)?,
        Err(e) => return Err(DatasetError::io(&record_path, e)),
    }
    let indices: Vec<u64> = (0..request.count)
        .filter(|&i| request.shard.holds(i))
        .collect();
    let pending: Vec<u64> = indices
        .iter()
        .copied()
        .filter(|&i| !sample_dir(out, i).is_dir())
        .collect();
    let summary = Summary {
        in_shard: indices.len() as u64,
        skipped: (indices.len() - pending.len()) as u64,
        made: pending.len() as u64,
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(request.jobs)
        .build()
        .map_err(|e| DatasetError::spec("--jobs", e.to_string()))?;
    pool.install(|| {
        pending.par_iter().try_for_each(|&i| {
            make_sample(spec, out, request.seed, i)?;
            sample_done();
            Ok(())
        })
    })?;
    Ok(summary)
}

/// Renders sample `index` into `out/.partial/<index>/` and renames it into place.
pub fn make_sample(spec: &DatasetSpec, out: &Path, seed: u64, index: u64) -> Result<()> {
    let sample = spec.sample(seed, index)?;
    let partial = out.join(".partial").join(format!("{index:09}"));
    if partial.exists() {
        std::fs::remove_dir_all(&partial).map_err(|e| DatasetError::io(&partial, e))?;
    }
    std::fs::create_dir_all(&partial).map_err(|e| DatasetError::io(&partial, e))?;
    let scene_err = |source| DatasetError::Scene { index, source };
    let loaded = xbandsim::LoadedSpec::from_toml(&sample.scene_toml, "scene.toml", &spec.base_dir)
        .map_err(scene_err)?;
    let scene = loaded.build().map_err(scene_err)?;
    let display = loaded.ppi_settings().map_err(scene_err)?;
    let sim = Simulation::new(scene);
    let outputs = Outputs {
        doppler_cube: spec.datacube,
        radial_velocity: display.doppler_colour,
        ..Default::default()
    };
    let name = format!("sample {index}");
    for k in 0..spec.frames {
        let frame = sim
            .render_frame_outputs(sample.render_seed, k, outputs, &|| {})
            .map_err(scene_err)?;
        let dir = if spec.frames == 1 {
            partial.clone()
        } else {
            partial.join(format!("frame_{k:04}"))
        };
        write_frame_files(
            sim.scene().radar(),
            &display,
            &frame,
            &dir,
            &name,
            sample.render_seed,
        )
        .map_err(scene_err)?;
    }
    let header = format!(
        "# xbandsim dataset sample {index}: re-render with\n#   xbandsim render scene.toml --seed {}{}\n",
        sample.render_seed,
        if spec.frames > 1 {
            format!(" --frames {}", spec.frames)
        } else {
            String::new()
        }
    );
    write_new(
        &partial.join("scene.toml"),
        format!("{header}{}", sample.scene_toml).as_bytes(),
    )?;
    let dest = sample_dir(out, index);
    let parent = dest.parent().unwrap_or(out);
    std::fs::create_dir_all(parent).map_err(|e| DatasetError::io(parent, e))?;
    match std::fs::rename(&partial, &dest) {
        Ok(()) => Ok(()),
        // Another run made it meanwhile (the same bytes): keep theirs.
        Err(_) if dest.is_dir() => {
            std::fs::remove_dir_all(&partial).map_err(|e| DatasetError::io(&partial, e))
        }
        Err(e) => Err(DatasetError::io(&dest, e)),
    }
}
