//! `proxima::Error` as Python exceptions: the Rust message, in the exception a
//! Python user expects for that kind of failure.

use proxima::Error;
use pyo3::exceptions::{
    PyFileNotFoundError, PyIsADirectoryError, PyKeyError, PyOSError, PyOverflowError,
    PyPermissionError, PyRuntimeError, PyValueError,
};
use pyo3::{PyErr, PyResult};
use std::io::ErrorKind;

/// The exception for a library error, with `msg` as its message:
///
/// - a file the system could not read: `FileNotFoundError`, `PermissionError`,
///   `IsADirectoryError` or `OSError`, with `errno` and `filename` set;
/// - a stale handle: `KeyError` (the bindings name objects by id and check ids
///   themselves, so this is only a fallback);
/// - a full index (2^32 - 1 live objects): `OverflowError`;
/// - a broken invariant (a bug, never bad input): `RuntimeError`;
/// - everything else — non-finite numbers, negative radii, non-rigid poses,
///   malformed or unknown mesh files, bad parameters: `ValueError`.
fn raise(e: &Error, msg: String) -> PyErr {
    match e {
        Error::Io { file, source } => {
            let args = (
                source.get_ref().raw_os_error().unwrap_or(0),
                msg,
                file.clone(),
            );
            match source.kind() {
                ErrorKind::NotFound => PyFileNotFoundError::new_err(args),
                ErrorKind::PermissionDenied => PyPermissionError::new_err(args),
                ErrorKind::IsADirectory => PyIsADirectoryError::new_err(args),
                _ => PyOSError::new_err(args),
            }
        }
        Error::StaleHandle => PyKeyError::new_err(msg),
        Error::CapacityExceeded { .. } => PyOverflowError::new_err(msg),
        Error::Invalid(_) => PyRuntimeError::new_err(msg),
        _ => PyValueError::new_err(msg),
    }
}

/// The exception for a library error with the error's own message (for an I/O
/// error, the operating system's message: the path is the exception's
/// `filename`). Which exception for which error: see `raise` in this file.
pub fn to_py(e: Error) -> PyErr {
    let msg = match &e {
        Error::Io { source, .. } => source.to_string(),
        _ => e.to_string(),
    };
    raise(&e, msg)
}

/// `proxima::Result` to `PyResult`.
pub trait OrRaise<T> {
    /// The value, or the error as its Python exception ([`to_py`]).
    fn or_raise(self) -> PyResult<T>;
    /// The value, or the error as its Python exception with `context: ` before
    /// its message (for example the row of a batch that failed).
    fn or_raise_at(self, context: impl FnOnce() -> String) -> PyResult<T>;
}

impl<T> OrRaise<T> for proxima::Result<T> {
    fn or_raise(self) -> PyResult<T> {
        self.map_err(to_py)
    }

    fn or_raise_at(self, context: impl FnOnce() -> String) -> PyResult<T> {
        self.map_err(|e| raise(&e, format!("{}: {e}", context())))
    }
}
