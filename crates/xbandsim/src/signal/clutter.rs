//! Signal source: sea clutter and rain of one revolution (docs/physics.md, "Sea clutter",
//! "Rain", §10). The [`ClutterMap`] holds every cell's mean power and texture; this source
//! draws its speckle pulse by pulse. In spoke mode every pulse gets fresh complex Gaussian
//! speckle ([`ClutterMap::add_to_spoke`], stream `ClutterSpeckle` of the pulse); in pulse
//! mode a dwell's pulses share one Doppler-coloured process per cell
//! ([`ClutterMap::add_dwell`], stream `ClutterDwell` of the spoke), whose Gaussian spectrum
//! is centred on the scatterers' drift seen from the moving antenna:
//! mean `−2·(V − V_own)·û/λ` with V downwind, spread `2σ_v/λ`.

use super::clutter_map::{ClutterMap, GaussianDoppler};
use super::{PulseAt, Source, SourceScratch};
use crate::model::{ClutterDoppler, Radar};
use crate::rng::{FrameKey, Stream};
use crate::schedule::Dwell;
use glam::DVec3;
use num_complex::Complex32;

/// How a dwell's pulses see the clutter.
#[derive(Debug, Clone, Copy)]
pub enum ClutterSpeckle {
    /// Fresh speckle every pulse (spoke mode).
    PerPulse,
    /// One Doppler-coloured process over each dwell (pulse mode), seen from an antenna moving
    /// at `own_velocity_mps` (ENU).
    Doppler {
        /// The scatterers' drift and spread.
        drift: ClutterDoppler,
        /// The antenna's velocity, ENU m/s.
        own_velocity_mps: DVec3,
        /// Wavelength, m.
        wavelength_m: f64,
        /// Spoke azimuths come from this scan's spokes.
        spokes: usize,
    },
}

/// The sea and rain clutter of a revolution as a signal source.
pub struct SeaAndRainClutter<'a> {
    map: &'a ClutterMap,
    speckle: ClutterSpeckle,
    record_len: usize,
}

impl<'a> SeaAndRainClutter<'a> {
    /// The clutter of `map` into records of `record_len` samples, its speckle drawn as
    /// `speckle` says.
    pub fn new(map: &'a ClutterMap, speckle: ClutterSpeckle, record_len: usize) -> Self {
        SeaAndRainClutter {
            map,
            speckle,
            record_len,
        }
    }

    /// Pulse-mode speckle for `radar` moving at `own_velocity_mps`.
    pub fn doppler_speckle(
        radar: &Radar,
        drift: ClutterDoppler,
        own_velocity_mps: DVec3,
    ) -> ClutterSpeckle {
        ClutterSpeckle::Doppler {
            drift,
            own_velocity_mps,
            wavelength_m: radar.wavelength_m(),
            spokes: radar.spokes(),
        }
    }
}

/// The Doppler spectra of sea clutter and rain seen by a beam at `azimuth_rad` from an antenna
/// moving at `own_velocity` (ENU m/s): mean `−2·(V − V_own)·û/λ` with V the scatterers' drift
/// downwind, spread `2σ_v/λ`.
pub fn clutter_doppler(
    drift: &ClutterDoppler,
    wavelength_m: f64,
    azimuth_rad: f64,
    own_velocity: DVec3,
) -> (GaussianDoppler, GaussianDoppler) {
    let look = DVec3::new(azimuth_rad.sin(), azimuth_rad.cos(), 0.0);
    let downwind = DVec3::new(drift.downwind_rad.sin(), drift.downwind_rad.cos(), 0.0);
    let line = |speed: f64, spread: f64| GaussianDoppler {
        mean_hz: -2.0 * (downwind * speed - own_velocity).dot(look) / wavelength_m,
        spread_hz: 2.0 * spread / wavelength_m,
    };
    (
        line(drift.sea_velocity_mps, drift.sea_spread_mps),
        line(drift.rain_velocity_mps, drift.rain_spread_mps),
    )
}

impl Source for SeaAndRainClutter<'_> {
    fn begin_dwell(&self, dwell: &Dwell, key: FrameKey, scratch: &mut SourceScratch) {
        let ClutterSpeckle::Doppler {
            drift,
            own_velocity_mps,
            wavelength_m,
            spokes,
        } = self.speckle
        else {
            return;
        };
        let k = dwell.spoke;
        let record = self.record_len;
        let spoke_az = std::f64::consts::TAU * k as f64 / spokes as f64;
        scratch.dwell_times.clear();
        scratch
            .dwell_times
            .extend(dwell.pulses.iter().map(|p| p.time_s));
        scratch.dwell_clutter.clear();
        scratch
            .dwell_clutter
            .resize(dwell.pulses.len() * record, Complex32::new(0.0, 0.0));
        let (sea, rain) = clutter_doppler(&drift, wavelength_m, spoke_az, own_velocity_mps);
        let look = DVec3::new(spoke_az.sin(), spoke_az.cos(), 0.0);
        let land_doppler_hz = 2.0 * own_velocity_mps.dot(look) / wavelength_m;
        self.map.add_dwell(
            k,
            &scratch.dwell_times,
            sea,
            rain,
            land_doppler_hz,
            key.dwell(k),
            &mut scratch.dwell_scratch,
            &mut scratch.dwell_clutter,
            record,
        );
    }

    /// Returns `Some(0)`: clutter starts at the radar.
    fn add_to_pulse(
        &self,
        at: &PulseAt,
        scratch: &mut SourceScratch,
        samples: &mut [Complex32],
    ) -> Option<usize> {
        let record = self.record_len;
        match self.speckle {
            ClutterSpeckle::PerPulse => self.map.add_to_spoke(
                at.spoke,
                at.key.pulse(at.pulse.number, Stream::ClutterSpeckle),
                &mut scratch.clutter_sea,
                &mut scratch.clutter_rain,
                &mut samples[..record],
            ),
            ClutterSpeckle::Doppler { .. } => {
                let m = at.index;
                for (b, x) in samples[..record]
                    .iter_mut()
                    .zip(&scratch.dwell_clutter[m * record..(m + 1) * record])
                {
                    *b += x;
                }
            }
        }
        Some(0)
    }
}
