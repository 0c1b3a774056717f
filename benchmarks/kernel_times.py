"""Where a step's time goes, kernel by kernel, without a profiler: ms a step of each kernel.

Wraps every compiled kernel of the solver modules that a step calls (and the simulation's
pair loop and mDBC update) in a wall-clock timer, runs --steps steps after --warmup, and
prints each kernel's ms a step and share of the step, the largest first. Unlike cProfile
(benchmarks/profile_layer.py, profile_case.py) it adds one timer call per kernel call and
nothing per Python line, so small kernels are not inflated. The scene is the throughput layer
(benchmarks/throughput.py; --ch, --shifting, --particles) or, with --case, a conveyor case
(--set KEY=VALUE overrides its keys). The solver is the one on PYTHONPATH, else this tree's.

Usage: python benchmarks/kernel_times.py [--ch 1.5] [--shifting none] [--particles 40000]
           [--case examples/conveyor_fast.yaml [--set shifting=lind]] [--threads 2] [--steps 200]
           [--warmup 5] [--rows 16]
"""
from __future__ import annotations

import argparse
import collections
import importlib
import sys
import time
from pathlib import Path

import numba

ROOT = Path(__file__).resolve().parents[1]
sys.path.append(str(ROOT))  # after PYTHONPATH: another tree's solver can be timed
sys.path.insert(0, str(ROOT / "benchmarks"))

MODULES = ("boundary", "cells", "forces", "integrate", "guards", "shifting", "implicit", "packing", "rheology")


def timed(times: dict, label: str, fn):
    def call(*args, **kwargs):
        tic = time.perf_counter()
        out = fn(*args, **kwargs)
        times[label] += time.perf_counter() - tic
        return out
    return call


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--ch", type=float, default=1.5)
    ap.add_argument("--shifting", default="none")
    ap.add_argument("--particles", type=int, default=40000)
    ap.add_argument("--case", default=None)
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--steps", type=int, default=200)
    ap.add_argument("--warmup", type=int, default=5)
    ap.add_argument("--rows", type=int, default=16)
    a = ap.parse_args(argv)
    numba.set_num_threads(a.threads)
    import solver  # before step_passes, which puts this tree first on sys.path
    from step_passes import simulation
    sim = simulation(a.case, a.ch, a.shifting, a.particles, a.warmup, a.set)
    times = collections.defaultdict(float)
    for name in MODULES:
        module = importlib.import_module(f"solver.{name}")
        for attr in dir(module):
            fn = getattr(module, attr)
            if hasattr(fn, "py_func") and hasattr(fn, "signatures"):  # a numba dispatcher
                setattr(module, attr, timed(times, f"{name}.{attr}", fn))
    sim.pair_loop = timed(times, "pair_loop", sim.pair_loop)
    sim.mdbc_update = timed(times, "mdbc_update", sim.mdbc_update)
    tic = time.perf_counter()
    for _ in range(a.steps):
        sim.step()
    total = time.perf_counter() - tic
    scene = a.case or f"layer, Ch {a.ch:g}, {a.shifting}"
    print(f"{scene} ({' '.join(a.set)}), solver {Path(solver.__file__).parent}: {sim.n} particles, "
          f"{a.threads} threads, {1e3 * total / a.steps:.3f} ms a step, "
          f"{sim.n * a.steps / total / 1e6:.2f} M particle-steps/s")
    print("| kernel | ms a step | share |\n|---|---|---|")
    for label, t in sorted(times.items(), key=lambda kv: -kv[1])[:a.rows]:
        print(f"| {label} | {1e3 * t / a.steps:.3f} | {100 * t / total:.1f} % |")
    rest = total - sum(times.values())
    print(f"| (Python between kernels) | {1e3 * rest / a.steps:.3f} | {100 * rest / total:.1f} % |")


if __name__ == "__main__":
    main()
