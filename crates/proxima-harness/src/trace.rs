//! Parser of the scene-trace format of `proxima replay` [sources: trace-format],
//! used by the CLI, the `replay` fuzz target and [`crate::replay`].
//!
//! The whole trace is parsed and checked before any index runs: syntax, finite
//! numbers, query shapes (through the library's own `validate`), and id liveness
//! (insert of a present id, move/remove of an absent one). So every index replays
//! the same valid operations, and a bad line stops the run before any output.
//! User ids are mapped once to dense slots, so a replay needs no hashing.
//!
//! # Adding a line
//!
//! A new line kind (issue #14's `nearest X Y Z K` and `sweep X0 Y0 Z0 X1 Y1 Z1 R`,
//! say) is a [`Query`] variant, a [`Kind`] (its keyword and table position), one
//! arm of the parser's `match` on the command (fields read with [`crate::lex`]),
//! and one arm of the engine's `apply` with its [`crate::replay::Answer`]. An
//! optional tail on an existing line (`insert ID X Y Z R GROUP MASK`) is read in
//! that line's arm by its field count, and carried as a field of its [`Op`].

use crate::lex::{self, expect_fields, numbers, ParseError, Res};
use proxima::broad::SceneHint;
use proxima::geom::{Aabb, Frustum, Ray, Sphere};
use proxima::glam::{Mat4, Vec3};
use std::collections::HashMap;

/// A query of a trace line.
#[derive(Clone, Debug, PartialEq)]
pub enum Query {
    /// `pairs`: count overlapping pairs.
    Pairs,
    /// `sphere X Y Z R`.
    Sphere(Sphere),
    /// `aabb X0 Y0 Z0 X1 Y1 Z1`.
    Aabb(Aabb),
    /// `ray OX OY OZ DX DY DZ TMAX`.
    Ray(Ray),
    /// `frustum M00 … M33` (boxed: it is much larger than the other variants).
    Frustum(Box<Frustum>),
}

/// One operation. `slot` is the dense number of the user id (see [`Trace::ids`]).
#[derive(Clone, Debug, PartialEq)]
pub enum Op {
    /// Add the object `slot`.
    Insert {
        /// Dense id.
        slot: u32,
        /// Its sphere.
        sphere: Sphere,
    },
    /// Move/resize the object `slot`.
    Move {
        /// Dense id.
        slot: u32,
        /// Its new sphere.
        sphere: Sphere,
    },
    /// Remove the object `slot`.
    Remove {
        /// Dense id.
        slot: u32,
    },
    /// A query: one output line.
    Query(Query),
}

/// Operation kinds, for timing tables (`kind as usize` indexes [`Kind::ALL`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[allow(missing_docs)] // each is its keyword (see `Kind::name`)
pub enum Kind {
    Insert,
    Move,
    Remove,
    Pairs,
    Sphere,
    Aabb,
    Ray,
    Frustum,
}

impl Kind {
    /// Every kind, in table order.
    pub const ALL: [Kind; 8] = [
        Kind::Insert,
        Kind::Move,
        Kind::Remove,
        Kind::Pairs,
        Kind::Sphere,
        Kind::Aabb,
        Kind::Ray,
        Kind::Frustum,
    ];

    /// The trace keyword.
    pub fn name(self) -> &'static str {
        match self {
            Kind::Insert => "insert",
            Kind::Move => "move",
            Kind::Remove => "remove",
            Kind::Pairs => "pairs",
            Kind::Sphere => "sphere",
            Kind::Aabb => "aabb",
            Kind::Ray => "ray",
            Kind::Frustum => "frustum",
        }
    }
}

impl Op {
    /// The kind of the operation.
    pub fn kind(&self) -> Kind {
        match self {
            Op::Insert { .. } => Kind::Insert,
            Op::Move { .. } => Kind::Move,
            Op::Remove { .. } => Kind::Remove,
            Op::Query(Query::Pairs) => Kind::Pairs,
            Op::Query(Query::Sphere(_)) => Kind::Sphere,
            Op::Query(Query::Aabb(_)) => Kind::Aabb,
            Op::Query(Query::Ray(_)) => Kind::Ray,
            Op::Query(Query::Frustum(_)) => Kind::Frustum,
        }
    }
}

/// A parsed, checked trace.
#[derive(Clone, Debug, Default)]
pub struct Trace {
    /// The operations, in order.
    pub ops: Vec<Op>,
    /// The 1-based source line of each operation.
    pub lines: Vec<u32>,
    /// The user id of each slot.
    pub ids: Vec<u64>,
    /// The largest number of objects alive at once.
    pub max_live: usize,
}

/// Most fields on a line (`frustum` and its 16 numbers).
const MAX_FIELDS: usize = 17;

impl Trace {
    /// Parses and checks a whole trace. O(lines); allocates only the result.
    pub fn parse(text: &[u8]) -> Result<Trace, ParseError> {
        let mut p = Parser::default();
        lex::for_each_line(text, |line, raw| {
            p.line(raw)?;
            if p.trace.ops.len() > p.trace.lines.len() {
                p.trace.lines.push(line as u32);
            }
            Ok(())
        })?;
        Ok(p.trace)
    }

    /// The [`SceneHint`] of the trace: bounding box of every inserted or moved
    /// centre and a high quantile of their radii.
    pub fn scene_hint(&self) -> SceneHint {
        let spheres = self.ops.iter().filter_map(|op| match op {
            Op::Insert { sphere, .. } | Op::Move { sphere, .. } => Some(*sphere),
            _ => None,
        });
        SceneHint::from_spheres(spheres, self.max_live)
    }

    /// Number of query lines (= output lines of a replay).
    pub fn query_count(&self) -> usize {
        self.ops
            .iter()
            .filter(|op| matches!(op, Op::Query(_)))
            .count()
    }
}

#[derive(Default)]
struct Parser {
    trace: Trace,
    slot_of: HashMap<u64, u32>,
    live: Vec<bool>,
    live_count: usize,
}

impl Parser {
    fn line(&mut self, raw: &[u8]) -> Res<()> {
        let line = lex::Line::<MAX_FIELDS>::split(raw)?;
        let Some(cmd) = line.command() else {
            return Ok(());
        };
        let args = line.args();
        let op = match cmd {
            "insert" | "move" => {
                expect_fields(cmd, args, &["ID", "X", "Y", "Z", "R"])?;
                let id = lex::id(args[0])?;
                let sphere = lex::sphere(&args[1..])?;
                if cmd == "insert" {
                    Op::Insert {
                        slot: self.insert(id)?,
                        sphere,
                    }
                } else {
                    Op::Move {
                        slot: self.live_slot(id)?,
                        sphere,
                    }
                }
            }
            "remove" => {
                expect_fields(cmd, args, &["ID"])?;
                let slot = self.live_slot(lex::id(args[0])?)?;
                self.live[slot as usize] = false;
                self.live_count -= 1;
                Op::Remove { slot }
            }
            "pairs" => {
                expect_fields(cmd, args, &[])?;
                Op::Query(Query::Pairs)
            }
            "sphere" => {
                expect_fields(cmd, args, &["X", "Y", "Z", "R"])?;
                Op::Query(Query::Sphere(lex::sphere(args)?))
            }
            "aabb" => {
                let v = numbers::<6>(cmd, args, &["X0", "Y0", "Z0", "X1", "Y1", "Z1"])?;
                let b = Aabb::new(Vec3::new(v[0], v[1], v[2]), Vec3::new(v[3], v[4], v[5]));
                b.validate().map_err(|e| e.to_string())?;
                Op::Query(Query::Aabb(b))
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
                Op::Query(Query::Ray(ray))
            }
            "frustum" => {
                const NAMES: [&str; 16] = [
                    "M00", "M01", "M02", "M03", "M10", "M11", "M12", "M13", "M20", "M21", "M22",
                    "M23", "M30", "M31", "M32", "M33",
                ];
                let v = numbers::<16>(cmd, args, &NAMES)?;
                let fr = Frustum::from_view_projection(Mat4::from_cols_array(&v))
                    .and_then(|fr| fr.validate().map(|()| fr))
                    .map_err(|e| format!("bad view-projection matrix: {e}"))?;
                Op::Query(Query::Frustum(Box::new(fr)))
            }
            other => return Err(format!("unknown command '{}'", lex::clip(other))),
        };
        self.trace.ops.push(op);
        Ok(())
    }

    fn insert(&mut self, id: u64) -> Res<u32> {
        let slot = match self.slot_of.get(&id) {
            Some(&s) if self.live[s as usize] => return Err(format!("id {id} is already present")),
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

#[cfg(test)]
mod tests {
    use super::*;

    fn err(text: &str) -> ParseError {
        Trace::parse(text.as_bytes()).unwrap_err()
    }

    #[test]
    fn parses_every_kind_with_comments_and_blank_lines() {
        let t = Trace::parse(
            b"# header\n\ninsert 7 0 0 0 1  # a comment\r\nmove 7 1 2 3 0.5\npairs\n\
              sphere 0 0 0 1\naabb 0 0 0 1 1 1\nray 0 0 0 1 0 0 5\n\
              frustum 1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1\nremove 7\ninsert 7 0 0 0 1\n",
        )
        .unwrap();
        let kinds: Vec<_> = t.ops.iter().map(|o| o.kind().name()).collect();
        assert_eq!(
            kinds,
            ["insert", "move", "pairs", "sphere", "aabb", "ray", "frustum", "remove", "insert"]
        );
        assert_eq!(t.lines, [3, 4, 5, 6, 7, 8, 9, 10, 11]);
        assert_eq!(t.ids, [7]);
        assert_eq!(t.max_live, 1);
        assert_eq!(t.query_count(), 5);
        for (i, k) in Kind::ALL.iter().enumerate() {
            assert_eq!(*k as usize, i);
        }
    }

    #[test]
    fn reports_line_and_reason() {
        let e = err("insert 1 0 0 0 1\n\nmove 2 0 0 0 1\n");
        assert_eq!(e.line, 3);
        assert_eq!(e.message, "unknown id 2");
        assert_eq!(err("insert 1 0 0 0 1\ninsert 1 0 0 0 1").line, 2);
        assert!(err("frob").message.contains("unknown command"));
        assert!(err("insert 1 0 0 0").message.contains("expects 5 fields"));
        assert!(err("pairs 3").message.contains("takes no fields"));
        assert!(err("sphere 0 0 0 -1").message.contains("negative radius"));
        assert!(err("sphere 0 nan 0 1").message.contains("not finite"));
        assert!(err("ray 0 0 0 1 0 0 inf")
            .message
            .contains("TMAX is not finite"));
        assert!(err("ray 0 0 0 1 0 0 -1").message.contains("max_t"));
        assert!(err("ray 0 0 0 0 0 0 1").message.contains("zero"));
        assert!(err("aabb 1 0 0 0 1 1").message.contains("min exceeds max"));
        assert!(err("insert -1 0 0 0 1").message.contains("bad id"));
        assert!(err("remove 1").message.contains("unknown id 1"));
        assert!(err(&"pairs ".repeat(20))
            .message
            .contains("too many fields"));
        // A zero matrix is degenerate but defined (zero-normal planes keep all).
        assert!(Trace::parse(b"frustum 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0").is_ok());
        assert!(Trace::parse(b"insert 1 0 0 0 1\n\xff\n").unwrap_err().line == 2);
    }

    #[test]
    fn hint_covers_moves() {
        let t = Trace::parse(b"insert 1 0 0 0 1\nmove 1 10 20 30 2\n").unwrap();
        let h = t.scene_hint();
        assert_eq!(h.world.max, Vec3::new(10.0, 20.0, 30.0));
        assert_eq!(h.max_live, 1);
    }
}
