"""proxima.Index: k nearest (nearest), sphere sweeps (sweep) and collision
filters, every kind, against numpy brute force."""

from __future__ import annotations

import brute
import numpy as np
import pytest

import proxima

KINDS = ["brute", "loose-kd", "octree", "grid2d", "hashgrid", "grid3d"]
ALL = 0xFFFFFFFF


def scene(rng, n=1200, side=100.0):
    c = rng.uniform(0, side, size=(n, 3))
    r = rng.uniform(0.2, 2.5, size=n)
    r[rng.choice(n, 4, replace=False)] = rng.uniform(10, 20, size=4)
    return c, r


def check_knn(idx, c, r, pts, k, admit=None, **kw):
    """idx.nearest on every point equals the oracle exactly (distances bit for
    bit, ids in (distance, id) order, padding)."""
    d, ids = idx.nearest(pts, k, **kw)
    if k == 1:
        assert d.shape == ids.shape == (len(pts),)
        d, ids = d[:, None], ids[:, None]
    else:
        assert d.shape == ids.shape == (len(pts), k)
    assert d.dtype == np.float32 and ids.dtype == np.int64
    oracle_kw = {
        "bound": kw.get("distance_upper_bound", np.inf),
        "metric": kw.get("metric", "surface"),
        "admit": admit,
    }
    for i, p in enumerate(pts):
        wd, wi = brute.knn(c, r, p, k, **oracle_kw)
        np.testing.assert_array_equal(d[i], wd, err_msg=f"point {i}")
        np.testing.assert_array_equal(ids[i], wi, err_msg=f"point {i}")
    return d, ids


# --- nearest ----------------------------------------------------------------


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("k", [1, 8, 64])
@pytest.mark.parametrize("metric", ["surface", "center"])
def test_nearest_matches_brute_force(kind, k, metric, rng):
    c, r = scene(rng)
    idx = proxima.Index(c, r, kind=kind)
    # Points inside the scene, on its border and well outside it.
    pts = np.concatenate([rng.uniform(-10, 110, (60, 3)), rng.uniform(-400, 500, (10, 3))])
    d, _ = check_knn(idx, c, r, pts, k, metric=metric)
    assert np.isfinite(d).all()
    if metric == "surface":
        assert (d[:, 0] == 0).any(), "some points lie inside a sphere"


@pytest.mark.parametrize("kind", KINDS)
def test_nearest_bound_far_points_and_k_above_n(kind, rng):
    c, r = scene(rng, n=300)
    idx = proxima.Index(c, r, kind=kind)
    pts = rng.uniform(-10, 110, (40, 3))
    for bound in (0.0, 1.0, 4.0, 15.0):
        d, ids = check_knn(idx, c, r, pts, 8, distance_upper_bound=bound)
        assert ((ids == -1) == np.isinf(d)).all()
        assert (d[np.isfinite(d)] <= bound).all()
    d, _ = check_knn(idx, c, r, pts, 8, distance_upper_bound=4.0, metric="center")
    assert np.isinf(d).any() and np.isfinite(d).any(), "the bound must cut some rows short"
    # Far away: still the k nearest (the search keeps growing).
    far = np.array([[1e6, -2e6, 3e5], [-1e7, 0, 0]])
    check_knn(idx, c, r, far, 5)
    d, ids = idx.nearest(far, 5, distance_upper_bound=1e3)
    assert (ids == -1).all() and np.isinf(d).all()
    # k > n: every object, then padding.
    d, ids = check_knn(idx, c, r, pts[:5], 350)
    assert (ids[:, :300] >= 0).all() and (ids[:, 300:] == -1).all()
    assert np.isinf(d[:, 300:]).all()
    assert sorted(ids[0, :300].tolist()) == list(range(300))


@pytest.mark.parametrize("kind", KINDS)
def test_nearest_ties_go_to_the_smaller_id(kind):
    # A lattice of points (radius 0): many objects at exactly equal distances.
    g = np.arange(5, dtype=float)
    c = np.stack(np.meshgrid(g, g, g, indexing="ij"), axis=-1).reshape(-1, 3)
    r = np.zeros(len(c))
    idx = proxima.Index(c, r, kind=kind)
    pts = np.array([[2, 2, 2], [2.5, 2.5, 2.5], [0, 0, 0], [2.5, 2, 2], [4.5, 4.5, 4.5]])
    for k in (1, 2, 7, 9, 27, 30):
        check_knn(idx, c, r, pts, k)
    # The centre of a cell: 8 corners at one distance, 4 of them asked for.
    d, ids = idx.nearest([[2.5, 2.5, 2.5]], 4)
    assert np.unique(d).size == 1
    corners = brute.knn(c, r, [2.5, 2.5, 2.5], 8)[1]
    assert ids[0].tolist() == sorted(corners.tolist())[:4]


@pytest.mark.parametrize("kind", KINDS)
def test_nearest_ties_after_removals_and_reinserts(kind, rng):
    # Removing and re-inserting reuses slots, so the library's handle order is
    # no longer id order: ties must still go to the smaller id.
    g = np.arange(4, dtype=float)
    lattice = np.stack(np.meshgrid(g, g, g, indexing="ij"), axis=-1).reshape(-1, 3)
    idx = proxima.Index(lattice, 0.0, kind=kind)
    c, r = list(lattice), [0.0] * len(lattice)
    alive = np.ones(len(lattice), bool)
    for _ in range(3):
        gone = rng.choice(np.nonzero(alive)[0], 10, replace=False)
        idx.remove_many(gone)
        alive[gone] = False
        pts = lattice[rng.choice(len(lattice), 10, replace=False)]
        new = idx.insert_many(pts, 0.0)
        assert new.tolist() == list(range(len(c), len(c) + 10))
        c += list(pts)
        r += [0.0] * 10
        alive = np.concatenate([alive, np.ones(10, bool)])
    c, r = np.array(c), np.array(r)
    qs = np.concatenate([lattice, lattice[:20] + 0.5])
    for k in (1, 3, 8):
        for w in (1, 2):
            d, ids = idx.nearest(qs, k, workers=w)
            d, ids = d.reshape(len(qs), k), ids.reshape(len(qs), k)
            for i, p in enumerate(qs):
                wd, wi = brute.knn(c, r, p, k, admit=alive)
                np.testing.assert_array_equal(d[i], wd)
                np.testing.assert_array_equal(ids[i], wi)


@pytest.mark.parametrize("kind", KINDS)
def test_nearest_after_moves_and_clear(kind, rng):
    c, r = scene(rng, n=400)
    idx = proxima.Index(c, r, kind=kind)
    c2 = c + rng.normal(0, 5, c.shape)
    idx.update_many(None, c2)
    pts = rng.uniform(0, 100, (30, 3))
    check_knn(idx, c2, r, pts, 6)
    idx.clear()
    d, ids = idx.nearest(pts, 3)
    assert (ids == -1).all() and np.isinf(d).all()
    # New ids continue after the cleared ones, and rank by id.
    new = idx.insert_many(c[:50], r[:50])
    d, ids = idx.nearest(pts, 4)
    for i, p in enumerate(pts):
        wd, wi = brute.knn(c[:50], r[:50], p, 4)
        np.testing.assert_array_equal(d[i], wd)
        np.testing.assert_array_equal(ids[i], np.where(wi >= 0, new[0] + wi, -1))


@pytest.mark.parametrize("kind", KINDS)
def test_nearest_empty_index_and_empty_batch(kind):
    idx = proxima.Index(kind=kind, world=[[0, 0, 0], [10, 10, 10]], r_max=1.0)
    d, ids = idx.nearest([[1, 2, 3], [4, 5, 6]], 3)
    assert d.shape == (2, 3) and np.isinf(d).all() and (ids == -1).all()
    d, ids = idx.nearest(np.zeros((0, 3)), 3)
    assert d.shape == ids.shape == (0, 3)
    d, ids = idx.nearest(np.zeros((0, 3)))
    assert d.shape == ids.shape == (0,)
    d, i = idx.nearest([1, 2, 3])
    assert d == np.inf and i == -1


def test_nearest_shapes_follow_ckdtree(rng):
    c = rng.uniform(0, 10, (50, 3))
    idx = proxima.Index(c, 0.0)
    d, i = idx.nearest(c[7])  # one point, k=1: scalars
    assert np.ndim(d) == 0 and np.ndim(i) == 0 and int(i) == 7 and float(d) == 0.0
    d, i = idx.nearest(c[7], 3)  # one point: (k,)
    assert d.shape == i.shape == (3,) and i[0] == 7
    d, i = idx.nearest(c[:5])  # k=1: (M,)
    assert d.shape == (5,) and i.tolist() == [0, 1, 2, 3, 4]
    d, i = idx.nearest(c[:5], 2)  # (M, k)
    assert d.shape == i.shape == (5, 2)
    d, i = idx.nearest(c[:5].tolist(), k=1)  # lists too
    assert i.tolist() == [0, 1, 2, 3, 4]


@pytest.mark.parametrize("kind", KINDS)
def test_nearest_workers_give_the_same_answers(kind, rng):
    c, r = scene(rng, n=2000)
    idx = proxima.Index(c, r, kind=kind)
    pts = rng.uniform(-5, 105, (700, 3))
    for k in (1, 10):
        one = idx.nearest(pts, k, metric="center", distance_upper_bound=12.0)
        for w in (2, -1):
            got = idx.nearest(pts, k, metric="center", distance_upper_bound=12.0, workers=w)
            np.testing.assert_array_equal(got[0], one[0])
            np.testing.assert_array_equal(got[1], one[1])


# --- sweeps -----------------------------------------------------------------


def random_sweeps(rng, m, lo=-10, hi=110, length=30.0):
    a = rng.uniform(lo, hi, (m, 3))
    b = a + rng.normal(0, length, (m, 3))
    return a, b


@pytest.mark.parametrize("kind", KINDS)
def test_sweeps_match_brute_force(kind, rng):
    c, r = scene(rng, n=800)
    idx = proxima.Index(c, r, kind=kind)
    a, b = random_sweeps(rng, 120)
    radii = rng.uniform(0, 3, 120)
    radii[:10] = 0.0  # segments
    b[10:15] = a[10:15]  # spheres at rest
    first, tf = idx.sweep(a, b, radii)
    ids, off, t = idx.sweep(a, b, radii, all=True)
    assert first.dtype == ids.dtype == np.int64 and tf.dtype == t.dtype == np.float32
    lists = brute.csr_lists(ids, off)
    ts = brute.csr_lists(t, off)
    hits = 0
    for i in range(len(a)):
        want_t, sure = brute.sweep(c, r, a[i], b[i], radii[i])
        got = lists[i]
        hits += len(got)
        # Every sure hit is reported, no sure miss is.
        must = set(np.nonzero(sure & np.isfinite(want_t))[0].tolist())
        never = set(np.nonzero(sure & np.isinf(want_t))[0].tolist())
        assert must <= set(got.tolist()), f"sweep {i}"
        assert not (never & set(got.tolist())), f"sweep {i}"
        assert len(set(got.tolist())) == len(got)
        # Each hit's time, and the order by (t, id).
        ok = np.isfinite(want_t[got])
        np.testing.assert_allclose(ts[i][ok], want_t[got][ok], atol=2e-4)
        assert all((ts[i][j], got[j]) < (ts[i][j + 1], got[j + 1]) for j in range(len(got) - 1))
        # The first hit is the all-hits list's first.
        if len(got):
            assert (first[i], tf[i]) == (got[0], ts[i][0])
        else:
            assert first[i] == -1 and tf[i] == np.inf
    assert hits > 50 and (first == -1).any()


@pytest.mark.parametrize("kind", KINDS)
def test_sweep_hand_checked(kind):
    c = np.array([[0, 0, 0], [10, 0, 0], [10, 0, 0], [20, 5, 0]], float)
    r = np.array([1.0, 1.0, 1.0, 1.0])
    idx = proxima.Index(c, r, kind=kind)
    # Along x from -10 to 30 with radius 1: touches 0 at x = -2 (t = 0.2), 1
    # and 2 (equal spheres) at x = 8 (t = 0.45); 3 is 5 off the line (> 2).
    first, t = idx.sweep([-10, 0, 0], [30, 0, 0], 1.0)
    assert first.tolist() == [0] and t.tolist() == [pytest.approx(0.2)]
    ids, off, t = idx.sweep([[-10, 0, 0]], [[30, 0, 0]], [1.0], all=True)
    assert ids.tolist() == [0, 1, 2] and off.tolist() == [0, 3]
    assert t.tolist() == [pytest.approx(0.2), pytest.approx(0.45), pytest.approx(0.45)]
    # From x = 5 the tie at t = 0.15 goes to the smaller id.
    first, t = idx.sweep([5, 0, 0], [25, 0, 0], 1.0)
    assert first.tolist() == [1] and t[0] == pytest.approx(0.15)
    # Starting inside: t = 0; at rest and missing: -1, inf; radius 0 segment.
    first, t = idx.sweep([[0.5, 0, 0], [50, 50, 50], [20, 0, 0]], [[9, 9, 9], [50, 50, 50], [20, 10, 0]], 0.0)
    assert first.tolist() == [0, -1, 3] and t[0] == 0 and t[1] == np.inf
    assert t[2] == pytest.approx(0.4)


@pytest.mark.parametrize("kind", KINDS)
def test_sweep_ties_after_reinserts(kind):
    idx = proxima.Index(np.array([[0, 0, 0], [10, 0, 0]], float), 1.0, kind=kind)
    idx.remove(0)
    twin = idx.insert([10, 0, 0], 1.0)  # reuses slot 0: a smaller handle
    assert twin == 2
    first, t = idx.sweep([0, 0, 0], [20, 0, 0], 0.0)
    assert first.tolist() == [1] and t[0] == pytest.approx(0.45)


@pytest.mark.parametrize("kind", KINDS)
def test_sweep_workers(kind, rng):
    c, r = scene(rng, n=1000)
    idx = proxima.Index(c, r, kind=kind)
    a, b = random_sweeps(rng, 600)
    for all_ in (False, True):
        one = idx.sweep(a, b, 0.5, all=all_)
        two = idx.sweep(a, b, 0.5, all=all_, workers=2)
        for x, y in zip(one, two):
            np.testing.assert_array_equal(x, y)


# --- filters ----------------------------------------------------------------


@pytest.mark.parametrize("kind", KINDS)
def test_filters_on_pairs_and_every_query(kind, rng):
    n = 900
    c, r = scene(rng, n=n)
    group = rng.choice([1, 2, 4, 3, 6], n)
    mask = rng.choice([1, 2, 4, 7, 5], n)
    idx = proxima.Index(c, r, kind=kind, group=group, mask=mask)
    assert idx.filter(5) == (group[5], mask[5])
    # pairs(): only interacting pairs.
    want = brute.pairs(c, r)
    keep = brute.interacts(group[want[:, 0]], mask[want[:, 0]], group[want[:, 1]], mask[want[:, 1]])
    got = idx.pairs()
    np.testing.assert_array_equal(got, want[keep])
    assert 0 < keep.sum() < len(want)
    for qg, qm in [(1, 1), (2, 7), (4, 2), (0, ALL), (ALL, ALL)]:
        admit = brute.interacts(group, mask, qg, qm)
        f = (qg, qm)
        sph = np.column_stack([rng.uniform(0, 100, (40, 3)), rng.uniform(1, 10, 40)])
        ids, off = idx.query_spheres(sph, filter=f)
        for i, q in enumerate(sph):
            w = brute.sphere_query(c, r, q)
            assert brute.csr_lists(ids, off)[i].tolist() == w[admit[w]].tolist()
        boxes = np.column_stack([(lo := rng.uniform(0, 90, (40, 3))), lo + rng.uniform(1, 20, (40, 3))])
        ids, off = idx.query_boxes(boxes, filter=f)
        for i, q in enumerate(boxes):
            w = brute.box_query(c, r, q)
            assert brute.csr_lists(ids, off)[i].tolist() == w[admit[w]].tolist()
        rays = np.column_stack([rng.uniform(0, 100, (40, 3)), rng.normal(size=(40, 3))])
        ids, off = idx.query_rays(rays, 40.0, filter=f)
        first, _ = idx.ray_first(rays, 40.0, filter=f)
        for i, q in enumerate(rays):
            w, _ = brute.ray_query(c, r, q, 40.0)
            got = brute.csr_lists(ids, off)[i]
            assert sorted(got.tolist()) == w[admit[w]].tolist()
            assert first[i] == (got[0] if len(got) else -1)
        pts = rng.uniform(0, 100, (30, 3))
        check_knn(idx, c, r, pts, 6, filter=f, admit=admit)
        a, b = random_sweeps(rng, 30)
        ids, off, _ = idx.sweep(a, b, 1.0, all=True, filter=f)
        first, _ = idx.sweep(a, b, 1.0, filter=f)
        unf, uoff, _ = idx.sweep(a, b, 1.0, all=True)
        for i in range(30):
            u = brute.csr_lists(unf, uoff)[i]
            got = brute.csr_lists(ids, off)[i]
            assert got.tolist() == u[admit[u]].tolist()
            assert first[i] == (got[0] if len(got) else -1)
        m = idx.query_frusta(np.eye(4), filter=f)
        assert set(m[0].tolist()) <= set(np.nonzero(admit)[0].tolist())
    # Inert objects (group 0) are in no pair and found by no filtered query.
    idx.set_filter(np.arange(n), group=0, mask=ALL)
    assert len(idx.pairs()) == 0
    assert idx.nearest(c[:3], 2, filter=(ALL, ALL))[1].tolist() == [[-1, -1]] * 3
    check_knn(idx, c, r, c[:3], 2)  # unfiltered: every object


def test_filters_insert_and_set_filter():
    idx = proxima.Index(kind="loose-kd", world=[[0, 0, 0], [10, 10, 10]], r_max=1.0)
    a = idx.insert([1, 1, 1], 1.0, group=1, mask=2)
    b = idx.insert([2, 1, 1], 1.0, group=2, mask=1)
    cs = idx.insert_many([[1, 2, 1], [2, 2, 1]], 1.0, group=[4, 4], mask=4)
    assert idx.filter(a) == (1, 2) and idx.filter(cs[1]) == (4, 4)
    assert idx.pairs().tolist() == [[a, b], [cs[0], cs[1]]]
    idx.set_filter(b, group=1, mask=2)
    assert idx.pairs().tolist() == [[cs[0], cs[1]]]
    idx.set_filter([a, b], group=[ALL, ALL], mask=[ALL, ALL])
    assert len(idx.pairs()) == 6
    assert idx.filter(b) == (ALL, ALL)
    with pytest.raises(KeyError):
        idx.set_filter([a, 99], group=1, mask=1)
    assert idx.filter(a) == (ALL, ALL), "all or nothing"
    with pytest.raises(ValueError, match="group"):
        idx.set_filter(a, group=-1, mask=1)
    with pytest.raises(ValueError, match="mask"):
        idx.insert([1, 1, 1], 1.0, mask=2**32)
    with pytest.raises(ValueError, match="group"):
        proxima.Index([[0, 0, 0], [1, 1, 1]], 1.0, group=[1, 2, 3])
    with pytest.raises(ValueError, match="group"):
        proxima.Index([[0, 0, 0]], 1.0, group=[1.5])
    assert len(idx) == 4


# --- bad input ----------------------------------------------------------------


@pytest.fixture
def idx(rng):
    c, r = scene(rng, n=100)
    return proxima.Index(c, r)


@pytest.mark.parametrize(
    "call, exc, message",
    [
        (lambda i: i.nearest([[0, 0]]), ValueError, r"points: expected shape \(M, 3\)"),
        (lambda i: i.nearest(np.zeros((2, 3, 1))), ValueError, "points"),
        (lambda i: i.nearest([[0, np.nan, 0]]), ValueError, "points: row 0 has a non-finite"),
        (lambda i: i.nearest([[0, 0, 0], [0, np.inf, 0]]), ValueError, "row 1"),
        (lambda i: i.nearest(np.array([["a", "b", "c"]])), ValueError, "real numbers"),
        (lambda i: i.nearest(np.zeros((1, 3), complex)), ValueError, "real numbers"),
        (lambda i: i.nearest("xyz"), ValueError, "points"),
        (lambda i: i.nearest([[0, 0, 0]], 0), ValueError, "k must be >= 1"),
        (lambda i: i.nearest([[0, 0, 0]], -3), ValueError, "k must be >= 1"),
        (lambda i: i.nearest([[0, 0, 0]], 1.5), TypeError, "k"),
        (lambda i: i.nearest([[0, 0, 0]], metric="manhattan"), ValueError, "metric"),
        (lambda i: i.nearest([[0, 0, 0]], distance_upper_bound=np.nan), ValueError, "distance_upper_bound"),
        (lambda i: i.nearest([[0, 0, 0]], distance_upper_bound=-1), ValueError, "distance_upper_bound"),
        (lambda i: i.nearest([[0, 0, 0]], filter=(1,)), ValueError, "filter"),
        (lambda i: i.nearest([[0, 0, 0]], filter=(1, -1)), ValueError, "mask"),
        (lambda i: i.nearest([[0, 0, 0]], filter="all"), ValueError, "filter"),
        (lambda i: i.nearest([[0, 0, 0]], workers=0), ValueError, "workers"),
        # An answer too large to allocate: a Python error, not an abort.
        (lambda i: i.nearest([[0, 0, 0]], 2**62), MemoryError, "does not fit in memory"),
        (lambda i: i.nearest(np.zeros((4, 3)), 2**59), MemoryError, "4 x 576460752303423488"),
        # No overflow, but more than isize::MAX bytes: the reservation fails.
        (lambda i: i.nearest(np.zeros((4, 3)), 2**58), MemoryError, "4 x 288230376151711744"),
        (lambda i: i.sweep([[0, 0, 0]], [[1, 1, 1], [2, 2, 2]]), ValueError, "1 starts but 2 ends"),
        (lambda i: i.sweep([[0, 0, 0]], [[1, 1]]), ValueError, "ends"),
        (lambda i: i.sweep([[0, 0, np.nan]], [[1, 1, 1]]), ValueError, "starts: row 0"),
        (lambda i: i.sweep([[0, 0, 0]], [[1, 1, 1]], -1.0), ValueError, "sweeps: row 0"),
        (lambda i: i.sweep([[0, 0, 0]], [[1, 1, 1]], [1.0, 2.0]), ValueError, "radii"),
        (lambda i: i.sweep([[0, 0, 0]], [[1, 1, 1]], np.nan), ValueError, "sweeps: row 0"),
        (lambda i: i.sweep([[0, 0, 0]], [[1, 1, 1]], filter=(1, 2, 3)), ValueError, "filter"),
        (lambda i: i.query_spheres([0, 0, 0, 1], filter=(2**32, 1)), ValueError, "group"),
        (lambda i: i.ray_first([0, 0, 0, 1, 0, 0], filter=[1]), ValueError, "filter"),
    ],
)
def test_bad_inputs_raise(idx, call, exc, message):
    before = (len(idx), idx.pairs().tolist())
    with pytest.raises(exc, match=message):
        call(idx)
    assert (len(idx), idx.pairs().tolist()) == before
    idx.validate()


def test_nearest_batches_over_many_blocks_and_large_k(rng):
    """One worker stages rows a block at a time (4096 rows at k = 10, 204 at
    k = 200, 40960 at k = 1) or, for a small batch or a large k, writes them
    in place: every way, each row is the oracle's, and two workers agree."""
    c, r = scene(rng, n=600)
    idx = proxima.Index(c, r, kind="octree")
    for m, k in [(9000, 10), (500, 200), (40, 3000), (10, 10), (45000, 1)]:
        pts = rng.uniform(-10, 110, (m, 3))
        d, ids = check_knn(idx, c, r, pts, k)
        d2, ids2 = idx.nearest(pts, k, workers=2)
        np.testing.assert_array_equal(d2.reshape(d.shape), d)
        np.testing.assert_array_equal(ids2.reshape(ids.shape), ids)


def test_read_only_and_misaligned_points(idx, rng):
    """Points over 1024 values are read in place: a read-only array is read
    as it is, a misaligned one (float64 or float32, large or small; these
    were refused as "not contiguous or misaligned") through a copy; each
    answers as a plain copy."""
    pts = rng.uniform(0, 100, (2000, 3))
    want = idx.nearest(pts.copy(), 3)
    frozen = pts.copy()
    frozen.flags.writeable = False

    def misaligned(a):
        raw = np.zeros(a.nbytes + 1, np.uint8)
        odd = np.frombuffer(raw.data, dtype=a.dtype, count=a.size, offset=1).reshape(a.shape)
        odd[:] = a
        assert not odd.flags.aligned and odd.flags.c_contiguous
        return odd

    for got in (idx.nearest(frozen, 3), idx.nearest(misaligned(pts), 3)):
        np.testing.assert_array_equal(got[0], want[0])
        np.testing.assert_array_equal(got[1], want[1])
    few = pts[:5]
    want = idx.nearest(few, 3)
    # Not an ndarray: a buffer at an odd offset, which numpy wraps misaligned.
    raw = b"\0" + few.tobytes()
    view = memoryview(raw)[1:].cast("d", list(few.shape))
    assert not np.asarray(view).flags.aligned
    for got in (idx.nearest(misaligned(few), 3), idx.nearest(view, 3)):
        np.testing.assert_array_equal(got[0], want[0])
        np.testing.assert_array_equal(got[1], want[1])
    want = idx.nearest(few.astype(np.float32), 3)
    for got in (idx.nearest(misaligned(few.astype(np.float32)), 3),):
        np.testing.assert_array_equal(got[0], want[0])
        np.testing.assert_array_equal(got[1], want[1])


def test_non_contiguous_and_other_dtypes(idx, rng):
    pts = rng.uniform(0, 100, (40, 6))
    view = pts[::2, 1:4]  # strided, non-contiguous
    assert not view.flags.c_contiguous
    want = idx.nearest(np.ascontiguousarray(view), 4)
    for got in (idx.nearest(view, 4), idx.nearest(np.asfortranarray(view), 4),
                idx.nearest(view.astype(np.float32), 4), idx.nearest(view.tolist(), 4)):
        np.testing.assert_array_equal(got[0], want[0])
        np.testing.assert_array_equal(got[1], want[1])
    ints = np.array([[1, 2, 3], [50, 50, 50]], dtype=np.int16)
    np.testing.assert_array_equal(idx.nearest(ints, 2)[1], idx.nearest(ints.astype(float), 2)[1])
    s = idx.sweep(pts[::2, :3], pts[::2, 3:], 0.5, all=True)
    t = idx.sweep(np.ascontiguousarray(pts[::2, :3]), np.ascontiguousarray(pts[::2, 3:]), 0.5, all=True)
    for x, y in zip(s, t):
        np.testing.assert_array_equal(x, y)


@pytest.mark.filterwarnings("ignore:overflow encountered in cast:RuntimeWarning")
def test_garbage_never_crashes(idx, rng):
    junk = [None, 3, "x", [], [[]], [[1, 2, 3, 4]], np.zeros((0,)), np.full((2, 3), np.nan),
            np.zeros((3, 3), dtype=object), {"a": 1}, np.zeros((2, 3), bool), 1e40]
    for a in junk:
        for call in (lambda: idx.nearest(a, 2), lambda: idx.sweep(a, a, 1.0),
                     lambda: idx.sweep(a, a, 1.0, all=True), lambda: idx.nearest([0, 0, 0], a),
                     lambda: idx.query_spheres([1, 1, 1, 1], filter=a)):
            try:
                call()
            except (ValueError, TypeError, OverflowError):
                pass
    idx.validate()
