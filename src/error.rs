//! The crate-wide error type. Every fallible operation returns [`Result`].
//!
//! Each variant maps to one stable C status code (see `crate::ffi::Status`).

use std::path::Path;

/// Everything that can go wrong in abgs.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// An argument is malformed (wrong length, inconsistent counts, bad option).
    #[error("invalid argument: {0}")]
    InvalidArgument(String),
    /// An index (vertex, triangle, edge) is outside its valid range.
    #[error("index out of range: {0}")]
    OutOfRange(String),
    /// A coordinate or parameter is NaN or infinite (or, for a grid vertex or a
    /// query point, beyond [`crate::geometry::MAX_COORDINATE`]).
    #[error("non-finite value: {0}")]
    NonFinite(String),
    /// A size value is not a finite number > 0.
    #[error("invalid size: {0}")]
    InvalidSize(String),
    /// The file could not be opened, read or written.
    #[error("cannot access '{path}': {source}")]
    Io {
        /// The file concerned.
        path: String,
        /// The operating-system error.
        #[source]
        source: std::io::Error,
    },
    /// The file was read but its content is malformed.
    #[error("cannot parse '{path}': {msg}")]
    Parse {
        /// The file concerned.
        path: String,
        /// What is wrong, with a line or record number where known.
        msg: String,
    },
    /// The file extension names no supported format.
    #[error("unsupported format: {0}")]
    UnsupportedFormat(String),
    /// The grid has no triangles left (after dropping degenerate ones).
    #[error("empty grid: {0}")]
    Empty(String),
    /// A learned model (GCN-ABGS, `abgs::gcn`) is missing, corrupt, has the wrong
    /// interface or gave unusable output, or its runtime failed. In C:
    /// `ABGS_ERR_INVALID_ARGUMENT`, with a message that starts with "model:".
    #[error("model: {0}")]
    Model(String),
    /// A size query was made on a grid that carries no sizes.
    #[error("the grid has no sizes: set or compute them first")]
    NoSizes,
}

impl Error {
    /// Builds an [`Error::Io`] for `path`.
    pub fn io(path: &Path, source: std::io::Error) -> Self {
        Error::Io {
            path: path.display().to_string(),
            source,
        }
    }

    /// Builds an [`Error::Parse`] for `path`.
    pub fn parse(path: &Path, msg: impl Into<String>) -> Self {
        Error::Parse {
            path: path.display().to_string(),
            msg: msg.into(),
        }
    }
}

/// Checks a parameter: `x` finite and within `[lo, hi]`, else
/// [`Error::InvalidArgument`] naming it (`what = x must be in [lo, hi]`).
pub(crate) fn check_range(x: f64, lo: f64, hi: f64, what: &str) -> Result<()> {
    if x.is_finite() && x >= lo && x <= hi {
        Ok(())
    } else {
        Err(Error::InvalidArgument(format!(
            "{what} = {x:?} must be in [{lo:?}, {hi:?}]"
        )))
    }
}

/// Shorthand for `std::result::Result<T, abgs::Error>`.
pub type Result<T> = std::result::Result<T, Error>;
