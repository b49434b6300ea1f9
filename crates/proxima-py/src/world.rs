//! `proxima.World`: the collision world (`proxima::world`) over numpy arrays —
//! shared mesh and ball shapes at rigid poses, collision filters, ignored
//! pairs, contacts, ray casts, sphere queries and culling — and its contacts
//! answer, `proxima.WorldContacts`.

use crate::arrays::{self, int_list, rows, vec3};
use crate::collide::{csr_row, rotation_update};
use crate::errors::OrRaise;
use crate::ids::Ids;
use crate::mesh::{AnyMesh, Mesh};
use crate::queries::Csr;
use crate::workers::Workers;
use numpy::{PyArray1, PyArray2, PyArrayMethods, PyUntypedArrayMethods};
use proxima::broad::{Filter, IndexKind};
use proxima::geom::{Aabb, Frustum, Ray, Sphere};
use proxima::glam::{Affine3A, Vec3};
use proxima::narrow::{check_pose, BoundingVolume, Kdop14, Kdop18, Kdop26, Mesh as RsMesh, Obb};
use proxima::world::{ContactMode, ContactReport, Shape, World as RsWorld, WorldConfig};
use proxima::Handle;
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use rayon::prelude::*;
use std::sync::Arc;

/// A world whose meshes use whichever bounding volume was chosen at run time;
/// payloads are the objects' ids.
pub enum AnyWorld {
    /// AABB trees.
    Aabb(RsWorld<u64, Aabb>),
    /// k-DOP-14 trees.
    Kdop14(RsWorld<u64, Kdop14>),
    /// k-DOP-18 trees.
    Kdop18(RsWorld<u64, Kdop18>),
    /// k-DOP-26 trees.
    Kdop26(RsWorld<u64, Kdop26>),
    /// OBB trees.
    Obb(RsWorld<u64, Obb>),
    /// Sphere trees.
    Sphere(RsWorld<u64, Sphere>),
}

/// `$body` with `$w` bound to the world inside `$any`, whatever its volume.
macro_rules! each_world {
    ($any:expr, $w:ident => $body:expr) => {
        match $any {
            AnyWorld::Aabb($w) => $body,
            AnyWorld::Kdop14($w) => $body,
            AnyWorld::Kdop18($w) => $body,
            AnyWorld::Kdop26($w) => $body,
            AnyWorld::Obb($w) => $body,
            AnyWorld::Sphere($w) => $body,
        }
    };
}

/// A bounding volume whose meshes a world of that volume can share.
trait Volume: BoundingVolume {
    /// The mesh inside `m`, shared, if it uses this volume.
    fn mesh_of(m: &AnyMesh) -> Option<Arc<RsMesh<Self>>>;
}

macro_rules! volumes {
    ($($v:ident: $t:ty),+) => {
        $(impl Volume for $t {
            fn mesh_of(m: &AnyMesh) -> Option<Arc<RsMesh<Self>>> {
                match m {
                    AnyMesh::$v(x) => Some(x.clone()),
                    _ => None,
                }
            }
        })+
    };
}
volumes!(Aabb: Aabb, Kdop14: Kdop14, Kdop18: Kdop18, Kdop26: Kdop26, Obb: Obb, Sphere: Sphere);

/// An `add` shape argument: a `Mesh` (shared) or a ball radius.
enum ShapeArg<'a> {
    Mesh(&'a AnyMesh),
    Ball(f32),
}

impl ShapeArg<'_> {
    /// The library shape for a world of volume `BV`: the same mesh (one more
    /// reference), or a checked ball.
    fn shape<BV: Volume>(&self) -> PyResult<Shape<BV>> {
        match self {
            ShapeArg::Mesh(m) => BV::mesh_of(m).map(Shape::Mesh).ok_or_else(|| {
                PyValueError::new_err(format!(
                    "shape: the mesh has bv {:?} but the world uses {:?}",
                    m.bv(),
                    BV::NAME
                ))
            }),
            ShapeArg::Ball(r) => Shape::sphere(*r).or_raise_at(|| "shape".into()),
        }
    }
}

/// Rigid poses from an argument (see [`arrays::poses`]), each checked,
/// naming the first bad one.
fn checked_poses(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<(Vec<Affine3A>, bool)> {
    let (poses, single) = arrays::poses(obj, what)?;
    for (i, p) in poses.iter().enumerate() {
        check_pose(p).or_raise_at(|| {
            if single {
                what.to_string()
            } else {
                format!("{what}: pose {i}")
            }
        })?;
    }
    Ok((poses, single))
}

/// One checked pose: `(4, 4)` or `(3, 4)`; `None` is the identity.
fn one_pose(obj: Option<&Bound<'_, PyAny>>, what: &str) -> PyResult<Affine3A> {
    let Some(obj) = obj else {
        return Ok(Affine3A::IDENTITY);
    };
    let (p, single) = checked_poses(obj, what)?;
    if !single {
        return Err(PyValueError::new_err(format!(
            "{what}: one (4, 4) or (3, 4) pose here (a batch goes to the *_many / set_poses calls)"
        )));
    }
    Ok(p[0])
}

/// A pose as a row-major `(4, 4)` matrix.
fn matrix(pose: &Affine3A) -> [f32; 16] {
    let (c, t) = (pose.matrix3, pose.translation);
    [
        c.x_axis.x, c.y_axis.x, c.z_axis.x, t.x, //
        c.x_axis.y, c.y_axis.y, c.z_axis.y, t.y, //
        c.x_axis.z, c.y_axis.z, c.z_axis.z, t.z, //
        0.0, 0.0, 0.0, 1.0,
    ]
}

/// A contacts answer in ids: object pairs `(a, b)` with `a < b` sorted, each
/// with its primitive pairs `(of a, of b)` ascending.
struct Packed {
    pairs: Vec<i64>,
    offsets: Vec<i64>,
    triangles: Vec<i64>,
    counters: [(&'static str, u64); 8],
}

/// Runs a contacts query on the calling thread or the pool and packs it.
fn contacts<BV: BoundingVolume>(
    w: &mut RsWorld<u64, BV>,
    mode: ContactMode,
    workers: &Workers,
) -> proxima::Result<Packed> {
    let mut r = ContactReport::default();
    if workers.parallel() {
        workers.run(|| w.par_contacts_into(mode, &mut r))?;
    } else {
        w.contacts_into(mode, &mut r)?;
    }
    let id = |h: Handle| *w.get(h).expect("a contact names live objects") as i64;
    // The library sorts by handle; ids order differently once slots are
    // reused, so each pair is put in id order and the list sorted again.
    let mut order: Vec<(i64, i64, usize)> = r
        .pairs
        .iter()
        .enumerate()
        .map(|(k, c)| {
            let (a, b) = (id(c.a), id(c.b));
            (a.min(b), a.max(b), k)
        })
        .collect();
    order.sort_unstable();
    let mut p = Packed {
        pairs: Vec::with_capacity(2 * order.len()),
        offsets: Vec::with_capacity(order.len() + 1),
        triangles: Vec::with_capacity(2 * r.triangles.len()),
        counters: [
            ("broad_pairs", r.counters.broad_pairs),
            ("filtered", r.counters.filtered),
            ("narrow_pairs", r.counters.narrow_pairs),
            ("coherent_pairs", r.counters.coherent_pairs),
            ("cut_starts", r.counters.cut_starts),
            ("nv", r.counters.cost.nv),
            ("np", r.counters.cost.np),
            ("nu", r.counters.cost.nu),
        ],
    };
    p.offsets.push(0);
    let mut swapped = Vec::new();
    for (a, b, k) in order {
        let c = &r.pairs[k];
        let tris = r.triangles_of(c);
        p.pairs.extend([a, b]);
        if id(c.a) == a {
            p.triangles
                .extend(tris.iter().flat_map(|&(i, j)| [i64::from(i), i64::from(j)]));
        } else {
            swapped.clear();
            swapped.extend(tris.iter().map(|&(i, j)| (j, i)));
            swapped.sort_unstable();
            p.triangles.extend(
                swapped
                    .iter()
                    .flat_map(|&(i, j)| [i64::from(i), i64::from(j)]),
            );
        }
        p.offsets.push((p.triangles.len() / 2) as i64);
    }
    Ok(p)
}

/// Runs `f` on every item, on the calling thread or the pool, in order.
fn batch<Q: Sync, R: Send>(
    items: &[Q],
    workers: &Workers,
    f: impl Fn(&Q) -> proxima::Result<R> + Sync,
) -> proxima::Result<Vec<R>> {
    if workers.parallel() {
        workers.run(|| items.par_iter().with_min_len(16).map(&f).collect())
    } else {
        items.iter().map(f).collect()
    }
}

/// Per-query id lists as CSR.
fn csr(lists: Vec<Vec<i64>>) -> Csr {
    let mut out = Csr {
        ids: Vec::with_capacity(lists.iter().map(Vec::len).sum()),
        offsets: Vec::with_capacity(lists.len() + 1),
        t: Vec::new(),
    };
    out.offsets.push(0);
    for l in lists {
        out.ids.extend(l);
        out.offsets.push(out.ids.len() as i64);
    }
    out
}

/// Handles as ascending ids.
fn sorted_ids<BV: BoundingVolume>(w: &RsWorld<u64, BV>, hs: Vec<Handle>) -> Vec<i64> {
    let mut ids: Vec<i64> = hs
        .into_iter()
        .map(|h| *w.get(h).expect("a query names live objects") as i64)
        .collect();
    ids.sort_unstable();
    ids
}

/// A collision world: objects, each a shape (a shared `Mesh`, or a solid
/// ball) at a rigid pose with a collision filter, named by integer ids.
#[pyclass(module = "proxima", name = "World")]
pub struct World {
    inner: AnyWorld,
    ids: Ids,
}

impl World {
    /// Adds `shape` at each of `poses` with `filter`, all or nothing, and
    /// returns the new ids.
    fn add_all(
        &mut self,
        shape: &Bound<'_, PyAny>,
        poses: &[Affine3A],
        filter: Filter,
        single: bool,
    ) -> PyResult<Vec<i64>> {
        // try_borrow: a mesh being changed on another thread raises, never panics.
        let mesh = shape
            .cast::<Mesh>()
            .ok()
            .map(|m| m.try_borrow())
            .transpose()?;
        let arg = match &mesh {
            Some(m) => ShapeArg::Mesh(&m.inner),
            None => ShapeArg::Ball(shape.extract::<f32>().map_err(|_| {
                PyTypeError::new_err(format!(
                    "shape: a proxima.Mesh or a ball radius, got {}",
                    shape.get_type()
                ))
            })?),
        };
        let first = self.ids.issued();
        let World { inner, ids } = self;
        each_world!(inner, w => {
            let shape = arg.shape()?;
            ids.reserve(poses.len());
            for (k, pose) in poses.iter().enumerate() {
                match w.insert_with_filter(shape.clone(), *pose, (first + k) as u64, filter) {
                    Ok(h) => {
                        ids.push(h);
                    }
                    Err(e) => {
                        for h in ids.take_from(first) {
                            w.remove(h).expect("just inserted");
                        }
                        return Err(e).or_raise_at(|| {
                            if single { "pose".into() } else { format!("poses: pose {k}") }
                        });
                    }
                }
            }
        });
        Ok((first as i64..self.ids.issued() as i64).collect())
    }

    /// The handles of two different live ids.
    fn pair(&self, a: i64, b: i64) -> PyResult<(Handle, Handle)> {
        Ok((self.ids.handle(a)?, self.ids.handle(b)?))
    }
}

#[pymethods]
impl World {
    /// World(*, index=None, bv="kdop18", bounds=None, coherence=True, rotation="auto")
    ///
    /// An empty world. `index`: the broad-phase index kind ("brute",
    /// "loose-kd", "octree", "grid2d", "hashgrid", "grid3d"; None: "loose-kd",
    /// the one least sensitive to sizes and spread). `bv`: the bounding volume
    /// of the meshes it takes (a `Mesh` with another bv is refused). `bounds`
    /// ([min, max] as (2, 3) or (6,)): where the objects will be, for the
    /// index's lifetime; None: the index is built at the first query from
    /// the objects then, and rebuilt when the scene drifts far from it.
    /// `coherence`: skip pairs of objects unchanged since the last contacts
    /// (same answers). `rotation` ("auto", "refit", "conservative"): how
    /// axis-aligned volumes follow rotations in mesh-mesh tests.
    /// ValueError on an unknown name or a bad box.
    #[new]
    #[pyo3(signature = (*, index=None, bv="kdop18", bounds=None, coherence=true, rotation="auto"))]
    fn new(
        index: Option<&str>,
        bv: &str,
        bounds: Option<&Bound<'_, PyAny>>,
        coherence: bool,
        rotation: &str,
    ) -> PyResult<World> {
        let config = WorldConfig {
            index: index
                .map(|k| k.parse::<IndexKind>())
                .transpose()
                .or_raise()?,
            bounds: bounds.map(|b| arrays::aabb(b, "bounds")).transpose()?,
            rotation: rotation_update(rotation)?,
            coherence,
            ..WorldConfig::default()
        };
        let inner = match bv {
            "aabb" => AnyWorld::Aabb(RsWorld::new(config).or_raise()?),
            "kdop14" => AnyWorld::Kdop14(RsWorld::new(config).or_raise()?),
            "kdop18" => AnyWorld::Kdop18(RsWorld::new(config).or_raise()?),
            "kdop26" => AnyWorld::Kdop26(RsWorld::new(config).or_raise()?),
            "obb" => AnyWorld::Obb(RsWorld::new(config).or_raise()?),
            "sphere" => AnyWorld::Sphere(RsWorld::new(config).or_raise()?),
            _ => {
                return Err(PyValueError::new_err(format!(
                    "unknown bv {bv:?} (known: {})",
                    crate::mesh::BV_NAMES.join(", ")
                )))
            }
        };
        Ok(World {
            inner,
            ids: Ids::new("world"),
        })
    }

    /// The broad-phase index kind ("loose-kd", ...).
    #[getter]
    fn index(&self) -> &'static str {
        let config = each_world!(&self.inner, w => *w.config());
        config.index.unwrap_or(IndexKind::LooseKd).name()
    }

    /// The bounding volume of the world's meshes ("kdop18", ...).
    #[getter]
    fn bv(&self) -> &'static str {
        fn name<BV: BoundingVolume>(_: &RsWorld<u64, BV>) -> &'static str {
            BV::NAME
        }
        each_world!(&self.inner, w => name(w))
    }

    /// Number of objects.
    fn __len__(&self) -> usize {
        each_world!(&self.inner, w => w.len())
    }

    /// Whether `id` names an object of the world.
    fn __contains__(&self, id: &Bound<'_, PyAny>) -> bool {
        id.extract::<i64>().is_ok_and(|id| self.ids.contains(id))
    }

    fn __repr__(&self) -> String {
        format!(
            "World(index={:?}, bv={:?}, len={})",
            self.index(),
            self.bv(),
            self.__len__()
        )
    }

    /// The ids of the objects, ascending.
    fn ids<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<i64>> {
        PyArray1::from_vec(py, self.ids.live())
    }

    /// add(shape, pose=None, *, group=0xFFFFFFFF, mask=0xFFFFFFFF) -> id
    ///
    /// Adds an object and returns its id (ids are insertion order, never
    /// reused). `shape`: a `Mesh` — shared, not copied: any number of
    /// objects use one mesh and its trees — or a number, the radius of a
    /// solid ball around the object's origin (its primitive is 0 in
    /// answers). `pose`: (4, 4) or (3, 4) rigid `[R | t]` (None: the
    /// identity). `group` / `mask`: collision filter bits; two objects are
    /// tested only if each one's group meets the other's mask. ValueError,
    /// adding nothing, on a non-rigid or non-finite pose, a bad radius, a
    /// mesh with another bv; TypeError on another kind of shape. O(1) plus
    /// one index insert.
    #[pyo3(signature = (shape, pose=None, *, group=0xFFFF_FFFF, mask=0xFFFF_FFFF))]
    fn add(
        &mut self,
        shape: &Bound<'_, PyAny>,
        pose: Option<&Bound<'_, PyAny>>,
        group: i64,
        mask: i64,
    ) -> PyResult<i64> {
        let filter = arrays::filter(group, mask)?;
        let pose = one_pose(pose, "pose")?;
        Ok(self.add_all(shape, &[pose], filter, true)?[0])
    }

    /// add_many(shape, poses, *, group=0xFFFFFFFF, mask=0xFFFFFFFF) -> ids
    ///
    /// Adds one object per pose of `poses` ((N, 4, 4) or (N, 3, 4)), all
    /// with `shape` (instancing) and the same filter; returns their ids
    /// (N,), consecutive. All or nothing: a bad pose raises ValueError
    /// naming it and adds nothing.
    #[pyo3(signature = (shape, poses, *, group=0xFFFF_FFFF, mask=0xFFFF_FFFF))]
    fn add_many<'py>(
        &mut self,
        py: Python<'py>,
        shape: &Bound<'py, PyAny>,
        poses: &Bound<'py, PyAny>,
        group: i64,
        mask: i64,
    ) -> PyResult<Bound<'py, PyArray1<i64>>> {
        let filter = arrays::filter(group, mask)?;
        let (poses, _) = checked_poses(poses, "poses")?;
        Ok(PyArray1::from_vec(
            py,
            self.add_all(shape, &poses, filter, false)?,
        ))
    }

    /// Removes an object (and its ignored pairs). KeyError if `id` is not in
    /// the world.
    fn remove(&mut self, id: i64) -> PyResult<()> {
        let h = self.ids.handle(id)?;
        each_world!(&mut self.inner, w => w.remove(h).or_raise())?;
        self.ids.forget(id);
        Ok(())
    }

    /// Removes every object of `ids` (and their ignored pairs). All or
    /// nothing: KeyError, removing nothing, if one is not in the world or
    /// appears twice.
    fn remove_many(&mut self, ids: &Bound<'_, PyAny>) -> PyResult<()> {
        let ids = int_list(ids, "ids")?;
        let hs = self.ids.handles_of(&ids)?;
        for (id, h) in ids.into_iter().zip(hs) {
            each_world!(&mut self.inner, w => w.remove(h).or_raise())?;
            self.ids.forget(id);
        }
        Ok(())
    }

    /// Moves one object to `pose` ((4, 4) or (3, 4) rigid). KeyError for an
    /// id not in the world; ValueError on a non-rigid or non-finite pose.
    /// Nothing changes on error. O(1) plus one index update.
    fn set_pose(&mut self, id: i64, pose: &Bound<'_, PyAny>) -> PyResult<()> {
        let h = self.ids.handle(id)?;
        let pose = one_pose(Some(pose), "pose")?;
        each_world!(&mut self.inner, w => w.set_pose(h, pose)).or_raise_at(|| "pose".into())
    }

    /// Moves the objects `ids` (N,) to `poses` ((N, 4, 4) or (N, 3, 4)): a
    /// frame's motion in one call. An id listed twice takes its last pose.
    /// All or nothing: a KeyError (id) or ValueError (pose, naming it)
    /// changes nothing. O(N) plus N index updates.
    fn set_poses(&mut self, ids: &Bound<'_, PyAny>, poses: &Bound<'_, PyAny>) -> PyResult<()> {
        let ids = int_list(ids, "ids")?;
        let (poses, _) = checked_poses(poses, "poses")?;
        if ids.len() != poses.len() {
            return Err(PyValueError::new_err(format!(
                "{} ids but {} poses",
                ids.len(),
                poses.len()
            )));
        }
        let moves = (ids.iter().zip(poses))
            .map(|(&id, p)| Ok((self.ids.handle(id)?, p)))
            .collect::<PyResult<Vec<_>>>()?;
        each_world!(&mut self.inner, w => w.set_poses(&moves)).or_raise_at(|| "poses".into())
    }

    /// The pose of an object, (4, 4) float32. KeyError if not in the world.
    fn pose<'py>(&self, py: Python<'py>, id: i64) -> PyResult<Bound<'py, PyArray2<f32>>> {
        let h = self.ids.handle(id)?;
        let p = each_world!(&self.inner, w => w.pose(h)).or_raise()?;
        PyArray1::from_slice(py, &matrix(&p)).reshape([4, 4])
    }

    /// Sets an object's collision filter bits. KeyError / ValueError.
    #[pyo3(signature = (id, *, group, mask))]
    fn set_filter(&mut self, id: i64, group: i64, mask: i64) -> PyResult<()> {
        let h = self.ids.handle(id)?;
        let f = arrays::filter(group, mask)?;
        each_world!(&mut self.inner, w => w.set_filter(h, f)).or_raise()
    }

    /// An object's filter as `(group, mask)`. KeyError if not in the world.
    fn filter(&self, id: i64) -> PyResult<(u32, u32)> {
        let h = self.ids.handle(id)?;
        let f = each_world!(&self.inner, w => w.object(h).map(|o| o.filter)).or_raise()?;
        Ok((f.group, f.mask))
    }

    /// Never report the pair (a, b) (either order) in contacts: an entry of
    /// the allowed-collision matrix (adjacent robot links always touch).
    /// KeyError for an id not in the world; ValueError for a == b.
    fn ignore(&mut self, a: i64, b: i64) -> PyResult<()> {
        let (ha, hb) = self.pair(a, b)?;
        each_world!(&mut self.inner, w => w.ignore(ha, hb)).or_raise()
    }

    /// Reports the pair (a, b) again; returns whether it was ignored.
    /// Raises as `ignore` does.
    fn unignore(&mut self, a: i64, b: i64) -> PyResult<bool> {
        let (ha, hb) = self.pair(a, b)?;
        each_world!(&mut self.inner, w => w.unignore(ha, hb)).or_raise()
    }

    /// Whether the pair (a, b) is ignored. Raises as `ignore` does.
    fn is_ignored(&self, a: i64, b: i64) -> PyResult<bool> {
        let (ha, hb) = self.pair(a, b)?;
        each_world!(&self.inner, w => w.is_ignored(ha, hb)).or_raise()
    }

    /// Number of ignored pairs.
    #[getter]
    fn n_ignored(&self) -> usize {
        each_world!(&self.inner, w => w.ignored_len())
    }

    /// contacts(*, first=False, workers=1) -> WorldContacts
    ///
    /// Every pair of objects whose posed shapes share a point (closed:
    /// touching counts), each once, after the filters and ignored pairs,
    /// with its intersecting primitive pairs (triangle indices; 0 for a
    /// ball); with `first=True`, one witness pair per object pair (each
    /// mesh traversal stops at its first contact: cheaper). Meshes are
    /// surfaces: a mesh entirely inside another does not touch it. With
    /// coherence, pairs of objects unchanged since the last contacts of the
    /// same kind are not tested again. `workers`: 1 (this thread), n (a pool
    /// of n threads) or -1 (one per core). Runs with the interpreter
    /// released. ValueError if two objects are so far apart that their
    /// relative pose leaves float32 range.
    #[pyo3(signature = (*, first=false, workers=1))]
    fn contacts(&mut self, py: Python<'_>, first: bool, workers: i64) -> PyResult<WorldContacts> {
        let workers = Workers::new(workers)?;
        let mode = if first {
            ContactMode::First
        } else {
            ContactMode::All
        };
        let inner = &mut self.inner;
        let p = py
            .detach(|| each_world!(inner, w => contacts(w, mode, &workers)))
            .or_raise()?;
        let (n, k) = (p.offsets.len() - 1, p.triangles.len() / 2);
        let counters = PyDict::new(py);
        for (name, v) in p.counters {
            counters.set_item(name, v)?;
        }
        Ok(WorldContacts {
            pairs: PyArray1::from_vec(py, p.pairs).reshape([n, 2])?.unbind(),
            offsets: PyArray1::from_vec(py, p.offsets).unbind(),
            triangles: PyArray1::from_vec(py, p.triangles)
                .reshape([k, 2])?
                .unbind(),
            counters: counters.unbind(),
        })
    }

    /// ray_cast(rays, tmax=None, *, group=0xFFFFFFFF, mask=0xFFFFFFFF, workers=1)
    ///
    /// The first primitive each ray hits: `rays` (R, 6) — origin x, y, z,
    /// direction x, y, z (any non-zero length; t is in its units) — for t
    /// in [0, tmax] (a scalar or (R,); inf by default), among the objects
    /// whose filter meets (`group`, `mask`). Smallest t; ties to the
    /// smaller object, then the smaller triangle. A ball is solid (t = 0
    /// from inside). Returns a dict with Open3D's names: "t_hit" (R,)
    /// float32 (inf for a miss), "geometry_ids" (R,) int64 (the object, -1
    /// for a miss), "primitive_ids" (R,) int64 (the triangle, 0 for a ball,
    /// -1 for a miss). Runs with the interpreter released.
    #[pyo3(signature = (rays, tmax=None, *, group=0xFFFF_FFFF, mask=0xFFFF_FFFF, workers=1))]
    fn ray_cast<'py>(
        &self,
        py: Python<'py>,
        rays: &Bound<'py, PyAny>,
        tmax: Option<&Bound<'py, PyAny>>,
        group: i64,
        mask: i64,
        workers: i64,
    ) -> PyResult<Bound<'py, PyDict>> {
        let f = arrays::filter(group, mask)?;
        let rs: Vec<Ray> = arrays::rays(rays, tmax)?;
        let workers = Workers::new(workers)?;
        let inner = &self.inner;
        let hits = py
            .detach(|| {
                each_world!(inner, w => batch(&rs, &workers, |r| {
                    Ok(w.ray_cast(r, f)?.map(|h| {
                        (*w.get(h.object).expect("a hit names a live object") as i64, h)
                    }))
                }))
            })
            .or_raise()?;
        let n = hits.len();
        let (mut t, mut ids, mut tris) = (Vec::with_capacity(n), vec![-1i64; n], vec![-1i64; n]);
        for (k, h) in hits.into_iter().enumerate() {
            match h {
                Some((id, h)) => {
                    t.push(h.t);
                    ids[k] = id;
                    tris[k] = i64::from(h.triangle);
                }
                None => t.push(f32::INFINITY),
            }
        }
        let out = PyDict::new(py);
        out.set_item("t_hit", PyArray1::from_vec(py, t))?;
        out.set_item("geometry_ids", PyArray1::from_vec(py, ids))?;
        out.set_item("primitive_ids", PyArray1::from_vec(py, tris))?;
        Ok(out)
    }

    /// overlap_sphere(spheres, *, group=0xFFFFFFFF, mask=0xFFFFFFFF, workers=1)
    ///
    /// The objects with some point within distance r of each query point:
    /// `spheres` (M, 4) — x, y, z, r (closed) — among the objects whose
    /// filter meets (`group`, `mask`); exact (a mesh needs a triangle that
    /// close, a ball must overlap). Returns `(ids, offsets)`: query i
    /// selects `ids[offsets[i]:offsets[i+1]]`, ascending. Runs with the
    /// interpreter released.
    #[pyo3(signature = (spheres, *, group=0xFFFF_FFFF, mask=0xFFFF_FFFF, workers=1))]
    fn overlap_sphere<'py>(
        &self,
        py: Python<'py>,
        spheres: &Bound<'py, PyAny>,
        group: i64,
        mask: i64,
        workers: i64,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let f = arrays::filter(group, mask)?;
        let (v, _) = rows(spheres, 4, "spheres")?;
        let qs: Vec<(Vec3, f32)> = v.chunks_exact(4).map(|s| (vec3(s), s[3])).collect();
        for (i, (c, r)) in qs.iter().enumerate() {
            Sphere::new(*c, *r)
                .validate()
                .or_raise_at(|| format!("spheres: row {i}"))?;
        }
        let workers = Workers::new(workers)?;
        let inner = &self.inner;
        let lists = py
            .detach(|| {
                each_world!(inner, w => batch(&qs, &workers, |(c, r)| {
                    Ok(sorted_ids(w, w.overlap_sphere(*c, *r, f)?))
                }))
            })
            .or_raise()?;
        csr_tuple(py, csr(lists))
    }

    /// cull(matrices, *, depth="zero_to_one", group=0xFFFFFFFF, mask=0xFFFFFFFF, workers=1)
    ///
    /// The objects whose bounding sphere is not entirely outside each view
    /// frustum (conservative: what a renderer must draw): `matrices`
    /// (M, 4, 4) view-projection matrices, row-major, acting on column
    /// vectors; `depth` as in `Index.query_frusta`. Returns `(ids, offsets)`
    /// as `overlap_sphere` does.
    #[pyo3(signature = (matrices, *, depth="zero_to_one", group=0xFFFF_FFFF, mask=0xFFFF_FFFF, workers=1))]
    fn cull<'py>(
        &self,
        py: Python<'py>,
        matrices: &Bound<'py, PyAny>,
        depth: &str,
        group: i64,
        mask: i64,
        workers: i64,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let f = arrays::filter(group, mask)?;
        let fs: Vec<Frustum> = arrays::frusta(matrices, depth)?;
        let workers = Workers::new(workers)?;
        let inner = &self.inner;
        let lists = py
            .detach(|| {
                each_world!(inner, w => batch(&fs, &workers, |q| Ok(sorted_ids(w, w.cull(q, f)?))))
            })
            .or_raise()?;
        csr_tuple(py, csr(lists))
    }

    /// Heap bytes held by the world's own structures and its id table
    /// (shared meshes not counted).
    #[getter]
    fn memory_bytes(&self) -> usize {
        each_world!(&self.inner, w => w.memory_bytes()) + self.ids.memory_bytes()
    }

    /// Checks the world's invariants (RuntimeError if one fails: a bug).
    fn validate(&self) -> PyResult<()> {
        each_world!(&self.inner, w => w.validate()).or_raise()
    }
}

/// `(ids, offsets)` as a tuple of arrays.
fn csr_tuple(py: Python<'_>, out: Csr) -> PyResult<Bound<'_, PyTuple>> {
    PyTuple::new(
        py,
        [
            PyArray1::from_vec(py, out.ids).into_any(),
            PyArray1::from_vec(py, out.offsets).into_any(),
        ],
    )
}

/// The answer of `World.contacts`, P object pairs in contact:
///
/// - `pairs` (P, 2) int64: object ids `(a, b)`, `a < b`, rows sorted;
/// - `offsets` (P + 1,) int64: pair i's primitive pairs are
///   `triangles[offsets[i]:offsets[i+1]]` (also `contacts[i]`);
/// - `triangles` (K, 2) int64: primitive pairs (triangle of a, triangle of
///   b; 0 for a ball), ascending within each pair; one per pair with
///   `first=True`;
/// - `counters`: dict of ints — "broad_pairs" (candidate pairs from the
///   broad phase), "filtered" (dropped as ignored, or by filters the index
///   did not already prune), "narrow_pairs"
///   (tested), "coherent_pairs" (reused unchanged), "cut_starts" (tests
///   started from the last traversal cut), "nv", "np", "nu" (volume tests,
///   primitive tests, volume updates).
///
/// `len(contacts)` is P; `bool(contacts)` is whether any pair touches.
#[pyclass(module = "proxima", name = "WorldContacts", frozen, get_all)]
pub struct WorldContacts {
    pairs: Py<PyArray2<i64>>,
    offsets: Py<PyArray1<i64>>,
    triangles: Py<PyArray2<i64>>,
    counters: Py<PyDict>,
}

#[pymethods]
impl WorldContacts {
    fn __len__(&self, py: Python<'_>) -> usize {
        self.offsets.bind(py).shape()[0].saturating_sub(1)
    }

    fn __bool__(&self, py: Python<'_>) -> bool {
        self.__len__(py) > 0
    }

    /// The (K_i, 2) primitive pairs of pair `i` (a view of `triangles`).
    fn __getitem__<'py>(&self, py: Python<'py>, i: isize) -> PyResult<Bound<'py, PyAny>> {
        csr_row(self.offsets.bind(py), self.triangles.bind(py), i, "pair")
    }

    fn __repr__(&self, py: Python<'_>) -> String {
        format!(
            "WorldContacts(pairs={}, triangles={})",
            self.__len__(py),
            self.triangles.bind(py).shape()[0]
        )
    }
}
