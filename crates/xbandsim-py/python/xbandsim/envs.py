"""Gymnasium environments: ``xbandsim/Detection-v0`` and ``xbandsim/Tracking-v0``.

A radar operator's MDP over the simulator (docs/rl.md): each step is one antenna revolution
simulated in Rust (crate ``xbandsim-rl``) with the settings the action chooses. This module
only adapts it to Gymnasium's API (spaces, seeding, ``render_mode``); the scene drawing, the
display chain, the plot extractor and the rewards are the Rust crate's.

.. code-block:: python

    import gymnasium as gym
    import xbandsim  # registers the environments

    env = gym.make("xbandsim/Tracking-v0", level=1, render_mode="rgb_array")
    obs, info = env.reset(seed=0)
    obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from . import _xbandsim

__all__ = [
    "ACTION_NAMES",
    "RadarEnv",
    "DetectionEnv",
    "TrackingEnv",
    "action_vector",
    "register_envs",
]

_NVEC, _NAMES = _xbandsim.action_space()
#: Names of the action vector's components (docs/rl.md, "Action").
ACTION_NAMES: tuple[str, ...] = tuple(_NAMES)

_PULSES = ("short", "medium", "long", "combined")


def action_vector(
    scan: int | str = "full",
    pulse: str = "combined",
    gain: int = 1,
    sea: int = 2,
    rain: int = 0,
    integration: int = 0,
) -> np.ndarray:
    """An action by name: ``scan`` is ``"full"`` or a quadrant 0-3 (0 = north-east,
    clockwise), ``pulse`` one of short/medium/long/combined, ``gain`` 0-3, ``sea`` 0-3,
    ``rain`` 0-2, ``integration`` 0-2 (1, 2 or 4 pulses per spoke)."""
    scan_index = 0 if scan == "full" else int(scan) + 1
    if pulse not in _PULSES:
        raise ValueError(f"pulse: {pulse!r} is not one of {_PULSES}")
    return np.array(
        [scan_index, _PULSES.index(pulse), gain, sea, rain, integration], dtype=np.int64
    )


class RadarEnv(gym.Env):
    """A radar-operator environment (docs/rl.md).

    Parameters
    ----------
    task:
        ``"detection"`` (find every target in few revolutions) or ``"tracking"`` (keep moving
        targets in track).
    level:
        Curriculum level 0-3: calm sea and one large target up to heavy clutter, rain and
        many small targets. ``reset(options={"level": k})`` changes it.
    image_size:
        Side of the square observation image, pixels (default 256).
    own_ship_state:
        When true the observation is a Dict: ``"ppi"`` (the image) and ``"own_ship"``
        (float32 ``[speed_kn, sin(course), cos(course)]``).
    max_steps:
        Revolutions per episode (default: 12 for detection, 30 for tracking).
    render_mode:
        ``None`` or ``"rgb_array"`` (the display in phosphor green, uint8 (size, size, 3)).
    threads:
        Worker threads for the simulation (default 1: one core per environment; vector
        environments scale across processes).
    sea_clutter:
        Sea clutter on (default); ``False`` leaves noise, rain and the targets (an easier
        curriculum step, or an ablation).
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 4}

    def __init__(
        self,
        task: str = "detection",
        level: int = 0,
        image_size: int = 256,
        own_ship_state: bool = False,
        max_steps: int | None = None,
        render_mode: str | None = None,
        threads: int = 1,
        sea_clutter: bool = True,
    ) -> None:
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(
                f"render_mode: {render_mode!r} is not one of {self.metadata['render_modes']}"
            )
        self.task = task
        self.level = int(level)
        self.image_size = int(image_size)
        self.own_ship_state = bool(own_ship_state)
        self._max_steps = 0 if max_steps is None else int(max_steps)
        self._threads = int(threads)
        self._sea_clutter = bool(sea_clutter)
        self.render_mode = render_mode
        self._env = self._make(self.level)
        self.action_space = spaces.MultiDiscrete(np.array(_NVEC, dtype=np.int64))
        image = spaces.Box(0, 255, (self.image_size, self.image_size), np.uint8)
        if self.own_ship_state:
            self.observation_space = spaces.Dict(
                {
                    "ppi": image,
                    "own_ship": spaces.Box(
                        np.array([0.0, -1.0, -1.0], dtype=np.float32),
                        np.array([50.0, 1.0, 1.0], dtype=np.float32),
                        dtype=np.float32,
                    ),
                }
            )
        else:
            self.observation_space = image

    def _make(self, level: int) -> Any:
        # Bad settings raise xbandsim.errors.InvalidFieldError naming the field.
        return _xbandsim.Env(
            self.task, level, self.image_size, self._max_steps, self._threads, self._sea_clutter
        )

    def _observation(self, image: np.ndarray, info: dict) -> Any:
        if not self.own_ship_state:
            return image
        course = np.deg2rad(info["own_ship_course_deg"])
        own = np.array(
            [info["own_ship_speed_kn"], np.sin(course), np.cos(course)], dtype=np.float32
        )
        return {"ppi": image, "own_ship": own}

    def reset(
        self, *, seed: int | None = None, options: dict | None = None
    ) -> tuple[Any, dict]:
        super().reset(seed=seed)
        if options and "level" in options and int(options["level"]) != self.level:
            self._env = self._make(int(options["level"]))
            self.level = int(options["level"])
        episode_seed = int(self.np_random.integers(0, 2**63 - 1))
        image, info = self._env.reset(episode_seed)
        info["episode_seed"] = episode_seed
        return self._observation(image, info), info

    def step(self, action: Any) -> tuple[Any, float, bool, bool, dict]:
        vector = np.asarray(action, dtype=np.int64).reshape(-1).tolist()
        image, reward, terminated, truncated, info = self._env.step(vector)
        return self._observation(image, info), reward, terminated, truncated, info

    def render(self) -> np.ndarray | None:
        if self.render_mode == "rgb_array":
            return self._env.render_rgb()
        return None

    @property
    def scene_toml(self) -> str:
        """The current episode's scene file (``xbandsim render`` re-renders it)."""
        return self._env.scene_toml


class DetectionEnv(RadarEnv):
    """``xbandsim/Detection-v0``: find every target in clutter in few revolutions."""

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(task="detection", **kwargs)


class TrackingEnv(RadarEnv):
    """``xbandsim/Tracking-v0``: keep moving targets in track, revolution after revolution."""

    def __init__(self, **kwargs: Any) -> None:
        super().__init__(task="tracking", **kwargs)


def register_envs() -> None:
    """Registers ``xbandsim/Detection-v0`` and ``xbandsim/Tracking-v0`` (done on
    ``import xbandsim`` when Gymnasium is installed)."""
    for name, entry in (
        ("xbandsim/Detection-v0", "xbandsim.envs:DetectionEnv"),
        ("xbandsim/Tracking-v0", "xbandsim.envs:TrackingEnv"),
    ):
        if name not in gym.registry:
            gym.register(id=name, entry_point=entry)
