//! Product: the receiver's video as a stream of spoke records, the way a networked marine
//! radar sends its picture (docs/formats.md, "spokes.bin"): a file header, then one record a
//! video spoke — its angle, the own ship's heading, time, range, bits and samples — with the
//! samples one byte each or packed as the set sends them (two 4-bit samples a byte, low
//! nibble first). [`encode`] writes a revolution, [`decode`] reads any such file back.

use crate::error::{Error, Result};
use crate::receiver::video_chain::Video;
use std::path::Path;

/// The file's first eight bytes.
pub const MAGIC: &[u8; 8] = b"XBSPOKE1";

/// Bytes of the file header: magic, record count (u32), spokes a revolution (u16), flags
/// (u16, 0).
pub const FILE_HEADER_BYTES: usize = 16;

/// Bytes of a record's header: angle (u16), heading (u16), range (f32), bits (u8), flags
/// (u8), samples (u16), time (f64).
pub const RECORD_HEADER_BYTES: usize = 20;

/// Record flag: the heading field holds the own ship's heading.
pub const FLAG_HEADING: u8 = 1;

/// Record flag: the samples are packed `bits` to a sample, low bits first.
pub const FLAG_PACKED: u8 = 2;

/// How a record stores its samples.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SpokePacking {
    /// One byte a sample.
    Bytes,
    /// `bits` a sample, packed low bits first.
    Packed,
}

impl SpokePacking {
    /// By the names `--spoke-format` takes: "bytes" or "packed".
    pub fn from_name(name: &str) -> Option<SpokePacking> {
        match name {
            "bytes" => Some(SpokePacking::Bytes),
            "packed" => Some(SpokePacking::Packed),
            _ => None,
        }
    }
}

/// What a revolution's records say besides the video: when it starts, how long it lasts and
/// the own ship's heading.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SweepTiming {
    /// Time the antenna passes north, s.
    pub start_time_s: f64,
    /// Antenna rotation period, s.
    pub period_s: f64,
    /// Own ship's heading, degrees (None: the radar has no own ship).
    pub heading_deg: Option<f64>,
}

/// A fraction of a revolution in units of 1/65536.
fn to_u16_turns(deg: f64) -> u16 {
    ((deg.rem_euclid(360.0) / 360.0 * 65536.0).round() as u32 % 65536) as u16
}

/// The records of `video`, one a spoke in sweep order from north, with `timing`.
pub fn encode(video: &Video, timing: SweepTiming, packing: SpokePacking) -> Vec<u8> {
    let n = video.samples;
    let payload = match packing {
        SpokePacking::Bytes => n,
        SpokePacking::Packed => (n * video.bits as usize).div_ceil(8),
    };
    let mut out =
        Vec::with_capacity(FILE_HEADER_BYTES + video.spokes * (RECORD_HEADER_BYTES + payload));
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&(video.spokes as u32).to_le_bytes());
    out.extend_from_slice(&(video.spokes as u16).to_le_bytes());
    out.extend_from_slice(&0u16.to_le_bytes());
    let range_m = (video.sample_m * n as f64) as f32;
    let mut flags = 0u8;
    if timing.heading_deg.is_some() {
        flags |= FLAG_HEADING;
    }
    if packing == SpokePacking::Packed {
        flags |= FLAG_PACKED;
    }
    let heading = timing.heading_deg.map_or(0, to_u16_turns);
    for s in 0..video.spokes {
        let fraction = s as f64 / video.spokes as f64;
        out.extend_from_slice(&to_u16_turns(360.0 * fraction).to_le_bytes());
        out.extend_from_slice(&heading.to_le_bytes());
        out.extend_from_slice(&range_m.to_le_bytes());
        out.push(video.bits as u8);
        out.push(flags);
        out.extend_from_slice(&(n as u16).to_le_bytes());
        let time_s = timing.start_time_s + fraction * timing.period_s;
        out.extend_from_slice(&time_s.to_le_bytes());
        let levels = &video.levels[s * n..(s + 1) * n];
        match packing {
            SpokePacking::Bytes => out.extend_from_slice(levels),
            SpokePacking::Packed => pack(levels, video.bits, &mut out),
        }
    }
    out
}

/// Appends `levels` packed `bits` to a sample, low bits first.
fn pack(levels: &[u8], bits: u32, out: &mut Vec<u8>) {
    let (mut acc, mut filled) = (0u32, 0u32);
    for &l in levels {
        acc |= u32::from(l) << filled;
        filled += bits;
        while filled >= 8 {
            out.push(acc as u8);
            acc >>= 8;
            filled -= 8;
        }
    }
    if filled > 0 {
        out.push(acc as u8);
    }
}

/// One decoded record.
#[derive(Debug, Clone, PartialEq)]
pub struct SpokeRecord {
    /// True bearing of the spoke, degrees from north.
    pub angle_deg: f64,
    /// Own ship's heading, degrees (None without one).
    pub heading_deg: Option<f64>,
    /// Range of the spoke's last sample's far edge, m.
    pub range_m: f32,
    /// Bits a sample has.
    pub bits: u8,
    /// Time the antenna pointed there, s.
    pub time_s: f64,
    /// The samples' levels.
    pub levels: Vec<u8>,
}

/// A decoded file: its spokes a revolution and its records.
#[derive(Debug, Clone, PartialEq)]
pub struct SpokeStream {
    /// Spokes a revolution.
    pub spokes_per_revolution: u16,
    /// The records in file order.
    pub records: Vec<SpokeRecord>,
}

/// Reads a spoke stream back from `bytes` read from `path`; a truncated or foreign file is an
/// I/O error (invalid data) naming the path and the byte.
pub fn decode(path: &Path, bytes: &[u8]) -> Result<SpokeStream> {
    let corrupt = |offset: usize, why: String| {
        Error::io(
            path,
            std::io::Error::new(
                std::io::ErrorKind::InvalidData,
                format!("not a readable spoke stream at byte {offset}: {why}"),
            ),
        )
    };
    if bytes.len() < FILE_HEADER_BYTES || &bytes[..8] != MAGIC {
        return Err(corrupt(0, "it does not start with XBSPOKE1".into()));
    }
    let count = u32::from_le_bytes(bytes[8..12].try_into().unwrap()) as usize;
    let spokes_per_revolution = u16::from_le_bytes(bytes[12..14].try_into().unwrap());
    let mut records = Vec::with_capacity(count.min(1 << 16));
    let mut at = FILE_HEADER_BYTES;
    for i in 0..count {
        let header = bytes
            .get(at..at + RECORD_HEADER_BYTES)
            .ok_or_else(|| corrupt(at, format!("record {i} of {count} is cut short")))?;
        let u16_at = |k: usize| u16::from_le_bytes([header[k], header[k + 1]]);
        let angle = u16_at(0);
        let heading = u16_at(2);
        let range_m = f32::from_le_bytes(header[4..8].try_into().unwrap());
        let bits = header[8];
        let flags = header[9];
        let samples = u16_at(10) as usize;
        let time_s = f64::from_le_bytes(header[12..20].try_into().unwrap());
        if !(1..=8).contains(&bits) {
            return Err(corrupt(
                at + 8,
                format!("record {i} has {bits} bits a sample"),
            ));
        }
        let payload = if flags & FLAG_PACKED != 0 {
            (samples * bits as usize).div_ceil(8)
        } else {
            samples
        };
        let body_at = at + RECORD_HEADER_BYTES;
        let body = bytes
            .get(body_at..body_at + payload)
            .ok_or_else(|| corrupt(body_at, format!("record {i} of {count} is cut short")))?;
        let levels = if flags & FLAG_PACKED != 0 {
            unpack(body, bits, samples)
        } else {
            body.to_vec()
        };
        let turns = |u: u16| f64::from(u) * 360.0 / 65536.0;
        records.push(SpokeRecord {
            angle_deg: turns(angle),
            heading_deg: (flags & FLAG_HEADING != 0).then(|| turns(heading)),
            range_m,
            bits,
            time_s,
            levels,
        });
        at = body_at + payload;
    }
    if at != bytes.len() {
        return Err(corrupt(at, "bytes follow the last record".into()));
    }
    Ok(SpokeStream {
        spokes_per_revolution,
        records,
    })
}

fn unpack(body: &[u8], bits: u8, samples: usize) -> Vec<u8> {
    let mask = (1u32 << bits) - 1;
    let (mut acc, mut filled, mut next) = (0u32, 0u32, 0usize);
    (0..samples)
        .map(|_| {
            while filled < u32::from(bits) {
                acc |= u32::from(body[next]) << filled;
                next += 1;
                filled += 8;
            }
            let v = (acc & mask) as u8;
            acc >>= bits;
            filled -= u32::from(bits);
            v
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn video(bits: u32, spokes: usize, samples: usize) -> Video {
        let top = (1u32 << bits) - 1;
        Video {
            spokes,
            samples,
            bits,
            sample_m: 2.5,
            threshold_db: 6.0,
            level_step_db: 1.0,
            levels: (0..spokes * samples)
                .map(|i| ((i * 7 + i / 3) as u32 % (top + 1)) as u8)
                .collect(),
        }
    }

    #[test]
    fn records_read_back_bytes_and_packed() {
        for bits in 1..=8 {
            for packing in [SpokePacking::Bytes, SpokePacking::Packed] {
                let v = video(bits, 8, 13);
                let timing = SweepTiming {
                    start_time_s: 5.0,
                    period_s: 2.5,
                    heading_deg: Some(90.0),
                };
                let bytes = encode(&v, timing, packing);
                let back = decode(Path::new("t"), &bytes).unwrap();
                assert_eq!(back.spokes_per_revolution, 8);
                assert_eq!(back.records.len(), 8);
                for (s, r) in back.records.iter().enumerate() {
                    assert_eq!(r.levels, v.levels[s * 13..(s + 1) * 13]);
                    assert!((r.angle_deg - 45.0 * s as f64).abs() < 1e-9);
                    assert_eq!(r.heading_deg, Some(90.0));
                    assert_eq!(r.bits as u32, bits);
                    assert_eq!(r.range_m, 32.5);
                    assert!((r.time_s - (5.0 + 2.5 * s as f64 / 8.0)).abs() < 1e-12);
                }
            }
        }
    }

    #[test]
    fn four_bit_samples_pack_two_a_byte_low_nibble_first() {
        let mut out = Vec::new();
        pack(&[1, 2, 3, 4, 5], 4, &mut out);
        assert_eq!(out, vec![0x21, 0x43, 0x05]);
        assert_eq!(unpack(&out, 4, 5), vec![1, 2, 3, 4, 5]);
    }

    #[test]
    fn a_cut_or_foreign_file_is_refused() {
        let v = video(4, 4, 10);
        let timing = SweepTiming {
            start_time_s: 0.0,
            period_s: 2.5,
            heading_deg: None,
        };
        let bytes = encode(&v, timing, SpokePacking::Packed);
        assert_eq!(
            decode(Path::new("t"), &bytes).unwrap().records[0].heading_deg,
            None
        );
        for cut in [3, 20, bytes.len() - 1] {
            assert!(
                decode(Path::new("t"), &bytes[..cut]).is_err(),
                "cut at {cut}"
            );
        }
        let mut extra = bytes.clone();
        extra.push(0);
        assert!(decode(Path::new("t"), &extra).is_err());
        assert!(decode(Path::new("t"), b"PK\x03\x04 not a stream").is_err());
    }
}
