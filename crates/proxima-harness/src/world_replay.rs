//! A world trace run on a [`World`] or on the brute-force world, one answer per
//! query line, with the time spent per operation kind [sources: world-trace].

use crate::world_oracle::BruteWorld;
use crate::world_trace::{WorldOp, WorldTrace};
use proxima::broad::Filter;
use proxima::geom::{Aabb, Sphere};
use proxima::glam::Affine3A;
use proxima::narrow::{BoundingVolume, BuildOptions, Kdop14, Kdop18, Kdop26, Mesh, Obb};
use proxima::world::{ContactMode, ContactReport, Shape, World, WorldConfig};
use proxima::Handle;
use std::fmt;
use std::time::{Duration, Instant};

/// The answer to one query line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WorldAnswer {
    /// Object pairs in contact, and (all-pairs mode) intersecting triangle pairs.
    Contacts(usize, Option<usize>),
    /// The user id and triangle hit first, if any.
    Ray(Option<(u64, u32)>),
    /// Objects with a triangle within the radius.
    Sphere(usize),
}

impl fmt::Display for WorldAnswer {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            WorldAnswer::Contacts(p, Some(t)) => write!(f, "contacts {p} {t}"),
            WorldAnswer::Contacts(p, None) => write!(f, "contacts {p}"),
            WorldAnswer::Ray(Some((id, tri))) => write!(f, "ray {id} {tri}"),
            WorldAnswer::Ray(None) => write!(f, "ray -"),
            WorldAnswer::Sphere(k) => write!(f, "sphere {k}"),
        }
    }
}

/// What one run produced over a trace.
#[derive(Debug)]
pub struct WorldRun {
    /// The run's name in timing tables (the index kind, or `oracle`).
    pub name: String,
    /// One answer per query line, in trace order.
    pub answers: Vec<WorldAnswer>,
    /// Total time and count per operation kind, in
    /// [`WorldKind::ALL`](crate::world_trace::WorldKind::ALL) order.
    pub time: [(Duration, usize); 8],
}

/// Runs `trace` on a [`World`] built with `config`; with `first`, contacts in
/// first-contact mode. An error is `(op position, message)`: the world
/// rejected an operation the parser let through (a pose beyond the world's
/// coordinate limit).
pub fn run_world<BV: BoundingVolume>(
    trace: &WorldTrace,
    config: WorldConfig,
    first: bool,
) -> Result<WorldRun, (usize, String)> {
    let mut world: World<u64, BV> = World::new(config).map_err(|e| (0, e.to_string()))?;
    let mut shapes: Vec<Option<Shape<BV>>> = vec![None; trace.meshes.len()];
    let mut handles: Vec<Option<Handle>> = vec![None; trace.ids.len()];
    let mut report = ContactReport::default();
    let mode = if first {
        ContactMode::First
    } else {
        ContactMode::All
    };
    let mut answers = Vec::with_capacity(trace.query_count());
    let mut time = [(Duration::ZERO, 0usize); 8];
    for (pos, op) in trace.ops.iter().enumerate() {
        let start = Instant::now();
        let res = apply(
            &mut world,
            &mut shapes,
            &mut handles,
            trace,
            op,
            mode,
            &mut report,
        );
        let k = op.kind() as usize;
        time[k].0 += start.elapsed();
        time[k].1 += 1;
        match res {
            Ok(Some(a)) => answers.push(a),
            Ok(None) => {}
            Err(e) => return Err((pos, e.to_string())),
        }
    }
    let name = world
        .index_kind()
        .or(config.index)
        .map_or("world".to_string(), |k| k.name().to_string());
    Ok(WorldRun {
        name,
        answers,
        time,
    })
}

/// Applies one operation to the world; a query returns its answer.
fn apply<BV: BoundingVolume>(
    world: &mut World<u64, BV>,
    shapes: &mut [Option<Shape<BV>>],
    handles: &mut [Option<Handle>],
    trace: &WorldTrace,
    op: &WorldOp,
    mode: ContactMode,
    report: &mut ContactReport,
) -> proxima::Result<Option<WorldAnswer>> {
    // The parser guarantees liveness; a missing handle would be a parser bug.
    let live = |h: Option<Handle>| h.ok_or(proxima::Error::StaleHandle);
    Ok(match *op {
        WorldOp::Mesh { mesh } => {
            let m = &trace.meshes[mesh as usize];
            let built = Mesh::from_trimesh((**m).clone(), BuildOptions::default())?;
            // Rays will be cast: build the ray tree now, with the mesh.
            built.ray_bvh();
            shapes[mesh as usize] = Some(built.into());
            None
        }
        WorldOp::Add { slot, mesh } => {
            let shape = shapes[mesh as usize]
                .clone()
                .expect("parsed after its mesh");
            let id = trace.ids[slot as usize];
            handles[slot as usize] = Some(world.insert(shape, Affine3A::IDENTITY, id)?);
            None
        }
        WorldOp::Pose { slot, pose } => {
            world.set_pose(live(handles[slot as usize])?, pose)?;
            None
        }
        WorldOp::Remove { slot } => {
            world.remove(live(handles[slot as usize].take())?)?;
            None
        }
        WorldOp::Ignore { a, b } => {
            world.ignore(live(handles[a as usize])?, live(handles[b as usize])?)?;
            None
        }
        WorldOp::Contacts => {
            world.contacts_into(mode, report)?;
            let tris = (mode == ContactMode::All).then_some(report.triangles.len());
            Some(WorldAnswer::Contacts(report.pairs.len(), tris))
        }
        WorldOp::Ray(ray) => {
            // Ties between objects go to the smaller user id, so every object's
            // first hit is needed, not the world's first.
            let mut best: Option<(f32, u64, u32)> = None;
            for h in world.ray_hits(&ray, Filter::ALL)? {
                let key = (h.t, *world.get(h.object)?, h.triangle);
                if best.is_none_or(|b| key < b) {
                    best = Some(key);
                }
            }
            Some(WorldAnswer::Ray(best.map(|(_, id, tri)| (id, tri))))
        }
        WorldOp::Sphere(s) => {
            let near = world.overlap_sphere(s.center, s.radius, Filter::ALL)?;
            Some(WorldAnswer::Sphere(near.len()))
        }
    })
}

/// Runs `trace` on the brute-force world.
pub fn run_oracle(trace: &WorldTrace, first: bool) -> WorldRun {
    let mut brute = BruteWorld::new(trace, first);
    let mut answers = Vec::with_capacity(trace.query_count());
    let mut time = [(Duration::ZERO, 0usize); 8];
    for op in &trace.ops {
        let start = Instant::now();
        let a = brute.apply(op);
        let k = op.kind() as usize;
        time[k].0 += start.elapsed();
        time[k].1 += 1;
        answers.extend(a);
    }
    WorldRun {
        name: "oracle".into(),
        answers,
        time,
    }
}

/// The position of the first answer where `other` differs from `reference` (a
/// missing answer counts as a difference), or `None` when they agree.
pub fn first_difference(reference: &[WorldAnswer], other: &[WorldAnswer]) -> Option<usize> {
    let n = reference.len().min(other.len());
    (0..n)
        .find(|&i| reference[i] != other[i])
        .or((reference.len() != other.len()).then_some(n))
}

/// The bounding volumes by name.
pub const BVS: [&str; 6] = ["aabb", "kdop14", "kdop18", "kdop26", "obb", "sphere"];

/// Runs a parsed trace on the world with bounding volume `bv` (one of [`BVS`]).
pub fn run_bv(
    bv: &str,
    trace: &WorldTrace,
    config: WorldConfig,
    first: bool,
) -> Result<WorldRun, (usize, String)> {
    match bv {
        "aabb" => run_world::<Aabb>(trace, config, first),
        "kdop14" => run_world::<Kdop14>(trace, config, first),
        "kdop18" => run_world::<Kdop18>(trace, config, first),
        "kdop26" => run_world::<Kdop26>(trace, config, first),
        "obb" => run_world::<Obb>(trace, config, first),
        "sphere" => run_world::<Sphere>(trace, config, first),
        other => Err((0, format!("unknown bounding volume '{other}'"))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn first_difference_finds_changed_and_missing_answers() {
        let a = [
            WorldAnswer::Contacts(1, Some(2)),
            WorldAnswer::Ray(Some((3, 4))),
            WorldAnswer::Sphere(5),
        ];
        assert_eq!(first_difference(&a, &a), None);
        let mut b = a;
        b[1] = WorldAnswer::Ray(Some((3, 5)));
        assert_eq!(first_difference(&a, &b), Some(1));
        b = a;
        b[0] = WorldAnswer::Contacts(1, None);
        assert_eq!(first_difference(&a, &b), Some(0));
        assert_eq!(first_difference(&a, &a[..2]), Some(2));
        assert_eq!(first_difference(&a[..2], &a), Some(2));
        let shown: Vec<String> = a.iter().map(ToString::to_string).collect();
        assert_eq!(shown, ["contacts 1 2", "ray 3 4", "sphere 5"]);
        assert_eq!(WorldAnswer::Ray(None).to_string(), "ray -");
        assert_eq!(WorldAnswer::Contacts(7, None).to_string(), "contacts 7");
    }
}
