#!/bin/bash
# Runs every peer harness on the shared meshes and compares its answers with
# Proxima's (README.md, "Validation"). From the repository root, after
# `scripts/peers.sh` and `cargo build --release`:
#
#   crates/proxima-bench/peers/validate.sh [w5] [w6] [world]     (default: all three)
#
# Work files go to target/peers/validate/. Prints one line per comparison; exit 1
# if a harness fails to run (answers that differ are reported, not fatal: FCL,
# coal and Embree decide touching and grazing cases with their own tolerances).
set -uo pipefail
ROOT=$(cd "$(dirname "$0")/../../.." && pwd)
cd "$ROOT" || exit 1
PEERS=$ROOT/crates/proxima-bench/peers
BIN=target/peers
PX=target/release/proxima
DATA=${DATA:-../shared/data}
OUT=target/peers/validate
mkdir -p "$OUT"
PARTS=${*:-w5 w6 world}
fail=0
run() { "$@" || { echo "FAILED: $*" >&2; fail=1; }; }

if [[ " $PARTS " == *" w5 "* ]]; then
    # name, moving mesh, fixed mesh, poses (a file, or a count to generate)
    while read -r name a b poses; do
        if [[ "$poses" =~ ^[0-9]+$ ]]; then
            python3 "$PEERS/gen_poses.py" "$DATA/$a" "$DATA/$b" "$poses" 5 >"$OUT/$name.poses"
            poses=$OUT/$name.poses
        fi
        run $PX collide "$DATA/$a" "$DATA/$b" --poses "$poses" >"$OUT/$name.px-all"
        run $PX collide "$DATA/$a" "$DATA/$b" --poses "$poses" --first >"$OUT/$name.px-first"
        for lib in fcl coal; do
            for bv in obbrss obb; do
                for mode in all first; do
                    f=$OUT/$name.$lib-$bv-$mode
                    run $BIN/w5_mesh --lib $lib --bv $bv "$DATA/$a" "$DATA/$b" "$poses" --mode $mode >"$f"
                    echo "w5 $name $lib $bv $mode vs proxima: $(python3 "$PEERS/compare.py" "$OUT/$name.px-$mode" "$f" --show 3 | tr '\n' ' ')"
                    echo "   $(grep -E '^# (build_us|query_us)' "$f" | tr '\n' ' ')"
                done
            done
            for bv in obbrss rss; do
                run $BIN/w5_mesh --lib $lib --bv $bv "$DATA/$a" "$DATA/$b" "$poses" --mode distance >"$OUT/$name.$lib-$bv-distance"
            done
        done
        echo "w5 $name distance fcl vs coal (obbrss): $(python3 "$PEERS/compare.py" "$OUT/$name.fcl-obbrss-distance" "$OUT/$name.coal-obbrss-distance" --tol 1e-6 --show 3 | tr '\n' ' ')"
        echo "w5 $name distance fcl obbrss vs rss: $(python3 "$PEERS/compare.py" "$OUT/$name.fcl-obbrss-distance" "$OUT/$name.fcl-rss-distance" --tol 1e-6 --show 3 | tr '\n' ' ')"
        echo "w5 $name distance coal obbrss vs rss: $(python3 "$PEERS/compare.py" "$OUT/$name.coal-obbrss-distance" "$OUT/$name.coal-rss-distance" --tol 1e-6 --show 3 | tr '\n' ' ')"
        # Distance 0 iff the meshes intersect (Proxima's all-pairs answer).
        for lib in fcl coal; do
            n=$(paste -d' ' "$OUT/$name.px-all" "$OUT/$name.$lib-obbrss-distance" | grep -v '#' |
                awk '($2 > 0) != ($4 == 0) { c++ } END { print c + 0 }')
            echo "w5 $name $lib distance==0 disagrees with proxima's contact on $n poses"
        done
    done <<EOF
rob-env rob.obj env.obj crates/proxima-bench/data/rob-env-1000.poses
bunny bunny.obj bunny.obj 300
teapot teapot.obj teapot.obj 300
hand-forearm hand_3finger.stl forearm.stl 300
skin-ribcage SKINbody.stl BONERibcage.stl 100
EOF
fi

if [[ " $PARTS " == *" w6 "* ]]; then
    for m in bunny.obj teapot.obj env.obj SKINbody.stl BONERibcage.stl; do
        python3 "$PEERS/gen_rays.py" "$DATA/$m" 100000 6 >"$OUT/$m.rays"
        run $BIN/w6_rays --lib embree "$DATA/$m" "$OUT/$m.rays" --brute 2000 --reps 3 >"$OUT/$m.w6"
        echo "w6 $m: $(grep -E '^# (build_ms|ns_per_ray|mode_mismatches|brute)' "$OUT/$m.w6" | tr '\n' ' ')"
    done
fi

if [[ " $PARTS " == *" world "* ]]; then
    W=${WORLD:-../shared/traces/world}
    for args in "" "--first" "--update moved" "--path api"; do
        # shellcheck disable=SC2086
        echo "world fcl_world $args: $(python3 "$PEERS/check_world_contacts.py" $BIN/fcl_world "$W" $args | tr '\n' ' ')"
    done
fi
exit $fail
