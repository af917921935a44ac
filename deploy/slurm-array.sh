#!/usr/bin/env bash
# A labelled dataset made by a Slurm job array: task i makes shard i of 16
# (`--shard slurm/16` reads SLURM_ARRAY_TASK_ID; the array is numbered 0-15) into a shared
# file system (docs/distributed.md). Samples depend only on (spec, seed, index): tasks run in
# any order, a requeued task skips what is written, and the result is byte for byte one
# `xbandsim dataset` run's. The task that completes the dataset writes the index files.
#
#   sbatch deploy/slurm-array.sh                  # all 16 shards
#   sbatch --array=3,7 deploy/slurm-array.sh      # remake shards 3 and 7 only
#   xbandsim dataset verify /shared/datasets/detection   # afterwards: every sample's sha256
#
# Logs go to the folder sbatch is run from (Slurm does not create folders for them).
#
#SBATCH --job-name=xbandsim-dataset
#SBATCH --array=0-15
#SBATCH --cpus-per-task=8
#SBATCH --mem=8G
#SBATCH --time=12:00:00
#SBATCH --requeue
#SBATCH --output=xbandsim-%A_%a.out
set -euo pipefail

XBANDSIM="${XBANDSIM:-target/release/xbandsim}"   # built once: cargo build --release -p xbandsim-cli
# (on x86-64 the build is for x86-64-v3; for nodes without AVX2 build it with
#  RUSTFLAGS="-C target-cpu=x86-64", docs/distributed.md)
SPEC="${SPEC:-datasets/detection.toml}"
OUT="${OUT:-/shared/datasets/detection}"
COUNT="${COUNT:-1000000}"
SHARDS=16                                          # = the --array size

"$XBANDSIM" dataset "$SPEC" --out "$OUT" --count "$COUNT" --seed 0 \
  --shard "slurm/$SHARDS" --jobs "${SLURM_CPUS_PER_TASK:-0}" \
  --format webdataset --shard-samples 200
