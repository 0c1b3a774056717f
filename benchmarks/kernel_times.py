"""Where a step's time goes: ms a step of each compiled kernel, without a profiler.

Wraps every numba kernel of the solver modules a step calls (and the simulation's pair loop
and mDBC update) in a wall-clock timer, runs --steps steps after --warmup, and prints each
kernel's ms a step and share of the step, the largest first. One timer call per kernel call
and nothing per Python line, so small kernels are not inflated as under cProfile. The scene is
the throughput layer (``benchmarks.common.layer``: --ch, --shifting, --particles) or a case or
scene YAML (--case), with --set overrides either way.

With --departures and a scene YAML, it prices each departure of the surge scheme on that scene
instead: the scene under surge (its numerics with the preset laid over them, as a flow campaign
builds it), under spec (its own numerics) and under surge with one departure reverted to the
scene's own value, each timed for --steps steps in --rounds alternating rounds (the median
taken). A step's cost and the acoustic limit's C (steps per simulated second go as 1 / C where
that limit binds, as on a dam break) give each variant's cost of a simulated second against
surge's.

    python -m benchmarks.kernel_times [--ch 1.5] [--shifting none] [--particles 40000] [--threads 2]
        [--steps 200] [--warmup 5] [--rows 16] [--case examples/conveyor_fast.yaml] [--set KEY=VALUE ...]
    python -m benchmarks.kernel_times --departures --case examples/dambreak.yaml [--speed 1.06] [--rounds 3]
"""
from __future__ import annotations

import collections
import copy
import importlib
import statistics
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


def surge_variants(scene: dict, speed: float) -> dict[str, dict]:
    """{name: scene} of ``--departures``: surge, spec and surge with each preset key reverted."""
    from solver.scene import Numerics
    from solver.schemes import merge, preset
    own = common.numerics_block(scene)
    depth = (scene.get("sound") or {}).get("depth") or 15.0 * scene["dp"]
    changes = preset("surge", speed, True, depth / scene["dp"])["numerics"]
    surge = merge(own, changes)
    out = {"surge": surge, "spec": own}
    # one departure a group: C and its rule go together (C 0.6 under the fixed rule is no scheme);
    # the shifting keys act only with the method they belong to (docs/numerics.md)
    groups = [("cfl", "cfl_rule")] + [(k,) for k in changes if k not in ("cfl", "cfl_rule", "shifting")]
    for group in groups:
        reverted = copy.deepcopy(surge)
        for key in group:
            if key in changes:
                reverted[key] = own[key] if key in own else getattr(Numerics(), key)
        if any(reverted[k] != surge[k] for k in group if k in changes):
            out["surge, " + ", ".join(f"{k}: {reverted[k]}" for k in group if k in changes)] = reverted
    variants = {}
    for name, num in out.items():
        d = copy.deepcopy(scene)
        d["numerics"] = num
        variants[name] = d
    return variants


def departures(a) -> int:
    """The ``--departures`` mode (module docstring)."""
    data = common.set_shifting(common.read_case(a.case, a.sets), a.shifting)
    if not common.is_scene(data):
        raise SystemExit("--departures: --case must be a scene YAML (docs/scene.md)")
    sims = {}
    for name, scene in surge_variants(data, a.speed).items():
        sims[name] = common.simulation(scene)
        for _ in range(a.warmup):
            sims[name].step()
    times = {name: [] for name in sims}
    for _ in range(a.rounds):
        for name, sim in sims.items():
            with common.Timer() as t:
                for _ in range(a.steps):
                    sim.step()
            times[name].append(t.seconds / a.steps)
    ms = {name: 1e3 * statistics.median(v) for name, v in times.items()}
    c_a = {name: sim.cfl_acoustic for name, sim in sims.items()}
    per_second = {name: ms[name] / c_a[name] for name in sims}
    n = next(iter(sims.values())).n
    print(f"{a.case.name} {' '.join(a.sets)}: {n} particles, {a.threads} threads, {a.rounds} rounds of "
          f"{a.steps} steps after {a.warmup}")
    print(common.table(["variant", "ms a step", "acoustic C", "cost of a simulated second / surge's"],
                       [[name, f"{ms[name]:.3f}", f"{c_a[name]:.3f}",
                         f"{per_second[name] / per_second['surge']:.2f}"] for name in sims]))
    common.summary(f"{a.case.name}: surge {ms['surge']:.2f} ms a step at C {c_a['surge']:.3f}, spec "
                   f"{ms['spec']:.2f} ms at C {c_a['spec']:.3f}: a simulated second costs "
                   f"{per_second['surge'] / per_second['spec']:.2f} times spec's under surge")
    return 0


def main(argv=None) -> int:
    ap = common.parser(__doc__, sets=True, rounds=3)
    ap.add_argument("--case", type=Path, default=None, help="a case or scene YAML instead of the layer")
    ap.add_argument("--ch", type=float, default=1.5, help="the layer's Ch")
    ap.add_argument("--shifting", default=None, help="the shifting method (default: the layer's none, the case's own)")
    ap.add_argument("--particles", type=int, default=40000, help="the layer's particles")
    ap.add_argument("--steps", type=int, default=200)
    ap.add_argument("--warmup", type=int, default=5)
    ap.add_argument("--rows", type=int, default=16, help="kernels listed")
    ap.add_argument("--departures", action="store_true", help="price each departure of surge on --case (a scene)")
    ap.add_argument("--speed", type=float, default=1.0, help="--departures: the flow's velocity scale, m/s")
    a = common.parse(ap, argv, QUICK)
    a.threads = common.set_threads(a.threads)
    if a.departures:
        return departures(a)
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
