"""The environments in Stable-Baselines3 as they are, without a wrapper: SB3's own checker has
nothing to warn about, PPO's CnnPolicy trains on the (H, W, 1) image, and MultiInputPolicy
puts the Dict observation's image through a CNN instead of flattening it.

scripts/test.sh installs SB3 and torch from PyPI (scripts/requirements-sb3.txt); where PyPI
has no torch wheel for this platform or Python it says so and these tests are skipped with
that reason, any other failure to install fails the run."""

import warnings

import numpy as np
import pytest

from conftest import optional_import  # noqa: E402

gym = pytest.importorskip("gymnasium", reason="gymnasium is not installed")
stable_baselines3 = optional_import("stable_baselines3", "sb3")
from stable_baselines3 import PPO  # noqa: E402
from stable_baselines3.common.env_checker import check_env  # noqa: E402
from stable_baselines3.common.torch_layers import NatureCNN  # noqa: E402

import xbandsim  # noqa: E402,F401  (registers the environments)

# NatureCNN's three convolutions need at least 36 x 36 pixels; 64 keeps the test fast.
SIZE = 64


@pytest.fixture(autouse=True)
def sb3_logs_in_the_tests_own_folder(tmp_path, monkeypatch):
    """PPO's logger makes a folder even when it writes nothing: the system's temporary
    folder (an SB3-<date> folder per model) unless SB3_LOGDIR names another."""
    monkeypatch.setenv("SB3_LOGDIR", str(tmp_path))


@pytest.mark.parametrize("own_ship_state", [False, True], ids=["Box", "Dict"])
def test_sb3_check_env_has_no_warnings(own_ship_state):
    env = gym.make(
        "xbandsim/Detection-v0", level=1, image_size=SIZE, own_ship_state=own_ship_state
    ).unwrapped
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        check_env(env, warn=True)
    assert [str(w.message) for w in caught] == []


def test_ppo_cnn_policy_trains_on_the_environment_as_it_is():
    env = gym.make("xbandsim/Detection-v0", level=1, image_size=SIZE)
    model = PPO(
        "CnnPolicy", env, n_steps=128, batch_size=64, n_epochs=1, seed=0, device="cpu", verbose=0
    )
    assert isinstance(model.policy.features_extractor, NatureCNN)
    model.learn(total_timesteps=256)
    assert model.num_timesteps >= 256
    obs, _ = env.reset(seed=1)
    action, _ = model.predict(obs, deterministic=True)
    assert env.action_space.contains(np.asarray(action, dtype=np.int64))
    env.step(action)


def test_multi_input_policy_puts_the_image_through_a_cnn():
    """With own_ship_state the observation is a Dict; SB3's CombinedExtractor takes its "ppi"
    through NatureCNN only when it is an image space (it flattened the (H, W) one)."""
    env = gym.make("xbandsim/Tracking-v0", level=1, image_size=SIZE, own_ship_state=True)
    model = PPO("MultiInputPolicy", env, n_steps=64, batch_size=64, seed=0, device="cpu")
    extractors = model.policy.features_extractor.extractors
    assert isinstance(extractors["ppi"], NatureCNN)
    model.learn(total_timesteps=64)
