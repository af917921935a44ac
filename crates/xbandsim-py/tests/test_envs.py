"""The Gymnasium environments (docs/rl.md): registration, Gymnasium's own checker, reproducible
resets, vector environments in one process and across processes, rendering, errors, and the
example scripts run headless (the heuristic agent must beat the random one)."""

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

gym = pytest.importorskip("gymnasium", reason="gymnasium is not installed")
from gymnasium.utils.env_checker import check_env  # noqa: E402

import xbandsim  # noqa: E402
from xbandsim.envs import ACTION_NAMES, action_vector  # noqa: E402

ROOT = Path(__file__).resolve().parents[3]
IDS = ["xbandsim/Detection-v0", "xbandsim/Tracking-v0"]


@pytest.mark.parametrize("env_id", IDS)
def test_registered_and_passes_gymnasiums_checker(env_id):
    env = gym.make(env_id, level=1, image_size=64, render_mode="rgb_array")
    check_env(env.unwrapped, skip_render_check=False)
    assert env.observation_space.shape == (64, 64)
    assert env.observation_space.dtype == np.uint8
    assert list(env.action_space.nvec) == [5, 4, 4, 4, 3, 3]
    assert ACTION_NAMES == ("scan", "pulse", "gain", "sea", "rain", "integration")
    env.close()


def test_default_observation_is_256_and_dict_observation_passes_the_checker():
    env = gym.make("xbandsim/Tracking-v0")
    obs, _ = env.reset(seed=0)
    assert obs.shape == (256, 256) and obs.dtype == np.uint8
    env = gym.make("xbandsim/Tracking-v0", level=2, image_size=48, own_ship_state=True)
    check_env(env.unwrapped)
    obs, info = env.reset(seed=1)
    assert set(obs) == {"ppi", "own_ship"}
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


def test_bad_settings_and_actions_raise_naming_the_field():
    with pytest.raises(xbandsim.InvalidFieldError) as e:
        gym.make("xbandsim/Detection-v0", level=4)
    assert e.value.field == "level"
    with pytest.raises(xbandsim.InvalidFieldError) as e:
        gym.make("xbandsim/Detection-v0", image_size=8)
    assert e.value.field == "image_size_px"
    with pytest.raises(ValueError, match="render_mode"):
        xbandsim.envs.DetectionEnv(render_mode="human")
    env = gym.make("xbandsim/Detection-v0", image_size=32)
    env.reset(seed=0)
    with pytest.raises(xbandsim.InvalidFieldError) as e:
        env.unwrapped.step([0, 0, 9, 0, 0, 0])
    assert e.value.field == "action.gain" and "0..4" in str(e.value)
    with pytest.raises(xbandsim.InvalidFieldError) as e:
        env.unwrapped.step([0, 0])
    assert e.value.field == "action"
    with pytest.raises(ValueError):
        action_vector(pulse="medium-long")


def _vector_rollout(vector_cls):
    envs = vector_cls(
        [lambda: gym.make("xbandsim/Tracking-v0", level=1, image_size=48) for _ in range(2)]
    )
    obs, _ = envs.reset(seed=[3, 4])
    frames = [obs]
    for _ in range(3):
        obs, rewards, terms, truncs, infos = envs.step(np.stack([action_vector()] * 2))
        assert obs.shape == (2, 48, 48) and rewards.shape == (2,)
        frames.append(obs)
    envs.close()
    return frames


def test_sync_and_async_vector_envs_agree():
    sync = _vector_rollout(gym.vector.SyncVectorEnv)
    asynchronous = _vector_rollout(gym.vector.AsyncVectorEnv)
    assert all(np.array_equal(a, b) for a, b in zip(sync, asynchronous))
    # The two environments drew different episodes.
    assert not np.array_equal(sync[0][0], sync[0][1])


def _example(*args, timeout=600):
    env = dict(os.environ, MPLBACKEND="Agg")
    out = subprocess.run(
        [sys.executable, *args],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=timeout,
    )
    assert out.returncode == 0, out.stderr
    return out.stdout


def test_example_agents_heuristic_beats_random():
    returns = json.loads(
        _example("examples/agents.py", "--episodes", "3", "--level", "1", "--json")
    )
    for task in ("detection", "tracking"):
        heuristic = np.mean(returns[f"{task}/heuristic"])
        random = np.mean(returns[f"{task}/random"])
        assert heuristic > random, (task, returns)


def test_example_render_frame_and_dataset_boxes_run_headless(tmp_path):
    pytest.importorskip("matplotlib", reason="the plotting examples need matplotlib")
    png = tmp_path / "frame.png"
    out = _example("examples/render_frame.py", "scenes/paper.toml", "--out", str(png))
    assert png.stat().st_size > 10_000 and "5 objects" in out
    ds = tmp_path / "ds"
    out = _example("examples/dataset_boxes.py", "--count", "4", "--out", str(ds))
    assert (ds / "boxes.png").stat().st_size > 10_000 and "4 samples" in out
