"""Numba compile time of a case's first step, for one or more solver trees, with a cold cache.

Each round runs, for each tree in turn (the order reversed every other round), a fresh process
with an empty SPH_SURGE_CACHE_DIR that builds the case's simulation and takes one step, and
times every numba compilation by numba's compile events (benchmarks/compile_events.py). A
compilation started inside another (a callee typed while its caller compiles) is counted in its
caller's seconds. One JSON line a
tree and round: the compile seconds summed, the process's wall seconds to the end of the step,
and the slowest functions.

Usage: python benchmarks/compile_time.py [TREE ...] [--case examples/conveyor_fast.yaml]
           [--layer CH SHIFTING] [--set KEY=VALUE ...] [--rounds 2] [--threads 2] [--top 6]
TREE: a directory holding a solver/ package (default: this tree). --layer takes
benchmarks/throughput.py's periodic layer (4 000 particles) instead of a conveyor case.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

CHILD = r"""
import json, sys, time
tic = time.perf_counter()
spec = json.loads(sys.argv[1])
sys.path.insert(0, spec["benchmarks"])
import compile_events  # records every compilation from here on
import numba
numba.set_num_threads(spec["threads"])
from solver.simulation import Simulation
if spec["layer"]:
    from throughput import layer_scene
    from solver.scene import scene_from_dict
    scene = scene_from_dict(layer_scene(float(spec["layer"][0]), spec["layer"][1], 4000))
else:
    from solver.cli import apply_overrides
    from solver.conveyor import build_scene, case_from_dict
    from solver.scene import read_yaml
    scene = build_scene(case_from_dict(apply_overrides(read_yaml(spec["case"]), spec["set"])))
sim = Simulation(scene)
sim.step()
totals = {name: seconds for name, (seconds, count) in compile_events.totals().items()}
print(json.dumps({"compile_s": sum(totals.values()), "wall_s": time.perf_counter() - tic,
                  "functions": totals}))
"""


def measure(tree: Path, spec: dict) -> dict:
    with tempfile.TemporaryDirectory(prefix="sph-surge-cold-") as cache:
        env = dict(os.environ, PYTHONPATH=str(tree), SPH_SURGE_CACHE_DIR=cache)
        env.pop("NUMBA_CACHE_DIR", None)
        out = subprocess.run([sys.executable, "-c", CHILD, json.dumps(spec)], env=env, cwd=tree,
                             capture_output=True, text=True, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("trees", nargs="*", type=Path, default=[ROOT])
    ap.add_argument("--case", type=Path, default=ROOT / "examples" / "conveyor_fast.yaml")
    ap.add_argument("--layer", nargs=2, metavar=("CH", "SHIFTING"))
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--top", type=int, default=6)
    a = ap.parse_args(argv)
    spec = {"case": str(a.case.resolve()), "layer": a.layer, "set": a.set, "threads": a.threads,
            "benchmarks": str(ROOT / "benchmarks")}
    for r in range(a.rounds):
        order = a.trees if r % 2 == 0 else a.trees[::-1]
        for tree in order:
            m = measure(tree.resolve(), spec)
            top = sorted(m["functions"].items(), key=lambda kv: -kv[1])[:a.top]
            print(json.dumps({"round": r, "tree": str(tree), "compile_s": round(m["compile_s"], 2),
                              "wall_s": round(m["wall_s"], 2),
                              "slowest": {k.replace("solver.", ""): round(v, 2) for k, v in top}}),
                  flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
