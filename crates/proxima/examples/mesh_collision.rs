//! Exact mesh-vs-mesh collision: a robot model against a room, both loaded from
//! the shared test meshes, at a few poses of the robot.
//!
//! `cargo run --release --example mesh_collision [A.obj B.obj]`

use proxima::glam::{Affine3A, Quat, Vec3};
use proxima::narrow::{Collider, Mesh};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let data = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data");
    let mut args = std::env::args().skip(1);
    let a_path = args.next().unwrap_or(format!("{data}/rob.obj"));
    let b_path = args.next().unwrap_or(format!("{data}/env.obj"));
    // Each mesh with its k-DOP (18 directions) hierarchy, built once.
    let a: Mesh = Mesh::load(&a_path)?;
    let b: Mesh = Mesh::load(&b_path)?;
    // Scratch space reused by every query.
    let mut collider = Collider::default();
    println!(
        "A: {} triangles, B: {} triangles",
        a.trimesh().len(),
        b.trimesh().len()
    );

    for step in 0..6 {
        // Slide A along y past a chair while turning it about z.
        let t = step as f32;
        let pose = Affine3A::from_rotation_translation(
            Quat::from_rotation_z(t * 0.1),
            Vec3::new(-1500.0, -1800.0 + 150.0 * t, 450.0),
        );
        let contacts = collider.all_pairs(&a, &pose, &b)?;
        let first = collider.first_contact(&a, &pose, &b)?;
        let c = contacts.counters;
        println!(
            "pose {step}: {:3} intersecting triangle pairs (first contact: {:?}); \
             BV tests {}, triangle tests {}, BV updates {}",
            contacts.pairs.len(),
            first.pair,
            c.nv,
            c.np,
            c.nu
        );
        // The first contact is one of the pairs.
        assert_eq!(first.pair.is_some(), !contacts.pairs.is_empty());
    }
    Ok(())
}
