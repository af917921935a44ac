"""Dataset generation on a Ray cluster (docs/distributed.md).

``generate`` runs the dataset generator (``xbandsim dataset``) as Ray tasks, one per block
of samples (block ``I`` of ``K`` is the generator's shard ``I/K``: the samples with
``index mod K = I``), writing into one directory every worker can reach. The generator's
guarantees carry over: sample ``i`` depends only on (spec, seed, i), a block that is run
again skips the samples already written (each written whole, by a rename), so a task retried
after its worker died finishes the block, and the result is byte for byte the dataset a
single ``xbandsim dataset`` run makes. The blocks write samples only; the index files are
written once, by the driver, after every block is done.

``samples`` gives the same samples as a ``ray.data.Dataset`` (one row per sample, its files as
bytes) for pipelines that stream into training or write with Ray's own writers.

Needs ``pip install ray`` (not a dependency of xbandsim).
"""

from __future__ import annotations

import os
import sys
import time
from typing import Any, Dict, List, Optional, Union

from . import _xbandsim
from . import dataset as _dataset

PathLike = Union[str, "os.PathLike[str]"]

__all__ = ["generate", "samples", "make_block"]


def _ray():
    try:
        import ray
    except ImportError as e:  # pragma: no cover - exercised where ray is absent
        raise ImportError(
            "xbandsim.distributed needs Ray: pip install 'ray>=2.9'"
        ) from e
    return ray


def make_block(
    spec: str,
    out: str,
    count: int,
    seed: int,
    block: int,
    blocks: int,
    jobs: int,
    shard_samples: Optional[int],
) -> Dict[str, Any]:
    """Makes block ``block`` of ``blocks`` (the generator's shard ``block/blocks``); what a
    Ray task runs. Returns the generator's counts with the block number."""
    summary = _dataset.generate(
        spec,
        out,
        count,
        seed,
        shard=f"{block}/{blocks}",
        jobs=jobs,
        shard_samples=shard_samples,
        assemble=False,
    )
    return dict(summary, block=block)


def generate(
    spec: PathLike,
    out: PathLike,
    count: int,
    seed: int = 0,
    *,
    blocks: Optional[int] = None,
    cpus_per_task: float = 1,
    jobs_per_task: int = 1,
    memory_per_task: Optional[int] = None,
    resources: Optional[Dict[str, float]] = None,
    max_retries: int = 3,
    shard_samples: Optional[int] = None,
    progress: bool = True,
) -> Dict[str, Any]:
    """Makes (or resumes) the dataset of ``spec`` in ``out`` on the Ray cluster this process
    is connected to (``ray.init()`` first; a local one is started when none is).

    ``spec`` and ``out`` must be paths every worker can read and write (a shared filesystem).
    ``blocks`` tasks are submitted (default: four per CPU of the cluster, at most one per
    sample or tar shard), each asking ``cpus_per_task`` CPUs and rendering ``jobs_per_task``
    samples at a time (``memory_per_task`` bytes and custom ``resources`` are passed to Ray's
    scheduler as they are; a 512x512 sample needs about 0.3 GB); a task whose worker dies is retried up to ``max_retries`` times and
    skips what was written. ``shard_samples`` writes WebDataset tar shards. A bad spec raises
    its ``DatasetSpecError`` from the first task (errors are not retried; only lost workers
    are). Returns the counts (``count``, ``blocks``, ``made`` and ``skipped`` by the tasks'
    last attempts, ``missing``, ``complete``: every sample and the index files are in place,
    ``seconds``).
    """
    if "://" in os.fspath(out):
        raise ValueError(
            f"out {os.fspath(out)!r}: URLs are not supported; mount the storage on every "
            "worker (NFS, CephFS, s3fs, gcsfuse, ...) and pass its path (docs/distributed.md)"
        )
    ray = _ray()
    spec = os.path.abspath(os.fspath(spec))
    out = os.path.abspath(os.fspath(out))
    count, seed = int(count), int(seed)
    if count <= 0:
        from .errors import DatasetSpecError

        raise DatasetSpecError(f"count {count}: a dataset needs at least one sample")
    if shard_samples is not None and int(shard_samples) < 1:
        from .errors import DatasetSpecError

        raise DatasetSpecError(
            f"shard_samples {shard_samples}: a tar shard needs at least one sample"
        )
    if not ray.is_initialized():
        ray.init()
    units = count if shard_samples is None else -(-count // int(shard_samples))
    if blocks is None:
        cpus = int(ray.cluster_resources().get("CPU", 1))
        blocks = max(1, min(units, 4 * cpus))
    blocks = int(blocks)
    if not 1 <= blocks <= units:
        from .errors import DatasetSpecError

        raise DatasetSpecError(
            f"blocks {blocks}: must be 1 … {units} (one sample or tar shard per block at least)"
        )
    options: Dict[str, Any] = dict(
        num_cpus=cpus_per_task, max_retries=max_retries, retry_exceptions=False
    )
    if memory_per_task is not None:
        options["memory"] = int(memory_per_task)
    if resources:
        options["resources"] = dict(resources)
    task = ray.remote(make_block).options(**options)
    start = time.perf_counter()
    pending = {
        task.remote(spec, out, count, seed, b, blocks, jobs_per_task, shard_samples): b
        for b in range(blocks)
    }
    results: List[Dict[str, Any]] = []
    try:
        while pending:
            done, _ = ray.wait(list(pending), num_returns=1)
            for ref in done:
                pending.pop(ref)
                results.append(ray.get(ref))  # a block that failed for good raises here
            if progress:
                sys.stderr.write(f"\rxbandsim: {len(results)}/{blocks} blocks done")
                sys.stderr.flush()
    finally:
        # On an error (or Ctrl-C) the other blocks are stopped, so that calling generate
        # again does not run beside them; what they wrote stays and is skipped then.
        for ref in pending:
            ray.cancel(ref, force=True)
        if progress:
            sys.stderr.write("\n")
    # Every block is in place: one more pass over the whole dataset finds nothing to make and
    # writes the index files (COCO, YOLO, targets.jsonl, the card) once.
    final = _dataset.generate(spec, out, count, seed, jobs=1, shard_samples=shard_samples)
    made = sum(r["made"] for r in results)
    in_blocks = sum(r["in_shard"] for r in results)
    return {
        "count": count,
        "blocks": blocks,
        "made": made,
        "skipped": in_blocks - made,
        "missing": final["missing"],
        # README.md (the card) is the index files' last.
        "complete": final["missing"] == 0 and os.path.isfile(os.path.join(out, "README.md")),
        "seconds": time.perf_counter() - start,
    }


def samples(spec: PathLike, count: int, seed: int = 0, *, cpus_per_task: float = 1) -> Any:
    """The samples of the dataset of ``spec`` as a ``ray.data.Dataset``, rendered by Ray's
    workers: one row per sample with ``index`` (int) and ``files`` (a dict of relative file
    name to bytes: the same bytes ``xbandsim dataset`` stores, PNGs, ``polar.npy``, labels).
    Write it with Ray's writers (``ds.write_parquet(...)``) or iterate it straight into
    training. (For WebDataset tar shards, ``generate(..., shard_samples=N)`` writes them with
    manifests.)"""
    ray = _ray()
    spec = os.path.abspath(os.fspath(spec))
    seed = int(seed)

    def render(batch: Dict[str, Any]) -> Dict[str, Any]:
        rows = []
        for i in batch["id"]:
            rows.append(dict(_xbandsim.render_sample(spec, seed, int(i))))
        return {"index": list(batch["id"]), "files": rows}

    return ray.data.range(int(count)).map_batches(
        render, batch_size=1, num_cpus=cpus_per_task, batch_format="numpy"
    )
