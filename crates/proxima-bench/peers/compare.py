#!/usr/bin/env python3
"""Compares the result lines of two runs, pose by pose (or ray by ray).

usage: compare.py EXPECTED GOT [--tol T] [--show K]

Result lines are the lines not starting with `#` (timings are ignored), compared in
order:
    pairs N / hit 0|1          equal
    distance D I J             |D - D'| <= T * max(1, |D|); the witness triangles I J
                               are reported apart (ties may pick other triangles)
    hit TRI T / -              (w6_rays) same triangle, or |T - T'| <= T * max(1, |T|)
                               (another triangle at the same t: an edge or a tie)
Prints the first K differences (`line N: expected ... got ...`) and a summary
`compared N lines: D differ[, W witness triangles differ]`. Exit 0 iff D == 0.
"""
import sys


def results(path):
    with open(path) as f:
        return [l.strip() for l in f if l.strip() and not l.startswith("#")]


def same(e, g, tol):
    """returns (equal, witness_equal)"""
    if e == g:
        return True, True
    we, wg = e.split(), g.split()
    if not we or not wg or we[0] != wg[0]:
        return False, False
    try:
        if we[0] == "distance" and len(we) == 4 and len(wg) == 4:
            de, dg = float(we[1]), float(wg[1])
            return abs(de - dg) <= tol * max(1.0, abs(de)), we[2:] == wg[2:]
        if we[0] == "hit" and len(we) == 3 and len(wg) == 3:
            te, tg = float(we[2]), float(wg[2])
            return abs(te - tg) <= tol * max(1.0, abs(te)), we[1] == wg[1]
    except ValueError:
        pass
    return False, False


def main():
    args = sys.argv[1:]
    tol, show = 1e-6, 10
    if "--tol" in args:
        i = args.index("--tol")
        tol = float(args[i + 1])
        del args[i : i + 2]
    if "--show" in args:
        i = args.index("--show")
        show = int(args[i + 1])
        del args[i : i + 2]
    if len(args) != 2:
        sys.exit(__doc__.strip().splitlines()[2])
    exp, got = results(args[0]), results(args[1])
    if len(exp) != len(got):
        print(f"{args[0]} has {len(exp)} result lines, {args[1]} has {len(got)}")
        return 1
    bad = witness = 0
    for n, (e, g) in enumerate(zip(exp, got), 1):
        eq, weq = same(e, g, tol)
        if not eq:
            bad += 1
            if bad <= show:
                print(f"line {n}: expected {e}, got {g}")
        elif not weq:
            witness += 1
    extra = f", {witness} witness triangles differ at an equal value" if witness else ""
    print(f"compared {len(exp)} lines: {bad} differ{extra}")
    return 0 if bad == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
