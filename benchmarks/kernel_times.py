"""Where a step's time goes: ms a step of each compiled kernel, without a profiler.

Wraps every numba kernel of the solver modules a step calls (and the simulation's pair loop
and mDBC update) in a wall-clock timer, runs --steps steps after --warmup, and prints each
kernel's ms a step and share of the step, the largest first. One timer call per kernel call
and nothing per Python line, so small kernels are not inflated as under cProfile. The scene is
the throughput layer (``benchmarks.common.layer``: --ch, --shifting, --particles) or a case or
scene YAML (--case), with --set overrides either way.

    python -m benchmarks.kernel_times [--ch 1.5] [--shifting none] [--particles 40000] [--threads 2]
        [--steps 200] [--warmup 5] [--rows 16] [--case examples/conveyor_fast.yaml] [--set KEY=VALUE ...]
"""
from __future__ import annotations

import collections
import importlib
from pathlib import Path

from benchmarks import common

MODULES = ("boundary", "cells", "forces", "integrate", "guards", "shifting", "implicit", "packing", "rheology")
QUICK = {"steps": 50}


def timed(times: dict, label: str, fn):
    def call(*args, **kwargs):
        with common.Timer() as t:
            out = fn(*args, **kwargs)
        times[label] += t.seconds
        return out
    return call


def instrument(sim) -> dict:
    """Wrap the kernels in timers; {label: seconds} filled as the simulation steps."""
    times = collections.defaultdict(float)
    for name in MODULES:
        try:
            module = importlib.import_module(f"solver.{name}")
        except ImportError:  # a module this tree does not have
            continue
        for attr in dir(module):
            fn = getattr(module, attr)
            if hasattr(fn, "py_func") and hasattr(fn, "signatures"):  # a numba dispatcher
                setattr(module, attr, timed(times, f"{name}.{attr}", fn))
    for attr in ("pair_loop", "mdbc_update"):
        if callable(getattr(sim, attr, None)):
            setattr(sim, attr, timed(times, attr, getattr(sim, attr)))
    return times


def main(argv=None) -> int:
    ap = common.parser(__doc__, sets=True)
    ap.add_argument("--case", type=Path, default=None, help="a case or scene YAML instead of the layer")
    ap.add_argument("--ch", type=float, default=1.5, help="the layer's Ch")
    ap.add_argument("--shifting", default=None, help="the shifting method (default: the layer's none, the case's own)")
    ap.add_argument("--particles", type=int, default=40000, help="the layer's particles")
    ap.add_argument("--steps", type=int, default=200)
    ap.add_argument("--warmup", type=int, default=5)
    ap.add_argument("--rows", type=int, default=16, help="kernels listed")
    a = common.parse(ap, argv, QUICK)
    a.threads = common.set_threads(a.threads)
    if a.case is not None:
        data, scene = common.set_shifting(common.read_case(a.case, a.sets), a.shifting), a.case.name
    else:
        data = common.layer(a.particles, a.ch, a.shifting or "none", a.sets)
        scene = f"layer, Ch {a.ch:g}, {a.shifting or 'none'}"
    sim = common.simulation(data)
    for _ in range(a.warmup):
        sim.step()
    times = instrument(sim)
    with common.Timer() as total:
        for _ in range(a.steps):
            sim.step()
    t = total.seconds
    print(f"{scene} {' '.join(a.sets)}: {sim.n} particles, {a.threads} threads, {a.steps} steps, "
          f"{1e3 * t / a.steps:.3f} ms a step, {sim.n * a.steps / t / 1e6:.2f} M particle-steps/s")
    ranked = sorted(times.items(), key=lambda kv: -kv[1])
    rest = t - sum(times.values())
    print(common.table(["kernel", "ms a step", "share"],
                       [[label, f"{1e3 * s / a.steps:.3f}", f"{100 * s / t:.1f} %"] for label, s in ranked[:a.rows]]
                       + [["(Python between kernels)", f"{1e3 * rest / a.steps:.3f}", f"{100 * rest / t:.1f} %"]]))
    top = ", ".join(f"{label} {100 * s / t:.0f} %" for label, s in ranked[:3])
    common.summary(f"{scene}, {sim.n} particles: {1e3 * t / a.steps:.2f} ms a step; {top}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
