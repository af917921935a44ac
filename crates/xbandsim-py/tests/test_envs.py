"""The Gymnasium environments (docs/rl.md): registration, Gymnasium's own checker, reproducible
resets, vector environments in one process and across processes, rendering, errors, and the
example scripts run headless (the heuristic agent must beat the random one)."""

import json

import numpy as np
import pytest

gym = pytest.importorskip("gymnasium", reason="gymnasium is not installed")
from gymnasium.utils.env_checker import check_env  # noqa: E402

import xbandsim  # noqa: E402
from conftest import run_python  # noqa: E402
from xbandsim.envs import ACTION_NAMES, action_vector  # noqa: E402

IDS = ["xbandsim/Detection-v0", "xbandsim/Tracking-v0"]


@pytest.mark.parametrize("env_id", IDS)
def test_registered_and_passes_gymnasiums_checker(env_id):
    env = gym.make(env_id, level=1, image_size=64, render_mode="rgb_array")
    check_env(env.unwrapped, skip_render_check=False)
    # One channel, last: (H, W, 1), Gymnasium's and Stable-Baselines3's image layout.
    assert env.observation_space.shape == (64, 64, 1)
    assert env.observation_space.dtype == np.uint8
    assert list(env.action_space.nvec) == [5, 4, 4, 4, 3, 3]
    assert ACTION_NAMES == ("scan", "pulse", "gain", "sea", "rain", "integration")
    env.close()


def test_default_observation_is_256_and_dict_observation_passes_the_checker():
    env = gym.make("xbandsim/Tracking-v0")
    obs, _ = env.reset(seed=0)
    assert obs.shape == (256, 256, 1) and obs.dtype == np.uint8
    env = gym.make("xbandsim/Tracking-v0", level=2, image_size=48, own_ship_state=True)
    check_env(env.unwrapped)
    obs, info = env.reset(seed=1)
    assert set(obs) == {"ppi", "own_ship"}
    assert obs["ppi"].shape == (48, 48, 1) and env.observation_space["ppi"].shape == (48, 48, 1)
    speed, s, c = obs["own_ship"]
    assert speed == pytest.approx(info["own_ship_speed_kn"], rel=1e-6)
    assert s * s + c * c == pytest.approx(1.0, abs=1e-6)


def _rollout(env, seed, steps=4):
    obs, info = env.reset(seed=seed)
    frames, rewards = [obs], []
    for k in range(steps):
        a = action_vector(scan="full" if k % 2 == 0 else k % 4, pulse="long", gain=k % 4)
        obs, r, term, trunc, info = env.step(a)
        frames.append(obs)
        rewards.append(r)
        if term or trunc:
            break
    return frames, rewards, info


def test_reset_with_a_seed_is_reproducible():
    env = gym.make("xbandsim/Tracking-v0", level=2, image_size=64)
    a = _rollout(env, 7)
    b = _rollout(env, 7)
    c = _rollout(gym.make("xbandsim/Tracking-v0", level=2, image_size=64), 7)
    for x in (b, c):
        assert all(np.array_equal(p, q) for p, q in zip(a[0], x[0]))
        assert a[1] == x[1]
    d = _rollout(env, 8)
    assert not all(np.array_equal(p, q) for p, q in zip(a[0], d[0]))


def test_info_reports_the_truth_it_scored():
    env = gym.make("xbandsim/Detection-v0", level=0, image_size=64)
    _, info = env.reset(seed=2)
    obs, reward, terminated, truncated, info = env.step(action_vector())
    assert info["revolution"] == 1
    assert info["pulses"] == 180  # a full scan, one pulse per spoke
    (target,) = info["targets"]  # level 0: one target
    assert target["class"] in ("boat", "ship") and target["rcs_m2"] >= 100.0
    assert 250.0 <= target["range_m"] <= 1400.0
    found = target["detected"]
    expect = (1.0 if found else 0.0) - 0.1 - 0.01 * info["false_plots"]
    assert reward == pytest.approx(expect, abs=1e-12)
    assert terminated == found and not truncated
    assert len(info["plot_list"]) == info["plots"]


def test_episodes_end_by_truncation_at_their_length():
    env = gym.make("xbandsim/Tracking-v0", level=0, image_size=32, max_steps=3)
    env.reset(seed=0)
    flags = [env.step(action_vector())[2:4] for _ in range(3)]
    assert flags == [(False, False), (False, False), (False, True)]


def test_level_option_changes_the_curriculum():
    env = gym.make("xbandsim/Tracking-v0", level=0, image_size=32)
    _, info = env.reset(seed=0)
    assert len(info["targets"]) == 1 and info["sea_state"] <= 1.5
    _, info = env.reset(seed=0, options={"level": 3})
    assert 3 <= len(info["targets"]) <= 8 and info["sea_state"] >= 4.0
    assert env.unwrapped.level == 3


def test_render_rgb_array():
    env = gym.make("xbandsim/Detection-v0", image_size=40, render_mode="rgb_array")
    obs, _ = env.reset(seed=0)
    rgb = env.render()
    assert rgb.shape == (40, 40, 3) and rgb.dtype == np.uint8
    # The phosphor-green map: red and blue never exceed green.
    assert (rgb[..., 1] >= rgb[..., 0]).all() and (rgb[..., 1] >= rgb[..., 2]).all()
    plain = gym.make("xbandsim/Detection-v0", image_size=40)
    plain.reset(seed=0)
    assert plain.render() is None


def test_bad_settings_and_actions_raise_naming_the_argument():
    with pytest.raises(xbandsim.InvalidArgumentError) as e:
        gym.make("xbandsim/Detection-v0", level=4)
    assert e.value.field == "level"
    assert str(e.value) == "invalid level 4: must be a whole number 0 … 3"
    with pytest.raises(xbandsim.InvalidArgumentError) as e:
        gym.make("xbandsim/Detection-v0", image_size=8)
    assert e.value.field == "image_size"
    assert str(e.value) == "invalid image_size 8: must be a whole number 16 … 2048"
    with pytest.raises(xbandsim.InvalidArgumentError, match="render_mode"):
        xbandsim.envs.DetectionEnv(render_mode="human")
    for kwargs, name in ((dict(level="1"), "level"), (dict(level=None), "level"),
                         (dict(threads=True), "threads"), (dict(own_ship_state=1), "own_ship_state")):
        with pytest.raises(xbandsim.ArgumentTypeError) as e:
            xbandsim.envs.DetectionEnv(**kwargs)
        assert e.value.field == name
    with pytest.raises(xbandsim.InvalidArgumentError) as e:
        xbandsim.envs.TrackingEnv(max_steps=1.5)
    assert e.value.problem == "not a whole number"
    env = gym.make("xbandsim/Detection-v0", image_size=32)
    env.reset(seed=0)
    with pytest.raises(xbandsim.InvalidArgumentError) as e:
        env.reset(seed=0, options={"level": 4})
    assert "0 … 3" in str(e.value)
    with pytest.raises(xbandsim.ArgumentTypeError):
        env.reset(seed="3")
    # Actions: each component named, its range written with inclusive bounds.
    with pytest.raises(xbandsim.InvalidArgumentError) as e:
        env.unwrapped.step([0, 0, 9, 0, 0, 0])
    assert e.value.field == "action.gain"
    assert str(e.value) == "invalid action.gain 9: must be a whole number 0 … 3"
    with pytest.raises(xbandsim.InvalidArgumentError) as e:
        env.unwrapped.step(np.array([5, 0, 0, 0, 0, 0]))
    assert str(e.value) == "invalid action.scan 5: must be a whole number 0 … 4"
    # NaN is not read as a number (it was cast to -9223372036854775808).
    with pytest.raises(xbandsim.InvalidArgumentError) as e:
        env.unwrapped.step(np.array([0, 0, np.nan, 0, 0, 0]))
    assert str(e.value) == "invalid action.gain NaN: must be a whole number 0 … 3"
    assert e.value.problem == "not finite"
    with pytest.raises(xbandsim.InvalidArgumentError) as e:
        env.unwrapped.step([0, 0])
    assert e.value.field == "action"
    assert "scan, pulse, gain, sea, rain, integration" in str(e.value)
    with pytest.raises(xbandsim.ArgumentTypeError):
        env.unwrapped.step([0, 0, True, 0, 0, 0])
    # Whole floats and NumPy integers are actions too.
    env.unwrapped.step(np.array([0, 3, 1.0, 2, 0, 0]))
    env.unwrapped.step([np.int8(0), 3, np.uint16(1), 2, 0, 0])
    # The episode's own checks (the Rust crate's) say the same.
    with pytest.raises(xbandsim.InvalidFieldError) as e:
        xbandsim._xbandsim.Env("detection", 4, 64, 0, 1)
    assert str(e.value) == "invalid `level` = 4: must be 0 … 3 (the curriculum levels)"
    xbandsim._xbandsim.Env("detection", xbandsim.envs.LEVELS - 1, 64, 0, 1)


def test_action_vector_checks_and_lists_the_names():
    assert list(action_vector(scan=2, pulse="long", gain=3, sea=0, rain=2, integration=1)) == [
        3, 2, 3, 0, 2, 1
    ]
    assert xbandsim.envs.PULSES == ("short", "medium", "long", "combined")
    with pytest.raises(xbandsim.InvalidArgumentError) as e:
        action_vector(pulse="medium-long")
    assert str(e.value) == (
        "invalid pulse 'medium-long': must be one of 'short', 'medium', 'long', 'combined'"
    )
    with pytest.raises(xbandsim.InvalidArgumentError) as e:
        action_vector(scan="north")
    assert str(e.value) == 'invalid scan \'north\': must be "full" or a quadrant 0 … 3'
    with pytest.raises(xbandsim.InvalidArgumentError) as e:
        action_vector(scan=4)
    assert str(e.value) == 'invalid scan 4: must be "full" or a quadrant 0 … 3'
    for name, bad in (("gain", 4), ("sea", -1), ("rain", 3), ("integration", 3)):
        with pytest.raises(xbandsim.InvalidArgumentError) as e:
            action_vector(**{name: bad})
        assert e.value.field == name and "must be a whole number 0 … " in str(e.value)
    with pytest.raises(xbandsim.InvalidArgumentError, match="invalid rain NaN"):
        action_vector(rain=float("nan"))
    with pytest.raises(xbandsim.ArgumentTypeError):
        action_vector(gain="2")
    # Every component name is an argument name.
    import inspect

    assert tuple(inspect.signature(action_vector).parameters) == ACTION_NAMES


def _vector_rollout(vector_cls):
    envs = vector_cls(
        [lambda: gym.make("xbandsim/Tracking-v0", level=1, image_size=48) for _ in range(2)]
    )
    obs, _ = envs.reset(seed=[3, 4])
    frames = [obs]
    for _ in range(3):
        obs, rewards, terms, truncs, infos = envs.step(np.stack([action_vector()] * 2))
        assert obs.shape == (2, 48, 48, 1) and rewards.shape == (2,)
        frames.append(obs)
    envs.close()
    return frames


def test_sync_and_async_vector_envs_agree():
    sync = _vector_rollout(gym.vector.SyncVectorEnv)
    asynchronous = _vector_rollout(gym.vector.AsyncVectorEnv)
    assert all(np.array_equal(a, b) for a, b in zip(sync, asynchronous))
    # The two environments drew different episodes.
    assert not np.array_equal(sync[0][0], sync[0][1])


def test_example_agents_heuristic_beats_random(repo_root):
    out = run_python(
        ["examples/agents.py", "--episodes", "3", "--level", "1", "--json"], repo_root
    )
    returns = json.loads(out.stdout)
    for task in ("detection", "tracking"):
        heuristic = np.mean(returns[f"{task}/heuristic"])
        random = np.mean(returns[f"{task}/random"])
        assert heuristic > random, (task, returns)


def test_example_tracker_tuning_searches_the_controls(repo_root):
    """examples/tune_tracker.py: the coordinate ascent tries every other value of each control
    once (1 + 3 + 3 + 3 + 2 + 2 settings), never ends below the default's HOTA, and the
    baseline tracker holds the targets of a calm level-0 episode (HOTA over 0.2)."""
    out = run_python(
        ["examples/tune_tracker.py", "--level", "0", "--episodes", "1", "--steps", "8", "--json"],
        repo_root,
    )
    result = json.loads(out.stdout)
    assert result["settings_tried"] == 14
    assert result["tuned"]["HOTA"] >= result["default"]["HOTA"]
    assert result["default"]["HOTA"] > 0.2, result



def test_the_tracking_env_reports_the_baseline_trackers_tracks():
    """Level 0 with reward="tracks": the tracker's confirmed tracks come in info with their
    fields, each paired with at most one target (its ``track_id``); every revolution pays the
    held share of the targets in view less 0.1 per false track; the detection task refuses the
    track reward, naming it."""
    env = gym.make("xbandsim/Tracking-v0", level=0, image_size=64, reward="tracks")
    _, info = env.reset(seed=0)
    held = 0
    for _ in range(8):
        _, reward, _, _, info = env.step(action_vector())
        targets = info["targets"]
        in_view = [t for t in targets if t["observed"]]
        paired = [t for t in in_view if t["track_id"] is not None]
        expect = (len(paired) / len(in_view) if in_view else 0.0) - 0.1 * info["false_tracks"]
        assert abs(reward - expect) < 1e-12
        ids = {t["id"] for t in info["tracks"]}
        assert {t["track_id"] for t in targets if t["track_id"] is not None} <= ids
        for t in info["tracks"]:
            assert {"id", "position_m", "velocity_mps", "course_deg", "speed_kn", "cpa_m"} <= set(t)
        held += len(paired)
    assert held > 0
    env.close()
    with pytest.raises(xbandsim.InvalidArgumentError, match="reward"):
        gym.make("xbandsim/Detection-v0", reward="tracks")


def test_the_track_reward_is_reproducible():
    """The same seed in a fresh environment gives the same tracks, pairings and rewards."""

    def run():
        env = gym.make("xbandsim/Tracking-v0", level=1, image_size=64, reward="tracks")
        env.reset(seed=4)
        out = []
        for k in range(6):
            _, reward, _, _, info = env.step(action_vector(gain=k % 4))
            out.append(
                (
                    reward,
                    info["false_tracks"],
                    [(t["id"], t["position_m"], t["velocity_mps"]) for t in info["tracks"]],
                    [t["track_id"] for t in info["targets"]],
                )
            )
        env.close()
        return out

    assert run() == run()
