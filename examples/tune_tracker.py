"""Tune the radar's controls for the baseline tracker: an agent that searches the operator's
settings of xbandsim/Tracking-v0 for the ones under which the baseline ARPA tracker's tracks
score the best HOTA against the truth (docs/rl.md, "Tracks").

    python examples/tune_tracker.py                       # level 1, 2 episodes of 20 revolutions
    python examples/tune_tracker.py --level 2 --episodes 3 --steps 30 --json

Each setting (pulse, gain, sea and rain clutter controls, pulses per spoke, held for a whole
episode) is scored on the same episodes (the same seeds): every revolution's confirmed tracks
(``info["tracks"]``) against the targets in view (``info["targets"]``, ``observed``: in range
and on a refreshed spoke, whether or not they leave an echo, so these scores are not those of
``xbandsim track``'s tracks.json, which count objects with an echo), with HOTA
from TrackEval and MOTA from py-motmetrics (``scripts/score_tracks.py``: ``pip install -r
scripts/requirements-check.txt``), averaged over the episodes. The agent is a coordinate
ascent: starting from the environment's default setting, it tries every value of one control
with the others held, keeps the best, and goes on to the next control, for ``--passes``
passes. It prints the default's HOTA and the tuned setting's.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import sys
from pathlib import Path

import gymnasium as gym

import xbandsim  # noqa: F401  (registers xbandsim/Tracking-v0)
from xbandsim.envs import ACTION_CHOICES, ACTION_NAMES, PULSES, action_vector

#: The controls the agent tunes, with their starting values (the warm-up revolution's).
START = {"pulse": "combined", "gain": 1, "sea": 2, "rain": 0, "integration": 0}

#: Distance within which a track and a target match, m (the tracker's truth gate).
GATE_M = 100.0


def load_score_tracks():
    """scripts/score_tracks.py as a module."""
    path = Path(__file__).resolve().parent.parent / "scripts" / "score_tracks.py"
    spec = importlib.util.spec_from_file_location("score_tracks", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def choices(control: str) -> list:
    """The values a control takes."""
    if control == "pulse":
        return list(PULSES)
    return list(range(ACTION_CHOICES[ACTION_NAMES.index(control)]))


def episode_doc(env, seed: int, steps: int, setting: dict) -> dict:
    """One episode under a fixed setting as a tracks document for score_tracks.score: each
    revolution's targets in view and confirmed tracks."""
    action = action_vector(scan="full", **setting)
    _, info = env.reset(seed=seed)
    scans = []
    for _ in range(steps):
        _, _, terminated, truncated, info = env.step(action)
        scans.append(
            {
                "objects": [
                    {"id": i, "position_m": t["position_m"], "has_echo": t["observed"]}
                    for i, t in enumerate(info["targets"])
                ],
                "tracks": [
                    {"id": t["id"], "position_m": t["position_m"], "status": "confirmed"}
                    for t in info["tracks"]
                ],
            }
        )
        if terminated or truncated:
            break
    return {"scans": scans}


def evaluate(env, score_tracks, seeds: list[int], steps: int, setting: dict) -> dict:
    """Mean HOTA and MOTA of the baseline tracker over the episodes of ``seeds``."""
    scores = [
        score_tracks.score(episode_doc(env, seed, steps, setting), GATE_M) for seed in seeds
    ]
    return {k: sum(s[k] for s in scores) / len(scores) for k in ("HOTA", "mota")}


def tune(level: int, episodes: int, steps: int, passes: int, seed: int) -> dict:
    score_tracks = load_score_tracks()
    env = gym.make(
        "xbandsim/Tracking-v0", level=level, image_size=128, max_steps=steps, reward="tracks"
    )
    seeds = [seed + k for k in range(episodes)]
    best = dict(START)
    best_score = evaluate(env, score_tracks, seeds, steps, best)
    default_score = dict(best_score)
    tried = 1
    for _ in range(passes):
        for control in START:
            held = best[control]
            for value in choices(control):
                if value == held:
                    continue
                setting = {**best, control: value}
                score = evaluate(env, score_tracks, seeds, steps, setting)
                tried += 1
                if score["HOTA"] > best_score["HOTA"]:
                    best, best_score = setting, score
    env.close()
    return {
        "default": {"setting": START, **default_score},
        "tuned": {"setting": best, **best_score},
        "settings_tried": tried,
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--level", type=int, default=1)
    parser.add_argument("--episodes", type=int, default=2)
    parser.add_argument("--steps", type=int, default=20, help="revolutions per episode")
    parser.add_argument("--passes", type=int, default=1, help="passes over the controls")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--json", action="store_true", help="print the result as JSON")
    args = parser.parse_args(argv)
    for name in ("episodes", "steps", "passes"):
        if getattr(args, name) < 1:
            parser.error(f"--{name} must be 1 or more")
    result = tune(args.level, args.episodes, args.steps, args.passes, args.seed)
    if args.json:
        print(json.dumps(result))
    else:
        for which in ("default", "tuned"):
            r = result[which]
            print(f"{which:8s} HOTA {r['HOTA']:.3f}  MOTA {r['mota']:.3f}  {r['setting']}")
        print(f"{result['settings_tried']} settings tried")
    return 0


if __name__ == "__main__":
    sys.exit(main())
