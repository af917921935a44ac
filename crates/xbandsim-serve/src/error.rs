//! Typed errors of the live radar; the CLI alone turns them into messages.

use std::path::PathBuf;

/// What stops the live radar or one of its requests.
#[derive(Debug, thiserror::Error)]
pub enum ServeError {
    /// The scene has no `[geo]` origin, so its positions have no latitude and longitude.
    #[error(
        "the scene has no [geo] origin with origin_lon_deg and origin_lat_deg, so its positions have no latitude and longitude: add one (docs/formats.md, \"[[land]] and [geo]\"), e.g. --set geo.origin_lat_deg=50.36 --set geo.origin_lon_deg=-4.14"
    )]
    NoGeoOrigin,
    /// An NMEA or AIS field the encoders cannot carry.
    #[error(transparent)]
    Nmea(#[from] xbandsim_nmea::NmeaError),
    /// The simulator refused the scene or a render.
    #[error(transparent)]
    Sim(#[from] xbandsim::Error),
    /// A setting of the server itself is out of range.
    #[error("invalid {field} {value}: {why}")]
    Setting {
        /// The option or control.
        field: String,
        /// Its value, as given.
        value: String,
        /// What it must be.
        why: String,
    },
    /// An address could not be bound or reached.
    #[error("{what} {addr}: {source}")]
    Network {
        /// What the address is for (`--listen`, `--nmea-udp`, ...).
        what: String,
        /// The address.
        addr: String,
        /// Why.
        source: std::io::Error,
    },
    /// A recording could not be written or read.
    #[error("{}: {message}", path.display())]
    Recording {
        /// The recording file.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
}

impl ServeError {
    /// A setting `field` with `value` that must be `why`.
    pub fn setting(field: &str, value: impl ToString, why: &str) -> ServeError {
        ServeError::Setting {
            field: field.to_string(),
            value: value.to_string(),
            why: why.to_string(),
        }
    }
}

/// Results of the live radar.
pub type Result<T> = std::result::Result<T, ServeError>;
