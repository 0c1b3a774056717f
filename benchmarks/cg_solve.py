"""The implicit laminar update's CG solve on the matrices of a real run: iterations, time and
solution error for several tolerances and pair-weight precisions, and the iterations with and
without CG's start from the last step's correction.

Runs the paper case (examples/conveyor_fast.yaml's scheme, implicit update) at the given dp
for a few steps, keeps the systems of the last ``--systems`` steps (the operator, right-hand
side, dt), and solves each of them with every variant in turn from the explicit step,
alternating variants so that a noisy host biases none of them. The error of a variant is
measured against a solve to 1e-12: the largest |v^{n+1} - v^{n+1}_exact| over the fluid, as a
fraction of the belt speed, and the same per simulated second (the error of one step times the
steps a second takes, an upper bound that assumes the step errors add up with one sign).
Then it steps on, in blocks of 10 steps that alternate the solver's start (the last step's
correction, as the solver runs, or the explicit step), and prints the CG iterations a step of each.

    python benchmarks/cg_solve.py --dp 0.00025 --ch 1.8 --threads 2
"""
from __future__ import annotations

import argparse
import time
from pathlib import Path

import numba
import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def paper_case_simulation(dp: float, ch: float, update: str):
    """The paper case with examples/conveyor_fast.yaml's scheme and ``viscous_update: update``,
    started at h_n with the lubrication film's velocity: (the simulation, the case)."""
    from solver.build import build_particles
    from solver.conveyor import build_scene, case_from_dict, lubrication_velocity
    from solver.scene import read_yaml
    from solver.simulation import Simulation

    d = read_yaml(ROOT / "examples" / "conveyor_fast.yaml")
    d.update(dp=dp, ch=ch, viscous_update=update, start_depth="theory")
    case = case_from_dict(d)
    scene = build_scene(case)
    parts = build_particles(scene)
    f = parts.kind == 0
    parts.u[f], parts.w[f] = lubrication_velocity(case, scene, parts.x[f], parts.z[f])
    return Simulation(scene, parts), case


def step_recording(sim, steps: int, record):
    """Step ``sim`` ``steps`` times, calling ``record(dt)`` before each viscous update (the
    evaluation's accelerations in ``sim.out``); returns the simulation's own ``_solve_viscous``."""
    original = sim._solve_viscous

    def recorded(dt):
        record(dt)
        return original(dt)

    sim._solve_viscous = recorded
    for _ in range(steps):
        reason = sim.step()
        if reason:
            raise SystemExit(f"the run stopped: {reason}")
    return original


def capture(dp: float, ch: float, steps: int, systems: int):
    """Step the case and keep the CG systems of its last ``systems`` steps: (the systems,
    the belt speed, the simulation, its own ``_solve_viscous``)."""
    from solver import forces

    sim, case = paper_case_simulation(dp, ch, "implicit")
    kept: list[dict] = []

    def keep(dt):
        n = sim.n_active
        op = [a.copy() if isinstance(a, np.ndarray) else a for a in sim.viscous_operator()]
        kept.append({"op": op, "kind": sim.kind.copy(), "ax": sim.out[forces.AX].copy(),
                     "az": sim.out[forces.AZ].copy(), "dt": dt, "n": n, "pairs": int(sim.pairs.count.sum())})
        del kept[:-systems]

    original = step_recording(sim, steps, keep)
    return kept, case.belt.speed, sim, original


def start_comparison(sim, original, blocks: int) -> dict:
    """CG iterations a step over alternating 10-step blocks, from the carried correction
    ("last correction") or from the explicit step."""
    def cold(dt):
        sim.implicit_cx[:] = 0.0
        sim.implicit_cz[:] = 0.0
        return original(dt)

    its = {"last correction": [], "explicit step": []}
    walls = {"last correction": [], "explicit step": []}
    for b in range(2 * blocks):
        name = "last correction" if b % 2 == 0 else "explicit step"
        sim._solve_viscous = original if b % 2 == 0 else cold
        for k in range(10):
            before = sim.solver_iterations
            tic = time.perf_counter()
            reason = sim.step()
            wall = time.perf_counter() - tic
            if reason:
                raise SystemExit(f"the run stopped: {reason}")
            if k > 0:  # a block's first step starts from the other block's last correction
                its[name].append(sim.solver_iterations - before)
                walls[name].append(wall)
    return its, walls


def solve(system: dict, tol: float, weights) -> tuple[np.ndarray, np.ndarray, int, float]:
    """CG on a kept system from the explicit step, with the pair weights ``weights``."""
    from solver import implicit
    ax = system["ax"].copy()
    az = system["az"].copy()
    work = np.zeros((implicit.WORK_ROWS, ax.size))
    op = list(system["op"])
    op[2] = weights
    tic = time.perf_counter()
    zero = np.zeros(ax.size)
    it, _ = implicit.solve(tuple(op), system["kind"], system["dt"], ax, az, zero, zero.copy(), system["n"], tol,
                           implicit.MAX_ITERATIONS, work)
    return ax[:system["n"]], az[:system["n"]], it, time.perf_counter() - tic


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--dp", type=float, default=0.00025)
    ap.add_argument("--ch", type=float, default=1.8)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--steps", type=int, default=40, help="steps to run before the kept systems end")
    ap.add_argument("--systems", type=int, default=5)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--tol", type=float, nargs="+", default=[1e-6, 1e-5, 1e-4, 1e-3])
    ap.add_argument("--blocks", type=int, default=5, help="10-step blocks of each start")
    a = ap.parse_args(argv)
    numba.set_num_threads(a.threads)
    systems, u_b, sim, original = capture(a.dp, a.ch, a.steps, a.systems)
    variants = [(tol, prec) for tol in a.tol for prec in ("float64", "float32")]
    stats = {v: {"it": [], "t": [], "err": []} for v in variants}
    for weights in (np.float64, np.float32):  # compile each precision before timing
        solve(systems[0], 1e-6, systems[0]["op"][2].astype(weights))
    for system in systems:
        w64 = system["op"][2].astype(np.float64)
        w32 = system["op"][2].astype(np.float32)
        ex, ez, _, _ = solve(system, 1e-12, w64)
        fluid = system["kind"][: system["n"]] == 0
        for r in range(a.rounds):
            for tol, prec in (variants if r % 2 == 0 else variants[::-1]):
                ax, az, it, t = solve(system, tol, w64 if prec == "float64" else w32)
                err = np.hypot(ax - ex, az - ez)[fluid].max() * system["dt"] / u_b
                s = stats[(tol, prec)]
                s["it"].append(it)
                s["t"].append(t)
                s["err"].append(err)
    dt = np.mean([s["dt"] for s in systems])
    n = systems[0]["n"]
    print(f"dp {a.dp * 1e3:g} mm, Ch {a.ch:g}: {n} particles, {systems[0]['pairs']} pairs, "
          f"mean dt {dt:.3g} s, {len(systems)} systems x {a.rounds} rounds, {a.threads} threads")
    print("| tolerance | pair weights | CG iterations | solve [ms] | ms an iteration "
          "| largest step error / u_b | per simulated s, summed |")
    print("|---|---|---|---|---|---|---|")
    for tol, prec in variants:
        s = stats[(tol, prec)]
        it = np.mean(s["it"])
        t = np.median(s["t"]) * 1e3
        err = max(s["err"])
        print(f"| {tol:g} | {prec} | {it:.1f} | {t:.1f} | {t / max(it, 1):.2f} | {err:.2e} | {err / dt:.2e} |")
    its, walls = start_comparison(sim, original, a.blocks)
    print(f"\nAs the solver runs, {a.blocks} alternating blocks of 10 steps (the first step of each "
          "block not counted):")
    for name, v in its.items():
        print(f"- from the {name}: {np.mean(v):.2f} CG iterations a step, "
              f"{np.median(walls[name]) * 1e3:.1f} ms a step (median), {len(v)} steps")


if __name__ == "__main__":
    main()
