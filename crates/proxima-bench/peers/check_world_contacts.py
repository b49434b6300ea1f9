#!/usr/bin/env python3
"""Checks the `contacts` lines of a world-trace peer against the traces' answers.

usage: check_world_contacts.py BIN TRACE_DIR [extra args]

For every TRACE_DIR/*.trace runs `BIN world TRACE [extra args]` (fcl_world accepts
the word `world` as `proxima world` does) and compares its `contacts` lines, in
order, with the trace's answers: exactly with NAME.out (`contacts P T`, or
`contacts P` with --first), and within the slack of NAME.expected (`contacts P SP
T ST` / `contacts-first P SP`; see shared/traces/world/README.md). `ray` and
`sphere` lines are not compared (the FCL peer prints `skip` for them). Prints the
differences and `NAME: E exact, S within slack, of N contacts lines`; exit 0 iff
every line is within the slack.
"""
import glob
import os
import subprocess
import sys


def contacts_lines(lines, first):
    out = []
    for line in lines:
        t = line.split()
        if not t:
            continue
        if t[0] == "contacts":
            out.append(tuple(int(x) for x in t[1 : (2 if first else 3)]))
    return out


def expected(path, first):
    rows = []
    with open(path) as f:
        for line in f:
            t = line.split()
            if first and t and t[0] == "contacts-first":
                rows.append(((int(t[1]),), (int(t[2]),)))
            elif not first and t and t[0] == "contacts" and len(t) == 5:
                rows.append(((int(t[1]), int(t[3])), (int(t[2]), int(t[4]))))
    return rows


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__.strip().splitlines()[2])
    binary, tdir, extra = sys.argv[1], sys.argv[2], sys.argv[3:]
    first = "--first" in extra
    ok = True
    for trace in sorted(glob.glob(os.path.join(tdir, "*.trace"))):
        name = os.path.basename(trace)[: -len(".trace")]
        p = subprocess.run([binary, "world", trace] + extra, capture_output=True, text=True)
        if p.returncode != 0:
            print(f"{name}: exit status {p.returncode}: {p.stderr.strip()[:200]}")
            ok = False
            continue
        got = contacts_lines(p.stdout.splitlines(), first)
        with open(trace[: -len(".trace")] + ".out") as f:
            exact = contacts_lines(f.read().splitlines(), first)
        slack = expected(trace[: -len(".trace")] + ".expected", first)
        if not (len(got) == len(exact) == len(slack)):
            print(f"{name}: {len(got)} contacts lines, answers have {len(exact)} / {len(slack)}")
            ok = False
            continue
        n_exact = n_slack = 0
        for i, (g, e, (v, s)) in enumerate(zip(got, exact, slack), 1):
            n_exact += g == e
            within = all(abs(a - b) <= k for a, b, k in zip(g, v, s))
            n_slack += within
            if not within:
                print(f"{name}: contacts line {i}: got {' '.join(map(str, g))}, expected {' '.join(map(str, e))}")
        print(f"{name}: {n_exact} exact, {n_slack} within slack, of {len(got)} contacts lines")
        ok = ok and n_slack == len(got)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
