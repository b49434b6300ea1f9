//! `proxima.collide`: mesh–mesh collision for one pose or a batch of poses, and
//! its result, `proxima.Contacts`.

use crate::arrays;
use crate::errors::OrRaise;
use crate::mesh::{AnyMesh, Mesh};
use crate::workers::Workers;
use numpy::ndarray::{ArrayD, IxDyn};
use numpy::{Element, IntoPyArray, PyArray1, PyArray2, PyArrayDyn, PyArrayMethods};
use proxima::glam::Affine3A;
use proxima::narrow::{
    check_pose, BoundingVolume, Collider, CostCounters, Mesh as RsMesh, RotationUpdate,
};
use pyo3::exceptions::{PyIndexError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::PySlice;
use rayon::prelude::*;
use std::any::Any;
use std::cell::RefCell;
use std::sync::{Mutex, PoisonError};

/// One pose's answer: its triangle pairs (all, or the first) and counters.
type PoseResult = (Vec<(u32, u32)>, CostCounters);

thread_local! {
    /// This thread's colliders, at most one per bounding volume, kept between
    /// calls: a new collider sizes its caches to the meshes on its first query
    /// (filling every entry; for rob × env ~2/3 of a first-contact call), a
    /// kept one starts a query in O(1). Each holds scratch space for the
    /// largest meshes it has met, until the thread ends.
    static COLLIDERS: RefCell<Vec<Box<dyn Any>>> = const { RefCell::new(Vec::new()) };
}

/// `f` with this thread's collider for `BV` (see [`COLLIDERS`]), set to
/// `rotation`; a new collider if this thread's is in use (re-entered).
fn with_collider<BV: BoundingVolume + 'static, R>(
    rotation: RotationUpdate,
    f: impl FnOnce(&mut Collider<BV>) -> R,
) -> R {
    COLLIDERS.with(|cell| {
        let Ok(mut kept) = cell.try_borrow_mut() else {
            return f(&mut Collider::new(rotation));
        };
        let i = match kept.iter().position(|c| c.is::<Collider<BV>>()) {
            Some(i) => i,
            None => {
                kept.push(Box::new(Collider::<BV>::new(rotation)));
                kept.len() - 1
            }
        };
        match kept[i].downcast_mut::<Collider<BV>>() {
            Some(c) => {
                c.rotation = rotation;
                f(c)
            }
            None => f(&mut Collider::new(rotation)),
        }
    })
}

/// Every pose of a batch (poses validated), on the calling thread or on the
/// pool, each thread with its kept collider ([`with_collider`]).
fn run<BV: BoundingVolume + 'static>(
    a: &RsMesh<BV>,
    b: &RsMesh<BV>,
    poses: &[Affine3A],
    first: bool,
    rotation: RotationUpdate,
    workers: &Workers,
) -> proxima::Result<Vec<PoseResult>> {
    let one = |c: &mut Collider<BV>, pose: &Affine3A| -> proxima::Result<PoseResult> {
        if first {
            let f = c.first_contact(a, pose, b)?;
            Ok((f.pair.into_iter().collect(), f.counters))
        } else {
            let all = c.all_pairs(a, pose, b)?;
            Ok((all.pairs, all.counters))
        }
    };
    if workers.parallel() {
        workers.run(|| {
            poses
                .par_iter()
                // A pose costs tens of microseconds: a few per task.
                .with_min_len(4)
                .map(|p| with_collider(rotation, |c| one(c, p)))
                .collect()
        })
    } else {
        with_collider(rotation, |c| poses.iter().map(|p| one(c, p)).collect())
    }
}

/// Row `i` (negative: from the end) of a CSR result: the view
/// `rows[offsets[i]:offsets[i+1]]`; `IndexError` naming `what` out of range.
pub fn csr_row<'py>(
    offsets: &Bound<'py, PyArray1<i64>>,
    rows: &Bound<'py, PyArray2<i64>>,
    i: isize,
    what: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let off = offsets.readonly();
    let off = off.as_slice()?;
    let n = off.len() as isize - 1;
    let k = if i < 0 { i + n } else { i };
    if !(0..n).contains(&k) {
        return Err(PyIndexError::new_err(format!(
            "{what} {i} out of range ({n} {what}s)"
        )));
    }
    let (s, e) = (off[k as usize] as isize, off[k as usize + 1] as isize);
    rows.get_item(PySlice::new(rows.py(), s, e, 1))
}

/// A `rotation=` argument: "auto", "refit" or "conservative" (how
/// axis-aligned volumes follow a rotated pose).
pub fn rotation_update(name: &str) -> PyResult<RotationUpdate> {
    match name {
        "auto" => Ok(RotationUpdate::Auto),
        "refit" => Ok(RotationUpdate::Refit),
        "conservative" => Ok(RotationUpdate::Conservative),
        r => Err(PyValueError::new_err(format!(
            "rotation must be \"auto\", \"refit\" or \"conservative\", got {r:?}"
        ))),
    }
}

/// The answer of `collide` for N poses (N = 1 for a single pose).
///
/// - `pairs` (K, 2) int64: every intersecting triangle pair (triangle of `a`,
///   triangle of `b`), pose after pose; with `first=True` at most one per pose;
/// - `offsets` (N + 1,) int64: pose i's pairs are
///   `pairs[offsets[i]:offsets[i+1]]` (also `contacts[i]`);
/// - `colliding` (N,) bool: whether pose i has an intersecting pair;
/// - `counters` (N, 3) uint64: the cost counters of each query, columns
///   (nv: bounding-volume pair tests, np: triangle pair tests, nu: volume
///   updates for the pose).
///
/// `len(contacts)` is N; `bool(contacts)` is whether any pose collides.
///
/// The arrays are made on first access (the same objects afterwards): a
/// one-pose call whose answer is only tested for truth makes none.
#[pyclass(module = "proxima", name = "Contacts", frozen)]
pub struct Contacts {
    /// N, the number of poses.
    poses: usize,
    /// K, the number of pairs.
    n_pairs: usize,
    pairs: LazyArray<i64>,
    offsets: LazyArray<i64>,
    colliding: LazyArray<bool>,
    counters: LazyArray<u64>,
}

/// An array of a [`Contacts`], made from the query's values on first access:
/// making, and later freeing, the four arrays (and two reshape views) of a
/// one-pose answer cost ~1 µs per call (perf, rob × env first contact: a
/// fifth of the call).
struct LazyArray<T> {
    /// The values and the array's shape (stored inline: no allocation),
    /// until the array is made.
    pending: Mutex<Option<(Vec<T>, IxDyn)>>,
    array: PyOnceLock<Py<PyAny>>,
}

impl<T: Element> LazyArray<T> {
    fn new(values: Vec<T>, shape: &[usize]) -> Self {
        LazyArray {
            pending: Mutex::new(Some((values, IxDyn(shape)))),
            array: PyOnceLock::new(),
        }
    }

    /// The array (its values moved in, not copied), made on the first call.
    fn get<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.array
            .get_or_try_init(py, || {
                let pending = self
                    .pending
                    .lock()
                    .unwrap_or_else(PoisonError::into_inner)
                    .take();
                let (values, shape) = pending
                    .ok_or_else(|| PyRuntimeError::new_err("Contacts: an array was lost"))?;
                let a = ArrayD::from_shape_vec(shape, values)
                    .map_err(|e| PyRuntimeError::new_err(format!("Contacts: {e}")))?;
                Ok(a.into_pyarray(py).into_any().unbind())
            })
            .map(|a| a.bind(py).clone())
    }

    /// `f` of the values: the query's, or the array's once made (the caller
    /// may have written to it).
    fn read<R>(&self, py: Python<'_>, f: impl FnOnce(&[T]) -> R) -> PyResult<R> {
        if let Some((values, _)) = &*self.pending.lock().unwrap_or_else(PoisonError::into_inner) {
            return Ok(f(values));
        }
        let array = self.get(py)?;
        let array = array.cast::<PyArrayDyn<T>>()?.try_readonly()?;
        Ok(f(array.as_slice()?))
    }
}

#[pymethods]
impl Contacts {
    /// (K, 2) int64: the intersecting triangle pairs, pose after pose.
    #[getter]
    fn pairs<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.pairs.get(py)
    }

    /// (N + 1,) int64: pose i's pairs are `pairs[offsets[i]:offsets[i+1]]`.
    #[getter]
    fn offsets<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.offsets.get(py)
    }

    /// (N,) bool: whether pose i has an intersecting pair.
    #[getter]
    fn colliding<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.colliding.get(py)
    }

    /// (N, 3) uint64: the cost counters (nv, np, nu) of each query.
    #[getter]
    fn counters<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.counters.get(py)
    }

    fn __len__(&self) -> usize {
        self.poses
    }

    fn __bool__(&self, py: Python<'_>) -> PyResult<bool> {
        self.colliding.read(py, |c| c.iter().any(|&c| c))
    }

    /// The (K_i, 2) triangle pairs of pose `i` (a view of `pairs`).
    fn __getitem__<'py>(&self, py: Python<'py>, i: isize) -> PyResult<Bound<'py, PyAny>> {
        let (offsets, pairs) = (self.offsets.get(py)?, self.pairs.get(py)?);
        csr_row(offsets.cast()?, pairs.cast()?, i, "pose")
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let c = self
            .colliding
            .read(py, |c| c.iter().filter(|&&c| c).count())?;
        Ok(format!(
            "Contacts(poses={}, colliding={c}, pairs={})",
            self.poses, self.n_pairs
        ))
    }
}

/// collide(a, b, poses, *, first=False, rotation="auto", workers=1)
///
/// Which triangles of mesh `a`, moved by each pose, intersect which triangles
/// of mesh `b` (at the identity), exactly (closed triangle–triangle test).
/// `poses`: one rigid pose, (4, 4) or (3, 4) `[R | t]`, or a batch (N, 4, 4)
/// or (N, 3, 4); for two world poses pass `inv(pose_b) @ pose_a`. With
/// `first=True` each query stops at its first intersecting pair (a yes/no
/// answer, cheaper). `rotation` ("auto", "refit", "conservative") chooses how
/// axis-aligned volumes follow a rotation. `workers`: 1 (this thread), n (a
/// pool of n threads) or -1 (one per core). Runs with the interpreter
/// released. Returns a `Contacts`.
///
/// Raises ValueError on a wrong shape, a non-finite value, a pose that is not
/// rigid (|RᵀR - I| > 1e-3 or det <= 0; naming the pose), or meshes with
/// different bounding volumes. All poses are checked before any work.
#[pyfunction]
#[pyo3(signature = (a, b, poses, *, first=false, rotation="auto", workers=1))]
pub fn collide(
    py: Python<'_>,
    a: PyRef<'_, Mesh>,
    b: PyRef<'_, Mesh>,
    poses: &Bound<'_, PyAny>,
    first: bool,
    rotation: &str,
    workers: i64,
) -> PyResult<Contacts> {
    let rotation = rotation_update(rotation)?;
    let (poses, _) = arrays::poses(poses, "poses")?;
    for (i, p) in poses.iter().enumerate() {
        check_pose(p).or_raise_at(|| format!("poses: pose {i}"))?;
    }
    let workers = Workers::new(workers)?;
    let (ma, mb) = (&a.inner, &b.inner);
    let results = py
        .detach(|| {
            // Same volume on both sides; other combinations are refused below.
            macro_rules! pair {
                ($($v:ident),+) => {
                    match (ma, mb) {
                        $((AnyMesh::$v(x), AnyMesh::$v(y)) => Some(run(&**x, &**y, &poses, first, rotation, &workers)),)+
                        _ => None,
                    }
                };
            }
            pair!(Aabb, Kdop14, Kdop18, Kdop26, Obb, Sphere)
        })
        .ok_or_else(|| {
            PyValueError::new_err(format!(
                "both meshes need the same bv, but a has {:?} and b has {:?}",
                ma.bv(),
                mb.bv()
            ))
        })?
        .or_raise()?;
    Ok(contacts(results))
}

// issue #15: `distance(a, b, poses, *, workers=1)` -> distances (N,) and the
// closest points (N, 2, 3) over the meshes' distance queries goes beside
// `collide` here, with the same pose handling, once `narrow/distance` lands.

/// Packs per-pose results into the values of a [`Contacts`].
fn contacts(results: Vec<PoseResult>) -> Contacts {
    let n = results.len();
    let k: usize = results.iter().map(|r| r.0.len()).sum();
    let mut pairs = Vec::with_capacity(2 * k);
    let mut offsets = Vec::with_capacity(n + 1);
    let mut colliding = Vec::with_capacity(n);
    let mut counters = Vec::with_capacity(3 * n);
    offsets.push(0i64);
    for (p, c) in results {
        colliding.push(!p.is_empty());
        pairs.extend(p.iter().flat_map(|&(i, j)| [i64::from(i), i64::from(j)]));
        offsets.push((pairs.len() / 2) as i64);
        counters.extend([c.nv, c.np, c.nu]);
    }
    Contacts {
        poses: n,
        n_pairs: k,
        pairs: LazyArray::new(pairs, &[k, 2]),
        offsets: LazyArray::new(offsets, &[n + 1]),
        colliding: LazyArray::new(colliding, &[n]),
        counters: LazyArray::new(counters, &[n, 3]),
    }
}
