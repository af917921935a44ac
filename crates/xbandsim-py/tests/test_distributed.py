"""Dataset generation on Ray (docs/distributed.md): a local cluster on loopback with two
workers makes a dataset while one worker is killed mid-run, and the result is complete and
byte for byte a single-process run's; the ray.data path gives the same bytes. Skipped, with
the reason, where Ray cannot be imported (scripts/test.sh says why it was not installed)."""

import hashlib
import os
import signal
import threading
import time
from pathlib import Path

import pytest

from conftest import optional_import  # noqa: E402

ray = optional_import("ray", "ray")

import xbandsim  # noqa: E402

# ray.data's own settings warn about themselves (DataContext deprecations), not about ours.
pytestmark = pytest.mark.filterwarnings("ignore::DeprecationWarning:ray.data.context")
import xbandsim.distributed as distributed  # noqa: E402

ROOT = Path(__file__).resolve().parents[3]
SPEC = ROOT / "datasets" / "detection.toml"
COUNT = 16


def tree_digest(root: Path) -> dict:
    """Every file's sha256 but those in .partial/, where a killed worker's half-written
    sample stays (never read; deleted by a later assembly once untouched for 10 minutes)."""
    return {
        str(p.relative_to(root)): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(root.rglob("*"))
        if p.is_file() and p.relative_to(root).parts[0] != ".partial"
    }


@pytest.fixture(scope="module")
def local_ray():
    os.environ["RAY_USAGE_STATS_ENABLED"] = "0"
    ray.init(
        num_cpus=2,
        include_dashboard=False,
        _node_ip_address="127.0.0.1",
        configure_logging=False,
        log_to_driver=False,
    )
    if os.environ.get("XBANDSIM_LOOPBACK_ONLY") == "1":
        # scripts/test.sh runs the suite in a network namespace holding only the loopback
        # interface: the cluster must be on it.
        assert {n["NodeManagerAddress"] for n in ray.nodes()} == {"127.0.0.1"}
    yield
    ray.shutdown()


@pytest.fixture(scope="module")
def single_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("single") / "ds"
    xbandsim.dataset.generate(SPEC, out, count=COUNT, seed=3, jobs=1)
    return out


def worker_pids_running(name: str) -> list:
    """Ray names a worker process `ray::<task>` while it runs a task."""
    pids = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            cmdline = Path("/proc", entry, "cmdline").read_bytes()
        except OSError:
            continue
        if cmdline.startswith(f"ray::{name}".encode()):
            pids.append(int(entry))
    return pids


def test_a_killed_worker_is_retried_and_the_dataset_is_a_single_runs(
    local_ray, single_run, tmp_path
):
    """Two blocks on two worker CPUs (block b holds the samples of index parity b). Once both
    blocks have written a sample and neither is finished, one worker is killed with SIGKILL:
    Ray must run its block again, and the retry must skip what the dead worker wrote."""
    out = tmp_path / "ray"
    killed = []

    def kill_one_worker_mid_run():
        deadline = time.time() + 120
        while time.time() < deadline and not killed:
            samples = out / "samples"
            made = [int(p.name) for p in samples.glob("*/*")] if samples.exists() else []
            per_block = [sum(1 for i in made if i % 2 == b) for b in (0, 1)]
            pids = worker_pids_running("make_block")
            if pids and all(1 <= n < COUNT // 2 - 1 for n in per_block):
                try:
                    os.kill(pids[0], signal.SIGKILL)
                except ProcessLookupError:  # it finished between the look and the kill
                    continue
                killed.append((pids[0], per_block))
                return
            time.sleep(0.02)

    killer = threading.Thread(target=kill_one_worker_mid_run)
    killer.start()
    summary = distributed.generate(SPEC, out, COUNT, seed=3, blocks=2, progress=False)
    killer.join()
    assert killed, "no worker was found mid-block"
    assert summary["complete"] and summary["missing"] == 0 and summary["blocks"] == 2
    # The killed block's retry found the samples its first attempt wrote.
    assert summary["skipped"] >= 1, (summary, killed)
    assert tree_digest(out) == tree_digest(single_run)


def test_ray_data_samples_are_the_stored_bytes(local_ray, single_run, tmp_path):
    ds = distributed.samples(SPEC, 4, seed=3)
    rows = sorted(ds.take_all(), key=lambda r: int(r["index"]))
    assert [int(r["index"]) for r in rows] == [0, 1, 2, 3]
    for row in rows:
        folder = next(single_run.glob(f"samples/*/{int(row['index']):09d}"))
        files = row["files"]
        assert set(files) == {
            p.name for p in folder.iterdir() if p.name != "files.sha256"
        }
        for name, data in files.items():
            assert (folder / name).read_bytes() == bytes(data), name
    # Written with Ray's own Parquet writer and read back, the bytes are still the files.
    import pyarrow.parquet as pq

    ds.write_parquet(str(tmp_path / "parquet"))
    table = pq.read_table(str(tmp_path / "parquet"))
    for index, files in zip(table["index"].to_pylist(), table["files"].to_pylist()):
        folder = next(single_run.glob(f"samples/*/{int(index):09d}"))
        assert (folder / "coco.json").read_bytes() == files["coco.json"]
        assert (folder / "polar.npy").read_bytes() == files["polar.npy"]
    # Ray's WebDataset writer, unencoded: every member `<index>.<file>` holds the file's bytes.
    import tarfile

    distributed.webdataset_rows(ds).write_webdataset(str(tmp_path / "wds"), encoder=None)
    members = {}
    for tar_path in sorted((tmp_path / "wds").glob("*.tar")):
        with tarfile.open(tar_path) as tar:
            for m in tar.getmembers():
                members[m.name] = tar.extractfile(m).read()
    stored = {
        f"{p.parent.name}.{p.name}": p.read_bytes()
        for p in single_run.glob("samples/*/00000000[0-3]/*")
        if p.name != "files.sha256"
    }
    assert members == stored


def test_generate_as_the_readme_shows_it_with_its_progress_lines(
    local_ray, single_run, tmp_path, capfd
):
    """`distributed.generate(spec, out, count, seed)` with nothing else: the default
    progress=True path, which writes a line per finished block (it raised TypeError after
    the last block: the progress line's prefix had taken the start time's name)."""
    out = tmp_path / "readme"
    summary = distributed.generate(SPEC, out, COUNT, 3)
    assert summary["complete"] and summary["missing"] == 0 and summary["made"] == COUNT
    assert isinstance(summary["seconds"], float) and summary["seconds"] > 0
    err = capfd.readouterr().err
    blocks = summary["blocks"]
    assert f"xbandsim: {blocks}/{blocks} blocks done" in err.splitlines()
    assert tree_digest(out) == tree_digest(single_run)


def test_bad_arguments_raise(local_ray, tmp_path):
    with pytest.raises(xbandsim.InvalidArgumentError) as e:
        distributed.generate(SPEC, tmp_path / "x", 0)
    assert str(e.value) == "invalid count 0: must be a whole number 1 … 2**64 - 1"
    with pytest.raises(xbandsim.InvalidArgumentError, match="invalid blocks 5: must be a "
                       "whole number 1 … 4"):
        distributed.generate(SPEC, tmp_path / "x", 4, blocks=5)
    with pytest.raises(xbandsim.InvalidArgumentError, match="shard_samples") as e:
        distributed.generate(SPEC, "s3://bucket/ds", 4)
    assert e.value.problem == "conflict"
    for kwargs, name in ((dict(count="10"), "count"), (dict(seed=None), "seed"),
                         (dict(progress="yes"), "progress"), (dict(blocks=True), "blocks")):
        with pytest.raises(xbandsim.ArgumentTypeError) as e:
            distributed.generate(**dict(dict(spec=SPEC, out=tmp_path / "x", count=4), **kwargs))
        assert e.value.field == name
    with pytest.raises(xbandsim.InvalidArgumentError) as e:
        distributed.generate(SPEC, tmp_path / "x", 4, seed=1.5)
    assert e.value.problem == "not a whole number"
    with pytest.raises(xbandsim.InvalidArgumentError) as e:
        distributed.generate(SPEC, tmp_path / "x", 4, cpus_per_task=float("nan"))
    assert str(e.value) == (
        "invalid cpus_per_task NaN: must be a finite number greater than 0"
    )
    with pytest.raises(xbandsim.ArgumentTypeError):
        distributed.samples(SPEC, "4")
    assert not (tmp_path / "x").exists()
    # An error in a task is the library's own exception (Ray's wrapper subclasses it), raised
    # once: errors are not retried, only lost workers are.
    bad = tmp_path / "bad.toml"
    bad.write_text(SPEC.read_text().replace('library = "kayak"', 'library = "submarine"', 1))
    with pytest.raises(xbandsim.DatasetSpecError, match="submarine"):
        distributed.generate(bad, tmp_path / "y", 2, blocks=1, progress=False)
    with pytest.raises(xbandsim.XbandsimIOError, match="missing.toml"):
        distributed.generate(tmp_path / "missing.toml", tmp_path / "z", 2, progress=False)


def test_an_fsspec_url_holds_a_single_runs_shards(local_ray, tmp_path):
    """Tar shards written through fsspec (a file:// URL here; s3://, gs://, ... take the same
    path): the tree under the URL is byte for byte a local run's, a second call skips every
    shard, a shard whose manifest is lost is made again, and a URL holding another dataset
    is refused before anything is rendered."""
    count, per_shard = 8, 3
    local = tmp_path / "local"
    xbandsim.dataset.generate(SPEC, local, count, seed=3, jobs=1, shard_samples=per_shard)
    remote = tmp_path / "remote"
    url = "file://" + str(remote)
    summary = distributed.generate(
        SPEC, url, count, seed=3, blocks=2, shard_samples=per_shard, progress=False
    )
    assert summary["complete"] and summary["made"] == count and summary["missing"] == 0
    assert tree_digest(remote) == tree_digest(local)
    assert (remote / "README.md").is_file() and (remote / "annotations.json").is_file()

    again = distributed.generate(
        SPEC, url, count, seed=3, blocks=2, shard_samples=per_shard, progress=False
    )
    assert again["complete"] and again["made"] == 0 and again["skipped"] == count

    (remote / "shards" / "shard-000001.manifest.json").unlink()
    (remote / "README.md").unlink()
    redo = distributed.generate(
        SPEC, url, count, seed=3, blocks=3, shard_samples=per_shard, progress=False
    )
    assert redo["complete"] and redo["made"] == per_shard, redo
    assert tree_digest(remote) == tree_digest(local)

    with pytest.raises(xbandsim.DatasetMismatchError, match="file://"):
        distributed.generate(
            SPEC, url, count, seed=4, blocks=2, shard_samples=per_shard, progress=False
        )
    assert tree_digest(remote) == tree_digest(local)
