"""Labelled datasets: ``xbandsim.dataset.generate`` runs ``xbandsim dataset`` in-process.

The generator is the Rust one (docs/formats.md, "Dataset spec"): the same spec, seed and
count give the same bytes whatever the shard, job count or order, a stopped run resumes, and
the index files (COCO, YOLO, targets.jsonl, the dataset card) are written by the run that
completes the dataset.
"""

import os
from typing import Dict, Optional, Union

from . import _xbandsim

PathLike = Union[str, "os.PathLike[str]"]


def generate(
    spec: PathLike,
    out: PathLike,
    count: int,
    seed: int = 0,
    *,
    shard: Optional[str] = None,
    jobs: int = 0,
    shard_samples: Optional[int] = None,
    assemble: bool = True,
) -> Dict[str, Union[int, bool]]:
    """Makes (or resumes) the dataset of ``spec`` (a dataset-spec TOML file) in ``out``.

    ``shard`` ``"I/K"`` makes only shard I of K; ``jobs`` samples at once (0: one per core);
    ``shard_samples`` writes WebDataset tar shards of that many samples instead of folders.
    ``assemble=False`` makes this run's samples only and leaves the index files to a later
    run (the CLI's ``--no-assemble``; for many shard runs at once). Returns the run's counts:
    ``in_shard``, ``skipped`` (already there), ``made``, ``missing`` (other shards' samples
    not made yet; with ``assemble=False`` this shard's only) and ``assembled`` (index files
    written).
    """
    for name, v in (("count", count), ("seed", seed), ("jobs", jobs)):
        if int(v) < 0:
            from .errors import DatasetSpecError

            raise DatasetSpecError(f"{name} {v}: must be a whole number of 0 or more")
    return _xbandsim.generate_dataset(
        os.fspath(spec),
        os.fspath(out),
        int(count),
        int(seed),
        shard,
        int(jobs),
        None if shard_samples is None else int(shard_samples),
        bool(assemble),
    )


__all__ = ["generate"]
