"""proxima.collide: hand-checked cases, brute force on small meshes, and the
CLI's answers (`proxima collide A B --poses F --stats`) on the shared meshes."""

from __future__ import annotations

import subprocess

import brute
import numpy as np
import pytest
from test_mesh import BVS, SQUARE_F, SQUARE_V, soup

import proxima


def rotation_x(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def test_readme_tile_through_the_floor():
    floor = proxima.Mesh(SQUARE_V, SQUARE_F)
    pose = np.eye(4)
    pose[:3, :3] = rotation_x(0.5)
    pose[:3, 3] = [0.2, 0.2, -0.3]
    c = proxima.collide(floor, floor, pose)
    assert len(c) == 1 and bool(c) and c.colliding.tolist() == [True]
    # The tilted tile crosses z = 0 along y = 0.2 + 0.3/tan(0.5) = 0.749, x in [0.2, 1.2]:
    # within the floor for x in [0.2, 1], over both of its triangles.
    va, fa = brute.transform(pose, SQUARE_V), SQUARE_F
    want, unsure = brute.mesh_pairs(SQUARE_V, fa, SQUARE_V, SQUARE_F, pose)
    assert not unsure
    assert set(map(tuple, c.pairs.tolist())) == want
    assert {j for _, j in want} == {0, 1}
    assert c.pairs.shape[1] == 2 and c.offsets.tolist() == [0, len(want)]
    assert c.counters.shape == (1, 3) and c.counters[0, 1] >= len(want)
    np.testing.assert_array_equal(c[0], c.pairs)
    np.testing.assert_array_equal(c[-1], c.pairs)
    # Lifted clear of the floor: nothing.
    pose[2, 3] = 2.0
    c = proxima.collide(floor, floor, pose[:3])  # the (3, 4) form
    assert not c and c.pairs.shape == (0, 2) and c.colliding.tolist() == [False]
    assert repr(c) == "Contacts(poses=1, colliding=0, pairs=0)"
    with pytest.raises(IndexError):
        c[1]


def test_touching_counts():
    # Two triangles sharing only a corner point: closed test, they intersect.
    a = proxima.Mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]])
    b = proxima.Mesh([[1, 0, 0], [2, 0, 1], [2, 1, -1]], [[0, 1, 2]])
    assert proxima.collide(a, b, np.eye(4)).pairs.tolist() == [[0, 0]]
    assert not proxima.collide(a, b, brute.poses(np.eye(3)[None], [[-1e-3, 0, 0]])[0])


@pytest.mark.parametrize("bv", BVS)
def test_random_small_meshes_match_brute_force(bv, rng):
    va, fa = soup(rng, 40)
    vb, fb = soup(rng, 50)
    a = proxima.Mesh(va, fa, bv=bv)
    b = proxima.Mesh(vb, fb, bv=bv)
    n = 40
    rot = brute.random_rotations(rng, n)
    rot[:5] = np.eye(3)  # pure translations take another path
    poses = brute.poses(rot, rng.uniform(-0.6, 0.6, (n, 3)))
    res = proxima.collide(a, b, poses)
    first = proxima.collide(a, b, poses, first=True)
    assert len(res) == n and res.offsets.shape == (n + 1,)
    colliding = 0
    for k in range(n):
        want, unsure = brute.mesh_pairs(va, fa, vb, fb, poses[k])
        got = set(map(tuple, res[k].tolist()))
        assert len(got) == len(res[k])  # each pair once
        assert want <= got <= want | unsure, f"pose {k}"
        assert res.colliding[k] == bool(got)
        assert first.colliding[k] == res.colliding[k]
        if got:
            assert len(first[k]) == 1 and tuple(first[k][0]) in got
            colliding += 1
        # Each pair found was tested once, so np >= the pairs.
        assert res.counters[k, 1] >= len(got)
        assert first.counters[k, 1] <= res.counters[k, 1]
    assert 5 < colliding < n


def test_rotation_modes_agree(rng):
    va, fa = soup(rng, 60)
    a = proxima.Mesh(va, fa)
    poses = brute.poses(brute.random_rotations(rng, 20), rng.uniform(-0.5, 0.5, (20, 3)))
    ref = proxima.collide(a, a, poses)
    assert ref.pairs.shape[0] > 20
    for rot in ("refit", "conservative"):
        c = proxima.collide(a, a, poses, rotation=rot)
        np.testing.assert_array_equal(c.offsets, ref.offsets)
        for k in range(len(c)):
            assert set(map(tuple, c[k].tolist())) == set(map(tuple, ref[k].tolist()))
    # Auto is conservative today: the same counters.
    np.testing.assert_array_equal(
        proxima.collide(a, a, poses, rotation="conservative").counters, ref.counters
    )


def write_poses(path, poses):
    """A pose file of the CLI: 12 numbers a line, row-major R then t, each the
    shortest text that reads back as the same float32."""
    lines = []
    for p in poses:
        nums = list(p[:3, :3].ravel()) + list(p[:3, 3])
        lines.append(" ".join(str(np.float32(x)) for x in nums))
    path.write_text("\n".join(lines) + "\n")


def cli_collide(cli, a, b, pose_file, *extra):
    out = subprocess.run(
        [cli, "collide", str(a), str(b), "--poses", str(pose_file), "--stats", *extra],
        check=True,
        capture_output=True,
        text=True,
    ).stdout
    rows = []
    for line in out.splitlines():
        w = line.split()
        if w and w[0] in ("pairs", "hit"):  # "hit 0|1" with --first
            rows.append([int(w[1]), int(w[3]), int(w[5]), int(w[7])])
    return np.array(rows, dtype=np.int64)


def rob_env_poses(rng, n):
    """Poses of rob near env: rows of the benchmark's pose file, and random
    rotations at translations inside env's box (FCL's test set-up)."""
    from conftest import ROOT

    rows = np.loadtxt(ROOT / "crates" / "proxima-bench" / "data" / "rob-env-1000.poses")
    pick = rows[rng.choice(len(rows), n // 2, replace=False)]
    from_file = brute.poses(pick[:, :9].reshape(-1, 3, 3), pick[:, 9:])
    rand = brute.poses(
        brute.random_rotations(rng, n - n // 2),
        rng.uniform([-3000, -3000, 0], [3000, 3000, 3000], (n - n // 2, 3)),
    )
    return np.concatenate([from_file, rand])


@pytest.mark.parametrize("bv", ["kdop18", "obb", "aabb"])
def test_rob_env_matches_the_cli(bv, rng, data, cli, tmp_path):
    rob = proxima.Mesh.load(data / "rob.obj", bv=bv)
    env = proxima.Mesh.load(data / "env.obj", bv=bv)
    poses = rob_env_poses(rng, 60)
    f = tmp_path / "poses.txt"
    write_poses(f, poses)
    want = cli_collide(cli, data / "rob.obj", data / "env.obj", f, "--bv", bv)
    assert want.shape == (60, 4)
    res = proxima.collide(rob, env, poses)
    got = np.column_stack([np.diff(res.offsets), res.counters]).astype(np.int64)
    np.testing.assert_array_equal(got, want)
    assert (want[:, 0] > 0).sum() >= 5
    # --first: the same yes/no per pose, and the same counters.
    want_first = cli_collide(cli, data / "rob.obj", data / "env.obj", f, "--bv", bv, "--first")
    first = proxima.collide(rob, env, poses, first=True)
    got = np.column_stack([np.diff(first.offsets), first.counters]).astype(np.int64)
    np.testing.assert_array_equal(got, want_first)
    np.testing.assert_array_equal(first.colliding, want[:, 0] > 0)
    # The same batch on a pool.
    par = proxima.collide(rob, env, poses, workers=2)
    for name in ("pairs", "offsets", "colliding", "counters"):
        np.testing.assert_array_equal(getattr(par, name), getattr(res, name))


def test_rob_env_pairs_match_brute_force(rng, data):
    rob = proxima.Mesh.load(data / "rob.obj")
    env = proxima.Mesh.load(data / "env.obj")
    poses = rob_env_poses(rng, 40)
    res = proxima.collide(rob, env, poses)
    # The two poses with the most pairs, against all 216 x 2180 triangle pairs.
    for k in np.argsort(-np.diff(res.offsets))[:2]:
        want, unsure = brute.mesh_pairs(rob.vertices, rob.faces, env.vertices, env.faces, poses[k], band=1e-7)
        got = set(map(tuple, res[k].tolist()))
        assert len(want) > 10
        assert want <= got <= want | unsure


def test_single_pose_and_batch_forms_agree(rng, data):
    rob = proxima.Mesh.load(data / "rob.obj")
    env = proxima.Mesh.load(data / "env.obj")
    poses = rob_env_poses(rng, 10)
    batch = proxima.collide(rob, env, poses)
    for k, p in enumerate(poses):
        one = proxima.collide(rob, env, p)
        np.testing.assert_array_equal(one.pairs, batch[k])
        np.testing.assert_array_equal(one.counters[0], batch.counters[k])
        np.testing.assert_array_equal(proxima.collide(rob, env, p[:3]).pairs, one.pairs)
    # float64 input and non-contiguous views are converted.
    view = np.zeros((10, 4, 8))
    view[:, :, ::2] = poses
    np.testing.assert_array_equal(proxima.collide(rob, env, view[:, :, ::2]).pairs, batch.pairs)
