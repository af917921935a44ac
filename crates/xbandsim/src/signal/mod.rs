//! Stage: signal sources — what reaches the receiver in one pulse (docs/architecture.md,
//! "Signal chain"; docs/physics.md, "Pipeline"). Each source adds its contribution to the
//! pulse's record (noise-rms units, `record_len` samples from the start of transmission)
//! given the pulse's time and azimuth ([`PulseAt`]) and the revolution's random streams
//! ([`FrameKey`]):
//!
//! - [`targets::FixedEchoes`]: the traced objects' echo groups weighted by the antenna
//!   pattern at the pulse's azimuth (docs/physics.md §3–§5);
//! - [`clutter::SeaAndRainClutter`]: the revolution's clutter map ([`clutter_map`]: cell
//!   geometry, σ0, texture, speckle), fresh speckle every pulse or Doppler-coloured over a
//!   dwell (docs/physics.md, "Sea clutter", "Rain", §10);
//! - [`targets::MovingEchoes`]: each moving object's echo advanced to the pulse's time —
//!   delay walk, carrier phase, bearing and intra-pulse Doppler (docs/physics.md §10);
//! - [`noise::ThermalNoise`]: the receiver's noise, in its own channel (the fused matched
//!   filter takes echoes and noise apart).
//!
//! The engine's per-dwell loop (`crate::engine`) adds them in that order — the order fixes
//! the float sums of every output byte, nothing physical — then hands the record to the
//! receiver and the matched filter.

pub mod beacons;
pub mod clutter;
pub mod clutter_map;
pub mod interference;
pub mod noise;
pub mod targets;

use crate::rng::FrameKey;
use crate::schedule::{Dwell, Pulse};
use clutter_map::DwellClutterScratch;
use num_complex::Complex32;

/// One pulse as the sources see it.
#[derive(Debug, Clone, Copy)]
pub struct PulseAt<'a> {
    /// The pulse: number (keys its streams), time, antenna azimuth.
    pub pulse: &'a Pulse,
    /// The spoke its dwell fills (places the clutter cells the beam sees).
    pub spoke: usize,
    /// Its place in the dwell (0 for the first pulse).
    pub index: usize,
    /// The revolution's random streams.
    pub key: FrameKey,
}

/// A source of received signal: adds its contribution to a pulse's record.
pub trait Source: Sync {
    /// Prepares the dwell `dwell` (filling the spoke `dwell.spoke`) before its first pulse: a
    /// source whose pulses are correlated over the dwell draws them here. Nothing by default.
    fn begin_dwell(&self, _dwell: &Dwell, _key: FrameKey, _scratch: &mut SourceScratch) {}

    /// Adds this source's signal of pulse `at` into `samples` (the record, noise-rms units),
    /// with `scratch` for its buffers. Returns the earliest sample it wrote (`Some(0)` for
    /// returns that start at the radar, such as clutter), which decides whether blanking cuts
    /// an echo; None when it wrote nothing.
    fn add_to_pulse(
        &self,
        at: &PulseAt,
        scratch: &mut SourceScratch,
        samples: &mut [Complex32],
    ) -> Option<usize>;
}

/// The sources' buffers of one worker, reused from pulse to pulse (what they held before
/// never changes an output: tested with NaN).
#[derive(Debug, Default)]
pub struct SourceScratch {
    /// Beam-weighted sea clutter power of the spoke being formed
    /// ([`clutter_map::ClutterMap::add_to_spoke`]).
    pub clutter_sea: Vec<f32>,
    /// Beam-weighted rain power of the spoke being formed.
    pub clutter_rain: Vec<f32>,
    /// The dwell's Doppler-coloured clutter, pulse after pulse (pulse mode).
    pub dwell_clutter: Vec<Complex32>,
    /// The dwell's pulse times, s.
    pub dwell_times: Vec<f64>,
    /// Buffers of [`clutter_map::ClutterMap::add_dwell`].
    pub dwell_scratch: DwellClutterScratch,
    /// One mover's impulse response (record length).
    pub mover: Vec<Complex32>,
}

impl SourceScratch {
    /// Fills every buffer with `value` (its real part for real buffers).
    pub fn fill(&mut self, value: Complex32) {
        self.clutter_sea.fill(value.re);
        self.clutter_rain.fill(value.re);
        self.dwell_clutter.fill(value);
        self.dwell_times.fill(f64::from(value.re));
        self.mover.fill(value);
    }
}

/// This radar as another transmitter's signal meets it: its antenna and where it stands,
/// the own ship's blind sectors, its wavelength, peak power, noise power per sample, sample
/// rate, receiver bandwidth (the sweep, or 1/T), record and pulse lengths (samples).
#[derive(Debug, Clone, Copy)]
pub struct ThisRadar<'a> {
    /// Its antenna.
    pub antenna: crate::antenna::Antenna,
    /// Its antenna's phase centre, ENU m.
    pub position_m: glam::DVec3,
    /// The own ship's blind sectors.
    pub blind: crate::model::artefacts::BlindView<'a>,
    /// Wavelength, m.
    pub wavelength_m: f64,
    /// Peak transmit power, W.
    pub peak_power_w: f64,
    /// Noise power per sample, W.
    pub noise_power_w: f64,
    /// Sample rate, Hz.
    pub sample_rate_hz: f64,
    /// Receiver bandwidth, Hz.
    pub bandwidth_hz: f64,
    /// Record length, samples.
    pub record_len: usize,
    /// Pulse length, samples (at least 1).
    pub pulse_len: usize,
}

impl ThisRadar<'_> {
    /// The one-way link to `position_m` with the beam at `beam_azimuth_rad`.
    pub fn link(&self, position_m: glam::DVec3, beam_azimuth_rad: f64) -> OneWayLink {
        OneWayLink::new(
            position_m,
            self.position_m,
            &self.antenna,
            &self.blind,
            beam_azimuth_rad,
            self.wavelength_m,
        )
    }
}

/// A one-way path between this radar's antenna and another transmitter (an interfering
/// radar, a beacon): its range, bearing, and this antenna's gain toward it for a beam at a
/// given azimuth — `G0·Gn(Δaz)·Gn_el(el)` times the blind sectors' one-way loss — with the
/// Friis spreading `(λ/4πR)²` (docs/physics.md §14).
#[derive(Debug, Clone, Copy)]
pub struct OneWayLink {
    /// Range, m (at least 1 m).
    pub range_m: f64,
    /// Gain of this antenna toward it times the spreading, for the beam given.
    pub gain_times_spreading: f64,
    /// Its bearing from this antenna, rad (nautical).
    pub bearing_rad: f64,
}

impl OneWayLink {
    /// The link to `position_m` from an antenna at `antenna_m` with `antenna` (beam at
    /// `beam_azimuth_rad`), `blind` sectors and wavelength `wavelength_m`.
    pub fn new(
        position_m: glam::DVec3,
        antenna_m: glam::DVec3,
        antenna: &crate::antenna::Antenna,
        blind: &crate::model::artefacts::BlindView,
        beam_azimuth_rad: f64,
        wavelength_m: f64,
    ) -> OneWayLink {
        let d = position_m - antenna_m;
        let range_m = d.length().max(1.0);
        let bearing_rad = d.x.atan2(d.y);
        let elevation = (d.z / range_m).asin();
        let gain = antenna.peak_gain_linear
            * antenna.azimuth_pattern(bearing_rad - beam_azimuth_rad)
            * antenna.elevation_pattern(elevation)
            * blind.one_way_power_factor(beam_azimuth_rad);
        let spreading = (wavelength_m / (4.0 * std::f64::consts::PI * range_m)).powi(2);
        OneWayLink {
            range_m,
            gain_times_spreading: gain * spreading,
            bearing_rad,
        }
    }
}

/// The earlier of two earliest samples.
#[inline]
pub(crate) fn earlier(a: Option<usize>, b: Option<usize>) -> Option<usize> {
    match (a, b) {
        (Some(x), Some(y)) => Some(x.min(y)),
        (x, None) => x,
        (None, y) => y,
    }
}

/// The carrier phase, rad, of a pulse that another transmitter sends (`source` its index,
/// `numbers` what tells its pulses apart), uniform and unrelated to this radar's pulses and
/// to any other: a hash keyed on the render's `seed`, so that each seed draws its own phases
/// and the same seed the same ones whatever the threads.
pub(crate) fn unrelated_phase_rad(seed: u64, salt: u64, source: usize, numbers: &[u64]) -> f64 {
    let mut h = crate::rng::splitmix64(seed ^ salt);
    h = crate::rng::splitmix64(h ^ source as u64);
    for &n in numbers {
        h = crate::rng::splitmix64(h ^ n);
    }
    std::f64::consts::TAU * crate::rng::unit_f64(h)
}
