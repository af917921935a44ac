"""Ctrl-C stops ``xbandsim.dataset.generate`` within about a second, as it stops the CLI, and
leaves a dataset that the same call resumes (docs/python.md, "Datasets")."""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import xbandsim

SPEC = """
[dataset]
frames = 1

[scene.radar]
spokes = 90
max_range_m = 600.0
position_m = [0.0, 0.0, 6.0]

[scene.environment]
clutter = true

[scene.display]
image_size_px = 128

[targets]
count = { uniform_int = [1, 3] }

[[targets.class]]
name = "buoy"
[targets.class.object]
shape = "cylinder"
radius_m = { uniform = [0.3, 1.0] }
height_m = 2.0
"""

COUNT = 400


def _samples(out: Path) -> int:
    root = out / "samples"
    return sum(1 for g in root.iterdir() for _ in g.iterdir()) if root.is_dir() else 0


def test_ctrl_c_stops_generate_within_a_second_and_the_dataset_resumes(tmp_path):
    spec = tmp_path / "spec.toml"
    spec.write_text(SPEC)
    out = tmp_path / "ds"
    code = (
        "import sys, xbandsim.dataset as d\n"
        f"d.generate({str(spec)!r}, {str(out)!r}, {COUNT}, 0, jobs=2)\n"
    )
    proc = subprocess.Popen(
        [sys.executable, "-c", code], stderr=subprocess.PIPE, text=True
    )
    try:
        deadline = time.monotonic() + 120
        while _samples(out) < 5:
            assert proc.poll() is None, proc.stderr.read()
            assert time.monotonic() < deadline, "no samples after 120 s"
            time.sleep(0.02)
        proc.send_signal(signal.SIGINT)
        sent = time.monotonic()
        proc.wait(timeout=30)
        stopped_after_s = time.monotonic() - sent
    finally:
        if proc.poll() is None:
            proc.kill()
    err = proc.stderr.read()
    assert "KeyboardInterrupt" in err, err
    assert stopped_after_s < 1.5, f"took {stopped_after_s:.2f} s to stop"
    made = _samples(out)
    assert 5 <= made < COUNT, made
    # Whole samples only: nothing half-written, no lock left, no index files.
    partial = out / ".partial"
    leftovers = [p for p in out.rglob("*") if p != partial and "partial" in str(p.relative_to(out))]
    leftovers += list(out.rglob("*.lock"))
    assert leftovers == [], leftovers
    assert not (out / "README.md").exists()
    # The same call resumes: the finished samples are skipped and the dataset completes.
    summary = xbandsim.dataset.generate(spec, out, COUNT, 0, jobs=2)
    assert summary["skipped"] == made and summary["made"] == COUNT - made
    assert summary["missing"] == 0 and summary["assembled"]
    assert os.path.isfile(out / "annotations.json")
