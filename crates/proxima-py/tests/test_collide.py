"""proxima.collide: hand-checked cases, brute force on small meshes, and the
CLI's answers (`proxima collide A B --poses F --stats`) on the shared meshes."""

from __future__ import annotations

import subprocess
import threading

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


def on_a_new_thread(f):
    """f() on a thread of its own: proxima keeps one collider per thread and
    bounding volume, so this one starts from new colliders."""
    out = []
    t = threading.Thread(target=lambda: out.append(f()))
    t.start()
    t.join()
    assert len(out) == 1, "f raised on its thread"
    return out[0]


def one_pose_answer(c):
    return c.pairs.copy(), c.counters[0].copy(), bool(c)


@pytest.mark.parametrize("bv", BVS)
def test_kept_colliders_answer_as_new_ones(bv, rng):
    # Meshes of two sizes in turn, so that a thread's kept collider meets
    # larger and smaller meshes and holds entries of other meshes and poses.
    small = proxima.Mesh(*soup(rng, 30), bv=bv)
    big = proxima.Mesh(*soup(rng, 300, size=0.15), bv=bv)
    cases = [(small, small), (big, small), (small, big), (big, big)]
    n = 12
    rot = brute.random_rotations(rng, n)
    rot[:3] = np.eye(3)  # pure translations take another path
    poses = brute.poses(rot, rng.uniform(-0.5, 0.5, (n, 3)))
    modes = [(first, rotation) for first in (False, True) for rotation in ("auto", "refit")]
    # The reference: every query alone, with new colliders.
    want = {
        (i, m, k): on_a_new_thread(
            lambda: one_pose_answer(proxima.collide(a, b, poses[k], first=first, rotation=rotation))
        )
        for i, (a, b) in enumerate(cases)
        for m, (first, rotation) in enumerate(modes)
        for k in range(n)
    }
    assert 10 < sum(hit for _, _, hit in want.values()) < len(want)
    # One-pose calls on this thread, cases and modes interleaved.
    for k in range(n):
        for i, (a, b) in enumerate(cases):
            for m, (first, rotation) in enumerate(modes):
                got = one_pose_answer(proxima.collide(a, b, poses[k], first=first, rotation=rotation))
                pairs, counters, hit = want[i, m, k]
                np.testing.assert_array_equal(got[0], pairs)
                np.testing.assert_array_equal(got[1], counters)
                assert got[2] == hit
    # Batches, here and on a pool (its threads keep colliders too).
    for workers in (1, 2, 1, 2):
        for i, (a, b) in enumerate(cases):
            for m, (first, rotation) in enumerate(modes):
                c = proxima.collide(a, b, poses, first=first, rotation=rotation, workers=workers)
                for k in range(n):
                    pairs, counters, hit = want[i, m, k]
                    np.testing.assert_array_equal(c[k], pairs)
                    np.testing.assert_array_equal(c.counters[k], counters)
                    assert c.colliding[k] == hit


def test_contacts_arrays_are_made_once_and_stay_the_callers():
    floor = proxima.Mesh(SQUARE_V, SQUARE_F)
    pose = np.eye(4)
    pose[:3, :3] = rotation_x(0.5)
    pose[:3, 3] = [0.2, 0.2, -0.3]
    want, _ = brute.mesh_pairs(SQUARE_V, SQUARE_F, SQUARE_V, SQUARE_F, pose)
    k = len(want)
    assert k >= 2
    # Before any array is made: len, bool, repr, indexing.
    c = proxima.collide(floor, floor, pose)
    assert len(c) == 1 and bool(c)
    assert repr(c) == f"Contacts(poses=1, colliding=1, pairs={k})"
    assert set(map(tuple, proxima.collide(floor, floor, pose)[0].tolist())) == want
    # Each array: its dtype and shape, C order, writable, the same object each time.
    for name, dtype, shape in [
        ("pairs", np.int64, (k, 2)),
        ("offsets", np.int64, (2,)),
        ("colliding", np.bool_, (1,)),
        ("counters", np.uint64, (1, 3)),
    ]:
        x = getattr(c, name)
        assert x is getattr(c, name), name
        assert x.dtype == dtype and x.shape == shape, name
        assert x.flags.c_contiguous and x.flags.writeable, name
    assert set(map(tuple, c.pairs.tolist())) == want and c.offsets.tolist() == [0, k]
    # What the caller writes into them is what the object answers from.
    c.colliding[0] = False
    assert not c and repr(c) == f"Contacts(poses=1, colliding=0, pairs={k})"
    c.offsets[1] = 1
    np.testing.assert_array_equal(c[0], c.pairs[:1])
    # An empty answer.
    far = pose.copy()
    far[2, 3] = 5.0
    e = proxima.collide(floor, floor, far, first=True)
    assert not e and len(e) == 1 and e.pairs.shape == (0, 2) and e[0].shape == (0, 2)
    assert e.colliding.tolist() == [False] and e.offsets.tolist() == [0, 0]


def test_pose_dtypes_and_layouts_agree(rng):
    a = proxima.Mesh(*soup(rng, 60))
    poses = brute.poses(brute.random_rotations(rng, 10), rng.uniform(-0.5, 0.5, (10, 3)))
    ref = proxima.collide(a, a, poses)
    assert ref.pairs.shape[0] > 10
    # float64 in C order is rounded in Rust; the other forms go through numpy.
    for other in (poses.astype(np.float32), poses.astype(">f8"), np.asfortranarray(poses), poses.tolist()):
        c = proxima.collide(a, a, other)
        np.testing.assert_array_equal(c.pairs, ref.pairs)
        np.testing.assert_array_equal(c.counters, ref.counters)
    for k in range(3):
        np.testing.assert_array_equal(proxima.collide(a, a, poses[k]).pairs, ref[k])
    # The same rounding as numpy's cast, ties and float32's extremes included.
    v = np.concatenate([
        rng.uniform(-1e3, 1e3, 300),
        1 + np.arange(1, 61) * 2.0**-25,  # halfway and quarter points between float32s
        [3.4028234663852886e38, 3.40282350e38, 1.401298464324817e-45, 7e-46, -2.0**-150, 1e-310, 0.0, -0.0],
    ])
    v = np.concatenate([v, np.zeros(-len(v) % 3)]).reshape(-1, 3)
    m = proxima.Mesh(v, np.arange(len(v) - len(v) % 3).reshape(-1, 3))
    np.testing.assert_array_equal(m.vertices.view(np.uint32), v.astype(np.float32).view(np.uint32))
    # Out of float32's range: not finite, as before.
    p = np.eye(4)
    p[0, 3] = 1e300
    with pytest.raises(ValueError, match=r"poses: pose 0 has a non-finite value"):
        proxima.collide(a, a, p)


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
