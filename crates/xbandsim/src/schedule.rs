//! The schedule the engine runs: a revolution as dwells (one per spoke of the record), each
//! dwell as the pulses integrated into it, each pulse at its own time and antenna azimuth.
//! "A pulse at time t at antenna azimuth a" is the unit of work; the spoke-mode scan — one
//! pulse per spoke, the antenna at the spoke's azimuth, one scene state per revolution with
//! every object where the beam crosses it ([`crate::model::Revolution`]) — is one schedule
//! ([`Schedule::frozen_scan`]) among others.

use crate::error::{Error, Problem, Result};
use crate::model::Radar;
use crate::rng::MAX_PULSES_PER_FRAME;

/// One transmitted pulse.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pulse {
    /// Pulse number within the revolution: it keys the pulse's random streams (noise,
    /// speckle), so it must be unique within a schedule.
    pub number: u64,
    /// Transmit time from the start of the run, s.
    pub time_s: f64,
    /// Antenna azimuth, rad (nautical: 0 = north, clockwise).
    pub azimuth_rad: f64,
}

/// The pulses integrated into one spoke of the record. Their matched-filter powers are
/// averaged (non-coherent integration); a one-pulse dwell is today's spoke.
#[derive(Debug, Clone, PartialEq)]
pub struct Dwell {
    /// The spoke (row of the polar record) this dwell fills; it also places the clutter
    /// cells the beam sees.
    pub spoke: usize,
    /// Its pulses (at least one).
    pub pulses: Vec<Pulse>,
}

/// One revolution's dwells, and the scene time every pulse sees.
#[derive(Debug, Clone, PartialEq)]
pub struct Schedule {
    spokes: usize,
    frame: u64,
    scene_time_s: f64,
    dwells: Vec<Dwell>,
}

impl Schedule {
    /// Today's scan: revolution `frame`, one pulse per spoke, pulse k at
    /// `t = (frame + k/spokes)·60/rpm` with the antenna at spoke k's azimuth `2πk/spokes`,
    /// and the scene state of the revolution that starts at `frame·60/rpm` (every object
    /// where the beam crosses it; a still scene is the same at every time).
    pub fn frozen_scan(radar: &Radar, frame: u64) -> Schedule {
        let scan = radar.scan();
        let spokes = scan.spokes();
        let period_s = scan.period_s();
        let dwells = (0..spokes)
            .map(|k| Dwell {
                spoke: k,
                pulses: vec![Pulse {
                    number: k as u64,
                    time_s: (frame as f64 + k as f64 / spokes as f64) * period_s,
                    azimuth_rad: scan.spoke_azimuth_rad(k),
                }],
            })
            .collect();
        Schedule {
            spokes,
            frame,
            scene_time_s: frame as f64 * period_s,
            dwells,
        }
    }

    /// The pulse-by-pulse scan of revolution `frame`: pulse n fired at
    /// `t = frame·T + n/prf` (n < `floor(prf·T)`, T = 60/rpm) with the antenna at
    /// `2π·n/(prf·T)`, integrated into the spoke nearest that azimuth; the pulses of each
    /// dwell in time order. Pulses within half a spoke before north belong to spoke 0 and
    /// are fired one period earlier, at the end of the previous revolution. The scene state is the revolution's (every object traced where
    /// the beam crosses it; the engine advances moving echoes to each pulse's time).
    pub fn pulse_scan(radar: &Radar, frame: u64) -> Schedule {
        let scan = radar.scan();
        if scan.stagger().is_staggered() {
            return Schedule::staggered_scan(radar, frame);
        }
        let spokes = scan.spokes();
        let start_s = frame as f64 * scan.period_s();
        let mut dwells: Vec<Dwell> = (0..spokes)
            .map(|k| Dwell {
                spoke: k,
                pulses: Vec::new(),
            })
            .collect();
        let total = scan.pulses_per_revolution();
        for n in 0..total {
            dwells[scan.spoke_of_pulse(n)].pulses.push(Pulse {
                number: n as u64,
                time_s: start_s + scan.pulse_time_s(n),
                azimuth_rad: scan.pulse_azimuth_rad(n),
            });
        }
        // Spoke 0's dwell straddles north: the pulses of the revolution's last half spoke
        // are fired, in a continuous scan, just before north, at the end of the previous
        // revolution. They keep their numbers (which key their streams) and are timed one
        // period earlier, so spoke 0's pulses are evenly spaced and in time order.
        let period_s = scan.period_s();
        let (mut late, early): (Vec<Pulse>, Vec<Pulse>) = dwells[0]
            .pulses
            .iter()
            .partition(|p| p.azimuth_rad > std::f64::consts::PI);
        for p in &mut late {
            p.time_s -= period_s;
        }
        dwells[0].pulses = late.into_iter().chain(early).collect();
        Schedule {
            spokes,
            frame,
            scene_time_s: start_s,
            dwells,
        }
    }

    /// The pulse-by-pulse scan of revolution `frame` for a staggered PRF: the one pulse train
    /// runs on through every revolution ([`crate::model::Scan::train_time_s`]), so no interval
    /// at a revolution's seam is shorter than the stagger's; revolution k takes the pulses
    /// fired from half a spoke before north at `k·T` to half a spoke before north at
    /// `(k + 1)·T`, numbered from 0 in fire order, each integrated into the spoke nearest the
    /// antenna's azimuth `2π·(t − k·T)/T`.
    fn staggered_scan(radar: &Radar, frame: u64) -> Schedule {
        let scan = radar.scan();
        let spokes = scan.spokes();
        let period_s = scan.period_s();
        let start_s = frame as f64 * period_s;
        let lead_s = 0.5 * period_s / spokes as f64;
        let mut dwells: Vec<Dwell> = (0..spokes)
            .map(|k| Dwell {
                spoke: k,
                pulses: Vec::new(),
            })
            .collect();
        let first = scan.first_train_pulse_at(start_s - lead_s);
        let end_s = start_s + period_s - lead_s;
        let mut g = first;
        loop {
            let t = scan.train_time_s(g);
            if t >= end_s {
                break;
            }
            let azimuth = (std::f64::consts::TAU * (t - start_s) / period_s)
                .rem_euclid(std::f64::consts::TAU);
            let spoke =
                ((azimuth / std::f64::consts::TAU * spokes as f64).round() as usize) % spokes;
            dwells[spoke].pulses.push(Pulse {
                number: (g - first) as u64,
                time_s: t,
                azimuth_rad: azimuth,
            });
            g += 1;
        }
        Schedule {
            spokes,
            frame,
            scene_time_s: start_s,
            dwells,
        }
    }

    /// The schedule the scene's `[processing] mode` asks for: [`Schedule::frozen_scan`]
    /// (spoke) or [`Schedule::pulse_scan`] (pulse).
    pub fn for_mode(radar: &Radar, mode: crate::model::ProcessingMode, frame: u64) -> Schedule {
        match mode {
            crate::model::ProcessingMode::Spoke => Schedule::frozen_scan(radar, frame),
            crate::model::ProcessingMode::Pulse => Schedule::pulse_scan(radar, frame),
        }
    }

    /// A schedule of one's own for `radar`: every spoke filled by exactly one dwell (in any
    /// order), every dwell with at least one pulse, pulse numbers unique, times and azimuths
    /// finite. The pulses see the scene state of the revolution starting at `scene_time_s`.
    pub fn new(
        radar: &Radar,
        frame: u64,
        scene_time_s: f64,
        dwells: Vec<Dwell>,
    ) -> Result<Schedule> {
        let spokes = radar.spokes();
        if !scene_time_s.is_finite() {
            return Err(Error::invalid(
                Problem::NotFinite,
                "schedule.scene_time_s",
                scene_time_s,
                "must be a finite number",
            ));
        }
        if dwells.len() != spokes {
            return Err(Error::invalid(
                Problem::Conflict,
                "schedule.dwells",
                dwells.len(),
                format!("a revolution needs one dwell per spoke (radar.spokes = {spokes})"),
            ));
        }
        let mut filled = vec![false; spokes];
        let mut numbers = std::collections::HashSet::new();
        for (i, d) in dwells.iter().enumerate() {
            let field = format!("schedule.dwells[{i}]");
            if d.spoke >= spokes || std::mem::replace(&mut filled[d.spoke], true) {
                return Err(Error::invalid(
                    Problem::Conflict,
                    format!("{field}.spoke"),
                    d.spoke,
                    format!("each spoke 0..{spokes} must be filled by exactly one dwell"),
                ));
            }
            if d.pulses.is_empty() {
                return Err(Error::invalid(
                    Problem::Missing,
                    format!("{field}.pulses"),
                    "[]",
                    "a dwell needs at least one pulse",
                ));
            }
            for p in &d.pulses {
                if !p.time_s.is_finite() || !p.azimuth_rad.is_finite() {
                    return Err(Error::invalid(
                        Problem::NotFinite,
                        format!("{field}.pulses"),
                        format!("{p:?}"),
                        "pulse times and azimuths must be finite",
                    ));
                }
                if p.number >= MAX_PULSES_PER_FRAME {
                    return Err(Error::invalid(
                        Problem::OutOfRange,
                        format!("{field}.pulses"),
                        p.number,
                        format!("pulse numbers must be below 2^40 = {MAX_PULSES_PER_FRAME} (they key the random streams)"),
                    ));
                }
                if !numbers.insert(p.number) {
                    return Err(Error::invalid(
                        Problem::Conflict,
                        format!("{field}.pulses"),
                        p.number,
                        "pulse numbers key the random streams and must be unique",
                    ));
                }
            }
        }
        Ok(Schedule {
            spokes,
            frame,
            scene_time_s,
            dwells,
        })
    }

    /// Spokes of the record it fills (the radar's it was made for).
    pub fn spokes(&self) -> usize {
        self.spokes
    }

    /// Revolution number (keys the random streams and the clutter texture's drift).
    pub fn frame(&self) -> u64 {
        self.frame
    }

    /// Start of the revolution whose scene state every pulse of this schedule sees, s.
    pub fn scene_time_s(&self) -> f64 {
        self.scene_time_s
    }

    /// The dwells.
    pub fn dwells(&self) -> &[Dwell] {
        &self.dwells
    }

    /// Number of pulses.
    pub fn num_pulses(&self) -> usize {
        self.dwells.iter().map(|d| d.pulses.len()).sum()
    }
}
