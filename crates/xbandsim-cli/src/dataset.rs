//! `xbandsim dataset SPEC --out DIR --count N [--seed S] [--shard I/K] [--jobs J]`: makes (or
//! resumes) a labelled dataset from a dataset spec (docs/formats.md, "Dataset spec").

use anyhow::{Context, Result};
use std::path::PathBuf;
use std::time::Instant;
use xbandsim_dataset::{generate, DatasetSpec, Format, Request, Shard};

/// Options of `xbandsim dataset`.
#[derive(clap::Args, Debug)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
pub struct DatasetArgs {
    /// Check or summarise a dataset instead of making one.
    #[command(subcommand)]
    pub action: Option<DatasetAction>,
    /// Dataset spec (TOML): base scene, fields drawn per sample, targets.
    #[arg(required = true)]
    pub spec: Option<PathBuf>,
    /// Output directory (created if missing; a run into a folder that holds the same dataset
    /// resumes it, skipping finished samples).
    #[arg(long, required = true)]
    pub out: Option<PathBuf>,
    /// Samples in the whole dataset.
    #[arg(long, required = true, value_parser = crate::whole_number)]
    pub count: Option<u64>,
    /// Dataset seed: sample i depends only on (spec, seed, i).
    #[arg(long, default_value_t = 0, value_parser = crate::whole_number)]
    pub seed: u64,
    /// Make only shard I of K (the samples with index mod K = I), e.g. --shard 0/4. I may be
    /// `k8s` (from JOB_COMPLETION_INDEX, set by a Kubernetes Indexed Job) or `slurm` (from
    /// SLURM_ARRAY_TASK_ID, a job array numbered 0 … K-1): --shard k8s/8.
    #[arg(long, value_name = "I/K")]
    pub shard: Option<String>,
    /// Samples rendered at once (default: one per core; at most 4 per core).
    #[arg(long, default_value_t = 0, value_parser = crate::whole_number)]
    pub jobs: u64,
    /// Storage: `dir` (a folder per sample, YOLO trees) or `webdataset` (tar shards of
    /// --shard-samples samples with sha256 manifests, for 10^6 samples and more; --shard I/K
    /// then splits the tar shards).
    #[arg(long, value_enum, default_value_t = StorageFormat::Dir)]
    pub format: StorageFormat,
    /// Samples per tar shard with --format webdataset.
    #[arg(long, default_value_t = 200, value_parser = crate::whole_number)]
    pub shard_samples: u64,
    /// Make this run's samples only and leave the index files (COCO, YOLO, targets.jsonl,
    /// README.md) to a later run without this flag: for many --shard runs at once, which
    /// would otherwise each scan the whole dataset when they finish.
    #[arg(long)]
    pub no_assemble: bool,
}

/// How `xbandsim dataset` stores samples.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum StorageFormat {
    /// A folder per sample.
    Dir,
    /// WebDataset tar shards.
    Webdataset,
}

/// What else `xbandsim dataset` does.
#[derive(clap::Subcommand, Debug)]
pub enum DatasetAction {
    /// Report missing or corrupt samples (every file against its sample's files.sha256) and
    /// missing index files; exits with status 1 when anything is wrong.
    Verify {
        /// Dataset folder.
        dir: PathBuf,
    },
    /// Print the JSON Schema of the dataset spec (draft 2020-12).
    Schema,
    /// Print objects and labels per class, the expected-SNR histogram and visibility
    /// fractions, and draw a contact sheet of random samples with their boxes.
    Stats {
        /// Dataset folder.
        dir: PathBuf,
        /// Contact sheet to write (default DIR/contact_sheet.png).
        #[arg(long)]
        sheet: Option<PathBuf>,
        /// Samples on the contact sheet.
        #[arg(long, default_value_t = 16, value_parser = crate::whole_number)]
        samples: u64,
        /// Side of each tile, px.
        #[arg(long, default_value_t = 256, value_parser = crate::whole_number)]
        tile_px: u64,
        /// Seed of the sheet's random choice.
        #[arg(long, default_value_t = 0, value_parser = crate::whole_number)]
        seed: u64,
    },
}

/// Runs `xbandsim dataset`.
pub fn run(a: &DatasetArgs) -> Result<()> {
    match &a.action {
        Some(DatasetAction::Verify { dir }) => return verify(dir),
        Some(DatasetAction::Schema) => {
            print!("{}", xbandsim_dataset::spec::JSON_SCHEMA);
            return Ok(());
        }
        Some(DatasetAction::Stats {
            dir,
            sheet,
            samples,
            tile_px,
            seed,
        }) => {
            let size = |n: u64| usize::try_from(n).unwrap_or(usize::MAX);
            return stats(dir, sheet.as_deref(), size(*samples), size(*tile_px), *seed);
        }
        None => {}
    }
    // clap requires these without a subcommand.
    let (Some(spec_path), Some(out), Some(count)) = (&a.spec, &a.out, a.count) else {
        anyhow::bail!("xbandsim dataset needs SPEC, --out and --count");
    };
    make(a, spec_path, out, count)
}

fn verify(dir: &std::path::Path) -> Result<()> {
    let (count, _) = xbandsim_dataset::stats::record(dir)
        .with_context(|| format!("verifying the dataset in {}", dir.display()))?;
    let progress = crate::progress::bar(count, "verify: samples");
    let report = xbandsim_dataset::verify::verify(dir, &|| progress.inc(1))
        .with_context(|| format!("verifying the dataset in {}", dir.display()))?;
    progress.finish_and_clear();
    let (unit, units) = if report.shards > 0 {
        ("shard", report.shards)
    } else {
        ("sample", report.count)
    };
    for i in &report.missing {
        if report.shards > 0 {
            crate::say!(
                "missing: shard {i} ({})",
                xbandsim_dataset::webdataset::shard_path(dir, *i).display()
            );
        } else {
            crate::say!(
                "missing: sample {i} ({})",
                xbandsim_dataset::sample_dir(dir, *i).display()
            );
        }
    }
    for (i, problem) in &report.corrupt {
        crate::say!("corrupt: {unit} {i}: {problem}");
    }
    for f in &report.missing_index_files {
        crate::say!("missing index file: {}", dir.join(f).display());
    }
    let whole = units - report.missing.len() as u64 - report.corrupt.len() as u64;
    crate::say!(
        "{}: {whole} of {units} {unit}s whole, {} missing, {} corrupt, {} index files missing",
        dir.display(),
        report.missing.len(),
        report.corrupt.len(),
        report.missing_index_files.len()
    );
    if !report.is_complete() {
        if !report.corrupt.is_empty() {
            crate::say!("delete the corrupt {unit}s (a sample's folder; a shard's tar and manifest) and run the same `xbandsim dataset` command again to remake them");
        }
        std::process::exit(1);
    }
    Ok(())
}

fn stats(
    dir: &std::path::Path,
    sheet: Option<&std::path::Path>,
    samples: usize,
    tile_px: usize,
    seed: u64,
) -> Result<()> {
    if !(1..=4096).contains(&tile_px) {
        anyhow::bail!("invalid --tile-px {tile_px}: must be 1 … 4096 (pixels on a tile's side)");
    }
    if !(1..=1024).contains(&samples) {
        anyhow::bail!("invalid --samples {samples}: must be 1 … 1024 (tiles on the sheet)");
    }
    let s = xbandsim_dataset::stats::stats(dir)
        .with_context(|| format!("reading the dataset in {}", dir.display()))?;
    print!("{}", s.report());
    let (png, shown) = xbandsim_dataset::stats::contact_sheet(dir, samples, tile_px, seed)
        .with_context(|| format!("drawing the contact sheet of {}", dir.display()))?;
    let path = sheet.map_or_else(|| dir.join("contact_sheet.png"), |p| p.to_path_buf());
    xbandsim::products::output::write_atomic(&path, &png)
        .with_context(|| format!("writing {}", path.display()))?;
    crate::say!("contact sheet of samples {shown:?} -> {}", path.display());
    Ok(())
}

fn make(
    a: &DatasetArgs,
    spec_path: &std::path::Path,
    out: &std::path::Path,
    count: u64,
) -> Result<()> {
    let t0 = Instant::now();
    let spec = DatasetSpec::read(spec_path)
        .with_context(|| format!("reading the dataset spec {}", spec_path.display()))?;
    let shard = match &a.shard {
        Some(s) => Shard::resolve(s, &|name| std::env::var(name).ok())?,
        None => Shard::ALL,
    };
    let format = match a.format {
        StorageFormat::Dir => Format::Dir,
        StorageFormat::Webdataset => Format::WebDataset {
            samples_per_shard: a.shard_samples,
        },
    };
    let request = Request {
        format,
        count,
        seed: a.seed,
        shard,
        jobs: usize::try_from(a.jobs).unwrap_or(usize::MAX),
        assemble: !a.no_assemble,
    };
    if request.worker_threads() < request.jobs {
        eprintln!(
            "note: --jobs {} is more than {} per core; rendering {} samples at once (more would only add memory)",
            request.jobs,
            xbandsim_dataset::generate::MAX_JOBS_PER_CORE,
            request.worker_threads()
        );
    }
    let in_shard = request.samples_in_shard();
    let progress = crate::progress::bar(in_shard, "dataset: samples");
    let summary = generate(&spec, out, &request, &|| progress.inc(1))
        .with_context(|| format!("making the dataset in {}", out.display()))?;
    progress.finish_and_clear();
    let secs = t0.elapsed().as_secs_f64();
    crate::say!(
        "dataset {}: {} samples in shard {}/{}, {} already there, {} made in {:.1} s ({:.1} samples/s) -> {}",
        spec_path.display(),
        summary.in_shard,
        shard.index,
        shard.count,
        summary.skipped,
        summary.made,
        secs,
        summary.made as f64 / secs.max(1e-9),
        out.display()
    );
    match (&summary.assembled, summary.missing) {
        (Some(x), _) => crate::say!(
            "labels: {} images, {} detection labels, {} target rows -> annotations.json (COCO), {}targets.jsonl, README.md",
            x.images,
            x.annotations,
            x.targets,
            if format == Format::Dir {
                "yolo/ and yolo_obb/ (data.yaml), "
            } else {
                ""
            }
        ),
        (None, 0) if a.no_assemble => crate::say!(
            "--no-assemble: the index files are left to a run without it, once every shard is done"
        ),
        (None, 0) => {}
        (None, n) => crate::say!(
            "{n} samples of other shards are not made yet: the dataset's index files (annotations.json, {}targets.jsonl, README.md) are written by the run that completes it",
            if format == Format::Dir {
                "yolo/, yolo_obb/, "
            } else {
                ""
            }
        ),
    }
    Ok(())
}
