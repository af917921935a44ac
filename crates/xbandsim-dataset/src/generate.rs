//! Generating a dataset into a directory (docs/formats.md, "Dataset directory"), as sample
//! folders ([`Format::Dir`]) or WebDataset tar shards ([`Format::WebDataset`],
//! [`crate::webdataset`]); the names and paths are [`crate::layout`]'s, a sample's files
//! [`crate::render`]'s:
//!
//! ```text
//! DIR/dataset.json                       the spec, seed, count and software version
//! DIR/samples/000000/000000042/          sample 42 (groups of 1000 samples per folder)
//!     scene.toml                         the scene that renders it, with its render seed
//!     polar.npy ppi.png ppi_gray.png truth.json [doppler_cube.npy]   (one frame), or
//!     frame_0000/ frame_0001/ …          (a sequence, `dataset.frames` > 1)
//! ```
//!
//! A sample is rendered into `DIR/.partial/<index>-<process tag>/` and renamed into place
//! when complete,
//! so a sample folder is either whole or absent: a run stopped at any moment (Ctrl-C,
//! kill -9) and started again skips the finished samples and redoes the rest. Sample i's
//! bytes depend only on (spec, seed, i), so shards, job counts and order do not change them.

use crate::error::{DatasetError, Result};
use crate::layout::{
    missing_samples, record_bytes, sample_manifest, shard_count, shard_samples, RECORD,
};
use crate::spec::DatasetSpec;
use rayon::prelude::*;
use std::path::Path;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

// Names a run's callers reach through this module: the layout's ([`crate::layout`]) and a
// sample's rendering ([`crate::render`]), both modules below this one.
pub use crate::layout::{
    frame_subdir, hex, sample_dir, sha256_hex, Format, MANIFEST, SAMPLES_PER_GROUP,
};
pub use crate::render::{render_sample, SampleFiles};

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
            DatasetError::argument(
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

    /// Reads `I/K`, where I may also be `k8s` (the index from `JOB_COMPLETION_INDEX`, which a
    /// Kubernetes Indexed Job sets in each pod) or `slurm` (`SLURM_ARRAY_TASK_ID`: a Slurm
    /// job array's task, submitted as `--array=0-(K-1)`; a resubmission of some tasks,
    /// `--array=3,7`, makes those same shards). `env` looks a variable up (the CLI passes the
    /// process environment); a missing or non-numeric variable is an error naming it.
    pub fn resolve(text: &str, env: &dyn Fn(&str) -> Option<String>) -> Result<Shard> {
        let Some((from, k)) = text.split_once('/') else {
            return Shard::parse(text);
        };
        let variable = match from.trim() {
            "k8s" => (
                "JOB_COMPLETION_INDEX",
                "a Kubernetes Indexed Job sets it in each pod",
            ),
            "slurm" => (
                "SLURM_ARRAY_TASK_ID",
                "a Slurm job array sets it in each task",
            ),
            _ => return Shard::parse(text),
        };
        let count: u64 = match k.trim().parse() {
            Ok(k) if k > 0 => k,
            _ => {
                return Err(DatasetError::argument(
                    "--shard",
                    format!("{text}: the shard count {k:?} must be a whole number above 0"),
                ))
            }
        };
        let (name, why) = variable;
        let value = env(name).ok_or_else(|| {
            DatasetError::argument("--shard", format!("{text}: {name} is not set ({why})"))
        })?;
        let index: u64 = value.trim().parse().map_err(|_| {
            DatasetError::argument(
                "--shard",
                format!("{text}: {name} = {value:?} is not a whole number"),
            )
        })?;
        if index >= count {
            return Err(DatasetError::argument(
                "--shard",
                format!(
                    "{text}: {name} = {index} is not below the shard count {count} (number the tasks 0 … {})",
                    count - 1
                ),
            ));
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
    /// How the samples are stored.
    pub format: Format,
    /// Whether this run writes the index files when it finds the dataset complete (the
    /// default). Off, it makes its shard's samples only and does not look at the others':
    /// for runs of many shards at once, with one run without `--shard` (or with this on)
    /// after them all (`xbandsim dataset --no-assemble`, `xbandsim.distributed`).
    pub assemble: bool,
}

/// Most samples rendered at once per core: more only adds memory (about 0.3 GB a 512²
/// sample) and threads, not speed, as a sample keeps its core busy.
pub const MAX_JOBS_PER_CORE: usize = 4;

impl Request {
    /// The threads the run renders with: `jobs`, or one per core for 0, and at most
    /// [`MAX_JOBS_PER_CORE`] per core (the samples' bytes do not depend on it).
    pub fn worker_threads(&self) -> usize {
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        if self.jobs == 0 {
            cores
        } else {
            self.jobs.min(MAX_JOBS_PER_CORE * cores)
        }
    }

    /// The tar shards this run's shard makes (tar shard t belongs to run `t mod K`), in order.
    pub fn tar_shards(&self, samples_per_shard: u64) -> Vec<u64> {
        (0..shard_count(self.count, samples_per_shard))
            .filter(|&t| self.shard.holds(t))
            .collect()
    }

    /// Samples this run's shard holds: samples `i mod K = I` in folders, the samples of tar
    /// shards `t mod K = I` in WebDataset shards.
    pub fn samples_in_shard(&self) -> u64 {
        match self.format {
            Format::Dir => (0..self.count).filter(|&i| self.shard.holds(i)).count() as u64,
            Format::WebDataset { samples_per_shard } => self
                .tar_shards(samples_per_shard)
                .into_iter()
                .map(|t| shard_samples(t, samples_per_shard, self.count).count() as u64)
                .sum(),
        }
    }
}

/// What a run did.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Summary {
    /// Samples of this shard.
    pub in_shard: u64,
    /// Already there from an earlier run, skipped.
    pub skipped: u64,
    /// Made now.
    pub made: u64,
    /// Samples of the whole dataset still missing (other shards'); with
    /// [`Request::assemble`] off, only this shard's are counted.
    pub missing: u64,
    /// The index files, when the dataset is complete and they were (re)written.
    pub assembled: Option<crate::assemble::Assembled>,
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
    generate_until(spec, out, request, sample_done, &AtomicBool::new(false))
}

/// [`generate`], stopping early once `stop` is set (by another thread, e.g. on Ctrl-C): no
/// sample is started after that, the sample folders being rendered are finished and written
/// whole (a sample takes well under a second at the shipped sizes; in tar shards, the shard
/// in progress is dropped after the samples in hand), the index files are not written, and
/// the run returns [`DatasetError::Interrupted`]. The folder is then as a killed run leaves
/// it, without its temporary files: the same request resumes it.
pub fn generate_until(
    spec: &DatasetSpec,
    out: &Path,
    request: &Request,
    sample_done: &(dyn Fn() + Sync),
    stop: &AtomicBool,
) -> Result<Summary> {
    if request.count == 0 {
        return Err(DatasetError::argument(
            "--count",
            "0: a dataset needs at least one sample".into(),
        ));
    }
    if request.format
        == (Format::WebDataset {
            samples_per_shard: 0,
        })
    {
        return Err(DatasetError::argument(
            "--shard-samples",
            "0: a shard needs at least one sample".into(),
        ));
    }
    std::fs::create_dir_all(out).map_err(|e| DatasetError::io(out, e))?;
    // While this run lives its temporaries are its own (crate::owner).
    let _owner = crate::owner::Owner::claim(out)?;
    let record = record_bytes(
        &spec.text,
        spec.frames,
        request.count,
        request.seed,
        request.format,
    )?;
    let record_path = out.join(RECORD);
    match std::fs::read(&record_path) {
        Ok(existing) if existing != record => {
            return Err(DatasetError::Mismatch {
                path: record_path,
                message: "this folder holds a dataset made with another spec, seed, count or format; use a new --out folder (or delete this one)".into(),
            })
        }
        Ok(_) => {}
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => write_new(&record_path, &record)?,
        Err(e) => return Err(DatasetError::io(&record_path, e)),
    }
    // The folder holds this dataset: what runs that are gone left half-written goes now.
    crate::owner::clean(out);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(request.worker_threads())
        .build()
        .map_err(|e| DatasetError::argument("--jobs", e.to_string()))?;
    // Every scene this run will draw is checked before the first is rendered.
    let pending = match request.format {
        Format::Dir => pending_dir_samples(out, request),
        Format::WebDataset { samples_per_shard } => crate::webdataset::pending_samples(
            out,
            request.count,
            samples_per_shard,
            &request.tar_shards(samples_per_shard),
        ),
    };
    pool.install(|| crate::check::check_samples(spec, request.seed, &pending, stop))?;
    let mut summary = match request.format {
        Format::Dir => pool.install(|| make_dir_samples(spec, out, request, sample_done, stop))?,
        Format::WebDataset { samples_per_shard } => {
            let shards = request.tar_shards(samples_per_shard);
            let made = pool.install(|| {
                crate::webdataset::make_shards(
                    spec,
                    out,
                    (request.seed, request.count, samples_per_shard),
                    &shards,
                    sample_done,
                    stop,
                )
            })?;
            Summary {
                in_shard: made.in_shards,
                skipped: made.skipped,
                made: made.made,
                ..Default::default()
            }
        }
    };
    if !request.assemble {
        summary.missing = summary.in_shard - summary.skipped - summary.made;
        return Ok(summary);
    }
    if stop.load(Ordering::Relaxed) {
        return Err(DatasetError::Interrupted { made: summary.made });
    }
    // The index files, once every sample of every shard is in place.
    summary.missing = match request.format {
        Format::Dir => (0..request.count)
            .filter(|&i| !sample_dir(out, i).is_dir())
            .count() as u64,
        Format::WebDataset { samples_per_shard } => {
            missing_samples(out, request.count, samples_per_shard)
        }
    };
    // README.md is written last by the assembly (crate::assemble): without it the index
    // files are missing or unfinished.
    if summary.missing == 0 && (summary.made > 0 || !out.join("README.md").is_file()) {
        crate::owner::clean(out);
        summary.assembled = Some(crate::assemble::assemble(
            spec,
            out,
            request.count,
            request.seed,
            request.format,
        )?);
    }
    Ok(summary)
}

/// The samples of the run's shard not in `out` yet, in index order.
fn pending_dir_samples(out: &Path, request: &Request) -> Vec<u64> {
    (0..request.count)
        .filter(|&i| request.shard.holds(i) && !sample_dir(out, i).is_dir())
        .collect()
}

fn make_dir_samples(
    spec: &DatasetSpec,
    out: &Path,
    request: &Request,
    sample_done: &(dyn Fn() + Sync),
    stop: &AtomicBool,
) -> Result<Summary> {
    let in_shard = (0..request.count)
        .filter(|&i| request.shard.holds(i))
        .count();
    let pending = pending_dir_samples(out, request);
    // Once stopped, the samples not started are skipped (not failed: a real error of a
    // sample in hand is the one reported), and the run says how many it made.
    let made = AtomicU64::new(0);
    pending.par_iter().try_for_each(|&i| {
        if stop.load(Ordering::Relaxed) {
            return Ok(());
        }
        make_sample(spec, out, request.seed, i)?;
        made.fetch_add(1, Ordering::Relaxed);
        sample_done();
        Ok::<(), DatasetError>(())
    })?;
    let made = made.into_inner();
    if made < pending.len() as u64 {
        return Err(DatasetError::Interrupted { made });
    }
    Ok(Summary {
        in_shard: in_shard as u64,
        skipped: (in_shard - pending.len()) as u64,
        made: pending.len() as u64,
        ..Default::default()
    })
}

/// Renders sample `index` ([`render_sample`]) into `out/.partial/<index>-<tag>/` with its
/// files.sha256 (the sha256 of every other file, in `sha256sum -c` form, written last) and
/// renames it into place.
pub fn make_sample(spec: &DatasetSpec, out: &Path, seed: u64, index: u64) -> Result<()> {
    let written = render_sample(spec, seed, index, Format::Dir)?;
    // Named for this process: two runs of one shard at once (a retried pod beside one still
    // terminating) each write their own and the first rename wins.
    let partial = out.join(".partial").join(format!(
        "{index:09}-{}",
        xbandsim::products::output::temp_suffix()
    ));
    if partial.exists() {
        std::fs::remove_dir_all(&partial).map_err(|e| DatasetError::io(&partial, e))?;
    }
    let filled = fill_partial(&partial, &written);
    if filled.is_err() {
        // A full disk or a failed write: the half-written folder goes (best effort).
        let _ = std::fs::remove_dir_all(&partial);
    }
    filled?;
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

/// Writes a sample's files and its manifest into the new folder `partial`.
fn fill_partial(partial: &Path, written: &SampleFiles) -> Result<()> {
    std::fs::create_dir_all(partial).map_err(|e| DatasetError::io(partial, e))?;
    for (rel, bytes) in written {
        let path = partial.join(rel);
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent).map_err(|e| DatasetError::io(parent, e))?;
        }
        std::fs::write(&path, bytes).map_err(|e| DatasetError::io(&path, e))?;
    }
    let manifest_path = partial.join(MANIFEST);
    std::fs::write(&manifest_path, sample_manifest(written))
        .map_err(|e| DatasetError::io(&manifest_path, e))
}
