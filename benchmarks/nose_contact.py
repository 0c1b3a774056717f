"""The front's nose on the belt: how high it stands, and the pressure the belt carries under it.

Runs a conveyor case and, with every probe sample, takes the dp-wide columns behind the toe
(column c spans [toe - (c + 1) dp, toe - c dp]) and records per column: the lowest fluid
particle's height above the belt surface, the free surface's height (the highest fluid
particle + dp/2), and the mean pressure of the belt's top particle row (z in (-dp, 0)). From
``--from`` on it prints their means, the pressure's excess over the hydrostatic head of the
column above that row, rho0 |g_n| (surface - z_row), and for scale the viscous pressure of a
moving contact line, mu u_b / r (Huh and Scriven 1971: p ~ mu U / r, r the distance from the
contact line, here the column's centre behind the toe; mu the case's Newtonian viscosity), the
share of samples in which the belt row sits at the floor of the mDBC density (rho0, p = 0: no
fluid pressing on it), and the toe's rms about its line.

``--no-shift-at-wall-surface`` replaces the Skillen shift (for this process only) by one that
leaves unshifted the particles near a free surface (div r < 1.9) within reach of a wall (the
kernel-weighted wall-normal sum non-zero), which includes the nose's contact with the belt.

``--slip-near-toe L`` lets the belt slip (for this process only) from L dp behind the toe
forward: after the mDBC update, a belt particle there takes the tangential velocity
u_b = u_wall + beta (u_wall - u_g) instead of its no-slip mirror 2 u_wall - u_g (beta 1), u_g
the ghost node's; ``--slip-beta`` sets beta (-1, the default: free slip, u_b = u_g; 0: the
wall's own velocity). The normal component stays mirrored. The toe is the monitor's, updated
with every probe sample. A slip patch at the contact line is the usual regularisation of the
moving contact line's stress singularity; SPEC and the paper have a no-slip belt.

    python benchmarks/nose_contact.py examples/conveyor_fast.yaml --set steady.stop=false \\
        --set steady.max_time=6 -o results/nose.npz [--no-shift-at-wall-surface]
    python benchmarks/nose_contact.py --analyse results/nose.npz [--from 3]
"""
from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numba as nb
import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

COLUMNS = 14
FIELDS = ("lowest", "surface", "wall_p")


def column_stats(x, z, kind, p, toe: float, dp: float, columns: int = COLUMNS) -> dict:
    """Per dp-wide column behind the toe: lowest fluid z, free-surface z (top + dp/2), mean p of
    the belt's top row (z in (-dp, 0)); NaN where a column holds none."""
    out = {k: np.full(columns, np.nan) for k in FIELDS}
    fluid = kind == 0
    row = (kind != 0) & (z < 0.0) & (z > -dp)
    for c in range(columns):
        inside = (x <= toe - c * dp) & (x > toe - (c + 1) * dp)
        f = fluid & inside
        if f.any():
            out["lowest"][c] = z[f].min()
            out["surface"][c] = z[f].max() + 0.5 * dp
        w = row & inside
        if w.any():
            out["wall_p"][c] = p[w].mean()
    return out


def skillen_without_wall_surface_shift():
    """``shifting.skillen_shift`` but no shift where div r < 1.9 within reach of a wall."""
    from solver.shifting import _off_wall

    @nb.njit(parallel=True)
    def skillen_shift(kind, u, w, gcx, gcz, divr, wnx, wnz, s0, n_active, A, h, dt, thr, clip, min_speed,
                      dx_out, dz_out):
        for i in nb.prange(n_active):
            dx_out[i] = 0.0
            dz_out[i] = 0.0
            if kind[i] != 0 or divr[i] < thr:
                continue
            near_wall = wnx[i] != 0.0 or wnz[i] != 0.0
            if near_wall and divr[i] < 1.9:
                continue
            f = min((divr[i] - thr) / (2.0 - thr), 1.0)
            speed = math.sqrt(u[i] * u[i] + w[i] * w[i])
            if not near_wall:
                speed = max(speed, min_speed)
            c = -A * h * speed * dt * f
            dx_out[i], dz_out[i] = _off_wall(min(max(c * gcx[i], -clip), clip),
                                             min(max(c * gcz[i], -clip), clip), wnx[i], wnz[i], s0)

    return skillen_shift


@nb.njit(parallel=True, cache=True)
def _slip_tangential(x, u, kind, wall, vwall, n_active, belt, x_from, beta):
    """Belt particles at x > x_from: u = u_wall + beta (u_wall - u_g), u_g = 2 u_wall - u the
    ghost velocity the mDBC mirrored (beta 1: no slip, unchanged; 0: u_wall; -1: free slip)."""
    for i in nb.prange(n_active):
        if kind[i] == 1 and wall[i] == belt and x[i] > x_from:
            vw = vwall[belt, 0]
            u[i] = vw + beta * (u[i] - vw)


def mdbc_with_slip_near_toe(state: dict):
    """``boundary.make_mdbc_update`` whose update then frees the belt's tangential velocity at
    x > state["x_from"] by state["beta"] (belt: wall index state["belt"])."""
    from solver import boundary

    shipped_make = boundary.make_mdbc_update

    def make(*args, **kwargs):
        shipped = shipped_make(*args, **kwargs)

        def mdbc_update(x, z, u, w, rho, mass, kind, wall, gxs, gzs, vwall, cl, n_active, *rest):
            shipped(x, z, u, w, rho, mass, kind, wall, gxs, gzs, vwall, cl, n_active, *rest)
            _slip_tangential(x, u, kind, wall, vwall, n_active, state["belt"], state["x_from"], state["beta"])

        return mdbc_update

    return make


def run(case_path: str, sets, out: str, no_wall_surface_shift: bool, slip_near_toe: float | None = None,
        slip_beta: float = -1.0) -> None:
    from sampled_run import load_case, report, run_sampled
    from solver import shifting

    case = load_case(case_path, sets)
    if no_wall_surface_shift:
        if case.shifting != "skillen":
            raise ValueError("--no-shift-at-wall-surface: applies to shifting skillen only")
        shifting.skillen_shift = skillen_without_wall_surface_shift()
    slip = {"belt": 0, "x_from": math.inf, "beta": slip_beta}  # no slip until the first sample gives the toe
    if slip_near_toe is not None:
        from solver import boundary
        boundary.make_mdbc_update = mdbc_with_slip_near_toe(slip)

    def columns(sim, d, case) -> dict:
        if slip_near_toe is not None:
            if math.isinf(slip["x_from"]):  # the first sample: find the belt once
                slip["belt"] = [wl.name for wl in sim.scene.walls].index("belt")
            slip["x_from"] = d["toe"] - slip_near_toe * sim.scene.dp
        n = sim.n_active
        got = column_stats(sim.x[:n], sim.z[:n], sim.kind[:n], sim.p[:n], d["toe"], sim.scene.dp)
        return {"t": sim.t, "toe": d["toe"], **{k: got[k] for k in FIELDS}}

    ds, series = run_sampled(case, columns)
    g_n = case.gravity * math.cos(math.radians(case.slope_deg))  # bed-normal gravity
    np.savez(out, dp=case.dp, ub=case.belt.speed, mu=case.viscosity, rho0=case.density, g_n=g_n,
             **series)
    report(case, ds, out)


def analyse(path: str, start: float) -> None:
    d = np.load(path)
    dp, ub, mu, rho0, g_n = (float(d[k]) for k in ("dp", "ub", "mu", "rho0", "g_n"))
    t = d["t"]
    m = t >= start - 1e-9
    if m.sum() < 2:
        print(f"{Path(path).name}: fewer than 2 samples from {start:g} s (the run ends at {t[-1]:.2f} s)")
        return
    toe = d["toe"][m]
    res = toe - np.polyval(np.polyfit(t[m], toe, 1), t[m])
    r = (np.arange(COLUMNS) + 0.5) * dp
    lowest = np.nanmean(d["lowest"][m], 0)
    lifted = np.nanmean(d["lowest"][m] > dp, 0)
    surface = np.nanmean(d["surface"][m], 0)
    wall_p = np.nanmean(d["wall_p"][m], 0)
    floor = np.mean(d["wall_p"][m] <= 0.0, 0)  # the mDBC density floor rho0: no fluid pressing
    head = rho0 * g_n * np.nanmean(d["surface"][m] + 0.5 * dp, 0)  # the top row's centres lie at -dp/2
    print(f"{Path(path).name}: {m.sum()} samples from {start:g} s; toe rms about its line {res.std() / dp:.2f} dp")
    print("| column centre behind the toe [dp] | lowest fluid [dp] | share with lowest > 1 dp | surface [dp] | "
          "belt row p [Pa] | share with it at its floor (p = 0) | hydrostatic head [Pa] | excess [Pa] | "
          "mu u_b / r [Pa] |")
    print("|---|---|---|---|---|---|---|---|---|")
    for c in range(COLUMNS):
        print(f"| {r[c] / dp:.1f} | {lowest[c] / dp:.2f} | {lifted[c]:.2f} | {surface[c] / dp:.2f} | {wall_p[c]:.0f} | "
              f"{floor[c]:.2f} | {head[c]:.0f} | {wall_p[c] - head[c]:.0f} | {mu * ub / r[c]:.0f} |")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("case", nargs="?", help="conveyor case YAML to run")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    ap.add_argument("-o", "--out", default="nose_contact.npz")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--no-shift-at-wall-surface", action="store_true")
    ap.add_argument("--slip-near-toe", type=float, metavar="L",
                    help="slip on the belt from L dp behind the toe forward")
    ap.add_argument("--slip-beta", type=float, default=-1.0,
                    help="there u_b = u_wall + beta (u_wall - u_g): -1 free slip (default), "
                         "0 the wall's velocity, 1 no slip")
    ap.add_argument("--analyse", nargs="*", default=[], metavar="NPZ", help="analyse earlier runs")
    ap.add_argument("--from", dest="start", type=float, default=3.0, help="first second analysed")
    a = ap.parse_args(argv)
    if a.case:
        import numba

        from solver.scene import SceneError
        numba.set_num_threads(a.threads)
        try:
            run(a.case, a.set, a.out, a.no_shift_at_wall_surface, a.slip_near_toe, a.slip_beta)
        except (SceneError, OSError, ValueError) as exc:
            print(f"error: {exc}", file=sys.stderr)
            return 2
        analyse(a.out, a.start)
    for path in a.analyse:
        analyse(path, a.start)
    if not (a.case or a.analyse):
        ap.error("give a case to run or --analyse NPZ")
    return 0


if __name__ == "__main__":
    sys.exit(main())
