//! The spoke stream's protobuf message (docs/live.md, "The spoke stream"): `RadarMessage` of
//! the mayara radar server's API, field numbers and types as its `RadarMessage.proto`
//! gives them ([`PROTO`] is the schema this server publishes at
//! `/v1/api/RadarMessage.proto`). Encoded by `prost` from these derived types.

/// The schema, as served.
pub const PROTO: &str = include_str!("RadarMessage.proto");

/// A message of the spoke stream: one or more consecutive spokes.
#[derive(Clone, PartialEq, prost::Message)]
pub struct RadarMessage {
    /// The radar's number.
    #[prost(uint32, tag = "1")]
    pub radar: u32,
    /// The spokes, in sweep order.
    #[prost(message, repeated, tag = "2")]
    pub spokes: Vec<Spoke>,
}

/// One spoke.
#[derive(Clone, PartialEq, prost::Message)]
pub struct Spoke {
    /// Spoke number from the bow, clockwise, `[0, spokes)`.
    #[prost(uint32, tag = "1")]
    pub angle: u32,
    /// Spoke number from true north, clockwise, `[0, spokes)`.
    #[prost(uint32, optional, tag = "2")]
    pub bearing: Option<u32>,
    /// Range of the last sample, m.
    #[prost(uint32, tag = "3")]
    pub range: u32,
    /// When the beam swept it, ms after 1970-01-01T00:00:00Z.
    #[prost(uint64, optional, tag = "4")]
    pub time: Option<u64>,
    /// The samples, one byte each: indices into the legend.
    #[prost(bytes = "vec", tag = "5")]
    pub data: Vec<u8>,
    /// The antenna's latitude, 1e-16 degree.
    #[prost(int64, optional, tag = "6")]
    pub lat: Option<i64>,
    /// The antenna's longitude, 1e-16 degree.
    #[prost(int64, optional, tag = "7")]
    pub lon: Option<i64>,
}

/// Degrees in the stream's unit, 1e-16 degree.
pub fn to_e16(deg: f64) -> i64 {
    (deg * 1e16).round() as i64
}

#[cfg(test)]
mod tests {
    use super::*;
    use prost::Message;

    /// The wire bytes of a spoke, written out by hand from the protobuf encoding rules
    /// (protobuf.dev, "Encoding": tag = field << 3 | wire type; varints 7 bits a byte, low
    /// first; int64 negative values as ten-byte two's complement varints).
    #[test]
    fn a_spoke_encodes_as_the_wire_format_says() {
        let m = RadarMessage {
            radar: 1,
            spokes: vec![Spoke {
                angle: 300,
                bearing: Some(0),
                range: 1500,
                time: Some(1),
                data: vec![0, 15],
                lat: Some(1),
                lon: Some(-1),
            }],
        };
        let mut spoke = vec![
            0x08, 0xAC, 0x02, // angle 300
            0x10, 0x00, // bearing 0 (optional: sent though zero)
            0x18, 0xDC, 0x0B, // range 1500
            0x20, 0x01, // time 1
            0x2A, 0x02, 0x00, 0x0F, // data
            0x30, 0x01, // lat 1
            0x38, // lon -1:
        ];
        spoke.extend([0xFF; 9]);
        spoke.push(0x01);
        let mut want = vec![0x08, 0x01, 0x12, spoke.len() as u8];
        want.extend(spoke);
        assert_eq!(m.encode_to_vec(), want);
        assert_eq!(RadarMessage::decode(&want[..]).unwrap(), m);
    }
}
