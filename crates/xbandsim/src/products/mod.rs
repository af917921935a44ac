//! Stage: products. What a render hands to its users: the [`Frame`] (the polar record and the
//! ground truth), the labels that make the truth ([`labels`]), the PPI image and its pixel
//! boxes ([`ppi`]), the encoders ([`output`]) and the frame's files written as a set
//! ([`frame_files`]: polar.npy, ppi.png, ppi_gray.png, truth.json; docs/formats.md) and plots
//! scored against the truth ([`plot_truth`]). Later products (range-Doppler cubes, video)
//! belong here too.

pub mod artefacts;
pub mod frame_files;
pub mod labels;
pub mod land;
pub mod output;
pub mod plot_truth;
pub mod ppi;
pub mod spokes;

use crate::model::revolution::ShipState;
pub use crate::receiver::video_chain::Video;
use labels::ObjectTruth;
use num_complex::Complex32;

/// Timings and counts of one frame.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct FrameStats {
    /// Rays cast by the scattering model.
    pub rays_cast: u64,
    /// Scattering contributions.
    pub contributions: usize,
    /// Echo groups after binning.
    pub echo_groups: usize,
    /// Seconds spent tracing and grouping the echoes (0 when the trace cache held the state).
    pub trace_s: f64,
    /// Seconds spent on clutter, echoes, noise and matched filtering.
    pub synthesis_s: f64,
}

/// The range-Doppler-azimuth cube of a pulse-mode revolution: for each spoke, the Doppler
/// spectrum of its first `doppler_pulses` pulses in every range bin (docs/formats.md,
/// "doppler_cube.npy").
#[derive(Debug, Clone, PartialEq)]
pub struct DopplerCube {
    /// Spokes (first axis).
    pub spokes: usize,
    /// Doppler bins (second axis): bin d at `(d − floor(doppler_bins/2))·doppler_bin_hz`.
    pub doppler_bins: usize,
    /// Range bins (third axis), as the polar record's.
    pub range_bins: usize,
    /// Doppler bin spacing `PRF/M`, Hz.
    pub doppler_bin_hz: f64,
    /// `|Y|²/Σw²` over the mean noise power, dB, spokes × Doppler × range, row-major.
    pub values_db: Vec<f32>,
}

impl DopplerCube {
    /// Doppler frequency of bin `d`, Hz.
    pub fn doppler_hz(&self, d: usize) -> f64 {
        (d as f64 - (self.doppler_bins / 2) as f64) * self.doppler_bin_hz
    }

    /// The Doppler spectrum (dB) of spoke `k` at range bin `j`.
    pub fn spectrum(&self, k: usize, j: usize) -> Vec<f32> {
        (0..self.doppler_bins)
            .map(|d| self.values_db[(k * self.doppler_bins + d) * self.range_bins + j])
            .collect()
    }
}

/// The raw received I/Q of every pulse of a revolution (`render --iq`; docs/formats.md,
/// "iq.npy"): what the receiver records before the matched filter.
#[derive(Debug, Clone, PartialEq)]
pub struct PulseIq {
    /// Rows: the pulses, spoke by spoke, each dwell's in fire order.
    pub pulses: usize,
    /// Columns: samples per pulse; sample n is `n/fs` after the pulse starts.
    pub samples: usize,
    /// Complex sample rate fs, Hz.
    pub sample_rate_hz: f64,
    /// pulses × samples, row-major, in units of the noise rms voltage `√(k·T0·F·fs)`.
    pub values: Vec<Complex32>,
    /// Each row's transmit time from the start of the run, s.
    pub times_s: Vec<f64>,
    /// Each row's antenna azimuth, rad (nautical).
    pub azimuths_rad: Vec<f64>,
    /// Each row's spoke.
    pub spokes: Vec<usize>,
}

/// The mean radial velocity of every cell of a pulse-mode revolution, estimated from its
/// dwell's pulses by the pulse-pair method (docs/physics.md §10; docs/formats.md,
/// "radial_velocity.npy"), with the cell's mean pulse power.
#[derive(Debug, Clone, PartialEq)]
pub struct RadialVelocity {
    /// Spokes (rows).
    pub spokes: usize,
    /// Range bins (columns), as the polar record's.
    pub range_bins: usize,
    /// Mean radial velocity `−λ·arg(R1)/(4π·PRI)`, m/s, positive opening, spokes × bins
    /// row-major; aliased into ±`unambiguous_mps`; 0 where `estimated` is false.
    pub velocity_mps: Vec<f32>,
    /// Whether the cell has an estimate (its lag-one sum R1 is not zero: false only where
    /// nothing at all was received, with the noise off).
    pub estimated: Vec<bool>,
    /// The dwell's mean pulse power `R0 = mean |y_m|²` over the mean noise power of the
    /// cell's own channel, dB (floor −120 dB): the noncoherent record's value, less
    /// `short_pulse_noise_db` in the short pulse's bins of combined pulse mode.
    pub power_db: Vec<f32>,
    /// The largest speed told apart from its aliases, `λ·PRF/4`, m/s.
    pub unambiguous_mps: f64,
}

impl RadialVelocity {
    /// Whether cell `i` (spoke·range_bins + bin) holds an echo at least `threshold_db` over the
    /// noise closing at [`labels::RADIAL_CLASS_THRESHOLD_MPS`] or faster: what a target
    /// analyser colours as approaching.
    pub fn approaching(&self, i: usize, threshold_db: f64) -> bool {
        self.estimated[i]
            && self.power_db[i] as f64 >= threshold_db
            && self.velocity_mps[i] as f64 <= -labels::RADIAL_CLASS_THRESHOLD_MPS
    }

    /// Whether cell `i` holds an echo at least `threshold_db` over the noise opening at
    /// [`labels::RADIAL_CLASS_THRESHOLD_MPS`] or faster: what a target analyser colours as
    /// receding.
    pub fn receding(&self, i: usize, threshold_db: f64) -> bool {
        self.estimated[i]
            && self.power_db[i] as f64 >= threshold_db
            && self.velocity_mps[i] as f64 >= labels::RADIAL_CLASS_THRESHOLD_MPS
    }
}

/// One rendered revolution.
#[derive(Debug, Clone)]
pub struct Frame {
    /// Revolution number (0 for the first).
    pub frame: u64,
    /// Time the revolution starts (the antenna through north), s from the start of the run.
    pub start_time_s: f64,
    /// The own ship at the start of the revolution (None without `[own_ship]`).
    pub own_ship: Option<ShipState>,
    /// Spokes (rows of `polar_db`).
    pub spokes: usize,
    /// Range bins (columns).
    pub range_bins: usize,
    /// Range of bin j is `j·range_bin_m`.
    pub range_bin_m: f64,
    /// Matched-filter output power over mean noise power, dB, spokes × bins row-major.
    pub polar_db: Vec<f32>,
    /// The range-Doppler cube (pulse mode, when asked for).
    pub doppler_cube: Option<DopplerCube>,
    /// The raw received I/Q of every pulse (when asked for).
    pub iq: Option<PulseIq>,
    /// Every cell's pulse-pair radial velocity (pulse mode, when asked for).
    pub radial_velocity: Option<RadialVelocity>,
    /// The receiver's quantised video (scenes with a `[receiver]` table).
    pub video: Option<Video>,
    /// The frame's artefacts: echoes that are not a target where they appear (sidelobe echoes,
    /// second-trace echoes, interference), each with its source, reason and boxes.
    pub artefacts: Vec<artefacts::ArtefactTruth>,
    /// Per-object ground truth (PPI pixel boxes are added by the PPI product for a given
    /// image: `products::ppi::PpiGeometry::label`).
    pub truth: Vec<ObjectTruth>,
    /// The land's cells and polygons (None without land in view, and in a render without
    /// clutter, which has no land echo).
    pub land: Option<land::LandTruth>,
    /// Counts and timings.
    pub stats: FrameStats,
}
