//! numpy in: every array argument goes through here, so that shapes, dtypes,
//! non-contiguous views, lists and NaN are handled in one place. Inputs are
//! copied into Rust vectors while the interpreter is held; the work that follows
//! may release it without any Python object being read concurrently.

use crate::errors::OrRaise;
use numpy::{PyArrayDescrMethods, PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use proxima::broad::Filter;
use proxima::geom::{Aabb, Frustum, Ray};
use proxima::glam::{Affine3A, Mat3A, Mat4, Vec3, Vec3A, Vec4};
use pyo3::exceptions::{PyMemoryError, PyValueError};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;

/// How far the last row of a 4×4 pose may be from `(0, 0, 0, 1)`.
const AFFINE_ROW_TOLERANCE: f32 = 1e-5;

/// `numpy.asarray(obj)` (a no-op for an array; an aligned copy of a
/// misaligned one), any failure as a `ValueError` naming the argument.
fn as_ndarray<'py>(obj: &Bound<'py, PyAny>, what: &str) -> PyResult<Bound<'py, PyAny>> {
    let a = if obj.is_instance_of::<numpy::PyUntypedArray>() {
        obj.clone()
    } else {
        asarray(obj.py())?
            .call1((obj,))
            .map_err(|e| PyValueError::new_err(format!("{what}: not an array ({e})")))?
    };
    // A misaligned array (a buffer read at an odd offset, as an ndarray or
    // wrapped by `asarray` without a copy) cannot be read as a slice: an
    // aligned copy can (`ndarray.copy`).
    match a.cast::<numpy::PyUntypedArray>() {
        Ok(u) if !u.is_aligned() => a
            .call_method0("copy")
            .map_err(|e| PyValueError::new_err(format!("{what}: cannot copy ({e})"))),
        _ => Ok(a),
    }
}

/// The dtype kind character of an array (`b'f'`, `b'i'`, ...).
fn kind(array: &Bound<'_, PyAny>) -> PyResult<u8> {
    let array = array.cast::<numpy::PyUntypedArray>()?;
    Ok(array.dtype().kind())
}

/// `numpy.asarray(array, dtype, order="C")`: a C-contiguous copy of a view,
/// converted to `dtype` (unlike `ascontiguousarray`, a 0-d array stays 0-d).
fn contiguous<'py>(array: &Bound<'py, PyAny>, dtype: &str) -> PyResult<Bound<'py, PyAny>> {
    let py = array.py();
    let f = asarray(py)?;
    f.call1((array, dtype, "C"))
}

/// `numpy.asarray`, looked up once.
fn asarray(py: Python<'_>) -> PyResult<&Bound<'_, PyAny>> {
    static ASARRAY: PyOnceLock<Py<PyAny>> = PyOnceLock::new();
    ASARRAY
        .get_or_try_init(py, || {
            py.import("numpy")?.getattr("asarray").map(Bound::unbind)
        })
        .map(|f| f.bind(py))
}

/// From this many values on, [`f32_values`] reads a float64 array in place.
const IN_PLACE_MIN: usize = 1024;

/// A numeric array of any real dtype (bool, integers, floats; not complex,
/// object or strings) as its shape and its values rounded to `f32`, C order.
pub fn f32_values(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<(Vec<usize>, Vec<f32>)> {
    let a = as_ndarray(obj, what)?;
    if !matches!(kind(&a)?, b'b' | b'i' | b'u' | b'f') {
        let dtype = a.cast::<numpy::PyUntypedArray>()?.dtype();
        return Err(PyValueError::new_err(format!(
            "{what}: expected real numbers, got an array of dtype {dtype}"
        )));
    }
    let err = |e| PyValueError::new_err(format!("{what}: {e}"));
    // numpy's default float64, C order (a pose, a row of points): rounded
    // here as numpy's cast would (to nearest), without the `asarray` call and
    // the temporary array that cost a one-pose `collide` ~0.8 µs (perf).
    // Large arrays are read in place (a borrow, not `to_vec`'s copy: 100k
    // points were a 2.4 MB temporary, its page faults and a `memmove`); one
    // borrowed mutably elsewhere is copied. Small ones (a pose, a point) are
    // copied: the borrow's bookkeeping does not pay there.
    if let Ok(x) = a.cast::<PyArrayDyn<f64>>() {
        if x.is_c_contiguous() {
            let round = |values: &[f64]| values.iter().map(|&v| v as f32).collect();
            if x.len() >= IN_PLACE_MIN {
                if let Ok(r) = x.try_readonly() {
                    if let Ok(values) = r.as_slice() {
                        return Ok((x.shape().to_vec(), round(values)));
                    }
                }
            }
            return Ok((x.shape().to_vec(), round(&x.to_vec().map_err(err)?)));
        }
    }
    let a = match a.cast::<PyArrayDyn<f32>>() {
        Ok(x) if x.is_c_contiguous() => x.clone(),
        _ => contiguous(&a, "float32")?.cast_into::<PyArrayDyn<f32>>()?,
    };
    let shape = a.shape().to_vec();
    let values = a.to_vec().map_err(err)?;
    Ok((shape, values))
}

/// An integer array (any integer dtype) as its shape and `i64` values. Floats
/// are refused (a float index is a mistake, not a conversion).
pub fn i64_values(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<(Vec<usize>, Vec<i64>)> {
    let a = as_ndarray(obj, what)?;
    match kind(&a)? {
        b'i' => {}
        b'u' => {
            // uint64 values above i64::MAX would wrap: refuse them here.
            let (shape, v) = u64_values(&a, what)?;
            let v = v
                .into_iter()
                .map(|x| i64::try_from(x).map_err(|_| too_large(what, x)))
                .collect::<PyResult<_>>()?;
            return Ok((shape, v));
        }
        _ => {
            let dtype = a.cast::<numpy::PyUntypedArray>()?.dtype();
            return Err(PyValueError::new_err(format!(
                "{what}: expected integers, got an array of dtype {dtype}"
            )));
        }
    }
    let a = match a.cast::<PyArrayDyn<i64>>() {
        Ok(x) if x.is_c_contiguous() => x.clone(),
        _ => contiguous(&a, "int64")?.cast_into::<PyArrayDyn<i64>>()?,
    };
    let shape = a.shape().to_vec();
    let values = a
        .to_vec()
        .map_err(|e| PyValueError::new_err(format!("{what}: {e}")))?;
    Ok((shape, values))
}

fn u64_values(a: &Bound<'_, PyAny>, what: &str) -> PyResult<(Vec<usize>, Vec<u64>)> {
    let a = contiguous(a, "uint64")?.cast_into::<PyArrayDyn<u64>>()?;
    let shape = a.shape().to_vec();
    let values = a
        .to_vec()
        .map_err(|e| PyValueError::new_err(format!("{what}: {e}")))?;
    Ok((shape, values))
}

fn too_large(what: &str, x: u64) -> PyErr {
    PyValueError::new_err(format!("{what}: value {x} is too large"))
}

/// Rows of `cols` numbers: an `(n, cols)` array, or one row as a `(cols,)`
/// array (`n = 1`); a 1-D array of size 0 is zero rows. Returns the values row
/// by row and `n`.
pub fn rows(obj: &Bound<'_, PyAny>, cols: usize, what: &str) -> PyResult<(Vec<f32>, usize)> {
    let (shape, v) = f32_values(obj, what)?;
    match shape[..] {
        [n, c] if c == cols => Ok((v, n)),
        [c] if c == cols => Ok((v, 1)),
        [0] => Ok((v, 0)),
        _ => Err(shape_error(what, &format!("(N, {cols})"), &shape)),
    }
}

/// [`rows`], refusing NaN and ±∞ (naming the row).
pub fn finite_rows(obj: &Bound<'_, PyAny>, cols: usize, what: &str) -> PyResult<(Vec<f32>, usize)> {
    let (v, n) = rows(obj, cols, what)?;
    check_finite(&v, cols, what, "row")?;
    Ok((v, n))
}

/// Fails on the first non-finite value, naming its item (`unit` `i`: the
/// `i`-th group of `size` values, a row, a matrix, a pose).
pub fn check_finite(v: &[f32], size: usize, what: &str, unit: &str) -> PyResult<()> {
    match v.iter().position(|x| !x.is_finite()) {
        None => Ok(()),
        Some(i) => Err(PyValueError::new_err(format!(
            "{what}: {unit} {} has a non-finite value ({})",
            i / size.max(1),
            v[i]
        ))),
    }
}

/// `n` values: a `(n,)` array, or a scalar repeated `n` times.
pub fn per_row(obj: &Bound<'_, PyAny>, n: usize, what: &str) -> PyResult<Vec<f32>> {
    let (shape, v) = f32_values(obj, what)?;
    match shape[..] {
        [] => Ok(vec![v[0]; n]),
        [m] if m == n => Ok(v),
        _ => Err(shape_error(what, &format!("a scalar or ({n},)"), &shape)),
    }
}

/// A 1-D integer array (or one integer) as `i64`s.
pub fn int_list(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<i64>> {
    let (shape, v) = i64_values(obj, what)?;
    match shape[..] {
        [] | [_] => Ok(v),
        _ => Err(shape_error(what, "(N,)", &shape)),
    }
}

/// Whether an answer of `rows` rows of `cols` entries, `bytes` bytes an
/// entry, can be allocated: `MemoryError` naming `what` if its size
/// overflows or the allocator refuses it (as numpy's own arrays would),
/// rather than let the answer's allocation abort the interpreter (Rust's
/// infallible allocation aborts on failure). A probe: reserved and released
/// at once, never written, so it costs no page of memory. It checks the
/// answer only, not the smaller working tables beside it, and an allocator
/// that overcommits may still grant what the machine cannot hold.
pub fn check_answer_size(what: &str, rows: usize, cols: usize, bytes: usize) -> PyResult<()> {
    let too_large = || {
        PyMemoryError::new_err(format!(
            "{what}: an answer of {rows} x {cols} entries does not fit in memory"
        ))
    };
    let n = rows
        .checked_mul(cols)
        .and_then(|n| n.checked_mul(bytes))
        .ok_or_else(too_large)?;
    Vec::<u8>::new()
        .try_reserve_exact(n)
        .map_err(|_| too_large())
}

/// The `ValueError` for an array of the wrong shape.
pub fn shape_error(what: &str, want: &str, got: &[usize]) -> PyErr {
    let got: Vec<String> = got.iter().map(|d| d.to_string()).collect();
    let got = match got.len() {
        1 => format!("({},)", got[0]),
        _ => format!("({})", got.join(", ")),
    };
    PyValueError::new_err(format!("{what}: expected shape {want}, got {got}"))
}

/// The first three values as a vector.
pub fn vec3(v: &[f32]) -> Vec3 {
    Vec3::new(v[0], v[1], v[2])
}

/// 4×4 matrices, row-major as numpy writes them (`m[i, j]` is row `i`, column
/// `j`): an `(M, 4, 4)` array or one `(4, 4)`. Returns them and whether one
/// matrix was given.
pub fn matrices4(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<(Vec<Mat4>, bool)> {
    let (shape, v) = f32_values(obj, what)?;
    let single = match shape[..] {
        [4, 4] => true,
        [_, 4, 4] => false,
        _ => return Err(shape_error(what, "(M, 4, 4) or (4, 4)", &shape)),
    };
    check_finite(&v, 16, what, "matrix")?;
    let m = v
        .chunks_exact(16)
        .map(|r| Mat4::from_cols_slice(r).transpose())
        .collect();
    Ok((m, single))
}

/// Rigid poses: `(N, 4, 4)` or `(N, 3, 4)` row-major `[R | t]` matrices, or a
/// single `(4, 4)` / `(3, 3 + 1)`. The last row of a 4×4 must be `(0, 0, 0, 1)`.
/// Finite values are checked here; rigidity is checked by the library (its
/// `check_pose`). Returns the poses and whether one pose was given.
pub fn poses(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<(Vec<Affine3A>, bool)> {
    let (shape, v) = f32_values(obj, what)?;
    let (rows, single) = match shape[..] {
        [r @ (3 | 4), 4] => (r, true),
        [_, r @ (3 | 4), 4] => (r, false),
        _ => {
            return Err(shape_error(
                what,
                "(N, 4, 4), (N, 3, 4), (4, 4) or (3, 4)",
                &shape,
            ))
        }
    };
    let size = rows * 4;
    check_finite(&v, size, what, "pose")?;
    v.chunks_exact(size)
        .enumerate()
        .map(|(i, m)| {
            if rows == 4 {
                let last = [m[12], m[13], m[14], m[15] - 1.0];
                if last.iter().any(|x| x.abs() > AFFINE_ROW_TOLERANCE) {
                    return Err(PyValueError::new_err(format!(
                        "{what}: pose {i}: the last row is {:?}, not (0, 0, 0, 1)",
                        &m[12..16]
                    )));
                }
            }
            let r = Mat3A::from_cols(
                Vec3A::new(m[0], m[4], m[8]),
                Vec3A::new(m[1], m[5], m[9]),
                Vec3A::new(m[2], m[6], m[10]),
            );
            Ok(Affine3A {
                matrix3: r,
                translation: Vec3A::new(m[3], m[7], m[11]),
            })
        })
        .collect::<PyResult<Vec<_>>>()
        .map(|p| (p, single))
}

/// Rays from `(m, 6)` rows (origin, direction) and `tmax` (a scalar or `(m,)`;
/// `None`: unbounded).
pub fn rays(rays: &Bound<'_, PyAny>, tmax: Option<&Bound<'_, PyAny>>) -> PyResult<Vec<Ray>> {
    let (v, m) = finite_rows(rays, 6, "rays")?;
    let t = match tmax {
        Some(t) => per_row(t, m, "tmax")?,
        None => vec![f32::INFINITY; m],
    };
    let out: Vec<Ray> = v
        .chunks_exact(6)
        .zip(t)
        .map(|(r, t)| Ray::with_max_t(vec3(&r[..3]), vec3(&r[3..]), t))
        .collect();
    for (i, r) in out.iter().enumerate() {
        r.validate().or_raise_at(|| format!("rays: row {i}"))?;
    }
    Ok(out)
}

/// View frusta from `(M, 4, 4)` (or one `(4, 4)`) view-projection matrices,
/// row-major, acting on column vectors; `depth` is the projection's clip-space
/// depth range: "zero_to_one" (Direct3D, Vulkan, Metal, wgpu, glam) or
/// "minus_one_to_one" (OpenGL). Each is checked, naming the first bad one.
pub fn frusta(matrices: &Bound<'_, PyAny>, depth: &str) -> PyResult<Vec<Frustum>> {
    // OpenGL's -w <= z <= w becomes 0 <= z' <= w with z' = (z + w) / 2.
    let to_zero_one = match depth {
        "zero_to_one" => Mat4::IDENTITY,
        "minus_one_to_one" => Mat4::from_cols(
            Vec4::X,
            Vec4::Y,
            Vec4::new(0.0, 0.0, 0.5, 0.0),
            Vec4::new(0.0, 0.0, 0.5, 1.0),
        ),
        d => {
            return Err(PyValueError::new_err(format!(
                "depth must be \"zero_to_one\" or \"minus_one_to_one\", got {d:?}"
            )))
        }
    };
    let (ms, _) = matrices4(matrices, "matrices")?;
    ms.into_iter()
        .enumerate()
        .map(|(i, m)| {
            Frustum::from_view_projection(to_zero_one * m)
                .or_raise_at(|| format!("matrices: matrix {i}"))
        })
        .collect()
}

/// A box from `(2, 3)` (`[min, max]`) or `(6,)` numbers, finite and not
/// inverted.
pub fn aabb(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Aabb> {
    let (shape, v) = f32_values(obj, what)?;
    if !matches!(shape[..], [2, 3] | [6]) {
        return Err(shape_error(what, "(2, 3) or (6,)", &shape));
    }
    check_finite(&v, 6, what, "box")?;
    let b = Aabb::new(vec3(&v[..3]), vec3(&v[3..]));
    b.validate().or_raise_at(|| what.into())?;
    Ok(b)
}

/// One filter field (`what`: "group" or "mask") as a 32-bit set.
fn bits(x: i64, what: &str) -> PyResult<u32> {
    u32::try_from(x).map_err(|_| {
        PyValueError::new_err(format!(
            "{what} must be an integer in 0..2**32 (a bit set), got {x}"
        ))
    })
}

/// A `group=` / `mask=` pair as a filter: each an integer in `0..2^32`.
pub fn filter(group: i64, mask: i64) -> PyResult<Filter> {
    Ok(Filter::new(bits(group, "group")?, bits(mask, "mask")?))
}

/// A query's `filter=` argument: `None` (every object) or a `(group, mask)`
/// pair of integers in `0..2^32`.
pub fn query_filter(obj: Option<&Bound<'_, PyAny>>) -> PyResult<Option<Filter>> {
    let Some(obj) = obj.filter(|o| !o.is_none()) else {
        return Ok(None);
    };
    let (group, mask): (i64, i64) = obj.extract().map_err(|_| {
        PyValueError::new_err(format!(
            "filter must be None or a (group, mask) pair of integers, got {}",
            obj.repr().map_or_else(|_| "?".into(), |r| r.to_string())
        ))
    })?;
    filter(group, mask).map(Some)
}

/// Per-object filters for `n` objects from `group=` and `mask=` arguments,
/// each `None` (every bit), one integer, or an `(n,)` integer array.
pub fn filters(
    group: Option<&Bound<'_, PyAny>>,
    mask: Option<&Bound<'_, PyAny>>,
    n: usize,
) -> PyResult<Vec<Filter>> {
    let field = |obj: Option<&Bound<'_, PyAny>>, what: &str| -> PyResult<Vec<u32>> {
        let Some(obj) = obj.filter(|o| !o.is_none()) else {
            return Ok(vec![u32::MAX; n]);
        };
        let (shape, v) = i64_values(obj, what)?;
        let v = v
            .into_iter()
            .map(|x| bits(x, what))
            .collect::<PyResult<Vec<u32>>>()?;
        match shape[..] {
            [] => Ok(vec![v[0]; n]),
            [m] if m == n => Ok(v),
            _ => Err(shape_error(what, &format!("an integer or ({n},)"), &shape)),
        }
    };
    let (g, m) = (field(group, "group")?, field(mask, "mask")?);
    Ok(g.into_iter()
        .zip(m)
        .map(|(g, m)| Filter::new(g, m))
        .collect())
}
