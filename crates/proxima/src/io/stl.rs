//! STL, binary and ASCII. Vertices are welded: corners with bit-identical
//! coordinates (after mapping `-0.0` to `0.0`) become one vertex, so a closed
//! STL surface loads as a shared-vertex mesh; no tolerance is applied, so the
//! geometry is exactly the file's.

use super::bytes::Bytes;
use super::{finite, Ctx};
use crate::narrow::TriMesh;
use crate::{FileLocation, Result};
use glam::Vec3;
use std::collections::HashMap;

const HEADER: usize = 80;
const RECORD: u64 = 50;

/// Whether `data` has the exact size of a binary STL: 84 + 50 n bytes, with n
/// the count at offset 80. Files that begin with `solid` can be binary too; the
/// size rule is what tells them apart.
pub(crate) fn is_binary(data: &[u8]) -> bool {
    let Some(n) = data.get(HEADER..HEADER + 4) else {
        return false;
    };
    let n = u32::from_le_bytes([n[0], n[1], n[2], n[3]]) as u64;
    data.len() as u64 == 84 + RECORD * n
}

fn looks_ascii(data: &[u8]) -> bool {
    let head = &data[..data.len().min(1024)];
    data.trim_ascii_start().starts_with(b"solid")
        && (head.windows(5).any(|w| w == b"facet") || head.windows(8).any(|w| w == b"endsolid"))
}

/// Parses an STL file, binary or ASCII (binary iff the size is 84 + 50 n with n
/// the count at offset 80, even if it begins with `solid`; else the ASCII
/// keywords). `name` is used in errors. Cost: linear in the file size, plus a
/// hash map for welding.
pub fn parse_stl(name: &str, data: &[u8]) -> Result<TriMesh> {
    let ctx = Ctx { file: name };
    if is_binary(data) {
        parse_binary(ctx, data)
    } else if looks_ascii(data) {
        parse_ascii(ctx, data)
    } else if data.len() < 84 {
        Err(ctx.offset(
            data.len(),
            "file too short for a binary STL (84-byte header) and not ASCII STL",
        ))
    } else {
        let n = u32::from_le_bytes([data[80], data[81], data[82], data[83]]) as u64;
        Err(ctx.offset(
            HEADER,
            format!(
                "binary STL declares {n} triangles, i.e. {} bytes, but the file has {}",
                84 + RECORD * n,
                data.len()
            ),
        ))
    }
}

/// Merges bit-identical vertices.
#[derive(Default)]
struct Welder {
    vertices: Vec<Vec3>,
    index: HashMap<[u32; 3], u32>,
}

impl Welder {
    fn add(&mut self, p: Vec3) -> u32 {
        let key = (p + Vec3::ZERO).to_array().map(f32::to_bits); // -0.0 + 0.0 = 0.0
        *self.index.entry(key).or_insert_with(|| {
            self.vertices.push(p + Vec3::ZERO);
            (self.vertices.len() - 1) as u32
        })
    }
}

fn parse_binary(ctx: Ctx, data: &[u8]) -> Result<TriMesh> {
    let n = (data.len() as u64 - 84) / RECORD; // checked by is_binary
    let mut r = Bytes::new(data, 84, false);
    let mut weld = Welder::default();
    let mut triangles = Vec::with_capacity(n as usize);
    for _ in 0..n {
        r.pos += 12; // the facet normal is not used
        let mut tri = [0u32; 3];
        for corner in &mut tri {
            let mut c = [0.0f32; 3];
            for k in &mut c {
                let at = r.pos;
                let x = r
                    .f32()
                    .ok_or_else(|| ctx.offset(at, "unexpected end of file"))?;
                *k = finite(x, "vertex coordinate").map_err(|m| ctx.offset(at, m))?;
            }
            *corner = weld.add(Vec3::from_array(c));
        }
        r.pos += 2; // attribute byte count
        triangles.push(tri);
    }
    ctx.finish(
        weld.vertices,
        triangles,
        FileLocation::Offset(data.len() as u64),
    )
}

#[derive(PartialEq, Clone, Copy)]
enum State {
    Outside,
    Solid,
    Facet,
    Loop,
    EndLoop,
}

fn parse_ascii(ctx: Ctx, data: &[u8]) -> Result<TriMesh> {
    let text = String::from_utf8_lossy(data);
    let mut weld = Welder::default();
    let mut triangles = Vec::new();
    let mut corners: Vec<u32> = Vec::new();
    let mut state = State::Outside;
    let mut last_line = 1;
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        last_line = line;
        let mut t = raw.split_ascii_whitespace();
        let Some(keyword) = t.next() else { continue };
        let expected = match (state, keyword) {
            (State::Outside, "solid") => State::Solid,
            (State::Solid, "facet") => State::Facet,
            (State::Solid, "endsolid") => State::Outside,
            (State::Facet, "outer") => {
                corners.clear();
                State::Loop
            }
            (State::Loop, "vertex") => {
                let mut c = [0.0f32; 3];
                for k in &mut c {
                    let tok = t
                        .next()
                        .ok_or_else(|| ctx.line(line, "vertex needs 3 coordinates"))?;
                    let x: f32 = tok
                        .parse()
                        .map_err(|_| ctx.line(line, format!("bad coordinate '{tok}'")))?;
                    *k = finite(x, "vertex coordinate").map_err(|m| ctx.line(line, m))?;
                }
                corners.push(weld.add(Vec3::from_array(c)));
                State::Loop
            }
            (State::Loop, "endloop") => {
                if corners.len() < 3 {
                    return Err(ctx.line(
                        line,
                        format!("loop has {} vertices, needs 3", corners.len()),
                    ));
                }
                for w in 1..corners.len() - 1 {
                    triangles.push([corners[0], corners[w], corners[w + 1]]);
                }
                State::EndLoop
            }
            (State::EndLoop, "endfacet") => State::Solid,
            (s, k) => {
                let want = match s {
                    State::Outside => "'solid'",
                    State::Solid => "'facet' or 'endsolid'",
                    State::Facet => "'outer loop'",
                    State::Loop => "'vertex' or 'endloop'",
                    State::EndLoop => "'endfacet'",
                };
                return Err(ctx.line(line, format!("expected {want}, found '{k}'")));
            }
        };
        state = expected;
    }
    if state != State::Outside {
        return Err(ctx.line(last_line, "unexpected end of file (missing 'endsolid')"));
    }
    ctx.finish(weld.vertices, triangles, FileLocation::Line(last_line))
}
