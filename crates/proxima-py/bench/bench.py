"""Proxima for Python beside the Python libraries its users would otherwise call.

    crates/proxima-py/bench/run.sh            # makes its venv, installs, runs this
    python bench.py [--only collide,pairs,rays] [--repeat N] [--workers N]

- collide: rob.obj vs env.obj over the 1,000 poses of
  crates/proxima-bench/data/rob-env-1000.poses, all intersecting triangle pairs
  and first contact, per pose including the Python call: proxima (one call per
  pose, and one call for the batch) beside python-fcl and coal (OBBRSS trees,
  one `collide` call per pose, as their users write it). Target: proxima <= 0.3x
  python-fcl per pose.
- pairs: all overlapping pairs of 100,000 spheres of equal radius (W1's density)
  with `Index(...).pairs()` beside scipy's `cKDTree.query_pairs` (build + query,
  and query alone). Target: <= 0.5x cKDTree.
- knn: k nearest (k = 1, 10) of 100,000 query points among 100,000 points
  with `Index.nearest(metric="center")` beside `cKDTree.query` (query alone,
  with workers, and build + query). Target: <= 0.5x cKDTree.query.
- rays: closest hits of 100,000 rays on bunny.obj with `Mesh.cast_rays` beside
  Open3D's `RaycastingScene.cast_rays` and trimesh's ray intersector (Embree
  through embreex when installed), each where installable.

Every comparison first checks that the libraries agree on the answers (counts,
or hits and triangles up to ties) and says so. Times are the median of
`--repeat` runs of wall-clock time; the machine should be quiet.
"""

from __future__ import annotations

import argparse
import importlib
import statistics
import sys
import time
from pathlib import Path

import numpy as np

import proxima

ROOT = Path(__file__).resolve().parents[3]
DATA = ROOT.parent / "shared" / "data"
POSES = ROOT / "crates" / "proxima-bench" / "data" / "rob-env-1000.poses"


def median_time(f, repeat):
    """Median wall-clock seconds of `repeat` calls of f (after one warm-up)."""
    f()
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        f()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def optional(name):
    try:
        return importlib.import_module(name)
    except Exception as e:  # not installable here, or broken
        print(f"  ({name} not available: {type(e).__name__}: {e})")
        return None


def version(mod):
    try:
        from importlib.metadata import version as v

        return v(mod)
    except Exception:
        return "?"


def row(name, seconds, per, unit, base=None):
    ratio = f"{seconds / base:6.2f}x" if base else ""
    print(f"  {name:<44} {seconds * 1e3:10.2f} ms   {seconds / per * 1e6:10.2f} us/{unit}  {ratio}")


# --- mesh collide ------------------------------------------------------------


def load_poses():
    rows = np.loadtxt(POSES)
    p = np.zeros((len(rows), 4, 4))
    p[:, :3, :3] = rows[:, :9].reshape(-1, 3, 3)
    p[:, :3, 3] = rows[:, 9:]
    p[:, 3, 3] = 1
    return p


def bench_collide(args):
    print("\n## collide: rob.obj (216 triangles) vs env.obj (2,180), 1,000 poses")
    rob = proxima.Mesh.load(DATA / "rob.obj")
    env = proxima.Mesh.load(DATA / "env.obj")
    poses = load_poses()
    n = len(poses)
    batch = proxima.collide(rob, env, poses)
    counts = np.diff(batch.offsets)
    print(f"  proxima: {int((counts > 0).sum())} colliding poses, {int(counts.sum())} triangle pairs")

    def per_call(first):
        for p in poses:
            proxima.collide(rob, env, p, first=first)

    results = {}
    t_all = median_time(lambda: per_call(False), args.repeat)
    t_first = median_time(lambda: per_call(True), args.repeat)
    t_batch = median_time(lambda: proxima.collide(rob, env, poses), args.repeat)
    t_batch_w = median_time(lambda: proxima.collide(rob, env, poses, workers=args.workers), args.repeat)
    results["proxima"] = (t_all, t_first)

    peers = {}
    fcl = optional("fcl")
    if fcl is not None:
        peers["python-fcl " + version("python-fcl")] = fcl_like(fcl, rob, env, poses, coal=False)
    coal = optional("coal")
    if coal is not None:
        peers["coal " + version("coal")] = fcl_like(coal, rob, env, poses, coal=True)
    base_all = base_first = None
    for name, (check, run) in peers.items():
        colliding, contacts = check()
        agree = np.array_equal(colliding, counts > 0)
        same_counts = int((contacts == counts).sum())
        print(
            f"  {name}: colliding poses {'agree' if agree else 'DISAGREE'} "
            f"({int(colliding.sum())}); equal pair counts on {same_counts}/{n} poses"
        )
        ta = median_time(lambda: run(False), args.repeat)
        tf = median_time(lambda: run(True), args.repeat)
        results[name] = (ta, tf)
        if base_all is None:
            base_all, base_first = ta, tf
    print("  all intersecting pairs, one call per pose:")
    for name, (ta, _) in results.items():
        row(name, ta, n, "pose", base_all)
    row(f"proxima, one call for the batch", t_batch, n, "pose", base_all)
    row(f"proxima, batch, workers={args.workers}", t_batch_w, n, "pose", base_all)
    print("  first contact (yes/no), one call per pose:")
    for name, (_, tf) in results.items():
        row(name, tf, n, "pose", base_first)


def fcl_like(lib, rob, env, poses, coal):
    """(check, run) for python-fcl or coal: OBBRSS models, one collide call per
    pose (set the transform, collide) as their users write it."""

    def model(m):
        if coal:
            # coal's beginModel takes (triangles, vertices); its arrays go in
            # through addVertices / addTriangles.
            b = lib.BVHModelOBBRSS()
            b.beginModel(m.n_triangles, m.n_vertices)
            b.addVertices(m.vertices.astype(np.float64))
            b.addTriangles(m.faces.astype(np.int32))
        else:
            b = lib.BVHModel()
            b.beginModel(m.n_vertices, m.n_triangles)
            b.addSubModel(m.vertices.astype(np.float64), m.faces.astype(np.int32))
        b.endModel()
        return b

    ma, mb = model(rob), model(env)
    if coal:
        ident = lib.Transform3s()

        def one(p, first):
            req = lib.CollisionRequest()
            req.num_max_contacts = 1 if first else 100_000
            res = lib.CollisionResult()
            lib.collide(ma, lib.Transform3s(p[:3, :3], p[:3, 3]), mb, ident, req, res)
            return res.isCollision(), res.numContacts()

    else:
        oa = lib.CollisionObject(ma, lib.Transform())
        ob = lib.CollisionObject(mb, lib.Transform())
        all_req = lib.CollisionRequest(num_max_contacts=100_000, enable_contact=True)
        first_req = lib.CollisionRequest(num_max_contacts=1)

        def one(p, first):
            oa.setTransform(lib.Transform(p[:3, :3], p[:3, 3]))
            res = lib.CollisionResult()
            n = lib.collide(oa, ob, first_req if first else all_req, res)
            return res.is_collision, n

    def check():
        out = [one(p, False) for p in poses]
        return np.array([c for c, _ in out]), np.array([k for _, k in out])

    def run(first):
        for p in poses:
            one(p, first)

    return check, run


# --- pairs -------------------------------------------------------------------


def bench_pairs(args):
    n, r = 100_000, 1.0
    # W1's density: 50,000 spheres of mean radius 1.25 in a cube of side 147.4.
    side = 147.4 * (n / 50_000) ** (1 / 3)
    print(f"\n## pairs: {n:,} spheres of radius {r} in a cube of side {side:.1f}")
    rng = np.random.default_rng(1)
    c = rng.uniform(0, side, (n, 3))
    spatial = optional("scipy.spatial")
    results = {}
    for kind in ("grid3d", "loose-kd"):
        idx = proxima.Index(c, r, kind=kind)
        p = idx.pairs(sort=False)
        build = median_time(lambda: proxima.Index(c, r, kind=kind), args.repeat)
        query = median_time(lambda: idx.pairs(sort=False), args.repeat)
        query_w = median_time(lambda: idx.pairs(sort=False, workers=args.workers), args.repeat)
        results[kind] = (len(p), build, query, query_w)
    base = None
    if spatial is not None:
        tree = spatial.cKDTree(c)
        want = tree.query_pairs(2 * r, output_type="ndarray")
        print(f"  scipy {version('scipy')}: {len(want):,} pairs")
        b = median_time(lambda: spatial.cKDTree(c), args.repeat)
        q = median_time(lambda: tree.query_pairs(2 * r, output_type="ndarray"), args.repeat)
        base = (b + q, q)
    for kind, (count, b, q, qw) in results.items():
        agree = "" if base is None else ("agree" if count == len(want) else f"DISAGREE ({len(want)})")
        print(f"  proxima {kind}: {count:,} pairs {agree}")
    print("  build + all pairs:")
    if base:
        row("cKDTree + query_pairs", base[0], n, "sphere", base[0])
    for kind, (_, b, q, _) in results.items():
        row(f"proxima Index({kind}) + pairs", b + q, n, "sphere", base and base[0])
    print("  all pairs of a built structure:")
    if base:
        row("cKDTree.query_pairs", base[1], n, "sphere", base[1])
    for kind, (_, _, q, qw) in results.items():
        row(f"proxima {kind} pairs()", q, n, "sphere", base and base[1])
        row(f"proxima {kind} pairs(workers={args.workers})", qw, n, "sphere", base and base[1])


def bench_knn(args):
    n = m = 100_000
    print(f"\n## knn: {n:,} points, {m:,} query points (uniform in a unit cube), k = 1 and 10")
    rng = np.random.default_rng(3)
    c = rng.uniform(0, 1, (n, 3))
    q = rng.uniform(0, 1, (m, 3))
    spatial = optional("scipy.spatial")
    kinds = ("loose-kd", "grid3d", "octree")
    for k in (1, 10):
        print(f"  k = {k}:")
        base = None
        timings = {}
        if spatial is not None:
            tree = spatial.cKDTree(c)
            wd, wi = tree.query(q, k)
            b = median_time(lambda: spatial.cKDTree(c), args.repeat)
            t = median_time(lambda: tree.query(q, k), args.repeat)
            tw = median_time(lambda: tree.query(q, k, workers=args.workers), args.repeat)
            base = t
            timings[f"scipy {version('scipy')} cKDTree.query"] = t
            timings[f"cKDTree.query(workers={args.workers})"] = tw
            timings["cKDTree build + query"] = b + t
        for kind in kinds:
            idx = proxima.Index(c, 0.0, kind=kind)
            d, i = idx.nearest(q, k, metric="center")
            if spatial is not None:
                # Distances are float32 here, float64 in scipy: ids may differ
                # only between neighbours within float32 rounding of a tie.
                same = (i == wi).mean()
                close = np.allclose(d, wd, rtol=1e-6, atol=1e-7)
                print(f"  proxima {kind}: same ids as cKDTree on {same:.4%}, distances {'agree' if close else 'DISAGREE'}")
            t = median_time(lambda: idx.nearest(q, k, metric="center"), args.repeat)
            tw = median_time(lambda: idx.nearest(q, k, metric="center", workers=args.workers), args.repeat)
            b = median_time(lambda: proxima.Index(c, 0.0, kind=kind), args.repeat)
            timings[f"proxima {kind} nearest"] = t
            timings[f"proxima {kind} nearest(workers={args.workers})"] = tw
            timings[f"proxima {kind} build + nearest"] = b + t
        for name, s in timings.items():
            row(name, s, m, "query", base)


# --- rays --------------------------------------------------------------------


def bench_rays(args):
    mesh = proxima.Mesh.load(DATA / "bunny.obj")
    n = 100_000
    print(f"\n## rays: {n:,} rays at bunny.obj ({mesh.n_triangles:,} triangles), closest hit")
    rng = np.random.default_rng(2)
    lo, hi = mesh.aabb
    o = rng.uniform(lo - (hi - lo), hi + (hi - lo), (n, 3))
    rays = np.column_stack([o, rng.uniform(lo, hi, (n, 3)) - o]).astype(np.float32)
    ours = mesh.cast_rays(rays)
    hit = ours["primitive_ids"] >= 0
    print(f"  proxima: {int(hit.sum()):,} hits")
    t = median_time(lambda: mesh.cast_rays(rays), args.repeat)
    tw = median_time(lambda: mesh.cast_rays(rays, workers=args.workers), args.repeat)
    timings = {}
    o3d = optional("open3d")
    if o3d is not None:
        scene = o3d.t.geometry.RaycastingScene()
        scene.add_triangles(
            o3d.core.Tensor(mesh.vertices), o3d.core.Tensor(mesh.faces.astype(np.uint32))
        )
        r = o3d.core.Tensor(rays)
        ans = scene.cast_rays(r)
        ids = ans["primitive_ids"].numpy().astype(np.int64)
        ids[ids == 4294967295] = -1
        same = (ids == ours["primitive_ids"]).mean()
        print(f"  open3d {version('open3d')}: same triangle on {same:.4%} of rays")
        timings[f"open3d {version('open3d')} RaycastingScene"] = median_time(
            lambda: scene.cast_rays(r), args.repeat
        )
    trimesh = optional("trimesh")
    if trimesh is not None:
        tm = trimesh.Trimesh(mesh.vertices, mesh.faces, process=False)
        name = type(tm.ray).__name__
        dirs = rays[:, 3:] / np.linalg.norm(rays[:, 3:], axis=1, keepdims=True)
        tri = tm.ray.intersects_first(rays[:, :3], dirs)
        same = (tri == ours["primitive_ids"]).mean()
        print(f"  trimesh {version('trimesh')} ({name}): same triangle on {same:.4%} of rays")
        timings[f"trimesh {name}.intersects_first"] = median_time(
            lambda: tm.ray.intersects_first(rays[:, :3], dirs), args.repeat
        )
    base = next(iter(timings.values()), None)
    for name, s in timings.items():
        row(name, s, n, "ray", base)
    row("proxima Mesh.cast_rays", t, n, "ray", base)
    row(f"proxima Mesh.cast_rays(workers={args.workers})", tw, n, "ray", base)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--only", default="collide,pairs,knn,rays")
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--workers", type=int, default=2)
    args = ap.parse_args()
    print(f"proxima {proxima.__version__}, numpy {np.__version__}, Python {sys.version.split()[0]}")
    for part in args.only.split(","):
        {"collide": bench_collide, "pairs": bench_pairs, "knn": bench_knn, "rays": bench_rays}[part](args)


if __name__ == "__main__":
    main()
