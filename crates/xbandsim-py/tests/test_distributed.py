"""Dataset generation on Ray (docs/distributed.md): a local cluster on loopback with two
workers makes a dataset while one worker is killed mid-run, and the result is complete and
byte for byte a single-process run's; the ray.data path gives the same bytes; the deploy
manifests agree with the CLI's --shard k8s/K and slurm/K. Skipped, with the reason, where Ray
cannot be imported."""

import hashlib
import os
import signal
import threading
import time
from pathlib import Path

import pytest

ray = pytest.importorskip(
    "ray",
    reason="Ray is not installed: "
    + os.environ.get(
        "XBANDSIM_RAY_UNAVAILABLE", "pip install -r scripts/requirements-ray.txt"
    ),
)

import xbandsim  # noqa: E402

# ray.data's own settings warn about themselves (DataContext deprecations), not about ours.
pytestmark = pytest.mark.filterwarnings("ignore::DeprecationWarning:ray.data.context")
import xbandsim.distributed as distributed  # noqa: E402

ROOT = Path(__file__).resolve().parents[3]
SPEC = ROOT / "datasets" / "detection.toml"
COUNT = 16


def tree_digest(root: Path) -> dict:
    return {
        str(p.relative_to(root)): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(root.rglob("*"))
        if p.is_file()
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
    out = tmp_path / "ray"
    killed = []

    def kill_one_worker_mid_run():
        deadline = time.time() + 120
        while time.time() < deadline and not killed:
            samples = out / "samples"
            made = list(samples.rglob("coco.json")) if samples.exists() else []
            pids = worker_pids_running("make_block")
            if made and pids:
                os.kill(pids[0], signal.SIGKILL)
                killed.append((pids[0], len(made)))
                return
            time.sleep(0.05)

    killer = threading.Thread(target=kill_one_worker_mid_run)
    killer.start()
    summary = distributed.generate(SPEC, out, COUNT, seed=3, blocks=4, progress=False)
    killer.join()
    assert killed, "no worker was found running a block"
    assert killed[0][1] < COUNT, "the kill came after every sample was made"
    assert summary["complete"] and summary["missing"] == 0 and summary["blocks"] == 4
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


def test_bad_arguments_raise(local_ray, tmp_path):
    with pytest.raises(xbandsim.DatasetSpecError):
        distributed.generate(SPEC, tmp_path / "x", 0)
    with pytest.raises(xbandsim.DatasetSpecError, match="blocks"):
        distributed.generate(SPEC, tmp_path / "x", 4, blocks=5)
    with pytest.raises(ValueError, match="URLs are not supported"):
        distributed.generate(SPEC, "s3://bucket/ds", 4)
    # An error in a task is the library's own exception (Ray's wrapper subclasses it), raised
    # once: errors are not retried, only lost workers are.
    bad = tmp_path / "bad.toml"
    bad.write_text(SPEC.read_text().replace('library = "kayak"', 'library = "submarine"', 1))
    with pytest.raises(xbandsim.DatasetSpecError, match="submarine"):
        distributed.generate(bad, tmp_path / "y", 2, blocks=1, progress=False)
    with pytest.raises(xbandsim.XbandsimIOError, match="missing.toml"):
        distributed.generate(tmp_path / "missing.toml", tmp_path / "z", 2, progress=False)


def test_deploy_manifests_match_the_clis_shard_from_the_environment():
    yaml = pytest.importorskip("yaml")
    job = yaml.safe_load((ROOT / "deploy" / "k8s-indexed-job.yaml").read_text())
    spec = job["spec"]
    assert spec["completionMode"] == "Indexed"
    command = spec["template"]["spec"]["containers"][0]["command"]
    assert command[command.index("--shard") + 1] == f"k8s/{spec['completions']}"
    rayjob = yaml.safe_load((ROOT / "deploy" / "kuberay-rayjob.yaml").read_text())
    assert rayjob["kind"] == "RayJob" and "distributed" in rayjob["spec"]["entrypoint"]
    slurm = (ROOT / "deploy" / "slurm-array.sh").read_text()
    assert "#SBATCH --array=0-15" in slurm and "SHARDS=16" in slurm
    assert '--shard "slurm/$SHARDS"' in slurm
