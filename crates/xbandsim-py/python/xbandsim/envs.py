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

from . import _args, _xbandsim
from .errors import ArgumentTypeError, InvalidArgumentError

__all__ = [
    "ACTION_NAMES",
    "ACTION_CHOICES",
    "PULSES",
    "LEVELS",
    "check_action",
    "RadarEnv",
    "DetectionEnv",
    "TrackingEnv",
    "action_vector",
    "register_envs",
]

_NVEC, _NAMES = _xbandsim.action_space()
#: Names of the action vector's components (docs/rl.md, "Action").
ACTION_NAMES: tuple[str, ...] = tuple(_NAMES)
#: Choices of each component, in ``ACTION_NAMES``' order: a component takes 0 … n - 1.
ACTION_CHOICES: tuple[int, ...] = tuple(int(n) for n in _NVEC)
#: ``pulse`` by name, in its index order (docs/rl.md, "Action").
PULSES: tuple[str, ...] = ("short", "medium", "long", "combined")
#: Curriculum levels 0 … LEVELS - 1 (docs/rl.md, "Episodes and the curriculum").
LEVELS = 4
_NVEC_ARRAY = np.array(ACTION_CHOICES, dtype=np.int64)


def action_vector(
    scan: int | str = "full",
    pulse: str = "combined",
    gain: int = 1,
    sea: int = 2,
    rain: int = 0,
    integration: int = 0,
) -> np.ndarray:
    """An action by name (docs/rl.md, "Action"); the arguments are ``ACTION_NAMES``:

    - ``scan``: ``"full"`` or a quadrant to dwell on, 0 … 3 (0 north-east, 1 south-east,
      2 south-west, 3 north-west);
    - ``pulse``: one of ``PULSES``, ``"short"``, ``"medium"``, ``"long"``, ``"combined"``;
    - ``gain``: 0 … 3 (display floor 12, 9, 6, 3 dB over noise);
    - ``sea``: 0 … 3 (sea clutter control off … strongest);
    - ``rain``: 0 … 2 (rain clutter control off, 0.6, 0.9);
    - ``integration``: 0 … 2 (1, 2 or 4 pulses per spoke).

    A value outside these raises ``InvalidArgumentError`` naming it and its choices (a wrong
    type ``ArgumentTypeError``)."""
    if isinstance(scan, str) and scan == "full":
        scan_index = 0
    else:
        quadrant = '"full" or a quadrant'
        if isinstance(scan, str):
            raise _args.error("scan", scan, f"must be {quadrant} 0 … 3", "unknown choice")
        scan_index = _args.whole("scan", scan, 0, ACTION_CHOICES[0] - 2, what=quadrant) + 1
    values = [
        scan_index,
        PULSES.index(_args.choice("pulse", pulse, PULSES)),
        *(
            _args.whole(name, value, 0, n - 1)
            for name, value, n in zip(ACTION_NAMES[2:], (gain, sea, rain, integration), ACTION_CHOICES[2:])
        ),
    ]
    return np.array(values, dtype=np.int64)


def check_action(action: Any) -> list[int]:
    """The action as the list of ints the episode takes: ``len(ACTION_NAMES)`` whole
    numbers, component ``i`` in 0 … ``ACTION_CHOICES[i]`` - 1 (ints of Python or NumPy, or
    whole floats). A bad component raises ``InvalidArgumentError`` naming it
    (``action.gain``): NaN is not read as a number."""
    n = len(ACTION_NAMES)
    if isinstance(action, np.ndarray) and action.size == n:
        a = action.reshape(-1)
        if a.dtype.kind in "iu" and ((a >= 0) & (a < _NVEC_ARRAY)).all():
            return a.tolist()  # the usual case: a MultiDiscrete sample, in range
        items = list(a)
    elif isinstance(action, (list, tuple)) and len(action) == n:
        items = list(action)
    else:
        sized = isinstance(action, (np.ndarray, list, tuple))
        raise _args.error(
            "action",
            action,
            f"an action is {n} whole numbers ({', '.join(ACTION_NAMES)})",
            "conflict" if sized else "wrong type",
            InvalidArgumentError if sized else ArgumentTypeError,
        )
    return [
        _args.whole(f"action.{name}", value, 0, choices - 1)
        for name, value, choices in zip(ACTION_NAMES, items, ACTION_CHOICES)
    ]


class RadarEnv(gym.Env):
    """A radar-operator environment (docs/rl.md).

    Parameters
    ----------
    task:
        ``"detection"`` (find every target in few revolutions) or ``"tracking"`` (keep moving
        targets in track).
    level:
        Curriculum level 0 … 3: calm sea and one large target up to heavy clutter, rain and
        many small targets. ``reset(options={"level": k})`` changes it.
    image_size:
        Side of the square observation image, pixels, 16 … 2048 (default 256): the
        observation is uint8 ``(image_size, image_size, 1)``.
    own_ship_state:
        When True the observation is a Dict: ``"ppi"`` (the image) and ``"own_ship"``
        (float32 ``[speed_kn, sin(course), cos(course)]``).
    max_steps:
        Revolutions per episode, 1 or more (default: 12 for detection, 30 for tracking).
    render_mode:
        ``None`` or ``"rgb_array"`` (the display in phosphor green, uint8 (size, size, 3)).
    threads:
        Worker threads for the simulation, 1 … 256 (default 1: one core per environment; vector
        environments scale across processes).
    sea_clutter:
        Sea clutter on (default); ``False`` leaves noise, rain and the targets (an easier
        curriculum step, or an ablation).
    reward:
        ``"plots"`` (default: plots in the targets' gates) or, for the tracking task,
        ``"tracks"``: the baseline ARPA tracker's confirmed tracks on the targets, less false
        tracks (docs/rl.md, "Reward"). Either way ``info["tracks"]`` lists the tracker's
        confirmed tracks and ``info["targets"][i]["track_id"]`` the one on target i.
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
        reward: str = "plots",
    ) -> None:
        self.task = _args.choice("task", task, ("detection", "tracking"))
        self.level = _args.whole("level", level, 0, LEVELS - 1)
        self.image_size = _args.whole("image_size", image_size, 16, 2048)
        self.own_ship_state = _args.flag("own_ship_state", own_ship_state)
        self._max_steps = _args.optional(_args.whole, "max_steps", max_steps, 1) or 0
        self._threads = _args.whole("threads", threads, 1, 256)
        self._sea_clutter = _args.flag("sea_clutter", sea_clutter)
        self._reward = _args.choice("reward", reward, ("plots", "tracks"))
        if self._reward == "tracks" and self.task != "tracking":
            raise _args.error(
                "reward", reward, "the track reward is the tracking task's", "conflict",
                InvalidArgumentError,
            )
        self.render_mode = _args.optional(
            _args.choice, "render_mode", render_mode, self.metadata["render_modes"]
        )
        self._env = self._make(self.level)
        self.action_space = spaces.MultiDiscrete(np.array(_NVEC, dtype=np.int64))
        # (H, W, 1): one channel, last, as Gymnasium's and Stable-Baselines3's image
        # convention has it (SB3's CnnPolicy takes it as it is).
        image = spaces.Box(0, 255, (self.image_size, self.image_size, 1), np.uint8)
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
        # The arguments are checked above (InvalidArgumentError naming them); the episode
        # checks its config again (InvalidFieldError), a check that cannot fail from here.
        return _xbandsim.Env(
            self.task,
            level,
            self.image_size,
            self._max_steps,
            self._threads,
            self._sea_clutter,
            self._reward,
        )

    def _observation(self, image: np.ndarray, info: dict) -> Any:
        image = image.reshape(self.image_size, self.image_size, 1)  # a view: no copy
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
        seed = _args.optional(_args.seed, "seed", seed)
        level = self.level
        if options and "level" in options:
            level = _args.whole("options['level']", options["level"], 0, LEVELS - 1)
        super().reset(seed=seed)
        if level != self.level:
            self._env = self._make(level)
            self.level = level
        episode_seed = int(self.np_random.integers(0, 2**63 - 1))
        image, info = self._env.reset(episode_seed)
        info["episode_seed"] = episode_seed
        return self._observation(image, info), info

    def step(self, action: Any) -> tuple[Any, float, bool, bool, dict]:
        image, reward, terminated, truncated, info = self._env.step(check_action(action))
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
