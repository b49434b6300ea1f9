"""Bad input raises the right exception with the library's message, changes
nothing, and never crashes the interpreter."""

from __future__ import annotations

import errno
import os

import numpy as np
import pytest
from test_mesh import SQUARE_F, SQUARE_V

import proxima

NAN, INF = float("nan"), float("inf")


@pytest.fixture
def idx():
    c = np.array([[0, 0, 0], [1, 0, 0], [5, 5, 5]], dtype=float)
    return proxima.Index(c, [1.0, 1.0, 0.5], kind="loose-kd")


def unchanged(idx, before):
    c, r = idx.spheres()
    np.testing.assert_array_equal(c, before[0])
    np.testing.assert_array_equal(r, before[1])
    idx.validate()


# --- Index construction ----------------------------------------------------


def test_unknown_kind_lists_the_known_ones():
    with pytest.raises(ValueError, match="unknown index \"kd\".*loose-kd.*grid3d"):
        proxima.Index(kind="kd")


@pytest.mark.parametrize(
    "centers, radii, message",
    [
        (np.zeros((3, 2)), 1.0, r"centers: expected shape \(N, 3\), got \(3, 2\)"),
        (np.zeros((2, 3, 1)), 1.0, r"centers: expected shape \(N, 3\), got \(2, 3, 1\)"),
        (np.zeros((3, 3)), np.ones(2), r"radii: expected shape a scalar or \(3,\), got \(2,\)"),
        (np.zeros((3, 3)), np.ones((3, 1)), r"radii: expected shape"),
        ([[0, 0, 0], [NAN, 0, 0]], 1.0, r"centers: row 1 has a non-finite value"),
        ([[0, 0, 0], [INF, 0, 0]], 1.0, r"centers: row 1 has a non-finite value"),
        (np.zeros((2, 3)), [1.0, NAN], r"spheres: row 1: sphere radius is not finite"),
        (np.zeros((2, 3)), [1.0, INF], r"spheres: row 1: sphere radius is not finite"),
        (np.zeros((2, 3)), [-1.0, 1.0], r"spheres: row 0: negative radius -1"),
        (np.zeros((2, 3), dtype=complex), 1.0, r"centers: expected real numbers, got an array of dtype complex128"),
        ([["a", "b", "c"]], 1.0, r"centers: expected real numbers"),
        ([[0, 0, 0], [1, 2]], 1.0, r"centers: not an array"),
        (np.array([None, None, None], dtype=object), 1.0, r"centers: expected real numbers"),
        ([[1e39, 0, 0]], 1.0, r"centers: row 0 has a non-finite value"),  # overflows float32
    ],
)
def test_bad_spheres(centers, radii, message):
    with pytest.raises(ValueError, match=message):
        with np.errstate(over="ignore"):
            proxima.Index(centers, radii)


def test_bad_hints():
    with pytest.raises(ValueError, match="give both centers and radii"):
        proxima.Index(np.zeros((2, 3)))
    with pytest.raises(ValueError, match=r"world: expected shape \(2, 3\) or \(6,\)"):
        proxima.Index(world=[0, 0, 0])
    with pytest.raises(ValueError, match="world: AABB min exceeds max"):
        proxima.Index(world=[[1, 1, 1], [0, 0, 0]])
    with pytest.raises(ValueError, match="world: box 0 has a non-finite value"):
        proxima.Index(world=[0, 0, 0, NAN, 1, 1])
    for r in (0.0, -1.0, NAN, INF):
        with pytest.raises(ValueError, match="r_max must be finite and positive"):
            proxima.Index(r_max=r)
    with pytest.raises(TypeError):
        proxima.Index(kind=3)


# --- stale ids and all-or-nothing mutations ----------------------------------


def test_stale_ids_raise_key_error(idx):
    idx.remove(1)
    for call in (
        lambda: idx.remove(1),
        lambda: idx.update(1, [0, 0, 0]),
        lambda: idx.get(1),
        lambda: idx.get(3),  # never issued
        lambda: idx.get(-1),
        lambda: idx.spheres([0, 1]),
        lambda: idx.remove_many([0, 1]),
    ):
        with pytest.raises(KeyError, match="id -?[13] is not in the index"):
            call()
    assert len(idx) == 2 and 0 in idx
    idx.clear()
    with pytest.raises(KeyError):
        idx.get(0)
    with pytest.raises(OverflowError):
        idx.get(2**70)


def test_failed_batches_change_nothing(idx):
    before = idx.spheres()
    with pytest.raises(KeyError, match="id 7"):
        idx.update_many([0, 7], [[9, 9, 9], [9, 9, 9]])
    with pytest.raises(ValueError, match="spheres: row 1: negative radius"):
        idx.update_many([0, 2], [[9, 9, 9], [9, 9, 9]], [1.0, -2.0])
    with pytest.raises(ValueError, match="centers: row 1 has a non-finite value"):
        idx.update_many([0, 2], [[9, 9, 9], [NAN, 9, 9]])
    with pytest.raises(ValueError, match="2 ids but 1 centers"):
        idx.update_many([0, 2], [[9, 9, 9]])
    with pytest.raises(ValueError, match="ids: expected integers, got an array of dtype float64"):
        idx.update_many([0.0, 2.0], [[9, 9, 9], [9, 9, 9]])
    with pytest.raises(KeyError, match="appears twice"):
        idx.remove_many([0, 2, 0])
    with pytest.raises(KeyError):
        idx.remove_many([0, 5])
    unchanged(idx, before)
    with pytest.raises(ValueError, match="spheres: row 1: negative radius"):
        idx.insert_many([[0, 0, 0], [1, 1, 1]], [1.0, -1.0])
    with pytest.raises(ValueError, match="insert takes one sphere"):
        idx.insert([[0, 0, 0], [1, 1, 1]], 1.0)
    with pytest.raises(ValueError, match="row 0: sphere radius is not finite"):
        idx.insert([0, 0, 0], NAN)
    unchanged(idx, before)
    assert len(idx) == 3
    # The next id is still 3: failed inserts take none.
    assert idx.insert([0, 0, 0], 1.0) == 3


# --- queries -----------------------------------------------------------------


def test_bad_queries(idx):
    cases = [
        (lambda: idx.query_spheres(np.zeros((2, 3))), r"spheres: expected shape \(N, 4\)"),
        (lambda: idx.query_spheres([0, 0, 0, -1]), r"spheres: row 0: negative radius -1"),
        (lambda: idx.query_spheres([[0, 0, 0, 1], [0, NAN, 0, 1]]), r"spheres: row 1: sphere centre is not finite"),
        (lambda: idx.query_boxes([1, 1, 1, 0, 0, 0]), r"boxes: row 0: AABB min exceeds max"),
        (lambda: idx.query_boxes([0, 0, 0, NAN, 1, 1]), r"boxes: row 0: AABB"),
        (lambda: idx.query_rays([0, 0, 0, 0, 0, 0]), r"rays: row 0: direction has zero length"),
        (lambda: idx.query_rays([0, 0, 0, NAN, 0, 1]), r"rays: row 0 has a non-finite value"),
        (lambda: idx.query_rays([0, 0, 0, 1, 0, 0], -1.0), r"rays: row 0: ray max_t is negative or NaN"),
        (lambda: idx.query_rays([0, 0, 0, 1, 0, 0], NAN), r"rays: row 0: ray max_t is negative or NaN"),
        (lambda: idx.query_rays(np.zeros((2, 6)) + [0, 0, 0, 1, 0, 0], [1.0]), r"tmax: expected shape a scalar or \(2,\)"),
        (lambda: idx.ray_first([0, 0, 0, 0, 0, 0]), r"rays: row 0: direction has zero length"),
        (lambda: idx.query_frusta(np.zeros((2, 4))), r"matrices: expected shape \(M, 4, 4\) or \(4, 4\)"),
        (lambda: idx.query_frusta(np.full((4, 4), NAN)), r"matrices: matrix 0 has a non-finite value"),
        (lambda: idx.query_frusta(np.eye(4), depth="gl"), r"depth must be"),
        (lambda: idx.pairs(workers=0), r"workers must be 1, a larger count, or -1"),
        (lambda: idx.query_spheres([0, 0, 0, 1], workers=-2), r"workers must be"),
    ]
    before = idx.spheres()
    for k, (call, message) in enumerate(cases):
        with pytest.raises(ValueError, match=message):
            call()
            pytest.fail(f"case {k} did not raise")
    unchanged(idx, before)


# --- meshes ------------------------------------------------------------------


def test_bad_meshes():
    cases = [
        ((SQUARE_V, SQUARE_F.astype(float)), r"faces: expected integers, got an array of dtype float64"),
        ((SQUARE_V, SQUARE_F[:, :2]), r"faces: expected shape \(F, 3\), got \(2, 2\)"),
        ((SQUARE_V, [[0, 1, 4]]), r"invalid mesh: triangle 0 uses vertex 4, but the mesh has 4 vertices"),
        ((SQUARE_V, [[0, 1, -1]]), r"faces: row 0 has vertex index -1"),
        ((SQUARE_V, [[0, 1, 2**40]]), r"faces: row 0 has vertex index"),
        ((SQUARE_V, np.zeros((0, 3), dtype=int)), r"invalid mesh: mesh has no triangles"),
        ((SQUARE_V[:, :2], SQUARE_F), r"vertices: expected shape \(N, 3\)"),
        ((np.where(SQUARE_V == 1, NAN, SQUARE_V), SQUARE_F), r"vertices: row 1 has a non-finite value"),
        ((SQUARE_V, np.array([[0, 1, 2]], dtype=np.uint64) + 2**63), r"faces: value 9223372036854775808 is too large"),
    ]
    for (v, f), message in cases:
        with pytest.raises(ValueError, match=message):
            proxima.Mesh(v, f)
    with pytest.raises(ValueError, match="unknown bv \"box\""):
        proxima.Mesh(SQUARE_V, SQUARE_F, bv="box")
    with pytest.raises(ValueError, match="split must be"):
        proxima.Mesh(SQUARE_V, SQUARE_F, split="best")
    with pytest.raises(ValueError, match="leaf_size must be at least 1"):
        proxima.Mesh(SQUARE_V, SQUARE_F, leaf_size=0)
    with pytest.raises(OverflowError):
        proxima.Mesh(SQUARE_V, SQUARE_F, leaf_size=-1)
    m = proxima.Mesh(SQUARE_V, SQUARE_F)
    with pytest.raises(ValueError, match="invalid mesh: .*4"):
        m.set_vertices(SQUARE_V[:3])
    bad = SQUARE_V.copy()
    bad[2, 1] = INF
    with pytest.raises(ValueError, match="vertices: row 2 has a non-finite value"):
        m.set_vertices(bad)
    np.testing.assert_array_equal(m.vertices, SQUARE_V)


def test_unreadable_files(tmp_path):
    missing = tmp_path / "missing.obj"
    with pytest.raises(FileNotFoundError) as e:
        proxima.Mesh.load(missing)
    assert e.value.errno == errno.ENOENT and e.value.filename == str(missing)
    assert "No such file or directory" in str(e.value)
    with pytest.raises(IsADirectoryError):
        proxima.Mesh.load(tmp_path)
    if os.geteuid() != 0:  # root reads anything
        locked = tmp_path / "locked.obj"
        locked.write_text("v 0 0 0\n")
        locked.chmod(0)
        with pytest.raises(PermissionError):
            proxima.Mesh.load(locked)


def test_malformed_files(tmp_path):
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n")
    with pytest.raises(ValueError, match=r"bad\.obj: line 4: .*9"):
        proxima.Mesh.load(bad)
    nan = tmp_path / "nan.obj"
    nan.write_text("v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n")
    with pytest.raises(ValueError, match=r"nan\.obj: line 2"):
        proxima.Mesh.load(nan)
    stl = tmp_path / "short.stl"
    stl.write_bytes(b"\0" * 80 + (5).to_bytes(4, "little") + b"\0" * 20)
    with pytest.raises(ValueError, match=r"short\.stl: byte offset"):
        proxima.Mesh.load(stl)
    unknown = tmp_path / "mesh.xyz"
    unknown.write_bytes(b"\x01\x02garbage")
    with pytest.raises(ValueError, match=r"mesh\.xyz: unknown mesh format"):
        proxima.Mesh.load(unknown)
    with pytest.raises(TypeError):
        proxima.Mesh.load(3)


# --- collide and ray casts ---------------------------------------------------


def test_bad_poses():
    m = proxima.Mesh(SQUARE_V, SQUARE_F)
    scaled = np.diag([2.0, 2.0, 2.0, 1.0])
    mirror = np.diag([-1.0, 1.0, 1.0, 1.0])
    batch = np.stack([np.eye(4)] * 3)
    batch[2, 0, 1] = 0.5  # shear
    cases = [
        (scaled, r"poses: pose 0: invalid pose: matrix is not a rotation"),
        (mirror, r"poses: pose 0: invalid pose: matrix is not a rotation .*det = -1"),
        (batch, r"poses: pose 2: invalid pose"),
        (np.full((4, 4), NAN), r"poses: pose 0 has a non-finite value"),
        (np.eye(4)[:2], r"poses: expected shape \(N, 4, 4\), \(N, 3, 4\), \(4, 4\) or \(3, 4\), got \(2, 4\)"),
        (np.eye(3), r"poses: expected shape"),
        (np.ones((4, 4)), r"poses: pose 0: the last row is"),
        ("not a pose", r"poses: expected real numbers"),
    ]
    for poses, message in cases:
        with pytest.raises(ValueError, match=message):
            proxima.collide(m, m, poses)
    with pytest.raises(ValueError, match="rotation must be"):
        proxima.collide(m, m, np.eye(4), rotation="fast")
    with pytest.raises(ValueError, match="workers must be"):
        proxima.collide(m, m, np.eye(4), workers=0)
    obb = proxima.Mesh(SQUARE_V, SQUARE_F, bv="obb")
    with pytest.raises(ValueError, match=r"both meshes need the same bv, but a has \"kdop18\" and b has \"obb\""):
        proxima.collide(m, obb, np.eye(4))
    with pytest.raises(TypeError):
        proxima.collide(m, "mesh", np.eye(4))
    with pytest.raises(ValueError, match=r"pose: invalid pose: matrix is not a rotation"):
        m.cast_rays([0, 0, 1, 0, 0, -1], pose=scaled)
    with pytest.raises(ValueError, match=r"pose: one \(4, 4\) or \(3, 4\) pose"):
        m.cast_rays([0, 0, 1, 0, 0, -1], pose=batch)
    with pytest.raises(ValueError, match=r"rays: row 0: direction has zero length"):
        m.cast_rays([0, 0, 1, 0, 0, 0])


def test_garbage_never_crashes(rng):
    """Every entry point fed junk of many shapes and dtypes: only the documented
    exceptions, and the interpreter survives (this test finishing is the check)."""
    idx = proxima.Index(np.zeros((3, 3)), 1.0)
    mesh = proxima.Mesh(SQUARE_V, SQUARE_F)
    junk = [
        None, 3, 2.5, "abc", b"xy", [], [[]], [[1, 2], [3]], {}, object(),
        np.zeros(0), np.zeros((0, 0)), np.zeros((2, 0)), np.zeros((1, 1, 1, 1)),
        np.zeros((5, 3), dtype=bool), np.zeros((4, 4), dtype=np.float16),
        np.arange(12).reshape(4, 3)[::-1], np.zeros((3, 6), dtype="U3"),
        np.array([1 + 2j]), np.full((2, 6), NAN), np.full((2, 4), INF),
        np.zeros((3, 4, 4)), np.zeros((3, 3, 4)),
        rng.normal(size=(7, 6)), rng.normal(size=(7, 4)), rng.normal(size=(2, 4, 4)),
    ]
    calls = [
        lambda x: proxima.Index(x, 1.0),
        lambda x: proxima.Index(np.zeros((2, 3)), x),
        lambda x: proxima.Index(world=x),
        idx.query_spheres, idx.query_boxes, idx.query_rays, idx.ray_first, idx.query_frusta,
        lambda x: idx.query_rays([0, 0, 0, 1, 0, 0], x),
        lambda x: idx.update_many(x, np.zeros((1, 3))),
        lambda x: idx.update_many(None, x),
        idx.remove_many, idx.spheres, lambda x: idx.insert(x, 1.0),
        lambda x: proxima.Mesh(x, SQUARE_F), lambda x: proxima.Mesh(SQUARE_V, x),
        lambda x: proxima.collide(mesh, mesh, x), mesh.cast_rays,
        lambda x: mesh.cast_rays([0, 0, 1, 0, 0, -1], pose=x), mesh.set_vertices,
    ]
    raised = 0
    for call in calls:
        for x in junk:
            try:
                call(x)
            except (ValueError, TypeError, KeyError, OverflowError):
                raised += 1
    assert raised > len(calls) * len(junk) // 2
    idx.validate()
    assert len(idx) == 3
