"""Whole runs of one conveyor case with two solver trees, alternately: particle-steps/s.

Each round runs ``python -m solver front CASE --set steady.max_time=T`` (and --set KEY=VALUE)
once with OLD_TREE's solver and once with NEW_TREE's (PYTHONPATH), the order swapped from
round to round, and prints one JSON line per run: the tree, its order in the round, steps,
mean dt, the time stepping's wall time (the run's own loop, without the scene's build and the
start's periodic film) and particle-steps/s; then the median rate of each tree and their ratio.
Before the rounds each tree compiles its kernels in a run of the same case at --compile-dp.

Usage: python benchmarks/paired_case.py OLD_TREE [NEW_TREE=.] --case FILE [--set KEY=VALUE ...]
           [--time 0.01] [--rounds 2] [--threads 2] [--compile-dp 0.001] [--compile-set KEY=VALUE ...]
Example: python benchmarks/paired_case.py /tmp/base --case examples/conveyor_fast.yaml --set dp=0.00025 \
           --compile-set viscous_update=substepped
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import xarray as xr


def run(tree: str, case: Path, sets: list[str], sim_time: float, threads: int) -> dict:
    with tempfile.TemporaryDirectory(prefix="sph-surge-paired-") as tmp:
        out = Path(tmp) / "front.nc"
        args = [sys.executable, "-m", "solver", "front", str(case), "-o", str(out), "--quiet",
                "--no-checkpoint", "--threads", str(threads), "--set", f"steady.max_time={sim_time}"]
        for s in sets:
            args += ["--set", s]
        env = dict(os.environ, PYTHONPATH=os.path.abspath(tree))
        done = subprocess.run(args, env=env, cwd=os.path.abspath(tree), capture_output=True, text=True)
        if done.returncode not in (0, 3):  # 3: not steady by max_time, as a short run ends
            raise SystemExit(f"{tree}: the run failed:\n{done.stderr}")
        with xr.open_dataset(out) as ds:
            a = dict(ds.attrs)
    n = int(a["n_fluid"]) + int(a["n_boundary"])
    steps, wall = int(a["steps"]), float(a["wall_time_s"])
    return {"particles": n, "steps": steps, "mean_dt": float(a["simulated_time_s"]) / steps,
            "stepping_s": round(wall, 2), "rate_M": round(n * steps / wall / 1e6, 4)}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("old")
    ap.add_argument("new", nargs="?", default=".")
    ap.add_argument("--case", type=Path, required=True)
    ap.add_argument("--set", action="append", default=[])
    ap.add_argument("--time", type=float, default=0.01)
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--compile-dp", type=float, default=0.001)
    ap.add_argument("--compile-set", action="append", default=[],
                    help="KEY=VALUE of the compile run only (viscous_update=substepped: dp = 0.25 mm's update)")
    a = ap.parse_args(argv)
    case = a.case.resolve()
    trees = {"old": a.old, "new": a.new}
    for tree in trees.values():
        run(tree, case, a.set + [f"dp={a.compile_dp}"] + a.compile_set, 0.002, a.threads)
    rates = {"old": [], "new": []}
    for r in range(a.rounds):
        order = ("old", "new") if r % 2 == 0 else ("new", "old")
        for k, name in enumerate(order):
            m = run(trees[name], case, a.set, a.time, a.threads)
            rates[name].append(m["rate_M"])
            print(json.dumps({"round": r, "tree": name, "order": k, **m}), flush=True)
    old, new = float(np.median(rates["old"])), float(np.median(rates["new"]))
    print(json.dumps({"old_rate_M": round(old, 4), "new_rate_M": round(new, 4), "new_over_old": round(new / old, 3)}))


if __name__ == "__main__":
    main()
