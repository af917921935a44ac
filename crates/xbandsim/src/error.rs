//! The library's one error type. Every variant names what was wrong (the field and its value,
//! or the file) and says what kind of problem it is ([`Problem`]), so that a caller can branch
//! on it; the CLI and the Python binding turn these into messages or exceptions.

use std::fmt;
use std::path::PathBuf;

/// What kind of problem a field has: lets a caller (a GUI, the Python binding, a dataset
/// generator sweeping parameters) react without parsing the message.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Problem {
    /// NaN or infinity where a finite number is needed.
    NotFinite,
    /// A number outside its allowed range (negative size, too many spokes, antenna below the
    /// sea...).
    OutOfRange,
    /// A name that is not one of the accepted choices.
    UnknownChoice,
    /// A value that is fine alone but contradicts another field (pulse longer than the PRI,
    /// two polarisations, a field the shape does not use, two objects with one name...).
    Conflict,
    /// A field that is needed is absent.
    Missing,
    /// A value that names something that could not be used (a mesh file that cannot be read).
    Unusable,
}

impl fmt::Display for Problem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Problem::NotFinite => "not finite",
            Problem::OutOfRange => "out of range",
            Problem::UnknownChoice => "unknown choice",
            Problem::Conflict => "conflict",
            Problem::Missing => "missing",
            Problem::Unusable => "unusable",
        })
    }
}

/// Where a field's value came from: a scene file (with the line and column of the value when
/// the field is written there; none when the value is a default) or a command-line override.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Location {
    /// The scene file, or `--set` for a command-line override.
    pub origin: String,
    /// 1-based line and column of the value in the file.
    pub line_column: Option<(usize, usize)>,
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line_column {
            Some((line, column)) => write!(f, "{}:{line}:{column}", self.origin),
            None => f.write_str(&self.origin),
        }
    }
}

/// `"{location}: "` or nothing.
struct At<'a>(&'a Option<Box<Location>>);

impl fmt::Display for At<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.0 {
            Some(l) => write!(f, "{l}: "),
            None => Ok(()),
        }
    }
}

/// Everything that can go wrong inside the xbandsim library.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The scene file is not valid TOML, or a value has the wrong type, a field is unknown or
    /// a choice is not one of the accepted names. `message` comes from the TOML parser and
    /// carries the line and column.
    #[error("{path}: {message}")]
    SceneSyntax { path: String, message: String },

    /// A field holds a value that is not allowed (negative size, NaN, a pulse longer than the
    /// PRI...).
    #[error("{at}invalid `{field}` = {value}: {reason}", at = At(location))]
    InvalidField {
        /// Dotted path of the field, e.g. `radar.pulse_width_us` or `object "buoy".radius_m`.
        field: String,
        /// The value as written.
        value: String,
        /// The kind of problem.
        problem: Problem,
        /// What is wrong and what to do, in words.
        reason: String,
        /// Where the value came from, when known.
        location: Option<Box<Location>>,
        /// The underlying error (a mesh file that could not be read).
        #[source]
        cause: Option<Box<Error>>,
    },

    /// A field that this object or radar needs is absent.
    #[error("{at}missing `{field}`: {reason}", at = At(location))]
    MissingField {
        /// Dotted path of the field.
        field: String,
        /// What needs it.
        reason: String,
        /// The scene file, when known.
        location: Option<Box<Location>>,
    },

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
    /// An [`Error::InvalidField`] of kind `problem`.
    pub fn invalid(
        problem: Problem,
        field: impl Into<String>,
        value: impl fmt::Display,
        reason: impl Into<String>,
    ) -> Self {
        Error::InvalidField {
            field: field.into(),
            value: value.to_string(),
            problem,
            reason: reason.into(),
            location: None,
            cause: None,
        }
    }

    /// An [`Error::InvalidField`] of kind [`Problem::Unusable`] caused by `cause`.
    pub fn unusable(
        field: impl Into<String>,
        value: impl fmt::Display,
        reason: impl Into<String>,
        cause: Error,
    ) -> Self {
        Error::InvalidField {
            field: field.into(),
            value: value.to_string(),
            problem: Problem::Unusable,
            reason: reason.into(),
            location: None,
            cause: Some(Box::new(cause)),
        }
    }

    /// Shorthand for [`Error::MissingField`].
    pub fn missing(field: impl Into<String>, reason: impl Into<String>) -> Self {
        Error::MissingField {
            field: field.into(),
            reason: reason.into(),
            location: None,
        }
    }

    /// Shorthand for [`Error::Io`].
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Io {
            path: path.into(),
            error: source,
        }
    }

    /// The kind of problem, for field errors ([`Problem::Missing`] for a missing field).
    pub fn problem(&self) -> Option<Problem> {
        match self {
            Error::InvalidField { problem, .. } => Some(*problem),
            Error::MissingField { .. } => Some(Problem::Missing),
            _ => None,
        }
    }

    /// The dotted path of the field at fault, for field errors.
    pub fn field(&self) -> Option<&str> {
        match self {
            Error::InvalidField { field, .. } | Error::MissingField { field, .. } => Some(field),
            _ => None,
        }
    }

    /// Where the field's value came from, for field errors that know it.
    pub fn location(&self) -> Option<&Location> {
        match self {
            Error::InvalidField { location, .. } | Error::MissingField { location, .. } => {
                location.as_deref()
            }
            _ => None,
        }
    }

    /// This error with its location set (field errors only; others are returned unchanged).
    pub fn at(mut self, at: Location) -> Self {
        match &mut self {
            Error::InvalidField { location, .. } | Error::MissingField { location, .. } => {
                *location = Some(Box::new(at));
            }
            _ => {}
        }
        self
    }

    /// The error without where its field was given: for scene text the user never wrote
    /// (a dataset sample's drawn scene), whose lines mean nothing to them.
    pub fn unlocated(mut self) -> Self {
        match &mut self {
            Error::InvalidField { location, .. } | Error::MissingField { location, .. } => {
                *location = None;
            }
            _ => {}
        }
        self
    }
}
