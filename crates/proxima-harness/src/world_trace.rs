//! Parser of the world-trace format of `proxima world` [sources: world-trace].
//!
//! The whole trace is parsed and checked before anything runs: syntax, finite
//! numbers, poses that are rotations (the library's `check_pose`), query shapes
//! (the library's `validate`), mesh names and id liveness, and every mesh file
//! read (through a caller's loader, so that tests and fuzzers need no files).
//! A bad line stops the run before any output, with `line N: what is wrong`.

use proxima::geom::{Ray, Sphere};
use proxima::glam::{Affine3A, Mat3A, Vec3, Vec3A};
use proxima::narrow::TriMesh;
use std::collections::HashMap;
use std::fmt;
use std::path::Path;
use std::sync::Arc;

use crate::lex::{clip, expect_fields as fields, numbers, Res};

/// One operation of a world trace; `slot` is the dense number of a user id
/// ([`WorldTrace::ids`]), `mesh` an index into [`WorldTrace::meshes`].
#[derive(Clone, Debug, PartialEq)]
pub enum WorldOp {
    /// `mesh NAME FILE`: build the mesh's trees.
    Mesh {
        /// Index into [`WorldTrace::meshes`].
        mesh: u32,
    },
    /// `add ID NAME`: a new object at the identity pose.
    Add {
        /// The object's slot.
        slot: u32,
        /// Index into [`WorldTrace::meshes`].
        mesh: u32,
    },
    /// `pose ID r00 … tz`.
    Pose {
        /// The object's slot.
        slot: u32,
        /// The new rigid pose.
        pose: Affine3A,
    },
    /// `remove ID`.
    Remove {
        /// The object's slot.
        slot: u32,
    },
    /// `ignore ID1 ID2`.
    Ignore {
        /// One object's slot.
        a: u32,
        /// The other object's slot.
        b: u32,
    },
    /// `contacts`.
    Contacts,
    /// `ray OX OY OZ DX DY DZ TMAX`.
    Ray(Ray),
    /// `sphere X Y Z R`.
    Sphere(Sphere),
}

/// Operation kinds, for timing tables (`kind as usize` indexes [`WorldKind::ALL`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WorldKind {
    /// `mesh` lines.
    Mesh,
    /// `add` lines.
    Add,
    /// `pose` lines.
    Pose,
    /// `remove` lines.
    Remove,
    /// `ignore` lines.
    Ignore,
    /// `contacts` lines.
    Contacts,
    /// `ray` lines.
    Ray,
    /// `sphere` lines.
    Sphere,
}

impl WorldKind {
    /// Every kind, in table order.
    pub const ALL: [WorldKind; 8] = [
        WorldKind::Mesh,
        WorldKind::Add,
        WorldKind::Pose,
        WorldKind::Remove,
        WorldKind::Ignore,
        WorldKind::Contacts,
        WorldKind::Ray,
        WorldKind::Sphere,
    ];

    /// The trace keyword.
    pub fn name(self) -> &'static str {
        match self {
            WorldKind::Mesh => "mesh",
            WorldKind::Add => "add",
            WorldKind::Pose => "pose",
            WorldKind::Remove => "remove",
            WorldKind::Ignore => "ignore",
            WorldKind::Contacts => "contacts",
            WorldKind::Ray => "ray",
            WorldKind::Sphere => "sphere",
        }
    }
}

impl WorldOp {
    /// The kind of the operation.
    pub fn kind(&self) -> WorldKind {
        match self {
            WorldOp::Mesh { .. } => WorldKind::Mesh,
            WorldOp::Add { .. } => WorldKind::Add,
            WorldOp::Pose { .. } => WorldKind::Pose,
            WorldOp::Remove { .. } => WorldKind::Remove,
            WorldOp::Ignore { .. } => WorldKind::Ignore,
            WorldOp::Contacts => WorldKind::Contacts,
            WorldOp::Ray(_) => WorldKind::Ray,
            WorldOp::Sphere(_) => WorldKind::Sphere,
        }
    }

    /// Whether the operation prints a result line.
    pub fn is_query(&self) -> bool {
        matches!(
            self,
            WorldOp::Contacts | WorldOp::Ray(_) | WorldOp::Sphere(_)
        )
    }
}

/// A parsed, checked world trace.
#[derive(Clone, Debug, Default)]
pub struct WorldTrace {
    /// The operations, in order.
    pub ops: Vec<WorldOp>,
    /// The 1-based source line of each operation.
    pub lines: Vec<u32>,
    /// The meshes' geometry, in the order of their `mesh` lines.
    pub meshes: Vec<Arc<TriMesh>>,
    /// The user id of each slot.
    pub ids: Vec<u64>,
    /// The largest number of objects alive at once.
    pub max_live: usize,
}

/// A bad line: printed as `line N: message`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ParseError {
    /// 1-based line number.
    pub line: usize,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for ParseError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "line {}: {}", self.line, self.message)
    }
}

/// Most fields on a line (`pose` and its 13).
const MAX_FIELDS: usize = 14;

impl WorldTrace {
    /// Parses and checks a trace whose `mesh` files are read by `load` (given
    /// the file as written). O(lines) plus the loads.
    pub fn parse_with(
        text: &[u8],
        mut load: impl FnMut(&str) -> Res<TriMesh>,
    ) -> Result<WorldTrace, ParseError> {
        let mut p = Parser::default();
        for (i, raw) in text.split(|&b| b == b'\n').enumerate() {
            let line = i + 1;
            p.line(raw, &mut load)
                .map_err(|message| ParseError { line, message })?;
            if p.trace.ops.len() > p.trace.lines.len() {
                p.trace.lines.push(line as u32);
            }
        }
        Ok(p.trace)
    }

    /// Parses a trace file's content, reading mesh files relative to `dir`
    /// (the trace's folder) with the library's loader.
    pub fn parse(text: &[u8], dir: &Path) -> Result<WorldTrace, ParseError> {
        WorldTrace::parse_with(text, |file| {
            proxima::io::load(dir.join(file)).map_err(|e| format!("cannot load mesh: {e}"))
        })
    }

    /// Number of query lines (= result lines of a run).
    pub fn query_count(&self) -> usize {
        self.ops.iter().filter(|op| op.is_query()).count()
    }

    /// Source line of each query, in order.
    pub fn query_lines(&self) -> Vec<u32> {
        self.ops
            .iter()
            .zip(&self.lines)
            .filter(|(op, _)| op.is_query())
            .map(|(_, &l)| l)
            .collect()
    }
}

#[derive(Default)]
struct Parser {
    trace: WorldTrace,
    mesh_of: HashMap<String, u32>,
    slot_of: HashMap<u64, u32>,
    live: Vec<bool>,
    live_count: usize,
}

impl Parser {
    fn line(&mut self, raw: &[u8], load: &mut impl FnMut(&str) -> Res<TriMesh>) -> Res<()> {
        let text = std::str::from_utf8(raw).map_err(|_| "not valid UTF-8".to_string())?;
        let text = text.split('#').next().unwrap_or("");
        let mut f = [""; MAX_FIELDS];
        let mut n = 0;
        for tok in text.split_ascii_whitespace() {
            if n == MAX_FIELDS {
                return Err(format!("too many fields (at most {MAX_FIELDS})"));
            }
            f[n] = tok;
            n += 1;
        }
        if n == 0 {
            return Ok(());
        }
        let (cmd, args) = (f[0], &f[1..n]);
        let op = match cmd {
            "mesh" => {
                fields(cmd, args, &["NAME", "FILE"])?;
                let (name, file) = (args[0], args[1]);
                if self.mesh_of.contains_key(name) {
                    return Err(format!("mesh '{}' is already defined", clip(name)));
                }
                let mesh = load(file)?;
                let k = self.trace.meshes.len() as u32;
                self.mesh_of.insert(name.to_string(), k);
                self.trace.meshes.push(Arc::new(mesh));
                WorldOp::Mesh { mesh: k }
            }
            "add" => {
                fields(cmd, args, &["ID", "NAME"])?;
                let id = parse_id(args[0])?;
                let mesh = *self
                    .mesh_of
                    .get(args[1])
                    .ok_or_else(|| format!("unknown mesh '{}'", clip(args[1])))?;
                WorldOp::Add {
                    slot: self.add(id)?,
                    mesh,
                }
            }
            "pose" => {
                let names = [
                    "ID", "r00", "r01", "r02", "r10", "r11", "r12", "r20", "r21", "r22", "tx",
                    "ty", "tz",
                ];
                fields(cmd, args, &names)?;
                let slot = self.live_slot(parse_id(args[0])?)?;
                let v = numbers::<12>(cmd, &args[1..], &names[1..])?;
                let pose = pose(&v);
                proxima::narrow::check_pose(&pose).map_err(|e| e.to_string())?;
                WorldOp::Pose { slot, pose }
            }
            "remove" => {
                fields(cmd, args, &["ID"])?;
                let slot = self.live_slot(parse_id(args[0])?)?;
                self.live[slot as usize] = false;
                self.live_count -= 1;
                WorldOp::Remove { slot }
            }
            "ignore" => {
                fields(cmd, args, &["ID1", "ID2"])?;
                let a = self.live_slot(parse_id(args[0])?)?;
                let b = self.live_slot(parse_id(args[1])?)?;
                if a == b {
                    return Err("ignore needs two different ids".into());
                }
                WorldOp::Ignore { a, b }
            }
            "contacts" => {
                fields(cmd, args, &[])?;
                WorldOp::Contacts
            }
            "ray" => {
                let names = ["OX", "OY", "OZ", "DX", "DY", "DZ", "TMAX"];
                let v = numbers::<7>(cmd, args, &names)?;
                let ray = Ray::with_max_t(
                    Vec3::new(v[0], v[1], v[2]),
                    Vec3::new(v[3], v[4], v[5]),
                    v[6],
                );
                ray.validate().map_err(|e| e.to_string())?;
                WorldOp::Ray(ray)
            }
            "sphere" => {
                let v = numbers::<4>(cmd, args, &["X", "Y", "Z", "R"])?;
                let s = Sphere::new(Vec3::new(v[0], v[1], v[2]), v[3]);
                s.validate().map_err(|e| e.to_string())?;
                WorldOp::Sphere(s)
            }
            other => return Err(format!("unknown command '{}'", clip(other))),
        };
        self.trace.ops.push(op);
        Ok(())
    }

    fn add(&mut self, id: u64) -> Res<u32> {
        let slot = match self.slot_of.get(&id) {
            Some(&s) if self.live[s as usize] => return Err(format!("id {id} is already in use")),
            Some(&s) => s,
            None => {
                let s = u32::try_from(self.trace.ids.len())
                    .map_err(|_| "more than 2^32 distinct ids".to_string())?;
                self.slot_of.insert(id, s);
                self.trace.ids.push(id);
                self.live.push(false);
                s
            }
        };
        self.live[slot as usize] = true;
        self.live_count += 1;
        self.trace.max_live = self.trace.max_live.max(self.live_count);
        Ok(slot)
    }

    fn live_slot(&self, id: u64) -> Res<u32> {
        match self.slot_of.get(&id) {
            Some(&s) if self.live[s as usize] => Ok(s),
            _ => Err(format!("unknown id {id}")),
        }
    }
}

/// The pose of 12 numbers: a row-major rotation, then a translation
/// (`p' = R p + t`).
pub fn pose(v: &[f32; 12]) -> Affine3A {
    Affine3A {
        matrix3: Mat3A::from_cols(
            Vec3A::new(v[0], v[3], v[6]),
            Vec3A::new(v[1], v[4], v[7]),
            Vec3A::new(v[2], v[5], v[8]),
        ),
        translation: Vec3A::new(v[9], v[10], v[11]),
    }
}

fn parse_id(s: &str) -> Res<u64> {
    s.parse()
        .map_err(|_| format!("bad id '{}' (expected an unsigned 64-bit integer)", clip(s)))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A loader that knows one mesh, `tri.obj`.
    fn tri(file: &str) -> Res<TriMesh> {
        if file == "tri.obj" {
            TriMesh::new(vec![Vec3::ZERO, Vec3::X, Vec3::Y], vec![[0, 1, 2]])
                .map_err(|e| e.to_string())
        } else {
            Err(format!("no such file {file}"))
        }
    }

    fn parse(text: &str) -> Result<WorldTrace, ParseError> {
        WorldTrace::parse_with(text.as_bytes(), tri)
    }

    #[test]
    fn parses_every_kind() {
        let t = parse(
            "# header\nmesh t tri.obj\nadd 5 t\nadd 18446744073709551615 t # max id\n\
             pose 5 0 -1 0 1 0 0 0 0 1 1 2 3\nignore 18446744073709551615 5\ncontacts\n\
             ray 0 0 0 1 0 0 5\nsphere 0 0 0 1\nremove 5\nadd 5 t\n",
        )
        .unwrap();
        let kinds: Vec<_> = t.ops.iter().map(|o| o.kind().name()).collect();
        assert_eq!(
            kinds,
            [
                "mesh", "add", "add", "pose", "ignore", "contacts", "ray", "sphere", "remove",
                "add"
            ]
        );
        assert_eq!(t.lines, [2, 3, 4, 5, 6, 7, 8, 9, 10, 11]);
        assert_eq!(t.ids, [5, u64::MAX]);
        assert_eq!((t.max_live, t.query_count()), (2, 3));
        assert_eq!(t.query_lines(), [7, 8, 9]);
        let WorldOp::Pose { pose: p, .. } = t.ops[3] else {
            panic!()
        };
        // Row-major: the first row (0, -1, 0) gives x' = -y + tx.
        assert_eq!(p.transform_point3(Vec3::Y), Vec3::new(0.0, 2.0, 3.0));
        assert_eq!(p.transform_point3(Vec3::X), Vec3::new(1.0, 3.0, 3.0));
        for (i, k) in WorldKind::ALL.iter().enumerate() {
            assert_eq!(*k as usize, i);
        }
    }

    #[test]
    fn reports_line_and_reason() {
        let err = |s: &str| parse(s).unwrap_err();
        let e = err("mesh t tri.obj\nadd 1 t\n\npose 2 1 0 0 0 1 0 0 0 1 0 0 0\n");
        assert_eq!((e.line, e.message.as_str()), (4, "unknown id 2"));
        assert!(err("mesh t tri.obj\nmesh t tri.obj")
            .message
            .contains("already defined"));
        assert!(err("mesh t other.obj").message.contains("no such file"));
        assert!(err("add 1 t").message.contains("unknown mesh 't'"));
        let m = "mesh t tri.obj\nadd 1 t\n";
        assert!(err(&format!("{m}add 1 t"))
            .message
            .contains("already in use"));
        assert!(err(&format!("{m}pose 1 2 0 0 0 1 0 0 0 1 0 0 0"))
            .message
            .contains("rotation"));
        assert!(err(&format!("{m}pose 1 -1 0 0 0 1 0 0 0 1 0 0 0"))
            .message
            .contains("rotation"));
        assert!(err(&format!("{m}pose 1 1 0 0 0 1 0 0 0 1 0 0 nan"))
            .message
            .contains("not finite"));
        assert!(err(&format!("{m}pose 1 1 0 0 0 1 0 0 0 1 0 0"))
            .message
            .contains("expects 13"));
        assert!(err(&format!("{m}ignore 1 1"))
            .message
            .contains("two different"));
        assert!(err(&format!("{m}ignore 1 2"))
            .message
            .contains("unknown id 2"));
        assert!(err(&format!("{m}remove 1\nremove 1"))
            .message
            .contains("unknown id 1"));
        assert!(err("contacts 1").message.contains("takes no fields"));
        assert!(err("ray 0 0 0 0 0 0 1").message.contains("zero"));
        assert!(err("ray 0 0 0 1 0 0 -1").message.contains("max_t"));
        assert!(err("sphere 0 0 0 -1").message.contains("negative radius"));
        assert!(err("add x t").message.contains("bad id"));
        assert!(err("frob").message.contains("unknown command"));
        assert!(err(&"contacts ".repeat(20))
            .message
            .contains("too many fields"));
        assert_eq!(
            WorldTrace::parse_with(b"contacts\n\xff\n", tri)
                .unwrap_err()
                .line,
            2
        );
    }
}
