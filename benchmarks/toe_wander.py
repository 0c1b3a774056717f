"""How far the toe wanders, and what that does to zeta_f's one-second toe velocity.

zeta_f (SPEC section 4) is the toe's velocity averaged over one second. This script reads
finished front runs and, from ``--from`` on, gives:
- the toe's rms about its least-squares line and the lag at which its autocorrelation first
  falls below zero (how slowly it wanders);
- over each whole second: the toe's least-squares velocity and its standard error
  (``solver.steady.trend_bound``, as zeta_f and its se are computed), as per cent of u_b; the
  rms and largest |v|, the median 2 se, the seconds whose |v| lies within 2 se (of a front
  that does not move, 95 % if the se describes the second-to-second scatter), and the fraction
  of seconds with |v| < 1 % and with |v| + 2 se < 1 %;
- the equivalent front's one-second velocity (rms), the front body's own motion.

With ``--estimators CASE [--set KEY=VALUE ...] -o OUT.npz`` it first runs the case and samples,
next to every probe sample, toe positions that do not jump by a particle: the most downstream
x where the kernel concentration of the fluid (``cf``) or of all particles (``ca``) on the line
z = a dp crosses half-way between its value in the uniform zone (or beyond the tip, ``ca``)
and zero, for a = 0.5, 1, 2, and where the free surface z_max stands at 1, 2 or 4 dp (``s``).
Each is then analysed as the toe is. The run goes through ``solver.front.run_front`` with its
monitor's ``sample`` extended (benchmarks/sampled_run.py).

    python benchmarks/toe_wander.py results/s32/sub06-skillen-20s.nc results/s32/sub06-lind-20s.nc
    python benchmarks/toe_wander.py --estimators examples/conveyor_fast.yaml --set steady.stop=false \\
        --set steady.max_time=6 -o results/toe.npz --from 2
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

from solver.steady import trend_bound  # noqa: E402

LINES = (("half", 0.5), ("one", 1.0), ("two", 2.0))  # z = a dp above the bed
LEVELS = (("s1", 1.0), ("s2", 2.0), ("s4", 4.0))  # free-surface heights, dp


def wander(t, y, ub: float, start: float) -> dict:
    """Rms about the trend, autocorrelation's first zero, and one-second velocities of y."""
    t, y = np.asarray(t, float), np.asarray(y, float)
    m = (t >= start - 1e-9) & np.isfinite(y)
    t, y = t[m], y[m]
    res = y - np.polyval(np.polyfit(t, y, 1), t)
    acf = np.correlate(res, res, "full")[res.size - 1:]
    zero = float(np.argmax(acf < 0) * np.median(np.diff(t)))
    v, se = [], []
    for a in np.arange(start, t[-1] - 1.0 + 1e-6, 1.0):
        w = (t >= a - 1e-9) & (t <= a + 1.0 + 1e-9)
        s, e = trend_bound(t[w], y[w])
        v.append(s / ub)
        se.append(e / ub)
    v, se = 100.0 * np.array(v), 100.0 * np.array(se)
    return {"rms": float(np.std(res)), "acf_zero": zero, "seconds": v.size,
            "v_rms": float(np.sqrt(np.mean(v ** 2))), "v_max": float(np.max(np.abs(v))),
            "se2_median": float(np.median(2.0 * se)), "below_1": float(np.mean(np.abs(v) < 1.0)),
            "below_1_2se": float(np.mean(np.abs(v) + 2.0 * se < 1.0)),
            "within_2se": int(np.sum(np.abs(v) <= 2.0 * se))}


def row(name: str, w: dict, dp: float) -> str:
    return (f"| {name} | {w['rms'] / dp:.2f} | {w['acf_zero']:.2f} | {w['seconds']} | {w['v_rms']:.2f} | "
            f"{w['v_max']:.2f} | {w['se2_median']:.2f} | {w['within_2se']} | {w['below_1']:.2f} | "
            f"{w['below_1_2se']:.2f} |")


HEADER = ("| signal | rms about trend [dp] | acf zero [s] | seconds | 1 s velocity rms [% u_b] | largest | "
          "2 se median | seconds with abs(v) <= 2 se | share abs(v) < 1 % | share abs(v) + 2 se < 1 % |\n"
          "|---|---|---|---|---|---|---|---|---|---|")


def analyse_runs(paths, start: float) -> None:
    import xarray as xr
    print(HEADER)
    for path in paths:
        with xr.open_dataset(path) as ds:
            ub, dp, t = float(ds.attrs["belt_speed_m_s"]), float(ds.attrs["dp"]), ds.time.values
            name = Path(path).stem
            print(row(f"{name}: toe", wander(t, ds.toe_position.values, ub, start), dp))
            print(row(f"{name}: equivalent front", wander(t, ds.front_equivalent.values, ub, start), dp))


def run_estimators(case_path: str, sets, out: str) -> None:
    from sampled_run import load_case, report, run_sampled
    from solver.probes import FieldSampler, last_crossing

    case = load_case(case_path, sets)

    def estimators(sim, d, case) -> dict:
        dp, hn, toe = sim.scene.dp, case.h_n, d["toe"]
        fs = FieldSampler(sim)
        xg = np.arange(toe - 10.0 * dp, toe + 3.0 * dp, 0.05 * dp)
        x_in = toe - np.linspace(*case.probes.uniform_zone, 7) * hn
        got = {"t": sim.t, "toe": toe, "front_equivalent": d["front_equivalent"]}
        for name, a in LINES:
            line = fs.points(xg, np.full(xg.size, a * dp))
            c_in = float(np.mean(fs.points(x_in, np.full(x_in.size, a * dp))[1]))
            got[f"cf_{name}"] = last_crossing(xg, line[1], 0.5 * c_in)
            got[f"ca_{name}"] = last_crossing(xg, line[0], 0.5 * (1.0 + line[0][-1]))
        zs = fs.surface(xg, 0.0)
        for name, a in LEVELS:
            got[name] = last_crossing(xg, zs, a * dp)
        return got

    ds, series = run_sampled(case, estimators)
    np.savez(out, ub=case.belt.speed, dp=case.dp, **series)
    report(case, ds, out)


def analyse_estimators(path: str, start: float) -> None:
    d = np.load(path)
    ub, dp, t = float(d["ub"]), float(d["dp"]), d["t"]
    print(HEADER)
    for k in d.files:
        if k not in ("ub", "dp", "t"):
            w = wander(t, d[k], ub, start)
            off = np.nanmean(d[k][t >= start] - d["toe"][t >= start]) / dp
            print(row(f"{k} (mean {off:+.2f} dp from the toe)", w, dp))


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("runs", nargs="*", help="front-run NetCDFs to analyse")
    ap.add_argument("--estimators", metavar="CASE", help="run CASE, sampling the jump-free toes too")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    ap.add_argument("-o", "--out", default="toe_estimators.npz")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--from", dest="start", type=float, default=3.0, help="first second analysed")
    a = ap.parse_args(argv)
    if a.estimators:
        import numba

        from solver.scene import SceneError
        numba.set_num_threads(a.threads)
        try:
            run_estimators(a.estimators, a.set, a.out)
        except (SceneError, OSError, ValueError) as exc:
            print(f"error: {exc}", file=sys.stderr)
            return 2
        analyse_estimators(a.out, a.start)
    if a.runs:
        analyse_runs(a.runs, a.start)
    if not (a.runs or a.estimators):
        ap.error("give runs to analyse or --estimators CASE")
    return 0


if __name__ == "__main__":
    sys.exit(main())
