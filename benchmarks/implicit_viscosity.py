"""What the implicit laminar term (physics.viscous_update: implicit) costs and saves, measured.

1. The paper case with config/paper.yaml's scheme (examples/conveyor.yaml, skillen) at cfl 0.4,
   cfl_viscous 0.2 (the scheme's step until it took the sub-stepped update at cfl 0.6) at
   dp = 1 mm (--time s simulated) and 0.25 mm (--fine-time s) for each Ch of --ch, with the
   explicit and the implicit update alternated within each of --rounds rounds (the machine is
   noisy), started at h_n (start_depth: theory, no start-up film: only the
   stepping is timed): steps, dt, ms a step, CG iterations a step, particle-steps/s, and the
   wall time per simulated second.
2. The Herschel-Bulkley film (examples/hb_film.yaml) to --film-end s with each update: steps,
   wall, CG iterations a step, and the L2 error of u against the exact film over the plug
   velocity.

Usage: python benchmarks/implicit_viscosity.py [--threads 2] [--rounds 1] [--time 0.05]
           [--fine-time 0.01] [--ch 1 1.3 1.8 2.2] [--film-end 1.2] [--skip-paper] [--skip-film]
Prints one JSON line per run.
"""
from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

import numba
import numpy as np
import yaml

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

SETTINGS = {
    "explicit": {"viscous_update": "explicit", "start_depth": "theory", "cfl": 0.4},
    "implicit": {"viscous_update": "implicit", "start_depth": "theory", "cfl": 0.4},
}


def film(update: str, end: float) -> dict:
    from solver import exact
    from solver.scene import scene_from_dict
    from solver.simulation import Simulation
    d = yaml.safe_load((ROOT / "examples" / "hb_film.yaml").read_text())
    d["physics"]["viscous_update"] = update
    d["time"] = {"end": end, "output_interval": end}
    sim = Simulation(scene_from_dict(d))
    tic = time.perf_counter()
    while sim.t < end - 1e-12:
        reason = sim.step(min(sim.info.dt, end - sim.t))
        if reason:
            return {"case": "hb_film", "update": update, "status": reason}
    wall = time.perf_counter() - tic
    s = sim.scene
    f = s.fluid
    H = f.blocks[0].z[1]
    n = sim.n_active
    fl = sim.kind[:n] == 0
    z, u = sim.z[:n][fl], sim.u[:n][fl]
    ue = exact.herschel_bulkley_film(z, H, s.gravity[0], f.density, f.yield_stress, f.consistency, f.index)
    up = exact.herschel_bulkley_film(H, H, s.gravity[0], f.density, f.yield_stress, f.consistency, f.index)
    return {"case": "hb_film", "update": update, "t": sim.t, "steps": sim.steps, "wall": round(wall, 2),
            "cg_per_step": round(sim.solver_iterations / sim.steps, 1),
            "l2_percent": round(100 * float(np.sqrt(np.mean((u - ue) ** 2)) / up), 3)}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--rounds", type=int, default=1)
    ap.add_argument("--ch", type=float, nargs="+", default=[1.0, 1.3, 1.8, 2.2])
    ap.add_argument("--time", type=float, default=0.05)
    ap.add_argument("--fine-time", type=float, default=0.01)
    ap.add_argument("--film-end", type=float, default=1.2)
    ap.add_argument("--skip-paper", action="store_true")
    ap.add_argument("--skip-film", action="store_true")
    a = ap.parse_args(argv)
    numba.set_num_threads(a.threads)
    from paper_grid import measure
    if not a.skip_paper:
        for s in SETTINGS.values():
            measure(0.002, 1.8, "skillen", 0.003, s)  # compile
        for rnd in range(a.rounds):
            for dp, sim_time in ((0.001, a.time), (0.00025, a.fine_time)):
                for ch in a.ch:
                    for name, s in SETTINGS.items():
                        r = measure(dp, ch, "skillen", sim_time, s)
                        stepping = r["wall"] - r["startup"]
                        r.update(setting=name, round=rnd, ms_per_step=round(1e3 * stepping / r["steps"], 2),
                                 wall_per_simulated_s=round(stepping / r["simulated"], 1))
                        print(json.dumps(r), flush=True)
    if not a.skip_film:
        for update in ("explicit", "implicit"):
            film(update, 0.01)  # compile
            print(json.dumps(film(update, a.film_end)), flush=True)


if __name__ == "__main__":
    main()
