"""The README's Python example, run as written (as the Rust examples are
doctests), from the repository's root as the README says."""

from __future__ import annotations

import os
import re

from conftest import ROOT


def python_blocks():
    text = (ROOT / "README.md").read_text()
    section = text.split("\n## Python\n", 1)[1].split("\n## ", 1)[0]
    return re.findall(r"```python\n(.*?)```", section, re.S)


def test_readme_example_runs(data):
    blocks = python_blocks()
    assert len(blocks) == 1 and "proxima.Index" in blocks[0]
    here = os.getcwd()
    os.chdir(ROOT)
    try:
        scope: dict = {}
        exec(compile(blocks[0], "README.md (## Python)", "exec"), scope)
    finally:
        os.chdir(here)
    # What the example computed is what it says.
    assert scope["pairs"].shape[1] == 2 and len(scope["pairs"]) > 100
    assert scope["contacts"].colliding.tolist() == [True, True, False]
    assert scope["world"].n_ignored == 1 and len(scope["world"]) == 3
