//! Operation sequences decoded from raw bytes, run on every index side by side with
//! `BruteForce` ([`run`]). Shared by the library's proptest suite
//! (`crates/proxima/tests/ops`) and the cargo-fuzz target `index_ops`.
//!
//! The decoder favours the inputs that break things: a small grid of values (many
//! exact touches), huge values (1e30, `f32::MAX`), subnormals, NaN, infinities and
//! negative radii, stale and foreign handles, bad constructor parameters. Every
//! index must give the same answers and the same errors as brute force, leave
//! itself unchanged after an error, and pass `validate()` after every operation.
//!
//! Collision filters, k-nearest queries and sphere sweeps are derived from the
//! numbers the older operations already decode (no byte is read for them), so
//! every saved input still decodes to the same operations.

use proxima::broad::{
    BruteForce, Filter, Grid2dConfig, Grid3dConfig, HashGrid, HashGridConfig, LinearOctree,
    LooseKdConfig, LooseKdTree, Metric, Nearest, OctreeConfig, Query, SpatialIndex,
    SpatialIndexExt, UniformGrid2d, UniformGrid3d,
};
use proxima::geom::{Aabb, Frustum, Plane, Ray, Segment, Sphere, SphereSweep};
use proxima::glam::{Mat4, Vec3};
use proxima::{Error, Handle, Result};
use std::ops::{ControlFlow, Deref, DerefMut};

/// Reads numbers from the fuzz bytes; past the end every read gives zero.
pub struct Bytes<'a> {
    data: &'a [u8],
    pos: usize,
}

impl<'a> Bytes<'a> {
    /// A reader at the start of `data`.
    pub fn new(data: &'a [u8]) -> Self {
        Bytes { data, pos: 0 }
    }
    /// Whether every byte has been read.
    pub fn done(&self) -> bool {
        self.pos >= self.data.len()
    }
    /// The next byte (0 past the end).
    pub fn u8(&mut self) -> u8 {
        let b = self.data.get(self.pos).copied().unwrap_or(0);
        self.pos += 1;
        b
    }
    /// The next four bytes, little-endian.
    pub fn u32(&mut self) -> u32 {
        u32::from_le_bytes([self.u8(), self.u8(), self.u8(), self.u8()])
    }
    /// A coordinate: mostly on a quarter-unit grid, sometimes huge or not finite.
    pub fn coord(&mut self) -> f32 {
        match self.u8() % 10 {
            0..=5 => (self.u8() as i32 - 128) as f32 * 0.25,
            6 => (self.u8() as i32 - 128) as f32 * 64.0,
            7 => pick(
                self.u8(),
                &[
                    0.0, -0.0, 1e30, -1e30, 3e38, -3e38, 1e-40, 1e20, -1e20, 1e-30,
                ],
            ),
            8 => f32::from_bits(self.u32()),
            _ => pick(
                self.u8(),
                &[
                    f32::NAN,
                    f32::INFINITY,
                    f32::NEG_INFINITY,
                    f32::MAX,
                    f32::MIN,
                ],
            ),
        }
    }
    /// A radius: mostly small and non-negative, sometimes 0, huge, negative or NaN.
    pub fn radius(&mut self) -> f32 {
        match self.u8() % 10 {
            0..=5 => self.u8() as f32 * 0.125,
            6 => 0.0,
            7 => pick(self.u8(), &[1e30, 3e38, f32::MAX, 1e-40, 1e15, 1000.0]),
            8 => f32::from_bits(self.u32()),
            _ => pick(self.u8(), &[-1.0, -0.0, f32::NAN, f32::INFINITY, -1e-40]),
        }
    }
    /// Three [`Bytes::coord`]s.
    pub fn vec3(&mut self) -> Vec3 {
        Vec3::new(self.coord(), self.coord(), self.coord())
    }
    /// A [`Bytes::vec3`] centre and a [`Bytes::radius`] (possibly invalid).
    pub fn sphere(&mut self) -> Sphere {
        Sphere::new(self.vec3(), self.radius())
    }
}

fn pick(b: u8, xs: &[f32]) -> f32 {
    xs[b as usize % xs.len()]
}

/// An index under test and its name. The trait object dispatches; the methods
/// below turn answers into comparable values (payload ids, bit patterns).
pub struct Named {
    name: &'static str,
    index: Box<dyn SpatialIndex<u64>>,
}

impl Deref for Named {
    type Target = dyn SpatialIndex<u64>;
    fn deref(&self) -> &Self::Target {
        self.index.as_ref()
    }
}

impl DerefMut for Named {
    fn deref_mut(&mut self) -> &mut Self::Target {
        self.index.as_mut()
    }
}

/// A stored payload as the runner's id. The indices hold `u64` payloads, as
/// the oracle and the replay engine do: each payload type builds all six
/// indices again, and a second one (`u32`) made this crate the longest unit
/// of CI's build after the world tests. Every payload is a `u32` id widened
/// (`next_id.into()`), so a wider one is a bug.
fn id(x: u64) -> u32 {
    u32::try_from(x).expect("a payload is a u32 id")
}

fn ids(r: Result<ControlFlow<()>>, mut v: Vec<u32>) -> Result<Vec<u32>> {
    let _ = r?;
    v.sort_unstable();
    Ok(v)
}

impl Named {
    fn new(name: &'static str, index: impl SpatialIndex<u64> + 'static) -> Self {
        Named {
            name,
            index: Box::new(index),
        }
    }
    fn name(&self) -> &'static str {
        self.name
    }
    fn get(&self, h: Handle) -> Result<(Sphere, u32)> {
        self.index.get(h).map(|(s, &v)| (s, id(v)))
    }
    fn get_mut_ok(&mut self, h: Handle) -> Result<u32> {
        self.index.get_mut(h).map(|&mut v| id(v))
    }
    /// Payload ids of the objects a sphere, box or frustum query reports, sorted.
    fn ids_in(&self, q: impl Into<Query>) -> Result<Vec<u32>> {
        let mut v = Vec::new();
        let r = self.index.for_each_in(q, |_, _, &x| {
            v.push(id(x));
            ControlFlow::Continue(())
        });
        ids(r, v)
    }
    fn ray_hits(&self, r: &Ray) -> Result<Vec<(u32, u32)>> {
        let mut v: Vec<(u32, u32)> = self
            .index
            .ray_hits(r)?
            .into_iter()
            .map(|h| (id(*self.index.get(h.handle).unwrap().1), h.t.to_bits()))
            .collect();
        v.sort_unstable();
        Ok(v)
    }
    fn ray_first(&self, r: &Ray) -> Result<Option<(u32, f32)>> {
        Ok(self
            .index
            .ray_first(r, None)?
            .map(|h| (id(*self.index.get(h.handle).unwrap().1), h.t)))
    }
    /// A filtered query's ids (sorted).
    fn filtered_ids(&self, q: &Query, f: Filter) -> Result<Vec<u32>> {
        let mut v = Vec::new();
        let r = self.index.visit(q, Some(f), &mut |_, _, &x| {
            v.push(id(x));
            ControlFlow::Continue(())
        });
        ids(r, v)
    }
    /// Every sweep hit as (id, `t` bits), sorted, and the first hit.
    #[allow(clippy::type_complexity)]
    fn sweep(
        &self,
        sw: &SphereSweep,
        f: Option<Filter>,
    ) -> Result<(Vec<(u32, u32)>, Option<(Handle, f32)>)> {
        let hits = match f {
            None => self.index.sweep_hits(sw)?,
            Some(f) => self.index.filtered(f).sweep_hits(sw)?,
        };
        let first = self.index.sweep_first(sw, f)?;
        assert_eq!(first, hits.first().copied(), "{}: sweep first", self.name);
        let mut v: Vec<(u32, u32)> = hits
            .iter()
            .map(|h| (id(*self.index.get(h.handle).unwrap().1), h.t.to_bits()))
            .collect();
        v.sort_unstable();
        Ok((v, first.map(|h| (h.handle, h.t))))
    }
    /// A k-nearest answer as (handle, id, distance bits), in order.
    fn nearest(&self, q: &Nearest, f: Option<Filter>) -> Result<Vec<(Handle, u32, u32)>> {
        let mut out = Vec::new();
        self.index.nearest_into(q, f, &mut out)?;
        Ok(out
            .iter()
            .map(|n| {
                let x = id(*self.index.get(n.handle).unwrap().1);
                (n.handle, x, n.distance.to_bits())
            })
            .collect())
    }
    fn pairs(&self) -> Vec<(u32, u32)> {
        let mut v = Vec::new();
        let _ = self.index.for_each_pair(|_, &a, _, &b| {
            let (a, b) = (id(a), id(b));
            v.push((a.min(b), a.max(b)));
            ControlFlow::Continue(())
        });
        v.sort_unstable();
        v
    }
    fn all(&self) -> Vec<(u32, [u32; 4])> {
        let mut v = Vec::new();
        self.index.for_each(&mut |_, s, &x| {
            let c = s.center;
            v.push((
                id(x),
                [
                    c.x.to_bits(),
                    c.y.to_bits(),
                    c.z.to_bits(),
                    s.radius.to_bits(),
                ],
            ))
        });
        v.sort_unstable();
        v
    }
    /// Number of objects reported by a sphere query told to stop after the first.
    fn early_stop(&self, s: &Sphere) -> Result<usize> {
        let mut n = 0;
        let _ = self.index.for_each_in(*s, |_, _, _| {
            n += 1;
            ControlFlow::Break(())
        })?;
        Ok(n)
    }
}

/// Builds brute force plus every index whose decoded constructor parameters are
/// accepted (a rejected constructor must be an `Err`, never a panic: panics
/// otherwise).
pub fn build(b: &mut Bytes) -> Vec<Named> {
    let mut out: Vec<Named> = vec![Named::new("brute", BruteForce::<u64>::new())];
    // Mostly a sane world; sometimes decoded (possibly invalid) parameters.
    let sane = !b.u8().is_multiple_of(4);
    let world = if sane {
        Aabb::new(Vec3::splat(-16.0), Vec3::splat(16.0))
    } else {
        Aabb::new(b.vec3(), b.vec3())
    };
    let r_max = if sane { 2.0 } else { b.radius() };
    let density = if sane {
        [0.25, 0.5, 1.0][b.u8() as usize % 3]
    } else {
        f32::from_bits(b.u32())
    };
    let depth = if sane { 2 + b.u8() % 20 } else { b.u8() };
    match LooseKdTree::with_config(LooseKdConfig {
        density,
        max_depth: depth,
        ..LooseKdConfig::new(world, r_max)
    }) {
        Ok(t) => out.push(Named::new("loose-kd", t)),
        Err(e) => check_param_error(&e),
    }
    let cfg = OctreeConfig {
        max_per_leaf: if sane { 1 + b.u8() as u32 % 8 } else { b.u32() },
        merge_below: if sane { b.u8() as u32 % 2 } else { b.u32() },
        max_depth: if sane {
            1 + b.u8() as u32 % 21
        } else {
            b.u32()
        },
        ..OctreeConfig::new(world)
    };
    match LinearOctree::with_config(cfg) {
        Ok(t) => out.push(Named::new("octree", t)),
        Err(e) => check_param_error(&e),
    }
    let cell = if sane {
        0.5 + b.u8() as f32 * 0.25
    } else {
        b.radius()
    };
    // Valid but huge grids (up to 2^24 cells) would make each case slow: skip them.
    let small = |cell: f32| {
        let e = world.extent();
        (e.x / cell + 1.0) * (e.y / cell + 1.0) <= 65536.0
    };
    if small(cell) || cell.is_nan() || cell <= 0.0 {
        match UniformGrid2d::with_config(Grid2dConfig {
            world,
            cell_size: cell,
        }) {
            Ok(t) => out.push(Named::new("grid2d", t)),
            Err(e) => check_param_error(&e),
        }
    }
    if small(UniformGrid2d::<u64>::default_cell_size(&world, r_max))
        || r_max.is_nan()
        || r_max <= 0.0
    {
        match UniformGrid2d::new(world, r_max) {
            Ok(t) => out.push(Named::new("grid2d-new", t)),
            Err(e) => check_param_error(&e),
        }
    }
    // The dense 3D grid allocates every cell up front: keep each case small too.
    let small3 = |cell: f32| {
        let e = world.extent();
        (e.x / cell + 1.0) * (e.y / cell + 1.0) * (e.z / cell + 1.0) <= 262_144.0
    };
    if small3(cell) || cell.is_nan() || cell <= 0.0 {
        match UniformGrid3d::with_config(Grid3dConfig {
            world,
            cell_size: cell,
        }) {
            Ok(t) => out.push(Named::new("grid3d", t)),
            Err(e) => check_param_error(&e),
        }
    }
    if small3(r_max / 0.49) || r_max.is_nan() || r_max <= 0.0 {
        match UniformGrid3d::new(world, r_max) {
            Ok(t) => out.push(Named::new("grid3d-new", t)),
            Err(e) => check_param_error(&e),
        }
    }
    if std::env::var_os("OPS_DEBUG").is_some() {
        eprintln!("hash grid cell {cell:?}, r_max {r_max:?}");
    }
    match HashGrid::with_config(HashGridConfig { cell_size: cell }) {
        Ok(t) => out.push(Named::new("hashgrid", t)),
        Err(e) => check_param_error(&e),
    }
    match HashGrid::new(r_max) {
        Ok(t) => out.push(Named::new("hashgrid-new", t)),
        Err(e) => check_param_error(&e),
    }
    out
}

fn check_param_error(e: &Error) {
    assert!(
        matches!(
            e,
            Error::InvalidParameter(_)
                | Error::Invalid(_)
                | Error::NonFinite { .. }
                | Error::InvertedAabb
        ),
        "constructor rejected with an unexpected error: {e:?}"
    );
}

/// One object as each index knows it.
struct Obj {
    id: u32,
    handles: Vec<Handle>,
}

fn frustum(b: &mut Bytes) -> Frustum {
    match b.u8() % 3 {
        0 => {
            let eye = b.vec3();
            let at = b.vec3();
            let fov = 0.2 + (b.u8() % 16) as f32 * 0.15;
            let far = 1.0 + b.u8() as f32;
            let m = Mat4::perspective_rh(fov, 1.0, 0.1, far) * Mat4::look_at_rh(eye, at, Vec3::Y);
            Frustum::from_view_projection(m)
                .unwrap_or(Frustum::from_planes([Plane::new(Vec3::X, f32::NAN); 6]))
        }
        1 => {
            let mut cols = [0.0f32; 16];
            for c in &mut cols {
                *c = b.coord();
            }
            Frustum::from_view_projection(Mat4::from_cols_array(&cols))
                .unwrap_or(Frustum::from_planes([Plane::new(Vec3::X, f32::NAN); 6]))
        }
        _ => {
            let mut planes = [Plane::new(Vec3::X, 0.0); 6];
            for p in &mut planes {
                *p = Plane::new(b.vec3(), b.coord());
            }
            Frustum::from_planes(planes)
        }
    }
}

/// Asserts that every index gave the same answer as brute force (index 0).
fn same<R: PartialEq + std::fmt::Debug>(what: &str, idx: &[Named], f: impl Fn(&Named) -> R) {
    let want = f(&idx[0]);
    for i in &idx[1..] {
        let got = f(i);
        assert_eq!(got, want, "{what}: {} differs from brute force", i.name());
    }
}

/// The bits of a sphere's numbers, mixed: the seed of derived choices.
fn bits(s: &Sphere) -> u32 {
    let c = s.center;
    (c.x.to_bits() ^ c.y.to_bits().rotate_left(7) ^ c.z.to_bits().rotate_left(13))
        .wrapping_mul(0x9e37_79b9)
        ^ s.radius.to_bits()
}

/// A filter derived from `x`: [`Filter::ALL`] half the time, else a few bits
/// (both answers of `interacts` common), sometimes inert.
fn derived_filter(x: u32) -> Filter {
    let y = x >> 3;
    match x % 8 {
        0..=3 => Filter::ALL,
        4 => Filter::new(y % 2, (y >> 1) % 8),
        _ => Filter::new(1 << (y % 3), 1 + (y >> 2) % 7),
    }
}

/// Handle of object `id` in index number `pos`.
fn handle_of(objs: &[Obj], pos: usize, id: u32) -> Handle {
    objs.iter()
        .find(|o| o.id == id)
        .map(|o| o.handles[pos])
        .expect("a live id")
}

/// k nearest around the query sphere's centre (k and the limit derived from
/// its radius, both metrics, filtered or not): every index gives brute
/// force's ranking, ties in its own handle order, and the same errors.
fn check_nearest(idx: &[Named], objs: &[Obj], s: &Sphere, f: Filter) {
    let x = bits(s);
    let k = match x % 5 {
        0 => 1,
        1 => 8,
        2 => 64,
        3 => objs.len() + 1,
        _ => (x >> 8) as usize % 4,
    };
    let mut q = Nearest::new(s.center, k);
    if x & 64 != 0 {
        q = q.metric(Metric::Center);
    }
    if x & 128 != 0 {
        q = q.within(s.radius);
    }
    let filter = (f != Filter::ALL).then_some(f);
    let all = idx[0].nearest(&Nearest { k: usize::MAX, ..q }, filter);
    for (pos, i) in idx.iter().enumerate() {
        let got = i.nearest(&q, filter);
        let want = all.clone().map(|all| {
            let mut v: Vec<(Handle, u32, u32)> = all
                .iter()
                .map(|&(_, id, d)| (handle_of(objs, pos, id), id, d))
                .collect();
            v.sort_unstable_by(|a, b| {
                f32::from_bits(a.2)
                    .total_cmp(&f32::from_bits(b.2))
                    .then(a.0.cmp(&b.0))
            });
            v.truncate(k);
            v
        });
        assert_eq!(got, want, "{}: nearest {q:?} {filter:?}", i.name());
    }
}

/// A sphere sweep: the same hits and times in every index, the same first
/// hit (ties in each index's own handle order), the same errors.
fn check_sweep(idx: &[Named], objs: &[Obj], sw: &SphereSweep, f: Option<Filter>) {
    let want = idx[0].sweep(sw, f).map(|x| x.0);
    for (pos, i) in idx.iter().enumerate() {
        let got = i.sweep(sw, f);
        assert_eq!(got.clone().map(|x| x.0), want, "{}: sweep {sw:?}", i.name());
        if let (Ok((_, first)), Ok(hits)) = (got, &want) {
            let best = hits
                .iter()
                .map(|&(id, t)| (f32::from_bits(t), handle_of(objs, pos, id)))
                .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            assert_eq!(
                first.map(|(h, t)| (t.to_bits(), h)),
                best.map(|(t, h)| (t.to_bits(), h)),
                "{}: sweep first {sw:?}",
                i.name()
            );
        }
    }
}

/// Checks what must hold after every operation.
fn check(idx: &[Named], live: usize) {
    for i in idx {
        if let Err(e) = i.validate() {
            panic!("{}: validate failed: {e}", i.name());
        }
        assert_eq!(i.len(), live, "{}: len", i.name());
    }
    same("contents", idx, |i| i.all());
}

/// Decodes and runs one operation sequence: panics on any disagreement with
/// brute force, failed `validate()` or wrong `len()`, so a test or a fuzz target
/// just calls it. O(bytes × indices × live objects).
pub fn run(data: &[u8]) {
    let mut b = Bytes::new(data);
    let mut idx = build(&mut b);
    let empty_mem: Vec<usize> = idx.iter().map(|i| i.memory_bytes()).collect();
    let mut objs: Vec<Obj> = Vec::new();
    let mut dead: Vec<Vec<Handle>> = Vec::new();
    let mut next_id = 0u32;
    let debug = std::env::var_os("OPS_DEBUG").is_some();
    while !b.done() {
        let op = b.u8() % 16;
        if debug {
            eprintln!("op {op} at byte {}", b.pos);
        }
        match op {
            0..=3 => {
                let s = b.sphere();
                if debug {
                    eprintln!("  insert {s:?}");
                }
                let f = derived_filter(bits(&s));
                let res: Vec<Result<Handle>> = idx
                    .iter_mut()
                    .map(|i| {
                        if f == Filter::ALL {
                            i.insert(s, next_id.into())
                        } else {
                            i.insert_with_filter(s, f, next_id.into())
                        }
                    })
                    .collect();
                let errs: Vec<Option<Error>> = res.iter().map(|r| r.clone().err()).collect();
                assert!(
                    errs.iter().all(|e| *e == errs[0]),
                    "insert {s:?}: indices disagree: {errs:?}"
                );
                if errs[0].is_none() {
                    objs.push(Obj {
                        id: next_id,
                        handles: res.into_iter().map(|r| r.unwrap()).collect(),
                    });
                    next_id += 1;
                } else {
                    assert_eq!(Some(s.validate().unwrap_err()), errs[0]);
                }
            }
            4 | 5 => {
                if objs.is_empty() {
                    continue;
                }
                let k = b.u8() as usize % objs.len();
                let s = b.sphere();
                if debug {
                    eprintln!("  update #{k} {s:?}");
                }
                let res: Vec<Result<()>> = idx
                    .iter_mut()
                    .zip(&objs[k].handles)
                    .map(|(i, &h)| i.update(h, s))
                    .collect();
                assert!(res.iter().all(|r| *r == res[0]), "update {s:?}: {res:?}");
            }
            6 => {
                if objs.is_empty() {
                    continue;
                }
                let k = b.u8() as usize % objs.len();
                let o = objs.swap_remove(k);
                for (i, &h) in idx.iter_mut().zip(&o.handles) {
                    assert_eq!(i.remove(h), Ok(o.id.into()), "{}: remove", i.name());
                }
                dead.push(o.handles);
            }
            7 => {
                // A stale handle (removed or cleared) or a foreign one (another
                // index's handle for a live object): every call must refuse it.
                let handles: Vec<Handle> = if b.u8().is_multiple_of(2) && !dead.is_empty() {
                    dead[b.u8() as usize % dead.len()].clone()
                } else if !objs.is_empty() {
                    let mut h = objs[b.u8() as usize % objs.len()].handles.clone();
                    h.rotate_left(1);
                    h
                } else {
                    continue;
                };
                let s = b.sphere();
                for (pos, (i, &h)) in idx.iter_mut().zip(&handles).enumerate() {
                    if objs.iter().any(|o| o.handles[pos] == h) {
                        continue; // a single index: rotation gave back its own handle
                    }
                    assert_eq!(i.get(h), Err(Error::StaleHandle), "{}: get", i.name());
                    assert_eq!(i.get_mut_ok(h), Err(Error::StaleHandle), "{}", i.name());
                    // With a bad sphere too, either error is a fine answer.
                    let want = s.validate().err().unwrap_or(Error::StaleHandle);
                    match i.update(h, s) {
                        Err(e) if e == Error::StaleHandle || e == want => {}
                        other => panic!("{}: update with a stale handle: {other:?}", i.name()),
                    }
                    assert_eq!(i.remove(h), Err(Error::StaleHandle), "{}", i.name());
                }
            }
            8 => {
                let s = b.sphere();
                same("sphere query", &idx, |i| i.ids_in(s));
                same("early stop", &idx, |i| i.early_stop(&s));
                let f = derived_filter(bits(&s) >> 3);
                same("filtered sphere query", &idx, |i| {
                    i.filtered_ids(&Query::Sphere(s), f)
                });
                check_nearest(&idx, &objs, &s, f);
            }
            9 => {
                let bx = Aabb::new(b.vec3(), b.vec3());
                same("aabb query", &idx, |i| i.ids_in(bx));
                let f = derived_filter(bx.min.x.to_bits() ^ bx.max.y.to_bits());
                same("filtered aabb query", &idx, |i| {
                    i.filtered_ids(&Query::Aabb(bx), f)
                });
            }
            10 => {
                let f = frustum(&mut b);
                if debug {
                    eprintln!("  {f:?}");
                }
                same("frustum query", &idx, |i| i.ids_in(f));
            }
            11 | 12 => {
                let max_t = match b.u8() % 4 {
                    0 => f32::INFINITY,
                    1 => b.radius(),
                    _ => b.u8() as f32,
                };
                let r = Ray::with_max_t(b.vec3(), b.vec3(), max_t);
                if debug {
                    eprintln!("  {r:?}");
                }
                same("ray hits", &idx, |i| i.ray_hits(&r));
                // The first hit: same t; ties may name different objects.
                let hits = idx[0].ray_hits(&r);
                let want = idx[0].ray_first(&r).map(|h| h.map(|x| x.1));
                for i in &idx {
                    let got = i.ray_first(&r);
                    assert_eq!(
                        got.clone().map(|h| h.map(|x| x.1)),
                        want,
                        "{}: ray first",
                        i.name()
                    );
                    if let (Ok(Some((id, t))), Ok(hits)) = (got, &hits) {
                        assert!(hits.contains(&(id, t.to_bits())), "{}: first hit", i.name());
                    }
                }
                let seg = Segment::new(b.vec3(), b.vec3());
                if debug {
                    eprintln!("  {seg:?}");
                }
                same("segment hits", &idx, |i| i.ray_hits(&seg.to_ray()));
                // The segment swept by a sphere of the ray's `max_t` as radius
                // (zero-length, radius 0, huge and invalid ones included).
                let sw = SphereSweep::new(seg.a, seg.b, max_t);
                let f = derived_filter(max_t.to_bits() ^ seg.a.x.to_bits());
                let f = (f != Filter::ALL).then_some(f);
                check_sweep(&idx, &objs, &sw, f);
                if sw.radius == 0.0 && sw.validate().is_ok() {
                    let d = sw.to - sw.from;
                    if sw.from + d == sw.to && sw.to - d == sw.from && d != Vec3::ZERO {
                        // An exact direction: radius 0 is the segment query.
                        for i in &idx {
                            let want = i.ray_hits(&Segment::new(sw.from, sw.to).to_ray());
                            let got = i.sweep(&sw, None).map(|x| x.0);
                            assert_eq!(got, want, "{}: radius-0 sweep = segment", i.name());
                        }
                    }
                }
            }
            13 => same("pairs", &idx, |i| i.pairs()),
            14 => {
                // Remove everything, then clear: memory must return to its empty value.
                if b.u8().is_multiple_of(2) {
                    for o in objs.drain(..) {
                        for (i, &h) in idx.iter_mut().zip(&o.handles) {
                            assert_eq!(i.remove(h), Ok(o.id.into()));
                        }
                        dead.push(o.handles);
                    }
                    check(&idx, 0);
                }
                for i in idx.iter_mut() {
                    i.clear();
                }
                for o in objs.drain(..) {
                    dead.push(o.handles);
                }
                for (i, &m) in idx.iter().zip(&empty_mem) {
                    assert_eq!(i.memory_bytes(), m, "{}: memory after clear", i.name());
                }
            }
            _ => {
                // Same update on an object, twice (a no-op move), then a get;
                // then a new filter for it (derived from its id and the count).
                if let Some(o) = objs.first() {
                    let f = derived_filter(o.id.wrapping_mul(0x9e37_79b9) ^ next_id);
                    for (i, &h) in idx.iter_mut().zip(&o.handles) {
                        let (s, v) = i.get(h).unwrap();
                        assert_eq!(v, o.id);
                        let before = i.filter(h).unwrap();
                        i.update(h, s).unwrap();
                        assert_eq!(i.filter(h), Ok(before), "{}: move keeps filter", i.name());
                        i.set_filter(h, f).unwrap();
                        assert_eq!(i.filter(h), Ok(f), "{}: set_filter", i.name());
                    }
                }
            }
        }
        check(&idx, objs.len());
    }
}
