//! The one error type veach reports: a line naming the file, flag or limit at fault.

use std::fmt;

/// Every error veach reports to a user: one line, naming the file or limit at fault.
#[derive(Debug)]
#[non_exhaustive]
pub enum Error {
    /// Bad input: a file, a flag, a setting.
    Input(String),
    /// No usable GPU adapter.
    NoAdapter(String),
    /// A device or veach limit would be exceeded.
    Limit(String),
    /// The GPU reported an error.
    Gpu(String),
    /// Reading or writing a file failed.
    Io { path: std::path::PathBuf, what: &'static str, source: std::io::Error },
}

impl Error {
    pub(crate) fn io(path: &std::path::Path, what: &'static str, source: std::io::Error) -> Error {
        Error::Io { path: path.to_path_buf(), what, source }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Input(m) | Error::NoAdapter(m) | Error::Limit(m) => write!(f, "{m}"),
            Error::Gpu(m) => write!(f, "GPU error: {m}"),
            Error::Io { path, what, source } => write!(f, "{}: {what}: {source}", path.display()),
        }
    }
}

impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Error::Io { source, .. } => Some(source),
            _ => None,
        }
    }
}
