#!/usr/bin/env python3
"""Scores the tracks of `xbandsim track` (tracks.json, docs/tracking.md) with the standard
multi-object tracking metrics of two well-kept libraries: CLEAR MOT (MOTA, MOTP) and IDF1
from py-motmetrics (Bernardin & Stiefelhagen 2008; Ristani et al. 2016), and HOTA with its
detection and association parts from TrackEval (Luiten et al., IJCV 129, 2021).

Each scan is a frame. Its ground truth: the objects that leave an echo (`has_echo`), at the
truth's positions; its hypotheses: the confirmed tracks, at their estimates. A track and an
object may match within `--gate-m` (default: the truth gate the tracks were made with,
`tracker.truth_gate_m`, 100 m unless set): motmetrics takes the Euclidean distance (MOTP in
metres), TrackEval the similarity
`1 − d/gate`.

`xbandsim track` scores its tracks the same way in Rust (`summary.scores` of tracks.json,
following both libraries step for step); `--check` fails unless the libraries' figures and
those agree to 1e-9.

Usage: score_tracks.py TRACKS_JSON [--gate-m D] [--json] [--check]
"""
import argparse
import json
import math
import sys

import numpy as np


def frames(doc):
    """Per scan: (gt ids, gt positions, track ids, track positions)."""
    out = []
    for scan in doc["scans"]:
        gt = [o for o in scan["objects"] if o["has_echo"]]
        tracks = [t for t in scan["tracks"] if t["status"] == "confirmed"]
        out.append((
            [o["id"] for o in gt],
            np.array([o["position_m"] for o in gt], dtype=float).reshape(-1, 2),
            [t["id"] for t in tracks],
            np.array([t["position_m"] for t in tracks], dtype=float).reshape(-1, 2),
        ))
    return out


def distances(a, b):
    return np.sqrt(((a[:, None, :] - b[None, :, :]) ** 2).sum(axis=2))


def accumulator(scans, gate_m):
    """py-motmetrics' accumulator of the scans (pairs allowed within `gate_m`)."""
    import motmetrics as mm
    acc = mm.MOTAccumulator(auto_id=True)
    for gt_ids, gt_pos, tr_ids, tr_pos in scans:
        d = distances(gt_pos, tr_pos)
        d[d > gate_m] = np.nan
        acc.update(gt_ids, tr_ids, d)
    return acc


CLEAR_MOT = ["mota", "motp", "idf1", "num_switches", "num_false_positives", "num_misses",
             "num_objects", "num_matches"]


def clear_mot(scans, gate_m):
    import motmetrics as mm
    row = mm.metrics.create().compute(accumulator(scans, gate_m), metrics=CLEAR_MOT, name="tracks")
    return {n: float(row[n].iloc[0]) for n in CLEAR_MOT}


def hota_result(scans, gate_m):
    """TrackEval's HOTA result of one sequence (arrays over its thresholds α)."""
    import trackeval
    gt_index, tr_index = {}, {}
    data = {"gt_ids": [], "tracker_ids": [], "similarity_scores": []}
    for gt_ids, gt_pos, tr_ids, tr_pos in scans:
        g = np.array([gt_index.setdefault(i, len(gt_index)) for i in gt_ids], dtype=int)
        t = np.array([tr_index.setdefault(i, len(tr_index)) for i in tr_ids], dtype=int)
        data["gt_ids"].append(g)
        data["tracker_ids"].append(t)
        data["similarity_scores"].append(np.clip(1.0 - distances(gt_pos, tr_pos) / gate_m, 0.0, 1.0))
    data["num_timesteps"] = len(scans)
    data["num_gt_ids"] = len(gt_index)
    data["num_tracker_ids"] = len(tr_index)
    data["num_gt_dets"] = sum(len(g) for g in data["gt_ids"])
    data["num_tracker_dets"] = sum(len(t) for t in data["tracker_ids"])
    return trackeval.metrics.HOTA().eval_sequence(data)


HOTA_FIELDS = ("HOTA", "DetA", "AssA", "LocA")


def hota(scans, gate_m):
    result = hota_result(scans, gate_m)
    # Averaged over TrackEval's localisation thresholds α = 0.05 … 0.95.
    return {k: float(np.mean(result[k])) for k in HOTA_FIELDS}


def score(doc, gate_m):
    scans = frames(doc)
    return {**clear_mot(scans, gate_m), **hota(scans, gate_m)}


# Our names in `summary.scores.figures` for the libraries' figures.
OURS = {"mota": "mota", "motp": "motp_m", "HOTA": "hota", "DetA": "det_a", "AssA": "ass_a",
        "LocA": "loc_a"}


def disagreements(scores, ours, tolerance=1e-9):
    """The figures where the libraries' `scores` and xbandsim's `ours` (tracks.json's
    `summary.scores.figures`) differ by more than `tolerance`."""
    out = []
    for theirs, mine in OURS.items():
        a, b = scores[theirs], ours.get(mine)
        if b is None:
            # xbandsim's null: no objects (MOTA) or no pairs (MOTP), where the libraries
            # divide by zero (inf or nan).
            agree = not math.isfinite(a)
        else:
            agree = abs(a - b) <= tolerance * max(1.0, abs(a))
        if not agree:
            out.append(f"{theirs}: libraries {a!r}, xbandsim {b!r}")
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("tracks_json")
    parser.add_argument("--gate-m", type=float, default=None,
                        help="pairing gate, m (default: the tracks' own truth gate, or 100)")
    parser.add_argument("--json", action="store_true", help="print the scores as JSON")
    parser.add_argument("--check", action="store_true",
                        help="fail unless xbandsim's own scores (summary.scores) agree")
    args = parser.parse_args()
    if args.gate_m is not None and not args.gate_m > 0:
        sys.exit(f"invalid --gate-m {args.gate_m}: must be a positive distance")
    try:
        with open(args.tracks_json) as f:
            doc = json.load(f)
    except (OSError, json.JSONDecodeError) as e:
        sys.exit(f"{args.tracks_json}: {e}")
    gate_m = args.gate_m
    if gate_m is None:
        gate_m = doc.get("tracker", {}).get("truth_gate_m", 100.0)
    if args.check and gate_m != doc.get("tracker", {}).get("truth_gate_m", gate_m):
        sys.exit(f"--check compares with the tracks' own scores: leave --gate-m out "
                 f"(they were scored within {doc['tracker']['truth_gate_m']} m)")
    scores = score(doc, gate_m)
    if args.json:
        print(json.dumps(scores, indent=2))
    else:
        for k, v in scores.items():
            print(f"{k:20s} {v:.4g}")
    if args.check:
        ours = doc.get("summary", {}).get("scores", {}).get("figures")
        if ours is None:
            sys.exit(f"{args.tracks_json}: no summary.scores to check (made by an older xbandsim?)")
        wrong = disagreements(scores, ours)
        if wrong:
            sys.exit("xbandsim's scores disagree with the libraries':\n  " + "\n  ".join(wrong))
        print("xbandsim's own scores agree with py-motmetrics' and TrackEval's")


if __name__ == "__main__":
    main()
