//! The world workloads as world traces ([sources: world-trace]): a tumble of a few
//! hundred meshes, robot arms among obstacles, a deep interpenetration
//! (SKINbody through BONERibcage) and a churn of objects added and removed, each
//! with every object moving or a tenth of them. Generated deterministically from
//! a seed, kept in memory as [`Op`]s for Proxima and written as trace text (with
//! the scaled meshes as OBJ files) for the peers.

use proxima::glam::{Affine3A, Quat, Vec3};
use proxima::narrow::TriMesh;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The folder of the shared meshes.
pub const DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data/");

/// The scenes by name, in table order.
pub const SCENES: [&str; 7] = [
    "tumble-all",
    "tumble-10",
    "arm-all",
    "arm-10",
    "deep",
    "churn-all",
    "churn-10",
];

/// One line of a world trace.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Op {
    /// `add ID NAME` (the mesh by number).
    Add {
        /// The object's id.
        id: u64,
        /// The mesh, an index into [`Scene::meshes`].
        mesh: usize,
    },
    /// `pose ID …`.
    Pose {
        /// The object's id.
        id: u64,
        /// Its new pose.
        pose: Affine3A,
    },
    /// `remove ID`.
    Remove {
        /// The object's id.
        id: u64,
    },
    /// `ignore ID1 ID2`.
    Ignore(u64, u64),
    /// `contacts`.
    Contacts,
}

/// A mesh of a scene: its trace name, its file, its triangles.
#[derive(Clone, Debug)]
pub struct SceneMesh {
    /// The word after `mesh`.
    pub name: String,
    /// Where the trace's `mesh` line points (absolute).
    pub file: PathBuf,
    /// The geometry, as read back from `file`.
    pub mesh: TriMesh,
}

/// A generated workload.
#[derive(Clone, Debug)]
pub struct Scene {
    /// Its name ([`SCENES`]).
    pub name: String,
    /// Its meshes.
    pub meshes: Vec<SceneMesh>,
    /// The trace's lines after the `mesh` lines.
    pub ops: Vec<Op>,
    /// Objects alive at the end, and how many move per frame (their mean).
    pub objects: usize,
    /// See `objects`.
    pub moving: f64,
}

impl Scene {
    /// Number of `contacts` lines (frames).
    pub fn frames(&self) -> usize {
        self.ops.iter().filter(|o| **o == Op::Contacts).count()
    }

    /// The trace text.
    pub fn trace(&self) -> String {
        let mut s = format!("# proxima-bench world scene {}\n", self.name);
        for m in &self.meshes {
            let _ = writeln!(s, "mesh {} {}", m.name, m.file.display());
        }
        for op in &self.ops {
            let _ = match *op {
                Op::Add { id, mesh } => writeln!(s, "add {id} {}", self.meshes[mesh].name),
                Op::Pose { id, pose } => {
                    let m = pose.matrix3;
                    let r = |i: usize| [m.x_axis[i], m.y_axis[i], m.z_axis[i]];
                    let t = pose.translation;
                    let nums: Vec<String> = [r(0), r(1), r(2), [t.x, t.y, t.z]]
                        .iter()
                        .flatten()
                        .map(|v| format!("{v}"))
                        .collect();
                    writeln!(s, "pose {id} {}", nums.join(" "))
                }
                Op::Remove { id } => writeln!(s, "remove {id}"),
                Op::Ignore(a, b) => writeln!(s, "ignore {a} {b}"),
                Op::Contacts => writeln!(s, "contacts"),
            };
        }
        s
    }
}

/// Loads `file` from the shared meshes, scaled to a longest side of `size` about
/// its box's centre, written to `dir/NAME.obj` (each `f32` printed so that it
/// reads back identically) and read back, so that Proxima and the peers use the
/// same numbers.
fn scaled(dir: &Path, name: &str, file: &str, size: f32) -> Result<SceneMesh, String> {
    let src = Path::new(DATA).join(file);
    let m = proxima::io::load(&src).map_err(|e| format!("{}: {e}", src.display()))?;
    let (lo, hi) = m
        .vertices()
        .iter()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(*v), hi.max(*v))
        });
    let (c, s) = ((lo + hi) * 0.5, size / (hi - lo).max_element());
    let mut text = String::new();
    for v in m.vertices() {
        let p = (*v - c) * s;
        let _ = writeln!(text, "v {} {} {}", p.x, p.y, p.z);
    }
    for t in m.triangles() {
        let _ = writeln!(text, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let out = dir.join(format!("{name}.obj"));
    std::fs::write(&out, text).map_err(|e| format!("{}: {e}", out.display()))?;
    let mesh = proxima::io::load(&out).map_err(|e| format!("{}: {e}", out.display()))?;
    let file = out.canonicalize().unwrap_or(out);
    Ok(SceneMesh {
        name: name.into(),
        file,
        mesh,
    })
}

/// A shared mesh as it is.
fn shared(name: &str, file: &str) -> Result<SceneMesh, String> {
    let src = Path::new(DATA).join(file);
    let mesh = proxima::io::load(&src).map_err(|e| format!("{}: {e}", src.display()))?;
    let file = src.canonicalize().unwrap_or(src);
    Ok(SceneMesh {
        name: name.into(),
        file,
        mesh,
    })
}

fn unit(rng: &mut Pcg64) -> Vec3 {
    loop {
        let v = Vec3::new(
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
        );
        if (0.01..=1.0).contains(&v.length_squared()) {
            return v.normalize();
        }
    }
}

/// A tumbling object: position, velocity, rotation axis, angle, spin.
#[derive(Clone, Copy, Debug)]
struct Body {
    pos: Vec3,
    vel: Vec3,
    axis: Vec3,
    angle: f32,
    spin: f32,
}

impl Body {
    fn random(rng: &mut Pcg64, side: f32) -> Body {
        Body {
            pos: Vec3::new(
                rng.gen_range(0.5..side - 0.5),
                rng.gen_range(0.5..side - 0.5),
                rng.gen_range(0.5..side - 0.5),
            ),
            vel: unit(rng) * rng.gen_range(0.02..0.08),
            axis: unit(rng),
            angle: rng.gen_range(0.0..std::f32::consts::TAU),
            spin: rng.gen_range(0.02..0.1),
        }
    }
    fn pose(&self) -> Affine3A {
        Affine3A::from_rotation_translation(Quat::from_axis_angle(self.axis, self.angle), self.pos)
    }
    fn step(&mut self, side: f32) {
        self.pos += self.vel;
        self.angle = (self.angle + self.spin) % std::f32::consts::TAU;
        for k in 0..3 {
            if self.pos[k] < 0.5 || self.pos[k] > side - 0.5 {
                self.vel[k] = -self.vel[k];
                self.pos[k] = self.pos[k].clamp(0.5, side - 0.5);
            }
        }
    }
}

/// The five unit meshes of the tumble and churn scenes.
fn unit_meshes(dir: &Path) -> Result<Vec<SceneMesh>, String> {
    [
        ("bunny", "bunny.obj"),
        ("teapot", "teapot.obj"),
        ("rob", "rob.obj"),
        ("hand", "hand_3finger.stl"),
        ("forearm", "forearm.stl"),
    ]
    .iter()
    .map(|(n, f)| scaled(dir, n, f, 1.0))
    .collect()
}

/// Whether object `id` is one of the tenth that move in a `-10` scene: one id
/// in each block of ten, at a place that shifts from block to block. Objects
/// take the five unit meshes in turn (`id % 5`), so every mesh moves equally
/// often; `id % 10 == 0` made every mover a bunny (3,674 triangles, the
/// costliest mesh by far), and the 10% frame measured bunny pairs rather than a
/// tenth of the scene.
fn tenth(id: u64) -> bool {
    (id + id / 10).is_multiple_of(10)
}

/// `n` unit meshes tumbling in a box (about 4 unit cells each), `frames`
/// frames; every object moves, or one in ten (`all` false).
fn tumble(dir: &Path, n: usize, frames: usize, all: bool, seed: u64) -> Result<Scene, String> {
    let meshes = unit_meshes(dir)?;
    let side = (n as f32 * 4.0).cbrt().max(3.0);
    let mut rng = Pcg64::seed_from_u64(seed);
    let mut bodies: Vec<Body> = (0..n).map(|_| Body::random(&mut rng, side)).collect();
    let mut ops = Vec::new();
    for (i, b) in bodies.iter().enumerate() {
        ops.push(Op::Add {
            id: i as u64,
            mesh: i % meshes.len(),
        });
        ops.push(Op::Pose {
            id: i as u64,
            pose: b.pose(),
        });
    }
    ops.push(Op::Contacts);
    let moves = |i: usize| all || tenth(i as u64);
    for _ in 0..frames {
        for (i, b) in bodies.iter_mut().enumerate().filter(|(i, _)| moves(*i)) {
            b.step(side);
            ops.push(Op::Pose {
                id: i as u64,
                pose: b.pose(),
            });
        }
        ops.push(Op::Contacts);
    }
    let moving = (0..n).filter(|&i| moves(i)).count() as f64;
    Ok(Scene {
        name: format!("tumble-{}", if all { "all" } else { "10" }),
        meshes,
        ops,
        objects: n,
        moving,
    })
}

/// Links per arm.
const LINKS: usize = 6;

/// `arms` robot arms of [`LINKS`] links (forearm meshes of length 1, a hand at
/// the tip), adjacent links ignored, on a row among fixed obstacles (teapots and
/// bunnies); every arm moves its joints each frame, or one in ten.
fn arm(dir: &Path, arms: usize, frames: usize, all: bool, seed: u64) -> Result<Scene, String> {
    let meshes = vec![
        scaled(dir, "link", "forearm.stl", 1.0)?,
        scaled(dir, "hand", "hand_3finger.stl", 0.8)?,
        scaled(dir, "teapot", "teapot.obj", 1.2)?,
        scaled(dir, "bunny", "bunny.obj", 1.2)?,
    ];
    // The link's long axis: its box's longest side.
    let (lo, hi) = meshes[0]
        .mesh
        .vertices()
        .iter()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(*v), hi.max(*v))
        });
    let e = hi - lo;
    let long = if e.x >= e.y && e.x >= e.z {
        Vec3::X
    } else if e.y >= e.z {
        Vec3::Y
    } else {
        Vec3::Z
    };
    // Rotate the long axis onto z: links stack upwards at the zero angles.
    let to_z = Quat::from_rotation_arc(long, Vec3::Z);
    let mut rng = Pcg64::seed_from_u64(seed);
    let spacing = 3.0;
    let mut ops = Vec::new();
    let mut id = 0u64;
    // Obstacles: fixed, between and around the arms.
    let obstacles = arms * 4;
    for k in 0..obstacles {
        let p = Vec3::new(
            rng.gen_range(-2.0..arms as f32 * spacing + 2.0),
            rng.gen_range(-3.0..3.0),
            rng.gen_range(0.5..LINKS as f32),
        );
        ops.push(Op::Add {
            id,
            mesh: 2 + k % 2,
        });
        ops.push(Op::Pose {
            id,
            pose: Affine3A::from_rotation_translation(
                Quat::from_axis_angle(unit(&mut rng), rng.gen_range(0.0..std::f32::consts::TAU)),
                p,
            ),
        });
        id += 1;
    }
    let phases: Vec<[f32; LINKS + 1]> = (0..arms)
        .map(|_| std::array::from_fn(|_| rng.gen_range(0.0..std::f32::consts::TAU)))
        .collect();
    let first_link = id;
    let link_id = |a: usize, l: usize| first_link + (a * (LINKS + 1) + l) as u64;
    for a in 0..arms {
        for l in 0..=LINKS {
            ops.push(Op::Add {
                id: link_id(a, l),
                mesh: if l == LINKS { 1 } else { 0 },
            });
            if l > 0 {
                ops.push(Op::Ignore(link_id(a, l - 1), link_id(a, l)));
            }
        }
    }
    // Forward kinematics: joint l turns about x (even) or y (odd) by a sine of
    // the frame.
    let chain = |a: usize, f: usize| -> Vec<Affine3A> {
        let mut joint = Affine3A::from_translation(Vec3::new(a as f32 * spacing, 0.0, 0.0));
        let mut out = Vec::with_capacity(LINKS + 1);
        for (l, phase) in phases[a].iter().enumerate() {
            let axis = if l % 2 == 0 { Vec3::X } else { Vec3::Y };
            let angle = 0.6 * (0.05 * f as f32 + phase).sin();
            joint *= Affine3A::from_quat(Quat::from_axis_angle(axis, angle));
            let centre = joint * Affine3A::from_translation(Vec3::new(0.0, 0.0, 0.5));
            out.push(centre * Affine3A::from_quat(to_z));
            joint = centre * Affine3A::from_translation(Vec3::new(0.0, 0.0, 0.55));
        }
        out
    };
    let moves = |a: usize| all || a.is_multiple_of(10);
    for f in 0..=frames {
        for a in (0..arms).filter(|&a| f == 0 || moves(a)) {
            for (l, pose) in chain(a, f).into_iter().enumerate() {
                ops.push(Op::Pose {
                    id: link_id(a, l),
                    pose,
                });
            }
        }
        ops.push(Op::Contacts);
    }
    let moving = ((0..arms).filter(|&a| moves(a)).count() * (LINKS + 1)) as f64;
    Ok(Scene {
        name: format!("arm-{}", if all { "all" } else { "10" }),
        meshes,
        ops,
        objects: obstacles + arms * (LINKS + 1),
        moving,
    })
}

/// SKINbody fixed and BONERibcage (74k triangles) moving inside it by small
/// turns and shifts: deep interpenetration, thousands of triangle pairs.
fn deep(frames: usize) -> Result<Scene, String> {
    let meshes = vec![
        shared("skin", "SKINbody.stl")?,
        shared("ribcage", "BONERibcage.stl")?,
    ];
    // The ribcage's box centre on the skin's, then small turns and shifts (a
    // hundredth of the skin's size).
    let centre = |m: &TriMesh| {
        let (lo, hi) = m
            .vertices()
            .iter()
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), v| {
                (lo.min(*v), hi.max(*v))
            });
        ((lo + hi) * 0.5, (hi - lo).max_element())
    };
    let ((cs, size), (cr, _)) = (centre(&meshes[0].mesh), centre(&meshes[1].mesh));
    let mut ops = vec![Op::Add { id: 1, mesh: 0 }, Op::Add { id: 2, mesh: 1 }];
    for f in 0..=frames {
        let t = f as f32 * 0.3;
        let turn = Quat::from_rotation_z(0.05 * t.sin()) * Quat::from_rotation_x(0.03 * t.cos());
        let shift = Vec3::new(t.sin(), t.cos(), 0.5 * t.sin()) * (0.01 * size);
        let pose = Affine3A::from_rotation_translation(turn, cs + shift - turn * cr);
        ops.push(Op::Pose { id: 2, pose });
        ops.push(Op::Contacts);
    }
    Ok(Scene {
        name: "deep".into(),
        meshes,
        ops,
        objects: 2,
        moving: 1.0,
    })
}

/// `n` unit meshes tumbling; every frame a tenth of them (the oldest) are
/// removed and as many added at new places; every object moves, or only the
/// newcomers and one in ten of the others.
fn churn(dir: &Path, n: usize, frames: usize, all: bool, seed: u64) -> Result<Scene, String> {
    let meshes = unit_meshes(dir)?;
    let side = (n as f32 * 4.0).cbrt().max(3.0);
    let mut rng = Pcg64::seed_from_u64(seed);
    let mut live: std::collections::VecDeque<(u64, Body)> = std::collections::VecDeque::new();
    let mut ops = Vec::new();
    let mut next = 0u64;
    let mut add =
        |ops: &mut Vec<Op>, live: &mut std::collections::VecDeque<(u64, Body)>, rng: &mut Pcg64| {
            let b = Body::random(rng, side);
            ops.push(Op::Add {
                id: next,
                mesh: (next % meshes.len() as u64) as usize,
            });
            ops.push(Op::Pose {
                id: next,
                pose: b.pose(),
            });
            live.push_back((next, b));
            next += 1;
        };
    for _ in 0..n {
        add(&mut ops, &mut live, &mut rng);
    }
    ops.push(Op::Contacts);
    let turnover = (n / 10).max(1);
    let mut moved = 0usize;
    for _ in 0..frames {
        for _ in 0..turnover {
            if let Some((id, _)) = live.pop_front() {
                ops.push(Op::Remove { id });
            }
        }
        for (id, b) in live.iter_mut().filter(|(id, _)| all || tenth(*id)) {
            b.step(side);
            ops.push(Op::Pose {
                id: *id,
                pose: b.pose(),
            });
            moved += 1;
        }
        for _ in 0..turnover {
            add(&mut ops, &mut live, &mut rng);
        }
        moved += turnover;
        ops.push(Op::Contacts);
    }
    Ok(Scene {
        name: format!("churn-{}", if all { "all" } else { "10" }),
        meshes,
        ops,
        objects: n,
        moving: moved as f64 / frames.max(1) as f64,
    })
}

/// Sizes of the scenes.
#[derive(Clone, Copy, Debug)]
pub struct Sizes {
    /// Objects of the tumble and churn scenes.
    pub n: usize,
    /// Arms of the arm scenes.
    pub arms: usize,
    /// Frames of every scene (the deep scene: a third of them).
    pub frames: usize,
}

/// Generates scene `name` ([`SCENES`]), writing its scaled meshes to `dir`.
pub fn generate(name: &str, dir: &Path, sizes: Sizes, seed: u64) -> Result<Scene, String> {
    let meshes = dir.join("meshes");
    let Sizes { n, arms, frames } = sizes;
    match name {
        "tumble-all" => tumble(&meshes, n, frames, true, seed),
        "tumble-10" => tumble(&meshes, n, frames, false, seed),
        "arm-all" => arm(&meshes, arms, frames, true, seed),
        "arm-10" => arm(&meshes, arms, frames, false, seed),
        "deep" => deep((frames / 3).max(1)),
        "churn-all" => churn(&meshes, n * 2 / 3, frames, true, seed),
        "churn-10" => churn(&meshes, n * 2 / 3, frames, false, seed),
        other => Err(format!(
            "unknown world scene {other:?} (known: {})",
            SCENES.join(", ")
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashSet;

    /// Every scene is a valid trace: poses, removes and ignores name live ids,
    /// adds new ones, and the text has one line per op.
    #[test]
    fn every_scene_is_a_consistent_trace() {
        let dir = std::env::temp_dir().join(format!("proxima-bench-world-{}", std::process::id()));
        let sizes = Sizes {
            n: 30,
            arms: 2,
            frames: 3,
        };
        for name in SCENES {
            let s = generate(name, &dir, sizes, 4).unwrap();
            assert_eq!(s.name, name);
            let mut live = HashSet::new();
            for op in &s.ops {
                match *op {
                    Op::Add { id, mesh } => assert!(live.insert(id) && mesh < s.meshes.len()),
                    Op::Pose { id, pose } => {
                        assert!(live.contains(&id), "{name}");
                        proxima::narrow::check_pose(&pose).unwrap();
                    }
                    Op::Remove { id } => assert!(live.remove(&id)),
                    Op::Ignore(a, b) => assert!(a != b && live.contains(&a) && live.contains(&b)),
                    Op::Contacts => {}
                }
            }
            assert_eq!(live.len(), s.objects, "{name}");
            assert!(s.frames() >= 2 && s.moving > 0.0);
            let text = s.trace();
            let lines = text.lines().filter(|l| !l.starts_with('#')).count();
            assert_eq!(lines, s.meshes.len() + s.ops.len());
            // The scaled meshes read back as the same numbers.
            for m in &s.meshes {
                assert_eq!(
                    proxima::io::load(&m.file).unwrap().vertices(),
                    m.mesh.vertices()
                );
            }
        }
        let _ = std::fs::remove_dir_all(dir);
    }

    /// The tenth that moves is a tenth of every mesh, not one mesh (the ids
    /// that are multiples of ten were all bunnies).
    #[test]
    fn the_moving_tenth_covers_every_mesh() {
        let dir = std::env::temp_dir().join(format!("proxima-bench-tenth-{}", std::process::id()));
        let sizes = Sizes {
            n: 100,
            arms: 1,
            frames: 2,
        };
        for name in ["tumble-10", "churn-10"] {
            let s = generate(name, &dir, sizes, 3).unwrap();
            let mesh_of: std::collections::HashMap<u64, usize> = s
                .ops
                .iter()
                .filter_map(|op| match *op {
                    Op::Add { id, mesh } => Some((id, mesh)),
                    _ => None,
                })
                .collect();
            // The poses of the last frame (after its last add, so no newcomer).
            let last = s.ops[..s.ops.len() - 1]
                .iter()
                .rposition(|op| matches!(op, Op::Contacts))
                .unwrap();
            let moved: Vec<u64> = s.ops[last + 1..]
                .iter()
                .take_while(|op| matches!(op, Op::Pose { .. } | Op::Remove { .. }))
                .filter_map(|op| match *op {
                    Op::Pose { id, .. } => Some(id),
                    _ => None,
                })
                .collect();
            let meshes: HashSet<usize> = moved.iter().map(|id| mesh_of[id]).collect();
            assert_eq!(meshes.len(), s.meshes.len(), "{name}: {moved:?}");
            if name == "tumble-10" {
                assert_eq!(moved.len(), 10);
            }
        }
        let _ = std::fs::remove_dir_all(dir);
    }
}
