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


# Two variants of the pair loop (examples/film.yaml with and without shifting), built in one
# process; prints how often the pair loop compiled, and how often an uncached function defined
# here did (1 when the compile events are seen).
VARIANTS = """
import collections
import sys
import numba
import yaml
from numba.core import event
from solver.scene import scene_from_dict
from solver.simulation import Simulation
counts = collections.Counter()

class Count(event.Listener):
    def on_start(self, ev):
        pass

    def on_end(self, ev):
        counts[ev.data["dispatcher"].py_func.__qualname__] += 1

event.register("numba:compile", Count())
for shifting in ("skillen", "none"):
    with open(sys.argv[1]) as fh:
        d = yaml.safe_load(fh)
    d.setdefault("numerics", {})["shifting"] = {"method": shifting}
    Simulation(scene_from_dict(d)).step()
numba.njit(lambda v: v + 1)(1)
print(sum(n for name, n in counts.items() if "pair_loop" in name),
      sum(n for name, n in counts.items() if "lambda" in name))
"""


def test_a_second_process_loads_the_pair_loops_from_the_cache():
    """Numba keys a cached closure on its closure's contents; a dispatcher there would pickle
    with a random id and make every process compile the loop afresh."""
    film = SOLVER_DIR.parent / "examples" / "film.yaml"
    env = dict(os.environ, NUMBA_NUM_THREADS="2")
    runs = [subprocess.run([sys.executable, "-c", VARIANTS, str(film)], env=env, capture_output=True,
                           text=True, timeout=600) for _ in range(2)]
    for res in runs:
        assert res.returncode == 0, res.stderr
    pair_loops, probe = (int(v) for v in runs[1].stdout.split()[-2:])
    assert probe == 1, "the compile events were not seen"
    assert pair_loops == 0, "the second process compiled the pair loop again"


def test_each_kernel_variant_has_its_own_cache_index():
    """Variants compiled from one factory are named after their switches, so that numba gives
    each its own cache index: two processes adding different variants to one index at once
    could give both the same data file, and one would later load the other's machine code."""
    from solver import boundary, forces
    loops = [forces.make_pair_loop(forces.PairOptions(**o)) for o in
             ({}, {"packing": 1}, {"rheology": 1}, {"rheology": 1, "stress": True})]
    names = [d.py_func.__qualname__ for d in loops]
    assert len(set(names)) == len(names) and all("pair_loop" in n for n in names)
    updates = [boundary.make_mdbc_update(c, p) for c in (False, True) for p in (False, True)]
    assert len({d.py_func.__qualname__ for d in updates}) == 4
    # the same switches give the same name in every process, so the cache is found again
    code = ("from solver import forces; print(forces.make_pair_loop(forces.PairOptions(rheology=1))"
            ".py_func.__qualname__)")
    again = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert again.returncode == 0, again.stderr
    assert again.stdout.strip() == names[2]
