//! Model: the radar presets — the sets a scene can start from — with their range scales and
//! pulse tables (docs/formats.md, "Radar presets", gives every figure and where it comes
//! from). A preset gives the defaults of the `[radar]` table; every field a scene file gives
//! overrides it. `range_scale_nm` picks a row of the preset's table: the recorded range, the
//! pulse and its PRF at once, as a set's range-scale switch does.

use crate::choice::{PulseLength, Transmitter};
use crate::constants::SPEED_OF_LIGHT_M_PER_S;
use crate::error::{Error, Problem, Result};
use crate::model::checks::finite;
use crate::scene::{RadarPreset, RadarSpec};

/// One nautical mile, m.
pub const NAUTICAL_MILE_M: f64 = 1852.0;

/// Range bins a range scale's spoke is sampled into at least (the simulation's sampling,
/// not a maker's figure: enough for a 1024-pixel PPI).
pub const MIN_BINS_PER_SCALE: f64 = 1024.0;

/// Samples a pulse spans at least at a range scale's sample rate.
pub const MIN_SAMPLES_PER_PULSE: f64 = 4.0;

/// One pulse of a preset: its length, repetition frequency and (solid state) sweep.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PulseRow {
    /// Which pulse.
    pub length: PulseLength,
    /// Pulse width, µs.
    pub width_us: f64,
    /// Pulse repetition frequency, Hz.
    pub prf_hz: f64,
    /// LFM sweep, MHz (0 for a magnetron's unmodulated pulse).
    pub bandwidth_mhz: f64,
}

/// One range scale of a preset: its range and the pulses it offers, the first its default.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScaleRow {
    /// The scale, nautical miles (the PPI's radius).
    pub range_nm: f64,
    /// The pulses it offers; the first is the one it fires unless `pulse_length` says.
    pub pulses: &'static [PulseLength],
}

/// A preset's figures: the `[radar]` defaults it gives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PresetFigures {
    /// The name a scene file uses.
    pub name: &'static str,
    /// What makes the pulse.
    pub transmitter: Transmitter,
    /// Carrier, GHz.
    pub frequency_ghz: f64,
    /// Peak power, W.
    pub peak_power_w: f64,
    /// Azimuth 3-dB beamwidth, degrees.
    pub azimuth_beamwidth_deg: f64,
    /// Elevation 3-dB beamwidth, degrees.
    pub elevation_beamwidth_deg: f64,
    /// Peak antenna gain, dBi (None: from the beamwidths).
    pub gain_dbi: Option<f64>,
    /// The azimuth pattern's sidelobes: (near sidelobes, far-sidelobe floor, back lobe), dB
    /// one-way; None: sinc².
    pub sidelobes_db: Option<(f64, f64, f64)>,
    /// Noise figure, dB.
    pub noise_figure_db: f64,
    /// Rotation, rpm.
    pub rotation_rpm: f64,
    /// Antenna height above the sea, m.
    pub antenna_height_m: f64,
    /// Spokes per revolution of the calibrated record.
    pub spokes: usize,
    /// Its pulses.
    pub pulses: &'static [PulseRow],
    /// Its range scales, shortest first.
    pub scales: &'static [ScaleRow],
    /// The scale a scene gets when it gives neither `range_scale_nm` nor `max_range_m`
    /// (None: the preset's fixed pulse, PRF and range below).
    pub default_scale_nm: Option<f64>,
}

use PulseLength::{Long, Medium, Short};

const fn scale(range_nm: f64, pulses: &'static [PulseLength]) -> ScaleRow {
    ScaleRow { range_nm, pulses }
}

const fn pulse(length: PulseLength, width_us: f64, prf_hz: f64, bandwidth_mhz: f64) -> PulseRow {
    PulseRow {
        length,
        width_us,
        prf_hz,
        bandwidth_mhz,
    }
}

/// The range scales of the DRS4D-NXT-like set, 1/8 … 36 NM.
const NXT_SCALES: &[ScaleRow] = &[
    scale(0.125, &[Short]),
    scale(0.25, &[Short]),
    scale(0.5, &[Short]),
    scale(0.75, &[Short, Medium]),
    scale(1.0, &[Short, Medium]),
    scale(1.5, &[Medium, Short, Long]),
    scale(2.0, &[Medium, Long]),
    scale(3.0, &[Medium, Long]),
    scale(4.0, &[Long, Medium]),
    scale(6.0, &[Long]),
    scale(8.0, &[Long]),
    scale(12.0, &[Long]),
    scale(16.0, &[Long]),
    scale(24.0, &[Long]),
    scale(32.0, &[Long]),
    scale(36.0, &[Long]),
];

/// The range scales of a small craft's radome set, 1/8 … 48 NM.
const RADOME_SCALES: &[ScaleRow] = &[
    scale(0.125, &[Short]),
    scale(0.25, &[Short]),
    scale(0.5, &[Short]),
    scale(0.75, &[Short, Medium]),
    scale(1.0, &[Short, Medium]),
    scale(1.5, &[Medium, Short, Long]),
    scale(2.0, &[Medium, Long]),
    scale(3.0, &[Medium, Long]),
    scale(4.0, &[Long, Medium]),
    scale(6.0, &[Long]),
    scale(8.0, &[Long]),
    scale(12.0, &[Long]),
    scale(16.0, &[Long]),
    scale(24.0, &[Long]),
    scale(36.0, &[Long]),
    scale(48.0, &[Long]),
];

/// The range scales of a ship's set, 1/8 … 96 NM.
const SHIP_SCALES: &[ScaleRow] = &[
    scale(0.125, &[Short]),
    scale(0.25, &[Short]),
    scale(0.5, &[Short, Medium]),
    scale(0.75, &[Short, Medium]),
    scale(1.5, &[Short, Medium, Long]),
    scale(3.0, &[Medium, Short, Long]),
    scale(6.0, &[Medium, Long]),
    scale(12.0, &[Long, Medium]),
    scale(24.0, &[Long]),
    scale(48.0, &[Long]),
    scale(72.0, &[Long]),
    scale(96.0, &[Long]),
];

/// The range scales of a solid-state open array, 1/8 … 72 NM.
const OPEN_ARRAY_SCALES: &[ScaleRow] = &[
    scale(0.125, &[Short]),
    scale(0.25, &[Short]),
    scale(0.5, &[Short]),
    scale(0.75, &[Short, Medium]),
    scale(1.0, &[Short, Medium]),
    scale(1.5, &[Medium, Short, Long]),
    scale(2.0, &[Medium, Long]),
    scale(3.0, &[Medium, Long]),
    scale(4.0, &[Long, Medium]),
    scale(6.0, &[Long]),
    scale(8.0, &[Long]),
    scale(12.0, &[Long]),
    scale(16.0, &[Long]),
    scale(24.0, &[Long]),
    scale(36.0, &[Long]),
    scale(48.0, &[Long]),
    scale(72.0, &[Long]),
];

/// The solid-state sets' pulses (assumed: short pulses near, longer and narrower sweeps far).
const SOLID_STATE_PULSES: &[PulseRow] = &[
    pulse(Short, 0.1, 2000.0, 50.0),
    pulse(Medium, 1.0, 1200.0, 20.0),
    pulse(Long, 4.0, 600.0, 5.0),
];

/// The magnetron sets' pulses: widths as the FR-8251's (0.08, 0.3, 1.2 µs); the radome
/// set's long pulse 0.8 µs and every PRF assumed.
const RADOME_PULSES: &[PulseRow] = &[
    pulse(Short, 0.08, 2100.0, 0.0),
    pulse(Medium, 0.3, 1200.0, 0.0),
    pulse(Long, 0.8, 600.0, 0.0),
];

const SHIP_PULSES: &[PulseRow] = &[
    pulse(Short, 0.08, 2100.0, 0.0),
    pulse(Medium, 0.3, 1200.0, 0.0),
    pulse(Long, 1.2, 500.0, 0.0),
];

/// The presets, in `RadarPreset` order (docs/formats.md, "Radar presets", gives the source
/// of every figure).
pub const PRESETS: [PresetFigures; 5] = [
    PresetFigures {
        name: "drs4d-nxt",
        transmitter: Transmitter::SolidState,
        frequency_ghz: 9.41,
        peak_power_w: 25.0,
        azimuth_beamwidth_deg: 3.9,
        elevation_beamwidth_deg: 25.0,
        gain_dbi: None,
        sidelobes_db: None,
        noise_figure_db: 5.0,
        rotation_rpm: 24.0,
        antenna_height_m: 4.0,
        spokes: 360,
        pulses: SOLID_STATE_PULSES,
        scales: NXT_SCALES,
        default_scale_nm: None,
    },
    PresetFigures {
        name: "magnetron-4kw-radome",
        transmitter: Transmitter::Magnetron,
        frequency_ghz: 9.41,
        peak_power_w: 4000.0,
        azimuth_beamwidth_deg: 3.5,
        elevation_beamwidth_deg: 25.0,
        gain_dbi: None,
        sidelobes_db: None,
        noise_figure_db: 6.0,
        rotation_rpm: 24.0,
        antenna_height_m: 4.0,
        spokes: 360,
        pulses: RADOME_PULSES,
        scales: RADOME_SCALES,
        default_scale_nm: Some(0.75),
    },
    PresetFigures {
        name: "magnetron-25kw-open-array",
        transmitter: Transmitter::Magnetron,
        frequency_ghz: 9.41,
        peak_power_w: 25_000.0,
        azimuth_beamwidth_deg: 1.1,
        elevation_beamwidth_deg: 23.0,
        gain_dbi: Some(29.0),
        sidelobes_db: Some((-23.0, -30.0, -35.0)),
        noise_figure_db: 6.0,
        rotation_rpm: 24.0,
        antenna_height_m: 15.0,
        spokes: 720,
        pulses: SHIP_PULSES,
        scales: SHIP_SCALES,
        default_scale_nm: Some(1.5),
    },
    PresetFigures {
        name: "s-band-30kw",
        transmitter: Transmitter::Magnetron,
        frequency_ghz: 3.05,
        peak_power_w: 30_000.0,
        azimuth_beamwidth_deg: 1.9,
        elevation_beamwidth_deg: 25.0,
        gain_dbi: None,
        sidelobes_db: Some((-23.0, -30.0, -35.0)),
        noise_figure_db: 5.0,
        rotation_rpm: 24.0,
        antenna_height_m: 25.0,
        spokes: 720,
        pulses: SHIP_PULSES,
        scales: SHIP_SCALES,
        default_scale_nm: Some(3.0),
    },
    PresetFigures {
        name: "solid-state-open-array",
        transmitter: Transmitter::SolidState,
        frequency_ghz: 9.41,
        peak_power_w: 25.0,
        azimuth_beamwidth_deg: 1.8,
        elevation_beamwidth_deg: 23.0,
        gain_dbi: Some(27.0),
        sidelobes_db: Some((-23.0, -30.0, -35.0)),
        noise_figure_db: 5.0,
        rotation_rpm: 24.0,
        antenna_height_m: 10.0,
        spokes: 720,
        pulses: SOLID_STATE_PULSES,
        scales: OPEN_ARRAY_SCALES,
        default_scale_nm: Some(1.5),
    },
];

/// A preset's figures.
pub fn figures(preset: RadarPreset) -> &'static PresetFigures {
    &PRESETS[match preset {
        RadarPreset::Drs4dNxt => 0,
        RadarPreset::Magnetron4kwRadome => 1,
        RadarPreset::Magnetron25kwOpenArray => 2,
        RadarPreset::SBand30kw => 3,
        RadarPreset::SolidStateOpenArray => 4,
    }]
}

/// The defaults a `[radar]` table gets from its preset and range scale, before its own
/// fields override them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RadarDefaults {
    /// The preset's figures.
    pub preset: &'static PresetFigures,
    /// The range scale in use, NM (None: the preset's fixed figures or `max_range_m`).
    pub range_scale_nm: Option<f64>,
    /// The pulse the scale fires (None without a scale).
    pub pulse: Option<PulseRow>,
    /// Recorded range, m.
    pub max_range_m: f64,
    /// Pulse width, µs.
    pub pulse_width_us: f64,
    /// PRF, Hz.
    pub prf_hz: f64,
    /// LFM sweep, MHz (solid state; 0 for the magnetron's pulse).
    pub bandwidth_mhz: f64,
    /// Complex sample rate, MHz.
    pub sample_rate_mhz: f64,
}

impl RadarDefaults {
    /// The defaults of `s`'s preset at `s.range_scale_nm` (or the preset's default scale when
    /// neither it nor `max_range_m` is given), with `pulse_length`; errors name the field.
    pub fn of(s: &RadarSpec) -> Result<RadarDefaults> {
        let preset = figures(s.preset.unwrap_or_default());
        let scale_nm = match (s.range_scale_nm, s.max_range_m) {
            (Some(nm), Some(m)) => {
                return Err(Error::invalid(
                    Problem::Conflict,
                    "radar.max_range_m",
                    m,
                    format!("radar.range_scale_nm = {nm} sets the recorded range ({nm} NM); give one of the two"),
                ))
            }
            (Some(nm), None) => Some(finite("radar.range_scale_nm", nm)?),
            (None, Some(_)) => None,
            (None, None) => preset.default_scale_nm,
        };
        let Some(nm) = scale_nm else {
            if let Some(p) = s.pulse_length {
                return Err(Error::invalid(
                    Problem::Conflict,
                    "radar.pulse_length",
                    format!("\"{}\"", p.name()),
                    "a pulse is chosen by range scale: give radar.range_scale_nm too",
                ));
            }
            return Ok(RadarDefaults {
                preset,
                range_scale_nm: None,
                pulse: None,
                max_range_m: 1500.0,
                pulse_width_us: 1.0,
                prf_hz: 1200.0,
                bandwidth_mhz: 50.0,
                sample_rate_mhz: 100.0,
            });
        };
        let row = preset
            .scales
            .iter()
            .find(|r| (r.range_nm - nm).abs() < 1e-9)
            .ok_or_else(|| {
                let offered: Vec<String> = preset
                    .scales
                    .iter()
                    .map(|r| r.range_nm.to_string())
                    .collect();
                Error::invalid(
                    Problem::OutOfRange,
                    "radar.range_scale_nm",
                    nm,
                    format!(
                        "the {} preset's range scales are {} NM",
                        preset.name,
                        offered.join(", ")
                    ),
                )
            })?;
        let length = match s.pulse_length {
            None => row.pulses[0],
            Some(p) if row.pulses.contains(&p) => p,
            Some(p) => {
                let offered: Vec<&str> = row.pulses.iter().map(|p| p.name()).collect();
                return Err(Error::invalid(
                    Problem::Conflict,
                    "radar.pulse_length",
                    format!("\"{}\"", p.name()),
                    format!(
                        "the {} preset's {nm} NM scale offers {}",
                        preset.name,
                        offered.join(", ")
                    ),
                ));
            }
        };
        let pulse = *preset
            .pulses
            .iter()
            .find(|p| p.length == length)
            .expect("every scale's pulses are in the preset's pulse table");
        let max_range_m = nm * NAUTICAL_MILE_M;
        // A transmitter other than the preset's changes the sweep the scale samples: a
        // solid-state set on a magnetron preset sweeps 50 MHz, a magnetron none.
        let bandwidth_mhz = match s.transmitter {
            Some(Transmitter::SolidState) if pulse.bandwidth_mhz == 0.0 => 50.0,
            Some(Transmitter::Magnetron) => 0.0,
            _ => pulse.bandwidth_mhz,
        };
        let sampled = PulseRow {
            bandwidth_mhz,
            ..pulse
        };
        Ok(RadarDefaults {
            preset,
            range_scale_nm: Some(nm),
            pulse: Some(pulse),
            max_range_m,
            pulse_width_us: pulse.width_us,
            prf_hz: pulse.prf_hz,
            bandwidth_mhz,
            sample_rate_mhz: scale_sample_rate_mhz(&sampled, max_range_m),
        })
    }
}

/// The range a `[radar]` table records, m: its `max_range_m`, else its range scale's, else its
/// preset's default.
pub fn recorded_range_m(s: &RadarSpec) -> Result<f64> {
    match s.max_range_m {
        Some(m) => Ok(m),
        None => Ok(RadarDefaults::of(s)?.max_range_m),
    }
}

/// The simulation's sample rate at a range scale, MHz: the largest of the pulse's sweep,
/// [`MIN_SAMPLES_PER_PULSE`] samples a pulse and [`MIN_BINS_PER_SCALE`] bins over the range,
/// rounded up to a multiple of 0.5 MHz (not a maker's figure: a real set samples its video at
/// a fixed rate and keeps a spoke's worth of samples per scale).
pub fn scale_sample_rate_mhz(pulse: &PulseRow, max_range_m: f64) -> f64 {
    let for_bins = MIN_BINS_PER_SCALE * SPEED_OF_LIGHT_M_PER_S / (2.0 * max_range_m) / 1e6;
    let fs = pulse
        .bandwidth_mhz
        .max(MIN_SAMPLES_PER_PULSE / pulse.width_us)
        .max(for_bins);
    (fs * 2.0).ceil() / 2.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_scale_fires_pulses_of_its_preset_within_the_unambiguous_range() {
        for p in &PRESETS {
            for row in p.scales {
                assert!(!row.pulses.is_empty());
                for length in row.pulses {
                    let pulse = p.pulses.iter().find(|q| q.length == *length).unwrap();
                    let range_m = row.range_nm * NAUTICAL_MILE_M;
                    let unambiguous_m = SPEED_OF_LIGHT_M_PER_S / (2.0 * pulse.prf_hz);
                    let pulse_m = SPEED_OF_LIGHT_M_PER_S * pulse.width_us * 1e-6 / 2.0;
                    assert!(
                        range_m + pulse_m < unambiguous_m,
                        "{} {} NM {:?}",
                        p.name,
                        row.range_nm,
                        length
                    );
                    let fs = scale_sample_rate_mhz(pulse, range_m);
                    assert!(fs * pulse.width_us >= MIN_SAMPLES_PER_PULSE);
                    assert!(fs >= pulse.bandwidth_mhz);
                }
            }
            assert!(p.scales.windows(2).all(|w| w[0].range_nm < w[1].range_nm));
            if let Some(nm) = p.default_scale_nm {
                assert!(p.scales.iter().any(|r| r.range_nm == nm));
            }
            assert_eq!(p.pulses.len(), 3);
            assert!(p.pulses[0].width_us < p.pulses[1].width_us);
            assert!(p.pulses[1].width_us < p.pulses[2].width_us);
        }
    }
}
