"""Labelled datasets: ``xbandsim.dataset.generate`` runs ``xbandsim dataset`` in-process.

The generator is the Rust one (docs/formats.md, "Dataset spec"): the same spec, seed and
count give the same bytes whatever the shard, job count or order, a stopped run resumes, and
the index files (COCO, YOLO, targets.jsonl, the dataset card) are written by the run that
completes the dataset.
"""

import os
from typing import Dict, Optional, Union

from . import _args, _xbandsim

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

    ``count`` is a whole number of 1 or more, ``seed`` 0 … 2**64 - 1, ``jobs`` 0 or more,
    ``shard_samples`` 1 or more; other values raise ``InvalidArgumentError`` (a wrong type
    ``ArgumentTypeError``) naming the argument, and a bad ``shard`` text the same naming
    ``shard``.
    """
    args = (
        _args.path("spec", spec),
        _args.path("out", out),
        _args.whole("count", count, 1, _args.U64_MAX),
        _args.seed("seed", seed),
        _args.optional(_args.text, "shard", shard),
        _args.whole("jobs", jobs, 0),
        _args.optional(_args.whole, "shard_samples", shard_samples, 1, _args.U64_MAX),
        _args.flag("assemble", assemble),
    )
    return _xbandsim.generate_dataset(*args)


__all__ = ["generate"]
