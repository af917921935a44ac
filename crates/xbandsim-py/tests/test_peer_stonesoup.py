"""scripts/peer_stonesoup.py: the Stone Soup peer tracker (Stone Soup 1.9.1,
https://stonesoup.readthedocs.io) on a tracks.json-like document made here: two boats on
straight lines, plots with 3 m Gaussian noise and no clutter. It must hold exactly the two
tracks once the 3-of-4 initiation has run, each within a few metres of its boat, score a
MOTA of at least 0.9 (scripts/score_tracks.py; Bernardin & Stiefelhagen 2008), and lose a
boat that stops echoing on the 6th missed scan, as `xbandsim track` does (docs/tracking.md).
No xbandsim binary is needed."""

import importlib.util
import math

import numpy as np
import pytest

from conftest import ROOT

pytest.importorskip("stonesoup", reason="pip install -r scripts/requirements-check.txt")


def load(name):
    spec = importlib.util.spec_from_file_location(name, ROOT / "scripts" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


peer = load("peer_stonesoup")
score_tracks = load("score_tracks")

PERIOD_S = 2.5
SIGMA_M = 3.0
# (id, start east, start north, velocity east, velocity north), m and m/s.
BOATS = [(0, -800.0, 500.0, 5.0, 0.0), (1, 600.0, -400.0, 0.0, 4.0)]
SETTINGS = {
    "gate": 13.82,
    "sigma_range_m": 5.0,
    "sigma_bearing_deg": 0.5,
    "sigma_a_cv_mps2": 0.05,
    "lost_after_misses": 6,
    "initiation": "3/4",
    "truth_gate_m": 100.0,
    "max_speed_kn": 40.0,
    "knot_mps": 0.5144444444444445,
}


def synthetic_doc(scans=30, silent_from=None, seed=7):
    """A tracks.json of `scans` revolutions with the antenna fixed at the origin: each boat
    plotted when the beam crosses it, with isotropic noise; boat 1 silent (no echo, no plot)
    from scan `silent_from` on."""
    rng = np.random.default_rng(seed)
    out = []
    for k in range(scans):
        start = k * PERIOD_S
        measurements, objects = [], []
        for i, x0, y0, vx, vy in BOATS:
            # The beam crosses the boat at start + bearing/360°·period (ships barely move in it).
            bearing = math.degrees(math.atan2(x0 + vx * start, y0 + vy * start)) % 360.0
            t = start + bearing / 360.0 * PERIOD_S
            x, y = x0 + vx * t, y0 + vy * t
            echo = silent_from is None or i != 1 or k < silent_from
            objects.append({"id": i, "position_m": [x, y], "has_echo": echo})
            if echo:
                measurements.append(
                    {
                        "time_s": t,
                        "position_m": [
                            x + rng.normal(0.0, SIGMA_M),
                            y + rng.normal(0.0, SIGMA_M),
                        ],
                        "covariance_m2": [[SIGMA_M**2, 0.0], [0.0, SIGMA_M**2]],
                    }
                )
        out.append(
            {
                "frame": k,
                "start_time_s": start,
                "period_s": PERIOD_S,
                "antenna_position_m": [0.0, 0.0, 6.0],
                "antenna_velocity_mps": [0.0, 0.0],
                "plots": len(measurements),
                "measurements": measurements,
                "tracks": [],
                "ended": [],
                "objects": objects,
            }
        )
    return {"scene": "synthetic", "seed": seed, "tracker": SETTINGS, "scans": out}


def nearest_m(track, scan):
    return min(
        math.dist(track["position_m"], o["position_m"]) for o in scan["objects"] if o["has_echo"]
    )


def test_the_peer_holds_two_straight_tracks():
    doc = synthetic_doc()
    tracks_doc, seconds = peer.track_with_stonesoup(doc)
    assert seconds > 0.0
    scans = tracks_doc["scans"]
    # Confirmed on the third plot, as 3-of-4 initiation confirms ours.
    assert [len(s["tracks"]) for s in scans[:2]] == [0, 0]
    for scan in scans[2:]:
        assert sorted(t["id"] for t in scan["tracks"]) == [0, 1], scan["frame"]
        for track in scan["tracks"]:
            limit = 15.0 if scan["frame"] < 6 else 8.0
            assert nearest_m(track, scan) < limit, (scan["frame"], track)
    s = score_tracks.score(tracks_doc, 100.0)
    assert s["mota"] >= 0.9, s
    assert s["num_switches"] == 0 and s["num_false_positives"] == 0, s
    # The input is left as it was: the peer's tracks are in a copy.
    assert all(s["tracks"] == [] for s in doc["scans"])


def test_the_peer_loses_a_silent_boat_on_the_sixth_missed_scan():
    silent = 12
    tracks_doc, _ = peer.track_with_stonesoup(synthetic_doc(scans=24, silent_from=silent))
    counts = [len(s["tracks"]) for s in tracks_doc["scans"]]
    # Kept through 5 missed scans (frames 12-16), lost on the 6th (frame 17).
    assert counts[silent : silent + 5] == [2] * 5, counts
    assert counts[silent + 5 :] == [1] * (24 - silent - 5), counts


def test_the_peer_settings_follow_the_tracks_json():
    s = peer.settings_of(synthetic_doc(scans=3))
    assert (s["initiation_hits"], s["initiation_scans"]) == (3, 4)
    assert s["gate"] == 13.82 and s["lost_after_misses"] == 6 and s["period_s"] == PERIOD_S
    p = peer.StoneSoupPeer(s)
    # Stone Soup's continuous white-noise acceleration model with q = σa²·T: over one period
    # its velocity and cross terms equal the discrete white-noise model's σa²·T² and σa²·T³/2.
    from datetime import timedelta

    q = p.transition_model.covar(time_interval=timedelta(seconds=PERIOD_S))
    sa2 = SETTINGS["sigma_a_cv_mps2"] ** 2
    assert q[1, 1] == pytest.approx(sa2 * PERIOD_S**2)
    assert q[0, 1] == pytest.approx(sa2 * PERIOD_S**3 / 2.0)
    assert q[0, 0] == pytest.approx(sa2 * PERIOD_S**4 / 3.0)
