#!/usr/bin/env bash
# A labelled dataset made by a Slurm job array: task i of 16 makes shard i of 16
# (`--shard slurm/16`: SLURM_ARRAY_TASK_ID less SLURM_ARRAY_TASK_MIN) into a shared
# filesystem (docs/distributed.md). Samples depend only on (spec, seed, index): tasks run in
# any order, a requeued or resubmitted task skips what is written, and the result is byte for
# byte one `xbandsim dataset` run's. The task that completes the dataset writes the index
# files; `xbandsim dataset verify` checks every sample's sha256 afterwards.
#
#   sbatch deploy/slurm-array.sh
#
#SBATCH --job-name=xbandsim-dataset
#SBATCH --array=0-15
#SBATCH --cpus-per-task=8
#SBATCH --mem=8G
#SBATCH --time=12:00:00
#SBATCH --requeue
#SBATCH --output=logs/xbandsim-%A_%a.out
set -euo pipefail

XBANDSIM="${XBANDSIM:-target/release/xbandsim}"   # built once: cargo build --release -p xbandsim-cli
SPEC="${SPEC:-datasets/detection.toml}"
OUT="${OUT:-/shared/datasets/detection}"
COUNT="${COUNT:-1000000}"
SHARDS=16                                          # = the --array size

"$XBANDSIM" dataset "$SPEC" --out "$OUT" --count "$COUNT" --seed 0 \
  --shard "slurm/$SHARDS" --jobs "$SLURM_CPUS_PER_TASK" \
  --format webdataset --shard-samples 1000
