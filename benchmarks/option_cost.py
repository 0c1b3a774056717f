"""Cost per step of a case option: the conveyor case with and without ``--set`` overrides,
stepped in one process in alternating rounds (the host is noisy: compare only figures of
one run).

    python benchmarks/option_cost.py --set viscous_correction=true --base shifting=skillen
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))


def build(overrides):
    from solver.build import build_particles
    from solver.cli import apply_overrides
    from solver.conveyor import build_scene, case_from_dict
    from solver.scene import read_yaml
    from solver.simulation import Simulation
    root = Path(__file__).resolve().parent.parent
    case = case_from_dict(apply_overrides(read_yaml(root / "examples" / "conveyor.yaml"), overrides))
    scene = build_scene(case)
    return Simulation(scene, build_particles(scene))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="the option measured")
    ap.add_argument("--base", action="append", default=[], metavar="KEY=VALUE", help="overrides of both runs")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--steps", type=int, default=400)
    ap.add_argument("--rounds", type=int, default=4)
    ap.add_argument("--warmup", type=int, default=50)
    a = ap.parse_args(argv)
    import numba
    numba.set_num_threads(a.threads)
    sims = {"off": build(a.base), "on": build(a.base + a.set)}
    for sim in sims.values():
        for _ in range(a.warmup):
            sim.step()
    rates = {k: [] for k in sims}
    for _ in range(a.rounds):
        for k, sim in sims.items():
            n0, t0 = sim.steps, time.perf_counter()
            for _ in range(a.steps):
                sim.step()
            rates[k].append(sim.n * (sim.steps - n0) / (time.perf_counter() - t0) / 1e6)
    for k, r in rates.items():
        print(f"{k:3s} {' '.join(a.set) if k == 'on' else '(base)':30s} M particle-steps/s: "
              f"{' '.join(f'{x:.3f}' for x in r)}  mean {np.mean(r):.3f}")
    print(f"cost: {100 * (1 - np.mean(rates['on']) / np.mean(rates['off'])):+.1f} % "
          f"({a.threads} threads, base {' '.join(a.base) or 'examples/conveyor.yaml'})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
