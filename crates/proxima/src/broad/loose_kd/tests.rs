//! Unit tests of the loose k-d tree (the randomized oracle suite lives in
//! `tests/oracle` and `tests/loose_kd.rs`).

use super::*;

use crate::broad::walk::Walk;

use crate::broad::LooseKdConfig;

use crate::broad::BruteForce;
use crate::broad::SpatialIndexExt;
use glam::{vec3, Vec3};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

fn cube(side: f32) -> Aabb {
    Aabb::new(Vec3::ZERO, Vec3::splat(side))
}

/// The source's `RecursivePush` [sources: kd-insert], re-derived on boxes alone
/// (independently of the tree's code): the depth and box where a sphere must sit.
fn seed_placement(world: Aabb, r_max: f32, d: f32, cap: usize, s: &Sphere) -> (usize, Aabb) {
    let mut b = world;
    let mut depth = 0;
    loop {
        let size = b.max - b.min;
        let mut a = 0;
        for i in 1..3 {
            if size[i] > size[a] {
                a = i;
            }
        }
        let ext = b.max[a] - b.min[a];
        let half = r_max.min(ext * d * 0.25);
        if s.radius >= half || depth == cap {
            return (depth, b);
        }
        let mid = b.min[a] * 0.5 + b.max[a] * 0.5;
        if s.center[a] > mid {
            b.min[a] = mid - half;
        } else {
            b.max[a] = mid + half;
        }
        depth += 1;
    }
}

#[test]
fn bad_parameters_are_rejected() {
    let w = cube(10.0);
    assert!(LooseKdTree::<()>::with_config(LooseKdConfig {
        density: 0.5,
        ..LooseKdConfig::new(w, 1.0)
    })
    .is_ok());
    assert!(LooseKdTree::<()>::with_config(LooseKdConfig {
        density: 0.5,
        ..LooseKdConfig::new(w, 0.0)
    })
    .is_err());
    assert!(LooseKdTree::<()>::with_config(LooseKdConfig {
        density: 0.5,
        ..LooseKdConfig::new(w, -1.0)
    })
    .is_err());
    assert!(LooseKdTree::<()>::with_config(LooseKdConfig {
        density: 0.5,
        ..LooseKdConfig::new(w, f32::NAN)
    })
    .is_err());
    assert!(LooseKdTree::<()>::with_config(LooseKdConfig {
        density: 0.5,
        ..LooseKdConfig::new(w, f32::INFINITY)
    })
    .is_err());
    assert!(LooseKdTree::<()>::with_config(LooseKdConfig {
        density: 0.0,
        ..LooseKdConfig::new(w, 1.0)
    })
    .is_err());
    assert!(LooseKdTree::<()>::with_config(LooseKdConfig {
        density: 1.0001,
        ..LooseKdConfig::new(w, 1.0)
    })
    .is_err());
    assert!(LooseKdTree::<()>::with_config(LooseKdConfig {
        density: f32::NAN,
        ..LooseKdConfig::new(w, 1.0)
    })
    .is_err());
    assert!(LooseKdTree::<()>::with_config(LooseKdConfig {
        density: 1.0,
        ..LooseKdConfig::new(w, 1.0)
    })
    .is_ok());
    let inverted = Aabb::new(Vec3::ONE, Vec3::ZERO);
    assert!(LooseKdTree::<()>::with_config(LooseKdConfig {
        density: 0.5,
        ..LooseKdConfig::new(inverted, 1.0)
    })
    .is_err());
    assert!(LooseKdTree::<()>::with_config(LooseKdConfig {
        density: 0.5,
        ..LooseKdConfig::new(Aabb::new(Vec3::ZERO, Vec3::INFINITY), 1.0)
    })
    .is_err());
    assert!(LooseKdTree::<()>::with_config(LooseKdConfig {
        density: 0.5,
        max_depth: 0,
        ..LooseKdConfig::new(w, 1.0)
    })
    .is_err());
    assert!(LooseKdTree::<()>::with_config(LooseKdConfig {
        density: 0.5,
        max_depth: MAX_DEPTH_LIMIT + 1,
        ..LooseKdConfig::new(w, 1.0)
    })
    .is_err());
    assert!(LooseKdTree::<()>::with_config(LooseKdConfig {
        density: 0.5,
        max_depth: MAX_DEPTH_LIMIT,
        ..LooseKdConfig::new(w, 1.0)
    })
    .is_ok());
}

#[test]
fn crafted_spheres_land_where_the_seed_puts_them() {
    // World 16 x 8 x 8, d = 1, R_max large: root splits x at m = 8 with h = 4.
    let world = Aabb::new(Vec3::ZERO, vec3(16.0, 8.0, 8.0));
    let mut t = LooseKdTree::with_config(LooseKdConfig {
        density: 1.0,
        ..LooseKdConfig::new(world, 100.0)
    })
    .unwrap();
    let at = |t: &LooseKdTree<u32>, h| {
        let p = t.placement(h).unwrap();
        (p.depth, p.node_box)
    };
    // r >= h = 4: attached to the root.
    let a = t.insert(Sphere::new(vec3(9.0, 1.0, 1.0), 4.0), 0).unwrap();
    assert_eq!(at(&t, a), (0, world));
    // r < 4, c_x = 9 > 8: positive child [4, 16] (m = 10, h = 3); 3.9 >= 3 stops.
    let b = t.insert(Sphere::new(vec3(9.0, 1.0, 1.0), 3.9), 1).unwrap();
    let pos = Aabb::new(vec3(4.0, 0.0, 0.0), vec3(16.0, 8.0, 8.0));
    assert_eq!(at(&t, b), (1, pos));
    // c_x == m goes negative: [0, 12].
    let c = t.insert(Sphere::new(vec3(8.0, 1.0, 1.0), 3.9), 2).unwrap();
    let neg = Aabb::new(Vec3::ZERO, vec3(12.0, 8.0, 8.0));
    assert_eq!(at(&t, c), (1, neg));
    // r = 2.9 < 3 descends again: c_x = 9 <= 10 → [4, 13] (m = 8.5, h = 2.25).
    let d = t.insert(Sphere::new(vec3(9.0, 1.0, 1.0), 2.9), 3).unwrap();
    let deeper = Aabb::new(vec3(4.0, 0.0, 0.0), vec3(13.0, 8.0, 8.0));
    assert_eq!(at(&t, d), (2, deeper));
    // Far outside the world box: the rule only compares on split axes.
    let e = t
        .insert(Sphere::new(vec3(9.0, -50.0, 1000.0), 2.9), 4)
        .unwrap();
    assert_eq!(at(&t, e), (2, deeper));
    // Larger than R_max: root.
    let f = t
        .insert(Sphere::new(vec3(1.0, 1.0, 1.0), 500.0), 5)
        .unwrap();
    assert_eq!(at(&t, f), (0, world));
    // Moving d across the root's split sends it to the negative side.
    t.update(d, Sphere::new(vec3(7.0, 1.0, 1.0), 2.9)).unwrap();
    let s = t.get(d).unwrap().0;
    assert_eq!(at(&t, d), seed_placement(world, 100.0, 1.0, 40, &s));
    assert_eq!(at(&t, d).0, 2);
    // Shrinking b below its node's h sends it deeper.
    t.update(b, Sphere::new(vec3(9.0, 1.0, 1.0), 1.0)).unwrap();
    assert!(at(&t, b).0 > 1);
    t.validate().unwrap();
    assert_eq!(t.stats().items_per_depth.iter().sum::<usize>(), 6);
}

/// Random inserts, moves (small, long, resizes, out of the world) and removals:
/// after every step each object sits exactly where the rule of [sources: kd-insert] puts it.
#[test]
fn placement_invariant_over_random_history() {
    for (d, cap) in [(0.5, 40u8), (0.1, 40), (1.0, 6)] {
        let world = Aabb::new(vec3(-50.0, 0.0, 0.0), vec3(50.0, 60.0, 20.0));
        let mut t = LooseKdTree::with_config(LooseKdConfig {
            density: d,
            max_depth: cap,
            ..LooseKdConfig::new(world, 2.0)
        })
        .unwrap();
        let mut rng = Pcg64::seed_from_u64(7);
        let mut live = Vec::new();
        let sphere = |rng: &mut Pcg64| {
            let c = vec3(
                rng.gen_range(-70.0..70.0),
                rng.gen_range(-10.0..70.0),
                rng.gen_range(-5.0..25.0),
            );
            let r = match rng.gen_range(0..10) {
                0 => 0.0,
                1 => rng.gen_range(2.0..30.0),
                _ => rng.gen_range(0.0..2.0),
            };
            Sphere::new(c, r)
        };
        for step in 0..4000 {
            match rng.gen_range(0..10) {
                0..=3 => live.push(t.insert(sphere(&mut rng), step).unwrap()),
                4..=7 if !live.is_empty() => {
                    let h = live[rng.gen_range(0..live.len())];
                    let old = t.get(h).unwrap().0;
                    let s = if rng.gen_bool(0.7) {
                        Sphere::new(
                            old.center + Vec3::splat(rng.gen_range(-1.0..1.0)),
                            old.radius,
                        )
                    } else {
                        sphere(&mut rng)
                    };
                    t.update(h, s).unwrap();
                }
                _ if !live.is_empty() => {
                    let h = live.swap_remove(rng.gen_range(0..live.len()));
                    t.remove(h).unwrap();
                }
                _ => {}
            }
            if step % 50 == 0 {
                t.validate().unwrap();
                for &h in &live {
                    let s = t.get(h).unwrap().0;
                    let p = t.placement(h).unwrap();
                    let want = seed_placement(world, 2.0, d, cap as usize, &s);
                    assert_eq!((p.depth, p.node_box), want, "d {d} step {step} {s:?}");
                }
            }
        }
    }
}

/// Because moves keep the placement rule exact, the tree depends only on the
/// current spheres: moving objects gives the same shape as inserting them fresh.
#[test]
fn shape_is_independent_of_history() {
    let world = cube(100.0);
    let mut rng = Pcg64::seed_from_u64(3);
    let mut moved = LooseKdTree::with_config(LooseKdConfig {
        density: 0.5,
        ..LooseKdConfig::new(world, 2.0)
    })
    .unwrap();
    let mut hs = Vec::new();
    for i in 0..2000 {
        let c = vec3(
            rng.gen_range(0.0..100.0),
            rng.gen_range(0.0..100.0),
            rng.gen_range(0.0..100.0),
        );
        hs.push(
            moved
                .insert(Sphere::new(c, rng.gen_range(0.5..2.0)), i)
                .unwrap(),
        );
    }
    for _ in 0..5 {
        for &h in &hs {
            let s = moved.get(h).unwrap().0;
            let step = vec3(
                rng.gen_range(-3.0..3.0),
                rng.gen_range(-3.0..3.0),
                rng.gen_range(-3.0..3.0),
            );
            moved
                .update(h, Sphere::new(s.center + step, s.radius))
                .unwrap();
        }
    }
    let mut fresh = LooseKdTree::with_config(LooseKdConfig {
        density: 0.5,
        ..LooseKdConfig::new(world, 2.0)
    })
    .unwrap();
    moved.for_each(&mut |_, s, v| {
        fresh.insert(*s, *v).unwrap();
    });
    moved.validate().unwrap();
    fresh.validate().unwrap();
    assert_eq!(moved.stats(), fresh.stats());
}

#[test]
fn depth_cap_holds_100k_points_on_one_point() {
    let mut t = LooseKdTree::with_config(LooseKdConfig {
        density: 0.5,
        max_depth: LooseKdConfig::DEFAULT_MAX_DEPTH,
        ..LooseKdConfig::new(cube(100.0), 2.0)
    })
    .unwrap();
    let p = vec3(37.5, 12.25, 80.0);
    let hs: Vec<_> = (0..100_000)
        .map(|i| t.insert(Sphere::new(p, 0.0), i).unwrap())
        .collect();
    t.validate().unwrap();
    let st = t.stats();
    assert_eq!(st.max_depth, LooseKdConfig::DEFAULT_MAX_DEPTH as usize);
    assert_eq!(
        st.nodes,
        LooseKdConfig::DEFAULT_MAX_DEPTH as usize + 1,
        "one path"
    );
    assert_eq!(st.max_items_per_node, 100_000);
    assert_eq!(t.within(p, 0.0).unwrap().len(), 100_000);
    assert!(t.within(p + Vec3::X, 0.5).unwrap().is_empty());
    // Moving within the capped cell is O(1) and keeps the structure.
    t.update(hs[0], Sphere::new(p + Vec3::splat(1e-6), 0.0))
        .unwrap();
    for h in hs {
        t.remove(h).unwrap();
    }
    t.validate().unwrap();
    assert_eq!(t.stats(), KdStats::default());
}

#[test]
fn ray_first_ties_go_to_the_smallest_handle() {
    let mut t = LooseKdTree::with_config(LooseKdConfig {
        density: 0.5,
        ..LooseKdConfig::new(cube(100.0), 2.0)
    })
    .unwrap();
    let mut b = BruteForce::new();
    let s = Sphere::new(vec3(50.0, 50.0, 50.0), 1.0);
    let mut hs = Vec::new();
    for i in 0..5 {
        // Same sphere, scattered insertion order around other objects.
        t.insert(Sphere::new(vec3(10.0 * i as f32, 5.0, 5.0), 1.0), 100)
            .unwrap();
        hs.push(t.insert(s, i).unwrap());
        b.insert(s, i).unwrap();
    }
    let ray = Ray::new(vec3(0.0, 50.0, 50.0), Vec3::X);
    let hit = t.ray_first(&ray, None).unwrap().unwrap();
    assert_eq!(hit.t, 49.0);
    assert_eq!(hit.handle, *hs.iter().min().unwrap());
    assert_eq!(b.ray_first(&ray, None).unwrap().unwrap().t, 49.0);
}

#[test]
fn memory_is_pooled_and_released_by_clear() {
    let mut t = LooseKdTree::with_config(LooseKdConfig {
        density: 0.5,
        ..LooseKdConfig::new(cube(100.0), 2.0)
    })
    .unwrap();
    let empty = t.memory_bytes();
    let mut rng = Pcg64::seed_from_u64(9);
    let hs: Vec<_> = (0..1000)
        .map(|i| {
            let c = Vec3::splat(rng.gen_range(0.0..100.0));
            t.insert(Sphere::new(c, 1.0), i).unwrap()
        })
        .collect();
    let full = t.memory_bytes();
    assert!(full > empty + 1000 * std::mem::size_of::<Sphere>());
    for h in hs {
        t.remove(h).unwrap();
    }
    // The object array keeps its capacity for reuse (compaction rebuilds the
    // node pool, so the total may shrink a little)...
    assert!(t.memory_bytes() >= empty + 1000 * std::mem::size_of::<Sphere>());
    // ...until clear releases it.
    t.clear();
    assert_eq!(t.memory_bytes(), empty);
    t.validate().unwrap();
}

#[test]
fn stale_handles_and_bad_spheres_change_nothing() {
    let mut t = LooseKdTree::with_config(LooseKdConfig {
        density: 0.5,
        ..LooseKdConfig::new(cube(10.0), 1.0)
    })
    .unwrap();
    let h = t.insert(Sphere::new(Vec3::ONE, 0.5), 1).unwrap();
    let before = t.stats();
    assert!(t.update(h, Sphere::new(Vec3::NAN, 0.5)).is_err());
    assert!(t.update(h, Sphere::new(Vec3::ONE, -0.5)).is_err());
    assert!(t.insert(Sphere::new(Vec3::ONE, f32::INFINITY), 2).is_err());
    assert_eq!(t.stats(), before);
    assert_eq!(t.remove(h), Ok(1));
    assert!(t.remove(h).is_err());
    assert!(t.update(h, Sphere::new(Vec3::ONE, 0.5)).is_err());
    assert!(t.placement(h).is_err());
    t.validate().unwrap();
}

/// Unordered pairs of payloads reported by `for_each_pair`, sorted; panics on a
/// pair reported twice.
fn value_pairs<I: SpatialIndex<u32>>(t: &I) -> Vec<(u32, u32)> {
    let mut v = Vec::new();
    let _ = t.for_each_pair(|_, a, _, b| {
        v.push((*a.min(b), *a.max(b)));
        ControlFlow::Continue(())
    });
    v.sort_unstable();
    let n = v.len();
    v.dedup();
    assert_eq!(v.len(), n, "a pair was reported twice");
    v
}

#[test]
fn crowded_nodes_sweep_finds_exactly_touching_pairs() {
    // Big spheres on a grid whose spacing equals the sum of radii (every grid
    // neighbour touches exactly) all stop at the root, so the root's own test and
    // the carried sets of the nodes below are far above the sweep threshold.
    let world = cube(20.0);
    let mut t = LooseKdTree::with_config(LooseKdConfig {
        density: 0.2,
        ..LooseKdConfig::new(world, 2.0)
    })
    .unwrap();
    let mut b = BruteForce::new();
    let mut rng = Pcg64::seed_from_u64(17);
    let mut hs = Vec::new();
    let mut v = 0u32;
    for x in 0..7 {
        for y in 0..7 {
            for z in 0..7 {
                let s = Sphere::new(vec3(x as f32, y as f32, z as f32) * 3.0, 1.5);
                hs.push((t.insert(s, v).unwrap(), b.insert(s, v).unwrap()));
                v += 1;
            }
        }
    }
    for _ in 0..600 {
        let c = vec3(
            rng.gen_range(0.0..20.0),
            rng.gen_range(0.0..20.0),
            rng.gen_range(0.0..20.0),
        );
        let s = Sphere::new(c, rng.gen_range(0.05..0.6));
        hs.push((t.insert(s, v).unwrap(), b.insert(s, v).unwrap()));
        v += 1;
    }
    assert!(t.stats().max_items_per_node >= 343);
    let expect = value_pairs(&b);
    assert!(expect.len() >= 3 * 6 * 49, "grid neighbours touch");
    assert_eq!(value_pairs(&t), expect);
    // Small moves, some of them changing node.
    for _ in 0..5 {
        for &(ht, hb) in &hs {
            let (s, _) = t.get(ht).unwrap();
            let d = vec3(
                rng.gen_range(-0.3..0.3),
                rng.gen_range(-0.3..0.3),
                rng.gen_range(-0.3..0.3),
            );
            let s = Sphere::new(s.center + d, s.radius);
            t.update(ht, s).unwrap();
            b.update(hb, s).unwrap();
        }
        t.validate().unwrap();
        assert_eq!(value_pairs(&t), value_pairs(&b));
    }
}

#[test]
fn bucketed_sweep_with_degenerate_and_overflowing_ranges() {
    // Nodes with many own objects take the bucketed sweep. Its bucket map must
    // stay non-decreasing when the lower ends are all equal (range 0), when
    // their range overflows f32 (far outside the world box), and with inert
    // objects and filters mixed in; every case against brute force.
    let world = cube(20.0);
    let scenes: Vec<Vec<Sphere>> = vec![
        // 40 identical spheres big enough to stop at the root: range 0.
        vec![Sphere::new(vec3(10.0, 10.0, 10.0), 1.9); 40],
        // Lower ends from -3e38 to 3e38: their range is infinite.
        (0..48)
            .map(|i| {
                let x = if i % 2 == 0 { -3e38 } else { 3e38 };
                Sphere::new(vec3(x, (i / 2) as f32 * 0.5, 0.0), 1.9)
            })
            .collect(),
        // A crowd with a few huge outliers, so most buckets stay empty and the
        // windows of the outliers' neighbours end in the same bucket.
        (0..120)
            .map(|i| {
                let t = i as f32;
                let c = if i % 30 == 0 {
                    vec3(1e30 * (t - 60.0), 3.0, 3.0)
                } else {
                    vec3(
                        10.0 + (t * 0.37).sin() * 4.0,
                        10.0 + (t * 0.71).cos() * 4.0,
                        10.0 + (t * 0.13).sin(),
                    )
                };
                Sphere::new(c, 1.5 + (t * 0.29).sin().abs() * 0.4)
            })
            .collect(),
    ];
    for (k, spheres) in scenes.iter().enumerate() {
        for filtered in [false, true] {
            let mut t = LooseKdTree::with_config(LooseKdConfig {
                density: 0.2,
                ..LooseKdConfig::new(world, 2.0)
            })
            .unwrap();
            let mut b = BruteForce::new();
            for (i, s) in spheres.iter().enumerate() {
                let v = i as u32;
                // Every third object inert, every fifth in a group of its own.
                let f = match (filtered, i % 3, i % 5) {
                    (false, _, _) => Filter::ALL,
                    (true, 0, _) => Filter::new(0, u32::MAX),
                    (true, _, 0) => Filter::new(2, 2),
                    _ => Filter::new(1, 1),
                };
                t.insert_with_filter(*s, f, v).unwrap();
                b.insert_with_filter(*s, f, v).unwrap();
            }
            assert!(
                t.stats().max_items_per_node >= 32,
                "scene {k}: the sweep must run"
            );
            let expect = value_pairs(&b);
            assert!(!expect.is_empty(), "scene {k}");
            assert_eq!(value_pairs(&t), expect, "scene {k}, filtered {filtered}");
            // A search stopped at its first pair reports exactly one.
            let mut seen = 0;
            let _ = t.for_each_pair(|_, _, _, _| {
                seen += 1;
                ControlFlow::Break(())
            });
            assert_eq!(seen, 1, "scene {k}");
        }
    }
}

#[test]
fn nested_pair_searches_use_their_own_buffers() {
    let mut t = LooseKdTree::with_config(LooseKdConfig {
        density: 0.2,
        ..LooseKdConfig::new(cube(20.0), 2.0)
    })
    .unwrap();
    let mut rng = Pcg64::seed_from_u64(5);
    for i in 0..500u32 {
        let c = vec3(
            rng.gen_range(0.0..20.0),
            rng.gen_range(0.0..20.0),
            rng.gen_range(0.0..20.0),
        );
        t.insert(Sphere::new(c, rng.gen_range(0.1..1.5)), i)
            .unwrap();
    }
    let outer = value_pairs(&t);
    assert!(!outer.is_empty());
    // A callback that runs a whole search itself, while the outer one holds the
    // tree's buffers: both must see every pair.
    let mut seen = 0;
    let _ = t.for_each_pair(|_, _, _, _| {
        assert_eq!(value_pairs(&t), outer);
        seen += 1;
        ControlFlow::Break(())
    });
    assert_eq!(seen, 1);
    assert_eq!(value_pairs(&t), outer, "buffers still usable afterwards");
}

#[test]
fn object_array_compacts_and_stays_exact_under_moves() {
    // Many small moves across cell borders relocate ranges and free nodes; the
    // array must get compacted (bounded dead and out-of-order counts), stay valid,
    // and keep giving the brute-force pairs and payloads.
    let mut t = LooseKdTree::with_config(LooseKdConfig {
        density: 0.25,
        ..LooseKdConfig::new(cube(60.0), 2.0)
    })
    .unwrap();
    let mut b = BruteForce::new();
    let mut rng = Pcg64::seed_from_u64(21);
    let mut objs: Vec<(Handle, Handle, Sphere)> = Vec::new();
    for i in 0..3000u32 {
        let c = Vec3::new(
            rng.gen_range(0.0..60.0),
            rng.gen_range(0.0..60.0),
            rng.gen_range(0.0..60.0),
        );
        let s = Sphere::new(c, rng.gen_range(0.1..2.0));
        objs.push((t.insert(s, i).unwrap(), b.insert(s, i).unwrap(), s));
    }
    let mut compactions = 0;
    for frame in 0..40 {
        for (th, bh, s) in objs.iter_mut() {
            let d = Vec3::new(
                rng.gen_range(-1.0..1.0),
                rng.gen_range(-1.0..1.0),
                rng.gen_range(-1.0..1.0),
            );
            s.center = (s.center + d).clamp(Vec3::ZERO, Vec3::splat(60.0));
            let before = t.store.disorder;
            t.update(*th, *s).unwrap();
            b.update(*bh, *s).unwrap();
            compactions += (t.store.disorder < before) as usize;
        }
        assert!(t.store.dead <= COMPACT_BOUND + t.len() / 2);
        t.validate().unwrap();
        if frame % 10 == 9 {
            assert_eq!(value_pairs(&t), value_pairs(&b));
            for (th, _, s) in &objs {
                assert_eq!(t.get(*th).unwrap().0, *s);
            }
        }
    }
    assert!(compactions > 0, "moves never triggered a compaction");
    *t.get_mut(objs[7].0).unwrap() = 99;
    assert_eq!(*t.get(objs[7].0).unwrap().1, 99);
}

/// Upper bound on the dead positions of a compacted-as-needed array (the
/// threshold of `insert::maybe_compact`, plus the one range freed last).
const COMPACT_BOUND: usize = 64 + 64;

/// Handles `index` selects for `q`, sorted.
fn selected<I: Walk<u32>, Q: Selection>(index: &I, q: &Q) -> Vec<u32> {
    let mut v = Vec::new();
    let _ = index.walk(q, |_, _, &x| {
        v.push(x);
        ControlFlow::Continue(())
    });
    v.sort_unstable();
    v
}

#[test]
fn chunk_bounds_prune_exactly_under_moves_removals_and_odd_queries() {
    // Chunk bounds only grow between compactions: moved, swapped-in and
    // relocated objects, objects outside the world or larger than R_max, and
    // queries of every shape (degenerate, tiny, huge, outside) must still give
    // exactly the brute-force answer.
    use crate::geom::Frustum;
    use glam::Mat4;
    let side = 80.0;
    let mut t = LooseKdTree::new(cube(side), 2.0).unwrap();
    let mut b = BruteForce::new();
    let mut rng = Pcg64::seed_from_u64(77);
    let mut objs: Vec<(Handle, Handle, Sphere, u32)> = Vec::new();
    let mut next_id = 0u32;
    let sphere = |rng: &mut Pcg64| {
        let c = Vec3::new(
            rng.gen_range(-5.0..side + 5.0),
            rng.gen_range(-5.0..side + 5.0),
            rng.gen_range(-5.0..side + 5.0),
        );
        let r = match rng.gen_range(0..20) {
            0 => 0.0,
            1 => rng.gen_range(2.0..9.0),
            _ => rng.gen_range(0.3..2.0),
        };
        Sphere::new(c, r)
    };
    let loose = |t: &LooseKdTree<u32>| {
        let (mut stack, mut k) = (vec![t.root], 0);
        while let Some(n) = stack.pop() {
            if n != NIL {
                k += t.nodes[n].loose as usize;
                stack.extend(t.nodes[n].child);
            }
        }
        k
    };
    let mut loose_frames = 0;
    for frame in 0..30 {
        // Inserts, then moves (mostly small: bounds grow in place), then removals.
        for _ in 0..400 {
            let s = sphere(&mut rng);
            objs.push((
                t.insert(s, next_id).unwrap(),
                b.insert(s, next_id).unwrap(),
                s,
                next_id,
            ));
            next_id += 1;
        }
        for (th, bh, s, _) in objs.iter_mut() {
            if rng.gen_range(0..4) == 0 {
                *s = if rng.gen_range(0..10) == 0 {
                    sphere(&mut rng)
                } else {
                    let d = Vec3::new(
                        rng.gen_range(-0.7..0.7),
                        rng.gen_range(-0.7..0.7),
                        rng.gen_range(-0.7..0.7),
                    );
                    Sphere::new(s.center + d, s.radius)
                };
                t.update(*th, *s).unwrap();
                b.update(*bh, *s).unwrap();
            }
        }
        loose_frames += (loose(&t) > 0) as usize;
        for _ in 0..250 {
            let i = rng.gen_range(0..objs.len());
            let (th, bh, _, id) = objs.swap_remove(i);
            assert_eq!(t.remove(th).unwrap(), id);
            assert_eq!(b.remove(bh).unwrap(), id);
        }
        // Both query paths: nodes made loose by in-place moves (tested object by
        // object) and, after a compaction, exact chunk bounds (then grown by
        // the inserts, swap-removals and relocations of the next frame).
        if frame % 2 == 1 {
            t.compact();
            assert_eq!(loose(&t), 0);
        }
        t.validate().unwrap();
        // Queries at objects' current centres: a moved object outside a stale
        // chunk bound would be missed by them.
        let near: Vec<Vec3> = (0..120)
            .map(|_| objs[rng.gen_range(0..objs.len())].2.center)
            .collect();
        let mut p = || {
            Vec3::new(
                rng.gen_range(-10.0..side + 10.0),
                rng.gen_range(-10.0..side + 10.0),
                rng.gen_range(-10.0..side + 10.0),
            )
        };
        for k in 0..180 {
            let (c, r) = if k < 60 {
                (p(), [0.0, 1e-6, 1.0, 3.0, 12.0, 1e4][k % 6])
            } else {
                (near[k - 60], [0.0, 1e-6, 0.05, 0.3, 1.0, 3.0][k % 6])
            };
            let q = Sphere::new(c, r);
            assert_eq!(selected(&t, &q), selected(&b, &q), "sphere {q:?}");
            let h = Vec3::new(r, 0.5 * r, 2.0 * r);
            let q = Aabb::new(c - h, c + h);
            assert_eq!(selected(&t, &q), selected(&b, &q), "box {q:?}");
            let dir = (p() - c).normalize_or(Vec3::X);
            for q in [
                Ray::new(c, dir),
                Ray::with_max_t(c, dir, r),
                Ray::with_max_t(c, Vec3::Z, 0.0),
            ] {
                assert_eq!(selected(&t, &q), selected(&b, &q), "ray {q:?}");
            }
        }
        for _ in 0..3 {
            let view = Mat4::look_at_rh(p(), p(), Vec3::Z);
            let far = [5.0, 40.0, 1e4][frame % 3];
            let proj = Mat4::perspective_rh(1.0, 1.5, 0.1, far);
            if let Ok(q) = Frustum::from_view_projection(proj * view) {
                assert_eq!(selected(&t, &q), selected(&b, &q), "frustum");
            }
        }
    }
    assert!(loose_frames > 10, "moves rarely made a node loose");
}

/// The default depth cap comes from the scene: cells about `R_max` wide, plus
/// the slack levels (a cube 100 wide with `R_max` 2: 6 splits per axis + 3).
/// A point cloud then stops at that depth instead of 40 (W7: 100k points took
/// 4.7 s to build at 40); spheres above 2% of `R_max` still stop by the
/// border-zone rule above the cap, exactly where they stopped before.
#[test]
fn default_depth_cap_follows_the_scene() {
    assert_eq!(LooseKdConfig::depth_for(&cube(100.0), 2.0), 21);
    assert_eq!(LooseKdConfig::new(cube(100.0), 2.0).max_depth, 21);
    // Wider than the largest cap allows, or R_max as wide as the world.
    assert_eq!(
        LooseKdConfig::depth_for(&cube(1e9), 1e-3),
        LooseKdConfig::DEFAULT_MAX_DEPTH
    );
    assert_eq!(
        LooseKdConfig::depth_for(&cube(1.0), 5.0),
        LooseKdConfig::DEPTH_SLACK
    );
    assert_eq!(
        LooseKdConfig::depth_for(&cube(100.0), f32::NAN),
        LooseKdConfig::DEFAULT_MAX_DEPTH
    );

    // A point cloud on a lattice 1 apart (R_max 2): nobody goes below the cap,
    // and every point is found.
    let mut t = LooseKdTree::new(cube(100.0), 2.0).unwrap();
    let mut pts = Vec::new();
    for i in 0..30 {
        for j in 0..30 {
            for k in 0..30 {
                pts.push(vec3(
                    i as f32 * 3.0 + 1.0,
                    j as f32 * 3.0 + 1.0,
                    k as f32 * 3.0 + 1.0,
                ));
            }
        }
    }
    for (n, p) in pts.iter().enumerate() {
        t.insert(Sphere::new(*p, 0.0), n).unwrap();
    }
    t.validate().unwrap();
    let st = t.stats();
    assert_eq!(st.max_depth, 21, "points stop at the scene's cap");
    let mut deep = LooseKdTree::with_config(LooseKdConfig {
        max_depth: LooseKdConfig::DEFAULT_MAX_DEPTH,
        ..LooseKdConfig::new(cube(100.0), 2.0)
    })
    .unwrap();
    for (n, p) in pts.iter().enumerate() {
        deep.insert(Sphere::new(*p, 0.0), n).unwrap();
    }
    let deep_nodes = deep.stats().nodes;
    assert!(
        3 * st.nodes < deep_nodes,
        "{} nodes at the scene's cap, {deep_nodes} at 40",
        st.nodes
    );
    for (n, p) in pts.iter().enumerate().step_by(97) {
        assert_eq!(t.within(*p, 0.0).unwrap().len(), 1, "point {n}");
    }
    // Spheres of W1's sizes stop where the border-zone rule puts them, above
    // the cap: the same depths as with the old cap of 40.
    let mut old = LooseKdTree::with_config(LooseKdConfig {
        max_depth: LooseKdConfig::DEFAULT_MAX_DEPTH,
        ..LooseKdConfig::new(cube(100.0), 2.0)
    })
    .unwrap();
    let mut new = LooseKdTree::new(cube(100.0), 2.0).unwrap();
    let mut rng = Pcg64::seed_from_u64(11);
    for n in 0..5000 {
        let c = vec3(
            rng.gen_range(0.0..100.0),
            rng.gen_range(0.0..100.0),
            rng.gen_range(0.0..100.0),
        );
        let s = Sphere::new(c, rng.gen_range(0.05..2.0));
        old.insert(s, n).unwrap();
        new.insert(s, n).unwrap();
    }
    assert_eq!(old.stats(), new.stats());
}
