"""numpy brute-force oracles for the tests: every answer computed from scratch,
in float64, on the float32 values the library stores.

Sphere, box and ray selections are decided exactly by the library; float64 on
float32 inputs decides them too except within ~1e-15 relative of a tie, which
random data never hits. Frusta, triangle pairs and ray-triangle hits involve
rounded intermediate values on the library's side (normalized planes, posed
vertices), so those oracles return, beside the answer, the cases too close to
call (within a small band), and tests accept either answer only there.
"""

from __future__ import annotations

import numpy as np


def f32(a) -> np.ndarray:
    """The float32 values the library stores, as float64."""
    return np.asarray(a, dtype=np.float32).astype(np.float64)


def pairs(centers, radii) -> np.ndarray:
    """Every overlapping pair (i < j), sorted, (P, 2) int64."""
    c, r = f32(centers), f32(radii)
    out = []
    for i in range(len(c) - 1):
        d2 = ((c[i + 1 :] - c[i]) ** 2).sum(axis=1)
        rs = r[i + 1 :] + r[i]
        j = np.nonzero(d2 <= rs * rs)[0] + i + 1
        out.append(np.stack([np.full(len(j), i), j], axis=1))
    if not out:
        return np.zeros((0, 2), dtype=np.int64)
    return np.concatenate(out).astype(np.int64)


def sphere_query(centers, radii, q) -> np.ndarray:
    """Rows whose sphere overlaps the sphere q = (x, y, z, r), ascending."""
    c, r, q = f32(centers), f32(radii), f32(q)
    d2 = ((c - q[:3]) ** 2).sum(axis=1)
    rs = r + q[3]
    return np.nonzero(d2 <= rs * rs)[0]


def box_query(centers, radii, b) -> np.ndarray:
    """Rows whose sphere overlaps the box b = (min xyz, max xyz), ascending."""
    c, r, b = f32(centers), f32(radii), f32(b)
    p = np.clip(c, b[:3], b[3:])
    d2 = ((c - p) ** 2).sum(axis=1)
    return np.nonzero(d2 <= r * r)[0]


def ray_query(centers, radii, ray, tmax=np.inf):
    """Rows whose sphere the ray (o, d) touches for t in [0, tmax], and each
    one's entry t (0 when the origin is inside)."""
    c, r, ray = f32(centers), f32(radii), f32(ray)
    o, d = ray[:3], ray[3:]
    tmax = float(np.float32(tmax))
    m = o - c
    mm = (m * m).sum(axis=1)
    b = m @ d
    a = d @ d
    inside = mm <= r * r
    disc = b * b - a * (mm - r * r)
    with np.errstate(invalid="ignore"):
        t_in = (-b - np.sqrt(np.maximum(disc, 0.0))) / a
    t_closest = -b / a
    closest_ok = t_closest <= tmax
    cross2 = (np.cross(m, d) ** 2).sum(axis=1)
    end = m + tmax * d if np.isfinite(tmax) else m
    end2 = (end * end).sum(axis=1)
    approaching = b < 0
    hit = inside | (
        approaching
        & np.where(closest_ok, cross2 <= r * r * a, np.isfinite(tmax) & (end2 <= r * r))
    )
    t = np.where(inside, 0.0, t_in)
    rows = np.nonzero(hit)[0]
    return rows, t[rows]


def frustum_planes(m, depth="zero_to_one") -> np.ndarray:
    """The six inward planes (n, d) of a view-projection matrix (rows of m act
    on column vectors), normalized, as a (6, 4) float64 array."""
    m = f32(m)
    if depth == "minus_one_to_one":
        c = np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 0.5, 0.5], [0, 0, 0, 1]])
        m = c @ m
    r0, r1, r2, r3 = m
    p = np.array([r3 + r0, r3 - r0, r3 + r1, r3 - r1, r2, r3 - r2])
    return p / np.linalg.norm(p[:, :3], axis=1)[:, None]


def frustum_query(centers, radii, m, depth="zero_to_one", band=1e-4):
    """(kept, unsure): rows certainly kept (not entirely outside any plane by
    more than `band`·scale), and rows within the band of a plane."""
    c, r = f32(centers), f32(radii)
    p = frustum_planes(m, depth)
    s = c @ p[:, :3].T + p[:, 3] + r[:, None]  # >= 0: not outside that plane
    worst = s.min(axis=1)
    scale = 1.0 + np.abs(c).max(axis=1) + r
    kept = np.nonzero(worst > band * scale)[0]
    unsure = np.nonzero(np.abs(worst) <= band * scale)[0]
    return kept, unsure


def transform(pose, points) -> np.ndarray:
    """Points moved by a (3, 4) or (4, 4) pose, computed as the library does
    (float32 pose on float32 points), returned as float64."""
    pose = f32(pose)
    return f32(f32(points) @ pose[:3, :3].T + pose[:3, 3])


def _axes(t1, t2):
    """Candidate separating axes of triangle pairs: (n, 17, 3)."""
    e1 = np.stack([t1[:, 1] - t1[:, 0], t1[:, 2] - t1[:, 1], t1[:, 0] - t1[:, 2]], axis=1)
    e2 = np.stack([t2[:, 1] - t2[:, 0], t2[:, 2] - t2[:, 1], t2[:, 0] - t2[:, 2]], axis=1)
    n1 = np.cross(e1[:, 0], e1[:, 1])
    n2 = np.cross(e2[:, 0], e2[:, 1])
    cross = np.cross(e1[:, :, None, :], e2[:, None, :, :]).reshape(-1, 9, 3)
    in1 = np.cross(n1[:, None, :], e1)
    in2 = np.cross(n2[:, None, :], e2)
    return np.concatenate([n1[:, None], n2[:, None], cross, in1, in2], axis=1)


def triangle_pairs(tris_a, tris_b, band=1e-6, chunk=200_000):
    """(hit, unsure) for triangle pairs tris_a[k] vs tris_b[k], (n, 3, 3)
    float64: the separating axis test over the 17 candidate axes (two normals,
    nine edge crosses, six in-plane edge normals), complete for closed
    non-degenerate triangles. `unsure` marks pairs whose best separation is
    within band·scale² of zero."""
    hits, unsures = [], []
    for s in range(0, len(tris_a), chunk):
        t1, t2 = tris_a[s : s + chunk], tris_b[s : s + chunk]
        ax = _axes(t1, t2)
        norm = np.linalg.norm(ax, axis=2)
        p1 = np.einsum("nkd,nvd->nkv", ax, t1)
        p2 = np.einsum("nkd,nvd->nkv", ax, t2)
        gap = np.maximum(p2.min(2) - p1.max(2), p1.min(2) - p2.max(2))
        ok = norm > 0
        gap = np.where(ok, gap / np.where(ok, norm, 1.0), -np.inf)
        sep = gap.max(axis=1)
        scale = 1.0 + np.abs(np.concatenate([t1, t2], axis=1)).reshape(len(t1), -1).max(1)
        hits.append(sep < 0)
        unsures.append(np.abs(sep) <= band * scale)
    return np.concatenate(hits), np.concatenate(unsures)


def mesh_pairs(va, fa, vb, fb, pose, band=1e-6):
    """(hits, unsure): sets of (i, j) triangle pairs of mesh a moved by `pose`
    against mesh b, certainly intersecting and too close to call."""
    ta = transform(pose, va)[fa]
    tb = f32(vb)[fb]
    ia, ib = np.meshgrid(np.arange(len(fa)), np.arange(len(fb)), indexing="ij")
    ia, ib = ia.ravel(), ib.ravel()
    hit, unsure = triangle_pairs(ta[ia], tb[ib], band)
    to_set = lambda mask: set(zip(ia[mask].tolist(), ib[mask].tolist()))
    return to_set(hit & ~unsure), to_set(unsure)


def ray_mesh(vertices, faces, rays, tmax=np.inf):
    """Closest hits by Möller–Trumbore over every triangle: (t, tri, unsure,
    tie) per ray; t inf and tri -1 for a miss; unsure where an edge, a vertex,
    the ray's end or a second triangle at nearly the same t (tie: overlapping
    coplanar triangles) could change the answer."""
    tri = f32(vertices)[faces]  # (F, 3, 3)
    rays = f32(rays)
    tmax = np.broadcast_to(f32(tmax), (len(rays),))[:, None]
    o, d = rays[:, None, :3], rays[:, None, 3:]
    a, e1, e2 = tri[None, :, 0], tri[None, :, 1] - tri[None, :, 0], tri[None, :, 2] - tri[None, :, 0]
    p = np.cross(d, e2)
    det = (e1 * p).sum(-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / det
        s = o - a
        u = (s * p).sum(-1) * inv
        q = np.cross(s, e1)
        v = (d * q).sum(-1) * inv
        t = (e2 * q).sum(-1) * inv
    bary = np.minimum(np.minimum(u, v), 1.0 - u - v)
    valid = np.isfinite(t) & (np.abs(det) > 0)
    hit = valid & (bary >= 0) & (t >= 0) & (t <= tmax)
    tt = np.where(hit, t, np.inf)
    best = tt.argmin(axis=1)
    rows = np.arange(len(rays))
    tbest = tt[rows, best]
    ids = np.where(np.isfinite(tbest), best, -1)
    # What could change the answer: a triangle no farther than the best hit
    # (or than tmax) passed within `eps` of an edge, touched near t = 0 or
    # near tmax, or a second hit at nearly the same t.
    eps = 1e-5
    reach = np.minimum(tmax[:, 0], tbest)[:, None] * (1 + eps) + eps
    edge = valid & (np.abs(bary) <= eps) & (t >= -eps) & (t <= reach)
    with np.errstate(invalid="ignore"):
        at_end = np.isfinite(tmax) & (np.abs(t - tmax) <= eps * (1 + np.abs(tmax)))
    ends = valid & (bary >= -eps) & ((np.abs(t) <= eps) | at_end)
    second = np.partition(tt, 1, axis=1)[:, 1] if tt.shape[1] > 1 else np.full(len(rays), np.inf)
    with np.errstate(invalid="ignore"):
        tie = np.isfinite(tbest) & (second - tbest <= eps * (1 + tbest))
    unsure = edge.any(axis=1) | ends.any(axis=1) | tie
    return tbest, ids, unsure, tie


def random_rotations(rng, n) -> np.ndarray:
    """n uniformly random rotation matrices (from unit quaternions)."""
    q = rng.normal(size=(n, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    w, x, y, z = q.T
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], -1),
            np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], -1),
            np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], -1),
        ],
        axis=1,
    )


def poses(rotations, translations) -> np.ndarray:
    """(N, 4, 4) float32 poses from (N, 3, 3) rotations and (N, 3) translations."""
    n = len(rotations)
    p = np.zeros((n, 4, 4))
    p[:, :3, :3] = rotations
    p[:, :3, 3] = translations
    p[:, 3, 3] = 1.0
    return p.astype(np.float32)


def csr_lists(ids, offsets):
    """CSR (ids, offsets) as a list of arrays."""
    return [ids[offsets[i] : offsets[i + 1]] for i in range(len(offsets) - 1)]


def point_triangle_distance(p, tris) -> np.ndarray:
    """Distance from the point p (3,) to each closed triangle of tris (F, 3, 3),
    float64: the plane distance when p projects inside, else the nearest edge."""
    p = np.asarray(p, dtype=np.float64)
    a, b, c = tris[:, 0], tris[:, 1], tris[:, 2]
    n = np.cross(b - a, c - a)
    nn = (n * n).sum(1)
    s = ((p - a) * n).sum(1) / nn
    q = p - s[:, None] * n
    side = lambda u, v: (np.cross(v - u, q - u) * n).sum(1) >= 0
    inside = side(a, b) & side(b, c) & side(c, a)

    def segment(u, v):
        e = v - u
        t = np.clip(((p - u) * e).sum(1) / (e * e).sum(1), 0.0, 1.0)
        return np.linalg.norm(p - (u + t[:, None] * e), axis=1)

    edges = np.minimum(np.minimum(segment(a, b), segment(b, c)), segment(c, a))
    return np.where(inside, np.abs(s) * np.sqrt(nn), edges)


class BruteWorld:
    """The collision world from scratch: every object pair, every primitive
    pair, in float64 on the float32 values the library stores, with the cases
    too close to call (within a band) reported beside the answers.

    Objects: id -> (mesh (vertices, faces) or ball radius, (4, 4) pose,
    group, mask). Meshes are surfaces, balls solid; a ball's centre is its
    pose's translation."""

    def __init__(self):
        self.objects = {}
        self.ignored = set()

    def add(self, i, shape, pose, group=0xFFFFFFFF, mask=0xFFFFFFFF):
        self.objects[i] = [shape, f32(pose), group, mask]

    def remove(self, i):
        del self.objects[i]
        self.ignored = {p for p in self.ignored if i not in p}

    def interacts(self, i, j):
        _, _, ga, ma = self.objects[i]
        _, _, gb, mb = self.objects[j]
        return (ga & mb) != 0 and (gb & ma) != 0

    @staticmethod
    def passes(o, group, mask):
        return (o[2] & mask) != 0 and (group & o[3]) != 0

    def world_triangles(self, i):
        shape, pose, _, _ = self.objects[i]
        v, f = shape
        return transform(pose, v)[f]

    def bound(self, i):
        """A ball around the posed shape: (centre, radius)."""
        shape, pose, _, _ = self.objects[i]
        if isinstance(shape, float):
            return pose[:3, 3], shape
        v = f32(shape[0])
        c = (v.min(0) + v.max(0)) / 2
        return pose[:3, :3] @ c + pose[:3, 3], np.linalg.norm(v - c, axis=1).max()

    def pair(self, i, j, band=1e-5):
        """(certain, unsure) sets of primitive pairs (of i, of j)."""
        si, pi = self.objects[i][:2]
        sj, pj = self.objects[j][:2]
        ball_i, ball_j = isinstance(si, float), isinstance(sj, float)
        if ball_i and ball_j:
            d = np.linalg.norm(pi[:3, 3] - pj[:3, 3]) - (si + sj)
            scale = 1 + np.abs(pi[:3, 3]).max() + np.abs(pj[:3, 3]).max()
            return ({(0, 0)} if d < -band * scale else set()), (
                {(0, 0)} if abs(d) <= band * scale else set()
            )
        if ball_i or ball_j:
            ball, mesh = (i, j) if ball_i else (j, i)
            r = self.objects[ball][0]
            centre = self.objects[ball][1][:3, 3]
            tris = self.world_triangles(mesh)
            d = point_triangle_distance(centre, tris) - r
            scale = 1 + np.abs(tris).max() + r
            sure = np.nonzero(d < -band * scale)[0]
            near = np.nonzero(np.abs(d) <= band * scale)[0]
            key = (lambda t: (0, int(t))) if ball_i else (lambda t: (int(t), 0))
            return {key(t) for t in sure}, {key(t) for t in near}
        # Mesh i moved into mesh j's frame.
        rel = np.linalg.inv(pj.astype(np.float64)) @ pi
        return mesh_pairs(si[0], si[1], sj[0], sj[1], rel, band=band)

    def contacts(self):
        """{(i, j): (certain, unsure)} over pairs i < j that may touch."""
        ids = sorted(self.objects)
        out = {}
        for k, i in enumerate(ids):
            ci, ri = self.bound(i)
            for j in ids[k + 1 :]:
                if (i, j) in self.ignored or not self.interacts(i, j):
                    continue
                cj, rj = self.bound(j)
                if np.linalg.norm(ci - cj) > (ri + rj) * 1.01 + 1e-3:
                    continue
                sure, unsure = self.pair(i, j)
                if sure or unsure:
                    out[(i, j)] = (sure, unsure)
        return out

    def near(self, q, group=0xFFFFFFFF, mask=0xFFFFFFFF, band=1e-5):
        """(certain, unsure) ids with a point within q[3] of q[:3]."""
        q = f32(q)
        sure, unsure = set(), set()
        for i, o in self.objects.items():
            if not self.passes(o, group, mask):
                continue
            shape, pose = o[:2]
            if isinstance(shape, float):
                d = np.linalg.norm(q[:3] - pose[:3, 3]) - (shape + q[3])
                scale = 1 + np.abs(pose[:3, 3]).max() + shape
            else:
                tris = self.world_triangles(i)
                d = point_triangle_distance(q[:3], tris).min() - q[3]
                scale = 1 + np.abs(tris).max()
            scale += np.abs(q).max()
            if d < -band * scale:
                sure.add(i)
            elif abs(d) <= band * scale:
                unsure.add(i)
        return sure, unsure

    def ray(self, ray, tmax=np.inf, group=0xFFFFFFFF, mask=0xFFFFFFFF):
        """Per object hit: {id: (t, triangle, unsure)}."""
        out = {}
        for i, o in self.objects.items():
            if not self.passes(o, group, mask):
                continue
            shape, pose = o[:2]
            if isinstance(shape, float):
                rows, t = ray_query(pose[None, :3, 3], [shape], ray, tmax)
                if len(rows):
                    out[i] = (t[0], 0, False)
            else:
                v = transform(pose, shape[0])
                t, tri, unsure, _ = ray_mesh(v, shape[1], np.asarray(ray)[None], tmax)
                if np.isfinite(t[0]) or unsure[0]:
                    out[i] = (t[0], int(tri[0]), bool(unsure[0]))
        return out


def knn(centers, radii, q, k, bound=np.inf, metric="surface", admit=None):
    """The k nearest rows to the point q: `(distances, ids)` padded to k with
    inf / -1, nearest first, ties by smaller row. Each distance is the float64
    value on the stored float32 numbers rounded to float32, which is the
    library's correctly rounded one except within ~1e-16 relative of a
    rounding midpoint (never met by the seeded data). `admit`: a boolean mask
    of the rows that may answer (a filter)."""
    c, r, q = f32(centers), f32(radii), f32(q)
    d = np.sqrt(((c - q) ** 2).sum(axis=1))
    if metric == "surface":
        d = np.maximum(d - r, 0.0)
    d = d.astype(np.float32)
    ok = d <= np.float32(bound)
    if admit is not None:
        ok &= admit
    rows = np.nonzero(ok)[0]
    order = rows[np.lexsort((rows, d[rows]))][:k]
    dist = np.full(k, np.inf, dtype=np.float32)
    ids = np.full(k, -1, dtype=np.int64)
    dist[: len(order)] = d[order]
    ids[: len(order)] = order
    return dist, ids


def sweep(centers, radii, a, b, radius, band=1e-4):
    """A sphere of `radius` moving from a (t = 0) to b (t = 1) against every
    row, closed form in float64: `(t, sure)` where t (N,) is each row's time
    of first contact (inf for a miss) and `sure` (N,) marks the rows decided
    with margin (the segment's distance to the centre is not within `band` of
    the radii's sum); elsewhere either answer is accepted."""
    c, r = f32(centers), f32(radii)
    a, b, rs = f32(a), f32(b), f32(radii) + float(np.float32(radius))
    d = b - a
    m = a - c
    dd = d @ d
    mm = (m * m).sum(axis=1)
    # The segment's closest point to each centre, for the margin.
    s = np.clip(-(m @ d) / dd, 0.0, 1.0) if dd > 0 else np.zeros(len(c))
    gap = np.sqrt(((m + s[:, None] * d) ** 2).sum(axis=1)) - rs
    hit = gap <= 0
    if dd > 0:
        half_b = m @ d
        disc = np.maximum(half_b * half_b - dd * (mm - rs * rs), 0.0)
        t = (-half_b - np.sqrt(disc)) / dd
    else:
        t = np.zeros(len(c))
    t = np.where(mm <= rs * rs, 0.0, t)
    t = np.where(hit, np.clip(t, 0.0, 1.0), np.inf)
    return t, np.abs(gap) > band * np.maximum(1.0, rs)


def interacts(g1, m1, g2, m2):
    """The two-way filter rule, elementwise."""
    return ((np.asarray(g1) & np.asarray(m2)) != 0) & ((np.asarray(g2) & np.asarray(m1)) != 0)
