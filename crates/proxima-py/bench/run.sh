#!/usr/bin/env bash
# Runs bench.py (README there: what it compares) in its own virtual environment,
# target/py/bench-venv: the proxima wheel that scripts/test.sh builds (built
# here if missing), numpy, scipy, and whichever peers install on this machine
# (python-fcl, coal, open3d, trimesh with embreex). Not needed by CI.
#
#   crates/proxima-py/bench/run.sh [bench.py options]
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/../../.." && pwd)
cd "$ROOT"
OUT=$ROOT/target/py
VENV=$OUT/bench-venv
PYTHON=${PYTHON:-python3}
say() { echo "bench: $*" >&2; }

[ -x "$VENV/bin/python" ] || "$PYTHON" -m venv "$VENV"
PIP=("$VENV/bin/python" -m pip install --quiet --disable-pip-version-check)
"${PIP[@]}" numpy scipy maturin
# Peers: each on its own, so that one that does not install skips only itself.
for peer in python-fcl coal open3d trimesh embreex; do
    "${PIP[@]}" "$peer" || say "$peer does not install here; skipped"
done
if ! ls "$OUT"/wheels/proxima-*.whl >/dev/null 2>&1; then
    say "building the wheel"
    "$VENV/bin/maturin" build --release --strip --quiet \
        --manifest-path crates/proxima-py/Cargo.toml \
        --interpreter "$VENV/bin/python" --out "$OUT/wheels"
fi
"${PIP[@]}" --no-deps --force-reinstall "$OUT"/wheels/proxima-*.whl
# Outside the source tree, so that `import proxima` is the installed wheel.
cd "$OUT" && "$VENV/bin/python" "$ROOT/crates/proxima-py/bench/bench.py" "$@"
