//! Stage: products. What a render hands to its users: the [`Frame`] (the polar record and the
//! ground truth), the labels that make the truth ([`labels`]), the PPI image and its pixel
//! boxes ([`ppi`]), the encoders ([`output`]) and the frame's files written as a set
//! ([`frame_files`]: polar.npy, ppi.png, ppi_gray.png, truth.json; docs/formats.md). Later
//! products (range-Doppler cubes, video) belong here too.

pub mod frame_files;
pub mod labels;
pub mod output;
pub mod ppi;

use crate::model::revolution::ShipState;
use labels::ObjectTruth;

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
    /// Per-object ground truth (PPI pixel boxes are added by the PPI product for a given
    /// image: `products::ppi::PpiGeometry::label`).
    pub truth: Vec<ObjectTruth>,
    /// Counts and timings.
    pub stats: FrameStats,
}
