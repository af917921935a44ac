//! The library's one error type. Every variant names what was wrong (the field and its value,
//! or the file); the CLI and the Python binding turn these into messages or exceptions.

use std::path::PathBuf;

/// Everything that can go wrong inside the xbandsim library.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The scene file is not valid TOML, or a value has the wrong type, or a field is unknown.
    /// `message` comes from the TOML parser and carries the line and column.
    #[error("{path}: {message}")]
    SceneSyntax { path: String, message: String },

    /// A field holds a value that is not allowed (negative size, NaN, unknown shape...).
    #[error("invalid `{field}` = {value}: {reason}")]
    InvalidField {
        field: String,
        value: String,
        reason: String,
    },

    /// A field that this object or radar needs is absent.
    #[error("missing `{field}`: {reason}")]
    MissingField { field: String, reason: String },

    /// Reading or writing a file failed. The OS error is part of the message (and not
    /// chained as a source as well, so it is printed once).
    #[error("{path}: {error}")]
    Io {
        path: PathBuf,
        error: std::io::Error,
    },

    /// A mesh file could not be read or is not a usable triangle mesh.
    #[error("mesh {path}: {message}")]
    Mesh { path: PathBuf, message: String },

    /// Encoding an output file (PNG, JSON) failed.
    #[error("encoding {path}: {message}")]
    Encode { path: PathBuf, message: String },
}

/// Result with the library's [`Error`].
pub type Result<T> = std::result::Result<T, Error>;

impl Error {
    /// Shorthand for [`Error::InvalidField`].
    pub fn invalid(
        field: impl Into<String>,
        value: impl std::fmt::Display,
        reason: impl Into<String>,
    ) -> Self {
        Error::InvalidField {
            field: field.into(),
            value: value.to_string(),
            reason: reason.into(),
        }
    }

    /// Shorthand for [`Error::MissingField`].
    pub fn missing(field: impl Into<String>, reason: impl Into<String>) -> Self {
        Error::MissingField {
            field: field.into(),
            reason: reason.into(),
        }
    }

    /// Shorthand for [`Error::Io`].
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Io {
            path: path.into(),
            error: source,
        }
    }
}
