"""Dataset generation on a Ray cluster (docs/distributed.md).

``generate`` runs the dataset generator (``xbandsim dataset``) as Ray tasks, one per block
of samples (block ``I`` of ``K`` is the generator's shard ``I/K``: the samples with
``index mod K = I``), writing into one directory every worker can reach. The generator's
guarantees carry over: sample ``i`` depends only on (spec, seed, i), a block that is run
again skips the samples already written (each written whole, by a rename), so a task retried
after its worker died finishes the block, and the result is byte for byte the dataset a
single ``xbandsim dataset`` run makes. The blocks write samples only; the index files are
written once, by the driver, after every block is done.

``out`` may also be an fsspec URL (``s3://bucket/ds``, ``gs://…``, ``file:///…``) with tar
shards (``shard_samples``): each task then renders one tar shard at a time into a local
folder and uploads the tar, then its manifest (a shard is done when its manifest is there),
and the driver writes the index files from the label members of the uploaded tars, read by
byte range. The tree under the URL is byte for byte the local run's.

``samples`` gives the same samples as a ``ray.data.Dataset`` (one row per sample, its files as
bytes) for pipelines that stream into training or write with Ray's own writers.

Needs Ray: ``pip install "./crates/xbandsim-py[ray]"`` (``ray[data]`` and fsspec; not
dependencies of xbandsim itself).
"""

from __future__ import annotations

import io
import os
import shutil
import sys
import tarfile
import tempfile
import time
from typing import Any, Dict, List, Optional, Tuple, Union

from . import _args, _xbandsim
from . import dataset as _dataset
from .errors import XbandsimError, XbandsimIOError

PathLike = Union[str, "os.PathLike[str]"]

__all__ = ["generate", "samples", "webdataset_rows", "make_block", "make_block_at_url"]


def _ray():
    try:
        import ray
    except ImportError as e:  # pragma: no cover - exercised where ray is absent
        raise ImportError(
            "xbandsim.distributed needs Ray: pip install 'ray[data]>=2.9' (or the package's "
            "[ray] extra: pip install './crates/xbandsim-py[ray]')"
        ) from e
    return ray


def _fsspec(url: str) -> Tuple[Any, str]:
    """The fsspec file system and root path of ``url``."""
    try:
        import fsspec
    except ImportError as e:
        raise ImportError(
            f"out {url!r}: a URL needs fsspec (pip install fsspec, and the file system's "
            "own package: s3fs, gcsfs, adlfs, ...)"
        ) from e
    fs, root = fsspec.core.url_to_fs(url)
    return fs, root.rstrip("/")


def _shard_sizes(count: int, shard_samples: int) -> List[int]:
    """Samples in each tar shard (the last may hold fewer), as the generator has them."""
    sizes = []
    for t in range(_xbandsim.shard_count(count, shard_samples)):
        first, end = _xbandsim.shard_samples(t, shard_samples, count)
        sizes.append(end - first)
    return sizes


def _fetch_record(fs: Any, root: str, folder: str) -> None:
    """Copies the URL's dataset.json (if any) into a local folder, so that the generator run
    there checks it (a URL holding another spec, seed or count is refused before rendering)."""
    remote = f"{root}/{_xbandsim.RECORD_FILE}"
    if fs.exists(remote):
        fs.get_file(remote, os.path.join(folder, _xbandsim.RECORD_FILE))


def _check_record(fs: Any, root: str, url: str, spec: str, count: int, seed: int,
                  shard_samples: int) -> None:
    """Refuses a URL that holds another dataset, and writes dataset.json there if absent."""
    with tempfile.TemporaryDirectory(prefix="xbandsim-record-") as local:
        _fetch_record(fs, root, local)
        shards = len(_shard_sizes(count, shard_samples))
        # Shard `shards` of `shards + 1` holds no tar shard: the generator checks (or writes)
        # the dataset record and renders nothing.
        try:
            _dataset.generate(spec, local, count, seed, shard=f"{shards}/{shards + 1}",
                              jobs=1, shard_samples=shard_samples, assemble=False)
        except XbandsimError as e:
            raise type(e)(f"out {url!r}: {e}".replace(local, url)) from None
        # Object stores have no folders (a no-op there); local and network file systems do.
        fs.makedirs(f"{root}/shards", exist_ok=True)
        record = _xbandsim.RECORD_FILE
        if not fs.exists(f"{root}/{record}"):
            fs.put_file(os.path.join(local, record), f"{root}/{record}")


def make_block_at_url(
    spec: str,
    url: str,
    count: int,
    seed: int,
    block: int,
    blocks: int,
    jobs: int,
    shard_samples: int,
) -> Dict[str, Any]:
    """Makes the tar shards ``t`` with ``t mod blocks = block`` of the dataset at ``url``: each
    one not yet there (no manifest) is rendered into a local folder and uploaded, the tar
    first and its manifest last; what a Ray task runs for a URL."""
    fs, root = _fsspec(url)
    sizes = _shard_sizes(count, shard_samples)
    shards = len(sizes)
    summary = dict(in_shard=0, skipped=0, made=0, block=block)
    for t in range(block, shards, blocks):
        n = sizes[t]
        summary["in_shard"] += n
        tar, manifest = _xbandsim.shard_file(t), _xbandsim.shard_manifest_file(t)
        if fs.exists(f"{root}/{manifest}"):
            summary["skipped"] += n
            continue
        stage = tempfile.mkdtemp(prefix="xbandsim-shard-")
        try:
            _fetch_record(fs, root, stage)
            _dataset.generate(spec, stage, count, seed, shard=f"{t}/{shards}", jobs=jobs,
                              shard_samples=shard_samples, assemble=False)
            fs.put_file(os.path.join(stage, tar), f"{root}/{tar}")
            fs.put_file(os.path.join(stage, manifest), f"{root}/{manifest}")
        finally:
            shutil.rmtree(stage, ignore_errors=True)
        summary["made"] += n
    return summary


def _assemble_at_url(fs: Any, root: str, url: str, spec: str, count: int, seed: int,
                     shard_samples: int) -> int:
    """Writes the index files of the dataset at ``url`` once every shard's manifest is there:
    the label members each shard's COCO and table rows come from are read by byte range
    (where the generator's layout puts them, from the manifest; each is checked against the
    manifest's sha256, in Rust) into a local mirror of label-only tars, the generator
    assembles the mirror, and annotations.json, targets.jsonl, baseline.jsonl and README.md (last) are
    uploaded. Returns the samples still missing (then nothing is written)."""
    sizes = _shard_sizes(count, shard_samples)
    shards = len(sizes)
    missing = sum(
        n for t, n in enumerate(sizes)
        if not fs.exists(f"{root}/{_xbandsim.shard_manifest_file(t)}")
    )
    if missing:
        return missing
    mirror = tempfile.mkdtemp(prefix="xbandsim-mirror-")
    try:
        os.makedirs(os.path.join(mirror, "shards"))
        _fetch_record(fs, root, mirror)
        for t in range(shards):
            tar_name, manifest = _xbandsim.shard_file(t), _xbandsim.shard_manifest_file(t)
            local_manifest = os.path.join(mirror, manifest)
            fs.get_file(f"{root}/{manifest}", local_manifest)
            wanted = _xbandsim.shard_label_ranges(local_manifest)
            names = [name for name, _, _ in wanted]
            paths = [f"{root}/{tar_name}"] * len(wanted)
            datas = (
                fs.cat_ranges(paths, [s for _, s, _ in wanted], [e for _, _, e in wanted])
                if wanted else []
            )
            problem = _xbandsim.check_shard_members(local_manifest, list(zip(names, datas)))
            if problem is not None:
                raise XbandsimIOError(
                    f"{url}/{tar_name}: {problem} (xbandsim dataset verify on a mounted copy "
                    "says more)"
                )
            with tarfile.open(os.path.join(mirror, tar_name), "w",
                              format=tarfile.USTAR_FORMAT) as tar:
                for name, data in zip(names, datas):
                    info = tarfile.TarInfo(name)
                    info.size = len(data)
                    tar.addfile(info, io.BytesIO(data))
        card = _xbandsim.CARD_FILE
        if fs.exists(f"{root}/{card}"):
            fs.rm_file(f"{root}/{card}")  # the card marks a finished assembly: gone first
        final = _dataset.generate(spec, mirror, count, seed, jobs=1,
                                  shard_samples=shard_samples)
        if final["missing"]:
            return int(final["missing"])
        # The card comes last in the list, as it is written last.
        for index_file in _xbandsim.index_files(shard_samples):
            fs.put_file(os.path.join(mirror, index_file), f"{root}/{index_file}")
        return 0
    finally:
        shutil.rmtree(mirror, ignore_errors=True)


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
    """Makes (or resumes) the dataset of ``spec`` in ``out`` on the Ray cluster this process is
    connected to (``ray.init()`` first; a local one is started when none is).

    ``spec`` and ``out`` must be paths every worker can read and write (a shared filesystem), or
    ``out`` an fsspec URL every worker can write with ``shard_samples`` set (see the module doc;
    the file system's fsspec package must be installed on every worker). ``blocks`` tasks are
    submitted (default: four per CPU of the cluster, at most one per sample or tar shard), each
    asking ``cpus_per_task`` CPUs and rendering ``jobs_per_task`` samples at a time
    (``memory_per_task`` bytes and custom ``resources`` are passed to Ray's scheduler as they
    are; a 512x512 sample needs about 0.3 GB); a task whose worker dies is retried up to
    ``max_retries`` times and skips what was written. ``shard_samples`` writes WebDataset tar
    shards. A bad spec raises its ``DatasetSpecError`` from the first task (errors are not
    retried; only lost workers are). Returns the counts (``count``, ``blocks``, ``made`` and
    ``skipped`` by the tasks' last attempts, ``missing``, ``complete``: every sample and the
    index files are in place, ``seconds``).
    """
    spec = os.path.abspath(_args.path("spec", spec))
    out = _args.path("out", out)
    count = _args.whole("count", count, 1, _args.U64_MAX)
    seed = _args.seed("seed", seed)
    blocks = _args.optional(_args.whole, "blocks", blocks, 1)
    cpus_per_task = _args.number("cpus_per_task", cpus_per_task, above=0)
    jobs_per_task = _args.whole("jobs_per_task", jobs_per_task, 0)
    memory_per_task = _args.optional(_args.whole, "memory_per_task", memory_per_task, 1)
    resources = _args.optional(_args.mapping, "resources", resources)
    max_retries = _args.whole("max_retries", max_retries, -1, what="a whole number (-1: forever)")
    shard_samples = _args.optional(_args.whole, "shard_samples", shard_samples, 1, _args.U64_MAX)
    progress = _args.flag("progress", progress)
    url = out if "://" in out else None
    if url is not None and shard_samples is None:
        raise _args.error(
            "shard_samples",
            None,
            f"out {url!r} is a URL, which needs tar shards (shard_samples=N): sample folders "
            "of many small files cannot be renamed into place on object storage "
            "(docs/distributed.md)",
            "conflict",
        )
    units = count if shard_samples is None else _xbandsim.shard_count(count, shard_samples)
    if blocks is not None and blocks > units:
        raise _args.error(
            "blocks",
            blocks,
            f"must be a whole number 1 … {units} (one sample or tar shard per block at least)",
            "out of range",
        )
    ray = _ray()
    out = url if url is not None else os.path.abspath(out)
    if url is not None:
        fs, root = _fsspec(url)
        _check_record(fs, root, url, spec, count, seed, int(shard_samples))
    if not ray.is_initialized():
        ray.init()
    if blocks is None:
        cpus = int(ray.cluster_resources().get("CPU", 1))
        blocks = max(1, min(units, 4 * cpus))
    options: Dict[str, Any] = dict(
        num_cpus=cpus_per_task, max_retries=max_retries, retry_exceptions=False
    )
    if memory_per_task is not None:
        options["memory"] = int(memory_per_task)
    if resources:
        options["resources"] = dict(resources)
    task = ray.remote(make_block if url is None else make_block_at_url).options(**options)
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
                # Rewritten in place on a terminal; a line each in logs (a RayJob's, a file).
                end = "" if sys.stderr.isatty() else "\n"
                lead = "\r" if end == "" else ""
                sys.stderr.write(f"{lead}xbandsim: {len(results)}/{blocks} blocks done{end}")
                sys.stderr.flush()
    finally:
        # On an error (or Ctrl-C) the other blocks are stopped, so that calling generate
        # again does not run beside them; what they wrote stays and is skipped then.
        for ref in pending:
            ray.cancel(ref, force=True)
        # Their outcomes (the same error, or the cancellation) are collected, so that Ray does
        # not print them as unhandled: the first error is the one raised.
        for ref in pending:
            try:
                ray.get(ref, timeout=30)
            except Exception:
                pass
        if progress and sys.stderr.isatty():
            sys.stderr.write("\n")
    # Every block is in place: one more pass over the whole dataset finds nothing to make and
    # writes the index files (COCO, YOLO, targets.jsonl, the card) once.
    if url is None:
        missing = int(
            _dataset.generate(spec, out, count, seed, jobs=1, shard_samples=shard_samples)[
                "missing"
            ]
        )
        # README.md (the card) is the index files' last.
        card = os.path.isfile(os.path.join(out, _xbandsim.CARD_FILE))
    else:
        missing = _assemble_at_url(fs, root, url, spec, count, seed, int(shard_samples))
        card = fs.exists(f"{root}/{_xbandsim.CARD_FILE}")
    made = sum(r["made"] for r in results)
    in_blocks = sum(r["in_shard"] for r in results)
    return {
        "count": count,
        "blocks": blocks,
        "made": made,
        "skipped": in_blocks - made,
        "missing": missing,
        "complete": missing == 0 and card,
        "seconds": time.perf_counter() - start,
    }


def samples(spec: PathLike, count: int, seed: int = 0, *, cpus_per_task: float = 1) -> Any:
    """The samples of the dataset of ``spec`` as a ``ray.data.Dataset``, rendered by Ray's
    workers: one row per sample with ``index`` (int) and ``files`` (a dict of relative file
    name to bytes: the same bytes ``xbandsim dataset`` stores, PNGs, ``polar.npy``, labels).
    Write it with Ray's writers (``ds.write_parquet(...)``; for ``write_webdataset`` see
    ``webdataset_rows``) or iterate it straight into training. (``generate(...,
    shard_samples=N)`` writes tar shards with manifests, byte for byte reproducible.)"""
    spec = os.path.abspath(_args.path("spec", spec))
    count = _args.whole("count", count, 1, _args.U64_MAX)
    seed = _args.seed("seed", seed)
    cpus_per_task = _args.number("cpus_per_task", cpus_per_task, above=0)
    ray = _ray()

    def render(batch: Dict[str, Any]) -> Dict[str, Any]:
        rows = []
        for i in batch["id"]:
            rows.append(dict(_xbandsim.render_sample(spec, seed, int(i))))
        return {"index": list(batch["id"]), "files": rows}

    return ray.data.range(count).map_batches(
        render, batch_size=1, num_cpus=cpus_per_task, batch_format="numpy"
    )


def _webdataset_row(row: Dict[str, Any]) -> Dict[str, Any]:
    flat: Dict[str, Any] = {"__key__": _xbandsim.sample_key(int(row["index"]))}
    for name, data in row["files"].items():
        flat[_xbandsim.member_extension(name)] = bytes(data)
    return flat


def webdataset_rows(ds: Any) -> Any:
    """``samples``' rows in the layout Ray's WebDataset writer takes: ``__key__`` (the index as
    nine digits) and one column per file (``ppi_gray.png``, ``coco.json``, ...; a frame's
    files as ``frame_0003.ppi_gray.png``). Write them unencoded, so that each member holds
    the file's bytes::

        distributed.webdataset_rows(distributed.samples(spec, n)).write_webdataset(
            path, encoder=None)

    Members are named ``<key>.<file>``, as in the tar shards of ``xbandsim dataset``; Ray
    chooses how rows are split into tars and stamps the time into the headers."""
    return ds.map(_webdataset_row)
