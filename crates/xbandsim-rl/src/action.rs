//! The operator's action: what a marine-radar operator (or an adaptive radar) sets before
//! each revolution — where the antenna looks, the pulse, the gain, the sea and rain clutter
//! controls and the pulses integrated per spoke. Encoded for Gymnasium as a `MultiDiscrete`
//! vector of [`ACTION_NVEC`] choices (docs/rl.md, "Action").

use xbandsim::{Error, Problem, Result};

/// Choices per component of the action vector: scan, pulse, gain, sea clutter, rain clutter,
/// integration.
pub const ACTION_NVEC: [u32; 6] = [5, 4, 4, 4, 3, 3];

/// Names of the action vector's components, in order (for messages and docs).
pub const ACTION_NAMES: [&str; 6] = ["scan", "pulse", "gain", "sea", "rain", "integration"];

/// Where the antenna looks during the step.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scan {
    /// A full revolution: every spoke once.
    Full,
    /// The step's time spent sweeping one 90° quadrant (0 = north-east, 1 = south-east,
    /// 2 = south-west, 3 = north-west, true bearings from north): its spokes get
    /// [`QUADRANTS`] times the pulses; the rest of the picture keeps what it showed.
    Quadrant(usize),
}

/// Number of quadrants a dwell can choose.
pub const QUADRANTS: usize = 4;

/// Transmitted pulse, as a marine radar's range-scale pulse choice.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PulseChoice {
    /// 0.1 µs: little energy, 15 m blind zone.
    Short,
    /// 0.5 µs.
    Medium,
    /// 2 µs LFM: 13 dB more energy than short, 300 m blind zone (eclipsing).
    Long,
    /// The long pulse with the short one filling its blind zone (`radar.pulse_mode =
    /// "combined"`).
    Combined,
}

impl PulseChoice {
    /// All choices, in action order.
    pub const ALL: [PulseChoice; 4] = [
        PulseChoice::Short,
        PulseChoice::Medium,
        PulseChoice::Long,
        PulseChoice::Combined,
    ];

    /// Name, as in docs/rl.md.
    pub fn name(self) -> &'static str {
        match self {
            PulseChoice::Short => "short",
            PulseChoice::Medium => "medium",
            PulseChoice::Long => "long",
            PulseChoice::Combined => "combined",
        }
    }

    /// The scene-file settings (`--set` form) that make this pulse.
    pub fn settings(self) -> Vec<String> {
        let (width_us, combined) = match self {
            PulseChoice::Short => (0.1, false),
            PulseChoice::Medium => (0.5, false),
            PulseChoice::Long => (2.0, false),
            PulseChoice::Combined => (2.0, true),
        };
        let mut s = vec![format!("radar.pulse_width_us={width_us}")];
        if combined {
            s.push("radar.pulse_mode=\"combined\"".into());
            s.push("radar.short_pulse_width_us=0.1".into());
        }
        s
    }
}

/// The display threshold the gain control sets, dB over the mean noise: the bottom of the
/// picture's gray scale, and 6 dB under the plot extractor's threshold
/// ([`crate::display::DETECTION_MARGIN_DB`]). Gain level 0 is the lowest gain.
pub const GAIN_FLOOR_DB: [f32; 4] = [12.0, 9.0, 6.0, 3.0];

/// Sea clutter control (STC) laws: the sensitivity is lowered by `10·k·log10(R_stc/R)` dB
/// inside [`crate::display::STC_RANGE_M`] ahead of the log amplifier, k per level (0 = off;
/// `xbandsim::receiver::video_chain::manual_stc_db`).
pub const STC_LAW: [f32; 4] = [0.0, 1.0, 2.0, 3.0];

/// Rain clutter control (FTC): the differentiator's time constant per level, µs (level 0:
/// off; `xbandsim::receiver::stages::Ftc`).
pub const FTC_TIME_CONSTANT_US: [Option<f64>; 3] = [None, Some(1.0), Some(0.3)];

/// Pulses integrated per spoke (non-coherently), per integration level.
pub const PULSES_PER_SPOKE: [usize; 3] = [1, 2, 4];

/// One step's settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Action {
    /// Where the antenna looks.
    pub scan: Scan,
    /// The pulse.
    pub pulse: PulseChoice,
    /// Gain level, 0..4 ([`GAIN_FLOOR_DB`]).
    pub gain: usize,
    /// Sea clutter control level, 0..4 ([`STC_LAW`]).
    pub sea: usize,
    /// Rain clutter control level, 0..3 ([`FTC_TIME_CONSTANT_US`]).
    pub rain: usize,
    /// Integration level, 0..3 ([`PULSES_PER_SPOKE`]).
    pub integration: usize,
}

impl Action {
    /// Decodes a `MultiDiscrete` action vector; a component out of range is an error naming
    /// it (`action.gain`, ...).
    pub fn from_vector(v: &[i64]) -> Result<Action> {
        if v.len() != ACTION_NVEC.len() {
            return Err(Error::invalid(
                Problem::Conflict,
                "action",
                format!("{v:?}"),
                format!(
                    "an action has {} components ({})",
                    ACTION_NVEC.len(),
                    ACTION_NAMES.join(", ")
                ),
            ));
        }
        for (i, (&x, &n)) in v.iter().zip(&ACTION_NVEC).enumerate() {
            if x < 0 || x >= i64::from(n) {
                return Err(Error::invalid(
                    Problem::OutOfRange,
                    format!("action.{}", ACTION_NAMES[i]),
                    x,
                    format!("must be 0 … {}", n - 1),
                ));
            }
        }
        let u = |i: usize| v[i] as usize;
        Ok(Action {
            scan: if u(0) == 0 {
                Scan::Full
            } else {
                Scan::Quadrant(u(0) - 1)
            },
            pulse: PulseChoice::ALL[u(1)],
            gain: u(2),
            sea: u(3),
            rain: u(4),
            integration: u(5),
        })
    }

    /// The action vector of this action.
    pub fn to_vector(&self) -> [i64; 6] {
        let scan = match self.scan {
            Scan::Full => 0,
            Scan::Quadrant(q) => q as i64 + 1,
        };
        let pulse = PulseChoice::ALL
            .iter()
            .position(|&p| p == self.pulse)
            .unwrap_or(0) as i64;
        [
            scan,
            pulse,
            self.gain as i64,
            self.sea as i64,
            self.rain as i64,
            self.integration as i64,
        ]
    }

    /// Display floor of this action's gain, dB over noise.
    pub fn floor_db(&self) -> f32 {
        GAIN_FLOOR_DB[self.gain]
    }
}

impl Default for Action {
    /// A full scan with the combined pulse, gain level 1, sea clutter control level 2 (20·log
    /// STC), no rain clutter control and one pulse per spoke.
    fn default() -> Action {
        Action {
            scan: Scan::Full,
            pulse: PulseChoice::Combined,
            gain: 1,
            sea: 2,
            rain: 0,
            integration: 0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_vector_round_trips_and_bad_ones_name_the_component() {
        let mut count = 0;
        for s in 0..5 {
            for p in 0..4 {
                for g in 0..4 {
                    for sea in 0..4 {
                        for r in 0..3 {
                            for i in 0..3 {
                                let v = [s, p, g, sea, r, i];
                                let a = Action::from_vector(&v).unwrap();
                                assert_eq!(a.to_vector(), v);
                                count += 1;
                            }
                        }
                    }
                }
            }
        }
        assert_eq!(
            count,
            ACTION_NVEC.iter().map(|&n| n as usize).product::<usize>()
        );
        let e = Action::from_vector(&[0, 0, 4, 0, 0, 0]).unwrap_err();
        assert!(e.to_string().contains("action.gain"), "{e}");
        // Inclusive bounds, as everywhere else: the last choice is the one named.
        assert!(e.to_string().ends_with("= 4: must be 0 … 3"), "{e}");
        let e = Action::from_vector(&[5, 0, 0, 0, 0, 0]).unwrap_err();
        assert!(
            e.to_string().ends_with("`action.scan` = 5: must be 0 … 4"),
            "{e}"
        );
        let e = Action::from_vector(&[0, -1, 0, 0, 0, 0]).unwrap_err();
        assert!(e.to_string().contains("action.pulse"), "{e}");
        assert!(Action::from_vector(&[0, 0, 0]).is_err());
    }
}
