"""The viscous term: how far its time-step limit stretches, by update; with --forms, its two
forms side by side.

Limit: runs the periodic film of examples/film.yaml (the paper fluid on its 15.3 deg incline;
docs/scheme.md section 7) at --dp and --ch, 18.76 mm deep rounded to whole rows, from rest with a
fixed step dt = C h^2 / nu for each --c, to --end s (a few viscous times H^2 / nu = 0.087 s), and
reports whether it stays bounded, the RMS error of u(z) against the exact semi-parabolic profile
(over its surface velocity), the depth and bed slip of the exact film fitted to the particles, the
acoustic C that step amounts to, and the CG iterations or RKC stages a step. --update sets the
scene's viscous_update (explicit, implicit, substepped); --set overrides any other scene key.

--forms (``numerics.viscous_form``, docs/numerics.md): (1) the exact-solution cases of
tests/test_rheology.py (--exact) run to their end time with each form: Bingham and power-law
plane Poiseuille flow (L2 error of u over the largest exact velocity; the Bingham plug's largest
deviation from the exact plug speed) and the Herschel-Bulkley film (L2 error over the plug speed,
plug speed, the computed plug thickness's error); in plane shear the stress form's extra term
vanishes, so the two should agree. (2) The cost of a step: the Bingham slump of
config/slump.yaml (surge, --slump-dp), one simulation per form, stepped --steps steps each,
alternately for --rounds rounds (the host is noisy).

    python -m benchmarks.viscous_limit [--dp 0.00025] [--ch 1.8] [--c 0.2 0.25 0.3 0.35 0.42] [--end 0.3]
        [--update explicit] [--threads 2] [--case examples/film.yaml] [--set KEY=VALUE ...]
    python -m benchmarks.viscous_limit --forms [--slump-dp 0.002] [--steps 300] [--rounds 4]
        [--exact bingham powerlaw hb_film] [--threads 2]
"""
from __future__ import annotations

import copy
import json
import math
import statistics

import numpy as np

from benchmarks import common

QUICK = {"dp": 0.001, "c": [0.2, 0.42], "end": 0.05, "steps": 40, "rounds": 2, "exact": []}
FORMS = ("laminar", "stress")


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


def exact_errors(name: str, form: str) -> dict:
    """The exact-solution errors of example ``name`` (bingham, powerlaw, hb_film) with ``form``."""
    from solver import exact
    from tests import test_rheology as tr
    num = {"numerics": {"viscous_form": form}}
    if name == "hb_film":
        l2, plug_speed, plug = tr.film_errors(name, **num)
        return {"L2": l2, "plug speed": plug_speed, "plug thickness": plug}
    scene, z, u, _, _ = tr.steady_state(name, **num)
    f = scene.fluid
    tau_y = f.yield_stress if name == "bingham" else 0.0
    ue = exact.herschel_bulkley_channel(z, tr.L_CHANNEL, scene.gravity[0], f.density, tau_y, f.consistency, f.index)
    out = {"L2": tr.l2(u, ue, ue.max())}
    if name == "bingham":
        plug = np.abs(z - tr.L_CHANNEL / 2) < f.yield_stress / (f.density * scene.gravity[0])
        out["plug speed"] = float(np.abs(u[plug] / ue.max() - 1).max())
    return out


def slump_scene(dp: float, form: str) -> dict:
    """The Bingham slump of config/slump.yaml at ``dp`` with surge's numerics and ``form``."""
    from workflow.study import config as campaign
    from workflow.study.registry import flow_of
    cfg = campaign.load(common.ROOT / "config" / "slump.yaml")
    flow = flow_of(cfg)
    case = next(c for c in flow.cases(cfg) if c.fluid == "bingham" and c.scheme == "surge")
    case = type(case)(dp, case.ch, case.shifting, scheme=case.scheme, fluid=case.fluid, axes=case.axes)
    d = copy.deepcopy(flow.case_dict(cfg, case))
    d["numerics"]["viscous_form"] = form
    return d


def step_costs(dp: float, steps: int, rounds: int) -> dict:
    """Seconds per step of each form, per round (alternating which goes first)."""
    from solver.scene import scene_from_dict
    from solver.simulation import Simulation
    sims = {f: Simulation(scene_from_dict(slump_scene(dp, f))) for f in FORMS}
    for sim in sims.values():  # compile and leave the first steps
        for _ in range(5):
            assert not sim.step()
    times = {f: [] for f in FORMS}
    for r in range(rounds):
        for f in (FORMS if r % 2 == 0 else FORMS[::-1]):
            with common.Timer() as t:
                for _ in range(steps):
                    reason = sims[f].step()
                    assert not reason, reason
            times[f].append(t.seconds / steps)
    return {"times": times, "particles": sims["laminar"].n_fluid}


def compare_forms(a) -> None:
    """--forms: the exact-solution errors and the step cost of each viscous form."""
    rows = []
    for name in a.exact:
        errs = {f: exact_errors(name, f) for f in FORMS}
        for key in errs["laminar"]:
            rows.append([name, key] + [f"{100 * errs[f][key]:.3f} %" for f in FORMS])
    if rows:
        print("Exact solutions: the error with each form\n")
        print(common.table(["example", "error", *FORMS], rows) + "\n")
    cost = step_costs(a.slump_dp, a.steps, a.rounds)
    med = {f: statistics.median(cost["times"][f]) for f in FORMS}
    ratios = [s / lam for s, lam in zip(cost["times"]["stress"], cost["times"]["laminar"])]
    print(f"Step cost: Bingham slump at dp = {1e3 * a.slump_dp:g} mm ({cost['particles']} fluid particles), "
          f"{a.steps} steps per form and round, alternately\n")
    print(common.table(["form", "ms per step (median)", "per round"],
                       [[f, f"{1e3 * med[f]:.2f}", ", ".join(f"{1e3 * t:.2f}" for t in cost["times"][f])]
                        for f in FORMS]) + "\n")
    common.summary(f"stress form: {100 * (statistics.median(ratios) - 1):+.1f} % per step against laminar "
                   f"(median of {a.rounds} rounds, slump at dp {1e3 * a.slump_dp:g} mm)")


def main(argv=None) -> int:
    ap = common.parser(__doc__, case="examples/film.yaml")
    ap.add_argument("--dp", type=float, default=0.00025)
    ap.add_argument("--ch", type=float, default=1.8)
    ap.add_argument("--c", type=float, nargs="+", default=[0.2, 0.25, 0.3, 0.35, 0.42], help="C of dt = C h^2 / nu")
    ap.add_argument("--end", type=float, default=0.3, help="simulated time [s]")
    ap.add_argument("--update", default=None, help="the scene's viscous_update (default: the scene's own)")
    ap.add_argument("--json", action="store_true", help="one JSON object a run as well")
    ap.add_argument("--forms", action="store_true", help="the two viscous forms side by side instead")
    ap.add_argument("--slump-dp", type=float, default=0.002, help="--forms: the slump's dp for the step cost, m")
    ap.add_argument("--steps", type=int, default=300, help="--forms: steps per form and round")
    ap.add_argument("--rounds", type=int, default=4, help="--forms: alternating rounds")
    ap.add_argument("--exact", nargs="*", default=["bingham", "powerlaw", "hb_film"],
                    help="--forms: exact-solution examples to run with each form")
    a = common.parse(ap, argv, QUICK)
    a.threads = common.set_threads(a.threads)
    if a.forms:
        print(f"{common.now()}; {common.host()}; {a.threads} threads\n")
        compare_forms(a)
        return 0
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
