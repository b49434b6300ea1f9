//! Stanford PLY: `ascii`, `binary_little_endian` and `binary_big_endian`.
//! The `vertex` element's `x y z` (any numeric type) and the `face` element's
//! `vertex_indices` (or `vertex_index`) list (any integer types) are read; every
//! other element and property is skipped. Faces are fan-triangulated.

use super::bytes::Bytes;
use super::text::Tokens;
use super::Ctx;
use crate::narrow::TriMesh;
use crate::{Error, FileLocation, Result};
use glam::Vec3;

#[derive(Clone, Copy, PartialEq, Debug)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(s: &str) -> Option<Scalar> {
        Some(match s {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn is_float(self) -> bool {
        matches!(self, Scalar::F32 | Scalar::F64)
    }
}

enum Property {
    Scalar(Scalar, String),
    List(Scalar, Scalar, String),
}

struct Element {
    name: String,
    count: u64,
    props: Vec<Property>,
    line: usize,
}

#[derive(PartialEq)]
enum Encoding {
    Ascii,
    Binary { big_endian: bool },
}

/// A number read from the data section.
#[derive(Clone, Copy)]
enum Value {
    Int(i64),
    Float(f64),
}

/// Parses a PLY file. `name` is used in errors. Header problems are reported by
/// line; data problems by line (ASCII) or byte offset (binary). Cost: linear in
/// the file size. Anything but whitespace after the last element is an error
/// (it means a count in the header is wrong).
pub fn parse_ply(name: &str, data: &[u8]) -> Result<TriMesh> {
    let ctx = Ctx { file: name };
    let (encoding, elements, data_start, data_line) = parse_header(ctx, data)?;
    let mut reader = match encoding {
        Encoding::Ascii => {
            let text = std::str::from_utf8(&data[data_start..]).map_err(|e| {
                ctx.offset(data_start + e.valid_up_to(), "ASCII PLY data is not text")
            })?;
            Reader::Ascii(Tokens::new(text, data_line), data_line)
        }
        Encoding::Binary { big_endian } => {
            Reader::Binary(Bytes::new(data, data_start, big_endian), data_start)
        }
    };
    let Some(vertex_element) = elements.iter().find(|e| e.name == "vertex") else {
        return Err(ctx.line(1, "no 'vertex' element in the header"));
    };
    if vertex_element.count > u32::MAX as u64 {
        return Err(ctx.line(vertex_element.line, "more than 2^32 - 1 vertices"));
    }
    let n_vertices = vertex_element.count;
    let mut vertices = Vec::new();
    let mut triangles = Vec::new();
    for e in &elements {
        match e.name.as_str() {
            "vertex" => read_vertices(ctx, &mut reader, e, &mut vertices)?,
            "face" => read_faces(ctx, &mut reader, e, n_vertices, &mut triangles)?,
            _ => skip_element(ctx, &mut reader, e)?,
        }
    }
    reader.expect_end(ctx)?;
    let end = reader.here();
    ctx.finish(vertices, triangles, end)
}

/// Returns the encoding, the elements, the byte offset of the data and its
/// first line number.
fn parse_header(ctx: Ctx, data: &[u8]) -> Result<(Encoding, Vec<Element>, usize, usize)> {
    let mut pos = 0;
    let mut line = 0;
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    loop {
        line += 1;
        let Some(len) = data[pos..].iter().position(|&b| b == b'\n') else {
            return Err(ctx.line(line, "header ends without 'end_header'"));
        };
        let raw = &data[pos..pos + len];
        pos += len + 1;
        let text =
            std::str::from_utf8(raw).map_err(|_| ctx.line(line, "header line is not text"))?;
        let mut t = text.split_ascii_whitespace();
        let keyword = t.next().unwrap_or("");
        if line == 1 {
            if text.trim_end() != "ply" {
                return Err(ctx.line(1, "not a PLY file (first line must be 'ply')"));
            }
            continue;
        }
        match keyword {
            "format" => {
                encoding = Some(match (t.next(), t.next()) {
                    (Some("ascii"), Some("1.0")) => Encoding::Ascii,
                    (Some("binary_little_endian"), Some("1.0")) => {
                        Encoding::Binary { big_endian: false }
                    }
                    (Some("binary_big_endian"), Some("1.0")) => {
                        Encoding::Binary { big_endian: true }
                    }
                    _ => return Err(ctx.line(line, format!("unsupported format '{text}'"))),
                })
            }
            "comment" | "obj_info" | "" => {}
            "element" => {
                let (Some(name), Some(count), None) = (t.next(), t.next(), t.next()) else {
                    return Err(ctx.line(line, "expected 'element <name> <count>'"));
                };
                let count = count
                    .parse()
                    .map_err(|_| ctx.line(line, format!("bad element count '{count}'")))?;
                elements.push(Element {
                    name: name.to_string(),
                    count,
                    props: Vec::new(),
                    line,
                });
            }
            "property" => {
                let element = elements
                    .last_mut()
                    .ok_or_else(|| ctx.line(line, "property before any element"))?;
                let words: Vec<&str> = t.collect();
                let ty = |s: &str| {
                    Scalar::parse(s).ok_or_else(|| ctx.line(line, format!("unknown type '{s}'")))
                };
                let prop = match words.as_slice() {
                    ["list", c, i, name] => Property::List(ty(c)?, ty(i)?, name.to_string()),
                    [s, name] => Property::Scalar(ty(s)?, name.to_string()),
                    _ => return Err(ctx.line(
                        line,
                        "expected 'property <type> <name>' or 'property list <type> <type> <name>'",
                    )),
                };
                if let Property::List(c, _, _) = &prop {
                    if c.is_float() {
                        return Err(ctx.line(line, "list count type must be an integer type"));
                    }
                }
                element.props.push(prop);
            }
            "end_header" => break,
            k => return Err(ctx.line(line, format!("unknown header keyword '{k}'"))),
        }
    }
    let encoding = encoding.ok_or_else(|| ctx.line(line, "header has no 'format' line"))?;
    check_layout(ctx, &elements)?;
    Ok((encoding, elements, pos, line + 1))
}

/// The vertex element has scalar x, y, z; the face element has an integer
/// index list.
fn check_layout(ctx: Ctx, elements: &[Element]) -> Result<()> {
    for e in elements {
        if e.name == "vertex" {
            for axis in ["x", "y", "z"] {
                if !e
                    .props
                    .iter()
                    .any(|p| matches!(p, Property::Scalar(_, n) if n == axis))
                {
                    return Err(ctx.line(
                        e.line,
                        format!("vertex element has no scalar property '{axis}'"),
                    ));
                }
            }
        }
        if e.name == "face" {
            match e.props.iter().find(|p| is_index_list(p)) {
                Some(Property::List(_, item, _)) if item.is_float() => {
                    return Err(ctx.line(e.line, "face vertex indices must have an integer type"))
                }
                Some(_) => {}
                None => return Err(ctx.line(e.line, "face element has no 'vertex_indices' list")),
            }
        }
    }
    Ok(())
}

fn is_index_list(p: &Property) -> bool {
    matches!(p, Property::List(_, _, n) if n == "vertex_indices" || n == "vertex_index")
}

enum Reader<'a> {
    /// Tokens and the line of the last value read.
    Ascii(Tokens<'a>, usize),
    /// Bytes and the offset of the last value read.
    Binary(Bytes<'a>, usize),
}

impl Reader<'_> {
    /// Location of the last value read (or of the start of the data).
    fn here(&self) -> FileLocation {
        match self {
            Reader::Ascii(_, line) => FileLocation::Line(*line),
            Reader::Binary(_, at) => FileLocation::Offset(*at as u64),
        }
    }

    fn read(&mut self, ctx: Ctx, s: Scalar) -> Result<Value> {
        match self {
            Reader::Ascii(t, line) => {
                let tok = t.next_token();
                *line = t.line;
                let tok = tok.ok_or_else(|| ctx.line(*line, "unexpected end of data"))?;
                let v = if s.is_float() {
                    tok.parse().ok().map(Value::Float)
                } else {
                    tok.parse().ok().map(Value::Int)
                };
                v.ok_or_else(|| ctx.line(*line, format!("bad {s:?} value '{tok}'")))
            }
            Reader::Binary(b, at) => {
                *at = b.pos;
                let v = match s {
                    Scalar::I8 => b
                        .take::<1>()
                        .map(|x| Value::Int(i8::from_le_bytes(x) as i64)),
                    Scalar::U8 => b.take::<1>().map(|x| Value::Int(x[0] as i64)),
                    Scalar::I16 => b
                        .take::<2>()
                        .map(|x| Value::Int(i16::from_le_bytes(x) as i64)),
                    Scalar::U16 => b
                        .take::<2>()
                        .map(|x| Value::Int(u16::from_le_bytes(x) as i64)),
                    Scalar::I32 => b
                        .take::<4>()
                        .map(|x| Value::Int(i32::from_le_bytes(x) as i64)),
                    Scalar::U32 => b
                        .take::<4>()
                        .map(|x| Value::Int(u32::from_le_bytes(x) as i64)),
                    Scalar::F32 => b.f32().map(|x| Value::Float(x as f64)),
                    Scalar::F64 => b.take::<8>().map(|x| Value::Float(f64::from_le_bytes(x))),
                };
                v.ok_or_else(|| ctx.offset(*at, "unexpected end of data"))
            }
        }
    }

    /// Only whitespace may follow the last element: more data means a count
    /// in the header is too small.
    fn expect_end(&mut self, ctx: Ctx) -> Result<()> {
        let extra = match self {
            Reader::Ascii(t, line) => {
                let extra = t.next_token().is_some();
                *line = t.line;
                extra
            }
            Reader::Binary(b, at) => {
                *at = b.pos;
                let rest = b.rest();
                !rest.iter().all(u8::is_ascii_whitespace)
            }
        };
        if extra {
            return Err(self.error(
                ctx,
                "data after the last element (an element count is too small?)",
            ));
        }
        Ok(())
    }

    fn error(&self, ctx: Ctx, msg: impl Into<String>) -> Error {
        ctx.at(self.here(), msg)
    }

    /// A list length: a non-negative integer.
    fn count(&mut self, ctx: Ctx, s: Scalar) -> Result<u64> {
        match self.read(ctx, s)? {
            Value::Int(n) if n >= 0 => Ok(n as u64),
            _ => Err(self.error(ctx, "list length is negative")),
        }
    }

    /// Skips `n` values of type `s` without storing them.
    fn skip(&mut self, ctx: Ctx, s: Scalar, n: u64) -> Result<()> {
        for _ in 0..n {
            self.read(ctx, s)?;
        }
        Ok(())
    }
}

fn read_vertices(ctx: Ctx, r: &mut Reader, e: &Element, out: &mut Vec<Vec3>) -> Result<()> {
    for _ in 0..e.count {
        let mut p = [f32::NAN; 3];
        for prop in &e.props {
            match prop {
                Property::Scalar(s, name) => {
                    let v = r.read(ctx, *s)?;
                    if let Some(k) = ["x", "y", "z"].iter().position(|a| a == name) {
                        let x = match v {
                            Value::Int(i) => i as f32,
                            Value::Float(f) => f as f32,
                        };
                        if !x.is_finite() {
                            return Err(r.error(ctx, format!("vertex {name} is not a finite f32")));
                        }
                        p[k] = x;
                    }
                }
                Property::List(c, i, _) => {
                    let n = r.count(ctx, *c)?;
                    r.skip(ctx, *i, n)?;
                }
            }
        }
        out.push(Vec3::from_array(p));
    }
    Ok(())
}

fn read_faces(
    ctx: Ctx,
    r: &mut Reader,
    e: &Element,
    n_vertices: u64,
    out: &mut Vec<[u32; 3]>,
) -> Result<()> {
    let mut corners: Vec<u32> = Vec::new();
    let index_prop = e.props.iter().position(is_index_list);
    for _ in 0..e.count {
        for (pi, prop) in e.props.iter().enumerate() {
            match prop {
                Property::Scalar(s, _) => {
                    r.read(ctx, *s)?;
                }
                Property::List(c, item, _) if Some(pi) == index_prop => {
                    let n = r.count(ctx, *c)?;
                    if n < 3 {
                        return Err(
                            r.error(ctx, format!("face has {n} vertices, needs at least 3"))
                        );
                    }
                    corners.clear();
                    for _ in 0..n {
                        let i = match r.read(ctx, *item)? {
                            Value::Int(i) if i >= 0 && (i as u64) < n_vertices => i as u32,
                            Value::Int(i) => {
                                return Err(r.error(
                                    ctx,
                                    format!("vertex index {i} out of range (0..{n_vertices})"),
                                ))
                            }
                            Value::Float(_) => {
                                return Err(r.error(ctx, "vertex index is not an integer"))
                            }
                        };
                        corners.push(i);
                    }
                    for w in 1..corners.len() - 1 {
                        out.push([corners[0], corners[w], corners[w + 1]]);
                    }
                }
                Property::List(c, i, _) => {
                    let n = r.count(ctx, *c)?;
                    r.skip(ctx, *i, n)?;
                }
            }
        }
    }
    Ok(())
}

fn skip_element(ctx: Ctx, r: &mut Reader, e: &Element) -> Result<()> {
    if e.props.is_empty() {
        return Ok(()); // nothing to read, however large the count
    }
    for _ in 0..e.count {
        for prop in &e.props {
            match prop {
                Property::Scalar(s, _) => {
                    r.read(ctx, *s)?;
                }
                Property::List(c, i, _) => {
                    let n = r.count(ctx, *c)?;
                    r.skip(ctx, *i, n)?;
                }
            }
        }
    }
    Ok(())
}
