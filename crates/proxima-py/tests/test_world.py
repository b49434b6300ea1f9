"""proxima.World: hand-checked scenes, long random sequences against a brute-force
world (every object pair, every primitive pair, numpy), coherence and workers
in lockstep, shared meshes, and bad input leaving the world unchanged."""

from __future__ import annotations

import brute
import numpy as np
import pytest
from test_gil import released_during
from test_mesh import BVS, SQUARE_F, SQUARE_V, soup

import proxima

ALL = 0xFFFFFFFF
TET_V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=float)
TET_F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])


def moved(t, rot=None):
    p = np.eye(4)
    if rot is not None:
        p[:3, :3] = rot
    p[:3, 3] = t
    return p


def as_dict(c):
    """{(a, b): [(ta, tb), ...]} from a WorldContacts."""
    return {tuple(p): [tuple(t) for t in c[k].tolist()] for k, p in enumerate(c.pairs.tolist())}


# --- hand-checked scenes -----------------------------------------------------


def test_two_tetrahedra_share_one_mesh():
    tet = proxima.Mesh(TET_V, TET_F)
    w = proxima.World()
    a = w.add(tet)
    b = w.add(tet, moved([0.2, 0.2, 0.2]))
    assert (a, b) == (0, 1) and len(w) == 2 and 1 in w and 2 not in w
    assert w.index == "loose-kd" and w.bv == "kdop18"
    assert repr(w) == 'World(index="loose-kd", bv="kdop18", len=2)'
    c = w.contacts()
    assert c.pairs.tolist() == [[0, 1]] and len(c) == 1 and bool(c)
    assert c.pairs.dtype == np.int64 and c.triangles.dtype == np.int64
    want, unsure = brute.mesh_pairs(TET_V, TET_F, TET_V, TET_F, np.linalg.inv(moved([0.2] * 3)))
    assert not unsure and set(map(tuple, c[0].tolist())) == want
    assert c.offsets.tolist() == [0, len(want)] and c.counters["narrow_pairs"] == 1
    assert set(c.counters) == {
        "broad_pairs", "filtered", "narrow_pairs", "coherent_pairs", "cut_starts", "nv", "np", "nu"
    }
    # Unchanged: coherence reuses the answer.
    again = w.contacts()
    assert as_dict(again) == as_dict(c)
    assert again.counters["coherent_pairs"] == 1 and again.counters["narrow_pairs"] == 0
    # Far apart: nothing.
    w.set_pose(b, moved([5, 5, 5]))
    c = w.contacts()
    assert not c and c.pairs.shape == (0, 2) and c.triangles.shape == (0, 2)
    assert c.offsets.tolist() == [0] and repr(c) == "WorldContacts(pairs=0, triangles=0)"
    np.testing.assert_array_equal(w.pose(b), moved([5, 5, 5]))
    assert w.pose(b).dtype == np.float32
    with pytest.raises(IndexError, match="pair 0 out of range"):
        c[0]
    w.validate()


def test_balls_floor_and_filters():
    floor = proxima.Mesh(SQUARE_V, SQUARE_F)
    w = proxima.World(index="brute")
    f = w.add(floor, group=1)
    ball = w.add(0.5, moved([0.5, 0.5, 0.4]), group=2)
    # The centre is over the shared diagonal: both triangles within 0.5.
    c = w.contacts()
    assert as_dict(c) == {(f, ball): [(0, 0), (1, 0)]}
    assert [tuple(p) for p in w.contacts(first=True).triangles.tolist()][0] in {(0, 0), (1, 0)}
    # Touching counts (0.5 is exact in float32); a hair above does not.
    w.set_pose(ball, moved([0.5, 0.5, 0.5]))
    assert as_dict(w.contacts()) == {(f, ball): [(0, 0), (1, 0)]}
    w.set_pose(ball, moved([0.5, 0.5, 0.5 + 1e-6]))
    assert not w.contacts()
    # Two balls: primitive 0 each.
    w.set_pose(ball, moved([0.5, 0.5, 3.0]))
    other = w.add(0.25, moved([0.5, 0.5, 3.7]), group=4)
    assert as_dict(w.contacts()) == {(ball, other): [(0, 0)]}
    # Filters: the ball (group 2) stops looking at group 4.
    w.set_filter(ball, group=2, mask=ALL & ~4)
    assert w.filter(ball) == (2, ALL & ~4)
    c = w.contacts()
    # The index prunes pairs whose filters do not interact inside its own pair
    # search: the world never sees this one.
    assert not c and c.counters["broad_pairs"] == 0 and c.counters["filtered"] == 0
    w.set_filter(ball, group=2, mask=ALL)
    assert len(w.contacts()) == 1
    # Ignored pairs.
    w.ignore(other, ball)
    assert w.is_ignored(ball, other) and w.n_ignored == 1
    c = w.contacts()
    # An ignored pair is a broad pair the world drops.
    assert not c and c.counters["broad_pairs"] == 1 and c.counters["filtered"] == 1
    assert w.unignore(ball, other) and not w.unignore(ball, other)
    assert len(w.contacts()) == 1
    w.ignore(ball, other)
    w.remove(other)  # drops its ignored pairs
    assert w.n_ignored == 0 and len(w) == 2 and other not in w


def test_rays_spheres_and_culling_by_hand():
    floor = proxima.Mesh(SQUARE_V, SQUARE_F)
    w = proxima.World(bv="obb")
    with pytest.raises(ValueError, match='the mesh has bv "kdop18" but the world uses "obb"'):
        w.add(floor)
    floor = proxima.Mesh(SQUARE_V, SQUARE_F, bv="obb")
    f = w.add(floor, group=1)
    b = w.add(0.1, moved([0.25, 0.75, 0.5]), group=2)
    down = [[0.25, 0.75, 1, 0, 0, -1], [0.75, 0.25, 1, 0, 0, -2], [5, 5, 1, 0, 0, -1]]
    r = w.ray_cast(down)
    assert r["geometry_ids"].tolist() == [b, f, -1]
    assert r["primitive_ids"].tolist() == [0, 0, -1]
    np.testing.assert_allclose(r["t_hit"], [0.4, 0.5, np.inf], rtol=1e-6)
    assert r["t_hit"].dtype == np.float32 and r["geometry_ids"].dtype == np.int64
    # Filtered to group 1: the ball is not seen; tmax cuts the second ray short.
    r = w.ray_cast(down, [2.0, 0.4, 2.0], group=ALL, mask=1)
    assert r["geometry_ids"].tolist() == [f, -1, -1]
    assert r["primitive_ids"].tolist() == [1, -1, -1]
    # Inside the ball: t = 0.
    assert w.ray_cast([0.25, 0.75, 0.5, 1, 0, 0])["t_hit"].tolist() == [0.0]
    ids, off = w.overlap_sphere([[0.25, 0.75, 0.3, 0.15], [0.25, 0.75, 0.3, 0.05], [9, 9, 9, 1]])
    lists = [l.tolist() for l in brute.csr_lists(ids, off)]
    # 0.3 above the floor: the floor is 0.3 away, the ball's surface 0.1.
    assert lists == [[b], [], []]
    ids, off = w.overlap_sphere([0.25, 0.75, 0.3, 0.3])
    assert ids.tolist() == [f, b] and off.tolist() == [0, 2]
    ids, off = w.overlap_sphere([0.25, 0.75, 0.3, 0.3], mask=2)
    assert ids.tolist() == [b]
    # Culling: an orthographic box x, y in [-1, 1], depth 0..10 looking down -z from z = 5.
    m = np.eye(4)
    m[2] = [0, 0, -0.1, 0.5]  # z' = (5 - z) / 10
    ids, off = w.cull(np.stack([m, moved([10, 0, 0]) @ m]))
    assert [l.tolist() for l in brute.csr_lists(ids, off)] == [[f, b], []]


def test_ids_are_insertion_order_and_never_reused():
    tet = proxima.Mesh(TET_V, TET_F)
    w = proxima.World(index="grid3d")
    ids = w.add_many(tet, np.stack([moved([3 * k, 0, 0]) for k in range(4)]))
    assert ids.tolist() == [0, 1, 2, 3] and ids.dtype == np.int64
    w.remove(1)
    w.remove(2)
    # New objects take new ids (the library reuses the slots: the contacts are
    # still reported in id order, each pair's triangles as (of a, of b)).
    c = w.add(tet, moved([3.2, 0.1, 0.1]))
    d = w.add(tet, moved([0.1, 0.2, 0.1]))
    assert (c, d) == (4, 5) and w.ids().tolist() == [0, 3, 4, 5]
    got = as_dict(w.contacts())
    assert sorted(got) == [(0, 5)]
    want, _ = brute.mesh_pairs(TET_V, TET_F, TET_V, TET_F, np.linalg.inv(moved([0.1, 0.2, 0.1])))
    assert set(got[(0, 5)]) == want and got[(0, 5)] == sorted(got[(0, 5)])
    w.set_poses([3, 4], np.stack([moved([0.3, 0, 0]), moved([0, 0.3, 0])])[:, :3])
    got = as_dict(w.contacts())
    assert sorted(got) == [(0, 3), (0, 4), (0, 5), (3, 4), (3, 5), (4, 5)]
    # Pairs whose smaller id sits in a later slot come out in id order too.
    for (a, b), tris in got.items():
        rel = np.linalg.inv(w.pose(b).astype(np.float64)) @ w.pose(a)
        want, unsure = brute.mesh_pairs(TET_V, TET_F, TET_V, TET_F, rel)
        assert want <= set(tris) <= want | unsure and tris == sorted(tris), (a, b)
    with pytest.raises(KeyError, match="id 4 appears twice"):
        w.remove_many([4, 4])
    with pytest.raises(KeyError, match="id 1 is not in the world"):
        w.remove_many([4, 1])
    assert len(w) == 4
    w.remove_many(np.array([5, 3]))
    assert w.ids().tolist() == [0, 4] and sorted(as_dict(w.contacts())) == [(0, 4)]


def test_a_shared_mesh_is_not_copied():
    tet = proxima.Mesh(TET_V, TET_F)
    w = proxima.World()
    ids = w.add_many(tet, np.stack([moved([2 * k, 0, 0]) for k in range(3)]))
    with pytest.raises(ValueError, match="the mesh is the shape of 3 World object"):
        tet.set_vertices(TET_V * 2)
    np.testing.assert_array_equal(tet.vertices, TET_V)
    for i in ids:
        w.remove(i)
    tet.set_vertices(TET_V * 2)  # no longer shared
    # Dropping a world releases its references too.
    w.add(tet)
    del w
    tet.set_vertices(TET_V)


# --- random sequences against the brute-force world --------------------------


def check_contacts(world, bw, first=False, workers=1):
    got = as_dict(world.contacts(first=first, workers=workers))
    c_pairs = list(got)
    assert c_pairs == sorted(c_pairs) and all(a < b for a, b in c_pairs)
    want = bw.contacts()
    n_tris = 0
    for key, (sure, unsure) in want.items():
        if sure:
            assert key in got, f"missing pair {key}"
    for key, tris in got.items():
        assert key in want, f"extra pair {key}"
        sure, unsure = want[key]
        if first:
            assert len(tris) == 1 and tris[0] in sure | unsure
        else:
            assert tris == sorted(set(tris)), key
            assert sure <= set(tris) <= sure | unsure, key
            n_tris += len(tris)
    return got, n_tris


def check_rays(world, bw, rng, n, group=ALL, mask=ALL):
    o = rng.uniform(-1.5, 3.5, (n, 3))
    d = rng.normal(size=(n, 3))
    d[: n // 2] = rng.uniform(-0.5, 2.5, (n // 2, 3)) - o[: n // 2]  # aimed into the scene
    tmax = rng.choice([np.inf, 1.0, 3.0], n)
    rays = np.hstack([o, d]).astype(np.float32)
    r = world.ray_cast(rays, tmax, group=group, mask=mask)
    hits = 0
    for k in range(n):
        cand = bw.ray(rays[k], tmax[k], group, mask)
        t, gid, tri = r["t_hit"][k], r["geometry_ids"][k], r["primitive_ids"][k]
        certain = [v[0] for v in cand.values() if not v[2] and np.isfinite(v[0])]
        best = min(certain, default=np.inf)
        tol = 1e-4 * (1 + abs(best)) if np.isfinite(best) else 0
        ts = sorted(v[0] for v in cand.values())
        clear = not any(v[2] for v in cand.values()) and (
            len(ts) < 2 or ts[1] - ts[0] > 1e-3 * (1 + abs(ts[0]))
        )
        if clear:
            if np.isfinite(best):
                i = min(cand, key=lambda i: cand[i][0])
                assert (gid, tri) == (i, cand[i][1]), f"ray {k}"
                assert abs(t - best) <= tol
                hits += 1
            else:
                assert gid == -1 and tri == -1 and t == np.inf, f"ray {k}"
        else:
            assert t <= best + tol  # a certain hit is never missed
            if gid >= 0:
                assert gid in cand
    return hits


def check_spheres(world, bw, rng, n, group=ALL, mask=ALL):
    q = np.hstack([rng.uniform(-1, 3, (n, 3)), rng.uniform(0, 0.8, (n, 1))]).astype(np.float32)
    ids, off = world.overlap_sphere(q, group=group, mask=mask)
    found = 0
    for k, got in enumerate(brute.csr_lists(ids, off)):
        sure, unsure = bw.near(q[k], group, mask)
        got = got.tolist()
        assert got == sorted(got) and sure <= set(got) <= sure | unsure, f"sphere {k}"
        found += len(got)
    return found


def random_pose(rng):
    return moved(rng.uniform(-0.2, 1.8, 3), brute.random_rotations(rng, 1)[0])


def run_sequence(rng, index, bv, steps=14):
    shapes = []
    for n in (12, 20, 30):
        v, f = soup(rng, n, size=0.35)
        shapes.append(((v, f), proxima.Mesh(v, f, bv=bv)))
    world = proxima.World(index=index, bv=bv)
    lockstep = proxima.World(index=index, bv=bv, coherence=False)
    bw = brute.BruteWorld()

    def add(pose, group=ALL, mask=ALL):
        if rng.random() < 0.25:
            r = float(np.float32(rng.uniform(0.05, 0.5)))
            data, shape = r, r
        else:
            data, shape = shapes[rng.integers(len(shapes))]
        i = world.add(shape, pose, group=group, mask=mask)
        assert lockstep.add(shape, pose, group=group, mask=mask) == i
        bw.add(i, data, pose, group, mask)

    for _ in range(10):
        add(random_pose(rng))
    totals = dict(pairs=0, tris=0, hits=0, near=0, first=0)
    for step in range(steps):
        ids = sorted(bw.objects)
        op = rng.integers(6)
        if op == 0 and len(ids) > 4:  # remove some
            for i in rng.choice(ids, 2, replace=False).tolist():
                world.remove(i)
                lockstep.remove(i)
                bw.remove(i)
        elif op == 1:  # add some, some with filters
            for _ in range(2):
                g = int(rng.choice([1, 2, ALL]))
                add(random_pose(rng), g, int(rng.choice([ALL, ALL & ~1, 2])))
        elif op == 2 and len(ids) > 2:  # ignore / unignore
            a, b = rng.choice(ids, 2, replace=False).tolist()
            key = (min(a, b), max(a, b))
            if key in bw.ignored:
                assert world.unignore(a, b) and lockstep.unignore(b, a)
                bw.ignored.discard(key)
            else:
                world.ignore(a, b)
                lockstep.ignore(a, b)
                bw.ignored.add(key)
            assert world.is_ignored(b, a) == (key in bw.ignored)
            assert world.n_ignored == len(bw.ignored)
        elif op == 3 and ids:  # refilter one
            i = int(rng.choice(ids))
            g, m = int(rng.choice([1, 2, ALL])), int(rng.choice([ALL, 2, 0]))
            world.set_filter(i, group=g, mask=m)
            lockstep.set_filter(i, group=g, mask=m)
            bw.objects[i][2:] = [g, m]
        # Move some (sometimes all) in one batch, a few only slightly.
        if ids:
            live = sorted(bw.objects)
            k = len(live) if step % 4 == 0 else max(1, len(live) // 3)
            move = rng.choice(live, k, replace=False)
            poses = []
            for i in move.tolist():
                p = bw.objects[i][1].astype(np.float64)
                if rng.random() < 0.5:
                    p = p.copy()
                    p[:3, 3] += rng.normal(0, 0.02, 3)
                else:
                    p = random_pose(rng)
                poses.append(p)
            poses = np.stack(poses).astype(np.float32)
            form = poses if step % 2 else poses[:, :3]  # (N, 4, 4) and (N, 3, 4)
            world.set_poses(move, form)
            lockstep.set_poses(move.tolist(), form.astype(np.float64))
            for i, p in zip(move.tolist(), poses):
                bw.objects[i][1] = brute.f32(p)
        got, n_tris = check_contacts(world, bw)
        totals["pairs"] += len(got)
        totals["tris"] += n_tris
        # Coherence off and the pool: the very same answer.
        other = lockstep.contacts(workers=2 if step % 3 == 0 else 1)
        assert as_dict(other) == got
        if step % 3 == 1:
            f, _ = check_contacts(world, bw, first=True)
            assert set(f) == set(got)
            totals["first"] += len(f)
        totals["hits"] += check_rays(world, bw, rng, 16)
        totals["near"] += check_spheres(world, bw, rng, 4)
        if step % 5 == 2:
            g, m = int(rng.choice([1, 2])), ALL
            check_rays(world, bw, rng, 6, group=g, mask=m)
            check_spheres(world, bw, rng, 3, group=g, mask=m)
        np.testing.assert_array_equal(world.ids(), sorted(bw.objects))
        world.validate()
    return totals


@pytest.mark.parametrize("index", proxima.INDEX_KINDS)
def test_random_sequences_match_brute_force(index):
    rng = np.random.default_rng(proxima.INDEX_KINDS.index(index))
    totals = run_sequence(rng, index, "kdop18")
    # The scenes are dense enough that every check had something to check.
    assert totals["pairs"] >= 10 and totals["tris"] >= 20, totals
    assert totals["hits"] >= 10 and totals["near"] >= 10 and totals["first"] >= 2, totals


@pytest.mark.parametrize("bv", [b for b in BVS if b != "kdop18"])
def test_random_sequences_every_bv(bv):
    rng = np.random.default_rng(10 + BVS.index(bv))
    totals = run_sequence(rng, None, bv, steps=6)
    assert totals["pairs"] >= 5 and totals["hits"] >= 5, totals


def test_culling_matches_bounding_spheres(rng):
    tet = proxima.Mesh(TET_V * 0.3, TET_F)
    w = proxima.World(index="octree")
    n = 300
    poses = brute.poses(brute.random_rotations(rng, n), rng.uniform(-10, 10, (n, 3)))
    ids = w.add_many(tet, poses, group=1)
    ball = w.add(0.2, moved([0.5, -0.5, 0.0]))
    c, r = tet.bounding_sphere
    centers = np.vstack([brute.transform(poses[k], c[None])[0] for k in range(n)] + [[0.5, -0.5, 0]])
    radii = np.append(np.full(n, r), 0.2)
    fov = np.diag([0.2, 0.2, 1.0, 1.0])
    fov[2] = [0, 0, -1 / 20, 0.5]
    fov[3] = [0, 0, 0, 1]
    mats = np.stack([fov, fov @ moved([3, 0, 0]), np.diag([0.2, 0.2, 0.05, 1.0])])
    got, off = w.cull(mats)
    for k, g in enumerate(brute.csr_lists(got, off)):
        inner, _ = brute.frustum_query(centers, radii, mats[k])
        outer, unsure = brute.frustum_query(centers, radii * 1.01 + 1e-3, mats[k])
        g = set(g.tolist())
        assert set(inner.tolist()) <= g <= set(outer.tolist()) | set(unsure.tolist()), k
        assert len(g) >= 10
    # Filters on culling.
    w.set_filter(ball, group=8, mask=ALL)
    got, _ = w.cull(mats[2], mask=8)
    assert got.tolist() == [ball]
    assert ids[-1] + 1 == ball


def test_contacts_release_the_gil(rng):
    v, f = soup(rng, 300, size=0.3)
    m = proxima.Mesh(v, f)
    w = proxima.World(coherence=False)
    w.add_many(m, brute.poses(brute.random_rotations(rng, 12), rng.uniform(0, 0.5, (12, 3))))
    assert released_during(lambda: w.contacts())
    assert released_during(lambda: w.contacts(workers=2))


# --- bad input ---------------------------------------------------------------


@pytest.fixture
def scene():
    tet = proxima.Mesh(TET_V, TET_F)
    w = proxima.World()
    w.add_many(tet, np.stack([moved([0.3 * k, 0, 0]) for k in range(3)]))
    w.add(0.4, moved([0, 0.5, 0]))
    w.ignore(0, 1)
    w.remove(2)
    return w, tet


def snapshot(w):
    c = w.contacts()
    return (
        w.ids().tolist(),
        [w.pose(i).tolist() for i in w.ids()],
        [w.filter(i) for i in w.ids()],
        w.n_ignored,
        c.pairs.tolist(),
        c.triangles.tolist(),
    )


def test_stale_ids_raise_key_error(scene):
    w, tet = scene
    before = snapshot(w)
    for call in (
        lambda: w.remove(2),
        lambda: w.set_pose(2, np.eye(4)),
        lambda: w.set_poses([0, 2], np.stack([np.eye(4)] * 2)),
        lambda: w.pose(7),
        lambda: w.filter(-1),
        lambda: w.set_filter(2, group=1, mask=1),
        lambda: w.ignore(0, 2),
        lambda: w.unignore(2, 0),
        lambda: w.is_ignored(0, 9),
    ):
        with pytest.raises(KeyError, match=r"id (2|7|-1|9) is not in the world"):
            call()
    assert snapshot(w) == before


def bad_poses():
    nan = np.eye(4)
    nan[0, 3] = np.nan
    scaled = np.diag([2.0, 2.0, 2.0, 1.0])
    mirror = np.diag([1.0, 1.0, -1.0, 1.0])
    sheared = np.eye(4)
    sheared[0, 1] = 0.1
    last_row = np.eye(4)
    last_row[3, 0] = 1.0
    far = moved([1e31, 0, 0])
    return [
        (nan, "non-finite"),
        (scaled, "rotation|rigid"),
        (mirror, "rotation|rigid|determinant"),
        (sheared, "rotation|rigid"),
        (last_row, r"last row"),
        (far, "beyond"),
        (np.eye(3), r"expected shape"),
        (np.zeros((4, 3)), r"expected shape"),
        ("pose", "not an array|expected real numbers"),
    ]


@pytest.mark.parametrize("pose,msg", bad_poses())
def test_bad_poses_change_nothing(scene, pose, msg):
    w, tet = scene
    before = snapshot(w)
    with pytest.raises(ValueError, match=msg):
        w.set_pose(0, pose)
    with pytest.raises(ValueError, match=msg):
        w.add(tet, pose)
    if np.ndim(pose) == 2 and np.shape(pose) == (4, 4):
        # One bad pose in a batch: nothing moves, nothing is added.
        with pytest.raises(ValueError, match=f"poses: .*({msg})"):
            w.set_poses([0, 1], np.stack([moved([4, 4, 4]), pose]))
        with pytest.raises(ValueError, match=f"poses: pose 1.*({msg})"):
            w.add_many(tet, np.stack([moved([4, 4, 4]), pose]))
    assert snapshot(w) == before
    assert w.add(tet) == 4  # no id was used up


def test_other_bad_input(scene):
    w, tet = scene
    before = snapshot(w)
    with pytest.raises(ValueError, match="2 ids but 1 poses"):
        w.set_poses([0, 1], np.eye(4)[None])
    with pytest.raises(ValueError, match=r"expected shape \(N, 4, 4\)"):
        w.set_poses([0], np.zeros((1, 4, 3)))
    with pytest.raises(ValueError, match="expected integers"):
        w.set_poses([0.5], np.eye(4)[None])
    with pytest.raises(ValueError, match="one \\(4, 4\\) or \\(3, 4\\) pose here"):
        w.add(tet, np.stack([np.eye(4)] * 2))
    with pytest.raises(ValueError, match="shape: negative radius"):
        w.add(-1.0)
    with pytest.raises(ValueError, match="shape: .*not finite"):
        w.add(float("nan"))
    with pytest.raises(TypeError, match="a proxima.Mesh or a ball radius"):
        w.add("tet")
    with pytest.raises(ValueError, match="group must be an integer in 0..2\\*\\*32"):
        w.add(tet, group=-1)
    with pytest.raises(ValueError, match="mask must be"):
        w.set_filter(0, group=1, mask=2**32)
    with pytest.raises(ValueError, match="two different objects"):
        w.ignore(1, 1)
    with pytest.raises(ValueError, match="rays: row 0"):
        w.ray_cast([[0, 0, 0, 0, 0, 0]])
    with pytest.raises(ValueError, match="rays: row 1 has a non-finite value"):
        w.ray_cast([[0, 0, 0, 1, 0, 0], [np.nan, 0, 0, 1, 0, 0]])
    with pytest.raises(ValueError, match=r"rays: expected shape \(N, 6\)"):
        w.ray_cast(np.zeros((2, 5)))
    with pytest.raises(ValueError, match="spheres: row 0: negative radius"):
        w.overlap_sphere([0, 0, 0, -1])
    with pytest.raises(ValueError, match="spheres: row 0: sphere centre is not finite"):
        w.overlap_sphere([0, np.inf, 0, 1])
    with pytest.raises(ValueError, match="depth must be"):
        w.cull(np.eye(4), depth="opengl")
    with pytest.raises(ValueError, match="workers must be"):
        w.contacts(workers=0)
    for kw in ({"index": "kd"}, {"bv": "capsule"}, {"rotation": "sometimes"}, {"bounds": [1, 1, 1, 0, 0, 0]}):
        with pytest.raises(ValueError):
            proxima.World(**kw)
    assert snapshot(w) == before
    # Non-contiguous and other dtypes are converted.
    poses = np.stack([moved([0, 0, 3]), moved([0, 3, 0])]).astype(np.float64)[:, :, :]
    w.set_poses(np.array([1, 0], dtype=np.uint8), poses[::-1][::-1])
    np.testing.assert_array_equal(w.pose(0), moved([0, 3, 0]))


def test_bounds_and_index_choice():
    tet = proxima.Mesh(TET_V, TET_F)
    for kind in proxima.INDEX_KINDS:
        w = proxima.World(index=kind, bounds=[[-5, -5, -5], [5, 5, 5]])
        assert w.index == kind
        w.add(tet)
        w.add(tet, moved([0.5, 0, 0]))
        w.add(tet, moved([40, 0, 0]))  # outside the bounds: still exact
        w.add(tet, moved([40.5, 0, 0]))
        assert w.contacts().pairs.tolist() == [[0, 1], [2, 3]]
        assert w.memory_bytes > 0
