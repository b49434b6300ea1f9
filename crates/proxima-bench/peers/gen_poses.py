#!/usr/bin/env python3
"""Random relative poses of two meshes in the pose-file format (design §4.2).

usage: gen_poses.py A B N [SEED] > FILE

Drawn like the W5 bench's generated poses (`proxima-bench` w5/poses.rs): rotation
uniform over SO(3) (Shoemake), A's box centre placed uniformly in a cube of half
side 0.6 (ra + rb) around B's box centre (ra, rb: half the box diagonals), so most
poses overlap the bounding spheres and many intersect. Not the same random stream
as the Rust bench: for validating the peer harnesses against `proxima collide`.
Every number is an f32 printed with 9 significant digits (it reads back exactly).
"""
import math
import random
import struct
import sys


def f32(x):
    return struct.unpack("<f", struct.pack("<f", x))[0]


def vertices(path):
    data = open(path, "rb").read()
    if path.lower().endswith(".stl"):
        if len(data) >= 84:
            (n,) = struct.unpack_from("<I", data, 80)
            if len(data) == 84 + 50 * n:
                for i in range(n):
                    for c in range(3):
                        yield struct.unpack_from("<3f", data, 84 + 50 * i + 12 + 12 * c)
                return
        for line in data.decode(errors="replace").splitlines():
            w = line.split()
            if w and w[0] == "vertex":
                yield tuple(float(x) for x in w[1:4])
        return
    for line in data.decode(errors="replace").splitlines():
        w = line.split("#", 1)[0].split()
        if w and w[0] == "v":
            yield tuple(float(x) for x in w[1:4])


def bounds(path):
    lo = [math.inf] * 3
    hi = [-math.inf] * 3
    for v in vertices(path):
        for k in range(3):
            lo[k] = min(lo[k], v[k])
            hi[k] = max(hi[k], v[k])
    c = [(lo[k] + hi[k]) / 2 for k in range(3)]
    r = math.sqrt(sum((hi[k] - lo[k]) ** 2 for k in range(3))) / 2
    return c, r


def main():
    if len(sys.argv) not in (4, 5):
        sys.exit(__doc__.strip().splitlines()[2])
    a, b, n = sys.argv[1], sys.argv[2], int(sys.argv[3])
    rng = random.Random(int(sys.argv[4]) if len(sys.argv) == 5 else 5)
    (ca, ra), (cb, rb) = bounds(a), bounds(b)
    h = 0.6 * (ra + rb)
    for _ in range(n):
        u1, u2, u3 = rng.random(), rng.random(), rng.random()
        s1, s2 = math.sqrt(1 - u1), math.sqrt(u1)
        x, y = s1 * math.sin(2 * math.pi * u2), s1 * math.cos(2 * math.pi * u2)
        z, w = s2 * math.sin(2 * math.pi * u3), s2 * math.cos(2 * math.pi * u3)
        r = [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
        c = [cb[k] + rng.random() * 2 * h - h for k in range(3)]
        t = [c[i] - sum(r[i][j] * ca[j] for j in range(3)) for i in range(3)]
        nums = [f32(r[i][j]) for i in range(3) for j in range(3)] + [f32(v) for v in t]
        print(" ".join(f"{v:.9g}" for v in nums))


if __name__ == "__main__":
    main()
