//! Typed errors of the encoders; the CLI alone turns them into messages.

/// A value an encoder cannot carry.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum NmeaError {
    /// `field` holds a value its message cannot encode.
    #[error("{field}: {message}")]
    Field {
        /// The field, as the message names it (`mmsi`, `name`, `lat_deg`, ...).
        field: &'static str,
        /// What is wrong with its value.
        message: String,
    },
}

impl NmeaError {
    /// An error in `field`.
    pub fn field(field: &'static str, message: impl Into<String>) -> NmeaError {
        NmeaError::Field {
            field,
            message: message.into(),
        }
    }
}

/// Results of the encoders.
pub type Result<T> = std::result::Result<T, NmeaError>;
