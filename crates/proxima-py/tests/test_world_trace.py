"""proxima.World replays the shared world trace (`shared/traces/world/small.trace`,
design.md §7.1) and gives the oracle's answers (`small.expected`, with its
tolerances), as `proxima world` must: bunny, teapot and rob meshes at random
poses, three crates touching face to face and along an edge, ignored pairs, a
removal and a re-add of an id, rays and sphere queries."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import ROOT

import proxima

TRACES = ROOT.parent / "shared" / "traces" / "world"


def expected(path, first):
    rows = []
    for line in path.read_text().splitlines():
        t = line.split()
        if not t or t[0].startswith("#"):
            continue
        if t[0] == "contacts":
            if not first:
                rows.append(("contacts", *map(int, t[1:5])))
        elif t[0] == "contacts-first":
            if first:
                rows.append(("contacts", int(t[1]), int(t[2])))
        elif t[0] == "ray":
            rows.append(("ray", *(t[1:] if t[1] in "-*" else map(int, t[1:3]))))
        else:
            rows.append(("sphere", int(t[1]), int(t[2])))
    return rows


def replay(trace, index, bv, first):
    """Runs the trace on a World; returns its answer rows in expected()'s form."""
    meshes, world, ids, users = {}, proxima.World(index=index, bv=bv), {}, {}
    out = []
    for line in trace.read_text().splitlines():
        t = line.split()
        if not t or t[0].startswith("#"):
            continue
        op = t[0]
        if op == "mesh":
            meshes[t[1]] = proxima.Mesh.load(trace.parent / t[2], bv=bv)
        elif op == "add":
            i = world.add(meshes[t[2]])
            ids[int(t[1])] = i
            users[i] = int(t[1])
        elif op == "pose":
            v = np.array(t[2:], dtype=np.float64)
            pose = np.hstack([v[:9].reshape(3, 3), v[9:, None]])
            world.set_pose(ids[int(t[1])], pose)
        elif op == "remove":
            world.remove(ids.pop(int(t[1])))
        elif op == "ignore":
            world.ignore(ids[int(t[1])], ids[int(t[2])])
        elif op == "contacts":
            c = world.contacts(first=first)
            for k in range(len(c)):  # distinct pairs within each object pair
                assert len(set(map(tuple, c[k].tolist()))) == len(c[k])
            out.append(("contacts", len(c), len(c.triangles)))
        elif op == "ray":
            v = [float(x) for x in t[1:]]
            r = world.ray_cast([v[:6]], v[6])
            g = int(r["geometry_ids"][0])
            out.append(("ray", users[g], int(r["primitive_ids"][0])) if g >= 0 else ("ray", "-"))
        elif op == "sphere":
            ids_, _ = world.overlap_sphere([float(x) for x in t[1:5]])
            out.append(("sphere", len(ids_)))
        else:
            raise AssertionError(f"unknown trace line {line!r}")
    return out


@pytest.mark.parametrize(
    "index,bv,first",
    [(None, "kdop18", False), (None, "kdop18", True), ("grid3d", "obb", False), ("brute", "sphere", True)],
)
def test_small_trace_matches_the_oracle(index, bv, first):
    trace = TRACES / "small.trace"
    assert trace.is_file(), f"the shared world trace is missing: {trace}"
    want = expected(TRACES / "small.expected", first)
    got = replay(trace, index, bv, first)
    assert len(got) == len(want) and len(want) > 40
    for k, (g, w) in enumerate(zip(got, want)):
        assert g[0] == w[0], k
        if w[0] == "contacts":
            assert abs(g[1] - w[1]) <= w[2], (k, g, w)
            if not first:
                assert abs(g[2] - w[3]) <= w[4], (k, g, w)
        elif w[0] == "ray":
            assert w[1] == "*" or g[1:] == w[1:], (k, g, w)
        else:
            assert abs(g[1] - w[1]) <= w[2], (k, g, w)
