#!/usr/bin/env bash
# THE test command (README "Set-up"; .ci/run calls it after fmt and clippy):
#
#   scripts/test.sh           every Rust test, then the Python package's tests
#   scripts/test.sh rust      `cargo test --workspace` only
#   scripts/test.sh python    the Python part only
#
# The Python part needs only CPython >= 3.10 with pip and venv (PYTHON, default
# python3) and the Rust toolchain: it makes a virtual environment under
# target/py/venv, installs maturin, numpy and pytest from the package index
# (once: later runs find them installed and ask the index nothing), builds the
# proxima wheel (abi3) with maturin into target/py/wheels, installs it, and runs
# pytest on crates/proxima-py/tests. Idempotent; a second run rebuilds only
# what changed. The collide tests compare with the CLI (PROXIMA_CLI names
# another): in the whole run `cargo test --workspace` has built it, and
# `scripts/test.sh python` builds it.
set -euo pipefail

ROOT=$(cd "$(dirname "$0")/.." && pwd)
cd "$ROOT"
WHAT=${1:-all}
case "$WHAT" in
all | rust | python) ;;
*)
    echo "usage: scripts/test.sh [all|rust|python]" >&2
    exit 2
    ;;
esac

say() { echo "test.sh: $*" >&2; }

if [ "$WHAT" != python ]; then
    say "cargo test --workspace"
    cargo test --workspace
fi
[ "$WHAT" = rust ] && exit 0

start=$(date +%s)
PY_OUT=$ROOT/target/py
VENV=$PY_OUT/venv
PYTHON=${PYTHON:-python3}
if [ ! -x "$VENV/bin/python" ]; then
    say "creating $VENV"
    "$PYTHON" -m venv "$VENV"
fi
VPY=$VENV/bin/python
# Installs only what is missing (pip asks the index nothing when every
# requirement is already satisfied).
"$VPY" -m pip install --quiet --disable-pip-version-check \
    -r crates/proxima-py/requirements-test.txt

say "building the wheel"
rm -rf "$PY_OUT/wheels"
"$VENV/bin/maturin" build --profile wheel --strip --quiet \
    --manifest-path crates/proxima-py/Cargo.toml \
    --interpreter "$VPY" --out "$PY_OUT/wheels"
"$VPY" -m pip install --quiet --disable-pip-version-check --no-deps --force-reinstall \
    "$PY_OUT"/wheels/proxima-*.whl

# The CLI whose answers the collide tests compare with, built from these
# sources (a stale binary would give stale answers). After `cargo test
# --workspace` it is already there: the CLI's integration tests had cargo
# build it, in the test profile, into target/debug. A `cargo build` would
# build it again in the dev profile (88 s on 2 cores), so only the Python
# part alone builds it.
if [ -z "${PROXIMA_CLI:-}" ]; then
    PROXIMA_CLI=$ROOT/target/debug/proxima
    if [ "$WHAT" = python ]; then
        say "building the CLI"
        cargo build --quiet -p proxima-cli
    fi
fi
export PROXIMA_CLI

say "pytest"
# From the tests' directory, so that `import proxima` is the installed wheel.
(cd crates/proxima-py && "$VPY" -m pytest -q -p no:cacheprovider tests)
say "Python part took $(($(date +%s) - start)) s"
