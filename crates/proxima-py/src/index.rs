//! `proxima.Index`: any of the six broad-phase indices, chosen by name, over
//! bounding spheres named by integer ids.

use crate::arrays::{self, filters, finite_rows, int_list, per_row, query_filter, rows, vec3};
use crate::errors::OrRaise;
use crate::ids::Ids;
use crate::queries::{self, Csr};
use crate::workers::Workers;
use numpy::{PyArray1, PyArray2, PyArrayMethods};
use proxima::broad::{AnyIndex, Filter, IndexKind, Metric, Query, SceneHint, SpatialIndex};
use proxima::geom::{Aabb, Sphere, SphereSweep};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// A broad-phase index over bounding spheres: one of the six built-in indices,
/// chosen by name.
///
/// Objects are named by integer **ids**: row `i` of the arrays the index was
/// built from is id `i`, and each later insert takes the next unused id, so ids
/// are insertion order (as row numbers are for scipy's cKDTree and geometry ids
/// for Open3D). An id is never reused: after `remove` or `clear` it raises
/// `KeyError`. Every query returns ids, so `centers[ids]` selects from the
/// arrays the index was built from.
///
/// Numbers are stored as float32 (float64 input is rounded); overlap is closed
/// (touching counts) and exact for the stored values.
///
/// Each object carries a collision filter, `group` and `mask` bit sets
/// (default every bit): `pairs()` reports two objects only if each one's
/// group meets the other's mask, and a query given `filter=(group, mask)`
/// reports only the objects whose filter interacts with that pair the same
/// way (the group/mask scheme of Box2D, Bullet and Rapier).
#[pyclass(module = "proxima", name = "Index")]
pub struct Index {
    inner: AnyIndex<u64>,
    /// The handle of each id ever issued.
    ids: Ids,
}

/// `(centers (K, 3), radii (K,))`.
type Spheres<'py> = (Bound<'py, PyArray2<f32>>, Bound<'py, PyArray1<f32>>);

/// `(ids (M,), t (M,))` of first ray hits.
type FirstHits<'py> = (Bound<'py, PyArray1<i64>>, Bound<'py, PyArray1<f32>>);

/// Spheres from `(n, 3)` centres and `(n,)` (or scalar) radii, each checked
/// (finite centre, finite non-negative radius), naming the first bad row.
fn spheres(
    centers: &Bound<'_, PyAny>,
    radii: &Bound<'_, PyAny>,
    what: &str,
) -> PyResult<Vec<Sphere>> {
    let (c, n) = finite_rows(centers, 3, "centers")?;
    let r = per_row(radii, n, "radii")?;
    let out: Vec<Sphere> = c
        .chunks_exact(3)
        .zip(r)
        .map(|(c, r)| Sphere::new(vec3(c), r))
        .collect();
    for (i, s) in out.iter().enumerate() {
        s.validate().or_raise_at(|| format!("{what}: row {i}"))?;
    }
    Ok(out)
}

impl Index {
    /// Stores `spheres` (already checked) with their `filters` under the next
    /// ids.
    fn insert_all(
        &mut self,
        py: Python<'_>,
        spheres: Vec<Sphere>,
        filters: Vec<Filter>,
    ) -> PyResult<Vec<i64>> {
        let first = self.ids.issued();
        let Index { inner, ids } = self;
        py.detach(|| {
            ids.reserve(spheres.len());
            for (k, (s, f)) in spheres.into_iter().zip(filters).enumerate() {
                let id = (first + k) as u64;
                match inner.insert_with_filter(s, f, id) {
                    Ok(h) => {
                        ids.push(h);
                    }
                    Err(e) => {
                        // Only a full index fails here: undo this batch.
                        for h in ids.take_from(first) {
                            let _ = inner.remove(h);
                        }
                        return Err(e);
                    }
                }
            }
            Ok(())
        })
        .or_raise()?;
        Ok((first as i64..self.ids.issued() as i64).collect())
    }

    /// A batch query's answer as `(ids, offsets)`, with `t` if asked.
    fn csr<'py>(py: Python<'py>, out: Csr, with_t: bool) -> Bound<'py, pyo3::types::PyTuple> {
        let ids = PyArray1::from_vec(py, out.ids).into_any();
        let offsets = PyArray1::from_vec(py, out.offsets).into_any();
        let items = if with_t {
            vec![ids, offsets, PyArray1::from_vec(py, out.t).into_any()]
        } else {
            vec![ids, offsets]
        };
        pyo3::types::PyTuple::new(py, items).expect("a tuple of arrays")
    }

    /// Runs a validated batch of queries with the interpreter released, among
    /// the objects the `filter=` argument admits.
    fn run(
        &self,
        py: Python<'_>,
        queries: &[Query],
        filter: Option<&Bound<'_, PyAny>>,
        workers: i64,
    ) -> PyResult<Csr> {
        let filter = query_filter(filter)?;
        let workers = Workers::new(workers)?;
        let inner = &self.inner;
        Ok(py.detach(|| queries::select(inner, queries, filter, &workers)))
    }
}

#[pymethods]
impl Index {
    /// Index(centers=None, radii=None, *, kind="grid3d", world=None, r_max=None, group=None, mask=None)
    ///
    /// Builds an index of `kind` ("brute", "loose-kd", "octree", "grid2d",
    /// "hashgrid" or "grid3d") holding the spheres `centers` (N, 3) with
    /// `radii` (N,) or one radius for all; row i gets id i. The index is tuned
    /// from the spheres (their box and the 99th percentile of the radii)
    /// unless `world` ([min, max] as (2, 3) or (6,)) and `r_max` (a typical
    /// large radius) say otherwise: give both when building an empty index
    /// that is filled by `insert` later. Any sphere is accepted, inside the
    /// world or not; the hint only tunes speed. `group` / `mask`: the
    /// objects' collision filters, each an integer bit set in 0..2**32 for
    /// all or an (N,) integer array (default: every bit). Cost: O(N) plus
    /// the inserts.
    ///
    /// Raises ValueError on an unknown kind, a wrong shape, a non-finite value,
    /// a negative radius or filter bits out of range.
    #[new]
    #[pyo3(signature = (centers=None, radii=None, *, kind="grid3d", world=None, r_max=None, group=None, mask=None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        py: Python<'_>,
        centers: Option<&Bound<'_, PyAny>>,
        radii: Option<&Bound<'_, PyAny>>,
        kind: &str,
        world: Option<&Bound<'_, PyAny>>,
        r_max: Option<f32>,
        group: Option<&Bound<'_, PyAny>>,
        mask: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Index> {
        let kind: IndexKind = kind.parse().or_raise()?;
        let spheres = match (centers, radii) {
            (Some(c), Some(r)) => spheres(c, r, "spheres")?,
            (None, None) => Vec::new(),
            _ => {
                return Err(PyValueError::new_err(
                    "give both centers and radii, or neither",
                ))
            }
        };
        let filters = filters(group, mask, spheres.len())?;
        let mut hint = SceneHint::from_spheres(spheres.iter().copied(), spheres.len());
        if let Some(w) = world {
            hint.world = arrays::aabb(w, "world")?;
        }
        if r_max.is_none() {
            point_cloud_hint(&mut hint, spheres.len());
        }
        if let Some(r) = r_max {
            if !(r.is_finite() && r > 0.0) {
                return Err(PyValueError::new_err(format!(
                    "r_max must be finite and positive, got {r}"
                )));
            }
            hint.r_max = r;
            hint.r_largest = hint.r_largest.max(r);
        }
        let mut index = Index {
            inner: kind.build(&hint).or_raise()?,
            ids: Ids::new("index"),
        };
        index.insert_all(py, spheres, filters)?;
        Ok(index)
    }

    /// The index's kind, as its name ("grid3d", ...).
    #[getter]
    fn kind(&self) -> &'static str {
        self.inner.kind().name()
    }

    /// Number of stored objects.
    fn __len__(&self) -> usize {
        self.inner.len()
    }

    /// Whether `id` names a stored object.
    fn __contains__(&self, id: &Bound<'_, PyAny>) -> bool {
        id.extract::<i64>().is_ok_and(|id| self.ids.contains(id))
    }

    fn __repr__(&self) -> String {
        format!("Index(kind={:?}, len={})", self.kind(), self.inner.len())
    }

    /// Stores one sphere, with collision filter `group` / `mask` (integers in
    /// 0..2**32, default every bit), and returns its id. O(log n) typical.
    #[pyo3(signature = (center, radius, *, group=None, mask=None))]
    fn insert(
        &mut self,
        py: Python<'_>,
        center: &Bound<'_, PyAny>,
        radius: &Bound<'_, PyAny>,
        group: Option<&Bound<'_, PyAny>>,
        mask: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<i64> {
        let s = spheres(center, radius, "sphere")?;
        if s.len() != 1 {
            return Err(PyValueError::new_err(
                "insert takes one sphere; use insert_many",
            ));
        }
        let f = filters(group, mask, 1)?;
        Ok(self.insert_all(py, s, f)?[0])
    }

    /// Stores the spheres `centers` (K, 3) with `radii` (K,) or one radius,
    /// and filters `group` / `mask` (each an integer or (K,); default every
    /// bit), and returns their ids (K,), consecutive. All or nothing: a bad
    /// row raises ValueError naming it and stores nothing.
    #[pyo3(signature = (centers, radii, *, group=None, mask=None))]
    fn insert_many<'py>(
        &mut self,
        py: Python<'py>,
        centers: &Bound<'py, PyAny>,
        radii: &Bound<'py, PyAny>,
        group: Option<&Bound<'py, PyAny>>,
        mask: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArray1<i64>>> {
        let s = spheres(centers, radii, "spheres")?;
        let f = filters(group, mask, s.len())?;
        Ok(PyArray1::from_vec(py, self.insert_all(py, s, f)?))
    }

    /// Sets the collision filter of the objects `ids` (one id or (K,)):
    /// `group` and `mask` each an integer in 0..2**32 or (K,). All or
    /// nothing: KeyError on an id not stored, ValueError on bad bits.
    #[pyo3(signature = (ids, *, group, mask))]
    fn set_filter(
        &mut self,
        ids: &Bound<'_, PyAny>,
        group: &Bound<'_, PyAny>,
        mask: &Bound<'_, PyAny>,
    ) -> PyResult<()> {
        let ids = int_list(ids, "ids")?;
        let hs = ids
            .iter()
            .map(|&id| self.ids.handle(id))
            .collect::<PyResult<Vec<_>>>()?;
        let fs = filters(Some(group), Some(mask), ids.len())?;
        for (h, f) in hs.into_iter().zip(fs) {
            self.inner.set_filter(h, f).or_raise()?;
        }
        Ok(())
    }

    /// An object's collision filter as `(group, mask)`. KeyError if not
    /// stored.
    fn filter(&self, id: i64) -> PyResult<(u32, u32)> {
        let f = SpatialIndex::filter(&self.inner, self.ids.handle(id)?).or_raise()?;
        Ok((f.group, f.mask))
    }

    /// Removes an object. KeyError if `id` is not stored.
    fn remove(&mut self, id: i64) -> PyResult<()> {
        let h = self.ids.handle(id)?;
        self.inner.remove(h).or_raise()?;
        self.ids.forget(id);
        Ok(())
    }

    /// Removes every object of `ids`. All or nothing: KeyError, removing
    /// nothing, if one is not stored or appears twice.
    fn remove_many(&mut self, ids: &Bound<'_, PyAny>) -> PyResult<()> {
        let ids = int_list(ids, "ids")?;
        let hs = self.ids.handles_of(&ids)?;
        for (id, h) in ids.into_iter().zip(hs) {
            self.inner.remove(h).or_raise()?;
            self.ids.forget(id);
        }
        Ok(())
    }

    /// Moves (and with `radius`, resizes) one object. KeyError if `id` is not
    /// stored; ValueError on a bad sphere (nothing changes).
    #[pyo3(signature = (id, center, radius=None))]
    fn update(
        &mut self,
        py: Python<'_>,
        id: i64,
        center: &Bound<'_, PyAny>,
        radius: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let ids = pyo3::types::PyList::new(py, [id])?;
        self.update_many(py, Some(ids.as_any()), center, radius)
    }

    /// Moves the objects `ids` (K,) to `centers` (K, 3), and resizes them to
    /// `radii` (K,) or one radius if given (otherwise they keep theirs).
    /// `ids=None` means ids 0..K-1 (every object of an index built from K
    /// rows). All or nothing: a stale id (KeyError) or a bad row (ValueError)
    /// changes nothing. Runs with the interpreter released. O(K) typical.
    #[pyo3(signature = (ids, centers, radii=None))]
    fn update_many(
        &mut self,
        py: Python<'_>,
        ids: Option<&Bound<'_, PyAny>>,
        centers: &Bound<'_, PyAny>,
        radii: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let (c, n) = finite_rows(centers, 3, "centers")?;
        let ids = match ids {
            Some(ids) => int_list(ids, "ids")?,
            None => (0..n as i64).collect(),
        };
        if ids.len() != n {
            return Err(PyValueError::new_err(format!(
                "{} ids but {n} centers",
                ids.len()
            )));
        }
        let r = radii.map(|r| per_row(r, n, "radii")).transpose()?;
        let mut moves = Vec::with_capacity(n);
        for (i, (&id, c)) in ids.iter().zip(c.chunks_exact(3)).enumerate() {
            let h = self.ids.handle(id)?;
            let radius = match &r {
                Some(r) => r[i],
                None => self.inner.get(h).or_raise()?.0.radius,
            };
            let s = Sphere::new(vec3(c), radius);
            s.validate().or_raise_at(|| format!("spheres: row {i}"))?;
            moves.push((h, s));
        }
        let inner = &mut self.inner;
        // Every handle is live and every sphere valid: no update can fail.
        py.detach(|| inner.update_many(moves)).or_raise()
    }

    /// The centre (3,) and radius of one object. KeyError if not stored.
    fn get<'py>(&self, py: Python<'py>, id: i64) -> PyResult<(Bound<'py, PyArray1<f32>>, f32)> {
        let (s, _) = self.inner.get(self.ids.handle(id)?).or_raise()?;
        Ok((PyArray1::from_slice(py, &s.center.to_array()), s.radius))
    }

    /// The ids of the stored objects, ascending.
    fn ids<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<i64>> {
        PyArray1::from_vec(py, self.ids.live())
    }

    /// The spheres of `ids` (default: every stored object, by ascending id) as
    /// `(centers (K, 3), radii (K,))`, float32. KeyError on an id not stored.
    #[pyo3(signature = (ids=None))]
    fn spheres<'py>(
        &self,
        py: Python<'py>,
        ids: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Spheres<'py>> {
        let ids: Vec<i64> = match ids {
            Some(ids) => int_list(ids, "ids")?,
            None => self.ids(py).to_vec()?,
        };
        let mut c = Vec::with_capacity(ids.len() * 3);
        let mut r = Vec::with_capacity(ids.len());
        for id in ids {
            let (s, _) = self.inner.get(self.ids.handle(id)?).or_raise()?;
            c.extend(s.center.to_array());
            r.push(s.radius);
        }
        let n = r.len();
        let c = PyArray1::from_vec(py, c).reshape([n, 3])?;
        Ok((c, PyArray1::from_vec(py, r)))
    }

    /// Removes every object (their ids raise KeyError from now on; new inserts
    /// continue after the last id issued) and releases the memory.
    fn clear(&mut self) {
        self.inner.clear();
        self.ids.forget_all();
    }

    /// Bytes held by the index and its id table.
    #[getter]
    fn memory_bytes(&self) -> usize {
        self.inner.memory_bytes() + self.ids.memory_bytes()
    }

    /// Checks the structure's invariants (RuntimeError if one fails: a bug).
    fn validate(&self) -> PyResult<()> {
        self.inner.validate().or_raise()
    }

    /// Objects overlapping each sphere of `spheres` (M, 4) — centre x, y, z,
    /// radius — (also the point-radius query). Returns `(ids, offsets)`:
    /// sphere i selects `ids[offsets[i]:offsets[i+1]]`, ascending; int64.
    /// One (4,) row is a batch of one. `filter`: None (every object) or a
    /// `(group, mask)` pair: only the objects whose filter interacts with it
    /// (each one's group meets the other's mask); the same on every query.
    /// `workers`: 1 (this thread), n (a pool of n threads) or -1 (one per
    /// core). Runs with the interpreter released.
    #[pyo3(signature = (spheres, *, filter=None, workers=1))]
    fn query_spheres<'py>(
        &self,
        py: Python<'py>,
        spheres: &Bound<'py, PyAny>,
        filter: Option<&Bound<'py, PyAny>>,
        workers: i64,
    ) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
        let (v, _) = rows(spheres, 4, "spheres")?;
        let qs: Vec<Query> = v
            .chunks_exact(4)
            .map(|s| Sphere::new(vec3(s), s[3]).into())
            .collect();
        queries::validate(&qs, "spheres")?;
        Ok(Self::csr(py, self.run(py, &qs, filter, workers)?, false))
    }

    /// Objects overlapping each box of `boxes` (M, 6) — min x, y, z, max x,
    /// y, z. Returns `(ids, offsets)` as `query_spheres` does.
    #[pyo3(signature = (boxes, *, filter=None, workers=1))]
    fn query_boxes<'py>(
        &self,
        py: Python<'py>,
        boxes: &Bound<'py, PyAny>,
        filter: Option<&Bound<'py, PyAny>>,
        workers: i64,
    ) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
        let (v, _) = rows(boxes, 6, "boxes")?;
        let qs: Vec<Query> = v
            .chunks_exact(6)
            .map(|b| Aabb::new(vec3(&b[..3]), vec3(&b[3..])).into())
            .collect();
        queries::validate(&qs, "boxes")?;
        Ok(Self::csr(py, self.run(py, &qs, filter, workers)?, false))
    }

    /// Objects each ray touches for some t in [0, tmax]: `rays` (M, 6) —
    /// origin x, y, z, direction x, y, z (any non-zero length; t is in its
    /// units) — and `tmax` (a scalar or (M,); inf by default). Returns
    /// `(ids, offsets)`, each ray's hits in order along it (entry t, 0 if the
    /// origin is inside; ties by id), and with `return_t=True` also `t`
    /// (float32) beside `ids`.
    #[pyo3(signature = (rays, tmax=None, *, return_t=false, filter=None, workers=1))]
    fn query_rays<'py>(
        &self,
        py: Python<'py>,
        rays: &Bound<'py, PyAny>,
        tmax: Option<&Bound<'py, PyAny>>,
        return_t: bool,
        filter: Option<&Bound<'py, PyAny>>,
        workers: i64,
    ) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
        let rs = arrays::rays(rays, tmax)?;
        let qs: Vec<Query> = rs.into_iter().map(Query::from).collect();
        Ok(Self::csr(py, self.run(py, &qs, filter, workers)?, return_t))
    }

    /// The first object each ray enters (smallest entry t; between equal t,
    /// one of them): `rays` (M, 6) and `tmax` as in `query_rays`. Returns
    /// `(ids (M,) int64, t (M,) float32)`, id -1 and t inf for a miss.
    #[pyo3(signature = (rays, tmax=None, *, filter=None, workers=1))]
    fn ray_first<'py>(
        &self,
        py: Python<'py>,
        rays: &Bound<'py, PyAny>,
        tmax: Option<&Bound<'py, PyAny>>,
        filter: Option<&Bound<'py, PyAny>>,
        workers: i64,
    ) -> PyResult<FirstHits<'py>> {
        let rs = arrays::rays(rays, tmax)?;
        let filter = query_filter(filter)?;
        let workers = Workers::new(workers)?;
        let inner = &self.inner;
        let (ids, t) = py.detach(|| queries::first_hits(inner, &rs, filter, &workers));
        Ok((PyArray1::from_vec(py, ids), PyArray1::from_vec(py, t)))
    }

    /// Objects inside each view frustum (culling): `matrices` (M, 4, 4)
    /// view-projection matrices (projection @ view, row-major as numpy
    /// writes them, acting on column vectors (x, y, z, 1)). `depth` is the
    /// clip-space depth range of the projection: "zero_to_one" (Direct3D,
    /// Vulkan, Metal, wgpu, glam) or "minus_one_to_one" (OpenGL). A sphere is
    /// culled only when it lies entirely outside one of the six planes, so
    /// spheres near a corner may be kept. Returns `(ids, offsets)` as
    /// `query_spheres` does.
    #[pyo3(signature = (matrices, *, depth="zero_to_one", filter=None, workers=1))]
    fn query_frusta<'py>(
        &self,
        py: Python<'py>,
        matrices: &Bound<'py, PyAny>,
        depth: &str,
        filter: Option<&Bound<'py, PyAny>>,
        workers: i64,
    ) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
        let qs: Vec<Query> = arrays::frusta(matrices, depth)?
            .into_iter()
            .map(Query::from)
            .collect();
        queries::validate(&qs, "matrices")?;
        Ok(Self::csr(py, self.run(py, &qs, filter, workers)?, false))
    }

    /// Every pair of stored objects that overlap (touching counts), once, as
    /// a (P, 2) int64 array of ids with the smaller id first; rows sorted
    /// unless `sort=False` (then in no particular order, and cheaper).
    #[pyo3(signature = (*, sort=true, workers=1))]
    fn pairs<'py>(
        &self,
        py: Python<'py>,
        sort: bool,
        workers: i64,
    ) -> PyResult<Bound<'py, PyArray2<i64>>> {
        let workers = Workers::new(workers)?;
        let inner = &self.inner;
        let p = py.detach(|| queries::pairs(inner, &workers, sort));
        let n = p.len();
        let flat: Vec<i64> = p.into_iter().flatten().collect();
        PyArray1::from_vec(py, flat).reshape([n, 2])
    }

    /// nearest(points, k=1, *, distance_upper_bound=inf, metric="surface", filter=None, workers=1)
    ///
    /// The `k` objects nearest to each point, like scipy's `cKDTree.query`:
    /// `points` (M, 3) (or one (3,) point) → `(distances, ids)`, nearest
    /// first, ties by smaller id. Shapes follow cKDTree: (M, k) for k > 1,
    /// (M,) for k == 1, and without the M axis for a single (3,) point (a
    /// float and an int for k == 1). Where fewer than k objects qualify the
    /// rows are padded with distance inf and id -1 (cKDTree pads with inf and
    /// n; -1 is never an id). Distances are float32, ids int64.
    ///
    /// `metric`: "surface" (default; max(0, |c - p| - r), 0 inside a
    /// sphere) or "center" (|c - p|; for point clouds, as cKDTree; with
    /// radius-0 spheres the two agree). `distance_upper_bound`: only objects
    /// at most this far (inclusive; cKDTree's bound is strict). `filter`:
    /// as for `query_spheres`. `k` is an int >= 1 (cKDTree's list of ranks is
    /// not supported). Each distance is correctly rounded, so every kind
    /// answers bit for bit the same. Cost per point: the index's best-first
    /// search, about O(log n + k log k); runs with the interpreter released.
    ///
    /// Raises ValueError on a wrong shape, a non-finite point, k < 1, a NaN
    /// or negative bound or an unknown metric, and MemoryError when the
    /// (M, k) answer cannot be allocated (a huge k).
    #[pyo3(signature = (points, k=1, *, distance_upper_bound=f64::INFINITY, metric="surface", filter=None, workers=1))]
    #[allow(clippy::too_many_arguments)]
    fn nearest<'py>(
        &self,
        py: Python<'py>,
        points: &Bound<'py, PyAny>,
        k: i64,
        distance_upper_bound: f64,
        metric: &str,
        filter: Option<&Bound<'py, PyAny>>,
        workers: i64,
    ) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
        let (shape, v) = arrays::f32_values(points, "points")?;
        let (m, single) = match shape[..] {
            [m, 3] => (m, false),
            [3] => (1, true),
            [0] => (0, false),
            _ => return Err(arrays::shape_error("points", "(M, 3) or (3,)", &shape)),
        };
        arrays::check_finite(&v, 3, "points", "row")?;
        let k = match usize::try_from(k) {
            Ok(k) if k >= 1 => k,
            _ => return Err(PyValueError::new_err(format!("k must be >= 1, got {k}"))),
        };
        let metric = match metric {
            "surface" => Metric::Surface,
            "center" => Metric::Center,
            other => {
                return Err(PyValueError::new_err(format!(
                    "metric must be \"surface\" or \"center\", got {other:?}"
                )))
            }
        };
        if distance_upper_bound.is_nan() || distance_upper_bound < 0.0 {
            return Err(PyValueError::new_err(format!(
                "distance_upper_bound must be >= 0 (inf for none), got {distance_upper_bound}"
            )));
        }
        // Rounded up, so that an object exactly at the bound (as a float64)
        // is not lost to rounding.
        let bound = round_up_f32(distance_upper_bound);
        let filter = query_filter(filter)?;
        let workers = Workers::new(workers)?;
        // Each entry an f32 distance and an i64 id.
        arrays::check_answer_size("nearest", m, k, 12)?;
        if u32::try_from(m).is_err() {
            return Err(PyValueError::new_err(format!(
                "points: at most 2^32 points a batch, got {m}"
            )));
        }
        let pts: Vec<_> = v.chunks_exact(3).map(vec3).collect();
        let (inner, ordered, by_slot) = (&self.inner, self.ids.ordered(), self.ids.id_of_slot());
        let table = py
            .detach(|| {
                queries::nearest(
                    inner, &pts, k, bound, metric, filter, ordered, by_slot, &workers,
                )
            })
            .or_raise()?;
        let d = PyArray1::from_vec(py, table.distances);
        let ids = PyArray1::from_vec(py, table.ids);
        let items: [Bound<'py, PyAny>; 2] = match (single, k) {
            (true, 1) => [d.as_any().get_item(0)?, ids.as_any().get_item(0)?],
            (true, _) | (false, 1) => [d.into_any(), ids.into_any()],
            (false, _) => [
                d.reshape([m, k])?.into_any(),
                ids.reshape([m, k])?.into_any(),
            ],
        };
        pyo3::types::PyTuple::new(py, items)
    }

    /// sweep(starts, ends, radii=0.0, *, all=False, filter=None, workers=1)
    ///
    /// Sphere casts: a sphere of radius `radii[i]` (a scalar or (M,); >= 0)
    /// whose centre moves in a straight line from `starts[i]` (time t = 0) to
    /// `ends[i]` (t = 1), both (M, 3). It touches a stored sphere when their
    /// distance comes to at most the sum of the radii (closed). Returns the
    /// first object each sweep touches, `(ids (M,) int64, t (M,) float32)`
    /// — smallest time of impact, ties by smaller id, id -1 and t inf for a
    /// miss, t = 0 when touching at the start — or with `all=True` every
    /// object touched as `(ids, offsets, t)`: sweep i touches
    /// `ids[offsets[i]:offsets[i+1]]` in order of t, ties by id. Radius 0 is
    /// the exact segment query. `filter` as for `query_spheres`. Runs with
    /// the interpreter released.
    #[pyo3(signature = (starts, ends, radii=None, *, all=false, filter=None, workers=1))]
    #[allow(clippy::too_many_arguments)]
    fn sweep<'py>(
        &self,
        py: Python<'py>,
        starts: &Bound<'py, PyAny>,
        ends: &Bound<'py, PyAny>,
        radii: Option<&Bound<'py, PyAny>>,
        all: bool,
        filter: Option<&Bound<'py, PyAny>>,
        workers: i64,
    ) -> PyResult<Bound<'py, pyo3::types::PyTuple>> {
        let (a, m) = finite_rows(starts, 3, "starts")?;
        let (b, m2) = finite_rows(ends, 3, "ends")?;
        if m != m2 {
            return Err(PyValueError::new_err(format!("{m} starts but {m2} ends")));
        }
        let r = match radii {
            Some(r) => per_row(r, m, "radii")?,
            None => vec![0.0; m],
        };
        let sweeps: Vec<SphereSweep> = (a.chunks_exact(3).zip(b.chunks_exact(3)).zip(r))
            .map(|((a, b), r)| SphereSweep::new(vec3(a), vec3(b), r))
            .collect();
        for (i, w) in sweeps.iter().enumerate() {
            w.validate().or_raise_at(|| format!("sweeps: row {i}"))?;
        }
        if all {
            let qs: Vec<Query> = sweeps.into_iter().map(Query::Sweep).collect();
            return Ok(Self::csr(py, self.run(py, &qs, filter, workers)?, true));
        }
        let filter = query_filter(filter)?;
        let workers = Workers::new(workers)?;
        let (inner, ordered) = (&self.inner, self.ids.ordered());
        let (ids, t) =
            py.detach(|| queries::first_sweeps(inner, &sweeps, filter, ordered, &workers));
        let items = [
            PyArray1::from_vec(py, ids).into_any(),
            PyArray1::from_vec(py, t).into_any(),
        ];
        pyo3::types::PyTuple::new(py, items)
    }
}

/// The smallest `f32` at least `x` (for `x >= 0`; `inf` stays `inf`).
fn round_up_f32(x: f64) -> f32 {
    let y = x as f32;
    if (y as f64) < x {
        f32::from_bits(y.to_bits() + 1)
    } else {
        y
    }
}

/// Point clouds (radii far below the spacing of the centres, e.g. radius 0 as
/// for scipy's cKDTree) would tune the indices to the library's minimum radius
/// hint: a grid of millions of empty cells, a tree split far below one point
/// per leaf (measured: 100k points in a unit cube, grid3d nearest 70x and
/// loose-kd 11x cKDTree.query). The radius hint is raised to half the mean
/// spacing `(world volume / n)^(1/3)`, so that a cell holds about one centre.
/// Scenes whose radius hint is at least a quarter of the spacing (W1's spheres
/// of equal radius) are left as they are.
fn point_cloud_hint(hint: &mut SceneHint, n: usize) {
    if n == 0 {
        return;
    }
    let e = hint.world.extent();
    let spacing = ((e.x as f64 * e.y as f64 * e.z as f64) / n as f64).cbrt() as f32;
    if spacing.is_finite() && hint.r_max < 0.25 * spacing {
        hint.r_max = 0.5 * spacing;
        hint.r_largest = hint.r_largest.max(hint.r_max);
    }
}
