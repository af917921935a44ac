//! Model: the artefacts a scene switches on — other radars nearby whose pulses reach the
//! receiver — validated from the scene file's `[artefacts]` table (docs/formats.md,
//! "[artefacts]"). `crate::signal::interference` adds their pulses.

use crate::error::{Error, Problem, Result};
use crate::model::checks::{finite, finite_vec, positive};
use crate::scene::{ArtefactsSpec, InterfererSpec};
use glam::DVec3;

/// Another radar whose pulses reach this one's receiver.
#[derive(Debug, Clone, PartialEq)]
pub struct Interferer {
    /// Its name.
    pub name: String,
    /// Its antenna, ENU m.
    pub position_m: DVec3,
    /// Its PRF, Hz.
    pub prf_hz: f64,
    /// Its rotation, rpm.
    pub rotation_rpm: f64,
    /// Its antenna's azimuth at t = 0, rad.
    pub start_azimuth_rad: f64,
    /// Its peak power, W.
    pub peak_power_w: f64,
    /// Its pulse width, s.
    pub pulse_width_s: f64,
    /// Its antenna's peak gain (linear).
    pub peak_gain_linear: f64,
    /// Its azimuth beamwidth, rad.
    pub azimuth_beamwidth_rad: f64,
    /// Its antenna's sidelobe floor (linear, one-way).
    pub sidelobe_linear: f64,
}

impl Interferer {
    /// Its antenna's azimuth at time `t_s`, rad.
    pub fn azimuth_at_rad(&self, t_s: f64) -> f64 {
        self.start_azimuth_rad + std::f64::consts::TAU * self.rotation_rpm / 60.0 * t_s
    }

    /// Its one-way normalised gain toward a bearing `bearing_rad` at time `t_s`: the sinc² of
    /// its beamwidth over its sidelobe floor.
    pub fn pattern_toward(&self, bearing_rad: f64, t_s: f64) -> f64 {
        let off = crate::antenna::wrap_angle_rad(bearing_rad - self.azimuth_at_rad(t_s));
        crate::antenna::sinc2_pattern(off, self.azimuth_beamwidth_rad).max(self.sidelobe_linear)
    }
}

/// The validated `[artefacts]` table.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Artefacts {
    /// Other radars nearby.
    pub interferers: Vec<Interferer>,
}

fn interferer(k: usize, s: &InterfererSpec) -> Result<Interferer> {
    let f = |name: &str| format!("artefacts.interferer[{k}].{name}");
    let Some(p) = s.position_m else {
        return Err(Error::missing(
            f("position_m"),
            "an interferer needs its antenna's position, [east, north, up] m",
        ));
    };
    let position_m = finite_vec(&f("position_m"), p)?;
    let sidelobe_db = finite(&f("sidelobe_db"), s.sidelobe_db.unwrap_or(-25.0))?;
    if !(-90.0..=0.0).contains(&sidelobe_db) {
        return Err(Error::invalid(
            Problem::OutOfRange,
            f("sidelobe_db"),
            sidelobe_db,
            "must be between -90 and 0 dB",
        ));
    }
    let beamwidth_deg = positive(
        &f("azimuth_beamwidth_deg"),
        s.azimuth_beamwidth_deg.unwrap_or(3.9),
    )?;
    if beamwidth_deg >= 180.0 {
        return Err(Error::invalid(
            Problem::OutOfRange,
            f("azimuth_beamwidth_deg"),
            beamwidth_deg,
            "must be less than 180",
        ));
    }
    let gain_dbi = finite(&f("gain_dbi"), s.gain_dbi.unwrap_or(25.0))?;
    if !(0.0..=50.0).contains(&gain_dbi) {
        return Err(Error::invalid(
            Problem::OutOfRange,
            f("gain_dbi"),
            gain_dbi,
            "must be between 0 and 50 dBi",
        ));
    }
    let prf_hz = positive(&f("prf_hz"), s.prf_hz.unwrap_or(1000.0))?;
    let pulse_width_us = positive(&f("pulse_width_us"), s.pulse_width_us.unwrap_or(0.3))?;
    if pulse_width_us * 1e-6 >= 1.0 / prf_hz {
        return Err(Error::invalid(
            Problem::Conflict,
            f("pulse_width_us"),
            pulse_width_us,
            format!("must be shorter than its pulse interval 1/prf_hz (prf_hz = {prf_hz})"),
        ));
    }
    Ok(Interferer {
        name: s.name.clone().unwrap_or_else(|| format!("interferer-{k}")),
        position_m,
        prf_hz,
        rotation_rpm: positive(&f("rotation_rpm"), s.rotation_rpm.unwrap_or(22.0))?,
        start_azimuth_rad: finite(&f("start_azimuth_deg"), s.start_azimuth_deg.unwrap_or(0.0))?
            .to_radians(),
        peak_power_w: positive(&f("peak_power_w"), s.peak_power_w.unwrap_or(4000.0))?,
        pulse_width_s: pulse_width_us * 1e-6,
        peak_gain_linear: 10f64.powf(gain_dbi / 10.0),
        azimuth_beamwidth_rad: beamwidth_deg.to_radians(),
        sidelobe_linear: 10f64.powf(sidelobe_db / 10.0),
    })
}

/// Validates `[artefacts]`.
pub fn build_artefacts(s: &ArtefactsSpec) -> Result<Artefacts> {
    Ok(Artefacts {
        interferers: s
            .interferer
            .iter()
            .enumerate()
            .map(|(k, i)| interferer(k, i))
            .collect::<Result<_>>()?,
    })
}
