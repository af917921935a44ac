//! Scoring tracks against the truth with the standard multi-object tracking metrics
//! (docs/tracking.md, "Scores"): CLEAR MOT's MOTA and MOTP (Bernardin & Stiefelhagen,
//! *EURASIP J. Image and Video Processing* 2008) and HOTA with its detection, association and
//! localisation parts (Luiten et al., *IJCV* 129, 2021).
//!
//! Each scan is a frame; its ground truth is the objects that leave an echo, its hypotheses
//! the confirmed tracks. A track and an object may pair within a gate `g` (m): CLEAR MOT
//! takes their distance `d` (MOTP in metres), HOTA the similarity `max(0, 1 − d/g)`.
//!
//! The algorithms follow the reference implementations step for step, so that the figures
//! are theirs (up to exact ties between assignments, which two solvers may break apart):
//! py-motmetrics 1.4.0's `MOTAccumulator.update` (each object's last pairing, however old,
//! kept while its track is there and within the gate; the rest by a least-distance
//! assignment of the most pairs; a pair that contradicts an object's last pairing is a
//! switch) and TrackEval 1.3.0's `HOTA.eval_sequence` (one assignment a frame maximising the
//! global alignment score times the similarity, then thresholded at α = 0.05, 0.10, …,
//! 0.95). `scripts/score_tracks.py --check` and a test in the Python suite score the same
//! sequences with both libraries and with this module.
//!
//! [`TrackingScore`] holds a sequence's counts in a form that adds over sequences as
//! TrackEval combines them (HOTA's association and localisation sums weighted by their true
//! positives), so a dataset's score is the sum of its sequences'.

use crate::assign::assign;
use serde::{Deserialize, Serialize};

/// HOTA's localisation thresholds α: 0.05, 0.10, …, 0.95 (TrackEval's).
pub const HOTA_ALPHAS: usize = 19;

/// The `a`-th HOTA threshold, as `numpy.arange(0.05, 0.99, 0.05)` makes it (start plus
/// `a` steps).
pub fn hota_alpha(a: usize) -> f64 {
    0.05 + a as f64 * 0.05
}

/// A sequence's (or several sequences') tracking counts, which add up over sequences.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrackingScore {
    /// Sequences counted.
    pub sequences: u64,
    /// Frames (scans) counted.
    pub frames: u64,
    /// Ground-truth objects summed over frames (CLEAR MOT's `num_objects`).
    pub objects: u64,
    /// Objects paired with a track, switches included (`num_detections`).
    pub matches: u64,
    /// Pairings that contradict the object's previous one (`num_switches`).
    pub switches: u64,
    /// Objects with no track (`num_misses`).
    pub misses: u64,
    /// Confirmed tracks with no object (`num_false_positives`).
    pub false_positives: u64,
    /// Sum of the paired distances, m (MOTP's numerator).
    pub distance_sum_m: f64,
    /// HOTA's true positives per threshold α.
    pub hota_tp: Vec<f64>,
    /// HOTA's false negatives per α.
    pub hota_fn: Vec<f64>,
    /// HOTA's false positives per α.
    pub hota_fp: Vec<f64>,
    /// Per α, the association accuracy times the true positives (the sum over true positives
    /// of their pair's association score).
    pub association_sum: Vec<f64>,
    /// Per α, the sum of the true positives' similarities.
    pub localisation_sum: Vec<f64>,
}

impl Default for TrackingScore {
    fn default() -> TrackingScore {
        TrackingScore {
            sequences: 0,
            frames: 0,
            objects: 0,
            matches: 0,
            switches: 0,
            misses: 0,
            false_positives: 0,
            distance_sum_m: 0.0,
            hota_tp: vec![0.0; HOTA_ALPHAS],
            hota_fn: vec![0.0; HOTA_ALPHAS],
            hota_fp: vec![0.0; HOTA_ALPHAS],
            association_sum: vec![0.0; HOTA_ALPHAS],
            localisation_sum: vec![0.0; HOTA_ALPHAS],
        }
    }
}

/// The summary figures of a [`TrackingScore`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TrackingFigures {
    /// MOTA = 1 − (misses + switches + false positives) / objects; `None` with no objects.
    pub mota: Option<f64>,
    /// MOTP: the mean distance of a paired track from its object, m; `None` with no pairs.
    pub motp_m: Option<f64>,
    /// HOTA, averaged over α.
    pub hota: f64,
    /// Detection accuracy, averaged over α.
    pub det_a: f64,
    /// Association accuracy, averaged over α.
    pub ass_a: f64,
    /// Localisation accuracy (mean similarity of the true positives), averaged over α.
    pub loc_a: f64,
}

impl TrackingScore {
    /// Adds another sequence's (or set's) counts.
    pub fn merge(&mut self, other: &TrackingScore) {
        self.sequences += other.sequences;
        self.frames += other.frames;
        self.objects += other.objects;
        self.matches += other.matches;
        self.switches += other.switches;
        self.misses += other.misses;
        self.false_positives += other.false_positives;
        self.distance_sum_m += other.distance_sum_m;
        for (mine, theirs) in [
            (&mut self.hota_tp, &other.hota_tp),
            (&mut self.hota_fn, &other.hota_fn),
            (&mut self.hota_fp, &other.hota_fp),
            (&mut self.association_sum, &other.association_sum),
            (&mut self.localisation_sum, &other.localisation_sum),
        ] {
            for (m, t) in mine.iter_mut().zip(theirs) {
                *m += t;
            }
        }
    }

    /// MOTA, MOTP and HOTA with its parts (TrackEval's combination over sequences: DetA from
    /// the summed counts, AssA and LocA weighted by true positives).
    pub fn figures(&self) -> TrackingFigures {
        let (mut hota, mut det_a, mut ass_a, mut loc_a) = (0.0, 0.0, 0.0, 0.0);
        for a in 0..HOTA_ALPHAS {
            let tp = self.hota_tp[a];
            let det = tp / (tp + self.hota_fn[a] + self.hota_fp[a]).max(1.0);
            let ass = self.association_sum[a] / tp.max(1e-10);
            let loc = if tp > 0.0 {
                self.localisation_sum[a] / tp
            } else {
                1.0
            };
            hota += (det * ass).sqrt();
            det_a += det;
            ass_a += ass;
            loc_a += loc;
        }
        let n = HOTA_ALPHAS as f64;
        TrackingFigures {
            mota: (self.objects > 0).then(|| {
                1.0 - (self.misses + self.switches + self.false_positives) as f64
                    / self.objects as f64
            }),
            motp_m: (self.matches > 0).then(|| self.distance_sum_m / self.matches as f64),
            hota: hota / n,
            det_a: det_a / n,
            ass_a: ass_a / n,
            loc_a: loc_a / n,
        }
    }
}

/// One frame as HOTA keeps it: dense indices of its objects and tracks, and their
/// similarities (row-major, objects × tracks).
struct HotaFrame {
    objects: Vec<usize>,
    tracks: Vec<usize>,
    similarity: Vec<f64>,
}

/// Scores one sequence frame by frame ([`SequenceScorer::add_frame`]), then
/// [`SequenceScorer::finish`] gives its [`TrackingScore`].
pub struct SequenceScorer {
    gate_m: f64,
    score: TrackingScore,
    /// CLEAR MOT: each object's last paired track.
    paired: std::collections::HashMap<u32, u32>,
    /// HOTA: dense indices of object and track ids, in order of first appearance.
    object_index: std::collections::HashMap<u32, usize>,
    track_index: std::collections::HashMap<u32, usize>,
    frames: Vec<HotaFrame>,
}

/// The cost of leaving a row or a column unpaired in an assignment of at most `pairs` pairs
/// whose pair costs span at most `span`: more than half of what `pairs` pairs can cost
/// beyond the cheapest, so that one more pair always pays. The assignment then takes as many
/// pairs as it can, then the least total cost, as motmetrics' solver does with its
/// expensive non-edges (`2·r·c + 1`) and scipy's rectangular assignment does by taking
/// `min(rows, cols)` pairs; scaled to the costs, so that the solver's potentials keep their
/// precision.
fn unpaired_cost(pairs: usize, span: f64) -> f64 {
    span * (pairs + 1) as f64
}

/// The distance of two points, m.
fn distance_m(a: [f64; 2], b: [f64; 2]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt()
}

impl SequenceScorer {
    /// A scorer pairing within `gate_m` metres (positive and finite, else `None`).
    pub fn new(gate_m: f64) -> Option<SequenceScorer> {
        (gate_m.is_finite() && gate_m > 0.0).then(|| SequenceScorer {
            gate_m,
            score: TrackingScore {
                sequences: 1,
                ..TrackingScore::default()
            },
            paired: Default::default(),
            object_index: Default::default(),
            track_index: Default::default(),
            frames: Vec::new(),
        })
    }

    /// Adds a frame: its objects `(id, position)` and confirmed tracks `(id, position)`, ENU
    /// metres. Returns, per object, the track CLEAR MOT paired it with in this frame.
    pub fn add_frame(
        &mut self,
        objects: &[(u32, [f64; 2])],
        tracks: &[(u32, [f64; 2])],
    ) -> Vec<Option<u32>> {
        let (no, nt) = (objects.len(), tracks.len());
        debug_assert!(
            objects
                .iter()
                .chain(tracks)
                .all(|(_, p)| p.iter().all(|x| x.is_finite())),
            "positions must be finite"
        );
        debug_assert!(
            (1..no).all(|i| objects[..i].iter().all(|o| o.0 != objects[i].0))
                && (1..nt).all(|j| tracks[..j].iter().all(|t| t.0 != tracks[j].0)),
            "ids must be unique within a frame"
        );
        let distances: Vec<f64> = objects
            .iter()
            .flat_map(|o| tracks.iter().map(move |t| distance_m(o.1, t.1)))
            .collect();
        let distance: &[f64] = &distances;
        let gate_m = self.gate_m;
        let within = move |i: usize, j: usize| distance[i * nt + j] <= gate_m;
        let s = &mut self.score;
        s.frames += 1;
        s.objects += no as u64;
        let mut track_of: Vec<Option<usize>> = vec![None; no];
        let mut track_used = vec![false; nt];
        // 1. Pairs of earlier frames that still hold.
        for (i, o) in objects.iter().enumerate() {
            let Some(&previous) = self.paired.get(&o.0) else {
                continue;
            };
            let Some(j) = (0..nt).find(|&j| !track_used[j] && tracks[j].0 == previous) else {
                continue;
            };
            if within(i, j) {
                track_of[i] = Some(j);
                track_used[j] = true;
                s.matches += 1;
                s.distance_sum_m += distance[i * nt + j];
            }
        }
        // 2. The rest: the most pairs within the gate, then the least total distance.
        let rows: Vec<usize> = (0..no).filter(|&i| track_of[i].is_none()).collect();
        let cols: Vec<usize> = (0..nt).filter(|&j| !track_used[j]).collect();
        let cost: Vec<Option<f64>> = rows
            .iter()
            .flat_map(|&i| {
                cols.iter()
                    .map(move |&j| within(i, j).then(|| distance[i * nt + j]))
            })
            .collect();
        let miss = unpaired_cost(rows.len().min(cols.len()), gate_m);
        for (r, c) in assign(&cost, rows.len(), cols.len(), miss) {
            let (i, j) = (rows[r], cols[c]);
            let (object, track) = (objects[i].0, tracks[j].0);
            if self.paired.get(&object).is_some_and(|&p| p != track) {
                s.switches += 1;
            }
            self.paired.insert(object, track);
            track_of[i] = Some(j);
            track_used[j] = true;
            s.matches += 1;
            s.distance_sum_m += distance[i * nt + j];
        }
        s.misses += track_of.iter().filter(|t| t.is_none()).count() as u64;
        s.false_positives += track_used.iter().filter(|u| !**u).count() as u64;
        // HOTA's frame, for the second pass.
        let index_of = |map: &mut std::collections::HashMap<u32, usize>, id: u32| {
            let next = map.len();
            *map.entry(id).or_insert(next)
        };
        let frame = HotaFrame {
            objects: objects
                .iter()
                .map(|o| index_of(&mut self.object_index, o.0))
                .collect(),
            tracks: tracks
                .iter()
                .map(|t| index_of(&mut self.track_index, t.0))
                .collect(),
            similarity: distance
                .iter()
                .map(|d| (1.0 - d / gate_m).clamp(0.0, 1.0))
                .collect(),
        };
        self.frames.push(frame);
        track_of
            .into_iter()
            .map(|j| j.map(|j| tracks[j].0))
            .collect()
    }

    /// The sequence's counts, with HOTA's (TrackEval's two passes over the frames).
    pub fn finish(self) -> TrackingScore {
        let mut s = self.score;
        let (ng, nt) = (self.object_index.len(), self.track_index.len());
        // First pass: how often each object and track is present, and their potential
        // matches (each frame's similarity over its IoU-like denominator).
        let mut potential = vec![0.0; ng * nt];
        let mut object_count = vec![0.0; ng];
        let mut track_count = vec![0.0; nt];
        for f in &self.frames {
            let (rows, cols) = (f.objects.len(), f.tracks.len());
            let row_sum: Vec<f64> = (0..rows)
                .map(|i| f.similarity[i * cols..(i + 1) * cols].iter().sum())
                .collect();
            let col_sum: Vec<f64> = (0..cols)
                .map(|j| (0..rows).map(|i| f.similarity[i * cols + j]).sum())
                .collect();
            for (i, &g) in f.objects.iter().enumerate() {
                for (j, &t) in f.tracks.iter().enumerate() {
                    let sim = f.similarity[i * cols + j];
                    let denominator = row_sum[i] + col_sum[j] - sim;
                    if denominator > f64::EPSILON {
                        potential[g * nt + t] += sim / denominator;
                    }
                }
            }
            for &g in &f.objects {
                object_count[g] += 1.0;
            }
            for &t in &f.tracks {
                track_count[t] += 1.0;
            }
        }
        let alignment: Vec<f64> = (0..ng * nt)
            .map(|k| {
                let (g, t) = (k / nt, k % nt);
                let p = potential[k];
                let denominator = object_count[g] + track_count[t] - p;
                if denominator > 0.0 {
                    p / denominator
                } else {
                    0.0
                }
            })
            .collect();
        // Second pass: per frame one assignment of the most alignment-weighted similarity,
        // thresholded at each α.
        let mut matches_count = vec![vec![0.0; ng * nt]; HOTA_ALPHAS];
        for f in &self.frames {
            let (rows, cols) = (f.objects.len(), f.tracks.len());
            if rows == 0 || cols == 0 {
                for a in 0..HOTA_ALPHAS {
                    s.hota_fp[a] += cols as f64;
                    s.hota_fn[a] += rows as f64;
                }
                continue;
            }
            let cost: Vec<Option<f64>> = (0..rows * cols)
                .map(|k| {
                    let (g, t) = (f.objects[k / cols], f.tracks[k % cols]);
                    Some(-alignment[g * nt + t] * f.similarity[k])
                })
                .collect();
            // Every pair is allowed, at a cost in [−1, 0]: the most pairs, min(rows, cols),
            // then the highest score, as scipy's rectangular assignment gives.
            let pairs = assign(&cost, rows, cols, unpaired_cost(rows.min(cols), 1.0));
            for a in 0..HOTA_ALPHAS {
                let threshold = hota_alpha(a) - f64::EPSILON;
                let mut matched = 0usize;
                for &(i, j) in &pairs {
                    let sim = f.similarity[i * cols + j];
                    if sim >= threshold {
                        matched += 1;
                        s.localisation_sum[a] += sim;
                        matches_count[a][f.objects[i] * nt + f.tracks[j]] += 1.0;
                    }
                }
                s.hota_tp[a] += matched as f64;
                s.hota_fn[a] += (rows - matched) as f64;
                s.hota_fp[a] += (cols - matched) as f64;
            }
        }
        for (a, counts) in matches_count.iter().enumerate() {
            s.association_sum[a] = counts
                .iter()
                .enumerate()
                .map(|(k, &m)| {
                    let (g, t) = (k / nt, k % nt);
                    m * m / (object_count[g] + track_count[t] - m).max(1.0)
                })
                .sum();
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two objects tracked perfectly for ten frames: MOTA 1, HOTA 1 (similarity 1 at d = 0).
    #[test]
    fn perfect_tracks_score_one() {
        let mut s = SequenceScorer::new(100.0).unwrap();
        for k in 0..10 {
            let x = k as f64 * 10.0;
            let objects = [(1, [x, 0.0]), (2, [0.0, x + 500.0])];
            let paired = s.add_frame(&objects, &[(7, [x, 0.0]), (9, [0.0, x + 500.0])]);
            assert_eq!(paired, vec![Some(7), Some(9)]);
        }
        let f = s.finish().figures();
        assert_eq!(f.mota, Some(1.0));
        assert_eq!(f.motp_m, Some(0.0));
        assert!((f.hota - 1.0).abs() < 1e-12, "{f:?}");
    }

    /// Hand-counted CLEAR MOT events: a miss, a false positive, a switch, and a pair kept
    /// through a closer rival (the previous frame's pair holds while within the gate).
    #[test]
    fn clear_mot_counts_by_hand() {
        let mut s = SequenceScorer::new(100.0).unwrap();
        // Frame 0: object 1 with track 10 at 20 m; object 2 missed; track 11 far: FP.
        s.add_frame(
            &[(1, [0.0, 0.0]), (2, [1000.0, 0.0])],
            &[(10, [20.0, 0.0]), (11, [0.0, 5000.0])],
        );
        // Frame 1: track 12 is closer to object 1, but 10 is still within the gate: kept.
        let paired = s.add_frame(&[(1, [0.0, 0.0])], &[(10, [90.0, 0.0]), (12, [1.0, 0.0])]);
        assert_eq!(paired, vec![Some(10)]);
        // Frame 2: track 10 is gone; 12 takes object 1: a switch.
        s.add_frame(&[(1, [0.0, 0.0])], &[(12, [1.0, 0.0])]);
        let score = s.finish();
        assert_eq!(score.objects, 4);
        assert_eq!(score.matches, 3);
        assert_eq!(score.switches, 1);
        assert_eq!(score.misses, 1);
        assert_eq!(score.false_positives, 2);
        assert!((score.distance_sum_m - 111.0).abs() < 1e-12);
        let f = score.figures();
        assert!((f.mota.unwrap() - (1.0 - 4.0 / 4.0)).abs() < 1e-12);
        assert!((f.motp_m.unwrap() - 37.0).abs() < 1e-12);
    }

    /// HOTA of one object and one track at a constant distance d: every frame pairs, the
    /// similarity is s = 1 − d/g, so DetA(α) = AssA(α) = 1 where s ≥ α and 0 elsewhere, and
    /// HOTA is the fraction of thresholds at or below s (Luiten et al. 2021, eq. 1–9).
    #[test]
    fn hota_of_a_constant_offset_is_the_fraction_of_thresholds_passed() {
        for d in [0.0, 12.0, 33.0, 61.0, 99.0] {
            let mut s = SequenceScorer::new(100.0).unwrap();
            for _ in 0..5 {
                s.add_frame(&[(3, [0.0, 0.0])], &[(4, [d, 0.0])]);
            }
            let f = s.finish().figures();
            let sim: f64 = 1.0 - d / 100.0;
            let alphas = [
                0.05, 0.1, 0.15, 0.2, 0.25, 0.3, 0.35, 0.4, 0.45, 0.5, 0.55, 0.6, 0.65, 0.7, 0.75,
                0.8, 0.85, 0.9, 0.95,
            ];
            let passed = alphas.iter().filter(|&&a| sim >= a - 1e-9).count();
            assert!(
                (f.hota - passed as f64 / HOTA_ALPHAS as f64).abs() < 1e-12,
                "d {d}: {f:?}"
            );
        }
    }

    /// One object followed by two tracks in turn, half the frames each: AssA is the
    /// association IoU 5/10 = 0.5 for every true positive, DetA 1, so HOTA = √0.5.
    #[test]
    fn hota_of_a_track_handed_over_halfway() {
        let mut s = SequenceScorer::new(100.0).unwrap();
        for k in 0..10 {
            let track = if k < 5 { 1 } else { 2 };
            s.add_frame(&[(8, [0.0, 0.0])], &[(track, [0.0, 0.0])]);
        }
        let score = s.finish();
        let f = score.figures();
        assert!((f.det_a - 1.0).abs() < 1e-12);
        assert!((f.ass_a - 0.5).abs() < 1e-12, "{f:?}");
        assert!((f.hota - 0.5f64.sqrt()).abs() < 1e-12);
        assert_eq!(score.switches, 1);
    }

    /// Merged sequences weight AssA by their true positives (TrackEval's combination): ten
    /// frames with AssA 0.5 (a track handed over halfway) and six with AssA 1 give
    /// (0.5·10 + 1·6)/16.
    #[test]
    fn merged_association_is_weighted_by_true_positives() {
        let mut handed = SequenceScorer::new(100.0).unwrap();
        for k in 0..10 {
            handed.add_frame(
                &[(8, [0.0, 0.0])],
                &[(if k < 5 { 1 } else { 2 }, [0.0, 0.0])],
            );
        }
        let mut held = SequenceScorer::new(100.0).unwrap();
        for _ in 0..6 {
            held.add_frame(&[(8, [0.0, 0.0])], &[(1, [0.0, 0.0])]);
        }
        let mut total = handed.finish();
        total.merge(&held.finish());
        let f = total.figures();
        assert!((f.ass_a - (0.5 * 10.0 + 6.0) / 16.0).abs() < 1e-12, "{f:?}");
        assert!((f.det_a - 1.0).abs() < 1e-12);
    }

    /// The CLEAR MOT assignment takes the most pairs before the least distance, whatever the
    /// gate: two objects and two tracks where the nearest pair would leave the others
    /// unpaired.
    #[test]
    fn the_most_pairs_come_before_the_least_distance() {
        for gate in [100.0, 1e7] {
            let mut s = SequenceScorer::new(gate).unwrap();
            // Track 1 is 10 m from object A and 90 m from B; track 2 is 95 m from A only.
            let paired = s.add_frame(
                &[(0, [0.0, 0.0]), (1, [0.0, 100.0])],
                &[(1, [0.0, 10.0]), (2, [0.0, -95.0])],
            );
            if gate == 100.0 {
                assert_eq!(paired, vec![Some(2), Some(1)]);
            } else {
                // With a gate this wide every pair is allowed: still two pairs.
                assert_eq!(paired.iter().flatten().count(), 2);
            }
        }
    }

    /// Merging two sequences adds their counts: the merged DetA is from the summed counts.
    #[test]
    fn merged_sequences_add_up() {
        let run = |n: usize, with_track: bool| {
            let mut s = SequenceScorer::new(50.0).unwrap();
            for _ in 0..n {
                let tracks: &[(u32, [f64; 2])] = if with_track { &[(1, [0.0, 0.0])] } else { &[] };
                s.add_frame(&[(1, [0.0, 0.0])], tracks);
            }
            s.finish()
        };
        let mut total = run(6, true);
        total.merge(&run(2, false));
        assert_eq!(total.sequences, 2);
        assert_eq!(total.objects, 8);
        let f = total.figures();
        assert!((f.det_a - 6.0 / 8.0).abs() < 1e-12);
        assert!((f.ass_a - 1.0).abs() < 1e-12);
        assert!((f.mota.unwrap() - 0.75).abs() < 1e-12);
    }
}
