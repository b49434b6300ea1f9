//! `proxima.Mesh`: a triangle mesh with its collision BVH (any of the six
//! bounding volumes, chosen by name) and its ray BVH; ray casts on batches.

use crate::arrays::{self, finite_rows, vec3};
use crate::errors::OrRaise;
use crate::workers::Workers;
use numpy::{PyArray1, PyArray2, PyArrayMethods};
use proxima::geom::{Aabb, Ray, Sphere};
use proxima::glam::{Affine3A, Vec3};
use proxima::narrow::{
    check_pose, BoundingVolume, BuildOptions, Kdop14, Kdop18, Kdop26, Mesh as RsMesh, Obb,
    SplitRule, TriMesh, TriangleHit,
};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;
use std::sync::Arc;

/// A mesh with whichever bounding volume was chosen at run time, in an `Arc`
/// so that `World` objects share it (its trees are built once).
pub enum AnyMesh {
    /// With an AABB tree.
    Aabb(Arc<RsMesh<Aabb>>),
    /// With a k-DOP-14 tree.
    Kdop14(Arc<RsMesh<Kdop14>>),
    /// With a k-DOP-18 tree.
    Kdop18(Arc<RsMesh<Kdop18>>),
    /// With a k-DOP-26 tree.
    Kdop26(Arc<RsMesh<Kdop26>>),
    /// With an OBB tree.
    Obb(Arc<RsMesh<Obb>>),
    /// With a sphere tree.
    Sphere(Arc<RsMesh<Sphere>>),
}

/// `$body` with `$m` bound to the mesh inside `$any`, whatever its volume.
macro_rules! each_mesh {
    ($any:expr, $m:ident => $body:expr) => {
        match $any {
            AnyMesh::Aabb($m) => $body,
            AnyMesh::Kdop14($m) => $body,
            AnyMesh::Kdop18($m) => $body,
            AnyMesh::Kdop26($m) => $body,
            AnyMesh::Obb($m) => $body,
            AnyMesh::Sphere($m) => $body,
        }
    };
}

/// The bounding-volume names, as the command-line tool spells them.
pub const BV_NAMES: [&str; 6] = ["aabb", "kdop14", "kdop18", "kdop26", "obb", "sphere"];

impl AnyMesh {
    /// Builds the collision tree of `geometry` with bounding volume `bv`.
    fn build(geometry: TriMesh, bv: &str, options: BuildOptions) -> proxima::Result<AnyMesh> {
        Ok(match bv {
            "aabb" => AnyMesh::Aabb(Arc::new(RsMesh::from_trimesh(geometry, options)?)),
            "kdop14" => AnyMesh::Kdop14(Arc::new(RsMesh::from_trimesh(geometry, options)?)),
            "kdop18" => AnyMesh::Kdop18(Arc::new(RsMesh::from_trimesh(geometry, options)?)),
            "kdop26" => AnyMesh::Kdop26(Arc::new(RsMesh::from_trimesh(geometry, options)?)),
            "obb" => AnyMesh::Obb(Arc::new(RsMesh::from_trimesh(geometry, options)?)),
            "sphere" => AnyMesh::Sphere(Arc::new(RsMesh::from_trimesh(geometry, options)?)),
            _ => unreachable!("checked by bv_name"),
        })
    }

    /// The bounding volume's name.
    pub fn bv(&self) -> &'static str {
        fn name<BV: BoundingVolume>(_: &RsMesh<BV>) -> &'static str {
            BV::NAME
        }
        each_mesh!(self, m => name(&**m))
    }

    fn trimesh(&self) -> &TriMesh {
        each_mesh!(self, m => m.trimesh())
    }
}

/// Checks a bounding-volume name.
fn bv_name(bv: &str) -> PyResult<&str> {
    if BV_NAMES.contains(&bv) {
        Ok(bv)
    } else {
        Err(PyValueError::new_err(format!(
            "unknown bv {bv:?} (known: {})",
            BV_NAMES.join(", ")
        )))
    }
}

/// Build options from the Python arguments.
fn options(split: &str, leaf_size: usize) -> PyResult<BuildOptions> {
    let split = match split {
        "sah" => SplitRule::Sah,
        "mean" => SplitRule::Mean,
        "median" => SplitRule::Median,
        s => {
            return Err(PyValueError::new_err(format!(
                "split must be \"sah\", \"mean\" or \"median\", got {s:?}"
            )))
        }
    };
    if leaf_size == 0 {
        return Err(PyValueError::new_err("leaf_size must be at least 1"));
    }
    Ok(BuildOptions { split, leaf_size })
}

/// Triangles from an `(F, 3)` integer array, each index in `0..2^32`.
fn faces(obj: &Bound<'_, PyAny>) -> PyResult<Vec<[u32; 3]>> {
    let (shape, v) = arrays::i64_values(obj, "faces")?;
    if !matches!(shape[..], [_, 3]) {
        return Err(arrays::shape_error("faces", "(F, 3)", &shape));
    }
    v.chunks_exact(3)
        .enumerate()
        .map(|(i, f)| {
            let idx = |x: i64| {
                u32::try_from(x).map_err(|_| {
                    PyValueError::new_err(format!("faces: row {i} has vertex index {x}"))
                })
            };
            Ok([idx(f[0])?, idx(f[1])?, idx(f[2])?])
        })
        .collect()
}

/// A triangle mesh with its collision BVH and ray BVH.
///
/// `Mesh(vertices, faces)` from arrays, `Mesh.load(path)` from an OBJ, STL or
/// PLY file. `bv` picks the collision tree's bounding volume: "kdop18" (the
/// default, fastest on the project's benchmarks), "kdop14", "kdop26", "aabb",
/// "obb" or "sphere"; two meshes collide only if they use the same one.
/// Vertices are stored as float32. Triangle indices (`primitive_ids`, the
/// pairs of `collide`) are rows of `faces`, i.e. the file's order.
#[pyclass(module = "proxima", name = "Mesh")]
pub struct Mesh {
    /// The mesh and its trees.
    pub inner: AnyMesh,
}

#[pymethods]
impl Mesh {
    /// Mesh(vertices, faces, *, bv="kdop18", split="sah", leaf_size=1)
    ///
    /// A mesh of `vertices` (V, 3) floats and `faces` (F, 3) vertex indices
    /// (any integer dtype). Builds the collision tree (O(F log F)), with the
    /// interpreter released; the ray tree is built on the first ray cast.
    /// `split` ("sah", "mean", "median") and `leaf_size` tune the tree.
    /// Raises ValueError on a wrong shape or dtype, a non-finite vertex, an
    /// index out of range, no faces, or an unknown bv or split.
    #[new]
    #[pyo3(signature = (vertices, faces, *, bv="kdop18", split="sah", leaf_size=1))]
    fn new(
        py: Python<'_>,
        vertices: &Bound<'_, PyAny>,
        faces: &Bound<'_, PyAny>,
        bv: &str,
        split: &str,
        leaf_size: usize,
    ) -> PyResult<Mesh> {
        let bv = bv_name(bv)?;
        let options = options(split, leaf_size)?;
        let (v, _) = finite_rows(vertices, 3, "vertices")?;
        let f = self::faces(faces)?;
        let v: Vec<Vec3> = v.chunks_exact(3).map(vec3).collect();
        py.detach(|| AnyMesh::build(TriMesh::new(v, f)?, bv, options))
            .or_raise()
            .map(|inner| Mesh { inner })
    }

    /// Mesh.load(path, *, bv="kdop18", split="sah", leaf_size=1)
    ///
    /// Reads an OBJ, STL (ASCII or binary) or PLY (ASCII or binary) file,
    /// told by its extension or its content, and builds the mesh as
    /// `Mesh(...)` does. FileNotFoundError / PermissionError / OSError if the
    /// file cannot be read; ValueError (naming the file and line or byte
    /// offset) if it is malformed or of an unknown format.
    #[staticmethod]
    #[pyo3(signature = (path, *, bv="kdop18", split="sah", leaf_size=1))]
    fn load(
        py: Python<'_>,
        path: PathBuf,
        bv: &str,
        split: &str,
        leaf_size: usize,
    ) -> PyResult<Mesh> {
        let bv = bv_name(bv)?;
        let options = options(split, leaf_size)?;
        py.detach(|| AnyMesh::build(proxima::io::load(&path)?, bv, options))
            .or_raise()
            .map(|inner| Mesh { inner })
    }

    /// The collision tree's bounding volume ("kdop18", ...).
    #[getter]
    fn bv(&self) -> &'static str {
        self.inner.bv()
    }

    /// Number of triangles.
    #[getter]
    fn n_triangles(&self) -> usize {
        self.inner.trimesh().len()
    }

    /// Number of vertices.
    #[getter]
    fn n_vertices(&self) -> usize {
        self.inner.trimesh().vertices().len()
    }

    /// A copy of the vertices, (V, 3) float32.
    #[getter]
    fn vertices<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f32>>> {
        let v = self.inner.trimesh().vertices();
        let flat: Vec<f32> = v.iter().flat_map(|p| p.to_array()).collect();
        PyArray1::from_vec(py, flat).reshape([v.len(), 3])
    }

    /// A copy of the triangles, (F, 3) int64 vertex indices.
    #[getter]
    fn faces<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<i64>>> {
        let t = self.inner.trimesh().triangles();
        let flat: Vec<i64> = t.iter().flat_map(|f| f.map(i64::from)).collect();
        PyArray1::from_vec(py, flat).reshape([t.len(), 3])
    }

    /// The box of every triangle corner, (2, 3): [min, max].
    #[getter]
    fn aabb<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f32>>> {
        let b = each_mesh!(&self.inner, m => m.aabb());
        let flat = [b.min.to_array(), b.max.to_array()].concat();
        PyArray1::from_vec(py, flat).reshape([2, 3])
    }

    /// A sphere containing every triangle corner: (center (3,), radius).
    #[getter]
    fn bounding_sphere<'py>(&self, py: Python<'py>) -> (Bound<'py, PyArray1<f32>>, f32) {
        let s = each_mesh!(&self.inner, m => m.bounding_sphere());
        (PyArray1::from_slice(py, &s.center.to_array()), s.radius)
    }

    /// Moves the vertices (same count, same faces: a deformed mesh) and
    /// refits both trees, O(V + F). ValueError, changing nothing, on a wrong
    /// count or a non-finite vertex, or while the mesh is the shape of objects
    /// of a `World` (a world's shapes never change under it).
    fn set_vertices(&mut self, py: Python<'_>, vertices: &Bound<'_, PyAny>) -> PyResult<()> {
        let (v, _) = finite_rows(vertices, 3, "vertices")?;
        let v: Vec<Vec3> = v.chunks_exact(3).map(vec3).collect();
        let inner = &mut self.inner;
        py.detach(|| {
            each_mesh!(inner, m => match Arc::get_mut(m) {
                Some(m) => m.set_vertices(&v),
                None => Err(proxima::Error::InvalidParameter(format!(
                    "the mesh is the shape of {} World object(s); remove them first, or build a new Mesh",
                    Arc::strong_count(m) - 1
                ))),
            })
        })
        .or_raise()
    }

    fn __repr__(&self) -> String {
        format!(
            "Mesh(n_vertices={}, n_triangles={}, bv={:?})",
            self.n_vertices(),
            self.n_triangles(),
            self.bv()
        )
    }

    /// The closest hit of each ray on the mesh, exact (watertight
    /// ray-triangle test): `rays` (R, 6) — origin x, y, z, direction x, y, z
    /// (any non-zero length; t is in its units) — up to `tmax` (a scalar or
    /// (R,); inf by default). With `pose` ((4, 4) or (3, 4) rigid), the mesh
    /// is placed at `pose` and the rays are in the world frame.
    ///
    /// Returns a dict with Open3D's names: "t_hit" (R,) float32 (inf for a
    /// miss), "primitive_ids" (R,) int64, the triangle (-1 for a miss; the
    /// smaller index when two triangles are hit at the same t), and
    /// "primitive_uvs" (R, 2) float32, the barycentrics (u, v) of the hit
    /// point (1-u-v)·a + u·b + v·c on the triangle's corners (0 for a miss).
    /// The first cast builds the ray tree. Runs with the interpreter released.
    #[pyo3(signature = (rays, tmax=None, *, pose=None, workers=1))]
    fn cast_rays<'py>(
        &self,
        py: Python<'py>,
        rays: &Bound<'py, PyAny>,
        tmax: Option<&Bound<'py, PyAny>>,
        pose: Option<&Bound<'py, PyAny>>,
        workers: i64,
    ) -> PyResult<Bound<'py, PyDict>> {
        let mut rs = arrays::rays(rays, tmax)?;
        if let Some(p) = pose {
            let (p, single) = arrays::poses(p, "pose")?;
            if !single {
                return Err(PyValueError::new_err(
                    "pose: one (4, 4) or (3, 4) pose for all rays",
                ));
            }
            check_pose(&p[0]).or_raise_at(|| "pose".into())?;
            let inv: Affine3A = p[0].inverse();
            for r in &mut rs {
                // A rigid motion keeps lengths: t is the same in both frames.
                r.origin = inv.transform_point3(r.origin);
                r.dir = inv.transform_vector3(r.dir);
            }
        }
        let workers = Workers::new(workers)?;
        let inner = &self.inner;
        let hits = py
            .detach(|| each_mesh!(inner, m => cast(&**m, &rs, &workers)))
            .or_raise()?;
        let n = hits.len();
        let mut t = Vec::with_capacity(n);
        let mut ids = Vec::with_capacity(n);
        let mut uv = Vec::with_capacity(2 * n);
        for h in hits {
            match h {
                Some(h) => {
                    t.push(h.t);
                    ids.push(i64::from(h.triangle));
                    uv.extend([h.u, h.v]);
                }
                None => {
                    t.push(f32::INFINITY);
                    ids.push(-1);
                    uv.extend([0.0, 0.0]);
                }
            }
        }
        let out = PyDict::new(py);
        out.set_item("t_hit", PyArray1::from_vec(py, t))?;
        out.set_item("primitive_ids", PyArray1::from_vec(py, ids))?;
        out.set_item("primitive_uvs", PyArray1::from_vec(py, uv).reshape([n, 2])?)?;
        Ok(out)
    }
}

/// Casts validated rays on the calling thread or the pool (the library's
/// parallel batch).
fn cast<BV: BoundingVolume>(
    m: &RsMesh<BV>,
    rays: &[Ray],
    workers: &Workers,
) -> proxima::Result<Vec<Option<TriangleHit>>> {
    if workers.parallel() {
        workers.run(|| m.cast_rays_par(rays))
    } else {
        rays.iter().map(|r| m.cast_ray(r)).collect()
    }
}
