//! Temporal coherence: answers equal with it on and off, unchanged pairs not
//! tested again, cuts reused on small motions; and the broad phase's rebuild
//! rule.

use super::brute::{BShape, BruteWorld};
use super::oracle::check_report;
use super::{crate_mesh, nudge, random_pose, rob, rock, MeshData};
use proxima::broad::IndexKind;
use proxima::geom::Aabb;
use proxima::glam::{Affine3A, Vec3};
use proxima::narrow::{BoundingVolume, Kdop18, Obb};
use proxima::world::{ContactReport, Shape, World, WorldConfig};
use proxima::Handle;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use std::sync::Arc;

/// `n` objects from `meshes` packed in a cube of side `side`.
fn scene<BV: BoundingVolume>(
    config: WorldConfig,
    meshes: &[Arc<MeshData>],
    n: usize,
    side: f32,
    rng: &mut Pcg64,
) -> (World<u64, BV>, BruteWorld, Vec<Handle>) {
    let mut world = World::new(config).unwrap();
    let mut brute = BruteWorld::default();
    let mut hs = Vec::new();
    for i in 0..n {
        let m = &meshes[i % meshes.len()];
        let pose = random_pose(rng, side / 2.0);
        let h = world
            .insert(Shape::from(m.mesh::<BV>()), pose, i as u64)
            .unwrap();
        brute.insert(h, BShape::Mesh(m.clone()), pose, Default::default());
        hs.push(h);
    }
    (world, brute, hs)
}

/// Equal reports of two worlds built alike (handles differ only in their tag).
fn same(a: &ContactReport, b: &ContactReport) {
    let slots = |r: &ContactReport| -> Vec<_> {
        r.pairs
            .iter()
            .map(|c| (c.a.index(), c.b.index(), c.triangles.clone()))
            .collect()
    };
    assert_eq!(slots(a), slots(b));
    assert_eq!(a.triangles, b.triangles);
}

/// Coherence on and off in lockstep, frames where a tenth of the objects move
/// a little, others where many move or jump: identical reports, checked
/// against brute force every few frames; and coherence does less work.
fn lockstep<BV: BoundingVolume>(kind: IndexKind, seed: u64, cut_limit: usize) {
    let mut rng = Pcg64::seed_from_u64(seed);
    let meshes = [
        Arc::new(rock(&mut rng)),
        Arc::new(crate_mesh()),
        Arc::new(rob()),
    ];
    let on = WorldConfig {
        index: Some(kind),
        cut_limit,
        ..WorldConfig::default()
    };
    let off = WorldConfig {
        coherence: false,
        ..on
    };
    let (mut w_on, mut brute, hs) = scene::<BV>(on, &meshes, 40, 3.0, &mut rng.clone());
    let (mut w_off, _, hs_off) = scene::<BV>(off, &meshes, 40, 3.0, &mut rng);
    let (mut work_on, mut work_off) = (0u64, 0u64);
    let (mut skipped, mut cut_starts, mut contacts) = (0, 0, 0);
    for frame in 0..60 {
        let share = if frame % 10 == 9 { 1.0 } else { 0.1 };
        let mut moves = Vec::new();
        for (i, &h) in hs.iter().enumerate() {
            if rng.gen_bool(share) {
                let p = w_on.pose(h).unwrap();
                let q = if rng.gen_bool(0.05) {
                    random_pose(&mut rng, 1.5)
                } else {
                    nudge(&mut rng, &p, 0.02)
                };
                moves.push((i, q));
            }
        }
        for &(i, q) in &moves {
            w_on.set_pose(hs[i], q).unwrap();
            w_off.set_pose(hs_off[i], q).unwrap();
            brute.objects.get_mut(&hs[i]).unwrap().pose = q;
        }
        let first = frame % 7 == 3;
        let (a, b) = if first {
            (
                w_on.contacts_first().unwrap(),
                w_off.contacts_first().unwrap(),
            )
        } else {
            (w_on.contacts().unwrap(), w_off.contacts().unwrap())
        };
        same(&a, &b);
        if frame % 5 == 0 {
            check_report(&a, &brute.contacts(), first);
        }
        w_on.validate().unwrap();
        w_off.validate().unwrap();
        if frame > 0 && share < 1.0 && !first && frame % 7 != 4 {
            work_on += a.counters.cost.nv;
            work_off += b.counters.cost.nv;
            skipped += a.counters.coherent_pairs;
            cut_starts += a.counters.cut_starts;
        }
        contacts += a.pairs.len();
        assert_eq!(b.counters.coherent_pairs + b.counters.cut_starts, 0);
    }
    assert!(contacts > 100, "{contacts}");
    assert!(skipped > 0, "{skipped}");
    assert_eq!(cut_starts > 0, cut_limit > 0, "{cut_starts}");
    // A tenth moving: well under half the volume tests.
    assert!(work_on * 2 < work_off, "{work_on} vs {work_off}");
}

#[test]
fn coherence_on_and_off_agree() {
    // Cuts are off by default (coherence.rs): with them and without.
    lockstep::<Kdop18>(IndexKind::LooseKd, 1, 1024);
    lockstep::<Obb>(IndexKind::Grid3d, 2, 1024);
    lockstep::<Kdop18>(IndexKind::Brute, 3, 1024);
    let default = WorldConfig::default().cut_limit;
    assert_eq!(default, 0);
    lockstep::<Kdop18>(IndexKind::LooseKd, 4, default);
}

#[test]
fn an_identical_pose_is_not_a_move() {
    let mut rng = Pcg64::seed_from_u64(9);
    let meshes = [Arc::new(rock(&mut rng))];
    let (mut w, _, hs) = scene::<Kdop18>(WorldConfig::default(), &meshes, 30, 1.5, &mut rng);
    let first = w.contacts().unwrap();
    assert!(first.counters.narrow_pairs > 0);
    for &h in &hs {
        let p = w.pose(h).unwrap();
        w.set_pose(h, p).unwrap();
    }
    let again = w.contacts().unwrap();
    same(&first, &again);
    assert_eq!(again.counters.narrow_pairs, 0);
    assert_eq!(again.counters.coherent_pairs, first.counters.narrow_pairs);
    // One object moved: only its pairs are tested.
    let p = nudge(&mut rng, &w.pose(hs[0]).unwrap(), 0.01);
    w.set_pose(hs[0], p).unwrap();
    let third = w.contacts().unwrap();
    assert!(third.counters.narrow_pairs < first.counters.narrow_pairs);
    assert!(
        third.counters.narrow_pairs + third.counters.coherent_pairs >= third.pairs.len() as u64
    );
    // The other mode does not reuse this mode's answers.
    let f = w.contacts_first().unwrap();
    assert_eq!(f.counters.coherent_pairs, 0);
    assert_eq!(f.pairs.len(), third.pairs.len());
}

#[test]
fn cuts_skip_the_volume_tests_above_them() {
    // Two robs at a near miss (along a direction, the first gap with no contact
    // on a 0.005 grid; of several orientations, the one the traversal finds
    // hardest), nudged a little each frame: the traversal cut recorded at one
    // frame is where the next one starts.
    let m = Arc::new(rob());
    let mut probe: World<u64> = World::new(WorldConfig {
        coherence: false,
        ..WorldConfig::default()
    })
    .unwrap();
    probe
        .insert(Shape::from(m.mesh()), Affine3A::IDENTITY, 0)
        .unwrap();
    let b = probe
        .insert(Shape::from(m.mesh()), Affine3A::IDENTITY, 1)
        .unwrap();
    let mut rng = Pcg64::seed_from_u64(8);
    let mut best = (0, Affine3A::IDENTITY);
    for _ in 0..12 {
        let turn = random_pose(&mut rng, 1e-9);
        let dir = random_pose(&mut rng, 1e-9).transform_vector3(Vec3::X);
        let mut d = 0.0;
        let at = |d: f32| Affine3A::from_translation(dir * d) * turn;
        loop {
            probe.set_pose(b, at(d)).unwrap();
            let r = probe.contacts().unwrap();
            if r.pairs.is_empty() {
                if r.counters.cost.nv > best.0 {
                    best = (r.counters.cost.nv, at(d));
                }
                break;
            }
            d += 0.005;
        }
    }
    let start = best.1;
    let mut totals = [(0u64, 0u64, 0usize); 2];
    for (k, coherence) in [true, false].into_iter().enumerate() {
        let mut rng = Pcg64::seed_from_u64(4);
        let mut w: World<u64> = World::new(WorldConfig {
            coherence,
            cut_limit: 1024,
            ..WorldConfig::default()
        })
        .unwrap();
        w.insert(Shape::from(m.mesh()), Affine3A::IDENTITY, 0)
            .unwrap();
        let b = w.insert(Shape::from(m.mesh()), start, 1).unwrap();
        for _ in 0..40 {
            let pose = nudge(&mut rng, &start, 0.002);
            w.set_pose(b, pose).unwrap();
            let r = w.contacts().unwrap();
            totals[k].0 += r.counters.cost.nv;
            totals[k].1 += r.counters.cut_starts;
            totals[k].2 += r.triangles.len();
        }
    }
    let (on, off) = (totals[0], totals[1]);
    assert_eq!(on.2, off.2, "same answers");
    assert!(on.1 >= 30 && off.1 == 0, "{totals:?}");
    // The near miss is decided high above the leaves: a fair share of the volume
    // tests is above the cut.
    assert!(on.0 * 10 < off.0 * 8, "{totals:?}");
}

#[test]
fn the_index_is_built_lazily_and_rebuilt_after_drift() {
    let mut rng = Pcg64::seed_from_u64(5);
    let meshes = [Arc::new(crate_mesh())];
    let (mut w, mut brute, hs) =
        scene::<Kdop18>(WorldConfig::default(), &meshes, 40, 2.0, &mut rng);
    assert_eq!((w.broad_phase_builds(), w.index_kind()), (0, None));
    // Queries before the first build scan the objects.
    let before = w
        .overlap_sphere(Vec3::ZERO, 1.0, Default::default())
        .unwrap();
    assert_eq!(
        before,
        brute.overlap_sphere(Vec3::ZERO, 1.0, Default::default())
    );
    check_report(&w.contacts().unwrap(), &brute.contacts(), false);
    assert_eq!(
        (w.broad_phase_builds(), w.index_kind()),
        (1, Some(IndexKind::LooseKd))
    );
    // A few objects leave the box: no rebuild (at most max(8, n/4) = 10).
    let far = |i: usize| Affine3A::from_translation(Vec3::new(100.0 + 2.0 * i as f32, 50.0, 0.0));
    for (i, &h) in hs.iter().enumerate().take(10) {
        w.set_pose(h, far(i)).unwrap();
        brute.objects.get_mut(&h).unwrap().pose = far(i);
    }
    check_report(&w.contacts().unwrap(), &brute.contacts(), false);
    assert_eq!(w.broad_phase_builds(), 1);
    // One more: rebuilt, same answers.
    w.set_pose(hs[10], far(10)).unwrap();
    brute.objects.get_mut(&hs[10]).unwrap().pose = far(10);
    check_report(&w.contacts().unwrap(), &brute.contacts(), false);
    assert_eq!(w.broad_phase_builds(), 2);
    w.validate().unwrap();
    // Radii far above the built r_max count too.
    let mut w2: World<u64> = World::new(WorldConfig::default()).unwrap();
    for i in 0..20 {
        let p = Affine3A::from_translation(Vec3::new(i as f32, 0.0, 0.0));
        w2.insert(Shape::sphere(0.4).unwrap(), p, i).unwrap();
    }
    w2.update_broad_phase().unwrap();
    for i in 0..9 {
        let p = Affine3A::from_translation(Vec3::new(i as f32 * 3.0, 5.0, 0.0));
        w2.insert(Shape::sphere(2.0).unwrap(), p, 100 + i).unwrap();
    }
    w2.update_broad_phase().unwrap();
    assert_eq!(w2.broad_phase_builds(), 2);
    w2.validate().unwrap();
    // With bounds, centres never trigger a rebuild.
    let mut w3: World<u64> = World::new(WorldConfig {
        bounds: Some(Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0))),
        ..WorldConfig::default()
    })
    .unwrap();
    let s = Shape::sphere(0.1).unwrap();
    let hs3: Vec<_> = (0..20)
        .map(|i| w3.insert(s.clone(), Affine3A::IDENTITY, i).unwrap())
        .collect();
    w3.update_broad_phase().unwrap();
    for (i, &h) in hs3.iter().enumerate() {
        w3.set_pose(h, far(i)).unwrap();
    }
    w3.update_broad_phase().unwrap();
    assert_eq!(w3.broad_phase_builds(), 1);
    w3.validate().unwrap();
}
