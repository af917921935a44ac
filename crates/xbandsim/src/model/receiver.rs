//! Model: the receiver's video chain settings — the log amplifier, gain, sea and rain clutter
//! controls, interference rejection, echo averaging and stretch, noise rejection and the
//! video grid — validated from the scene file's `[receiver]` table (docs/formats.md,
//! "[receiver]"). `crate::receiver::video_chain` runs them.

use crate::choice::{InterferenceRejection, StcMode};
use crate::error::{Error, Problem, Result};
use crate::model::checks::finite;
use crate::scene::ReceiverSpec;

/// The video threshold at 0 dB gain, dB over the noise: about 5 % of noise-only samples
/// (`10·log10(1 + x)` of an exponential x of mean 1) reach the first level, the light
/// speckle operators set the gain for.
pub const THRESHOLD_AT_ZERO_GAIN_DB: f32 = 6.0;

/// Largest number of video spokes or samples.
pub const MAX_VIDEO_GRID: usize = 8192;

/// The sea clutter control.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Stc {
    /// Off.
    Off,
    /// Attenuation `min(level_db, 10·law·log10(range_m/R))` for R < range_m, 0 beyond.
    Manual {
        /// Deepest attenuation, dB.
        level_db: f32,
        /// Where the attenuation ends, m.
        range_m: f64,
        /// The law's exponent k.
        law: f32,
    },
    /// Brings the median log video along range down to `level_db` over the noise where the
    /// clutter is above it, never attenuating more far than near.
    Auto {
        /// The level the median clutter is brought to, dB over noise.
        level_db: f32,
    },
}

/// The validated `[receiver]` table.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VideoSettings {
    /// Bits a sample is quantised to.
    pub video_bits: u32,
    /// Video spokes a revolution.
    pub video_spokes: usize,
    /// Video samples a spoke.
    pub video_samples: usize,
    /// The log amplifier saturates at this many dB over the noise.
    pub log_dynamic_range_db: f32,
    /// Gain, dB.
    pub gain_db: f32,
    /// Span of the levels above the threshold, dB.
    pub video_span_db: f32,
    /// Sea clutter control.
    pub stc: Stc,
    /// Rain clutter control: the FTC's time constant, s (None: off).
    pub ftc_time_constant_s: Option<f64>,
    /// Interference rejection.
    pub interference_rejection: InterferenceRejection,
    /// Scans averaged (1: off).
    pub echo_average_scans: u32,
    /// Range stretch, samples.
    pub echo_stretch_samples: usize,
    /// Lone samples cleared.
    pub noise_rejection: bool,
}

impl Default for VideoSettings {
    fn default() -> VideoSettings {
        VideoSettings::from_spec(&ReceiverSpec::default()).expect("the defaults are valid")
    }
}

fn in_range(field: &str, v: f64, lo: f64, hi: f64, why: &str) -> Result<f64> {
    let v = finite(field, v)?;
    if (lo..=hi).contains(&v) {
        Ok(v)
    } else {
        Err(Error::invalid(Problem::OutOfRange, field, v, why))
    }
}

fn count_in(field: &str, v: usize, lo: usize, hi: usize) -> Result<usize> {
    if (lo..=hi).contains(&v) {
        Ok(v)
    } else {
        Err(Error::invalid(
            Problem::OutOfRange,
            field,
            v,
            format!("must be between {lo} and {hi}"),
        ))
    }
}

impl VideoSettings {
    /// The validated settings; every error names its `receiver.` field.
    pub fn from_spec(s: &ReceiverSpec) -> Result<VideoSettings> {
        let video_bits = count_in(
            "receiver.video_bits",
            s.video_bits.unwrap_or(4) as usize,
            1,
            8,
        )?;
        let video_spokes = count_in(
            "receiver.video_spokes",
            s.video_spokes.unwrap_or(2048),
            1,
            MAX_VIDEO_GRID,
        )?;
        let video_samples = count_in(
            "receiver.video_samples",
            s.video_samples.unwrap_or(512),
            1,
            MAX_VIDEO_GRID,
        )?;
        let log_dynamic_range_db = in_range(
            "receiver.log_dynamic_range_db",
            s.log_dynamic_range_db.unwrap_or(80.0),
            10.0,
            140.0,
            "must be between 10 and 140 dB",
        )?;
        let gain_db = in_range(
            "receiver.gain_db",
            s.gain_db.unwrap_or(0.0),
            -60.0,
            f64::from(THRESHOLD_AT_ZERO_GAIN_DB),
            "must be between -60 and 6 dB (6 dB puts the threshold at the noise's 0 dB)",
        )?;
        let video_span_db = in_range(
            "receiver.video_span_db",
            s.video_span_db.unwrap_or(40.0),
            1.0,
            140.0,
            "must be between 1 and 140 dB",
        )?;
        let mode = s.stc.unwrap_or_default();
        let manual_fields = [
            ("receiver.stc_level_db", s.stc_level_db),
            ("receiver.stc_range_m", s.stc_range_m),
            ("receiver.stc_law", s.stc_law),
        ];
        let auto_fields = [("receiver.stc_auto_level_db", s.stc_auto_level_db)];
        let refuse_unused = |fields: &[(&str, Option<f64>)], wants: &str| -> Result<()> {
            for (field, v) in fields {
                if let Some(v) = v {
                    return Err(Error::invalid(
                        Problem::Conflict,
                        *field,
                        v,
                        format!("only receiver.stc = \"{wants}\" uses it"),
                    ));
                }
            }
            Ok(())
        };
        let stc = match mode {
            StcMode::Off => {
                refuse_unused(&manual_fields, "manual")?;
                refuse_unused(&auto_fields, "auto")?;
                Stc::Off
            }
            StcMode::Manual => {
                refuse_unused(&auto_fields, "auto")?;
                Stc::Manual {
                    level_db: in_range(
                        "receiver.stc_level_db",
                        s.stc_level_db.unwrap_or(20.0),
                        0.0,
                        100.0,
                        "must be between 0 and 100 dB",
                    )? as f32,
                    range_m: in_range(
                        "receiver.stc_range_m",
                        s.stc_range_m.unwrap_or(4000.0),
                        1.0,
                        1.0e6,
                        "must be between 1 m and 1000 km",
                    )?,
                    law: in_range(
                        "receiver.stc_law",
                        s.stc_law.unwrap_or(3.0),
                        0.0,
                        8.0,
                        "must be between 0 and 8",
                    )? as f32,
                }
            }
            StcMode::Auto => {
                refuse_unused(&manual_fields, "manual")?;
                Stc::Auto {
                    level_db: in_range(
                        "receiver.stc_auto_level_db",
                        s.stc_auto_level_db.unwrap_or(3.0),
                        0.1,
                        60.0,
                        "must be between 0.1 and 60 dB over the noise",
                    )? as f32,
                }
            }
        };
        let ftc_time_constant_s = match s.ftc_time_constant_us {
            None => None,
            Some(t) => Some(
                in_range(
                    "receiver.ftc_time_constant_us",
                    t,
                    0.001,
                    1000.0,
                    "must be between 0.001 and 1000 µs (leave it out for no FTC)",
                )? * 1e-6,
            ),
        };
        let echo_average_scans = count_in(
            "receiver.echo_average_scans",
            s.echo_average_scans.unwrap_or(1) as usize,
            1,
            16,
        )? as u32;
        let echo_stretch_samples = count_in(
            "receiver.echo_stretch_samples",
            s.echo_stretch_samples.unwrap_or(0),
            0,
            16,
        )?;
        Ok(VideoSettings {
            video_bits: video_bits as u32,
            video_spokes,
            video_samples,
            log_dynamic_range_db: log_dynamic_range_db as f32,
            gain_db: gain_db as f32,
            video_span_db: video_span_db as f32,
            stc,
            ftc_time_constant_s,
            interference_rejection: s.interference_rejection.unwrap_or_default(),
            echo_average_scans,
            echo_stretch_samples,
            noise_rejection: s.noise_rejection.unwrap_or(false),
        })
    }

    /// Largest video level, `2^bits − 1`.
    pub fn max_level(&self) -> u8 {
        ((1u32 << self.video_bits) - 1) as u8
    }

    /// The video threshold, dB over the noise: [`THRESHOLD_AT_ZERO_GAIN_DB`] − gain.
    pub fn threshold_db(&self) -> f32 {
        THRESHOLD_AT_ZERO_GAIN_DB - self.gain_db
    }
}
