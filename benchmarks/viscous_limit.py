"""How far the viscous time-step limit dt3 = h^2 / nu can be stretched, measured.

At the paper's finest resolution (dp = 0.25 mm, Ch = 1.8) the viscous limit C_CFL h^2/nu is
half the acoustic one, so it doubles the step count there. This script runs the film of
SPEC section 7 (the paper fluid on the 15.3 deg incline, periodic, coefsound 10 as in the
conveyor case; h_n = 18.76 mm deep, rounded to whole rows of dp: 19.0 mm at dp = 1 and 0.5 mm,
18.75 mm at 0.25 mm, the depth the error is measured against) at that dp and Ch from rest, with a fixed step
dt = C h^2 / nu for each C, to --end seconds (several viscous times H^2/nu = 0.087 s), and
reports whether it stays bounded and the RMS error of u(z) against the exact
semi-parabolic profile (in units of its surface velocity) at the end, beside the acoustic
step 0.2 h / c0 the solver would otherwise take. A bounded film also gets the depth H' and the
bed slip of the exact film fitted to its particles (``film_fit``).

With --implicit (or --update implicit) the film runs with `physics.viscous_update: implicit`
(backward Euler in the laminar term, solver/implicit.py), where C may exceed the explicit edge;
the CG iterations per step are reported. --update substepped integrates the laminar term by
RKC stages instead (the RKC stages per step are reported).

Usage: python benchmarks/viscous_limit.py [--dp 0.00025] [--ch 1.8] [--c 0.2 0.25 0.3 0.35 0.42]
           [--end 0.3] [--threads 2] [--implicit | --update substepped] [--physics KEY=VALUE ...]
"""
from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path

import numba
import numpy as np
import yaml

from solver import exact
from solver.scene import scene_from_dict
from solver.simulation import Simulation
from throughput import set_physics

ROOT = Path(__file__).resolve().parents[1]


def film(dp: float, ch: float, end: float, update: str = "explicit", physics=()) -> dict:
    d = yaml.safe_load((ROOT / "examples" / "film.yaml").read_text())
    H = round(0.01876 / dp) * dp  # whole rows: the lattice fills exactly this depth
    L = 24 * dp
    T = math.ceil(2 * ch) * dp
    d.update(dp=dp, ch=ch, periodic_x=[0.0, L], cfl=0.2)
    d["fluid"]["blocks"] = [{"x": [0.0, L], "z": [0.0, H]}]
    d["walls"] = [{"name": "bed", "x": [0.0, L], "z": [-T, 0.0]}]
    d["time"] = {"end": end, "output_interval": end}
    d.setdefault("physics", {})["viscous_update"] = update
    return set_physics(d, physics)


def film_depth(sim: Simulation) -> float:
    """The film's depth: the top of its fluid block (whole rows, ``film``)."""
    return max(b.z[1] for b in sim.scene.fluid.blocks)


def exact_error(sim: Simulation) -> float:
    """RMS of u - u_exact over fluid particles, over the exact surface velocity."""
    s = sim.scene
    f = sim.kind[:sim.n_active] == 0
    H = film_depth(sim)
    return exact.film_rms_error(sim.z[:sim.n_active][f], sim.u[:sim.n_active][f], H, s.gravity[0], s.nu)


def film_fit(sim: Simulation) -> tuple[float, float]:
    """(H', c) of the least-squares fit u = g sin(theta) / nu (z H' - z^2 / 2) + c to the fluid
    particles: the depth whose exact film the profile is, and the slip at the bed, c over the
    exact surface velocity of the rows' depth."""
    s = sim.scene
    f = sim.kind[:sim.n_active] == 0
    z, u = sim.z[:sim.n_active][f], sim.u[:sim.n_active][f]
    k = s.gravity[0] / s.nu
    (depth, slip), *_ = np.linalg.lstsq(np.c_[k * z, np.ones_like(z)], u + 0.5 * k * z * z, rcond=None)
    H = film_depth(sim)
    return float(depth), float(slip / (0.5 * k * H * H))


def run(dp: float, ch: float, C: float, end: float, update: str = "explicit", physics=()) -> dict:
    sim = Simulation(scene_from_dict(film(dp, ch, end, update, physics)))
    dt = C * sim.h ** 2 / sim.nu
    acoustic = 0.2 * sim.h / sim.c0
    steps = int(math.ceil(end / dt))
    tic = time.perf_counter()
    reason = ""
    for _ in range(steps):
        reason = sim.step(dt)
        if reason:
            break
    wall = time.perf_counter() - tic
    fit = (math.nan, math.nan) if reason else film_fit(sim)
    return {"film_depth_fit_mm": round(1e3 * fit[0], 4), "film_slip": round(fit[1], 5),
            "dp": dp, "ch": ch, "update": update, "physics": list(physics), "C": C, "dt": dt,
            "acoustic_dt": acoustic, "acoustic_C": round(dt * sim.c0 / sim.h, 3), "steps": sim.steps,
            "t": sim.t, "status": "diverged" if reason else "bounded", "reason": reason,
            "u_rms_error": math.nan if reason else exact_error(sim), "wall_s": round(wall, 1),
            "particles": sim.n, "cg_iterations_per_step": round(sim.solver_iterations / max(sim.steps, 1), 1),
            "rkc_stages_per_step": round(sim.rkc_stages / max(sim.steps, 1), 2)}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--dp", type=float, default=0.00025)
    ap.add_argument("--ch", type=float, default=1.8)
    ap.add_argument("--c", type=float, nargs="+", default=[0.2, 0.25, 0.3, 0.35, 0.42])
    ap.add_argument("--end", type=float, default=0.3)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--implicit", action="store_true", help="physics.viscous_update: implicit")
    ap.add_argument("--update", choices=["explicit", "implicit", "substepped"], default="explicit",
                    help="physics.viscous_update (--implicit: implicit)")
    ap.add_argument("--physics", nargs="*", default=[], metavar="KEY=VALUE",
                    help="scene physics settings, e.g. viscous_correction=true shifting.method=skillen")
    a = ap.parse_args(argv)
    numba.set_num_threads(a.threads)
    for C in a.c:
        print(json.dumps(run(a.dp, a.ch, C, a.end, "implicit" if a.implicit else a.update, a.physics)),
              flush=True)


if __name__ == "__main__":
    main()
