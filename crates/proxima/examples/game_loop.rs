//! A game loop over a broad-phase index: spawn objects, move every one each
//! frame, find the touching pairs, and cull against a camera's view frustum.
//!
//! `cargo run --release --example game_loop`

use proxima::broad::{LooseKdTree, SpatialIndex, SpatialIndexExt};
use proxima::geom::{Aabb, Frustum, Sphere};
use proxima::glam::{Mat4, Vec3};

/// What the game keeps per object; the index stores a copy of the id as payload.
struct Body {
    handle: proxima::Handle,
    velocity: Vec3,
}

fn main() -> proxima::Result<()> {
    let world = Aabb::new(Vec3::ZERO, Vec3::splat(100.0));
    // Loose k-d tree: world box and largest typical radius [sources: kd-tree].
    let mut index = LooseKdTree::<usize>::new(world, 1.0)?;

    // Spawn 2000 bodies on a deterministic pseudo-random lattice.
    let mut bodies = Vec::new();
    for i in 0..2000usize {
        let f = i as f32;
        let p = Vec3::new((f * 7.31) % 100.0, (f * 3.17) % 100.0, (f * 1.93) % 100.0);
        let velocity = Vec3::new((f * 0.37).sin(), (f * 0.71).cos(), (f * 0.13).sin()) * 0.5;
        let handle = index.insert(Sphere::new(p, 0.5 + (i % 3) as f32 * 0.25), i)?;
        bodies.push(Body { handle, velocity });
    }

    // A camera in the middle of the world looking along +x (depth 0..1, as in wgpu).
    let view = Mat4::look_at_rh(Vec3::splat(50.0), Vec3::new(100.0, 50.0, 50.0), Vec3::Z);
    let proj = Mat4::perspective_rh(60f32.to_radians(), 16.0 / 9.0, 0.1, 200.0);
    let frustum = Frustum::from_view_projection(proj * view)?;

    for frame in 1..=10 {
        // Move every body, bouncing off the walls.
        for b in &mut bodies {
            let (mut s, _) = index.get(b.handle)?;
            s.center += b.velocity;
            for a in 0..3 {
                if !(0.0..=100.0).contains(&s.center[a]) {
                    b.velocity[a] = -b.velocity[a];
                    s.center[a] = s.center[a].clamp(0.0, 100.0);
                }
            }
            index.update(b.handle, s)?;
        }
        // Every overlapping pair once (payloads are the body numbers).
        let mut contacts = 0;
        let _ = index.for_each_pair(|_, &i, _, &j| {
            debug_assert_ne!(i, j);
            contacts += 1;
            std::ops::ControlFlow::Continue(())
        });
        // What the camera sees.
        let visible = index.query(frustum)?.len();
        // Who is near the centre (a radius query).
        let near = index.within(Vec3::splat(50.0), 10.0)?.len();
        println!(
            "frame {frame:2}: {contacts:4} contacts, {visible:4} visible, {near:3} near the centre"
        );
    }
    Ok(())
}
