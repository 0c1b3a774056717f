"""The pair loop alone, of two solver trees, on the same particle arrays: ms per call.

OLD_TREE's and NEW_TREE's (default: this tree) solver/ are each copied to a temporary
package and imported. One simulation of this tree (benchmarks/throughput.py's periodic
layer, 40k particles) is stepped --warmup times; then the two trees' pair loops, compiled
with the same options, are called on its arrays in turn, --calls times each, the order
swapped every call. Both read the same memory, so the host's state and the arrays' placement
weigh on both alike (whole steps of two simulations in one process do not: the one built
first runs faster). Both are copies because a copy's loop ran 7-8 % slower than the same code
imported as ``solver`` (identical trees read 0.92-0.93 new/old when only OLD_TREE was copied,
1.00 with both copied). The first call's summed accumulators of the two are compared
(round-off only), and so is their machine code ("same_machine_code": the two compiled loops'
assembly with symbol and label names taken out; identical trees give true, and still differed
by 7-8 % in speed when one was the tree imported as ``solver``). One JSON line per configuration.

Usage: python benchmarks/pair_loop.py OLD_TREE [NEW_TREE] [--ch 1.5 1.8] [--shifting none skillen lind]
           [--threads 2] [--calls 60] [--physics KEY=VALUE ...] [--jitter 0 0.05]
(--jitter DP: the fluid particles moved by up to DP dp first, an arrangement as disordered as a
flow's; the stepped layer is still a lattice, whose exact rows make the 2h test predictable)
(--physics viscous_correction=true volume_relaxation=0.1 density_diffusion_reference=column:
the pair loop of examples/conveyor_fast.yaml's scheme)
"""
from __future__ import annotations

import argparse
import importlib
import inspect
import json
import re
import shutil
import sys
import tempfile
import time
from pathlib import Path

import numba
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))
from throughput import jitter, layer_scene, set_physics  # noqa: E402


def import_tree(tree: Path, name: str):
    """The solver package of ``tree``, importable as ``name``."""
    tmp = Path(tempfile.mkdtemp(prefix="sph-surge-old-"))
    shutil.copytree(tree / "solver", tmp / name, ignore=shutil.ignore_patterns("__pycache__"))
    sys.path.insert(0, str(tmp))
    return importlib.import_module(name)


def machine_code(loop) -> str:
    """The assembly of a pair loop's thread kernel, symbol, label and constant names taken out
    (they differ between two packages of the same code), directives and comments dropped."""
    kernel = loop.py_func.__globals__["_thread_pairs"]
    text = "\n".join(kernel.inspect_asm().values())
    text = re.sub(r"\.LBB\d+_\d+", "LABEL", re.sub(r"\.LCPI\d+_\d+", "CONST", re.sub(r"_ZN[\w$.]+", "SYMBOL", text)))
    return "\n".join(line for line in text.splitlines()
                     if line.strip() and not line.strip().startswith(("#", ".")))


def measure(old_forces, new_forces, ch: float, shifting: str, calls: int, warmup: int, particles: int,
            physics=(), jitter_dp: float = 0.0) -> dict:
    from solver import forces
    from solver.scene import scene_from_dict
    from solver.simulation import Simulation
    s = Simulation(scene_from_dict(set_physics(layer_scene(ch, shifting, particles), physics)))
    for _ in range(warmup):
        s.step()
    if jitter_dp > 0:
        jitter(s, jitter_dp)
        s._sort()
    options = s.pair_options
    forces.pressure_and_inverse_density(s.rho, s.p, s.irho, s.B, s.rho0)
    fields = forces.PairFields(s.x, s.z, s.u, s.w, s.rho, s.p, s.mass, s.kind, s.wnx, s.wnz, s.shift_dx,
                               s.shift_dz, s.nu_p, s.gamma_p, s.cell_volume, s.irho, s.viscous_scale)
    loops = []
    for tree, module in (("old", old_forces), ("new", new_forces)):
        known = inspect.signature(module.make_pair_loop).parameters  # an older tree's switches
        if any(v for k, v in options.items() if k not in known):
            raise SystemExit(f"the {tree} tree's pair loop has no switch for "
                             f"{[k for k in options if k not in known]}")
        loops.append((module.make_pair_loop(**{k: v for k, v in options.items() if k in known}),
                      module.PairFields(*fields[:len(module.PairFields._fields)])))

    def call(k):
        fn, f = loops[k]
        tic = time.perf_counter()
        fn(f, s.cells, s.split, s.constants, s.acc, s.vmax_t, *s.pairs)
        return time.perf_counter() - tic

    sums = []
    for k in (0, 1):
        call(k)
        sums.append(s.acc.sum(axis=0))
    times = [[], []]
    for c in range(calls):
        for k in ((0, 1) if c % 2 == 0 else (1, 0)):
            times[k].append(call(k))
    old, new = (1e3 * np.asarray(t) for t in times)
    scale = np.abs(sums[0]).max(axis=0)
    return {"ch": ch, "shifting": shifting, "jitter_dp": jitter_dp, "threads": numba.get_num_threads(),
            "particles": s.n,
            "calls": calls, "old_ms": round(float(np.median(old)), 3), "new_ms": round(float(np.median(new)), 3),
            "new_over_old": round(float(np.median(new) / np.median(old)), 3),
            "max_rel_difference": float((np.abs(sums[1] - sums[0]).max(axis=0) / np.where(scale > 0, scale, 1)).max()),
            "same_machine_code": machine_code(loops[0][0]) == machine_code(loops[1][0])}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("old", type=Path)
    ap.add_argument("new", type=Path, nargs="?", default=ROOT)
    ap.add_argument("--ch", type=float, nargs="+", default=[1.5, 1.8])
    ap.add_argument("--shifting", nargs="+", default=["none", "skillen", "lind"])
    ap.add_argument("--particles", type=int, default=40000)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--calls", type=int, default=60)
    ap.add_argument("--warmup", type=int, default=20)
    ap.add_argument("--physics", nargs="*", default=[], metavar="KEY=VALUE",
                    help="overrides below the layer's physics, e.g. viscous_correction=true volume_relaxation=0.1")
    ap.add_argument("--jitter", type=float, nargs="+", default=[0.0], metavar="DP",
                    help="fluid particles moved by up to this many dp before timing (0: the stepped lattice)")
    a = ap.parse_args(argv)
    numba.set_num_threads(a.threads)
    old_forces = importlib.import_module(f"{import_tree(a.old.resolve(), 'solver_old').__name__}.forces")
    new_forces = importlib.import_module(f"{import_tree(a.new.resolve(), 'solver_new').__name__}.forces")
    for ch in a.ch:
        for shifting in a.shifting:
            for amplitude in a.jitter:
                row = measure(old_forces, new_forces, ch, shifting, a.calls, a.warmup, a.particles, a.physics,
                              amplitude)
                print(json.dumps({**row, "physics": a.physics}), flush=True)


if __name__ == "__main__":
    main()
