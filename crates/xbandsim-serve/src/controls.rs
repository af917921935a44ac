//! The operator's controls (docs/live.md, "Controls"): range scale, gain, sea clutter, rain
//! clutter and interference rejection, as the mayara API describes and sets them, and how
//! each sets the receiver's video chain (docs/physics.md §12, "Receiver video").

use crate::error::{Result, ServeError};
use serde::{Deserialize, Serialize};
use serde_json::{json, Value};
use xbandsim::choice::InterferenceRejection;
use xbandsim::model::receiver::{Stc, VideoSettings};

/// The control ids, as the API names them.
pub const RANGE: &str = "1";
/// Gain.
pub const GAIN: &str = "2";
/// Sea clutter.
pub const SEA: &str = "3";
/// Rain clutter.
pub const RAIN: &str = "4";
/// Interference rejection.
pub const INTERFERENCE: &str = "5";

/// Range scales a marine radar offers, m (those up to the scene's recorded range are
/// offered, and that range itself).
const RANGE_SCALES_M: [f64; 14] = [
    125.0, 250.0, 500.0, 750.0, 1000.0, 1500.0, 2000.0, 3000.0, 4000.0, 6000.0, 8000.0, 12000.0,
    16000.0, 24000.0,
];

/// The rain control's steps: the FTC differentiator's time constant, µs (None: off).
pub const RAIN_TIME_CONSTANTS_US: [Option<f64>; 4] = [None, Some(3.0), Some(1.0), Some(0.3)];

/// The gain control's range, dB.
pub const GAIN_RANGE_DB: (f64, f64) = (-30.0, 30.0);

/// The sea control's range, dB of manual STC depth.
pub const SEA_RANGE_DB: (f64, f64) = (0.0, 50.0);

/// The controls' values.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Controls {
    /// Range scale, m: the video covers 0 to this.
    pub range_m: f64,
    /// Gain, dB.
    pub gain_db: f64,
    /// Sea clutter: manual STC depth, dB (0: off), unless `sea_auto`.
    pub sea_db: f64,
    /// Sea clutter on auto (auto STC).
    pub sea_auto: bool,
    /// Rain clutter step, 0–3.
    pub rain: u32,
    /// Interference rejection.
    pub interference: InterferenceRejection,
}

/// One control's value as the API sends and takes it: `{"id": "2", "value": 10}`, with
/// `auto` for the sea control.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ControlValue {
    /// The control's id.
    pub id: String,
    /// Its value (a number; a string holding one is taken too).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub value: Option<Value>,
    /// Whether it is on auto (the sea control only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub auto: Option<bool>,
    /// Why a value was refused (sent back to the client that set it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
}

fn ir_code(ir: InterferenceRejection) -> u32 {
    match ir {
        InterferenceRejection::Off => 0,
        InterferenceRejection::Low => 1,
        InterferenceRejection::Medium => 2,
        InterferenceRejection::High => 3,
    }
}

/// The range scales offered for a recorded range of `max_range_m`.
pub fn range_scales_m(max_range_m: f64) -> Vec<f64> {
    let mut v: Vec<f64> = RANGE_SCALES_M
        .iter()
        .copied()
        .filter(|&r| r < max_range_m - 0.5)
        .collect();
    v.push(max_range_m.round());
    v
}

/// The control's number, refused (naming the control as `name`) outside `lo..=hi` dB.
fn decibels_within(c: &ControlValue, name: &str, (lo, hi): (f64, f64)) -> Result<f64> {
    let v = number(c)?;
    if !(lo..=hi).contains(&v) {
        return Err(ServeError::setting(
            name,
            v,
            &format!("must be {lo} to {hi} dB"),
        ));
    }
    Ok(v)
}

fn number(c: &ControlValue) -> Result<f64> {
    let bad = || {
        ServeError::setting(
            &format!("control {}", c.id),
            value_text(c),
            "needs a number",
        )
    };
    match &c.value {
        Some(Value::Number(n)) => n.as_f64().ok_or_else(bad),
        Some(Value::String(s)) => s.trim().parse::<f64>().map_err(|_| bad()),
        _ => Err(bad()),
    }
    .and_then(|v| if v.is_finite() { Ok(v) } else { Err(bad()) })
}

fn value_text(c: &ControlValue) -> String {
    c.value
        .as_ref()
        .map_or_else(|| "(none)".to_string(), |v| v.to_string())
}

impl Controls {
    /// The controls as the scene's `[receiver]` (or the default receiver) sets them, at the
    /// full recorded range.
    pub fn of_settings(v: &VideoSettings, max_range_m: f64) -> Controls {
        let (sea_db, sea_auto) = match v.stc {
            Stc::Off => (0.0, false),
            Stc::Manual { level_db, .. } => (level_db as f64, false),
            Stc::Auto { .. } => (0.0, true),
        };
        let rain = match v.ftc_time_constant_s {
            None => 0,
            Some(tau_s) => (1..RAIN_TIME_CONSTANTS_US.len())
                .min_by(|&a, &b| {
                    let d = |k: usize| (RAIN_TIME_CONSTANTS_US[k].unwrap() - tau_s * 1e6).abs();
                    d(a).total_cmp(&d(b))
                })
                .unwrap_or(1) as u32,
        };
        Controls {
            range_m: max_range_m.round(),
            gain_db: (v.gain_db as f64).clamp(GAIN_RANGE_DB.0, GAIN_RANGE_DB.1),
            sea_db: sea_db.clamp(SEA_RANGE_DB.0, SEA_RANGE_DB.1),
            sea_auto,
            rain,
            interference: v.interference_rejection,
        }
    }

    /// The video chain's settings: `base` (the scene's receiver) with these controls.
    pub fn apply(&self, base: &VideoSettings) -> VideoSettings {
        let mut v = *base;
        v.gain_db = self.gain_db as f32;
        v.stc = if self.sea_auto {
            match base.stc {
                Stc::Auto { .. } => base.stc,
                _ => Stc::Auto { level_db: 3.0 },
            }
        } else if self.sea_db > 0.0 {
            match base.stc {
                Stc::Manual { range_m, law, .. } => Stc::Manual {
                    level_db: self.sea_db as f32,
                    range_m,
                    law,
                },
                _ => Stc::Manual {
                    level_db: self.sea_db as f32,
                    range_m: 4000.0,
                    law: 3.0,
                },
            }
        } else {
            Stc::Off
        };
        v.ftc_time_constant_s = RAIN_TIME_CONSTANTS_US[self.rain as usize].map(|us| us * 1e-6);
        v.interference_rejection = self.interference;
        v
    }

    /// Every control's value, as the control stream sends them.
    pub fn values(&self) -> Vec<ControlValue> {
        let v = |id: &str, value: Value, auto: Option<bool>| ControlValue {
            id: id.to_string(),
            value: Some(value),
            auto,
            error: None,
        };
        vec![
            v(RANGE, json!(self.range_m), None),
            v(GAIN, json!(self.gain_db), None),
            v(SEA, json!(self.sea_db), Some(self.sea_auto)),
            v(RAIN, json!(self.rain), None),
            v(INTERFERENCE, json!(ir_code(self.interference)), None),
        ]
    }

    /// Sets one control from the API; the range scale must be one of `scales_m`. Returns
    /// the control's new value.
    pub fn set(&mut self, c: &ControlValue, scales_m: &[f64]) -> Result<ControlValue> {
        let field = format!("control {}", c.id);
        let whole = |v: f64, hi: u32, what: &str| -> Result<u32> {
            if v.fract() == 0.0 && (0.0..=hi as f64).contains(&v) {
                Ok(v as u32)
            } else {
                Err(ServeError::setting(&field, v, what))
            }
        };
        match c.id.as_str() {
            RANGE => {
                let v = number(c)?;
                if !scales_m.iter().any(|&s| (s - v).abs() < 0.5) {
                    return Err(ServeError::setting(
                        "control 1 (range)",
                        v,
                        &format!("must be one of the range scales {scales_m:?} m"),
                    ));
                }
                self.range_m = v.round();
            }
            GAIN => {
                self.gain_db = decibels_within(c, "control 2 (gain)", GAIN_RANGE_DB)?;
            }
            SEA => {
                // Both checked before either is set.
                let value = match c.value {
                    Some(_) => Some(decibels_within(
                        c,
                        "control 3 (sea clutter)",
                        SEA_RANGE_DB,
                    )?),
                    None if c.auto.is_none() => {
                        return Err(ServeError::setting(
                            "control 3 (sea clutter)",
                            "(none)",
                            "needs a value or auto",
                        ))
                    }
                    None => None,
                };
                if let Some(auto) = c.auto {
                    self.sea_auto = auto;
                }
                if let Some(v) = value {
                    self.sea_db = v;
                }
            }
            RAIN => {
                let v = number(c)?;
                self.rain = whole(v, 3, "must be 0 (off), 1, 2 or 3 (strongest)")?;
            }
            INTERFERENCE => {
                let v = number(c)?;
                self.interference =
                    match whole(v, 3, "must be 0 (off), 1 (low), 2 (medium) or 3 (high)")? {
                        0 => InterferenceRejection::Off,
                        1 => InterferenceRejection::Low,
                        2 => InterferenceRejection::Medium,
                        _ => InterferenceRejection::High,
                    };
            }
            other => {
                return Err(ServeError::setting(
                    "control id",
                    format!("{other:?}"),
                    "must be 1 (range), 2 (gain), 3 (sea clutter), 4 (rain clutter) or 5 (interference rejection)",
                ))
            }
        }
        Ok(self
            .values()
            .into_iter()
            .find(|v| v.id == c.id)
            .expect("the id was matched"))
    }

    /// The controls as the radar description lists them (mayara v1's `controls` object).
    pub fn describe(scales_m: &[f64]) -> Value {
        let range_descriptions: serde_json::Map<String, Value> = scales_m
            .iter()
            .map(|&r| {
                let text = if r >= 1000.0 {
                    format!("{} km", r / 1000.0)
                } else {
                    format!("{r} m")
                };
                (format!("{r}"), json!(text))
            })
            .collect();
        json!({
            RANGE: {
                "name": "Range",
                "description": "Range scale: the spokes cover 0 to this range",
                "validValues": scales_m,
                "descriptions": range_descriptions,
                "units": "m",
            },
            GAIN: {
                "name": "Gain",
                "description": "Receiver gain: lowers the video threshold (6 dB over the noise at 0 dB)",
                "minValue": GAIN_RANGE_DB.0,
                "maxValue": GAIN_RANGE_DB.1,
                "stepValue": 1.0,
                "units": "dB",
            },
            SEA: {
                "name": "Sea clutter",
                "description": "Sea clutter control (STC): the deepest attenuation near the radar; auto levels the clutter",
                "minValue": SEA_RANGE_DB.0,
                "maxValue": SEA_RANGE_DB.1,
                "stepValue": 1.0,
                "units": "dB",
                "hasAuto": true,
            },
            RAIN: {
                "name": "Rain clutter",
                "description": "Rain clutter control (FTC): a differentiator along range, shorter time constants for higher steps",
                "validValues": [0, 1, 2, 3],
                "descriptions": {"0": "Off", "1": "Low (3 us)", "2": "Medium (1 us)", "3": "High (0.3 us)"},
            },
            INTERFERENCE: {
                "name": "Interference rejection",
                "description": "Sweep-to-sweep correlation against other radars' pulses",
                "validValues": [0, 1, 2, 3],
                "descriptions": {"0": "Off", "1": "Low", "2": "Medium", "3": "High"},
            },
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cv(id: &str, value: Value) -> ControlValue {
        ControlValue {
            id: id.into(),
            value: Some(value),
            auto: None,
            error: None,
        }
    }

    #[test]
    fn controls_set_the_video_chain_and_refuse_bad_values() {
        let base = VideoSettings::default();
        let scales = range_scales_m(1500.0);
        assert_eq!(scales, vec![125.0, 250.0, 500.0, 750.0, 1000.0, 1500.0]);
        let mut c = Controls::of_settings(&base, 1500.0);
        assert_eq!(c.range_m, 1500.0);
        c.set(&cv(GAIN, json!(12)), &scales).unwrap();
        c.set(&cv(SEA, json!("20")), &scales).unwrap();
        c.set(&cv(RAIN, json!(2)), &scales).unwrap();
        c.set(&cv(INTERFERENCE, json!(3)), &scales).unwrap();
        c.set(&cv(RANGE, json!(750)), &scales).unwrap();
        let v = c.apply(&base);
        assert_eq!(v.gain_db, 12.0);
        assert!(matches!(v.stc, Stc::Manual { level_db, .. } if level_db == 20.0));
        assert_eq!(v.ftc_time_constant_s, Some(1e-6));
        assert_eq!(v.interference_rejection, InterferenceRejection::High);
        assert_eq!(c.range_m, 750.0);
        let auto = ControlValue {
            id: SEA.into(),
            value: None,
            auto: Some(true),
            error: None,
        };
        c.set(&auto, &scales).unwrap();
        assert!(matches!(c.apply(&base).stc, Stc::Auto { .. }));
        // A refused value leaves auto as it was.
        let both = ControlValue {
            id: SEA.into(),
            value: Some(json!(99)),
            auto: Some(false),
            error: None,
        };
        assert!(c.set(&both, &scales).is_err());
        assert!(c.sea_auto && c.sea_db == 20.0);
        for (id, value, names) in [
            (GAIN, json!(31), "control 2 (gain) 31"),
            (RANGE, json!(800), "control 1 (range) 800"),
            (RAIN, json!(1.5), "control 4 1.5"),
            (GAIN, json!("loud"), "control 2 \"loud\""),
            ("9", json!(1), "control id \"9\""),
        ] {
            let e = c.set(&cv(id, value), &scales).unwrap_err().to_string();
            assert!(e.contains(names), "{e}");
        }
        assert_eq!(c.range_m, 750.0);
    }
}
