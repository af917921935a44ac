//! Model: signal processing — how the pulses of a revolution are fired and turned into the
//! record: one pulse per spoke (the fast path) or every pulse at the PRF, integrated over the
//! pulses of each spoke, and the Doppler processing of the range-Doppler cube, validated from
//! the scene file's `[processing]` table (docs/formats.md; docs/physics.md §10).

use super::radar::Radar;
use crate::error::{Error, Problem, Result};
use crate::scene::{ProcessingSpec, WindowName};
use crate::waveform::Window;

pub use crate::choice::ProcessingMode;

pub use crate::choice::Integration;

/// Validated processing settings.
#[derive(Debug, Clone, PartialEq)]
pub struct Processing {
    mode: ProcessingMode,
    integration: Integration,
    doppler_pulses: usize,
    doppler_window: Window,
}

impl Default for Processing {
    fn default() -> Self {
        Processing {
            mode: ProcessingMode::Spoke,
            integration: Integration::Noncoherent,
            doppler_pulses: 1,
            doppler_window: Window::Hamming,
        }
    }
}

impl Processing {
    /// The firing mode.
    pub fn mode(&self) -> ProcessingMode {
        self.mode
    }

    /// The integration of a spoke's pulses.
    pub fn integration(&self) -> Integration {
        self.integration
    }

    /// Pulses in a Doppler CPI (the first this many pulses of each spoke); 1 in spoke mode.
    pub fn doppler_pulses(&self) -> usize {
        self.doppler_pulses
    }

    /// Window across the CPI's pulses.
    pub fn doppler_window(&self) -> Window {
        self.doppler_window
    }
}

/// The fewest pulses any spoke gets in pulse mode (pulse n goes to the spoke nearest its
/// azimuth, [`super::Scan::spoke_of_pulse`]).
pub fn fewest_pulses_per_spoke(radar: &Radar) -> usize {
    let scan = radar.scan();
    if scan.stagger().is_staggered() {
        return scan.fewest_train_pulses_per_spoke();
    }
    let mut counts = vec![0usize; scan.spokes()];
    for n in 0..scan.pulses_per_revolution() {
        counts[scan.spoke_of_pulse(n)] += 1;
    }
    counts.into_iter().min().unwrap_or(0)
}

pub(super) fn build_processing(s: &ProcessingSpec, radar: &Radar) -> Result<Processing> {
    let mode = s.mode.unwrap_or_default();
    let integration = s.integration.unwrap_or_default();
    let doppler_window = match s.doppler_window.unwrap_or(WindowName::Hamming) {
        WindowName::None => Window::None,
        WindowName::Hamming => Window::Hamming,
        WindowName::Taylor => Window::TAYLOR_DEFAULT,
    };
    match mode {
        ProcessingMode::Spoke => {
            for (field, set) in [
                ("processing.doppler_pulses", s.doppler_pulses.is_some()),
                ("processing.doppler_window", s.doppler_window.is_some()),
            ] {
                if set {
                    return Err(Error::invalid(
                        Problem::Conflict,
                        field,
                        "(set)",
                        "Doppler processing needs processing.mode = \"pulse\" (spoke mode fires one pulse per spoke)",
                    ));
                }
            }
            Ok(Processing {
                mode,
                integration,
                ..Processing::default()
            })
        }
        ProcessingMode::Pulse => {
            let scan = radar.scan();
            let pulses = scan.pulses_per_revolution();
            if pulses < scan.spokes() {
                return Err(Error::invalid(
                    Problem::Conflict,
                    "processing.mode",
                    "\"pulse\"",
                    format!(
                        "radar.prf_hz × 60/radar.rotation_rpm gives {pulses} pulses per revolution, fewer than radar.spokes = {}: every spoke needs a pulse (raise the PRF or lower the spokes)",
                        scan.spokes()
                    ),
                ));
            }
            let fewest = fewest_pulses_per_spoke(radar);
            let doppler_pulses = s.doppler_pulses.unwrap_or(fewest);
            if doppler_pulses < 2 || doppler_pulses > fewest {
                return Err(Error::invalid(
                    Problem::OutOfRange,
                    "processing.doppler_pulses",
                    doppler_pulses,
                    format!(
                        "a CPI takes the first pulses of a spoke: from 2 to the fewest pulses a spoke gets, {fewest} here (PRF × 60/rpm / spokes)"
                    ),
                ));
            }
            Ok(Processing {
                mode,
                integration,
                doppler_pulses,
                doppler_window,
            })
        }
    }
}
