"""The implicit or sub-stepped viscous update alone, of two solver trees, on the same arrays: ms a step.

Steps the paper case (examples/conveyor_fast.yaml's scheme, ``viscous_update: --update``) at
--dp for --warmup steps with this tree, then calls each tree's whole update of the last
step's evaluation (as its ``Simulation._solve_viscous`` runs it, with the arrangement of the
pair list into rows if that tree has one; the same pair list, right-hand side and dt for
both; CG from the explicit step, to the solver's tolerance) --calls times, the order swapped
every call, and prints the median ms of each, their ratio, the stages or CG iterations, and
the largest difference of the two results over the largest |delta / dt|.

Both trees (NEW_TREE: default this one) are imported as copies (``benchmarks/pair_loop.py``:
a copy against the tree imported as ``solver`` read 7-8 % slower for identical code).

Usage: python benchmarks/viscous_update.py OLD_TREE [NEW_TREE] [--update substepped|implicit] [--dp 0.00025] [--ch 1.8]
           [--threads 2] [--warmup 4] [--calls 20]
"""
from __future__ import annotations

import argparse
import importlib
import json
import sys
import time
from pathlib import Path

import numba
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))
from cg_solve import paper_case_simulation, step_recording  # noqa: E402
from pair_loop import import_tree  # noqa: E402


def simulation(dp: float, ch: float, update: str, warmup: int):
    """The paper case stepped ``warmup`` times, and its last evaluation's accelerations and dt."""
    sim, _ = paper_case_simulation(dp, ch, update)
    kept = {}
    step_recording(sim, warmup, lambda dt: kept.update(dt=dt, ax=sim.out[0].copy(), az=sim.out[1].copy()))
    return sim, kept


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("old_tree", type=Path)
    ap.add_argument("new_tree", type=Path, nargs="?", default=Path(__file__).resolve().parents[1])
    ap.add_argument("--update", choices=["substepped", "implicit"], default="substepped")
    ap.add_argument("--dp", type=float, default=0.00025)
    ap.add_argument("--ch", type=float, default=1.8)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--warmup", type=int, default=4)
    ap.add_argument("--calls", type=int, default=20)
    a = ap.parse_args(argv)
    numba.set_num_threads(a.threads)
    from solver import implicit
    import_tree(a.old_tree, "solver_old")
    old_implicit = importlib.import_module("solver_old.implicit")
    import_tree(a.new_tree, "solver_new")
    new_implicit = importlib.import_module("solver_new.implicit")
    sim, kept = simulation(a.dp, a.ch, a.update, a.warmup)
    n, dt = sim.n_active, kept["dt"]
    diag = sim.out[sim.nq - 1]
    cg = a.update == "implicit"
    fluid = sim.kind[:n] == 0
    tol, most = implicit.TOLERANCE, implicit.MAX_ITERATIONS

    def runner(impl):
        """The whole update of ``impl`` (a solver tree's implicit module) on the kept step."""
        if not hasattr(impl, "operator"):  # trees that arranged the pair list by rows first
            return rows_runner(impl)
        shares = impl.product_shares(sim.nthreads, sim.n)
        work = np.zeros((impl.WORK_ROWS if cg else impl.SUBSTEP_WORK_ROWS, sim.n))

        def run(ax, az):
            op = impl.operator(sim.pairs, sim.cells, sim.split, diag, sim.mass, shares)
            if cg:
                s = impl.solve(op, sim.kind, dt, ax, az, *np.zeros((2, sim.n)), n, tol, most, work)[0]
            else:
                s = impl.substep(op, sim.kind, dt, ax, az, n, work)
            return s, float(np.sqrt(np.max(ax[:n][fluid] ** 2 + az[:n][fluid] ** 2, initial=0.0)))
        return run

    def rows_runner(impl):
        rows = impl.rows_for(sim.nthreads, sim.n, sim.pairs.i.shape[1])
        work = np.zeros((max(impl.WORK_ROWS, 6), sim.n))

        def run(ax, az):
            impl.sort_pairs(*sim.pairs[:3], sim.pairs.count, sim.mass, n, rows)
            if cg:
                s = impl.solve(*rows[:3], diag, sim.mass, sim.kind, dt, ax, az, *np.zeros((2, sim.n)), n, tol,
                               most, work)[0]
            else:
                s = impl.substep(*rows[:3], diag, sim.kind, dt, ax, az, n, work)
            return s, float(np.hypot(ax[:n][fluid], az[:n][fluid]).max(initial=0.0))
        return run

    run_old, run_new = runner(old_implicit), runner(new_implicit)
    runs = {"old": run_old, "new": run_new}
    times = {"old": [], "new": []}
    results = {}
    for c in range(a.calls + 1):
        for name in (("old", "new") if c % 2 == 0 else ("new", "old")):
            ax, az = kept["ax"].copy(), kept["az"].copy()
            tic = time.perf_counter()
            s, amax = runs[name](ax, az)
            if c > 0:  # the first call compiles
                times[name].append(time.perf_counter() - tic)
            results[name] = (s, amax, ax[:n][fluid], az[:n][fluid])
    so, ao, xo, zo = results["old"]
    sn, an, xn, zn = results["new"]
    scale = max(np.abs(xo).max(), np.abs(zo).max())
    diff = max(np.abs(xo - xn).max(), np.abs(zo - zn).max()) / scale
    out = {"update": a.update, "dp": a.dp, "ch": a.ch, "threads": a.threads, "particles": sim.n,
           "pairs": int(sim.pairs.count.sum()),
           "stages_or_iterations": [so, sn], "old_ms": round(1e3 * float(np.median(times["old"])), 2),
           "new_ms": round(1e3 * float(np.median(times["new"])), 2),
           "relative_difference": float(f"{diff:.2g}"), "amax_relative_difference": float(f"{abs(ao - an) / ao:.2g}")}
    out["new_over_old"] = round(out["new_ms"] / out["old_ms"], 3)
    print(json.dumps(out))


if __name__ == "__main__":
    main()
