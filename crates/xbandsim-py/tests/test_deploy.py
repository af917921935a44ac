"""The deploy/ examples (docs/distributed.md) agree with the CLI: a Kubernetes Indexed Job's
completions are its --shard k8s/K, a Slurm array's tasks are numbered 0 … K-1 for
--shard slurm/K, and the KubeRay RayJob runs xbandsim.distributed."""

import re
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[3]


def test_kubernetes_indexed_job():
    job = yaml.safe_load((ROOT / "deploy" / "k8s-indexed-job.yaml").read_text())
    assert job["apiVersion"] == "batch/v1" and job["kind"] == "Job"
    spec = job["spec"]
    assert spec["completionMode"] == "Indexed"
    assert spec["podReplacementPolicy"] == "Failed"
    command = spec["template"]["spec"]["containers"][0]["command"]
    assert command[:2] == ["xbandsim", "dataset"]
    assert command[command.index("--shard") + 1] == f"k8s/{spec['completions']}"


def test_kuberay_rayjob():
    rayjob = yaml.safe_load((ROOT / "deploy" / "kuberay-rayjob.yaml").read_text())
    assert rayjob["apiVersion"] == "ray.io/v1" and rayjob["kind"] == "RayJob"
    entry = rayjob["spec"]["entrypoint"]
    assert "xbandsim.distributed" in entry and "generate(" in entry
    head = rayjob["spec"]["rayClusterSpec"]["headGroupSpec"]
    assert head["rayStartParams"]["num-cpus"] == "0"


def test_slurm_array():
    script = (ROOT / "deploy" / "slurm-array.sh").read_text()
    first, last = map(int, re.search(r"#SBATCH --array=(\d+)-(\d+)", script).groups())
    shards = int(re.search(r"^SHARDS=(\d+)", script, re.M).group(1))
    assert first == 0 and last == shards - 1
    assert '--shard "slurm/$SHARDS"' in script
    assert "#SBATCH --output=" in script and "logs/" not in script
