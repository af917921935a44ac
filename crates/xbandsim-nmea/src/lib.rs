//! # xbandsim-nmea
//!
//! What a ship's navigation network carries, encoded from a scenario's truth
//! (docs/live.md): NMEA 0183 sentences of the own ship's GPS and compass, and of a radar's
//! tracked targets ([`sentence`]), and AIS messages of other ships as an AIS receiver
//! passes them on (`!AIVDM`, ITU-R M.1371; [`ais`]). Every sentence carries its checksum.
//! The crate encodes; it does not read, and knows nothing of scenes: callers give it
//! positions, velocities and times.

pub mod ais;
pub mod error;
pub mod sentence;

pub use error::{NmeaError, Result};
