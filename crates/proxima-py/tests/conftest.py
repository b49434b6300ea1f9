"""Shared fixtures: the repository's paths, the shared test meshes, the CLI."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))  # `import brute`

ROOT = Path(__file__).resolve().parents[3]
# The shared data beside the clone, as for the Rust tests (`../shared`).
DATA = ROOT.parent / "shared" / "data"


@pytest.fixture
def rng():
    return np.random.default_rng(20240607)


@pytest.fixture(scope="session")
def data():
    assert DATA.is_dir(), f"the shared test meshes are missing: {DATA}"
    return DATA


@pytest.fixture(scope="session")
def cli():
    """The `proxima` command-line tool: $PROXIMA_CLI, or target/{release,debug}/proxima,
    or built now (never skipped: the collide tests need its answers)."""
    env = os.environ.get("PROXIMA_CLI")
    if env:
        assert Path(env).is_file(), f"PROXIMA_CLI={env} does not exist"
        return env
    for profile in ("release", "debug"):
        p = ROOT / "target" / profile / "proxima"
        if p.is_file():
            return str(p)
    subprocess.run(["cargo", "build", "-q", "-p", "proxima-cli"], cwd=ROOT, check=True)
    return str(ROOT / "target" / "debug" / "proxima")
