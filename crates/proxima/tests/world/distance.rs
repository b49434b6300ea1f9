//! World distances (issue #15 part 4) against brute force over every object
//! pair and every triangle pair (`triangle_distance` of the world-posed `f32`
//! triangles, `f64`): `distance`, `nearest_obstacle` with filters and ignored
//! pairs, `contacts_within` (with margin 0 exactly `contacts`).

use super::{grid_pose, meshes, random_pose, MeshData};
use proxima::broad::Filter;
use proxima::geom::Sphere as SphereBv;
use proxima::glam::{Affine3A, DVec3, Vec3};
use proxima::narrow::{closest_point_on_triangle, triangle_distance, BoundingVolume, Kdop18, Obb};
use proxima::world::{ObjectDistance, Shape, World, WorldConfig};
use proxima::{Error, Handle};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use std::collections::{BTreeMap, BTreeSet};
use std::sync::Arc;

/// The scene's extent (objects within a few units): the tolerance between
/// distances measured in the world frame and in a mesh's frame is 1e-5 of it.
const TOL: f64 = 1e-5 * 8.0;

#[derive(Clone)]
enum Sh {
    Mesh(Arc<MeshData>),
    Ball(f32),
}

struct Obj {
    h: Handle,
    sh: Sh,
    pose: Affine3A,
    filter: Filter,
}

/// The world-posed triangles of a mesh object.
fn world_tris(m: &MeshData, pose: &Affine3A) -> Vec<[Vec3; 3]> {
    (0..m.triangles.len())
        .map(|i| m.triangle(i).map(|v| pose.transform_point3(v)))
        .collect()
}

/// Every primitive pair of two objects with its distance.
type PairDistances = Vec<((u32, u32), f64)>;

/// Brute-force distance of two objects, and every primitive pair's distance.
fn brute(a: &Obj, b: &Obj) -> (f64, PairDistances) {
    let centre = |o: &Obj| Vec3::from(o.pose.translation);
    let mut all = Vec::new();
    match (&a.sh, &b.sh) {
        (Sh::Mesh(ma), Sh::Mesh(mb)) => {
            let (ta, tb) = (world_tris(ma, &a.pose), world_tris(mb, &b.pose));
            for (i, x) in ta.iter().enumerate() {
                for (j, y) in tb.iter().enumerate() {
                    all.push(((i as u32, j as u32), triangle_distance(x, y).distance));
                }
            }
        }
        (Sh::Ball(r), Sh::Mesh(m)) | (Sh::Mesh(m), Sh::Ball(r)) => {
            let (ball, mesh, ball_first) = match a.sh {
                Sh::Ball(_) => (a, b, true),
                _ => (b, a, false),
            };
            let c = centre(ball);
            for (j, t) in world_tris(m, &mesh.pose).iter().enumerate() {
                let d =
                    (closest_point_on_triangle(c, t).distance(c.as_dvec3()) - *r as f64).max(0.0);
                let k = if ball_first {
                    (0, j as u32)
                } else {
                    (j as u32, 0)
                };
                all.push((k, d));
            }
        }
        (Sh::Ball(ra), Sh::Ball(rb)) => {
            let d = centre(a).as_dvec3().distance(centre(b).as_dvec3()) - *ra as f64 - *rb as f64;
            all.push(((0, 0), d.max(0.0)));
        }
    }
    let min = all.iter().map(|x| x.1).fold(f64::INFINITY, f64::min);
    (min, all)
}

/// How far `p` is from primitive `k` of `o` (world frame).
fn off_shape(o: &Obj, k: u32, p: DVec3) -> f64 {
    match &o.sh {
        Sh::Mesh(m) => {
            let t = world_tris(m, &o.pose)[k as usize];
            let q = closest_point_on_triangle(p.as_vec3(), &t);
            (q - p).length()
        }
        Sh::Ball(r) => {
            assert_eq!(k, 0);
            (p.distance(Vec3::from(o.pose.translation).as_dvec3()) - *r as f64).max(0.0)
        }
    }
}

/// A random scene in a world with volume `BV`: meshes of every kind and balls,
/// random and exact (touching) poses, some filters and ignored pairs.
fn scene<BV: BoundingVolume>(seed: u64, n: usize, filters: bool) -> (World<u64, BV>, Vec<Obj>) {
    let mut rng = Pcg64::seed_from_u64(seed);
    let ms = meshes(&mut rng);
    let mut world = World::<u64, BV>::new(WorldConfig::default()).unwrap();
    let mut objs = Vec::new();
    for k in 0..n {
        let sh = match rng.gen_range(0..8) {
            0 => Sh::Ball(rng.gen_range(0.05..0.4)),
            1 => Sh::Ball(0.0),
            _ => Sh::Mesh(ms[rng.gen_range(0..ms.len())].clone()),
        };
        let pose = if rng.gen_bool(0.3) {
            grid_pose(&mut rng, 3)
        } else {
            random_pose(&mut rng, 1.6)
        };
        let filter = if filters && rng.gen_bool(0.4) {
            Filter::new(rng.gen_range(0..4), rng.gen_range(0..4))
        } else {
            Filter::ALL
        };
        let shape: Shape<BV> = match &sh {
            Sh::Mesh(m) => m.mesh::<BV>().into(),
            Sh::Ball(r) => Shape::sphere(*r).unwrap(),
        };
        let h = world
            .insert_with_filter(shape, pose, k as u64, filter)
            .unwrap();
        objs.push(Obj {
            h,
            sh,
            pose,
            filter,
        });
    }
    if filters {
        for _ in 0..n / 2 {
            let (i, j) = (rng.gen_range(0..n), rng.gen_range(0..n));
            if i != j {
                world.ignore(objs[i].h, objs[j].h).unwrap();
            }
        }
    }
    (world, objs)
}

fn eligible<BV: BoundingVolume>(w: &World<u64, BV>, a: &Obj, b: &Obj) -> bool {
    a.h != b.h && a.filter.interacts(b.filter) && !w.is_ignored(a.h, b.h).unwrap()
}

/// Checks one distance answer against brute force: value, points on their
/// primitives, at that distance.
fn check_distance(d: &ObjectDistance, a: &Obj, b: &Obj, want: f64, ctx: &str) {
    assert_eq!((d.a, d.b), (a.h, b.h), "{ctx}");
    assert!(
        (d.distance - want).abs() <= TOL,
        "{ctx}: {} vs brute {want}",
        d.distance
    );
    assert!(d.distance >= 0.0, "{ctx}");
    let [p, q] = d.points;
    assert!(
        off_shape(a, d.primitives.0, p) <= TOL,
        "{ctx}: point of a off its primitive"
    );
    assert!(
        off_shape(b, d.primitives.1, q) <= TOL,
        "{ctx}: point of b off its primitive"
    );
    assert!(
        ((p - q).length() - d.distance).abs() <= TOL,
        "{ctx}: points {p} {q}"
    );
}

fn distances_match_brute_force<BV: BoundingVolume>(seed: u64) -> (usize, usize) {
    let (mut world, objs) = scene::<BV>(seed, 12, false);
    let contacts = world.contacts().unwrap();
    let touching: BTreeSet<(Handle, Handle)> = contacts.pairs.iter().map(|c| (c.a, c.b)).collect();
    let (mut zero, mut apart) = (0, 0);
    for a in &objs {
        for b in &objs {
            if a.h == b.h {
                continue;
            }
            let ctx = format!("{} seed {seed} {:?} {:?}", BV::NAME, a.h, b.h);
            let d = world.distance(a.h, b.h).unwrap();
            let (want, _) = brute(a, b);
            check_distance(&d, a, b, want, &ctx);
            // Zero exactly when contacts reports the pair.
            let key = if a.h < b.h { (a.h, b.h) } else { (b.h, a.h) };
            assert_eq!(
                d.distance == 0.0,
                touching.contains(&key),
                "{ctx}: {}",
                d.distance
            );
            // Symmetric.
            let e = world.distance(b.h, a.h).unwrap();
            assert_eq!(e.distance, d.distance, "{ctx}");
            assert_eq!((e.primitives.1, e.primitives.0), d.primitives, "{ctx}");
            if d.distance == 0.0 {
                zero += 1;
            } else {
                apart += 1;
            }
        }
    }
    (zero, apart)
}

#[test]
fn distance_matches_brute_force_and_contacts() {
    let (mut zero, mut apart) = (0, 0);
    for seed in 0..6 {
        for (z, a) in [
            distances_match_brute_force::<Kdop18>(seed),
            distances_match_brute_force::<Obb>(100 + seed),
            distances_match_brute_force::<SphereBv>(200 + seed),
        ] {
            zero += z;
            apart += a;
        }
    }
    assert!(zero > 30 && apart > 300, "{zero} touching, {apart} apart");
}

fn nearest_matches_brute_force<BV: BoundingVolume>(seed: u64) -> usize {
    let (world, objs) = scene::<BV>(seed, 14, true);
    let mut found = 0;
    for a in &objs {
        let ctx = format!("{} seed {seed} {:?}", BV::NAME, a.h);
        let got = world.nearest_obstacle(a.h).unwrap();
        let cands: Vec<&Obj> = objs.iter().filter(|b| eligible(&world, a, b)).collect();
        let Some(n) = got else {
            assert!(cands.is_empty(), "{ctx}: none found among {}", cands.len());
            continue;
        };
        found += 1;
        let b = cands
            .iter()
            .find(|b| b.h == n.b)
            .expect("an eligible obstacle");
        let want = cands
            .iter()
            .map(|b| brute(a, b).0)
            .fold(f64::INFINITY, f64::min);
        check_distance(&n, a, b, want, &ctx);
        // The nearest by the world's own distance, ties to the smaller handle.
        assert_eq!(n, world.distance(a.h, n.b).unwrap(), "{ctx}");
        for c in &cands {
            let d = world.distance(a.h, c.h).unwrap().distance;
            assert!(
                d > n.distance || (d == n.distance && c.h >= n.b),
                "{ctx}: {:?} at {d}",
                c.h
            );
        }
    }
    found
}

#[test]
fn nearest_obstacle_honours_filters_and_ignored_pairs() {
    let mut found = 0;
    for seed in 0..8 {
        found += nearest_matches_brute_force::<Kdop18>(seed);
        found += nearest_matches_brute_force::<Obb>(50 + seed);
    }
    assert!(found > 150, "{found}");
    // A lone object, and one whose filter meets nobody's.
    let mut w = World::<u64>::new(WorldConfig::default()).unwrap();
    let a = w
        .insert(Shape::sphere(1.0).unwrap(), Affine3A::IDENTITY, 0)
        .unwrap();
    assert_eq!(w.nearest_obstacle(a).unwrap(), None);
    let b = w
        .insert_with_filter(
            Shape::sphere(1.0).unwrap(),
            Affine3A::from_translation(Vec3::X * 5.0),
            1,
            Filter::new(1, 0),
        )
        .unwrap();
    assert_eq!(w.nearest_obstacle(a).unwrap(), None);
    w.set_filter(b, Filter::ALL).unwrap();
    let n = w.nearest_obstacle(a).unwrap().unwrap();
    assert_eq!((n.b, n.distance), (b, 3.0));
    w.ignore(a, b).unwrap();
    assert_eq!(w.nearest_obstacle(a).unwrap(), None);
}

fn contacts_within_match_brute_force<BV: BoundingVolume>(seed: u64) -> (usize, usize) {
    let (mut world, objs) = scene::<BV>(seed, 12, true);
    // Margin 0: exactly `contacts`.
    let plain = world.contacts().unwrap();
    let zero = world.contacts_within(0.0).unwrap();
    assert_eq!(zero.pairs, plain.pairs, "{} seed {seed}", BV::NAME);
    assert_eq!(zero.triangles, plain.triangles, "{} seed {seed}", BV::NAME);
    let mut seen = (0, 0);
    for margin in [0.02f64, 0.1, 0.35] {
        let r = world.contacts_within(margin).unwrap();
        let got: BTreeMap<(Handle, Handle), BTreeSet<(u32, u32)>> = r
            .pairs
            .iter()
            .map(|c| ((c.a, c.b), r.triangles_of(c).iter().copied().collect()))
            .collect();
        // Sorted by handles, each pair's primitives ascending.
        assert!(r
            .pairs
            .windows(2)
            .all(|w| (w[0].a, w[0].b) < (w[1].a, w[1].b)));
        assert!(r
            .pairs
            .iter()
            .all(|c| r.triangles_of(c).windows(2).all(|w| w[0] < w[1])));
        for (i, a) in objs.iter().enumerate() {
            for b in &objs[i + 1..] {
                let key = if a.h < b.h { (a.h, b.h) } else { (b.h, a.h) };
                let ctx = format!("{} seed {seed} margin {margin} {key:?}", BV::NAME);
                let listed = got.get(&key);
                if !eligible(&world, a, b) {
                    assert!(listed.is_none(), "{ctx}: filtered or ignored pair reported");
                    continue;
                }
                let (_, all) = brute(a, b);
                let flip = a.h > b.h;
                for ((i, j), d) in all {
                    let k = if flip { (j, i) } else { (i, j) };
                    let has = listed.is_some_and(|s| s.contains(&k));
                    if d < margin - TOL {
                        assert!(has, "{ctx}: {k:?} at {d} missing");
                        seen.0 += 1;
                    } else if d > margin + TOL {
                        assert!(!has, "{ctx}: {k:?} at {d} reported");
                        seen.1 += 1;
                    }
                }
                if let Some(s) = listed {
                    assert!(!s.is_empty(), "{ctx}");
                }
            }
        }
    }
    seen
}

#[test]
fn contacts_within_matches_brute_force() {
    let (mut near, mut far) = (0, 0);
    for seed in 0..5 {
        for (n, f) in [
            contacts_within_match_brute_force::<Kdop18>(seed),
            contacts_within_match_brute_force::<Obb>(30 + seed),
        ] {
            near += n;
            far += f;
        }
    }
    assert!(near > 200 && far > 10_000, "{near} near, {far} far");
}

#[test]
fn bad_distance_queries_are_errors() {
    let (mut world, objs) = scene::<Kdop18>(3, 6, false);
    let (a, b) = (objs[0].h, objs[1].h);
    assert!(matches!(
        world.distance(a, a),
        Err(Error::InvalidParameter(_))
    ));
    for m in [-1.0, f64::NAN, f64::INFINITY] {
        assert!(world.contacts_within(m).is_err(), "{m}");
    }
    // A huge but finite margin: every pair (all within the coordinate limit).
    let all = world.contacts_within(1e300).unwrap();
    assert_eq!(all.pairs.len(), 15);
    world.remove(b).unwrap();
    assert!(matches!(world.distance(a, b), Err(Error::StaleHandle)));
    assert!(matches!(world.nearest_obstacle(b), Err(Error::StaleHandle)));
}
