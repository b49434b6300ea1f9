//! The crate's one error type, [`Error`], and the pieces it carries: where in a
//! file a parse failed ([`FileLocation`]) and a shareable I/O error ([`IoError`]).

use std::fmt;
use std::sync::Arc;

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
    /// A parameter is out of its documented range (for example a density outside
    /// `(0, 1]`, or a BVH leaf size of 0). Nothing was built or changed.
    InvalidParameter(String),
    /// A structure's invariant does not hold (from `validate()`): a bug or a
    /// corrupted structure, never a bad argument.
    Invalid(String),
    /// A triangle mesh failed validation (no triangles, index out of range,
    /// non-finite vertex).
    InvalidMesh(String),
    /// A tree was given a mesh that it was not built over, or whose vertices
    /// changed since it was built or refit (a [`Bvh`](crate::narrow::Bvh) reads
    /// the vertices of the mesh it is given). Nothing was computed or changed.
    MeshMismatch(String),
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
    /// A mesh file could not be read: the operating system's error, kept as this
    /// error's [`source`](std::error::Error::source).
    Io {
        /// The file's path as given.
        file: String,
        /// What failed.
        source: IoError,
    },
    /// A mesh file whose format is told neither by its extension nor by its
    /// content (see [`io::Format`](crate::io::Format)).
    UnknownFormat {
        /// The file's path as given.
        file: String,
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

/// A [`std::io::Error`] that can be cloned and compared, as [`Error`] must be: the
/// error is shared (an `Arc`), and two are equal when their
/// [`kind`](std::io::Error::kind) and message are.
#[derive(Clone, Debug)]
pub struct IoError(Arc<std::io::Error>);

impl IoError {
    /// The error's kind (for example [`NotFound`](std::io::ErrorKind::NotFound)).
    pub fn kind(&self) -> std::io::ErrorKind {
        self.0.kind()
    }

    /// The operating system's error itself.
    pub fn get_ref(&self) -> &std::io::Error {
        &self.0
    }
}

impl From<std::io::Error> for IoError {
    fn from(e: std::io::Error) -> Self {
        IoError(Arc::new(e))
    }
}

impl PartialEq for IoError {
    fn eq(&self, other: &Self) -> bool {
        self.kind() == other.kind() && self.0.to_string() == other.0.to_string()
    }
}

impl fmt::Display for IoError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.0.fmt(f)
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
            Error::MeshMismatch(msg) => write!(f, "mesh mismatch: {msg}"),
            Error::InvalidPose(msg) => write!(f, "invalid pose: {msg}"),
            Error::IndexOutOfRange { what, index, len } => {
                write!(f, "{what} index {index} out of range (there are {len})")
            }
            Error::CapacityExceeded { what, limit } => {
                write!(f, "capacity exceeded: all {limit} {what} are in use")
            }
            Error::Io { file, source } => write!(f, "{file}: {source}"),
            Error::UnknownFormat { file } => write!(
                f,
                "{file}: unknown mesh format (expected .obj, .stl or .ply)"
            ),
            Error::Parse { file, at, msg } => write!(f, "{file}: {at}: {msg}"),
        }
    }
}

impl std::error::Error for Error {
    /// For [`Error::Io`], the operating system's error; `None` otherwise (every
    /// other variant is the first cause).
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Error::Io { source, .. } => Some(source.get_ref()),
            _ => None,
        }
    }
}

/// Checks that every component of `v` is finite.
pub(crate) fn check_vec3(v: glam::Vec3, what: &'static str) -> Result<()> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(Error::NonFinite { what })
    }
}

/// Checks that a radius is finite (`what` names it) and not negative.
pub(crate) fn check_radius(radius: f32, what: &'static str) -> Result<()> {
    if !radius.is_finite() {
        return Err(Error::NonFinite { what });
    }
    if radius < 0.0 {
        return Err(Error::NegativeRadius { radius });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::error::Error as _;
    use std::io;

    #[test]
    fn io_errors_keep_their_source_and_compare_by_kind_and_message() {
        let e = Error::Io {
            file: "a.obj".into(),
            source: io::Error::new(io::ErrorKind::NotFound, "no such file").into(),
        };
        assert_eq!(e.to_string(), "a.obj: no such file");
        let src = e.source().expect("an I/O error has a source");
        let io = src
            .downcast_ref::<io::Error>()
            .expect("the io::Error itself");
        assert_eq!(io.kind(), io::ErrorKind::NotFound);
        // Clone and compare: equal to itself and to a copy, not to another kind.
        assert_eq!(e.clone(), e);
        let other = Error::Io {
            file: "a.obj".into(),
            source: io::Error::new(io::ErrorKind::PermissionDenied, "no such file").into(),
        };
        assert_ne!(e, other);
        assert!(Error::UnknownFormat { file: "x".into() }.source().is_none());
        assert!(Error::Invalid("x".into()).source().is_none());
    }

    #[test]
    fn unknown_format_names_the_file_in_one_line() {
        let e = Error::UnknownFormat {
            file: "mesh.xyz".into(),
        };
        assert_eq!(
            e.to_string(),
            "mesh.xyz: unknown mesh format (expected .obj, .stl or .ply)"
        );
    }
}
