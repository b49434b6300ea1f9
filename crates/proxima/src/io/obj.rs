//! Wavefront OBJ: `v` and `f` statements; everything else (`vt`, `vn`, groups,
//! materials, lines, `#` comments) is skipped.

use super::{finite, Ctx};
use crate::narrow::TriMesh;
use crate::{FileLocation, Result};
use glam::Vec3;

/// Parses OBJ text. `name` is used in errors.
///
/// - `v x y z [w …]`: a vertex (extra values such as `w` or colours are ignored);
///   coordinates must be finite `f32`.
/// - `f i j k …`: a polygon, fan-triangulated as `(i, j, k), (i, k, l), …`. Each
///   corner may be `v`, `v/vt`, `v//vn` or `v/vt/vn`; only `v` is used. Positive
///   indices are 1-based, negative ones relative (`-1` = the latest vertex); both
///   must refer to a vertex already defined, as the OBJ specification requires.
/// - A first statement line of exactly two unsigned integers is the
///   `<nverts> <ntris>` header of FCL's test meshes (`env.obj`, `rob.obj`); the
///   file must then hold exactly that many vertices and triangles.
///
/// Cost: linear in the file size; memory proportional to what is read.
pub fn parse_obj(name: &str, data: &[u8]) -> Result<TriMesh> {
    let ctx = Ctx { file: name };
    let text = String::from_utf8_lossy(data);
    let mut vertices: Vec<Vec3> = Vec::new();
    let mut triangles: Vec<[u32; 3]> = Vec::new();
    let mut header: Option<(usize, [u64; 2])> = None;
    let mut first_statement = true;
    let mut last_line = 1;
    let mut polygon: Vec<u32> = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let line = i + 1;
        last_line = line;
        let content = raw.split('#').next().unwrap_or("");
        let mut tokens = content.split_ascii_whitespace();
        let Some(keyword) = tokens.next() else {
            continue;
        };
        if std::mem::take(&mut first_statement) {
            if let Some(h) = parse_header(content) {
                header = Some((line, h));
                continue;
            }
        }
        match keyword {
            "v" => {
                let mut c = [0.0f32; 3];
                for (k, axis) in c.iter_mut().zip(["x", "y", "z"]) {
                    let tok = tokens
                        .next()
                        .ok_or_else(|| ctx.line(line, "vertex needs 3 coordinates"))?;
                    let x: f32 = tok.parse().map_err(|_| {
                        ctx.line(line, format!("bad vertex {axis} coordinate '{tok}'"))
                    })?;
                    *k = finite(x, &format!("vertex {axis} coordinate"))
                        .map_err(|m| ctx.line(line, m))?;
                }
                if vertices.len() >= u32::MAX as usize {
                    return Err(ctx.line(line, "more than 2^32 - 1 vertices"));
                }
                vertices.push(Vec3::from_array(c));
            }
            "f" => {
                polygon.clear();
                for tok in tokens {
                    let index = resolve(tok, vertices.len()).map_err(|m| ctx.line(line, m))?;
                    polygon.push(index);
                }
                if polygon.len() < 3 {
                    return Err(ctx.line(
                        line,
                        format!("face has {} corners, needs at least 3", polygon.len()),
                    ));
                }
                for w in 1..polygon.len() - 1 {
                    triangles.push([polygon[0], polygon[w], polygon[w + 1]]);
                }
            }
            _ => {}
        }
    }
    if let Some((line, [nv, nt])) = header {
        if nv != vertices.len() as u64 || nt != triangles.len() as u64 {
            return Err(ctx.line(
                line,
                format!(
                    "header promises {nv} vertices and {nt} triangles, the file has {} and {}",
                    vertices.len(),
                    triangles.len()
                ),
            ));
        }
    }
    ctx.finish(vertices, triangles, FileLocation::Line(last_line))
}

/// `<nverts> <ntris>`: exactly two unsigned integers.
fn parse_header(content: &str) -> Option<[u64; 2]> {
    let mut t = content.split_ascii_whitespace();
    let h = [t.next()?.parse().ok()?, t.next()?.parse().ok()?];
    t.next().is_none().then_some(h)
}

/// The 0-based vertex index of a face corner `v[/vt[/vn]]`, given `n` vertices
/// defined so far.
fn resolve(tok: &str, n: usize) -> std::result::Result<u32, String> {
    let v = tok.split('/').next().unwrap_or("");
    let i: i64 = v.parse().map_err(|_| format!("bad face corner '{tok}'"))?;
    let index = match i {
        0 => return Err("face index 0 (OBJ indices start at 1)".into()),
        i if i > 0 => i - 1,
        i => n as i64 + i,
    };
    if index < 0 || index >= n as i64 {
        return Err(format!(
            "face corner '{tok}' refers to a vertex that does not exist ({n} defined so far)"
        ));
    }
    Ok(index as u32)
}
