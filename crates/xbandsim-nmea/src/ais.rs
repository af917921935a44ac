//! AIS messages as an AIS receiver passes them on: the bit layouts of ITU-R M.1371-5 (the
//! field tables of messages 1–3, 5, 18 and 24, as gpsd's "AIVDM/AIVDO protocol decoding"
//! also lays them out), six-bit ASCII text, and the `!AIVDM`/`!AIVDO` sentences that carry
//! the payload armoured six bits to a character (IEC 61162-1).
//!
//! Units on the air: positions in 1/10 000 minute, speed over ground in 0.1 kn, course in
//! 0.1°, heading in whole degrees, rate of turn as `4.733·√(°/min)`; each "not available"
//! value is the standard's (181°, 91°, 1023, 3600, 511, −128, second 60).

use crate::error::{NmeaError, Result};
use crate::sentence::frame;

/// A message's bits, most significant first.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Bits(Vec<bool>);

impl Bits {
    /// The number of bits.
    pub fn len(&self) -> usize {
        self.0.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// `value`'s `n` low bits.
    fn unsigned(&mut self, value: u64, n: usize) {
        for k in (0..n).rev() {
            self.0.push((value >> k) & 1 == 1);
        }
    }

    /// `value` in `n` bits, two's complement.
    fn signed(&mut self, value: i64, n: usize) {
        self.unsigned(value as u64 & ((1u64 << n) - 1), n);
    }

    /// `text` in six-bit ASCII, `chars` characters, padded with `@` (upper-cased; a
    /// character six-bit ASCII lacks, or a text too long, is refused naming `field`).
    fn text(&mut self, field: &'static str, text: &str, chars: usize) -> Result<()> {
        let upper = text.to_ascii_uppercase();
        if upper.chars().count() > chars {
            return Err(NmeaError::field(
                field,
                format!("{text:?}: at most {chars} characters"),
            ));
        }
        for c in upper.chars().chain(std::iter::repeat('@')).take(chars) {
            let code = c as u32;
            let six = match code {
                64..=95 => code - 64,
                32..=63 => code,
                _ => {
                    return Err(NmeaError::field(
                        field,
                        format!("{text:?}: {c:?} is not in AIS six-bit ASCII (A–Z, 0–9, space and @[\\]^_!\"#$%&'()*+,-./:;<=>?)"),
                    ))
                }
            };
            self.unsigned(u64::from(six), 6);
        }
        Ok(())
    }
}

/// The payload characters of `bits` (six bits each, the last padded with zero fill bits)
/// and the number of fill bits.
pub fn armour(bits: &Bits) -> (String, usize) {
    let fill = (6 - bits.len() % 6) % 6;
    let mut out = String::with_capacity(bits.len().div_ceil(6));
    for chunk in bits.0.chunks(6) {
        let mut v = 0u8;
        for k in 0..6 {
            v = (v << 1) | u8::from(chunk.get(k).copied().unwrap_or(false));
        }
        out.push(char::from(if v < 40 { v + 48 } else { v + 56 }));
    }
    (out, fill)
}

/// Payload characters a sentence carries at most (IEC 61162-1 keeps a sentence within 82
/// characters).
pub const PAYLOAD_CHARS_PER_SENTENCE: usize = 60;

/// The sentences that carry `bits`: `!{talker}VDM` (received) or `VDO` (own ship) on radio
/// `channel` (`A` or `B`), split into fragments of [`PAYLOAD_CHARS_PER_SENTENCE`]
/// characters; a message of several fragments carries `sequence` (0–9) in each.
pub fn sentences(bits: &Bits, talker: &str, own: bool, channel: char, sequence: u8) -> Vec<String> {
    let (payload, fill) = armour(bits);
    let chars: Vec<char> = payload.chars().collect();
    let parts: Vec<String> = chars
        .chunks(PAYLOAD_CHARS_PER_SENTENCE)
        .map(|c| c.iter().collect())
        .collect();
    let kind = if own { "VDO" } else { "VDM" };
    let total = parts.len();
    let seq = if total > 1 {
        (sequence % 10).to_string()
    } else {
        String::new()
    };
    parts
        .iter()
        .enumerate()
        .map(|(k, part)| {
            let fill_here = if k + 1 == total { fill } else { 0 };
            frame(
                '!',
                &format!(
                    "{talker}{kind},{total},{},{seq},{channel},{part},{fill_here}",
                    k + 1
                ),
            )
        })
        .collect()
}

/// Checks an MMSI: nine digits at most, not zero.
fn check_mmsi(mmsi: u32) -> Result<()> {
    if mmsi == 0 || mmsi > 999_999_999 {
        return Err(NmeaError::field(
            "mmsi",
            format!("{mmsi}: an MMSI is 1 to 999999999"),
        ));
    }
    Ok(())
}

/// Longitude on the air: 1/10 000 minute, 181° when unknown.
fn lon_value(lon_deg: Option<f64>) -> Result<i64> {
    match lon_deg {
        None => Ok(181 * 600_000),
        Some(x) if x.is_finite() && x.abs() <= 180.0 => Ok((x * 600_000.0).round() as i64),
        Some(x) => Err(NmeaError::field(
            "lon_deg",
            format!("{x}: must be within ±180°"),
        )),
    }
}

/// Latitude on the air: 1/10 000 minute, 91° when unknown.
fn lat_value(lat_deg: Option<f64>) -> Result<i64> {
    match lat_deg {
        None => Ok(91 * 600_000),
        Some(x) if x.is_finite() && x.abs() <= 90.0 => Ok((x * 600_000.0).round() as i64),
        Some(x) => Err(NmeaError::field(
            "lat_deg",
            format!("{x}: must be within ±90°"),
        )),
    }
}

/// Speed over ground on the air: 0.1 kn, 1022 for 102.2 kn or more, 1023 when unknown.
fn sog_value(sog_kn: Option<f64>) -> u64 {
    match sog_kn {
        Some(v) if v.is_finite() => (v.max(0.0) * 10.0).round().min(1022.0) as u64,
        _ => 1023,
    }
}

/// Course over ground on the air: 0.1°, 3600 when unknown.
fn cog_value(cog_deg: Option<f64>) -> u64 {
    match cog_deg {
        Some(v) if v.is_finite() => (v.rem_euclid(360.0) * 10.0).round() as u64 % 3600,
        _ => 3600,
    }
}

/// True heading on the air: whole degrees, 511 when unknown.
fn heading_value(heading_deg: Option<f64>) -> u64 {
    match heading_deg {
        Some(v) if v.is_finite() => v.rem_euclid(360.0).round() as u64 % 360,
        _ => 511,
    }
}

/// Rate of turn on the air: `4.733·√|ROT|` with ROT's sign, ROT in °/min, at most 126 (a
/// turn indicator's full scale, 708 °/min); −128 when unknown.
fn rot_value(rot_deg_per_min: Option<f64>) -> i64 {
    match rot_deg_per_min {
        Some(r) if r.is_finite() => {
            let v = (4.733 * r.abs().sqrt()).round().min(126.0) as i64;
            if r < 0.0 {
                -v
            } else {
                v
            }
        }
        _ => -128,
    }
}

/// The UTC second of a report: 0–59, 60 when unknown.
fn second_value(second: Option<u32>) -> u64 {
    second.filter(|s| *s < 60).map_or(60, u64::from)
}

/// What both classes' position reports say of a vessel's motion, in the same 73 bits
/// (speed over ground to UTC second).
#[derive(Debug, Clone, PartialEq)]
pub struct ReportedMotion {
    /// Speed over ground, knots.
    pub sog_kn: Option<f64>,
    /// Position accuracy better than 10 m (a differential fix).
    pub high_accuracy: bool,
    /// Longitude, degrees east.
    pub lon_deg: Option<f64>,
    /// Latitude, degrees north.
    pub lat_deg: Option<f64>,
    /// Course over ground, degrees true.
    pub cog_deg: Option<f64>,
    /// True heading, degrees.
    pub heading_deg: Option<f64>,
    /// The UTC second the position is of.
    pub second: Option<u32>,
}

impl ReportedMotion {
    /// Its bits: speed, accuracy, longitude, latitude, course, heading, second.
    fn encode(&self, b: &mut Bits) -> Result<()> {
        b.unsigned(sog_value(self.sog_kn), 10);
        b.unsigned(u64::from(self.high_accuracy), 1);
        b.signed(lon_value(self.lon_deg)?, 28);
        b.signed(lat_value(self.lat_deg)?, 27);
        b.unsigned(cog_value(self.cog_deg), 12);
        b.unsigned(heading_value(self.heading_deg), 9);
        b.unsigned(second_value(self.second), 6);
        Ok(())
    }
}

/// A class A position report (messages 1, 2 and 3).
#[derive(Debug, Clone, PartialEq)]
pub struct ClassAPosition {
    /// 1 (scheduled), 2 (assigned scheduled) or 3 (special, in answer to an interrogation).
    pub message_type: u8,
    /// The ship's MMSI.
    pub mmsi: u32,
    /// Navigational status, 0–15 (0: under way using engine; 1: at anchor; 5: moored; 15:
    /// not defined).
    pub nav_status: u8,
    /// Rate of turn, °/min (positive to starboard); `None` when unknown.
    pub rot_deg_per_min: Option<f64>,
    /// Where it is and how it moves.
    pub motion: ReportedMotion,
    /// RAIM in use.
    pub raim: bool,
    /// The radio status (SOTDMA or ITDMA communication state), 19 bits.
    pub radio: u32,
}

/// The 168 bits of a class A position report.
pub fn class_a_position(m: &ClassAPosition) -> Result<Bits> {
    if !(1..=3).contains(&m.message_type) {
        return Err(NmeaError::field(
            "message_type",
            format!(
                "{}: a class A position report is message 1, 2 or 3",
                m.message_type
            ),
        ));
    }
    check_mmsi(m.mmsi)?;
    if m.nav_status > 15 {
        return Err(NmeaError::field(
            "nav_status",
            format!("{}: must be 0 to 15", m.nav_status),
        ));
    }
    let mut b = Bits::default();
    b.unsigned(u64::from(m.message_type), 6);
    b.unsigned(0, 2); // repeat indicator
    b.unsigned(u64::from(m.mmsi), 30);
    b.unsigned(u64::from(m.nav_status), 4);
    b.signed(rot_value(m.rot_deg_per_min), 8);
    m.motion.encode(&mut b)?;
    b.unsigned(0, 2); // special manoeuvre indicator: not available
    b.unsigned(0, 3); // spare
    b.unsigned(u64::from(m.raim), 1);
    b.unsigned(u64::from(m.radio & 0x7_ffff), 19);
    Ok(b)
}

/// A class B position report (message 18), from a carrier-sense (CS) unit.
#[derive(Debug, Clone, PartialEq)]
pub struct ClassBPosition {
    /// The vessel's MMSI.
    pub mmsi: u32,
    /// Where it is and how it moves.
    pub motion: ReportedMotion,
}

/// The 168 bits of a class B position report: a CS unit without display or DSC, on the
/// whole marine band, able to take message 22, autonomous, no RAIM; the radio field is the
/// communication-state selector `1` and a CS unit's default state `1100000000000000110`
/// (ITU-R M.1371-5, message 18).
pub fn class_b_position(m: &ClassBPosition) -> Result<Bits> {
    check_mmsi(m.mmsi)?;
    let mut b = Bits::default();
    b.unsigned(18, 6);
    b.unsigned(0, 2);
    b.unsigned(u64::from(m.mmsi), 30);
    b.unsigned(0, 8); // reserved for regional use
    m.motion.encode(&mut b)?;
    b.unsigned(0, 2); // reserved for regional use
    b.unsigned(1, 1); // CS unit
    b.unsigned(0, 1); // no display
    b.unsigned(0, 1); // no DSC
    b.unsigned(1, 1); // whole marine band
    b.unsigned(1, 1); // takes message 22
    b.unsigned(0, 1); // autonomous mode
    b.unsigned(0, 1); // no RAIM
    b.unsigned(CLASS_B_CS_RADIO, 20);
    Ok(b)
}

/// Message 18's radio field for a CS unit: selector `1`, then `1100000000000000110`.
pub const CLASS_B_CS_RADIO: u64 = 0b1110_0000_0000_0000_0110;

/// A ship's static data as AIS carries it (messages 5 and 24).
#[derive(Debug, Clone, PartialEq)]
pub struct StaticData {
    /// The ship's MMSI.
    pub mmsi: u32,
    /// IMO number (0 for none).
    pub imo: u32,
    /// Call sign, up to 7 characters.
    pub call_sign: String,
    /// Name, up to 20 characters.
    pub name: String,
    /// Ship and cargo type, 0–99 (30: fishing; 36: sailing; 37: pleasure craft; 50: pilot
    /// vessel; 60–69: passenger; 70–79: cargo; 80–89: tanker).
    pub ship_type: u8,
    /// Distances from the position reference to the bow, stern, port and starboard, m.
    pub to_bow_m: u32,
    /// See `to_bow_m`.
    pub to_stern_m: u32,
    /// See `to_bow_m`.
    pub to_port_m: u32,
    /// See `to_bow_m`.
    pub to_starboard_m: u32,
    /// Draught, m.
    pub draught_m: f64,
    /// Destination, up to 20 characters.
    pub destination: String,
}

/// A ship's dimensions on the air: 9, 9, 6 and 6 bits, each clamped to its largest value
/// (511 m and 63 m, which mean "that or more").
fn dimensions(b: &mut Bits, s: &StaticData) {
    b.unsigned(u64::from(s.to_bow_m.min(511)), 9);
    b.unsigned(u64::from(s.to_stern_m.min(511)), 9);
    b.unsigned(u64::from(s.to_port_m.min(63)), 6);
    b.unsigned(u64::from(s.to_starboard_m.min(63)), 6);
}

fn check_static(s: &StaticData) -> Result<()> {
    check_mmsi(s.mmsi)?;
    if s.ship_type > 99 {
        return Err(NmeaError::field(
            "ship_type",
            format!("{}: must be 0 to 99", s.ship_type),
        ));
    }
    if s.imo > 0x3fff_ffff {
        return Err(NmeaError::field("imo", format!("{}: too large", s.imo)));
    }
    Ok(())
}

/// The 424 bits of a class A ship's static and voyage data (message 5): AIS version 2
/// (ITU-R M.1371-5), a GPS position fix, no ETA, data terminal ready.
pub fn static_and_voyage(s: &StaticData) -> Result<Bits> {
    check_static(s)?;
    let mut b = Bits::default();
    b.unsigned(5, 6);
    b.unsigned(0, 2);
    b.unsigned(u64::from(s.mmsi), 30);
    b.unsigned(2, 2); // AIS version: ITU-R M.1371-5
    b.unsigned(u64::from(s.imo), 30);
    b.text("call_sign", &s.call_sign, 7)?;
    b.text("name", &s.name, 20)?;
    b.unsigned(u64::from(s.ship_type), 8);
    dimensions(&mut b, s);
    b.unsigned(1, 4); // GPS
    b.unsigned(0, 4); // ETA month: not available
    b.unsigned(0, 5); // day
    b.unsigned(24, 5); // hour
    b.unsigned(60, 6); // minute
    let draught = if s.draught_m.is_finite() {
        (s.draught_m.max(0.0) * 10.0).round().min(255.0) as u64
    } else {
        0
    };
    b.unsigned(draught, 8);
    b.text("destination", &s.destination, 20)?;
    b.unsigned(0, 1); // data terminal ready
    b.unsigned(0, 1); // spare
    Ok(b)
}

/// The first 40 bits of message 24, either part: type, repeat indicator, MMSI, part number
/// (0 for A, 1 for B).
fn static_data_report(s: &StaticData, part: u64) -> Result<Bits> {
    check_static(s)?;
    let mut b = Bits::default();
    b.unsigned(24, 6);
    b.unsigned(0, 2);
    b.unsigned(u64::from(s.mmsi), 30);
    b.unsigned(part, 2);
    Ok(b)
}

/// The 160 bits of class B static data part A (message 24A): the name.
pub fn static_part_a(s: &StaticData) -> Result<Bits> {
    let mut b = static_data_report(s, 0)?;
    b.text("name", &s.name, 20)?;
    Ok(b)
}

/// The 168 bits of class B static data part B (message 24B): type, vendor (`XBS`, unit
/// model 1, serial 0), call sign and dimensions.
pub fn static_part_b(s: &StaticData) -> Result<Bits> {
    let mut b = static_data_report(s, 1)?;
    b.unsigned(u64::from(s.ship_type), 8);
    b.text("vendor", "XBS", 3)?;
    b.unsigned(1, 4); // unit model code
    b.unsigned(0, 20); // serial number
    b.text("call_sign", &s.call_sign, 7)?;
    dimensions(&mut b, s);
    b.unsigned(0, 6); // spare (EPFD type and spare in later editions: 0)
    Ok(b)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two class A reports published with their sentences (the first from a decoder's
    /// documentation, the second from pyais' test suite), re-encoded from their decoded
    /// fields to the same characters and checksum.
    #[test]
    fn class_a_reports_encode_as_published() {
        let published = [
            (
                ClassAPosition {
                    message_type: 1,
                    mmsi: 227_006_760,
                    nav_status: 0,
                    rot_deg_per_min: None,
                    motion: ReportedMotion {
                        sog_kn: Some(0.0),
                        high_accuracy: false,
                        lon_deg: Some(78_828.0 / 600_000.0),
                        lat_deg: Some(29_685_346.0 / 600_000.0),
                        cog_deg: Some(36.7),
                        heading_deg: None,
                        second: Some(14),
                    },
                    raim: false,
                    radio: 22_136,
                },
                "!AIVDM,1,1,,A,13HOI:0P0000VOHLCnHQKwvL05Ip,0*23\r\n",
            ),
            (
                ClassAPosition {
                    message_type: 1,
                    mmsi: 367_533_950,
                    nav_status: 0,
                    rot_deg_per_min: None,
                    motion: ReportedMotion {
                        sog_kn: Some(0.0),
                        high_accuracy: true,
                        lon_deg: Some(-73_444_939.0 / 600_000.0),
                        lat_deg: Some(22_685_051.0 / 600_000.0),
                        cog_deg: None,
                        heading_deg: None,
                        second: Some(34),
                    },
                    raim: true,
                    radio: 34_059,
                },
                "!AIVDM,1,1,,A,15NPOOPP00o?b=bE`UNv4?w428D;,0*24\r\n",
            ),
        ];
        for (m, sentence) in published {
            let bits = class_a_position(&m).unwrap();
            assert_eq!(bits.len(), 168);
            assert_eq!(
                sentences(&bits, "AI", false, 'A', 0),
                vec![sentence.to_string()]
            );
        }
    }

    /// Six-bit ASCII: `@` is 0, `A` 1, space 32, `0` 48; lower case is upper-cased; other
    /// characters and overlong texts are refused naming the field.
    #[test]
    fn six_bit_text() {
        let mut b = Bits::default();
        b.text("name", "a 0", 4).unwrap();
        let (chars, fill) = armour(&b);
        // 1, 32, 48, 0 → '1', 'P', 'h', '0' (values from 40 on skip eight characters)
        assert_eq!((chars.as_str(), fill), ("1Ph0", 0));
        let err = Bits::default().text("name", "Ä", 4).unwrap_err();
        assert!(err.to_string().starts_with("name:"), "{err}");
        let err = Bits::default()
            .text("call_sign", "TOOLONGX", 7)
            .unwrap_err();
        assert!(err.to_string().starts_with("call_sign:"), "{err}");
    }

    /// Message 5 is 424 bits: 71 characters with 2 fill bits, in two fragments that share a
    /// sequence number; only the last carries the fill bits.
    #[test]
    fn static_and_voyage_data_span_two_sentences() {
        let s = StaticData {
            mmsi: 235_000_001,
            imo: 9_000_001,
            call_sign: "2ABC3".into(),
            name: "Crossing Ship".into(),
            ship_type: 70,
            to_bow_m: 60,
            to_stern_m: 50,
            to_port_m: 9,
            to_starboard_m: 9,
            draught_m: 6.4,
            destination: "PLYMOUTH".into(),
        };
        let bits = static_and_voyage(&s).unwrap();
        assert_eq!(bits.len(), 424);
        let out = sentences(&bits, "AI", false, 'B', 3);
        assert_eq!(out.len(), 2);
        assert!(out[0].starts_with("!AIVDM,2,1,3,B,") && out[0].contains(",0*"));
        assert!(out[1].starts_with("!AIVDM,2,2,3,B,") && out[1].contains(",2*"));
        assert_eq!(
            class_b_position(&ClassBPosition {
                mmsi: 235_000_002,
                motion: ReportedMotion {
                    sog_kn: Some(5.0),
                    high_accuracy: false,
                    lon_deg: Some(-4.1),
                    lat_deg: Some(50.3),
                    cog_deg: Some(90.0),
                    heading_deg: None,
                    second: Some(1),
                },
            })
            .unwrap()
            .len(),
            168
        );
        assert_eq!(static_part_a(&s).unwrap().len(), 160);
        assert_eq!(static_part_b(&s).unwrap().len(), 168);
    }

    /// Message 18 ends with the CS unit's radio field, selector 1 then 1100000000000000110.
    #[test]
    fn class_b_reports_end_with_the_cs_radio_state() {
        let bits = class_b_position(&ClassBPosition {
            mmsi: 235_000_002,
            motion: ReportedMotion {
                sog_kn: Some(5.0),
                high_accuracy: false,
                lon_deg: Some(-4.1),
                lat_deg: Some(50.3),
                cog_deg: Some(90.0),
                heading_deg: None,
                second: Some(1),
            },
        })
        .unwrap();
        let tail: String = bits.0[148..]
            .iter()
            .map(|&b| if b { '1' } else { '0' })
            .collect();
        assert_eq!(tail, "11100000000000000110");
    }

    /// Values outside what the message carries are refused naming the field; unknown ones
    /// take the standard's "not available" codes.
    #[test]
    fn bad_values_are_refused_and_unknown_ones_coded() {
        let m = ClassAPosition {
            message_type: 1,
            mmsi: 0,
            nav_status: 0,
            rot_deg_per_min: None,
            motion: ReportedMotion {
                sog_kn: None,
                high_accuracy: false,
                lon_deg: None,
                lat_deg: None,
                cog_deg: None,
                heading_deg: None,
                second: None,
            },
            raim: false,
            radio: 0,
        };
        assert!(class_a_position(&m)
            .unwrap_err()
            .to_string()
            .starts_with("mmsi: 0"));
        let m = ClassAPosition { mmsi: 1, ..m };
        let bad = ClassAPosition {
            motion: ReportedMotion {
                lat_deg: Some(95.0),
                ..m.motion.clone()
            },
            ..m.clone()
        };
        assert!(class_a_position(&bad)
            .unwrap_err()
            .to_string()
            .starts_with("lat_deg: 95"));
        assert_eq!(rot_value(None), -128);
        assert_eq!(rot_value(Some(-10.0)), -15); // 4.733·√10 = 14.97
        assert_eq!(sog_value(Some(200.0)), 1022);
        assert_eq!(cog_value(Some(359.99)), 0);
        assert_eq!(heading_value(None), 511);
        assert_eq!(lon_value(None).unwrap(), 108_600_000);
        assert_eq!(lat_value(None).unwrap(), 54_600_000);
        assert_eq!(second_value(None), 60);
        assert_eq!(class_a_position(&m).unwrap().len(), 168);
    }
}
