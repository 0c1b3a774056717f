"""Where the throughput layer's step goes: cProfile of benchmarks/throughput.py's 40k layer.

For each shifting method given, builds the layer (Ch --ch, --threads threads), runs 5 warm-up
steps, profiles --steps steps and prints each function's own time a step and its share of the
total (the numba kernels are called from Python, so each shows as one row).

Usage: python benchmarks/profile_layer.py [--ch 1.5] [--threads 2] [--steps 200] [--rows 12]
           [--shifting none skillen]
"""
from __future__ import annotations

import argparse
import cProfile
import pstats
import sys
from pathlib import Path

import numba

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from throughput import layer_scene  # noqa: E402

from solver.scene import scene_from_dict  # noqa: E402
from solver.simulation import Simulation  # noqa: E402


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--ch", type=float, default=1.5)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--steps", type=int, default=200)
    ap.add_argument("--rows", type=int, default=12)
    ap.add_argument("--particles", type=int, default=40000)
    ap.add_argument("--shifting", nargs="+", default=["none", "skillen"])
    a = ap.parse_args(argv)
    numba.set_num_threads(a.threads)
    for method in a.shifting:
        sim = Simulation(scene_from_dict(layer_scene(a.ch, method, a.particles)))
        for _ in range(5):
            sim.step()
        prof = cProfile.Profile()
        prof.enable()
        for _ in range(a.steps):
            sim.step()
        prof.disable()
        stats = pstats.Stats(prof).stats
        total = sum(v[2] for v in stats.values())
        print(f"\n{method}, Ch {a.ch:g}, {sim.n} particles, {a.threads} threads: "
              f"{1e3 * total / a.steps:.2f} ms a step (own time summed)")
        print("| function | ms a step | share | calls a step |\n|---|---|---|---|")
        for (_, _, name), v in sorted(stats.items(), key=lambda kv: -kv[1][2])[:a.rows]:
            print(f"| {name} | {1e3 * v[2] / a.steps:.3f} | {100 * v[2] / total:.1f} % | {v[1] / a.steps:.1f} |")


if __name__ == "__main__":
    main()
