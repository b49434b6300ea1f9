"""proxima.Mesh: construction, files, properties, ray casts against brute force."""

from __future__ import annotations

import brute
import numpy as np
import pytest

import proxima

BVS = ["aabb", "kdop14", "kdop18", "kdop26", "obb", "sphere"]

# A unit square in the plane z = 0, as two triangles (the README's floor).
SQUARE_V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], dtype=float)
SQUARE_F = np.array([[0, 1, 2], [0, 2, 3]])


def soup(rng, n, size=0.4, box=1.0):
    """n random triangles (own vertices) in a cube of side `box`."""
    c = rng.uniform(0, box, (n, 1, 3))
    v = (c + rng.uniform(-size, size, (n, 3, 3))).reshape(-1, 3)
    return v, np.arange(3 * n).reshape(n, 3)


def test_bounding_volumes_by_name():
    assert proxima.BOUNDING_VOLUMES == BVS
    for bv in BVS:
        m = proxima.Mesh(SQUARE_V, SQUARE_F, bv=bv)
        assert m.bv == bv


def test_properties():
    m = proxima.Mesh(SQUARE_V, SQUARE_F)
    assert (m.n_vertices, m.n_triangles, m.bv) == (4, 2, "kdop18")
    np.testing.assert_array_equal(m.vertices, SQUARE_V.astype(np.float32))
    assert m.vertices.dtype == np.float32
    np.testing.assert_array_equal(m.faces, SQUARE_F)
    assert m.faces.dtype == np.int64
    np.testing.assert_array_equal(m.aabb, [[0, 0, 0], [1, 1, 0]])
    center, radius = m.bounding_sphere
    np.testing.assert_array_equal(center, [0.5, 0.5, 0])
    assert np.sqrt(0.5) <= radius < np.sqrt(0.5) * 1.0001
    assert repr(m) == 'Mesh(n_vertices=4, n_triangles=2, bv="kdop18")'


def test_load_matches_the_file(data):
    rob = proxima.Mesh.load(data / "rob.obj")
    assert rob.n_triangles == 216
    # The OBJ's own vertex lines (after the non-standard header line).
    lines = (data / "rob.obj").read_text().splitlines()
    v = np.array([[float(x) for x in l.split()[1:4]] for l in lines if l.startswith("v ")])
    np.testing.assert_array_equal(rob.vertices, v.astype(np.float32))
    again = proxima.Mesh(rob.vertices, rob.faces)
    np.testing.assert_array_equal(again.faces, rob.faces)
    # str paths and every format.
    assert proxima.Mesh.load(str(data / "env.obj"), bv="obb").n_triangles == 2180
    assert proxima.Mesh.load(data / "forearm.stl").n_triangles > 900
    assert proxima.Mesh.load(data / "teapot.obj", split="median", leaf_size=4).n_triangles == 992


def test_load_ply(tmp_path):
    p = tmp_path / "square.ply"
    p.write_text(
        "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
        "property float z\nelement face 2\nproperty list uchar int vertex_indices\n"
        "end_header\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n"
    )
    m = proxima.Mesh.load(p)
    np.testing.assert_array_equal(m.faces, SQUARE_F)


def test_ray_casts_hand_checked():
    floor = proxima.Mesh(SQUARE_V, SQUARE_F)
    rays = np.array(
        [
            [0.25, 0.75, 1, 0, 0, -1],  # the README's ray: triangle 1 at t = 1
            [0.75, 0.25, 2, 0, 0, -2],  # triangle 0, t = 1 in units of the direction
            [2, 2, 1, 0, 0, -1],  # misses
            [0.5, 0.5, 1, 0, 0, 1],  # points away
        ]
    )
    hit = floor.cast_rays(rays)
    assert set(hit) == {"t_hit", "primitive_ids", "primitive_uvs"}
    assert hit["t_hit"].tolist() == [1.0, 1.0, np.inf, np.inf]
    assert hit["primitive_ids"].tolist() == [1, 0, -1, -1]
    assert hit["t_hit"].dtype == np.float32 and hit["primitive_ids"].dtype == np.int64
    # (0.25, 0.75) on triangle 1 = (0, 2, 3): (1-u-v)·a + u·b + v·c.
    u, v = hit["primitive_uvs"][0]
    p = (1 - u - v) * SQUARE_V[0] + u * SQUARE_V[2] + v * SQUARE_V[3]
    np.testing.assert_allclose(p, [0.25, 0.75, 0], atol=1e-6)
    assert hit["primitive_uvs"][2].tolist() == [0, 0]
    # tmax cuts the first ray short.
    short = floor.cast_rays(rays[:1], tmax=0.5)
    assert short["primitive_ids"].tolist() == [-1]
    # A posed mesh: the floor lifted by 3 along z.
    pose = np.eye(4)
    pose[2, 3] = 3
    lifted = floor.cast_rays([[0.25, 0.75, 5, 0, 0, -1]], pose=pose)
    assert lifted["t_hit"].tolist() == [2.0] and lifted["primitive_ids"].tolist() == [1]


@pytest.mark.parametrize("bv", ["kdop18", "obb"])
def test_ray_casts_match_brute_force(bv, rng, data):
    meshes = [proxima.Mesh.load(data / "rob.obj", bv=bv), proxima.Mesh(*soup(rng, 150), bv=bv)]
    for mesh in meshes:
        v, f = mesh.vertices, mesh.faces
        lo, hi = mesh.aabb
        n = 1500
        o = rng.uniform(lo - (hi - lo) * 0.3, hi + (hi - lo) * 0.3, (n, 3))
        target = rng.uniform(lo, hi, (n, 3))
        rays = np.column_stack([o, target - o]).astype(np.float32)
        tmax = np.where(rng.uniform(size=n) < 0.7, np.inf, rng.uniform(0, 1.2, n)).astype(np.float32)
        got = mesh.cast_rays(rays, tmax)
        want_t, want_id, unsure, tie = brute.ray_mesh(v, f, rays, tmax)
        sure = ~unsure
        assert sure.sum() > 0.9 * n
        # Two triangles at the same t: t is certain, the triangle one of them.
        np.testing.assert_allclose(got["t_hit"][tie], want_t[tie], rtol=1e-5)
        hits = np.isfinite(want_t) & sure
        assert hits.sum() > 0.2 * n
        np.testing.assert_array_equal(got["primitive_ids"][sure], want_id[sure])
        np.testing.assert_allclose(got["t_hit"][hits], want_t[hits], rtol=1e-5, atol=1e-5)
        assert np.all(np.isinf(got["t_hit"][sure & ~hits]))
        # Hit points from the barycentrics lie on the ray.
        k = np.nonzero(got["primitive_ids"] >= 0)[0]
        tri = v[f[got["primitive_ids"][k]]].astype(np.float64)
        u, w = got["primitive_uvs"][k, 0:1], got["primitive_uvs"][k, 1:2]
        p = (1 - u - w) * tri[:, 0] + u * tri[:, 1] + w * tri[:, 2]
        q = rays[k, :3] + got["t_hit"][k, None] * rays[k, 3:]
        np.testing.assert_allclose(p, q, atol=1e-3 * float(np.abs(hi - lo).max()))
        # Workers: the same answers.
        for w in (2, -1):
            par = mesh.cast_rays(rays, tmax, workers=w)
            for key in got:
                np.testing.assert_array_equal(par[key], got[key])


def test_posed_casts_equal_casts_on_moved_vertices(rng, data):
    rob = proxima.Mesh.load(data / "rob.obj")
    rot = brute.random_rotations(rng, 1)[0]
    pose = brute.poses(rot[None], rng.uniform(-50, 50, (1, 3)))[0]
    moved = proxima.Mesh(brute.transform(pose, rob.vertices), rob.faces)
    lo, hi = moved.aabb
    o = rng.uniform(lo - 20, hi + 20, (500, 3))
    rays = np.column_stack([o, rng.uniform(lo, hi, (500, 3)) - o])
    a = rob.cast_rays(rays, pose=pose)
    b = moved.cast_rays(rays)
    agree = a["primitive_ids"] == b["primitive_ids"]
    assert agree.mean() > 0.97  # edges may round either way
    both = agree & (a["primitive_ids"] >= 0)
    assert both.sum() > 100
    np.testing.assert_allclose(a["t_hit"][both], b["t_hit"][both], rtol=1e-4)
    # The (3, 4) form of the same pose.
    c = rob.cast_rays(rays, pose=pose[:3])
    np.testing.assert_array_equal(c["primitive_ids"], a["primitive_ids"])


def test_set_vertices_refits_both_trees(rng):
    v, f = soup(rng, 80)
    m = proxima.Mesh(v, f)
    rays = np.column_stack([rng.uniform(-1, 2, (300, 3)), rng.normal(size=(300, 3))])
    m.cast_rays(rays)  # builds the ray tree
    v2 = v + 5.0
    m.set_vertices(v2)
    np.testing.assert_array_equal(m.vertices, v2.astype(np.float32))
    fresh = proxima.Mesh(v2, f)
    a, b = m.cast_rays(rays + [5, 5, 5, 0, 0, 0]), fresh.cast_rays(rays + [5, 5, 5, 0, 0, 0])
    np.testing.assert_array_equal(a["primitive_ids"], b["primitive_ids"])
    np.testing.assert_array_equal(a["t_hit"], b["t_hit"])
    pose = np.eye(4)
    np.testing.assert_array_equal(
        proxima.collide(m, fresh, pose).pairs, proxima.collide(fresh, fresh, pose).pairs
    )
