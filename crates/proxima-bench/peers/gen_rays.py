#!/usr/bin/env python3
"""Random rays around a mesh in w6_rays's binary ray format (README.md).

usage: gen_rays.py MESH N [SEED] > FILE.rays

Three kinds mixed as in the W6 bench (`proxima-bench` w6/rays.rs), not the same
random stream: 70 % from the sphere of twice the bounding radius aimed at a point
of the box (20 % of all with tmax in [0.5, 1] x the distance to that point, the
rest unbounded), 30 % from a point of the box enlarged 1.5x in a random direction.
Directions are unit vectors in f32. Format: b"PXRAYS01", u64 count, then 7
little-endian f32 per ray (ox oy oz dx dy dz tmax; tmax may be +inf).
"""
import math
import os
import random
import struct
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gen_poses import vertices  # noqa: E402


def unit(rng):
    while True:
        v = [rng.uniform(-1, 1) for _ in range(3)]
        n = sum(x * x for x in v)
        if 1e-4 < n <= 1:
            n = math.sqrt(n)
            return [x / n for x in v]


def main():
    if len(sys.argv) not in (3, 4):
        sys.exit(__doc__.strip().splitlines()[2])
    lo = [math.inf] * 3
    hi = [-math.inf] * 3
    for v in vertices(sys.argv[1]):
        for k in range(3):
            lo[k], hi[k] = min(lo[k], v[k]), max(hi[k], v[k])
    n = int(sys.argv[2])
    rng = random.Random(int(sys.argv[3]) if len(sys.argv) == 4 else 6)
    c = [(lo[k] + hi[k]) / 2 for k in range(3)]
    h = [(hi[k] - lo[k]) / 2 for k in range(3)]
    r = max(math.sqrt(sum(x * x for x in h)), 1e-6)
    out = bytearray(b"PXRAYS01" + struct.pack("<Q", n))
    for i in range(n):
        kind = i % 10
        if kind in (5, 6, 7):
            o = [rng.uniform(c[k] - 1.5 * h[k], c[k] + 1.5 * h[k]) for k in range(3)]
            d = unit(rng)
            tmax = math.inf
        else:
            u = unit(rng)
            o = [c[k] + u[k] * 2 * r for k in range(3)]
            target = [rng.uniform(lo[k], hi[k]) for k in range(3)]
            d = [target[k] - o[k] for k in range(3)]
            length = math.sqrt(sum(x * x for x in d))
            d = [x / length for x in d]
            tmax = length * rng.uniform(0.5, 1.0) if kind >= 8 else math.inf
        out += struct.pack("<7f", *o, *d, tmax)
    sys.stdout.buffer.write(out)


if __name__ == "__main__":
    main()
