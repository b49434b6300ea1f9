//! Octree-specific tests (the generic oracle suite in `tests/oracle` covers the
//! queries and pairs against brute force).

use super::*;

use crate::broad::OctreeConfig;

use crate::broad::SpatialIndex;
use crate::broad::SpatialIndexExt;
use crate::geom::{Frustum, Relation, Sphere};
use glam::{vec3, Mat4};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use std::cell::Cell;

/// A power-of-two world so cell boxes and centres are exact in f32.
fn world() -> Aabb {
    Aabb::new(Vec3::ZERO, Vec3::splat(64.0))
}

fn cfg(max_per_leaf: u32, merge_below: u32, max_depth: u32) -> OctreeConfig {
    OctreeConfig {
        max_per_leaf,
        merge_below,
        max_depth,
        ..OctreeConfig::new(world())
    }
}

/// Integer box of a cell at depth-21 resolution: `[lo, hi)` per axis.
fn ibox(c: LocationCode) -> ([u64; 3], [u64; 3]) {
    let s = 1u64 << (MAX_DEPTH - c.depth());
    let xyz = c.coords();
    let lo = xyz.map(|v| v as u64 * s);
    (lo, lo.map(|v| v + s))
}

fn all_leaves<T>(t: &LinearOctree<T>) -> Vec<LocationCode> {
    let mut v = Vec::new();
    t.for_each_leaf(|c, _| v.push(c));
    v.sort();
    v
}

/// Brute force: leaves overlapping the neighbour cell `n` (positive volume) whose
/// extent reaches the face `n` shares with `code`.
fn brute_face_neighbors(leaves: &[LocationCode], code: LocationCode, f: Face) -> Vec<LocationCode> {
    let Some(n) = code.face_neighbor(f) else {
        return vec![];
    };
    let (nlo, nhi) = ibox(n);
    let a = f.axis();
    let mut out: Vec<_> = leaves
        .iter()
        .copied()
        .filter(|&l| {
            let (lo, hi) = ibox(l);
            let overlap = (0..3).all(|k| lo[k] < nhi[k] && nlo[k] < hi[k]);
            let reaches = if f.is_positive() {
                lo[a] <= nlo[a]
            } else {
                hi[a] >= nhi[a]
            };
            overlap && reaches
        })
        .collect();
    out.sort();
    out
}

/// Brute force for a node `code`: leaves sharing a face patch (positive area) with
/// it across `f`.
fn brute_face_patch(leaves: &[LocationCode], code: LocationCode, f: Face) -> Vec<LocationCode> {
    let (clo, chi) = ibox(code);
    let a = f.axis();
    let mut out: Vec<_> = leaves
        .iter()
        .copied()
        .filter(|&l| {
            let (lo, hi) = ibox(l);
            let touches = if f.is_positive() {
                lo[a] == chi[a]
            } else {
                hi[a] == clo[a]
            };
            touches
                && (0..3)
                    .filter(|&k| k != a)
                    .all(|k| lo[k] < chi[k] && clo[k] < hi[k])
        })
        .collect();
    out.sort();
    out
}

fn clustered_tree(seed: u64, n: usize) -> LinearOctree<usize> {
    let mut rng = Pcg64::seed_from_u64(seed);
    let mut t = LinearOctree::with_config(OctreeConfig {
        world: world(),
        ..cfg(2, 1, 8)
    })
    .unwrap();
    let centres = [
        vec3(10.0, 10.0, 10.0),
        vec3(40.0, 20.0, 50.0),
        vec3(33.0, 33.0, 33.0),
    ];
    for i in 0..n {
        let c = if rng.gen_bool(0.7) {
            centres[i % 3]
                + vec3(
                    rng.gen_range(-3.0..3.0),
                    rng.gen_range(-3.0..3.0),
                    rng.gen_range(-3.0..3.0),
                )
        } else {
            vec3(
                rng.gen_range(0.0..64.0),
                rng.gen_range(0.0..64.0),
                rng.gen_range(0.0..64.0),
            )
        };
        t.insert(Sphere::new(c, 0.5), i).unwrap();
    }
    t.validate().unwrap();
    t
}

#[test]
fn face_neighbors_across_depths_match_brute_force() {
    for seed in 0..4 {
        let t = clustered_tree(seed, 300);
        let leaves = all_leaves(&t);
        let depths: std::collections::BTreeSet<u32> = leaves.iter().map(|c| c.depth()).collect();
        assert!(
            depths.len() >= 4,
            "want leaves at many depths, got {depths:?}"
        );
        let mut nodes: Vec<LocationCode> = t.map.values().map(|&i| t.nodes[i].code).collect();
        nodes.sort();
        let (mut up, mut down) = (0, 0);
        for &c in &nodes {
            for f in Face::ALL {
                let mut got = t.face_neighbors(c, f);
                got.sort();
                assert_eq!(got, brute_face_neighbors(&leaves, c, f), "{c:?} {f:?}");
                // For a node, that is exactly the leaves sharing a face patch.
                assert_eq!(got, brute_face_patch(&leaves, c, f), "{c:?} {f:?}");
                up += got.iter().filter(|g| g.depth() < c.depth()).count();
                down += got.iter().filter(|g| g.depth() > c.depth()).count();
            }
        }
        assert!(
            up > 0 && down > 0,
            "both larger and smaller neighbours occur"
        );
        // Arbitrary codes (mostly not nodes) at every depth.
        let mut rng = Pcg64::seed_from_u64(seed + 100);
        for _ in 0..3000 {
            let d = rng.gen_range(0..=9u32);
            let n = 1u32 << d;
            let c = LocationCode::from_coords(
                d,
                [
                    rng.gen_range(0..n),
                    rng.gen_range(0..n),
                    rng.gen_range(0..n),
                ],
            )
            .unwrap();
            for f in Face::ALL {
                let mut got = t.face_neighbors(c, f);
                got.sort();
                assert_eq!(got, brute_face_neighbors(&leaves, c, f), "{c:?} {f:?}");
            }
        }
    }
}

/// The experiment of [sources: octree-experiment]: 12 objects moving freely through an octree split
/// down to one object per leaf, validated after every frame. Every move is
/// classified independently by geometry (where the new centre lies relative to
/// the old leaf's box) and the stats must show the matching path.
#[test]
fn twelve_moving_objects_use_the_neighbour_path() {
    let mut rng = Pcg64::seed_from_u64(4);
    let w = world();
    let mut t: LinearOctree<usize> = LinearOctree::with_config(OctreeConfig {
        world: w,
        ..cfg(1, 1, 10)
    })
    .unwrap();
    let mut pos = Vec::new();
    let mut vel = Vec::new();
    let mut hs = Vec::new();
    for i in 0..12 {
        let p = vec3(
            rng.gen_range(1.0..63.0),
            rng.gen_range(1.0..63.0),
            rng.gen_range(1.0..63.0),
        );
        let v = vec3(
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
        ) * 0.4;
        hs.push(t.insert(Sphere::new(p, 0.7), i).unwrap());
        pos.push(p);
        vel.push(v);
    }
    t.validate().unwrap();
    let (mut expect_same, mut expect_face, mut expect_diag, mut expect_jump) =
        (0u64, 0u64, 0u64, 0u64);
    let mut max_depth_seen = 0;
    for frame in 0..5000 {
        for i in 0..12 {
            let mut p = pos[i] + vel[i];
            for a in 0..3 {
                if p[a] < 0.0 || p[a] > 64.0 {
                    vel[i][a] = -vel[i][a];
                    p[a] = p[a].clamp(0.0, 64.0);
                }
            }
            if rng.gen_bool(0.002) {
                // An occasional teleport: a long jump.
                p = vec3(
                    rng.gen_range(0.0..64.0),
                    rng.gen_range(0.0..64.0),
                    rng.gen_range(0.0..64.0),
                );
            }
            // Classify by geometry before the move.
            let leaf = t.leaf_of(hs[i]).unwrap();
            let b = t.cell_box(leaf);
            let size = b.extent().x;
            // The world's top faces belong to the last cells.
            let pin = p.min(Vec3::splat(64.0 - 1e-3));
            let off = ((pin - b.min) / size).floor();
            let inside_world =
                |q: Vec3| q.cmpge(Vec3::ZERO).all() && q.cmple(Vec3::splat(64.0)).all();
            assert!(inside_world(p));
            let nz = (0..3).filter(|&a| off[a] != 0.0).count();
            let adjacent = (0..3).all(|a| (-1.0..=1.0).contains(&off[a]));
            let before = t.stats();
            t.update(hs[i], Sphere::new(p, 0.7)).unwrap();
            let after = t.stats();
            if nz == 0 {
                expect_same += 1;
            } else if adjacent && nz == 1 {
                expect_face += 1;
                assert_eq!(
                    after.face_moves,
                    before.face_moves + 1,
                    "frame {frame}: face move {leaf:?} {b:?} {p} {off} {before:?} {after:?} -> {:?}", t.leaf_of(hs[i])
                );
                let resolved =
                    (after.neighbor_same_depth + after.neighbor_up + after.neighbor_down)
                        - (before.neighbor_same_depth + before.neighbor_up + before.neighbor_down);
                assert_eq!(resolved, 1);
            } else if adjacent {
                expect_diag += 1;
            } else {
                expect_jump += 1;
                assert_eq!(
                    after.jump_moves,
                    before.jump_moves + 1,
                    "frame {frame}: jump"
                );
            }
            pos[i] = p;
        }
        t.validate()
            .unwrap_or_else(|e| panic!("frame {frame}: {e}"));
        max_depth_seen = max_depth_seen.max(t.stats().depth);
    }
    let s = t.stats();
    assert_eq!(s.same_leaf_moves, expect_same);
    assert_eq!(s.face_moves, expect_face);
    assert_eq!(s.edge_corner_moves, expect_diag);
    assert_eq!(s.jump_moves, expect_jump);
    eprintln!("seed experiment: {s:?}");
    assert!(s.face_moves > 1000, "{s:?}");
    assert!(s.jump_moves > 10, "{s:?}");
    // Neighbours at other depths occur and are resolved by going up or down.
    assert!(s.neighbor_up > 0 && s.neighbor_down > 0, "{s:?}");
    assert!(s.splits > 0 && s.merges > 0, "{s:?}");
    assert!(
        max_depth_seen >= 4,
        "tree should be deep, got {max_depth_seen}"
    );
    // Every object is where a fresh tree would put it: a leaf holding its centre.
    for (i, h) in hs.iter().enumerate() {
        assert!(t.leaf_of(*h).unwrap().contains(LocationCode::of_point(
            t.root_cell(),
            pos[i],
            MAX_DEPTH
        )));
    }
}

#[test]
fn border_oscillation_does_not_split_and_merge_every_frame() {
    let mut t: LinearOctree<u32> = LinearOctree::with_config(OctreeConfig {
        world: world(),
        ..cfg(4, 2, 10)
    })
    .unwrap();
    // Four objects in the low-x half of the root, one oscillating across x = 32.
    for i in 0..4 {
        t.insert(Sphere::new(vec3(10.0 + i as f32, 10.0, 10.0), 0.5), i)
            .unwrap();
    }
    let h = t
        .insert(Sphere::new(vec3(31.9, 10.0, 10.0), 0.5), 9)
        .unwrap();
    t.validate().unwrap();
    let s0 = t.stats();
    for frame in 0..1000 {
        let x = if frame % 2 == 0 { 32.1 } else { 31.9 };
        t.update(h, Sphere::new(vec3(x, 10.0, 10.0), 0.5)).unwrap();
        t.validate().unwrap();
    }
    let s = t.stats();
    assert_eq!(
        (s.splits, s.merges),
        (s0.splits, s0.merges),
        "{s0:?} -> {s:?}"
    );
    assert_eq!(s.face_moves - s0.face_moves, 1000);

    // The tightest allowed setting, merge_below = max_per_leaf, still has one
    // object of hysteresis: an object moving in and out of a full leaf's cell
    // splits it once (5 > 4) and never merges it back (4 is not below 4).
    let mut t: LinearOctree<u32> = LinearOctree::with_config(OctreeConfig {
        world: world(),
        ..cfg(4, 4, 10)
    })
    .unwrap();
    for i in 0..4 {
        t.insert(Sphere::new(vec3(10.0 + i as f32, 10.0, 10.0), 0.5), i)
            .unwrap();
    }
    let h = t
        .insert(Sphere::new(vec3(40.0, 10.0, 10.0), 0.5), 9)
        .unwrap();
    let mut after_first = None;
    for frame in 0..100 {
        let x = if frame % 2 == 0 { 14.0 } else { 40.0 };
        t.update(h, Sphere::new(vec3(x, 10.0, 10.0), 0.5)).unwrap();
        t.validate().unwrap();
        if frame == 1 {
            after_first = Some(t.stats());
        }
    }
    // The first entry splits the full leaf (a cascade, once); after that the
    // structure never changes again.
    let (s1, s) = (after_first.unwrap(), t.stats());
    assert!(s1.splits > 0, "{s1:?}");
    assert_eq!(
        (s.splits, s.merges),
        (s1.splits, s1.merges),
        "{s1:?} -> {s:?}"
    );
}

#[test]
fn config_and_world_are_validated() {
    let w = world();
    assert!(LinearOctree::<()>::with_config(OctreeConfig {
        world: w,
        ..cfg(0, 0, 8)
    })
    .is_err());
    assert!(LinearOctree::<()>::with_config(OctreeConfig {
        world: w,
        ..cfg(4, 5, 8)
    })
    .is_err());
    assert!(LinearOctree::<()>::with_config(OctreeConfig {
        world: w,
        ..cfg(4, 2, 22)
    })
    .is_err());
    assert!(LinearOctree::<()>::with_config(OctreeConfig {
        world: Aabb::new(Vec3::ONE, Vec3::ZERO),
        ..cfg(4, 2, 8)
    })
    .is_err());
    assert!(LinearOctree::<()>::with_config(OctreeConfig {
        world: Aabb::new(Vec3::ZERO, Vec3::splat(f32::NAN)),
        ..cfg(4, 2, 8)
    })
    .is_err());
    assert!(LinearOctree::<()>::with_config(OctreeConfig {
        world: w,
        ..cfg(4, 0, 21)
    })
    .is_ok());
    // A degenerate (point) world still works: everything is clamped onto it.
    let mut t = LinearOctree::new(Aabb::new(Vec3::ONE, Vec3::ONE)).unwrap();
    for i in 0..50 {
        t.insert(Sphere::new(vec3(i as f32, 0.0, -(i as f32)), 1.0), i)
            .unwrap();
    }
    t.validate().unwrap();
    assert_eq!(t.within(vec3(49.0, 0.0, -49.0), 0.3).unwrap().len(), 1);
}

#[test]
fn merge_disabled_still_deletes_empty_leaves() {
    let mut t: LinearOctree<usize> = LinearOctree::with_config(OctreeConfig {
        world: world(),
        ..cfg(1, 0, 8)
    })
    .unwrap();
    let mut rng = Pcg64::seed_from_u64(9);
    let hs: Vec<_> = (0..200)
        .map(|i| {
            let p = vec3(
                rng.gen_range(0.0..64.0),
                rng.gen_range(0.0..64.0),
                rng.gen_range(0.0..64.0),
            );
            t.insert(Sphere::new(p, 0.1), i).unwrap()
        })
        .collect();
    t.validate().unwrap();
    for h in hs {
        t.remove(h).unwrap();
        t.validate().unwrap();
    }
    let s = t.stats();
    assert_eq!((s.nodes, s.leaves, s.merges), (1, 1, 0), "{s:?}");
}

/// Counts how often spheres are tested one by one.
struct Counting<'a> {
    inner: Frustum,
    tests: &'a Cell<usize>,
}

impl crate::broad::selection::sealed::Sealed for Counting<'_> {}

impl Selection for Counting<'_> {
    fn validate(&self) -> crate::Result<()> {
        self.inner.validate()
    }
    fn selects(&self, s: &Sphere) -> bool {
        self.tests.set(self.tests.get() + 1);
        self.inner.selects(s)
    }
    fn classify_box(&self, b: &Aabb, mask: u8) -> (Relation, u8) {
        self.inner.classify_box(b, mask)
    }
    fn bounds(&self) -> Option<Aabb> {
        None
    }
}

#[test]
fn frustum_reports_inside_subtrees_without_testing_spheres() {
    let t = clustered_tree(5, 400);
    let tests = Cell::new(0);
    // A camera far back, looking at the whole world: everything is Inside.
    let view = Mat4::look_at_rh(vec3(32.0, 32.0, 400.0), vec3(32.0, 32.0, 32.0), Vec3::Y);
    let proj = Mat4::perspective_rh(1.0, 1.0, 1.0, 1000.0);
    let q = Counting {
        inner: Frustum::from_view_projection(proj * view).unwrap(),
        tests: &tests,
    };
    let mut n = 0;
    let _ = t.walk(&q, |_, _, _| {
        n += 1;
        std::ops::ControlFlow::Continue(())
    });
    assert_eq!((n, tests.get()), (400, 0));
    // A narrow one: fewer sphere tests than objects, and the same answer as a scan.
    let view = Mat4::look_at_rh(vec3(10.0, 10.0, 40.0), vec3(10.0, 10.0, 10.0), Vec3::Y);
    let proj = Mat4::perspective_rh(0.3, 1.0, 1.0, 100.0);
    let fr = Frustum::from_view_projection(proj * view).unwrap();
    let q = Counting {
        inner: fr,
        tests: &tests,
    };
    tests.set(0);
    let mut got = Vec::new();
    let _ = t.walk(&q, |h, _, _| {
        got.push(h);
        std::ops::ControlFlow::Continue(())
    });
    let mut want = Vec::new();
    t.for_each(&mut |h, s, _| {
        if fr.selects(s) {
            want.push(h)
        }
    });
    got.sort();
    want.sort();
    assert_eq!(got, want);
    assert!(
        !got.is_empty() && tests.get() < 400,
        "{} tests",
        tests.get()
    );
}

#[test]
fn clear_memory_and_stats() {
    let mut t = clustered_tree(1, 500);
    let m = t.memory_bytes();
    assert!(m > 500 * std::mem::size_of::<Sphere>(), "{m}");
    let s = t.stats();
    assert_eq!(s.objects, 500);
    assert!(s.leaves > 50 && s.nodes > s.leaves);
    t.clear();
    t.validate().unwrap();
    assert!(t.memory_bytes() < m / 4);
    assert_eq!(t.stats().nodes, 1);
}

/// `child_halves` gives every child the same `f32` box as `loose_of` with
/// its parent's extent, bit for bit, in a world whose cell sides and
/// corners round (the k-nearest and ray searches prune with the halves, and
/// `validate` checks the loose boxes).
#[test]
fn child_halves_are_the_childrens_loose_boxes_bit_for_bit() {
    let mut rng = Pcg64::seed_from_u64(61);
    let mut t = LinearOctree::with_config(OctreeConfig {
        world: Aabb::new(vec3(-3.7, 1.3, 0.1), vec3(97.1, 50.9, 33.3)),
        ..cfg(2, 1, 8)
    })
    .unwrap();
    for i in 0..600 {
        let c = vec3(
            rng.gen_range(-3.0..97.0),
            rng.gen_range(1.5..50.0),
            rng.gen_range(0.2..33.0),
        );
        t.insert(Sphere::new(c, rng.gen_range(0.0..2.0)), i)
            .unwrap();
    }
    let mut stack = vec![(t.root, [0u32; 3], 0u32)];
    let mut checked = 0;
    while let Some((i, c, d)) = stack.pop() {
        let n = &t.nodes[i];
        if n.leaf {
            continue;
        }
        let halves = t.child_halves(n, c, d);
        for (k, &ch) in n.children.iter().enumerate() {
            if ch == node::NONE {
                continue;
            }
            let cc = query::child_coords(c, k);
            let want = t.loose_of(cc, d + 1, n.max_extent);
            for a in 0..3 {
                let (lo, hi) = halves[a][(k >> a) & 1];
                assert_eq!(
                    lo.to_bits(),
                    want.min[a].to_bits(),
                    "node {i} child {k} axis {a}"
                );
                assert_eq!(
                    hi.to_bits(),
                    want.max[a].to_bits(),
                    "node {i} child {k} axis {a}"
                );
            }
            stack.push((ch, cc, d + 1));
            checked += 1;
        }
    }
    assert!(checked > 50, "{checked}");
}

/// A leaf of `SEED_MAX` (64) items, past `max_per_leaf` at the depth cap,
/// most of them duplicates at one point: the first leaf's seed lists the `k`
/// it bounds by ahead of the other passers, and when those `k` include the
/// leaf's last item and every item before it passes, the branch-free list
/// writes one slot past the leaf's 64 (63 duplicates and the query off them,
/// k = 2 or 10: a 64-slot list panicked here). Filtered (a filter that
/// admits all: no seed), a point cloud's leaf goes through the four-wide
/// pre-test, whose last quad writes four slots from the 64th. Brute force's
/// ids and distances, for k = 1, 2, 10, 64 and 70, from points on, beside
/// and away from the duplicates, both metrics, with and without the filter.
#[test]
fn nearest_over_a_full_leaf_of_duplicates_at_the_depth_cap() {
    use crate::broad::{BruteForce, Metric, Nearest};
    let p = vec3(10.25, 20.5, 30.75);
    for (dups, radius) in [(64usize, 0.0f32), (64, 0.5), (63, 0.0), (40, 0.0)] {
        let mut t = LinearOctree::with_config(cfg(8, 4, 3)).unwrap();
        let mut brute = BruteForce::new();
        let mut ids = (Vec::new(), Vec::new());
        for i in 0..64 {
            // The rest of the leaf just beside the duplicates, same cell.
            let c = if i < dups {
                p
            } else {
                p + Vec3::splat(0.001 * i as f32)
            };
            let s = Sphere::new(c, radius);
            ids.0.push(t.insert(s, i).unwrap());
            ids.1.push(brute.insert(s, i).unwrap());
        }
        t.validate().unwrap();
        let mut largest = 0;
        t.for_each_leaf(|_, n| largest = largest.max(n));
        assert_eq!(largest, 64, "one leaf holds all 64");
        for q in [p, p + vec3(0.5, 0.0, 0.0), vec3(60.0, 1.0, 2.0)] {
            for k in [1, 2, 10, 64, 70] {
                let metrics = [Metric::Surface, Metric::Center];
                for (metric, filter) in metrics
                    .into_iter()
                    .flat_map(|m| [None, Some(crate::broad::Filter::ALL)].map(|f| (m, f)))
                {
                    let n = Nearest::new(q, k).metric(metric);
                    let (mut got, mut want) = (Vec::new(), Vec::new());
                    t.nearest_into(&n, filter, &mut got).unwrap();
                    brute.nearest_into(&n, filter, &mut want).unwrap();
                    let as_ids =
                        |v: &[crate::broad::Neighbor], hs: &[Handle]| -> Vec<(usize, u32)> {
                            v.iter()
                                .map(|x| {
                                    (
                                        hs.iter().position(|&h| h == x.handle).unwrap(),
                                        x.distance.to_bits(),
                                    )
                                })
                                .collect()
                        };
                    assert_eq!(
                        as_ids(&got, &ids.0),
                        as_ids(&want, &ids.1),
                        "{dups} {q:?} k {k} {filter:?}"
                    );
                }
            }
        }
    }
}

/// Sweep selections (all hits) and first hits against brute force over
/// leaves of every size, so that the four-wide pre-test's quads and its
/// remainder of 0-3 spheres both run, and the first hits' octant filter
/// (`LinearOctree::octants`) on leaves of over 64 items (slots from 64 on are in
/// no mask) and on leaves at the depth cap (no octants: four clusters of
/// equal spheres, whose ties the first hit breaks by handle): random
/// sweeps, zero-length ones, radius 0, grazes at the summed radii from a
/// stored sphere, and an early stop; each non-empty sweep's segment also as
/// a ray (first hit).
#[test]
fn sweeps_over_leaves_of_every_size_match_brute_force() {
    use crate::geom::{overlap, SphereSweep};
    use std::ops::ControlFlow;
    let mut rng = Pcg64::seed_from_u64(91);
    let p = |rng: &mut Pcg64| vec3(rng.gen(), rng.gen(), rng.gen()) * 64.0;
    let twins = [0, 1, 2, 3].map(|_| p(&mut rng));
    for leaf in [1u32, 3, 4, 5, 6, 7, 9, 32, 48, 400] {
        let mut t = LinearOctree::with_config(cfg(leaf, leaf / 2, 21)).unwrap();
        let mut spheres = Vec::new();
        for i in 0..1500usize {
            // Equal twins (centre and radius): ties, broken by handle.
            let s = if i % 100 < 3 {
                Sphere::new(twins[i / 100 % 4], 1.0)
            } else {
                Sphere::new(p(&mut rng), rng.gen_range(0.0..2.0))
            };
            t.insert(s, i).unwrap();
            spheres.push(s);
        }
        t.validate().unwrap();
        let (mut deepest, mut fullest) = (0, 0);
        t.for_each_leaf(|code, objects| {
            deepest = deepest.max(code.depth());
            fullest = fullest.max(objects);
        });
        assert_eq!(
            deepest == MAX_DEPTH,
            leaf <= 9,
            "leaf {leaf}: depth {deepest}"
        );
        assert_eq!(
            fullest > 64,
            leaf == 400,
            "leaf {leaf}: {fullest} in a leaf"
        );
        let (mut hits, mut firsts) = (0, 0);
        for j in 0..600 {
            let radius = if j % 3 == 0 {
                0.0
            } else {
                rng.gen_range(0.0..3.0)
            };
            let from = p(&mut rng);
            let to = match j % 4 {
                0 => from,
                1 => {
                    // Past a stored sphere at the summed radii (a graze,
                    // up to rounding either way).
                    let s = spheres[rng.gen_range(0..spheres.len())];
                    let u = (p(&mut rng) - Vec3::splat(32.0)).normalize_or(Vec3::X);
                    let n = u.any_orthonormal_vector();
                    let mid = s.center + n * (s.radius + radius);
                    let sw_from = mid - u * 5.0;
                    let sw = SphereSweep::new(sw_from, mid + u * 5.0, radius);
                    check_sweep(&t, &spheres, &sw, &mut hits, &mut firsts);
                    continue;
                }
                _ => from + (p(&mut rng) - Vec3::splat(32.0)) * rng.gen_range(0.05..0.5),
            };
            check_sweep(
                &t,
                &spheres,
                &SphereSweep::new(from, to, radius),
                &mut hits,
                &mut firsts,
            );
        }
        assert!(
            hits > 400 && firsts > 150,
            "leaf {leaf}: {hits} hits, {firsts} firsts"
        );
    }

    fn check_sweep(
        t: &LinearOctree<usize>,
        spheres: &[Sphere],
        sw: &SphereSweep,
        hits: &mut usize,
        firsts: &mut usize,
    ) {
        let mut got = Vec::new();
        let flow = t.for_each_in(*sw, |_, _, &i| {
            got.push(i);
            ControlFlow::Continue(())
        });
        assert_eq!(flow, Ok(ControlFlow::Continue(())));
        got.sort_unstable();
        let want: Vec<usize> = (0..spheres.len())
            .filter(|&i| overlap::sweep_touches_sphere(sw, &spheres[i]))
            .collect();
        assert_eq!(got, want, "{sw:?}");
        *hits += got.len();
        let mut seen = 0;
        let flow = t.for_each_in(*sw, |_, _, _| {
            seen += 1;
            ControlFlow::Break(())
        });
        let stopped = if want.is_empty() {
            ControlFlow::Continue(())
        } else {
            ControlFlow::Break(())
        };
        assert_eq!(flow, Ok(stopped), "early stop, {sw:?}");
        assert_eq!(seen, want.len().min(1), "early stop, {sw:?}");
        // The smallest `(t, handle)`: handles ascend with the ids here.
        let first_of =
            |hit: Option<crate::broad::RayHit>| hit.map(|h| (h.t, *t.get(h.handle).unwrap().1));
        let smallest = |tests: &mut dyn Iterator<Item = (f32, usize)>| {
            tests.min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)))
        };
        let want = smallest(
            &mut (0..spheres.len())
                .filter_map(|i| overlap::sweep_sphere(sw, &spheres[i]).map(|t| (t, i))),
        );
        assert_eq!(first_of(t.sweep_first(sw, None).unwrap()), want, "{sw:?}");
        *firsts += want.is_some() as usize;
        // The same segment as a ray (no four-lane pre-test: one item at a
        // time through the octant filter).
        if sw.from != sw.to {
            let ray = crate::geom::Ray::with_max_t(sw.from, sw.to - sw.from, 1.0);
            let want = smallest(
                &mut (0..spheres.len())
                    .filter_map(|i| overlap::ray_sphere(&ray, &spheres[i]).map(|t| (t, i))),
            );
            assert_eq!(first_of(t.ray_first(&ray, None).unwrap()), want, "{ray:?}");
        }
    }
}

/// The depth-first kNN's first descent (straight into the nearest octant
/// while nothing is held) against brute force where that descent finds
/// nothing it may keep: a leaf of duplicates next to the query, stored out of
/// handle order (removals move the last item into the gap), beside a second
/// cluster in another octant, queried with a limit just below the
/// duplicates' distance, with a filter that rejects them, and with neither;
/// k = 1, 2, 5, 10 and 40, both metrics. The same ids and distances, bit for bit.
#[test]
fn nearest_when_the_first_descent_keeps_nothing() {
    use crate::broad::{BruteForce, Filter, Metric, Nearest, Neighbor};
    let near = vec3(10.25, 20.5, 30.75);
    let far = vec3(50.5, 44.25, 12.125);
    let mut rng = Pcg64::seed_from_u64(77);
    for radius in [0.0f32, 0.25] {
        let mut t = LinearOctree::with_config(cfg(32, 8, 4)).unwrap();
        let mut brute = BruteForce::new();
        // (octree handle, brute handle) per id.
        let mut live: Vec<(Handle, Handle, u32)> = Vec::new();
        let mut next = 0u32;
        let mut add = |t: &mut LinearOctree<u32>, brute: &mut BruteForce<u32>, c: Vec3, g: u32| {
            let (s, f) = (Sphere::new(c, radius), Filter::new(g, u32::MAX));
            let id = next;
            next += 1;
            (
                t.insert_with_filter(s, f, id).unwrap(),
                brute.insert_with_filter(s, f, id).unwrap(),
                id,
            )
        };
        for _ in 0..24 {
            live.push(add(&mut t, &mut brute, near, 1));
        }
        for _ in 0..40 {
            let jitter = vec3(rng.gen(), rng.gen(), rng.gen()) * 2.0;
            live.push(add(&mut t, &mut brute, far + jitter, 2));
        }
        // Out of handle order: remove some duplicates and add them back.
        for _ in 0..10 {
            // One of the duplicates (ids of the far cluster are 24..64).
            let mut i = rng.gen_range(0..live.len());
            while (24..64).contains(&live[i].2) {
                i = rng.gen_range(0..live.len());
            }
            let (a, b, _) = live.swap_remove(i);
            t.remove(a).unwrap();
            brute.remove(b).unwrap();
            live.push(add(&mut t, &mut brute, near, 1));
        }
        t.validate().unwrap();
        let id_of = |v: &[Neighbor], octree: bool| -> Vec<(u32, u32)> {
            v.iter()
                .map(|n| {
                    let e = live
                        .iter()
                        .find(|e| {
                            if octree {
                                e.0 == n.handle
                            } else {
                                e.1 == n.handle
                            }
                        })
                        .unwrap();
                    (e.2, n.distance.to_bits())
                })
                .collect()
        };
        let q = near + vec3(0.5, 0.0, 0.0);
        for metric in [Metric::Surface, Metric::Center] {
            let dup = metric.distance(q, &Sphere::new(near, radius));
            let below = f32::from_bits(dup.to_bits() - 1);
            for k in [1, 2, 5, 10, 40] {
                for (limit, filter) in [
                    (f32::INFINITY, None),
                    (below, None),
                    (f32::INFINITY, Some(Filter::new(u32::MAX, 2))),
                    (below, Some(Filter::new(u32::MAX, 1))),
                ] {
                    let n = Nearest::new(q, k).metric(metric).within(limit);
                    let (mut got, mut want) = (Vec::new(), Vec::new());
                    t.nearest_into(&n, filter, &mut got).unwrap();
                    brute.nearest_into(&n, filter, &mut want).unwrap();
                    assert_eq!(
                        id_of(&got, true),
                        id_of(&want, false),
                        "r {radius} {metric:?} k {k} limit {limit} {filter:?}"
                    );
                    // The cases are not vacuous: the far cluster answers
                    // when the duplicates are filtered out.
                    if filter.is_some_and(|f| f.mask == 2) {
                        assert_eq!(got.len(), k.min(40));
                    }
                }
            }
        }
    }
}
