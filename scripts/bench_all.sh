#!/bin/bash
# Regenerates docs/bench/* (the raw outputs behind BENCHMARKS.md) from the
# release bench binary. Run from the repo root after
# `cargo build --release -p proxima-bench` (and `scripts/peers.sh` for the C++
# peers of W5); takes about 12 minutes on 2 cores. Every peer runs in each of
# its modes (one row each, the `mode` field); ratios are over the fastest.
set -e
B=./target/release/proxima-bench
D=docs/bench
uptime > $D/load.txt
$B w1 --n 10000  --frames 30 --json > $D/w1-10k.json 2>/dev/null
$B w1 --n 100000 --frames 30 --json > $D/w1-100k.json 2>/dev/null
$B w2 --n 100000 --frames 30 --json > $D/w2-100k.json 2>/dev/null
$B w3 --n 100000 --frames 30 --json > $D/w3-100k.json 2>/dev/null
$B w9 --n 100000 --frames 30 --json > $D/w9-100k.json 2>/dev/null
uptime >> $D/load.txt
# Issue #14 part 3: W1 100k with half the objects in a group that collides with
# nothing (`--inert 0.5`), beside the unfiltered run above; parry3d filters in
# its pair callback. Compare pairs_ms_median with w1-100k.json.
$B w1 --n 100000 --frames 30 --inert 0.5 --json > $D/w1-100k-inert0.5.json 2>/dev/null
uptime >> $D/load.txt
for t in 1 2; do $B w1 --n 100000 --frames 30 --clock wall --threads $t --only LooseKdTree,UniformGrid3d,parry3d --json > $D/w1-100k-wall-t$t.json 2>/dev/null; done
$B w4 > $D/w4.txt 2>/dev/null
$B w4 --json > $D/w4.json 2>/dev/null
$B w4 --threads 2 --clock wall --only UniformGrid3d,LinearOctree,LooseKdTree,rstar,parry3d > $D/w4-wall-t2.txt 2>/dev/null
$B w4 --threads 1 --clock wall --only UniformGrid3d,LinearOctree,LooseKdTree,rstar,parry3d > $D/w4-wall-t1.txt 2>/dev/null
uptime >> $D/load.txt
# W7 (k nearest: points and spheres, k = 1, 10, 100) on 100k and 1M, and W8
# (100k sphere sweeps); both check every peer's answers before timing.
$B w7 --n 100000 > $D/w7-100k.txt 2>/dev/null
$B w7 --n 100000 --json > $D/w7-100k.json 2>/dev/null
$B w7 --n 1000000 --reps 3 > $D/w7-1m.txt 2>/dev/null
$B w8 > $D/w8.txt 2>/dev/null
$B w8 --json > $D/w8.json 2>/dev/null
uptime >> $D/load.txt
# W5 with the C++ peers (FCL, coal) when scripts/peers.sh has built them (the
# table says so otherwise); wall clock, as their harness measures.
$B w5 --clock wall > $D/w5.txt 2>/dev/null
$B w5 --clock wall --json > $D/w5.json 2>/dev/null
# W6 runs Embree beside ours when scripts/peers.sh has built target/peers/w6_rays.
[ -x target/peers/w6_rays ] || echo "bench_all: no target/peers/w6_rays (scripts/peers.sh): W6 without Embree" >&2
$B w6 > $D/w6.txt 2>/dev/null
$B w6 --json > $D/w6.json 2>/dev/null
uptime >> $D/load.txt
$B w1 --n 1000000 --frames 10 --json > $D/w1-1m.json 2>/dev/null
uptime >> $D/load.txt
# Issue #17 part 7: W1 1M pairs on 1 and 2 threads (wall clock; the pair search
# runs in a pool of that size, the update on the calling thread). Compare the
# pairs_ms_median of t2 with t1; meaningful only on a quiet machine (load.txt).
for t in 1 2; do $B w1 --n 1000000 --frames 10 --clock wall --threads $t --only LooseKdTree,UniformGrid3d --json > $D/w1-1m-wall-t$t.json 2>/dev/null; done
uptime >> $D/load.txt
python3 - > $D/w1-1m-threads.txt <<'PY'
import json
t = {k: {r['structure']: r for r in json.load(open(f'docs/bench/w1-1m-wall-t{k}.json'))} for k in (1, 2)}
print('W1 1M, wall clock: pairs ms/frame on 1 and 2 threads, speed-up (target >= 1.7x)')
for name in t[1]:
    a, b = t[1][name]['pairs_ms_median'], t[2][name]['pairs_ms_median']
    print(f'{name:<14} {a:9.1f} {b:9.1f} {a / b:6.2f}x')
PY
python3 - <<'PY'
import json
rows=[]
for f in ['w1-10k','w1-100k','w1-1m','w2-100k','w3-100k','w9-100k']:
    rows += [r for r in json.load(open(f'docs/bench/{f}.json')) if r['structure']!='BruteForce']
json.dump(rows, open('/tmp/w1-w3-nobrute.json','w'))
PY
$B chart /tmp/w1-w3-nobrute.json --out $D/w1-w3.svg --metric frame_ms_median --title "W1-W3: update all + all pairs, median frame"
$B chart $D/w6.json --out $D/w6.svg --metric us_per_ray --title "W6: closest hit per ray"
