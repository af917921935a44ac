//! `xbandsim dataset SPEC --out DIR --count N [--seed S] [--shard I/K] [--jobs J]`: makes (or
//! resumes) a labelled dataset from a dataset spec (docs/formats.md, "Dataset spec").

use anyhow::{Context, Result};
use std::path::PathBuf;
use std::time::Instant;
use xbandsim_dataset::{generate, DatasetSpec, Request, Shard};

/// Options of `xbandsim dataset`.
#[derive(clap::Args, Debug)]
pub struct DatasetArgs {
    /// Dataset spec (TOML): base scene, fields drawn per sample, targets.
    pub spec: PathBuf,
    /// Output directory (created if missing; a run into a folder that holds the same dataset
    /// resumes it, skipping finished samples).
    #[arg(long)]
    pub out: PathBuf,
    /// Samples in the whole dataset.
    #[arg(long)]
    pub count: u64,
    /// Dataset seed: sample i depends only on (spec, seed, i).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Make only shard I of K (the samples with index mod K = I), e.g. --shard 0/4.
    #[arg(long, value_name = "I/K")]
    pub shard: Option<String>,
    /// Samples rendered at once (default: one per core).
    #[arg(long, default_value_t = 0)]
    pub jobs: usize,
}

/// Runs `xbandsim dataset`.
pub fn run(a: &DatasetArgs) -> Result<()> {
    let t0 = Instant::now();
    let spec = DatasetSpec::read(&a.spec)
        .with_context(|| format!("reading the dataset spec {}", a.spec.display()))?;
    let shard = match &a.shard {
        Some(s) => Shard::parse(s)?,
        None => Shard::ALL,
    };
    let request = Request {
        count: a.count,
        seed: a.seed,
        shard,
        jobs: a.jobs,
    };
    let in_shard = (0..a.count).filter(|&i| shard.holds(i)).count() as u64;
    let progress = crate::progress::bar(in_shard, "dataset: samples");
    let summary = generate(&spec, &a.out, &request, &|| progress.inc(1))
        .with_context(|| format!("making the dataset in {}", a.out.display()))?;
    progress.finish_and_clear();
    let secs = t0.elapsed().as_secs_f64();
    crate::say!(
        "dataset {}: {} samples in shard {}/{}, {} already there, {} made in {:.1} s ({:.1} samples/s) -> {}",
        a.spec.display(),
        summary.in_shard,
        shard.index,
        shard.count,
        summary.skipped,
        summary.made,
        secs,
        summary.made as f64 / secs.max(1e-9),
        a.out.display()
    );
    Ok(())
}
