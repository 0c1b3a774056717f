"""How far the viscous time-step limit dt = C h^2 / nu can be stretched, by laminar-term update.

Runs the periodic film of examples/film.yaml (the paper fluid on its 15.3 deg incline; docs/scheme.md
section 7) at --dp and --ch, 18.76 mm deep rounded to whole rows, from rest with a fixed step
dt = C h^2 / nu for each --c, to --end s (a few viscous times H^2 / nu = 0.087 s), and reports
whether it stays bounded, the RMS error of u(z) against the exact semi-parabolic profile (over
its surface velocity), the depth and bed slip of the exact film fitted to the particles, the
acoustic C that step amounts to, and the CG iterations or RKC stages a step. --update sets the
scene's viscous_update (explicit, implicit, substepped); --set overrides any other scene key.

    python -m benchmarks.viscous_limit [--dp 0.00025] [--ch 1.8] [--c 0.2 0.25 0.3 0.35 0.42] [--end 0.3]
        [--update explicit] [--threads 2] [--case examples/film.yaml] [--set KEY=VALUE ...]
"""
from __future__ import annotations

import json
import math

import numpy as np

from benchmarks import common

QUICK = {"dp": 0.001, "c": [0.2, 0.42], "end": 0.05}


def film(path, dp: float, ch: float, end: float, update: str | None, sets=()) -> dict:
    """The film scene at dp and Ch, 18.76 mm deep in whole rows, 24 dp long."""
    d = common.read_yaml(path)
    H = round(0.01876 / dp) * dp  # whole rows: the lattice fills exactly this depth
    L, T = 24 * dp, math.ceil(2 * ch) * dp
    d.update(dp=dp, ch=ch, periodic_x=[0.0, L], time={"end": end, "output_interval": end})
    d["fluid"]["blocks"] = [{"x": [0.0, L], "z": [0.0, H]}]
    d["walls"] = [{"name": "bed", "x": [0.0, L], "z": [-T, 0.0]}]
    if update:
        common.numerics_block(d)["viscous_update"] = update
    return common.override(d, sets)


def fluid_of(sim) -> tuple[np.ndarray, np.ndarray, float]:
    """(z, u) of the fluid particles and the film's depth (the top of its fluid block)."""
    n = sim.n_active
    f = sim.kind[:n] == 0
    return sim.z[:n][f], sim.u[:n][f], max(b.z[1] for b in sim.scene.fluid.blocks)


def exact_error(sim) -> float:
    """RMS of u - u_exact over the fluid particles, over the exact surface velocity."""
    from solver import exact
    z, u, H = fluid_of(sim)
    return exact.film_rms_error(z, u, H, sim.scene.gravity[0], sim.scene.nu)


def film_fit(sim) -> tuple[float, float]:
    """(H', c) of the least-squares fit u = g sin(theta) / nu (z H' - z^2 / 2) + c: the depth
    whose exact film the profile is, and the bed slip c over the exact surface velocity."""
    z, u, H = fluid_of(sim)
    k = sim.scene.gravity[0] / sim.scene.nu
    (depth, slip), *_ = np.linalg.lstsq(np.c_[k * z, np.ones_like(z)], u + 0.5 * k * z * z, rcond=None)
    return float(depth), float(slip / (0.5 * k * H * H))


def run(scene: dict, C: float, end: float) -> dict:
    sim = common.simulation(scene)
    dt = C * sim.h ** 2 / sim.nu
    reason = ""
    with common.Timer() as t:
        for _ in range(int(math.ceil(end / dt))):
            reason = sim.step(dt)
            if reason:
                break
    depth, slip = (math.nan, math.nan) if reason else film_fit(sim)
    steps = max(sim.steps, 1)
    return {"dp": sim.scene.dp, "ch": sim.scene.ch, "C": C, "dt": dt, "acoustic_C": dt * sim.c0 / sim.h,
            "steps": sim.steps, "t": sim.t, "status": "diverged" if reason else "bounded", "reason": reason,
            "u_rms_error": math.nan if reason else exact_error(sim), "film_depth_fit_mm": 1e3 * depth,
            "film_slip": slip, "wall_s": t.seconds, "particles": sim.n,
            "cg_per_step": getattr(sim, "solver_iterations", 0) / steps,
            "rkc_per_step": getattr(sim, "rkc_stages", 0) / steps}


def main(argv=None) -> int:
    ap = common.parser(__doc__, case="examples/film.yaml")
    ap.add_argument("--dp", type=float, default=0.00025)
    ap.add_argument("--ch", type=float, default=1.8)
    ap.add_argument("--c", type=float, nargs="+", default=[0.2, 0.25, 0.3, 0.35, 0.42], help="C of dt = C h^2 / nu")
    ap.add_argument("--end", type=float, default=0.3, help="simulated time [s]")
    ap.add_argument("--update", default=None, help="the scene's viscous_update (default: the scene's own)")
    ap.add_argument("--json", action="store_true", help="one JSON object a run as well")
    a = common.parse(ap, argv, QUICK)
    a.threads = common.set_threads(a.threads)
    scene = film(a.case, a.dp, a.ch, a.end, a.update, a.sets)
    rows = []
    for C in a.c:
        rows.append(run(scene, C, a.end))
        if a.json:
            print(json.dumps(rows[-1]), flush=True)
    print(f"{a.case.name} at dp = {a.dp * 1e3:g} mm, Ch = {a.ch:g}, update {a.update or 'as the scene'}"
          f"{''.join(' ' + s for s in a.sets)}, to {a.end:g} s, {a.threads} threads")
    print(common.table(
        ["C (h^2 / nu)", "acoustic C", "dt [s]", "steps", "status", "u RMS error", "fitted depth [mm]", "bed slip",
         "CG / step", "RKC stages / step", "wall [s]"],
        [[f"{r['C']:g}", f"{r['acoustic_C']:.3f}", f"{r['dt']:.3g}", r["steps"], r["status"] + (
            f" ({r['reason'][:60]})" if r["reason"] else ""), f"{r['u_rms_error']:.4f}",
          f"{r['film_depth_fit_mm']:.3f}", f"{r['film_slip']:+.4f}", f"{r['cg_per_step']:.1f}",
          f"{r['rkc_per_step']:.2f}", f"{r['wall_s']:.1f}"] for r in rows]))
    bounded = [r["C"] for r in rows if r["status"] == "bounded"]
    common.summary(f"film at dp {a.dp * 1e3:g} mm, Ch {a.ch:g}, update {a.update or 'as the scene'}: bounded at C = "
                   + (", ".join(f"{c:g}" for c in bounded) or "none") + f" of {', '.join(f'{c:g}' for c in a.c)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
