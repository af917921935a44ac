#!/usr/bin/env python3
"""Environment steps per second of xbandsim/Detection-v0 and xbandsim/Tracking-v0 at 256x256
on one core, the Python layer's overhead over the Rust call, and the NumPy paper-equivalent
frame (bench/reference/numpy_frame.py) timed in the same run as the reference (absolute
speeds differ 2-3x between machines of one kind; ratios measured together carry over).

    python bench/env_steps.py [--steps 300] [--repeats 3] [--json]

One step is one antenna revolution (docs/rl.md). The process is pinned to one CPU and every
environment runs its simulation on one thread. "rust" times _xbandsim.Env.step (the Rust
episode, the observation moved into NumPy, the info dict built); "gym" times the registered
environment made by gymnasium.make (Gymnasium's wrappers and xbandsim.envs' conversion on top).
Needs the package installed (pip install ./crates/xbandsim-py) and gymnasium.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))


def pin_one_core() -> int:
    cpu = min(os.sched_getaffinity(0))
    os.sched_setaffinity(0, {cpu})
    return cpu


def time_rust(task: str, level: int, size: int, steps: int, action) -> float:
    from xbandsim import _xbandsim

    env = _xbandsim.Env(task, level, size, 10**9, 1)
    env.reset(1)
    action = [int(a) for a in action]
    start = time.perf_counter()
    for _ in range(steps):
        env.step(action)
    return (time.perf_counter() - start) / steps


def time_gym(task: str, level: int, size: int, steps: int, action=None, seed: int = 1) -> float:
    import gymnasium as gym
    import numpy as np

    env = gym.make(f"xbandsim/{task.capitalize()}-v0", level=level, image_size=size,
                   max_steps=10**9)
    env.reset(seed=seed)
    env.action_space.seed(seed)
    actions = [np.asarray(action) if action is not None else env.action_space.sample()
               for _ in range(steps)]
    start = time.perf_counter()
    for a in actions:
        env.step(a)
    return (time.perf_counter() - start) / steps


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=300)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--json", action="store_true")
    a = ap.parse_args()
    cpu = pin_one_core()
    import xbandsim  # noqa: F401  (registers the environments)
    from xbandsim.envs import action_vector

    default = action_vector()  # full scan, combined pulse, one pulse per spoke
    rows = []
    for task in ("detection", "tracking"):
        for level in range(4):
            rust, gym_, rand = [], [], []
            for _ in range(a.repeats):  # interleaved, medians: the two loops see one machine
                rust.append(time_rust(task, level, a.size, a.steps, default))
                gym_.append(time_gym(task, level, a.size, a.steps, default))
                rand.append(time_gym(task, level, a.size, a.steps // 3))
            r, g, x = (statistics.median(v) for v in (rust, gym_, rand))
            rows.append({
                "task": task, "level": level,
                "steps_per_s_default_action": 1.0 / g,
                "steps_per_s_random_actions": 1.0 / x,
                "rust_ms": r * 1e3, "gym_ms": g * 1e3,
                "python_overhead_percent": 100.0 * (g - r) / r,
            })
    ref = subprocess.run([sys.executable, os.path.join(HERE, "reference", "numpy_frame.py"),
                          "--json", "--T", "1", "--repeats", str(a.repeats)],
                         check=True, capture_output=True, text=True,
                         cwd=os.path.join(HERE, "reference"))
    numpy_frame_s = json.loads(ref.stdout)["frames"]["1"]
    result = {"cpu": cpu, "image_size": a.size, "steps": a.steps, "rows": rows,
              "numpy_paper_frame_s": numpy_frame_s}
    if a.json:
        print(json.dumps(result, indent=1))
        return 0
    print(f"one core (cpu {cpu}), {a.size}x{a.size} observations, {a.steps} steps, "
          f"median of {a.repeats}")
    print(f"{'env':24s} {'level':>5s} {'steps/s':>8s} {'random':>8s} {'rust ms':>8s} "
          f"{'gym ms':>8s} {'overhead':>8s} {'x NumPy frame':>13s}")
    for r in rows:
        env_id = f"xbandsim/{r['task'].capitalize()}-v0"
        print(f"{env_id:24s} {r['level']:5d} {r['steps_per_s_default_action']:8.0f} "
              f"{r['steps_per_s_random_actions']:8.0f} {r['rust_ms']:8.2f} {r['gym_ms']:8.2f} "
              f"{r['python_overhead_percent']:7.1f}% "
              f"{r['steps_per_s_default_action'] * numpy_frame_s:13.1f}")
    print(f"reference: NumPy paper-equivalent frame (1 us) {numpy_frame_s * 1e3:.0f} ms "
          f"in this run; the last column is steps per reference frame")
    return 0


if __name__ == "__main__":
    sys.exit(main())
