//! The crate's one error type.

use std::fmt;

/// Everything that can go wrong in a Proxima call. A call that returns an error
/// leaves the structure it was called on exactly as it was.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum Error {
    /// A coordinate, radius or matrix entry was NaN or infinite.
    NonFinite {
        /// Which input was not finite (for example `"sphere centre"`).
        what: &'static str,
    },
    /// A radius was negative.
    NegativeRadius {
        /// The offending radius.
        radius: f32,
    },
    /// An AABB whose `min` exceeds its `max` on some axis.
    InvertedAabb,
    /// A ray or segment direction of zero length.
    ZeroDirection,
    /// A ray's `max_t` was negative or NaN.
    InvalidRayLength,
    /// A handle that was removed, belongs to another index, or predates `clear()`.
    StaleHandle,
    /// A constructor parameter is out of its documented range (for example a
    /// density outside `(0, 1]`).
    InvalidParameter(String),
    /// A structure's invariant does not hold (from `validate()`).
    Invalid(String),
    /// A triangle mesh failed validation (no triangles, index out of range,
    /// non-finite vertex).
    InvalidMesh(String),
    /// A pose that is not a rigid motion: non-finite, or a matrix that is not a
    /// rotation (orthonormal with determinant +1, within a small tolerance).
    InvalidPose(String),
    /// An index into a collection was out of range (for example a triangle index
    /// of a [`TriMesh`](crate::narrow::TriMesh)).
    IndexOutOfRange {
        /// What was indexed (for example `"triangle"`).
        what: &'static str,
        /// The index given.
        index: usize,
        /// The number of elements.
        len: usize,
    },
    /// A structure is full: every handle slot (2^32 - 1 per index) is in use. The
    /// insert that failed changed nothing.
    CapacityExceeded {
        /// What is full (for example `"object slots"`).
        what: &'static str,
        /// The limit that was reached.
        limit: usize,
    },
    /// A mesh file could not be read (I/O failure, unknown format).
    Io {
        /// The file's path as given.
        file: String,
        /// What failed.
        msg: String,
    },
    /// A mesh file is malformed: truncated, garbage, an index out of range, a
    /// non-finite coordinate, a count that does not match the data…
    Parse {
        /// The file's path as given (or a caller-chosen name for in-memory data).
        file: String,
        /// Where: a line (text formats) or a byte offset (binary formats).
        at: FileLocation,
        /// What is wrong.
        msg: String,
    },
}

/// Where in a file a [`Error::Parse`] was found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FileLocation {
    /// A 1-based line number of a text file.
    Line(usize),
    /// A 0-based byte offset into a binary file (or binary section).
    Offset(u64),
}

impl fmt::Display for FileLocation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            FileLocation::Line(n) => write!(f, "line {n}"),
            FileLocation::Offset(o) => write!(f, "byte offset {o}"),
        }
    }
}

/// `Result` with [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::NonFinite { what } => write!(f, "{what} is not finite"),
            Error::NegativeRadius { radius } => write!(f, "negative radius {radius}"),
            Error::InvertedAabb => write!(f, "AABB min exceeds max"),
            Error::ZeroDirection => write!(f, "direction has zero length"),
            Error::InvalidRayLength => write!(f, "ray max_t is negative or NaN"),
            Error::StaleHandle => {
                write!(f, "stale handle: removed, cleared, or from another index")
            }
            Error::InvalidParameter(msg) => write!(f, "invalid parameter: {msg}"),
            Error::Invalid(msg) => write!(f, "invariant violated: {msg}"),
            Error::InvalidMesh(msg) => write!(f, "invalid mesh: {msg}"),
            Error::InvalidPose(msg) => write!(f, "invalid pose: {msg}"),
            Error::IndexOutOfRange { what, index, len } => {
                write!(f, "{what} index {index} out of range (there are {len})")
            }
            Error::CapacityExceeded { what, limit } => {
                write!(f, "capacity exceeded: all {limit} {what} are in use")
            }
            Error::Io { file, msg } => write!(f, "{file}: {msg}"),
            Error::Parse { file, at, msg } => write!(f, "{file}: {at}: {msg}"),
        }
    }
}

impl std::error::Error for Error {}

/// Checks that every component of `v` is finite.
pub(crate) fn check_vec3(v: glam::Vec3, what: &'static str) -> Result<()> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(Error::NonFinite { what })
    }
}
