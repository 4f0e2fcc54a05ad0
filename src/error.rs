//! The one error type of the library: each variant renders as a single line that names the
//! file or option at fault and the reason, as the CLI prints it.

use std::path::PathBuf;

/// Everything that can go wrong in asperity.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A file could not be opened, read or written.
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// A file was read but its content is not what its format requires (truncated, corrupt,
    /// no topography in it, NaN heights, …).
    #[error("{}: {reason}", path.display())]
    File { path: PathBuf, reason: String },
    /// An option or parameter value that the physics or the grid cannot take.
    #[error("{option}: {reason}")]
    Invalid { option: String, reason: String },
    /// An iterative solver stopped at its iteration limit above its tolerance.
    #[error(
        "{solver} did not converge: residual {residual:.3e} above tolerance {tolerance:.1e} \
         after {iterations} iterations (raise --max-iter or loosen --tolerance)"
    )]
    NotConverged { solver: &'static str, iterations: usize, residual: f64, tolerance: f64 },
    /// Long work stopped early because its caller asked it to (a progress callback answered
    /// `ControlFlow::Break`, for instance on Ctrl-C).
    #[error("{what}: interrupted")]
    Interrupted { what: String },
}

impl Error {
    /// An I/O error on `path`.
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Io { path: path.into(), source }
    }

    /// A content error in the file at `path`.
    pub fn file(path: impl Into<PathBuf>, reason: impl Into<String>) -> Self {
        Error::File { path: path.into(), reason: reason.into() }
    }

    /// An invalid value for `option` (a CLI flag such as `--load`, or a config key).
    pub fn invalid(option: impl Into<String>, reason: impl Into<String>) -> Self {
        Error::Invalid { option: option.into(), reason: reason.into() }
    }
}

/// Result with the library's [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;
