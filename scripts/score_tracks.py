#!/usr/bin/env python3
"""Scores the tracks of `xbandsim track` (tracks.json, docs/tracking.md) with the standard
multi-object tracking metrics of two well-kept libraries: CLEAR MOT (MOTA, MOTP) and IDF1
from py-motmetrics (Bernardin & Stiefelhagen 2008; Ristani et al. 2016), and HOTA with its
detection and association parts from TrackEval (Luiten et al., IJCV 129, 2021).

Each scan is a frame. Its ground truth: the objects that leave an echo (`has_echo`), at the
truth's positions; its hypotheses: the confirmed tracks, at their estimates. A track and an
object may match within `--gate-m` (default 100 m, the truth gate of `xbandsim track`):
motmetrics takes the Euclidean distance (MOTP in metres), TrackEval the similarity
`1 − d/gate`.

Usage: score_tracks.py TRACKS_JSON [--gate-m D] [--json]
"""
import argparse
import json
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


def clear_mot(scans, gate_m):
    import motmetrics as mm

    acc = mm.MOTAccumulator(auto_id=True)
    for gt_ids, gt_pos, tr_ids, tr_pos in scans:
        d = distances(gt_pos, tr_pos)
        d[d > gate_m] = np.nan
        acc.update(gt_ids, tr_ids, d)
    names = ["mota", "motp", "idf1", "num_switches", "num_false_positives", "num_misses",
             "num_objects", "num_matches"]
    row = mm.metrics.create().compute(acc, metrics=names, name="tracks")
    return {n: float(row[n].iloc[0]) for n in names}


def hota(scans, gate_m):
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
    result = trackeval.metrics.HOTA().eval_sequence(data)
    # Averaged over TrackEval's localisation thresholds α = 0.05 … 0.95.
    return {k: float(np.mean(result[k])) for k in ("HOTA", "DetA", "AssA", "LocA")}


def score(doc, gate_m):
    scans = frames(doc)
    return {**clear_mot(scans, gate_m), **hota(scans, gate_m)}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("tracks_json")
    parser.add_argument("--gate-m", type=float, default=100.0)
    parser.add_argument("--json", action="store_true", help="print the scores as JSON")
    args = parser.parse_args()
    if not args.gate_m > 0:
        sys.exit(f"invalid --gate-m {args.gate_m}: must be a positive distance")
    try:
        with open(args.tracks_json) as f:
            doc = json.load(f)
    except (OSError, json.JSONDecodeError) as e:
        sys.exit(f"{args.tracks_json}: {e}")
    scores = score(doc, args.gate_m)
    if args.json:
        print(json.dumps(scores, indent=2))
    else:
        for k, v in scores.items():
            print(f"{k:20s} {v:.4g}")


if __name__ == "__main__":
    main()
