"""The classical baseline every dataset carries (docs/tracking.md, "Dataset baseline"),
scored by the well-kept libraries: each sequence of the tracking spec has its truth and
confirmed tracks in baseline.json, and py-motmetrics 1.4.0 (CLEAR MOT: Bernardin &
Stiefelhagen 2008) and TrackEval 1.3.0 (HOTA: Luiten et al. 2021) must give the MOTA, MOTP
and HOTA that xbandsim computed for it to 1e-9; the targets table's baseline fields must
say the same as baseline.json, and the dataset card must carry the scores."""

import importlib.util
import json

import numpy as np
import pytest

import xbandsim
from conftest import ROOT

pytest.importorskip("motmetrics", reason="pip install -r scripts/requirements-check.txt")
pytest.importorskip("trackeval", reason="pip install -r scripts/requirements-check.txt")

spec = importlib.util.spec_from_file_location("score_tracks", ROOT / "scripts" / "score_tracks.py")
score_tracks = importlib.util.module_from_spec(spec)
spec.loader.exec_module(score_tracks)


@pytest.fixture(scope="module")
def tracking_dataset(tmp_path_factory):
    out = tmp_path_factory.mktemp("tracking")
    xbandsim.dataset.generate(ROOT / "datasets" / "tracking.toml", out, count=6, seed=11)
    return out


def baselines(out):
    with open(out / "baseline.jsonl") as f:
        return [json.loads(line) for line in f if line.strip()]


def scans_of(baseline):
    """The sequence as score_tracks scores it: per frame (truth ids, positions, tracks)."""
    out = []
    for f in baseline["frames"]:
        out.append((
            [o["id"] for o in f["truth"]],
            np.array([o["position_m"] for o in f["truth"]], dtype=float).reshape(-1, 2),
            [t["id"] for t in f["tracks"]],
            np.array([t["position_m"] for t in f["tracks"]], dtype=float).reshape(-1, 2),
        ))
    return out


def test_each_sequence_scores_as_the_libraries_score_it(tracking_dataset):
    samples = baselines(tracking_dataset)
    assert [b["sample"] for b in samples] == list(range(6))
    tracks = 0
    for b in samples:
        gate = b["settings"]["truth_gate_m"]
        scans = scans_of(b)
        tracks += sum(len(s[2]) for s in scans)
        scores = {**score_tracks.clear_mot(scans, gate), **score_tracks.hota(scans, gate)}
        wrong = score_tracks.disagreements(scores, b["tracking"]["figures"])
        assert not wrong, (b["sample"], wrong)
        counts = b["tracking"]["counts"]
        assert counts["misses"] == scores["num_misses"]
        assert counts["false_positives"] == scores["num_false_positives"]
        assert counts["switches"] == scores["num_switches"]
    # The comparison means something only with tracks to score.
    assert tracks > 10


def test_targets_table_agrees_with_baseline_json(tracking_dataset):
    samples = {b["sample"]: b for b in baselines(tracking_dataset)}
    rows = [json.loads(line) for line in open(tracking_dataset / "targets.jsonl") if line.strip()]
    assert rows
    for row in rows:
        frame = samples[row["sample"]]["frames"][row["frame"]]
        in_truth = {o["id"] for o in frame["truth"]}
        # Detection is asked only of objects that leave an echo: those in the frame's truth.
        assert (row["baseline_detected"] is not None) == (row["track_id"] in in_truth)
        paired = {t["object_id"]: t["id"] for t in frame["tracks"] if t["object_id"] is not None}
        assert row["baseline_track_id"] == paired.get(row["track_id"])
    for b in samples.values():
        for f in b["frames"]:
            detected = sum(
                1 for r in rows
                if r["sample"] == b["sample"] and r["frame"] == f["frame"] and r["baseline_detected"]
            )
            assert detected == f["objects_detected"]


def test_card_carries_the_libraries_combined_scores(tracking_dataset):
    """The card's tracking row is what the libraries give over all sequences: motmetrics'
    overall MOTA and MOTP, and TrackEval's HOTA.combine_sequences."""
    import motmetrics as mm
    import trackeval

    samples = baselines(tracking_dataset)
    gate = samples[0]["settings"]["truth_gate_m"]
    accumulators = [score_tracks.accumulator(scans_of(b), gate) for b in samples]
    names = [str(b["sample"]) for b in samples]
    overall = mm.metrics.create().compute_many(
        accumulators, names=names, metrics=score_tracks.CLEAR_MOT, generate_overall=True
    ).loc["OVERALL"]
    combined = trackeval.metrics.HOTA().combine_sequences(
        {n: score_tracks.hota_result(scans_of(b), gate) for n, b in zip(names, samples)}
    )
    row = "| {:.3f} | {:.3f} | {:.3f} | {:.3f} | {:.3f} | {:.3f} | {} | {} | {} |".format(
        overall["mota"], overall["motp"],
        *(float(np.mean(combined[k])) for k in score_tracks.HOTA_FIELDS),
        int(overall["num_misses"]), int(overall["num_false_positives"]),
        int(overall["num_switches"]),
    )
    card = (tracking_dataset / "README.md").read_text()
    assert "## Baseline: CFAR plots and ARPA tracks" in card
    assert row in card, (row, card[card.index("## Baseline"):])
