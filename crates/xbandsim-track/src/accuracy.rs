//! Tracked-target accuracy against the IMO performance standard for radar equipment,
//! resolution MSC.192(79) §5.25.4.7.1 (docs/tracking.md, "Accuracy"): after one minute of
//! steady-state tracking a tracker must give the relative motion's trend, after three minutes
//! the target's predicted motion, each within the following 95 %-probability figures, for a
//! target that holds course and speed:
//!
//! | after | relative course | relative speed | CPA | TCPA | true course | true speed |
//! |---|---|---|---|---|---|---|
//! | 1 min | 11° | 1.5 kn or 10 % | 1.0 NM | | | |
//! | 3 min | 3° | 0.8 kn or 1 % | 0.3 NM | 0.5 min | 5° | 0.5 kn or 1 % |
//!
//! ("or x %": whichever is greater, of the true value.) [`AccuracyTally`] gathers the errors of
//! tracks matched to truth objects and says, per figure, what share of them lies within the
//! limit and whether that share is at least 95 %.

use crate::tracker::closest_approach;
use serde::Serialize;
use xbandsim::model::motion::KNOT_M_PER_S;

/// One nautical mile, m.
pub const NAUTICAL_MILE_M: f64 = 1852.0;

/// Below this relative speed a course is not defined, m/s (0.1 kn).
const STILL_MPS: f64 = 0.1 * KNOT_M_PER_S;

/// A limit of the standard's table: a fixed part and, where it says "or x %", a part in
/// proportion to the true value, whichever is greater.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Limit {
    /// The fixed part, in the figure's unit.
    pub fixed: f64,
    /// The share of the true value, 0 where the table gives none.
    pub of_true_value: f64,
}

impl Limit {
    const fn fixed(fixed: f64) -> Limit {
        Limit {
            fixed,
            of_true_value: 0.0,
        }
    }

    /// The limit for a true value `truth`.
    pub fn at(&self, truth: f64) -> f64 {
        self.fixed.max(self.of_true_value * truth.abs())
    }
}

/// The table's row after `minutes` of tracking: limits of relative course (deg), relative
/// speed (kn), CPA (m), TCPA (s), true course (deg), true speed (kn); `None` where the row
/// gives none.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ImoRow {
    /// Minutes of steady-state tracking.
    pub minutes: f64,
    /// Relative course, degrees.
    pub relative_course_deg: Limit,
    /// Relative speed, kn.
    pub relative_speed_kn: Limit,
    /// CPA, m.
    pub cpa_m: Limit,
    /// TCPA, s.
    pub tcpa_s: Option<Limit>,
    /// True course, degrees.
    pub true_course_deg: Option<Limit>,
    /// True speed, kn.
    pub true_speed_kn: Option<Limit>,
}

/// MSC.192(79) §5.25.4.7.1's table, after 1 and after 3 minutes.
pub const IMO_ACCURACY: [ImoRow; 2] = [
    ImoRow {
        minutes: 1.0,
        relative_course_deg: Limit::fixed(11.0),
        relative_speed_kn: Limit {
            fixed: 1.5,
            of_true_value: 0.10,
        },
        cpa_m: Limit::fixed(1.0 * NAUTICAL_MILE_M),
        tcpa_s: None,
        true_course_deg: None,
        true_speed_kn: None,
    },
    ImoRow {
        minutes: 3.0,
        relative_course_deg: Limit::fixed(3.0),
        relative_speed_kn: Limit {
            fixed: 0.8,
            of_true_value: 0.01,
        },
        cpa_m: Limit::fixed(0.3 * NAUTICAL_MILE_M),
        tcpa_s: Some(Limit::fixed(30.0)),
        true_course_deg: Some(Limit::fixed(5.0)),
        true_speed_kn: Some(Limit {
            fixed: 0.5,
            of_true_value: 0.01,
        }),
    },
];

/// A track and its truth at one scan: positions relative to the own ship (m) and velocities
/// over ground (m/s), ENU.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AccuracySample {
    /// Minutes the track has been confirmed (the target held course and speed throughout).
    pub minutes_tracked: f64,
    /// The track's position relative to the own ship.
    pub track_relative_position_m: [f64; 2],
    /// The track's velocity.
    pub track_velocity_mps: [f64; 2],
    /// The truth's position relative to the own ship.
    pub true_relative_position_m: [f64; 2],
    /// The truth's velocity.
    pub true_velocity_mps: [f64; 2],
    /// The own ship's velocity.
    pub own_velocity_mps: [f64; 2],
}

/// The angle from `b` to `a`, degrees in (−180, 180].
pub fn angle_difference_deg(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(360.0);
    if d > 180.0 {
        d - 360.0
    } else {
        d
    }
}

fn course_deg(v: [f64; 2]) -> f64 {
    v[0].atan2(v[1]).to_degrees().rem_euclid(360.0)
}

/// One figure's result: how many samples had it, the 95th percentile of its absolute error,
/// the share within the limit, and whether that share is at least 95 %.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FigureResult {
    /// Samples with the figure defined.
    pub samples: usize,
    /// The 95th percentile of the absolute error (nearest rank), in the figure's unit; null
    /// without samples.
    pub error_p95: Option<f64>,
    /// The share of samples within the limit; null without samples.
    pub within_limit: Option<f64>,
    /// Whether at least 95 % are within it; null without samples.
    pub meets_standard: Option<bool>,
}

#[derive(Debug, Default, Clone)]
struct Figure {
    errors: Vec<f64>,
    within: usize,
}

impl Figure {
    fn add(&mut self, error: f64, limit: f64) {
        self.errors.push(error.abs());
        self.within += usize::from(error.abs() <= limit);
    }

    fn result(&self) -> FigureResult {
        let n = self.errors.len();
        if n == 0 {
            return FigureResult {
                samples: 0,
                error_p95: None,
                within_limit: None,
                meets_standard: None,
            };
        }
        let mut sorted = self.errors.clone();
        sorted.sort_by(f64::total_cmp);
        let rank = ((0.95 * n as f64).ceil() as usize).clamp(1, n);
        let share = self.within as f64 / n as f64;
        FigureResult {
            samples: n,
            error_p95: Some(sorted[rank - 1]),
            within_limit: Some(share),
            meets_standard: Some(share >= 0.95),
        }
    }
}

/// One row's results.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RowResult {
    /// The row of the standard.
    pub standard: ImoRow,
    /// Relative course, degrees.
    pub relative_course_deg: FigureResult,
    /// Relative speed, kn.
    pub relative_speed_kn: FigureResult,
    /// CPA, m.
    pub cpa_m: FigureResult,
    /// TCPA, s (null where the row has no limit).
    pub tcpa_s: Option<FigureResult>,
    /// True course, degrees.
    pub true_course_deg: Option<FigureResult>,
    /// True speed, kn.
    pub true_speed_kn: Option<FigureResult>,
}

/// The errors of tracked targets gathered per row of [`IMO_ACCURACY`]: a sample counts for a
/// row when its track has been confirmed at least the row's minutes.
#[derive(Debug, Clone, Default)]
pub struct AccuracyTally {
    rows: [[Figure; 6]; 2],
}

impl AccuracyTally {
    /// An empty tally.
    pub fn new() -> AccuracyTally {
        AccuracyTally::default()
    }

    /// Adds one sample to every row it has been tracked long enough for. Courses count where
    /// the true relative (or true) speed is at least 0.1 kn; TCPA where the true relative
    /// speed is.
    pub fn add(&mut self, s: &AccuracySample) {
        let rel = |v: [f64; 2]| [v[0] - s.own_velocity_mps[0], v[1] - s.own_velocity_mps[1]];
        let (track_rel, true_rel) = (rel(s.track_velocity_mps), rel(s.true_velocity_mps));
        let speed = |v: [f64; 2]| v[0].hypot(v[1]);
        let (track_cpa, track_tcpa) = closest_approach(s.track_relative_position_m, track_rel);
        let (true_cpa, true_tcpa) = closest_approach(s.true_relative_position_m, true_rel);
        // TCPA only where the true relative speed defines it.
        let true_tcpa = true_tcpa.filter(|_| speed(true_rel) >= STILL_MPS);
        for (row, figures) in IMO_ACCURACY.iter().zip(self.rows.iter_mut()) {
            if s.minutes_tracked < row.minutes {
                continue;
            }
            let true_rel_kn = speed(true_rel) / KNOT_M_PER_S;
            if speed(true_rel) >= STILL_MPS {
                figures[0].add(
                    angle_difference_deg(course_deg(track_rel), course_deg(true_rel)),
                    row.relative_course_deg.at(0.0),
                );
            }
            figures[1].add(
                speed(track_rel) / KNOT_M_PER_S - true_rel_kn,
                row.relative_speed_kn.at(true_rel_kn),
            );
            figures[2].add(track_cpa - true_cpa, row.cpa_m.at(true_cpa));
            if let (Some(limit), Some(t_track), Some(t_true)) = (row.tcpa_s, track_tcpa, true_tcpa)
            {
                figures[3].add(t_track - t_true, limit.at(t_true));
            }
            if let Some(limit) = row.true_course_deg {
                if speed(s.true_velocity_mps) >= STILL_MPS {
                    figures[4].add(
                        angle_difference_deg(
                            course_deg(s.track_velocity_mps),
                            course_deg(s.true_velocity_mps),
                        ),
                        limit.at(0.0),
                    );
                }
            }
            if let Some(limit) = row.true_speed_kn {
                let true_kn = speed(s.true_velocity_mps) / KNOT_M_PER_S;
                figures[5].add(
                    speed(s.track_velocity_mps) / KNOT_M_PER_S - true_kn,
                    limit.at(true_kn),
                );
            }
        }
    }

    /// The results, one per row of [`IMO_ACCURACY`].
    pub fn results(&self) -> Vec<RowResult> {
        IMO_ACCURACY
            .iter()
            .zip(&self.rows)
            .map(|(row, f)| RowResult {
                standard: *row,
                relative_course_deg: f[0].result(),
                relative_speed_kn: f[1].result(),
                cpa_m: f[2].result(),
                tcpa_s: row.tcpa_s.map(|_| f[3].result()),
                true_course_deg: row.true_course_deg.map(|_| f[4].result()),
                true_speed_kn: row.true_speed_kn.map(|_| f[5].result()),
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(minutes: f64, course_error_deg: f64, speed_error_kn: f64) -> AccuracySample {
        // A target 5 NM north steaming west at 12 kn; own ship north at 10 kn.
        let v = 12.0 * KNOT_M_PER_S;
        let own = [0.0, 10.0 * KNOT_M_PER_S];
        let rel_true = [-v - own[0], -own[1]];
        let (s, c) = course_error_deg.to_radians().sin_cos();
        let scale = (rel_true[0].hypot(rel_true[1]) + speed_error_kn * KNOT_M_PER_S)
            / rel_true[0].hypot(rel_true[1]);
        // The relative velocity turned by the error and scaled, back to over ground.
        let rel_track = [
            scale * (rel_true[0] * c + rel_true[1] * s),
            scale * (-rel_true[0] * s + rel_true[1] * c),
        ];
        AccuracySample {
            minutes_tracked: minutes,
            track_relative_position_m: [0.0, 5.0 * NAUTICAL_MILE_M],
            track_velocity_mps: [rel_track[0] + own[0], rel_track[1] + own[1]],
            true_relative_position_m: [0.0, 5.0 * NAUTICAL_MILE_M],
            true_velocity_mps: [-v, 0.0],
            own_velocity_mps: own,
        }
    }

    /// The table's limits, the percentile and the 95 % rule on samples of known errors: 19
    /// of 20 within 3° of relative course meet the 3-minute row, 18 of 20 do not; a sample
    /// tracked under a minute counts in no row; TCPA and the true motion only after three.
    #[test]
    fn the_tally_applies_the_imo_table() {
        let mut tally = AccuracyTally::new();
        for k in 0..20 {
            let error = if k < 19 { 2.0 } else { 4.0 };
            tally.add(&sample(3.5, error, 0.1));
        }
        tally.add(&sample(0.5, 50.0, 10.0));
        let r = tally.results();
        assert_eq!(r.len(), 2);
        let three = &r[1];
        assert_eq!(three.relative_course_deg.samples, 20);
        assert_eq!(three.relative_course_deg.within_limit, Some(0.95));
        assert_eq!(three.relative_course_deg.meets_standard, Some(true));
        let p95 = three.relative_course_deg.error_p95.unwrap();
        assert!((p95 - 2.0).abs() < 1e-9, "{p95}");
        // The relative speed error is 0.1 kn: within 0.8 kn.
        assert_eq!(three.relative_speed_kn.meets_standard, Some(true));
        assert!((three.relative_speed_kn.error_p95.unwrap() - 0.1).abs() < 1e-9);
        assert!(three.tcpa_s.unwrap().samples == 20);
        assert!(three.true_course_deg.unwrap().samples == 20);
        // The 1-minute row holds the same 20 (tracked 3.5 min) and not the half-minute one.
        assert_eq!(r[0].relative_course_deg.samples, 20);
        assert!(r[0].tcpa_s.is_none());
        let mut worse = AccuracyTally::new();
        for k in 0..20 {
            worse.add(&sample(3.5, if k < 18 { 2.0 } else { 4.0 }, 0.1));
        }
        let r = worse.results();
        assert_eq!(r[1].relative_course_deg.meets_standard, Some(false));
        assert_eq!(r[0].relative_course_deg.meets_standard, Some(true));
        // "1.5 kn or 10 %": the relative speed here is 15.6 kn, so 1.56 kn is the limit.
        let rel_kn = (12.0_f64.powi(2) + 10.0_f64.powi(2)).sqrt();
        assert!((IMO_ACCURACY[0].relative_speed_kn.at(rel_kn) - 0.1 * rel_kn).abs() < 1e-12);
        assert_eq!(IMO_ACCURACY[0].relative_speed_kn.at(5.0), 1.5);
        let mut edge = AccuracyTally::new();
        edge.add(&sample(1.0, 0.0, 1.55));
        edge.add(&sample(1.0, 0.0, 1.57));
        assert_eq!(edge.results()[0].relative_speed_kn.within_limit, Some(0.5));
    }
}
