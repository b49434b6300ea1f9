#!/bin/bash
# Installs the C++ peers of the benchmarks (FCL 0.7, coal 3.0, Embree) and builds
# their harnesses (crates/proxima-bench/peers/, README there) into target/peers/.
#
#   scripts/peers.sh            install what is missing, rebuild what is stale
#   scripts/peers.sh --force    rebuild every harness
#
# Idempotent: a second run installs nothing and compiles nothing. Not needed by CI.
# - FCL 0.7 and Embree 3.13 come from Debian (libfcl-dev, libembree-dev). Debian 12
#   has no Embree 4, and the Embree 4 found on the Python index only ships as a
#   private libembree4.so inside Python bindings (no headers, no pkg-config), so
#   the ray harness uses Embree 3.13 (README: "Embree version").
# - coal 3.0 comes from the `libcoal` wheel (headers, libcoal.so, coal.pc) in a
#   venv under target/peers/venv, with Eigen's headers from `cmeel-eigen`.
# Environment: PEERS_OUT (default target/peers), CXX (default g++).
set -euo pipefail

ROOT=$(cd "$(dirname "$0")/.." && pwd)
SRC=$ROOT/crates/proxima-bench/peers
OUT=${PEERS_OUT:-$ROOT/target/peers}
CXX=${CXX:-g++}
FORCE=0
[ "${1:-}" = "--force" ] && FORCE=1
mkdir -p "$OUT"

say() { echo "peers: $*" >&2; }

# --- Debian packages -------------------------------------------------------
APT_PKGS=(g++ pkg-config python3-venv libfcl-dev libembree-dev)
missing=()
for p in "${APT_PKGS[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || missing+=("$p")
done
# python3-venv is only needed when the interpreter on PATH lacks venv/ensurepip.
if [[ " ${missing[*]} " == *" python3-venv "* ]] && python3 -c 'import venv, ensurepip' 2>/dev/null; then
    missing=("${missing[@]/python3-venv}")
fi
read -r -a missing <<<"${missing[*]}"
if ((${#missing[@]})); then
    SUDO=
    [ "$(id -u)" -ne 0 ] && SUDO=sudo
    say "installing ${missing[*]} (apt)"
    $SUDO apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# --- coal from the libcoal wheel ------------------------------------------
VENV=$OUT/venv
if [ ! -x "$VENV/bin/python" ]; then
    say "creating $VENV"
    python3 -m venv "$VENV"
fi
if ! "$VENV/bin/python" - <<'PY' 2>/dev/null; then
import importlib.metadata as m
assert m.version("libcoal").startswith("3.0.")
m.version("cmeel-eigen")
PY
    say "installing libcoal==3.0.* and cmeel-eigen (pip, into $VENV)"
    "$VENV/bin/pip" install -q --disable-pip-version-check 'libcoal==3.0.*' cmeel-eigen
fi
prefixes=("$VENV"/lib/python3*/site-packages/cmeel.prefix)
CMEEL=${prefixes[0]}
[ -f "$CMEEL/lib/pkgconfig/coal.pc" ] || { say "no coal.pc under $CMEEL"; exit 1; }

# --- build ------------------------------------------------------------------
# -O3 -march=native for our own code. EIGEN_MAX_ALIGN_BYTES=16: FCL and coal are
# compiled for baseline x86-64 (16-byte Eigen alignment); a harness built with
# AVX would otherwise lay out their Eigen members differently (Eigen's ABI rule).
BASE=(-std=c++17 -O3 -march=native -DNDEBUG -Wall -Wextra -Wno-unused-parameter)
EIGEN_ABI=(-DEIGEN_MAX_ALIGN_BYTES=16)
COMMON=("$SRC/common.hpp")

# build NAME SOURCES -- FLAGS...: compiles when a source, a header, this script
# or the flags changed since the last build (recorded in NAME.flags).
build() {
    local name=$1 src=$2
    shift 3
    local bin=$OUT/$name flags="$*"
    local stale=$FORCE
    [ -x "$bin" ] || stale=1
    [ -f "$bin.flags" ] && [ "$(cat "$bin.flags")" = "$flags" ] || stale=1
    for f in "$src" "${COMMON[@]}" "$0"; do
        [ "$f" -nt "$bin" ] && stale=1
    done
    if [ "$stale" = 1 ]; then
        say "building $name"
        # shellcheck disable=SC2086
        $CXX "${BASE[@]}" -o "$bin.tmp" "$src" $flags
        mv "$bin.tmp" "$bin"
        echo "$flags" >"$bin.flags"
    fi
}

FCL_FLAGS="${EIGEN_ABI[*]} -DPEER_FCL $(pkg-config --cflags fcl | sed 's/-std=c++11//') $(pkg-config --libs fcl)"
COAL_PC=$CMEEL/lib/pkgconfig:$CMEEL/share/pkgconfig
COAL_FLAGS="${EIGEN_ABI[*]} -DPEER_COAL $(PKG_CONFIG_PATH=$COAL_PC pkg-config --cflags coal) \
$(PKG_CONFIG_PATH=$COAL_PC pkg-config --libs coal) -Wl,-rpath,$CMEEL/lib"
EMBREE_PC=$(pkg-config --exists embree3 && echo embree3 || echo embree)
EMBREE_FLAGS="$(pkg-config --cflags "$EMBREE_PC" 2>/dev/null) $(pkg-config --libs "$EMBREE_PC" 2>/dev/null || echo -lembree3) -pthread"

# Two compilers at a time (the machine has 2 cores); any failure fails the script.
pids=()
build w5_mesh-fcl "$SRC/w5_mesh.cpp" -- "$FCL_FLAGS" & pids+=($!)
build w5_mesh-coal "$SRC/w5_mesh.cpp" -- "$COAL_FLAGS" & pids+=($!)
for p in "${pids[@]}"; do wait "$p"; done
pids=()
build fcl_world "$SRC/fcl_world.cpp" -- "$FCL_FLAGS" & pids+=($!)
build w6_rays "$SRC/w6_rays.cpp" -- "$EMBREE_FLAGS" & pids+=($!)
for p in "${pids[@]}"; do wait "$p"; done

# `w5_mesh --lib fcl|coal ...`: one name for both builds (FCL and coal cannot
# share a process: each brings its own octomap).
cat >"$OUT/w5_mesh.tmp" <<'SH'
#!/bin/sh
# Dispatches `w5_mesh --lib fcl|coal ...` to w5_mesh-fcl or w5_mesh-coal.
dir=$(dirname "$0")
lib=
prev=
for a in "$@"; do
    [ "$prev" = "--lib" ] && lib=$a
    prev=$a
done
case "$lib" in
    fcl|coal) exec "$dir/w5_mesh-$lib" "$@" ;;
    *) echo "w5_mesh: --lib fcl|coal is required" >&2; exit 2 ;;
esac
SH
chmod +x "$OUT/w5_mesh.tmp"
mv "$OUT/w5_mesh.tmp" "$OUT/w5_mesh"

for b in w5_mesh w5_mesh-fcl w5_mesh-coal w6_rays fcl_world; do
    echo "$OUT/$b"
done
