"""proxima.Index: every kind, every query, against numpy brute force."""

from __future__ import annotations

import brute
import numpy as np
import pytest

import proxima

KINDS = ["brute", "loose-kd", "octree", "grid2d", "hashgrid", "grid3d"]


def test_kinds_are_the_six_by_name():
    assert proxima.INDEX_KINDS == KINDS
    for k in KINDS:
        assert proxima.Index(kind=k).kind == k


def scene(rng, n=1500, side=100.0):
    c = rng.uniform(0, side, size=(n, 3))
    r = rng.uniform(0.5, 3.0, size=n)
    # A few large ones, so that every index meets objects larger than its hint.
    r[rng.choice(n, 5, replace=False)] = rng.uniform(10, 25, size=5)
    return c, r


# --- small hand-checked cases ------------------------------------------------


@pytest.mark.parametrize("kind", KINDS)
def test_hand_checked(kind):
    centers = np.array([[0, 0, 0], [2, 0, 0], [10, 0, 0], [10, 3.5, 0]], dtype=float)
    radii = np.array([1.0, 1.0, 2.0, 1.5])
    idx = proxima.Index(centers, radii, kind=kind)
    assert len(idx) == 4 and idx.kind == kind
    assert idx.ids().tolist() == [0, 1, 2, 3]
    # 0 and 1 touch (distance 2 = 1 + 1: closed), 2 and 3 touch (3.5 = 2 + 1.5).
    assert idx.pairs().tolist() == [[0, 1], [2, 3]]
    ids, off = idx.query_spheres([[1, 0, 0, 0], [10, 0, 0, 0.5], [50, 50, 50, 1]])
    assert off.tolist() == [0, 2, 3, 3]
    assert ids.tolist() == [0, 1, 2]
    ids, off = idx.query_boxes([[-5, -1, -1, 2.5, 1, 1], [8.5, 4.5, -1, 9, 6, 1]])
    assert brute.csr_lists(ids, off)[0].tolist() == [0, 1]
    assert brute.csr_lists(ids, off)[1].tolist() == [3]  # corner (9, 4.5, 0) is 1.118 from (10, 3.5, 0)
    # A ray along +x from x = -5 meets 0 at t = 4, 1 at t = 6, 2 at t = 13.
    ids, off, t = idx.query_rays([-5, 0, 0, 1, 0, 0], return_t=True)
    assert ids.tolist() == [0, 1, 2] and t.tolist() == [4.0, 6.0, 13.0]
    ids, off = idx.query_rays([-5, 0, 0, 1, 0, 0], tmax=5.5)
    assert ids.tolist() == [0]
    first, t = idx.ray_first([[-5, 0, 0, 2, 0, 0], [0, 10, 0, 0, 1, 0]])
    assert first.tolist() == [0, -1] and t.tolist() == [2.0, np.inf]
    # Origin inside sphere 2: t = 0.
    ids, _, t = idx.query_rays([10, 0, 0, 0, 0, 1], return_t=True)
    assert ids.tolist() == [2] and t.tolist() == [0.0]


def look_at_perspective(eye, target, fov=1.0, aspect=1.5, near=0.1, far=60.0, gl=False):
    """A right-handed view-projection matrix (glam's look_at_rh and
    perspective_rh, or OpenGL's depth range with gl=True), row-major."""
    eye, target = np.asarray(eye, float), np.asarray(target, float)
    f = target - eye
    f /= np.linalg.norm(f)
    up = np.array([0.0, 0.0, 1.0]) if abs(f[2]) < 0.99 else np.array([0.0, 1.0, 0.0])
    s = np.cross(f, up)
    s /= np.linalg.norm(s)
    u = np.cross(s, f)
    view = np.eye(4)
    view[0, :3], view[1, :3], view[2, :3] = s, u, -f
    view[:3, 3] = -view[:3, :3] @ eye
    h = 1.0 / np.tan(fov / 2)
    proj = np.zeros((4, 4))
    proj[0, 0], proj[1, 1] = h / aspect, h
    if gl:
        proj[2, 2], proj[2, 3] = (far + near) / (near - far), 2 * far * near / (near - far)
    else:
        proj[2, 2], proj[2, 3] = far / (near - far), near * far / (near - far)
    proj[3, 2] = -1.0
    return proj @ view


@pytest.mark.parametrize("kind", KINDS)
def test_frustum_hand_checked(kind):
    # Camera at the origin looking down +x; near 0.1, far 60.
    centers = np.array([[10, 0, 0], [-10, 0, 0], [70, 0, 0], [61, 0, 0], [10, 50, 0]], dtype=float)
    radii = np.array([1.0, 1.0, 1.0, 2.0, 1.0])
    idx = proxima.Index(centers, radii, kind=kind)
    m = look_at_perspective([0, 0, 0], [1, 0, 0])
    ids, off = idx.query_frusta(m)
    assert ids.tolist() == [0, 3]  # in front, and the one reaching over the far plane
    # The same camera with OpenGL's depth range gives the same frustum.
    gl = look_at_perspective([0, 0, 0], [1, 0, 0], gl=True)
    ids, _ = idx.query_frusta(gl, depth="minus_one_to_one")
    assert ids.tolist() == [0, 3]
    # Read as a [0, 1] matrix, the OpenGL one would put its near plane where
    # its z_clip = 0, 2fn/(f+n) = 0.1997 units out: a small sphere at 0.15 is
    # inside the true frustum and culled by the misread one.
    idx2 = proxima.Index([[0.15, 0, 0]], [0.01], kind=kind)
    assert idx2.query_frusta(gl, depth="minus_one_to_one")[0].tolist() == [0]
    assert idx2.query_frusta(gl)[0].tolist() == []


# --- against brute force on random data --------------------------------------


@pytest.mark.parametrize("kind", KINDS)
def test_random_queries_match_brute_force(kind, rng):
    c, r = scene(rng)
    idx = proxima.Index(c, r, kind=kind)
    idx.validate()
    want = brute.pairs(c, r)
    assert len(want) > 400
    got = idx.pairs()
    np.testing.assert_array_equal(got, want)
    unsorted = idx.pairs(sort=False)
    np.testing.assert_array_equal(np.unique(unsorted, axis=0), want)

    m = 300
    sph = np.column_stack([rng.uniform(-10, 110, (m, 3)), rng.uniform(0, 8, m)])
    ids, off = idx.query_spheres(sph)
    assert off.shape == (m + 1,) and off[0] == 0 and off[-1] == len(ids)
    lists = brute.csr_lists(ids, off)
    for q, got in zip(sph, lists):
        np.testing.assert_array_equal(got, brute.sphere_query(c, r, q))
    assert sum(map(len, lists)) > m

    lo = rng.uniform(-10, 100, (m, 3))
    boxes = np.column_stack([lo, lo + rng.uniform(0, 15, (m, 3))])
    ids, off = idx.query_boxes(boxes)
    for q, got in zip(boxes, brute.csr_lists(ids, off)):
        np.testing.assert_array_equal(got, brute.box_query(c, r, q))

    rays = np.column_stack([rng.uniform(-20, 120, (m, 3)), rng.normal(size=(m, 3))])
    tmax = np.where(rng.uniform(size=m) < 0.5, np.inf, rng.uniform(0, 80, m))
    ids, off, t = idx.query_rays(rays, tmax, return_t=True)
    first, first_t = idx.ray_first(rays, tmax)
    hits = 0
    for k, (q, tm) in enumerate(zip(rays, tmax)):
        got, got_t = ids[off[k] : off[k + 1]], t[off[k] : off[k + 1]]
        rows, want_t = brute.ray_query(c, r, q, tm)
        assert sorted(got.tolist()) == rows.tolist()
        hits += len(rows)
        # Ordered along the ray, each t as the oracle's.
        assert np.all(np.diff(got_t) >= 0)
        order = np.argsort(got)
        np.testing.assert_allclose(got_t[order], want_t, rtol=1e-4, atol=1e-4)
        if len(rows):
            assert first_t[k] == got_t[0]
            assert first[k] in got[got_t == got_t[0]]
        else:
            assert first[k] == -1 and first_t[k] == np.inf
    assert hits > m // 4

    seen = 0
    for depth, gl in (("zero_to_one", False), ("minus_one_to_one", True)):
        mats = [
            look_at_perspective(
                rng.uniform(0, 100, 3), rng.uniform(0, 100, 3), far=rng.uniform(20, 80), gl=gl
            )
            for _ in range(30)
        ]
        ids, off = idx.query_frusta(np.array(mats), depth=depth)
        for mat, got in zip(mats, brute.csr_lists(ids, off)):
            kept, unsure = brute.frustum_query(c, r, mat, depth)
            got = set(got.tolist())
            assert set(kept.tolist()) <= got <= set(kept.tolist()) | set(unsure.tolist())
            seen += len(kept)
    assert seen > 60


@pytest.mark.parametrize("kind", KINDS)
def test_long_random_sequence_of_inserts_moves_removes(kind, rng):
    """Insert, move, resize and remove at random; after every round the index
    answers pairs and queries as brute force over the live spheres does."""
    idx = proxima.Index(kind=kind, world=[[0, 0, 0], [60, 60, 60]], r_max=2.0)
    live: dict[int, tuple[np.ndarray, float]] = {}
    next_id = 0
    for rnd in range(25):
        k = int(rng.integers(20, 120))
        c = rng.uniform(-5, 65, (k, 3))
        r = rng.uniform(0.2, 2.5, k)
        if rnd % 3 == 0:
            for i in range(k):
                assert idx.insert(c[i], r[i]) == next_id
                live[next_id] = (c[i], r[i])
                next_id += 1
        else:
            new = idx.insert_many(c, r)
            assert new.tolist() == list(range(next_id, next_id + k))
            for i, h in enumerate(new.tolist()):
                live[h] = (c[i], r[i])
            next_id += k
        ids = np.array(sorted(live))
        # Move a random half (some far outside the world), resize some.
        mv = rng.choice(ids, len(ids) // 2, replace=False)
        to = rng.uniform(-5, 65, (len(mv), 3))
        to[::17] *= 4.0
        if rnd % 2:
            idx.update_many(mv, to)
            for h, p in zip(mv.tolist(), to):
                live[h] = (p, live[h][1])
        else:
            rr = rng.uniform(0.0, 4.0, len(mv))
            idx.update_many(mv, to, rr)
            for h, p, q in zip(mv.tolist(), to, rr):
                live[h] = (p, q)
        h = int(rng.choice(ids))
        idx.update(h, [30.0, 30.0, 30.0], 1.0)
        live[h] = (np.array([30.0, 30.0, 30.0]), 1.0)
        # Remove a third, one by one and in a batch.
        rm = rng.choice(ids, len(ids) // 3, replace=False)
        for h in rm[:5].tolist():
            idx.remove(h)
            del live[h]
        idx.remove_many(rm[5:])
        for h in rm[5:].tolist():
            del live[h]
        idx.validate()
        assert len(idx) == len(live)
        ids = np.array(sorted(live), dtype=np.int64)
        np.testing.assert_array_equal(idx.ids(), ids)
        cc = np.array([live[h][0] for h in ids]).reshape(-1, 3)
        rr = np.array([live[h][1] for h in ids])
        got_c, got_r = idx.spheres()
        np.testing.assert_array_equal(got_c, cc.astype(np.float32))
        np.testing.assert_array_equal(got_r, rr.astype(np.float32))
        want = ids[brute.pairs(cc, rr)] if len(ids) else np.zeros((0, 2), np.int64)
        np.testing.assert_array_equal(idx.pairs(), want)
        q = np.column_stack([rng.uniform(-5, 65, (20, 3)), rng.uniform(0, 10, 20)])
        got = brute.csr_lists(*idx.query_spheres(q))
        for qq, g in zip(q, got):
            np.testing.assert_array_equal(g, ids[brute.sphere_query(cc, rr, qq)])
    assert next_id > 1000
    # Removed ids stay stale; new ones continue after the last.
    idx.clear()
    assert len(idx) == 0 and idx.pairs().shape == (0, 2)
    assert idx.insert([1, 1, 1], 1) == next_id


@pytest.mark.parametrize("kind", KINDS)
def test_workers_give_the_same_answers(kind, rng):
    c, r = scene(rng, n=3000)
    idx = proxima.Index(c, r, kind=kind)
    sph = np.column_stack([rng.uniform(0, 100, (1000, 3)), rng.uniform(0, 5, 1000)])
    rays = np.column_stack([rng.uniform(0, 100, (1000, 3)), rng.normal(size=(1000, 3))])
    one = [idx.pairs(), *idx.query_spheres(sph), *idx.query_rays(rays, 30.0, return_t=True), *idx.ray_first(rays)]
    for w in (2, 3, -1):
        many = [
            idx.pairs(workers=w),
            *idx.query_spheres(sph, workers=w),
            *idx.query_rays(rays, 30.0, return_t=True, workers=w),
            *idx.ray_first(rays, workers=w),
        ]
        for a, b in zip(one, many):
            np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(
        np.unique(idx.pairs(sort=False, workers=2), axis=0), one[0]
    )


def test_ids_follow_rows_and_round_trip(rng):
    c, r = scene(rng, n=50)
    idx = proxima.Index(c, r, kind="loose-kd")
    for i in (0, 17, 49):
        center, radius = idx.get(i)
        np.testing.assert_array_equal(center, c[i].astype(np.float32))
        assert radius == np.float32(r[i])
        assert i in idx
    assert 50 not in idx and -1 not in idx and "x" not in idx
    new = idx.insert([5, 5, 5], 2.0)
    assert new == 50 and new in idx
    idx.remove(3)
    assert 3 not in idx and len(idx) == 50
    sel_c, sel_r = idx.spheres([49, 0])
    np.testing.assert_array_equal(sel_c, c[[49, 0]].astype(np.float32))
    # The CSR ids index the constructor's arrays directly.
    ids, off = idx.query_spheres(np.append(c[10], 0.0))
    assert 10 in ids.tolist()
    assert "Index(kind=\"loose-kd\", len=50)" == repr(idx)
    assert idx.memory_bytes > 0


def test_update_all_with_ids_none(rng):
    c, r = scene(rng, n=400)
    idx = proxima.Index(c, r, kind="grid3d")
    for _ in range(5):
        c = c + rng.normal(scale=2.0, size=c.shape)
        idx.update_many(None, c)
        np.testing.assert_array_equal(idx.pairs(), brute.pairs(c, r))
    r2 = r * 1.5
    idx.update_many(None, c, r2)
    np.testing.assert_array_equal(idx.pairs(), brute.pairs(c, r2))


def test_empty_index_and_empty_batches():
    idx = proxima.Index(kind="octree")
    assert len(idx) == 0 and idx.pairs().shape == (0, 2)
    ids, off = idx.query_spheres(np.zeros((0, 4)))
    assert ids.shape == (0,) and off.tolist() == [0]
    ids, off = idx.query_spheres([1, 2, 3, 4])
    assert ids.shape == (0,) and off.tolist() == [0, 0]
    assert idx.insert_many(np.zeros((0, 3)), np.zeros(0)).shape == (0,)
    first, t = idx.ray_first(np.zeros((0, 6)))
    assert first.shape == (0,) and t.shape == (0,)
    ids, off = idx.query_frusta(np.zeros((0, 4, 4)))
    assert off.tolist() == [0]


def test_dtypes_lists_and_views_are_converted(rng):
    c, r = scene(rng, n=300)
    want = proxima.Index(c.astype(np.float32), r.astype(np.float32)).pairs()
    big = np.zeros((600, 6))
    big[::2, 1:4] = c
    views = [
        c.tolist(),  # nested lists
        np.asfortranarray(c),  # column-major
        big[::2, 1:4],  # strided view
        np.ascontiguousarray(c.T).T,  # transposed view
        c.astype(np.float64),
        np.asarray(c, dtype=np.longdouble),  # wider than float64
    ]
    for v in views:
        got = proxima.Index(v, r[::-1][::-1]).pairs()
        np.testing.assert_array_equal(got, want)
    ints = np.array([[0, 0, 0], [3, 0, 0]], dtype=np.int16)
    assert proxima.Index(ints, np.array([1, 2], dtype=np.uint8)).pairs().tolist() == [[0, 1]]
    ids = np.array([0, 1], dtype=np.uint32)
    idx = proxima.Index(ints, 1.0)
    idx.update_many(ids, [[0, 0, 0], [2, 0, 0]])
    assert idx.pairs().tolist() == [[0, 1]]
