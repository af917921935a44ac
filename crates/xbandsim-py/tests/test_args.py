"""Argument checking, one set of rules for every public function (xbandsim/_args.py): whole
numbers take Python and NumPy ints and refuse bool, str, None, fractions, NaN and infinity
with a message naming the argument, its value and the allowed range; scene values take NumPy
scalars and arrays alike in from_dict and with_settings and refuse NaN and infinity naming
the field; each kind of error has its class."""

import math
from pathlib import Path

import numpy as np
import pytest

import xbandsim
from xbandsim.data import RadarDataset

ROOT = Path(__file__).resolve().parents[3]
SPEC = ROOT / "datasets" / "detection.toml"
SMALL = {
    "radar": {"spokes": 90, "max_range_m": 1500.0},
    "environment": {"clutter": False},
    "object": [{"name": "buoy", "shape": "point", "rcs_m2": 10.0, "position_m": [0.0, 800.0, 2.0]}],
}

# (bad value, exception class, problem, how the message shows the value)
BAD_WHOLE = [
    (None, xbandsim.ArgumentTypeError, "wrong type", "None"),
    ("3", xbandsim.ArgumentTypeError, "wrong type", "'3'"),
    (True, xbandsim.ArgumentTypeError, "wrong type", "True"),
    (1.5, xbandsim.InvalidArgumentError, "not a whole number", "1.5"),
    (math.nan, xbandsim.InvalidArgumentError, "not finite", "NaN"),
    (math.inf, xbandsim.InvalidArgumentError, "not finite", "inf"),
    (np.float64("nan"), xbandsim.InvalidArgumentError, "not finite", "NaN"),
    (-1, xbandsim.InvalidArgumentError, "out of range", "-1"),
]


def _calls(tmp_path):
    """name -> (argument, call(value)) for every public function taking a whole number."""
    sim = xbandsim.Scene.from_dict(SMALL).simulation()
    out = tmp_path / "never-made"
    return {
        "Simulation.render seed": ("seed", lambda v: sim.render(seed=v)),
        "Simulation.render frame": ("frame", lambda v: sim.render(frame=v)),
        "render seed": ("seed", lambda v: xbandsim.render(ROOT / "scenes" / "paper.toml", seed=v)),
        "dataset.generate count": ("count", lambda v: xbandsim.dataset.generate(SPEC, out, v)),
        "dataset.generate seed": ("seed", lambda v: xbandsim.dataset.generate(SPEC, out, 2, v)),
        "dataset.generate jobs": (
            "jobs", lambda v: xbandsim.dataset.generate(SPEC, out, 2, jobs=v)
        ),
        "dataset.generate shard_samples": (
            "shard_samples", lambda v: xbandsim.dataset.generate(SPEC, out, 2, shard_samples=v)
        ),
        "RadarDataset count": ("count", lambda v: RadarDataset(SPEC, count=v, tensors=False)),
        "RadarDataset seed": ("seed", lambda v: RadarDataset(SPEC, count=1, seed=v)),
    }


@pytest.mark.parametrize("bad,cls,problem,shown", BAD_WHOLE, ids=[repr(b[0]) for b in BAD_WHOLE])
def test_whole_number_arguments_refuse_what_is_not_one(tmp_path, bad, cls, problem, shown):
    for what, (name, call) in _calls(tmp_path).items():
        if bad is None and what in ("dataset.generate shard_samples", "RadarDataset count"):
            continue  # None is allowed there (folders; a dataset folder's every sample)
        with pytest.raises(cls) as e:
            call(bad)
        assert e.value.field == name and e.value.problem == problem, (what, e.value)
        message = str(e.value)
        # The CLI's words: the argument, the value, what is allowed (inclusive bounds).
        assert message.startswith(f"invalid {name} {shown}: must be a whole number"), (what, message)
        assert "…" in message or "or more" in message, (what, message)
        assert isinstance(e.value, xbandsim.XbandsimError) and isinstance(e.value, ValueError)
        if cls is xbandsim.ArgumentTypeError:
            assert isinstance(e.value, TypeError)
    assert not (tmp_path / "never-made").exists()


def test_the_messages_give_the_range_with_inclusive_bounds(tmp_path):
    with pytest.raises(xbandsim.InvalidArgumentError) as e:
        xbandsim.dataset.generate(SPEC, tmp_path / "x", 0)
    assert str(e.value) == "invalid count 0: must be a whole number 1 … 2**64 - 1"
    with pytest.raises(xbandsim.InvalidArgumentError) as e:
        xbandsim.Scene.from_dict(SMALL).simulation().render(seed=2**64)
    assert str(e.value) == (
        "invalid seed 18446744073709551616: must be a whole number 0 … 2**64 - 1"
    )
    with pytest.raises(xbandsim.ArgumentTypeError) as e:
        RadarDataset(SPEC, count=None)
    assert e.value.field == "count" and "needs count" in str(e.value)
    with pytest.raises(xbandsim.InvalidArgumentError, match=r"invalid image 'infrared': must "
                       r"be one of 'gray', 'colour'"):
        RadarDataset(SPEC, count=1, image="infrared")
    with pytest.raises(xbandsim.ArgumentTypeError, match="invalid masks 1: must be True or False"):
        RadarDataset(SPEC, count=1, masks=1)
    # A bad shard text is the generator's error (the CLI's words), of the same class.
    with pytest.raises(xbandsim.InvalidArgumentError) as e:
        xbandsim.dataset.generate(SPEC, tmp_path / "y", 4, shard="5/4")
    assert e.value.field == "shard" and "5/4" in str(e.value)
    with pytest.raises(xbandsim.ArgumentTypeError) as e:
        xbandsim.dataset.generate(SPEC, tmp_path / "y", 4, shard=5)
    assert e.value.field == "shard"


def test_numpy_integers_and_whole_floats_are_whole_numbers(tmp_path):
    sim = xbandsim.Scene.from_dict(SMALL).simulation()
    want = sim.render(seed=3, frame=1).polar_db
    for seed, frame in ((np.int64(3), np.uint8(1)), (np.array(3), 1), (3.0, np.float32(1.0))):
        assert np.array_equal(sim.render(seed=seed, frame=frame).polar_db, want)
    summary = xbandsim.dataset.generate(SPEC, tmp_path / "ds", np.int32(2), np.int64(5), jobs=np.int8(1))
    assert summary["made"] == 2
    ds = RadarDataset(tmp_path / "ds", count=np.int64(1), tensors=False)
    assert len(ds) == 1


def test_with_settings_refuses_nan_and_infinity_naming_the_field():
    scene = xbandsim.Scene.from_dict(SMALL)
    for value, shown in ((math.nan, "NaN"), (math.inf, "inf"), (-math.inf, "-inf"),
                         (np.float32("nan"), "NaN")):
        with pytest.raises(xbandsim.InvalidFieldError) as e:
            scene.with_settings({"radar.pulse_width_us": value})
        assert str(e.value) == (
            f"settings: invalid `radar.pulse_width_us` = {shown}: must be a finite number"
        )
        assert e.value.field == "radar.pulse_width_us" and e.value.problem == "not finite"
    with pytest.raises(xbandsim.InvalidFieldError) as e:
        scene.with_settings({"object[0].position_m": np.array([0.0, np.nan, 2.0])})
    assert str(e.value) == (
        "settings: invalid `object[0].position_m` = [0.0, NaN, 2.0]: component 1 must be a "
        "finite number"
    )
    # The same words as the scene loader's for a TOML file holding nan.
    with pytest.raises(xbandsim.InvalidFieldError) as e:
        scene.with_settings({"radar.pulse_width_us": -1.0}).simulation()
    assert e.value.problem == "out of range"
    with pytest.raises(xbandsim.ArgumentTypeError):
        scene.with_settings([("radar.spokes", 45)])


def test_from_dict_takes_numpy_values_as_with_settings_does():
    plain = xbandsim.Scene.from_dict(SMALL).simulation().render(seed=1).polar_db
    numpy_scene = {
        "radar": {"spokes": np.int64(90), "max_range_m": np.float32(1500.0)},
        "environment": {"clutter": np.bool_(False)},
        "object": [
            {"name": np.str_("buoy"), "shape": "point", "rcs_m2": np.float64(10.0),
             "position_m": np.array([0.0, 800.0, 2.0])}
        ],
    }
    from_numpy = xbandsim.Scene.from_dict(numpy_scene).simulation().render(seed=1).polar_db
    assert np.array_equal(plain, from_numpy)
    by_settings = (
        xbandsim.Scene.from_dict(SMALL)
        .with_settings({"radar.spokes": np.int64(90), "object[0].position_m": np.array([0.0, 800.0, 2.0])})
        .simulation()
        .render(seed=1)
        .polar_db
    )
    assert np.array_equal(plain, by_settings)
    bad = dict(SMALL, radar={"spokes": 90, "max_range_m": np.float64("inf")})
    with pytest.raises(xbandsim.InvalidFieldError) as e:
        xbandsim.Scene.from_dict(bad, name="mine")
    assert str(e.value) == "mine: invalid `radar.max_range_m` = inf: must be a finite number"
    assert e.value.field == "radar.max_range_m"
    with pytest.raises(xbandsim.SceneSyntaxError, match="radar.spokes"):
        xbandsim.Scene.from_dict({"radar": {"spokes": {1, 2}}})
    with pytest.raises(xbandsim.ArgumentTypeError):
        xbandsim.Scene.from_dict([("radar", {})])
