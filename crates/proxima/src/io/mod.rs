//! Mesh loading: OBJ, STL (binary and ASCII) and PLY (ASCII and binary) into a
//! [`TriMesh`] ([`load`], [`parse`]), or straight into a [`Mesh`] with its trees
//! ([`Mesh::load`]).
//!
//! Every loader reads the whole file into memory once and never trusts a count
//! in it: storage grows only with data actually read, so a lying header costs at
//! most the file's size. Malformed input gives [`Error::Parse`] naming the file
//! and the line (text) or byte offset (binary); nothing panics. Polygons are
//! fan-triangulated; degenerate triangles are kept (the narrow phase handles them).

mod bytes;
mod obj;
mod ply;
mod stl;
mod text;

pub use obj::parse_obj;
pub use ply::parse_ply;
pub use stl::parse_stl;

use crate::narrow::{BoundingVolume, BuildOptions, Mesh, TriMesh};
use crate::{Error, FileLocation, Result};
use glam::Vec3;
use std::path::Path;

/// A mesh file format understood by [`load`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// Wavefront OBJ (also with the `<nverts> <ntris>` header line of FCL's files).
    Obj,
    /// STL, binary or ASCII (told apart by content).
    Stl,
    /// Stanford PLY, ASCII or binary of either byte order.
    Ply,
}

impl Format {
    /// The format named by a file extension (case-insensitive), if any.
    pub fn from_extension(path: &Path) -> Option<Format> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "obj" => Some(Format::Obj),
            "stl" => Some(Format::Stl),
            "ply" => Some(Format::Ply),
            _ => None,
        }
    }

    /// Guesses the format from the content: PLY's magic line, STL's `solid`
    /// keyword or binary size rule (84 + 50 n bytes), else OBJ's `v`/`f` lines.
    pub fn sniff(data: &[u8]) -> Option<Format> {
        if data.starts_with(b"ply\n") || data.starts_with(b"ply\r\n") {
            return Some(Format::Ply);
        }
        if stl::is_binary(data) || data.trim_ascii_start().starts_with(b"solid") {
            return Some(Format::Stl);
        }
        let text = String::from_utf8_lossy(&data[..data.len().min(4096)]);
        let obj_like = text
            .lines()
            .any(|l| l.starts_with("v ") || l.starts_with("f ") || l.starts_with("v\t"));
        obj_like.then_some(Format::Obj)
    }
}

/// Loads a triangle mesh, choosing the format by extension (`.obj`, `.stl`,
/// `.ply`, any case) or else by content ([`Format::sniff`]). Cost: one read of
/// the file and time linear in its size (plus a hash map for STL welding).
pub fn load(path: impl AsRef<Path>) -> Result<TriMesh> {
    let path = path.as_ref();
    let name = path.display().to_string();
    let data = std::fs::read(path).map_err(|e| Error::Io {
        file: name.clone(),
        source: e.into(),
    })?;
    let format = Format::from_extension(path)
        .or_else(|| Format::sniff(&data))
        .ok_or_else(|| Error::UnknownFormat { file: name.clone() })?;
    parse(&name, &data, format)
}

// Here, not in `narrow`: the narrow phase does not depend on the loaders.
impl<BV: BoundingVolume> Mesh<BV> {
    /// Loads a mesh file ([`load`]: OBJ, STL or PLY, by extension or content) and
    /// builds its collision tree with [`BuildOptions::default`]
    /// ([`Mesh::from_trimesh`]). Fails with the loader's error, which names the
    /// file ([`Error::Io`], [`Error::UnknownFormat`], [`Error::Parse`]).
    pub fn load(path: impl AsRef<Path>) -> Result<Mesh<BV>> {
        Mesh::from_trimesh(load(path)?, BuildOptions::default())
    }
}

/// Parses in-memory file content of a known format; `name` is used in errors.
pub fn parse(name: &str, data: &[u8], format: Format) -> Result<TriMesh> {
    match format {
        Format::Obj => parse_obj(name, data),
        Format::Stl => parse_stl(name, data),
        Format::Ply => parse_ply(name, data),
    }
}

/// Builds errors that name the file.
#[derive(Clone, Copy)]
pub(crate) struct Ctx<'a> {
    pub file: &'a str,
}

impl Ctx<'_> {
    pub fn at(&self, at: FileLocation, msg: impl Into<String>) -> Error {
        Error::Parse {
            file: self.file.to_string(),
            at,
            msg: msg.into(),
        }
    }

    pub fn line(&self, line: usize, msg: impl Into<String>) -> Error {
        self.at(FileLocation::Line(line), msg)
    }

    pub fn offset(&self, offset: usize, msg: impl Into<String>) -> Error {
        self.at(FileLocation::Offset(offset as u64), msg)
    }

    /// Final validation; every index was already range-checked by the loader,
    /// so only "no triangles" can fail here, reported at `end`.
    pub fn finish(
        &self,
        vertices: Vec<Vec3>,
        triangles: Vec<[u32; 3]>,
        end: FileLocation,
    ) -> Result<TriMesh> {
        if triangles.is_empty() {
            return Err(self.at(end, "the file contains no triangles"));
        }
        TriMesh::new(vertices, triangles).map_err(|e| self.at(end, e.to_string()))
    }
}

/// A finite `f32` or an error message for it.
pub(crate) fn finite(x: f32, what: &str) -> std::result::Result<f32, String> {
    if x.is_finite() {
        Ok(x)
    } else {
        Err(format!("{what} is not finite ({x})"))
    }
}
