//! Typed errors of the dataset generator; the CLI alone turns them into messages.

use std::path::PathBuf;

/// What can go wrong making a dataset.
#[derive(Debug, thiserror::Error)]
pub enum DatasetError {
    /// The dataset spec is not valid: `field` names the offending entry.
    #[error("dataset spec: {field}: {message}")]
    Spec { field: String, message: String },
    /// An argument of the run (not of the spec) is not valid: `name` is the CLI option
    /// (`--shard`, `--jobs`).
    #[error("{name}: {message}")]
    Argument { name: String, message: String },
    /// A sample's scene was refused by the scene loader (the spec drew an invalid scene).
    /// The loader's error is part of the message (and not chained as a source as well, so
    /// it is printed once).
    #[error("sample {index}: {error}")]
    Scene { index: u64, error: xbandsim::Error },
    /// Reading or writing a file failed. The OS error is part of the message (and not
    /// chained as a source as well, so it is printed once).
    #[error("{}: {error}", path.display())]
    Io {
        path: PathBuf,
        error: std::io::Error,
    },
    /// The output directory holds a different dataset.
    #[error("{}: {message}", path.display())]
    Mismatch { path: PathBuf, message: String },
    /// The run was asked to stop (Ctrl-C in Python) before its samples were all made: the
    /// samples already written are whole and a later run resumes from them.
    #[error(
        "stopped after {made} new samples: the dataset is resumable (run the same command again)"
    )]
    Interrupted { made: u64 },
}

impl DatasetError {
    /// A spec error at `field`.
    pub fn spec(field: impl Into<String>, message: String) -> DatasetError {
        DatasetError::Spec {
            field: field.into(),
            message,
        }
    }

    /// An error in the run's argument `name`.
    pub fn argument(name: impl Into<String>, message: String) -> DatasetError {
        DatasetError::Argument {
            name: name.into(),
            message,
        }
    }

    /// An I/O error on `path`.
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> DatasetError {
        DatasetError::Io {
            path: path.into(),
            error: source,
        }
    }
}

/// `r`, its error located at `path`.
pub(crate) fn at<T>(path: &std::path::Path, r: std::io::Result<T>) -> Result<T> {
    r.map_err(|e| DatasetError::io(path, e))
}

/// A file at `path` whose contents are not what they should be.
pub(crate) fn invalid_data(path: &std::path::Path, message: impl Into<String>) -> DatasetError {
    DatasetError::io(
        path,
        std::io::Error::new(std::io::ErrorKind::InvalidData, message.into()),
    )
}

/// Results of the dataset generator.
pub type Result<T> = std::result::Result<T, DatasetError>;
