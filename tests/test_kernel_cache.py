"""The numba cache is keyed on every solver source, so an edited inlined helper recompiles.

``probes.sample_points`` inlines ``kernel.w_value`` from another file. Numba alone would
check only probes.py and load the old machine code after kernel.py changed.
"""
import math
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

import solver

pytestmark = pytest.mark.slow

SOLVER_DIR = Path(solver.__file__).resolve().parent

# One particle of volume 1 at the origin; C at the origin is W(0) = 7 / (4 pi h^2).
PROBE = """
import numpy as np
import solver
from solver.cells import Grid
from solver.probes import sample_points
one = np.zeros(1)
out = np.zeros((5, 1))
cl = Grid(-1.0, -1.0, 2.0, 2.0, 1, 1, False, 0.0).cell_list(np.array([0, 1]))
sample_points(one, one, one, one, one, one, np.ones(1), np.ones(1), np.zeros(1, np.int64), cl, 0.1, out)
print(repr(float(out[0, 0])), solver.sources.numba_cache_dir())
"""


def _probe(root: Path, cache: Path) -> tuple[float, str]:
    env = dict(os.environ, PYTHONPATH=str(root), SPH_SURGE_CACHE_DIR=str(cache), NUMBA_CACHE_DIR="")
    res = subprocess.run([sys.executable, "-c", PROBE], env=env, cwd=root, capture_output=True,
                         text=True, timeout=300)
    assert res.returncode == 0, res.stderr
    value, cache_dir = res.stdout.split()
    return float(value), cache_dir


def test_editing_an_inlined_helper_recompiles(tmp_path):
    root = tmp_path / "src"
    shutil.copytree(SOLVER_DIR, root / "solver", ignore=shutil.ignore_patterns("__pycache__"))
    cache = tmp_path / "cache"
    w0 = 7.0 / (4.0 * math.pi * 0.1 ** 2)

    first, dir1 = _probe(root, cache)
    assert first == pytest.approx(w0, rel=1e-12)
    assert any(Path(dir1).rglob("*.nbi")), "the kernel was not cached"
    again, dir2 = _probe(root, cache)  # unchanged sources: the same cache, the same value
    assert (again, dir2) == (first, dir1)

    kernel = root / "solver" / "kernel.py"
    text = kernel.read_text()
    edited = text.replace("return alpha * s * s * s * s * (2.0 * q + 1.0)",
                          "return 2.0 * alpha * s * s * s * s * (2.0 * q + 1.0)")
    assert edited != text
    kernel.write_text(edited)
    doubled, dir3 = _probe(root, cache)
    assert doubled == pytest.approx(2.0 * w0, rel=1e-12), "stale machine code was loaded"
    assert dir3 != dir1
