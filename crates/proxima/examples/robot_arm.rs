//! A robot arm among obstacles: link meshes posed by joint angles (forward
//! kinematics), adjacent links ignored (the allowed-collision matrix), each
//! step checked for self-collision and collision with the environment, plus a
//! range-finder ray from the gripper and a safety zone around the base.
//!
//! `cargo run --release --example robot_arm`
//!
//! The links are the decimated Kinova Jaco meshes of the shared test data
//! (`forearm.stl`, `hand_3finger.stl`); the base and the obstacles are built
//! here. Swap in your own meshes with `Shape::load`.

use proxima::broad::Filter;
use proxima::geom::Ray;
use proxima::glam::{Affine3A, Quat, Vec3};
use proxima::narrow::Mesh;
use proxima::world::{Shape, World, WorldConfig};
use proxima::Handle;

/// Collision groups: links collide with links and with the environment, the
/// environment only with links (obstacles never test each other).
const ROBOT: u32 = 1;
const ENV: u32 = 2;

/// An axis-aligned box mesh of half extents `h` around the origin.
fn cuboid(h: Vec3) -> proxima::Result<Shape> {
    let v = (0..8)
        .map(|i| {
            Vec3::new(
                if i & 1 == 0 { -h.x } else { h.x },
                if i & 2 == 0 { -h.y } else { h.y },
                if i & 4 == 0 { -h.z } else { h.z },
            )
        })
        .collect();
    let quads = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    let t = quads
        .iter()
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .collect();
    Ok(Mesh::new(v, t)?.into())
}

/// One link: its shape, where it sits in its joint's frame, and the joint that
/// moves it (rotation axis in the parent link's frame, offset from the parent
/// joint).
struct Link {
    name: &'static str,
    shape: Shape,
    visual: Affine3A,
    axis: Vec3,
    offset: Vec3,
}

/// Forward kinematics: each link's world pose for the joint angles `q`.
fn link_poses(links: &[Link], q: &[f32]) -> Vec<Affine3A> {
    let mut frame = Affine3A::IDENTITY;
    links
        .iter()
        .zip(q)
        .map(|(l, &angle)| {
            frame = frame
                * Affine3A::from_translation(l.offset)
                * Affine3A::from_quat(Quat::from_axis_angle(l.axis, angle));
            frame * l.visual
        })
        .collect()
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let data = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data");
    // A link mesh is loaded once and shared: both arm segments use the forearm.
    let segment: Shape = Shape::load(format!("{data}/forearm.stl"))?;
    let hand: Shape = Shape::load(format!("{data}/hand_3finger.stl"))?;
    // The forearm mesh runs along +y from its joint; the hand along -z, so it
    // is turned to run along +y too.
    let along_y = Affine3A::from_quat(Quat::from_rotation_x(std::f32::consts::FRAC_PI_2));
    let links = [
        Link {
            name: "base",
            shape: cuboid(Vec3::new(0.06, 0.06, 0.04))?,
            visual: Affine3A::IDENTITY,
            axis: Vec3::Z,
            offset: Vec3::ZERO,
        },
        Link {
            name: "upper arm",
            shape: segment.clone(),
            visual: Affine3A::IDENTITY,
            axis: Vec3::X,
            offset: Vec3::new(0.0, 0.0, 0.05),
        },
        Link {
            name: "lower arm",
            shape: segment,
            visual: Affine3A::IDENTITY,
            axis: Vec3::X,
            offset: Vec3::new(0.0, 0.2, 0.0),
        },
        Link {
            name: "hand",
            shape: hand,
            visual: along_y,
            axis: Vec3::Y,
            offset: Vec3::new(0.0, 0.2, 0.0),
        },
    ];

    // The default world: a loose k-d tree built from the scene at the first
    // query, k-DOP-18 trees, temporal coherence on.
    let mut world: World<&'static str> = World::new(WorldConfig::default())?;
    let arm = Filter::new(ROBOT, ROBOT | ENV);
    let env = Filter::new(ENV, ROBOT);
    let zero = [0.0; 4];
    let mut handles: Vec<Handle> = Vec::new();
    for (l, pose) in links.iter().zip(link_poses(&links, &zero)) {
        handles.push(world.insert_with_filter(l.shape.clone(), pose, l.name, arm)?);
    }
    // Adjacent links always touch at their joints: never report them.
    for w in handles.windows(2) {
        world.ignore(w[0], w[1])?;
    }
    // The environment: a shelf, a post and a ball-shaped lamp.
    let at = Affine3A::from_translation;
    world.insert_with_filter(
        cuboid(Vec3::new(0.2, 0.05, 0.01))?,
        at(Vec3::new(0.0, 0.32, 0.12)),
        "shelf",
        env,
    )?;
    world.insert_with_filter(
        cuboid(Vec3::new(0.02, 0.02, 0.3))?,
        at(Vec3::new(-0.25, 0.1, 0.0)),
        "post",
        env,
    )?;
    world.insert_with_filter(
        Shape::sphere(0.05)?,
        at(Vec3::new(0.15, 0.3, 0.35)),
        "lamp",
        env,
    )?;

    let steps = 40;
    let mut colliding_steps = 0;
    for step in 0..=steps {
        // A trajectory: turn the base, lift and bend the arm, roll the hand.
        let s = step as f32 / steps as f32;
        let q = [
            -0.8 + 1.6 * s,
            0.9 * (s * std::f32::consts::PI).sin(),
            -1.2 * s,
            3.0 * s,
        ];
        let poses: Vec<_> = handles
            .iter()
            .copied()
            .zip(link_poses(&links, &q))
            .collect();
        world.set_poses(&poses)?;
        // One witness per colliding pair is enough to reject a configuration.
        let report = world.contacts_first()?;
        let names: Vec<String> = report
            .pairs
            .iter()
            .map(|c| format!("{} × {}", world.get(c.a).unwrap(), world.get(c.b).unwrap()))
            .collect();
        // A range finder along the hand's axis, seeing only the environment.
        let tip = poses[3].1;
        let beam = Ray::with_max_t(
            tip.transform_point3(Vec3::ZERO),
            tip.transform_vector3(Vec3::NEG_Z),
            1.0,
        );
        let range = world.ray_cast(&beam, Filter::new(ROBOT, ENV))?;
        // Anything (robot or environment) within 5 cm of the base's top?
        let near_base = world.overlap_sphere(Vec3::new(0.0, 0.0, 0.06), 0.05, Filter::ALL)?;
        let c = report.counters;
        if !names.is_empty() {
            colliding_steps += 1;
        }
        println!(
            "step {step:2}: {:<32} range {:<14} near base {}  (pairs tested {}, BV tests {})",
            if names.is_empty() {
                "free".to_string()
            } else {
                names.join(", ")
            },
            range.map_or("-".to_string(), |h| format!(
                "{:.3} ({})",
                h.t,
                world.get(h.object).unwrap()
            )),
            near_base.len(),
            c.narrow_pairs,
            c.cost.nv,
        );
    }
    println!("{colliding_steps} of {} configurations collide", steps + 1);
    world.validate()?;
    Ok(())
}
