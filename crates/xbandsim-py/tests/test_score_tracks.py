"""scripts/score_tracks.py against the metrics' definitions on tracks whose scores are known:
MOTA = 1 − (misses + false positives + switches)/objects (Bernardin & Stiefelhagen 2008),
IDF1 = 2·IDTP/(objects + hypotheses) (Ristani et al. 2016), HOTA = 1 for a perfect tracker
at zero distance (Luiten et al. 2021)."""

import importlib.util

from conftest import ROOT

spec = importlib.util.spec_from_file_location("score_tracks", ROOT / "scripts" / "score_tracks.py")
score_tracks = importlib.util.module_from_spec(spec)
spec.loader.exec_module(score_tracks)


def doc(scans):
    """A tracks.json of `scans`: each a list of objects (id, x, y) and of tracks (id, x, y)."""
    return {
        "scans": [
            {
                "objects": [{"id": i, "position_m": [x, y], "has_echo": True} for i, x, y in objects],
                "tracks": [
                    {"id": i, "position_m": [x, y], "status": "confirmed"} for i, x, y in tracks
                ],
            }
            for objects, tracks in scans
        ]
    }


OBJECTS = [(0, 0.0, 1000.0), (1, 500.0, 0.0)]


def test_a_perfect_tracker_scores_one():
    s = score_tracks.score(doc([(OBJECTS, [(7, 0.0, 1000.0), (9, 500.0, 0.0)])] * 3), 100.0)
    assert s["mota"] == 1.0 and s["idf1"] == 1.0 and s["motp"] == 0.0
    assert abs(s["HOTA"] - 1.0) < 1e-12 and abs(s["AssA"] - 1.0) < 1e-12


def test_false_tracks_misses_and_switches_count_as_defined():
    perfect = [(7, 0.0, 1000.0), (9, 500.0, 0.0)]
    scans = [
        (OBJECTS, perfect + [(3, -400.0, -400.0)]),  # a false track
        (OBJECTS, perfect[:1]),  # object 1 missed
        (OBJECTS, [(9, 0.0, 1000.0), (7, 500.0, 0.0)]),  # the two tracks swap objects
    ]
    s = score_tracks.score(doc(scans), 100.0)
    assert s["num_false_positives"] == 1 and s["num_misses"] == 1
    assert s["num_switches"] == 2
    assert abs(s["mota"] - (1.0 - (1 + 1 + 2) / 6.0)) < 1e-12
    # IDTP: the best one-to-one identity map keeps 7↔0 and 9↔1 for two scans each, less
    # object 1's miss: 3 of 6 objects and 6 hypotheses.
    assert abs(s["idf1"] - 2.0 * 3.0 / (6.0 + 6.0)) < 1e-12
    # A track 30 m off an object counts 30 m in MOTP.
    s = score_tracks.score(doc([(OBJECTS[:1], [(7, 30.0, 1000.0)])]), 100.0)
    assert abs(s["motp"] - 30.0) < 1e-9
