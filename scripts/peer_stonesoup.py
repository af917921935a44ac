#!/usr/bin/env python3
"""Tracks the plots of `xbandsim track` a second time with a peer tracker built from Stone Soup
1.9.1 (Barr et al., "Stone Soup: announcement of beta release of an open-source framework for
tracking and state estimation", Proc. SPIE 11018, 2019; https://stonesoup.readthedocs.io),
and scores both trackers on the same truth with scripts/score_tracks.py, side by side, with
the time each spent tracking.

Usage: peer_stonesoup.py [--xbandsim PATH] [--gate-m D] [--json] [--check] SCENE.toml
       [TRACK_ARGS...]

It runs `xbandsim track SCENE.toml --out <tmp>/tracks.json TRACK_ARGS...`, reads the time our
tracker took ("tracker X ms" in the summary line it prints: the per-scan step alone, without
rendering and plot extraction), and feeds the very measurements our tracker saw
(`scans[].measurements`, each with its own time, ENU position and covariance; docs/tracking.md)
to Stone Soup, scan by scan. Our options go before SCENE.toml; everything after it goes to
`xbandsim track`.

How the peer is matched to ours (docs/tracking.md, "The tracker"), and where it cannot be:

- Motion: Stone Soup's `ConstantVelocity` on each axis, state `[x, vx, y, vy]`. It is the
  continuous white-noise acceleration model, `Q = q·[[dt³/3, dt²/2], [dt²/2, dt]]`
  (stonesoup/models/transition/linear.py, `ConstantNthDerivative.covar`); ours is the
  discrete white-noise acceleration model, `Q = σa²·[[dt⁴/4, dt³/2], [dt³/2, dt²]]`
  (Bar-Shalom, Li & Kirubarajan, *Estimation with Applications to Tracking and Navigation*,
  Wiley 2001, "BLK", ch. 6, has both). No constant q makes the two equal for every dt; the
  peer takes `q = σa²·T`, T the scan period (the tracks.json's `period_s`), which makes the
  velocity and cross terms equal at dt = T (the step a track takes from scan to scan) and
  the position term 4/3 of ours there (BLK's reading of q: velocity changes over a period
  of the order of √(q·T), ours σa·T). `q = σa²` (the obvious reading of `noise_diff_coeff`)
  would make the velocity noise's variance T (2.5) times too small. Ours is an IMM of that
  model with two coordinated turns; Stone Soup 1.9.1 has no IMM, so the peer runs the
  constant-velocity filter alone: its gate is tighter on a turning target and it lags in a
  turn.
- Measurements: a `LinearGaussian` model per detection, mapping (0, 2), with that
  measurement's own `covariance_m2`; `KalmanPredictor` and `KalmanUpdater`.
- Time: each detection keeps its own time (`time_s`, as a `datetime` from a fixed epoch;
  `timedelta` rounds it to 1 µs, a few µm at ship speeds). Stone Soup's `DistanceHypothesiser`
  predicts a track to each detection's own timestamp before measuring the distance, as ours
  predicts to each plot's time, so the spread of times within a scan is kept. Ours also tries
  a plot just past north at the revolution's end (a target running ahead of the beam); the
  JSON carries only the bearing's time, so the peer has that one.
- Gate: Stone Soup's `Mahalanobis` measure is the square root, `SquaredMahalanobis` is
  `νᵀS⁻¹ν` (stonesoup/measures/state.py), S from `predict_measurement` (`H·P·Hᵀ + R`). The
  peer uses `SquaredMahalanobis` with `missed_distance` = our gate (13.82): the same gate as
  `Mahalanobis` with `missed_distance = √13.82`, and moreover the same global nearest
  neighbour. `GNNWith2DAssignment` minimises the summed distance with `missed_distance` for
  each track left unpaired; ours minimises the summed `νᵀS⁻¹ν` with gate/2 for each track and
  each plot left unpaired. Both come to `Σ d² − gate·(pairs) + const`, the same optimum (on
  the square root the optimum would differ; ours also splits the problem into connected
  groups, which leaves the optimum as it is). Ours gates on the IMM's mixture, the peer on
  the constant-velocity prediction.
- Initiation: `MultiMeasurementInitiator` with `min_points` = M of our M/N (3), its own
  `GNNWith2DAssignment` over the detections no confirmed track took (ours too: confirmed
  tracks first, then tentative ones with the plots left), and a new track per detection left
  over, at the plot with the plot's covariance and velocity `0 ± max_speed_kn·0.514444/2` m/s
  on each axis, as ours. Its tentative tracks are dropped by an `UpdateTimeStepsDeleter`
  after N − M + 1 (2) scans in a row without a plot; ours drops one as soon as M of N is out
  of reach (2 misses in all), so the peer lets a few more through (plot, miss, plot, miss,
  plot); a tentative track's miss is predicted to the scan's middle (the initiator appends
  the missed hypothesis's prediction itself). Ours also needs a track score over its
  confirmation threshold, from a clutter map (a sequential probability ratio test), and
  merges confirmed tracks that stay within 50 m and 2 m/s: Stone Soup has neither, so
  expect more false tracks on clutter.
- Loss: an `UpdateTimeStepsDeleter` with `time_steps_since_update = lost_after_misses` (6):
  it walks back over the track's distinct timestamps and deletes once more than that many
  go by without an `Update` (stonesoup/deleter/time.py), that is on the 6th missed scan in a
  row, as ours. (`CovarianceBasedDeleter` deletes on the covariance's trace, which grows
  with the time coasted, not with the scans missed.)
- Reported position: each track's last state, as ours reports each track at its own time:
  an update at its plot's time, or, on a missed scan, the prediction to when the beam
  crossed it (from the antenna at the scan's start, `start + bearing/360°·period`), which
  is also when the truth objects are placed. Stone Soup's trackers would append the missed
  hypothesis's prediction, made to the one timestamp given to `associate` (here the scan's
  middle); the peer re-predicts a missed track to its beam time instead.
- Timing: `time.perf_counter` around each scan's step: making the scan's `Detection`s (ours
  converts plots to measurements in its step too), association, updates, deletion and
  initiation; not the JSON loading, nor the tracks' positions written out for scoring.

Stone Soup API notes (1.9.1): `Mahalanobis` is not squared; the hypothesiser keeps a pair only
when `distance < missed_distance` (ours `≤`); `Detection`s hash by identity, so sets of them
iterate in no fixed order (the peer sorts where an order shows); `KalmanPredictor.predict`
caches on (prior, timestamp), which does not help here, as every detection has its own time.
"""
import argparse
import datetime
import importlib.util
import json
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
EPOCH = datetime.datetime(2000, 1, 1)
KNOT_MPS = 1852.0 / 3600.0
METRICS = [
    "mota",
    "motp",
    "idf1",
    "num_false_positives",
    "num_misses",
    "num_switches",
    "HOTA",
    "DetA",
    "AssA",
    "LocA",
]


def load_score_tracks():
    """scripts/score_tracks.py as a module (it is a script, not a package)."""
    path = ROOT / "scripts" / "score_tracks.py"
    spec = importlib.util.spec_from_file_location("score_tracks", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def at(seconds):
    """A `datetime` `seconds` after the fixed epoch (Stone Soup times are datetimes)."""
    return EPOCH + datetime.timedelta(seconds=seconds)


def settings_of(doc):
    """The peer's settings from the tracks.json's `tracker` and its scan period."""
    s = doc["tracker"]
    hits, scans = (int(v) for v in str(s.get("initiation", "3/4")).split("/"))
    periods = [scan["period_s"] for scan in doc["scans"] if scan.get("period_s")]
    return {
        "gate": float(s["gate"]),
        "sigma_a_cv_mps2": float(s["sigma_a_cv_mps2"]),
        "lost_after_misses": int(s["lost_after_misses"]),
        "initiation_hits": hits,
        "initiation_scans": scans,
        "max_speed_kn": float(s["max_speed_kn"]),
        "knot_mps": float(s.get("knot_mps", KNOT_MPS)),
        "period_s": float(np.median(periods)) if periods else 2.5,
    }


class StoneSoupPeer:
    """Stone Soup components set up like our tracker (see the module's docstring), and the
    per-scan step that drives them."""

    def __init__(self, settings):
        from stonesoup.dataassociator.neighbour import GNNWith2DAssignment
        from stonesoup.deleter.time import UpdateTimeStepsDeleter
        from stonesoup.hypothesiser.distance import DistanceHypothesiser
        from stonesoup.initiator.simple import (
            MultiMeasurementInitiator,
            SimpleMeasurementInitiator,
        )
        from stonesoup.measures import SquaredMahalanobis
        from stonesoup.models.measurement.linear import LinearGaussian
        from stonesoup.models.transition.linear import (
            CombinedLinearGaussianTransitionModel,
            ConstantVelocity,
        )
        from stonesoup.predictor.kalman import KalmanPredictor
        from stonesoup.types.detection import Detection
        from stonesoup.types.state import GaussianState
        from stonesoup.updater.kalman import KalmanUpdater

        self.settings = settings
        self._Detection = Detection
        self._LinearGaussian = LinearGaussian
        q = settings["sigma_a_cv_mps2"] ** 2 * settings["period_s"]
        self.transition_model = CombinedLinearGaussianTransitionModel(
            [ConstantVelocity(q), ConstantVelocity(q)]
        )
        self.predictor = KalmanPredictor(self.transition_model)
        # No default model: every detection carries its own.
        self.updater = KalmanUpdater(measurement_model=None)
        hypothesiser = DistanceHypothesiser(
            self.predictor,
            self.updater,
            measure=SquaredMahalanobis(),
            missed_distance=settings["gate"],
        )
        self.associator = GNNWith2DAssignment(hypothesiser)
        self.deleter = UpdateTimeStepsDeleter(
            time_steps_since_update=settings["lost_after_misses"]
        )
        sv = settings["max_speed_kn"] * settings["knot_mps"] / 2.0
        # The position entries are replaced by each detection's and its covariance's.
        prior = GaussianState(np.zeros((4, 1)), np.diag([0.0, sv * sv, 0.0, sv * sv]))
        hits, scans = settings["initiation_hits"], settings["initiation_scans"]
        if hits <= 1:
            self.initiator = SimpleMeasurementInitiator(prior)
        else:
            self.initiator = MultiMeasurementInitiator(
                prior_state=prior,
                deleter=UpdateTimeStepsDeleter(time_steps_since_update=scans - hits + 1),
                data_associator=GNNWith2DAssignment(hypothesiser),
                updater=self.updater,
                min_points=hits,
            )
        self.tracks = set()

    def detections(self, scan):
        """The scan's measurements as Stone Soup detections, each with its own time and
        covariance."""
        out = []
        for m in scan["measurements"]:
            model = self._LinearGaussian(
                ndim_state=4, mapping=(0, 2), noise_covar=np.asarray(m["covariance_m2"])
            )
            out.append(
                self._Detection(
                    np.array([[m["position_m"][0]], [m["position_m"][1]]]),
                    timestamp=at(m["time_s"]),
                    measurement_model=model,
                )
            )
        return out

    def beam_time(self, track, scan):
        """When the beam crossed `track`'s position this scan (ours predicts a track to this
        time and coasts it there on a miss), not before the track's own last time."""
        state = track.state_vector
        ax, ay = scan["antenna_position_m"][:2]
        bearing = math.degrees(math.atan2(state[0, 0] - ax, state[2, 0] - ay)) % 360.0
        t = scan["start_time_s"] + bearing / 360.0 * scan["period_s"]
        return max(at(t), track.timestamp)

    def step(self, scan):
        """One scan: association of the confirmed tracks, their updates or coasts, deletion,
        then initiation on the detections left over. Returns the new tracks."""
        detections = set(self.detections(scan))
        middle = at(scan["start_time_s"] + scan["period_s"] / 2.0)
        associations = self.associator.associate(self.tracks, detections, middle)
        taken = set()
        for track, hypothesis in associations.items():
            if hypothesis:
                track.append(self.updater.update(hypothesis))
                taken.add(hypothesis.measurement)
            else:
                track.append(self.predictor.predict(track, timestamp=self.beam_time(track, scan)))
        self.tracks -= self.deleter.delete_tracks(self.tracks)
        new = self.initiator.initiate(detections - taken, middle)
        self.tracks |= new
        return new


def track_with_stonesoup(doc):
    """Tracks `doc`'s measurements (a tracks.json) with the Stone Soup peer. Returns a copy
    of `doc` whose `scans[].tracks` are the peer's tracks (confirmed ones: `id` a stable
    integer, `position_m` and `velocity_mps` its last state, `time_s` that state's time) and
    the seconds spent in the peer's per-scan steps."""
    peer = StoneSoupPeer(settings_of(doc))
    ids = {}
    seconds = 0.0
    scans = []
    for scan in doc["scans"]:
        t0 = time.perf_counter()
        new = peer.step(scan)
        seconds += time.perf_counter() - t0
        # Ids in a fixed order: by the new track's first time, then its position.
        for track in sorted(new, key=lambda t: (t[0].timestamp, *t.state_vector[[0, 2], 0])):
            ids[track.id] = len(ids)
        tracks = []
        for track in peer.tracks:
            x = track.state_vector
            tracks.append(
                {
                    "id": ids[track.id],
                    "status": "confirmed",
                    "time_s": (track.timestamp - EPOCH).total_seconds(),
                    "position_m": [float(x[0, 0]), float(x[2, 0])],
                    "velocity_mps": [float(x[1, 0]), float(x[3, 0])],
                }
            )
        tracks.sort(key=lambda t: t["id"])
        scans.append({**scan, "tracks": tracks, "ended": []})
    out = {k: v for k, v in doc.items() if k not in ("scans", "summary")}
    out["scans"] = scans
    out["tracker"] = {"peer": "Stone Soup", **doc.get("tracker", {})}
    return out, seconds


def default_binary():
    found = shutil.which("xbandsim")
    return found or str(ROOT / "target" / "release" / "xbandsim")


def run_xbandsim(binary, scene, track_args, out):
    """Runs `xbandsim track` and returns (its tracks.json, its tracker's time in ms)."""
    path = Path(binary)
    if not (path.is_file() and os.access(path, os.X_OK)):
        sys.exit(
            f"xbandsim binary not found or not executable: {binary} (build it with "
            "`cargo build --release` or pass --xbandsim PATH)"
        )
    cmd = [str(path), "track", str(scene), "--out", str(out), *track_args]
    try:
        run = subprocess.run(cmd, capture_output=True, text=True)
    except OSError as e:
        sys.exit(f"cannot run {binary}: {e}")
    if run.returncode != 0:
        sys.exit(
            f"{' '.join(cmd)} failed with exit status {run.returncode}:\n{run.stderr.strip()}"
        )
    # The summary line goes to stdout (crates/xbandsim-cli, `say!`); stderr is searched too.
    output = run.stdout + "\n" + run.stderr
    found = re.findall(r"\btracker ([0-9]+(?:\.[0-9]*)?) ms", output)
    if not found:
        sys.exit(
            f"{' '.join(cmd)}: no 'tracker X ms' in its output; is {binary} an xbandsim "
            f"that times its tracker?\n{output.strip()}"
        )
    try:
        with open(out) as f:
            doc = json.load(f)
    except (OSError, json.JSONDecodeError) as e:
        sys.exit(f"{out}: {e}")
    return doc, float(found[-1])


def table(ours, peer, ours_ms, peer_ms):
    rows = [("metric", "xbandsim", "Stone Soup")]
    for k in METRICS:
        rows.append((k, f"{ours[k]:.4g}", f"{peer[k]:.4g}"))
    rows.append(("tracking time, ms", f"{ours_ms:.3f}", f"{peer_ms:.3f}"))
    ratio = f"{peer_ms / ours_ms:.4g}" if ours_ms > 0 else "inf"
    rows.append(("speed ratio (Stone Soup time / xbandsim time)", "", ratio))
    widths = [max(len(r[i]) for r in rows) for i in range(3)]
    lines = [f"{a:<{widths[0]}}  {b:>{widths[1]}}  {c:>{widths[2]}}" for a, b, c in rows]
    lines.insert(1, "-" * len(lines[0]))
    return "\n".join(lines)


def main():
    parser = argparse.ArgumentParser(
        description=__doc__.split("\n\n")[0],
        usage="%(prog)s [--xbandsim PATH] [--gate-m D] [--json] [--check] SCENE.toml "
        "[TRACK_ARGS...]",
    )
    parser.add_argument("--xbandsim", default=None, help="the xbandsim binary")
    parser.add_argument("--gate-m", type=float, default=100.0, help="the scoring gate, m")
    parser.add_argument("--json", action="store_true", help="print the results as JSON")
    parser.add_argument(
        "--check",
        action="store_true",
        help="exit with status 1 unless xbandsim scores at least Stone Soup's MOTA and HOTA "
        "and tracks faster",
    )
    parser.add_argument("scene")
    parser.add_argument("track_args", nargs=argparse.REMAINDER)
    args = parser.parse_args()
    if not (math.isfinite(args.gate_m) and args.gate_m > 0):
        sys.exit(f"invalid --gate-m {args.gate_m}: must be a positive distance")
    if "--out" in args.track_args or any(a.startswith("--out=") for a in args.track_args):
        sys.exit("--out is the script's own: leave it out of the xbandsim track arguments")
    try:
        import stonesoup  # noqa: F401
    except ImportError:
        sys.exit("Stone Soup is not installed: pip install -r scripts/requirements-check.txt")
    binary = args.xbandsim or default_binary()
    with tempfile.TemporaryDirectory() as tmp:
        doc, ours_ms = run_xbandsim(binary, args.scene, args.track_args, Path(tmp) / "tracks.json")
    peer_doc, peer_s = track_with_stonesoup(doc)
    score_tracks = load_score_tracks()
    ours = score_tracks.score(doc, args.gate_m)
    peer = score_tracks.score(peer_doc, args.gate_m)
    peer_ms = peer_s * 1e3
    ratio = peer_ms / ours_ms if ours_ms > 0 else float("inf")
    if args.json:
        print(
            json.dumps(
                {
                    "xbandsim": ours,
                    "stonesoup": peer,
                    "xbandsim_tracker_ms": ours_ms,
                    "stonesoup_tracker_ms": peer_ms,
                    "speed_ratio": ratio,
                },
                indent=2,
            )
        )
    else:
        print(f"{args.scene}: {len(doc['scans'])} scans, scored within {args.gate_m:g} m")
        print(table(ours, peer, ours_ms, peer_ms))
    if args.check:
        worse = [m for m in ("mota", "HOTA") if ours[m] < peer[m]]
        if ratio < 1.0:
            worse.append("tracking time")
        if worse:
            sys.exit(f"xbandsim's tracker is behind Stone Soup's on {', '.join(worse)}")


if __name__ == "__main__":
    main()
