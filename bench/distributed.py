#!/usr/bin/env python3
"""Labelled frames per second of xbandsim.distributed.generate on a local Ray cluster with 1
and 2 worker CPUs, beside the plain CLI (`xbandsim dataset --jobs 1` and `--jobs 2`) on the
same spec, seed and count, and the NumPy paper-equivalent frame (bench/reference/
numpy_frame.py) timed in the same run as the reference (absolute speeds differ 2-3x between
machines of one kind; ratios measured together carry over). docs/distributed.md.

    python bench/distributed.py [--count 48] [--spec datasets/detection.toml] [--json]

Each run makes the whole dataset in a new directory, index files included, and is timed from
the first task to the last file (Ray's start-up, about a second or two, is not counted: a
cluster is started once for many datasets). Every Ray result is checked byte for byte against
the CLI's. Also reports the bytes stored per sample (what a shared filesystem must absorb per
frame). Needs Ray (pip install -r scripts/requirements-ray.txt), the package and the CLI
(cargo build --release -p xbandsim-cli).
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


def tree(root: str) -> dict:
    out = {}
    for dirpath, _, files in os.walk(root):
        for f in files:
            p = os.path.join(dirpath, f)
            with open(p, "rb") as fh:
                out[os.path.relpath(p, root)] = hashlib.sha256(fh.read()).hexdigest()
    return out


def sample_bytes(root: str) -> int:
    total = 0
    for dirpath, _, files in os.walk(os.path.join(root, "samples")):
        total += sum(os.path.getsize(os.path.join(dirpath, f)) for f in files)
    return total


def time_cli(cli: str, spec: str, out: str, count: int, seed: int, jobs: int) -> float:
    start = time.perf_counter()
    subprocess.run([cli, "dataset", spec, "--out", out, "--count", str(count), "--seed",
                    str(seed), "--jobs", str(jobs)], check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return time.perf_counter() - start


def time_ray(spec: str, out: str, count: int, seed: int, cpus: int) -> float:
    import ray

    import xbandsim.distributed as distributed

    os.environ["RAY_USAGE_STATS_ENABLED"] = "0"
    ray.init(num_cpus=cpus, include_dashboard=False, _node_ip_address="127.0.0.1",
             configure_logging=False, log_to_driver=False)
    try:
        # A warm-up task loads the extension module in each worker, as a long-lived cluster
        # has; then the timed run.
        ray.get([ray.remote(lambda: __import__("xbandsim")).options(num_cpus=1).remote()
                 for _ in range(cpus)])
        summary = distributed.generate(spec, out, count, seed, progress=False)
    finally:
        ray.shutdown()
    assert summary["complete"] and summary["missing"] == 0, summary
    return summary["seconds"]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--count", type=int, default=48)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--spec", default=os.path.join(ROOT, "datasets", "detection.toml"))
    ap.add_argument("--cli", default=os.path.join(ROOT, "target", "release", "xbandsim"))
    ap.add_argument("--json", action="store_true")
    a = ap.parse_args()
    if not os.access(a.cli, os.X_OK):
        sys.exit(f"{a.cli}: not built (cargo build --release -p xbandsim-cli)")
    spec = os.path.abspath(a.spec)
    work = tempfile.mkdtemp(prefix="xbandsim-bench-")
    try:
        seconds = {}
        seconds["cli_jobs1"] = time_cli(a.cli, spec, os.path.join(work, "cli1"), a.count,
                                        a.seed, 1)
        seconds["cli_jobs2"] = time_cli(a.cli, spec, os.path.join(work, "cli2"), a.count,
                                        a.seed, 2)
        seconds["ray_1cpu"] = time_ray(spec, os.path.join(work, "ray1"), a.count, a.seed, 1)
        seconds["ray_2cpu"] = time_ray(spec, os.path.join(work, "ray2"), a.count, a.seed, 2)
        reference = tree(os.path.join(work, "cli1"))
        identical = {k: tree(os.path.join(work, d)) == reference
                     for k, d in (("cli_jobs2", "cli2"), ("ray_1cpu", "ray1"),
                                  ("ray_2cpu", "ray2"))}
        per_sample = sample_bytes(os.path.join(work, "cli1")) / a.count
    finally:
        shutil.rmtree(work, ignore_errors=True)
    ref = subprocess.run([sys.executable, os.path.join(HERE, "reference", "numpy_frame.py"),
                          "--json", "--T", "1", "--repeats", "3"],
                         check=True, capture_output=True, text=True,
                         cwd=os.path.join(HERE, "reference"))
    numpy_frame_s = json.loads(ref.stdout)["frames"]["1"]
    fps = {k: a.count / s for k, s in seconds.items()}
    result = {
        "count": a.count, "spec": os.path.relpath(spec, ROOT), "cpus": os.cpu_count(),
        "seconds": seconds, "frames_per_s": fps, "identical_to_cli_jobs1": identical,
        "ray_scaling_2_over_1": fps["ray_2cpu"] / fps["ray_1cpu"],
        "ray_overhead_percent_1cpu": 100.0 * (seconds["ray_1cpu"] / seconds["cli_jobs1"] - 1),
        "ray_overhead_percent_2cpu": 100.0 * (seconds["ray_2cpu"] / seconds["cli_jobs2"] - 1),
        "bytes_per_sample": per_sample,
        "numpy_paper_frame_s": numpy_frame_s,
    }
    if a.json:
        print(json.dumps(result, indent=1))
        return 0
    print(f"{a.count} samples of {result['spec']}, seed {a.seed}, {os.cpu_count()} CPUs")
    print(f"{'run':22s} {'seconds':>8s} {'frames/s':>9s} {'x NumPy frame':>13s} {'same bytes':>10s}")
    names = {"cli_jobs1": "xbandsim dataset -j1", "cli_jobs2": "xbandsim dataset -j2",
             "ray_1cpu": "Ray, 1 worker CPU", "ray_2cpu": "Ray, 2 worker CPUs"}
    for k, name in names.items():
        same = "reference" if k == "cli_jobs1" else ("yes" if identical[k] else "NO")
        print(f"{name:22s} {seconds[k]:8.2f} {fps[k]:9.2f} {fps[k] * numpy_frame_s:13.2f} "
              f"{same:>10s}")
    print(f"Ray 2 CPUs / 1 CPU: {result['ray_scaling_2_over_1']:.2f}x; Ray over the CLI: "
          f"{result['ray_overhead_percent_1cpu']:+.1f}% (1 CPU), "
          f"{result['ray_overhead_percent_2cpu']:+.1f}% (2 CPUs)")
    print(f"stored per sample: {per_sample / 1e3:.0f} kB; reference: NumPy paper-equivalent "
          f"frame {numpy_frame_s * 1e3:.0f} ms in this run (the x column is frames per "
          f"reference frame)")
    return 0 if all(identical.values()) else 1


if __name__ == "__main__":
    sys.exit(main())
