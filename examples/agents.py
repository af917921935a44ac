"""Run a random agent and a simple heuristic agent on the xbandsim Gymnasium environments and
print their returns (docs/rl.md).

    python examples/agents.py                      # both tasks, level 1, 4 episodes each
    python examples/agents.py --task tracking --level 2 --episodes 8 --json

The heuristic is what a watch officer does, using only what the display shows (the number of
plots, never the ground truth): full scans with two pulses per spoke, starting on the combined
pulse (no blind zone); while the picture is cluttered with plots it turns the gain down, then
the sea and rain clutter controls up, then shortens the pulse; while it is nearly empty it
lengthens the pulse and turns the gain up.
"""

from __future__ import annotations

import argparse
import json
import sys

import gymnasium as gym
import numpy as np

import xbandsim  # noqa: F401  (registers xbandsim/Detection-v0 and xbandsim/Tracking-v0)
from xbandsim.envs import action_vector


class HeuristicAgent:
    """Full scans; gain, sea and rain clutter controls and pulse steered by the plot count."""

    PULSES = ("combined", "medium", "short")

    def __init__(self) -> None:
        self.reset()

    def reset(self) -> None:
        self.gain, self.sea, self.rain, self.pulse = 1, 2, 1, 0

    def act(self, info: dict) -> np.ndarray:
        plots = info.get("plots", 0)
        if plots > 25:
            # Cluttered: less gain, then more sea and rain clutter control, then a shorter
            # pulse (the same clutter-to-target ratio, but all of it lower over the noise).
            if self.gain > 0:
                self.gain -= 1
            elif self.sea < 3:
                self.sea += 1
            elif self.rain < 2:
                self.rain += 1
            elif self.pulse < len(self.PULSES) - 1:
                self.pulse += 1
        elif plots < 3:
            if self.pulse > 0:
                self.pulse -= 1
            elif self.gain < 3:
                self.gain += 1
        return action_vector(
            scan="full",
            pulse=self.PULSES[self.pulse],
            gain=self.gain,
            sea=self.sea,
            rain=self.rain,
            integration=1,
        )


def run(env_id: str, level: int, episodes: int, agent: str, seed: int) -> list[float]:
    env = gym.make(env_id, level=level, image_size=128)
    env.action_space.seed(seed)
    heuristic = HeuristicAgent()
    returns = []
    for episode in range(episodes):
        _, info = env.reset(seed=seed + episode)
        heuristic.reset()
        total, done = 0.0, False
        while not done:
            if agent == "random":
                action = env.action_space.sample()
            else:
                action = heuristic.act(info)
            _, reward, terminated, truncated, info = env.step(action)
            total += float(reward)
            done = terminated or truncated
        returns.append(total)
    env.close()
    return returns


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--task", choices=["detection", "tracking", "both"], default="both")
    parser.add_argument("--level", type=int, default=1)
    parser.add_argument("--episodes", type=int, default=4)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--json", action="store_true", help="print the returns as JSON")
    args = parser.parse_args(argv)
    tasks = ["detection", "tracking"] if args.task == "both" else [args.task]
    results = {}
    for task in tasks:
        env_id = f"xbandsim/{task.capitalize()}-v0"
        for agent in ("random", "heuristic"):
            r = run(env_id, args.level, args.episodes, agent, args.seed)
            results[f"{task}/{agent}"] = r
            if not args.json:
                print(f"{env_id:24s} level {args.level}  {agent:9s}  mean return "
                      f"{np.mean(r):7.2f}  ({', '.join(f'{x:.2f}' for x in r)})")
    if args.json:
        print(json.dumps(results))
    return 0


if __name__ == "__main__":
    sys.exit(main())
