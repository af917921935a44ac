#!/usr/bin/env python3
"""Runs `xbandsim bench` and the reference programs of bench/reference/ in one session and
prints each xbandsim figure beside its reference as a ratio (absolute speeds differ 2-3x
between machines of the same kind; ratios measured in one run carry over).

    python3 bench/compare.py [--xbandsim target/release/xbandsim] [--repeats 5] [--json]

Needs the reference's Python packages (bench/reference/requirements.txt); bench/run.sh sets
up a virtual environment with them and runs this.
"""

import argparse
import json
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
REF = os.path.join(HERE, "reference")


def run_json(cmd):
    out = subprocess.run(cmd, check=True, capture_output=True, text=True, cwd=REF)
    return json.loads(out.stdout)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--xbandsim", default=os.path.join(HERE, "..", "target", "release", "xbandsim"))
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--json", action="store_true")
    a = ap.parse_args()
    py = sys.executable
    rows = {r["name"]: r for r in run_json([os.path.abspath(a.xbandsim), "bench", "--json",
                                            "--repeats", str(a.repeats)])}
    embree = run_json([py, "embree_scan.py", "--json", "--repeats", str(a.repeats)])
    embree_sea = run_json([py, "embree_scan.py", "--json", "--sea", "--repeats", str(a.repeats)])
    numpy = run_json([py, "numpy_frame.py", "--json", "--repeats", str(max(1, a.repeats // 2))])

    def row(prefix):
        return next(r for n, r in rows.items() if n.startswith(prefix))

    table = []
    scan = row("scan-pattern rays, paper scene (closest hit)")["value"]
    table.append(("scan-pattern rays, paper scene (closest hit)", scan, "M rays/s",
                  embree["rays_per_s_median"] / 1e6, "Embree", scan / (embree["rays_per_s_median"] / 1e6)))
    sea = row("scan-pattern rays, paper scene + sea plane")["value"]
    table.append(("same + sea plane (z = 0; Embree: 2 tris)", sea, "M rays/s",
                  embree_sea["rays_per_s_median"] / 1e6, "Embree",
                  sea / (embree_sea["rays_per_s_median"] / 1e6)))
    for pulse in ("1", "20", "50"):
        ours = row(f"paper-equivalent frame")  # first; refine below by pulse width
        ours = next(r for n, r in rows.items()
                    if n.startswith("paper-equivalent frame") and n.endswith(f", {pulse} us"))
        ref_ms = numpy["frames"][pulse] * 1e3
        table.append((f"paper-equivalent frame, {pulse} us", ours["value"], "ms", ref_ms,
                      "NumPy", ref_ms / ours["value"]))
    # A labelled dataset frame (datasets/detection.toml, every core) as a time per frame beside
    # the NumPy paper frame: the ratio is NumPy frames per labelled frame's time.
    labelled = row("labelled 512^2 frames/s")["value"]
    labelled_ms = 1e3 / labelled
    ref_ms = numpy["frames"]["1"] * 1e3
    table.append(("labelled 512^2 dataset frame, all cores", labelled_ms, "ms", ref_ms,
                  "NumPy 1 us", ref_ms / labelled_ms))
    # The same spec with 1-10 targets (no empty frames).
    one_to_ten_ms = 1e3 / row("labelled 512^2 frames/s, the same with 1-10 targets")["value"]
    table.append(("same, 1-10 targets (no empty frames)", one_to_ten_ms, "ms", ref_ms,
                  "NumPy 1 us", ref_ms / one_to_ten_ms))
    if a.json:
        print(json.dumps([dict(zip(("measurement", "xbandsim", "unit", "reference", "reference_name",
                                    "speedup"), t)) for t in table], indent=1))
        return
    print(f"{'measurement':<42} {'xbandsim':>12} {'reference':>14}  {'xbandsim speed / reference'}")
    for name, ours, unit, ref, ref_name, speedup in table:
        print(f"{name:<42} {ours:>8.1f} {unit:<4}{ref:>9.1f} {unit:<4} ({ref_name})  {speedup:.2f}x")


if __name__ == "__main__":
    main()
