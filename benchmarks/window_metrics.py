"""Metrics over successive windows of one front run: when the start's transient ends and whether
the front stays settled (best on runs with steady.stop: false and a long max_time).

For each window [t0, t0 + length], t0 from --from (seconds, or ``steady``: the steady detection
of solver/steady.py replayed on the run's probe series) in steps of --stride, it prints the
study's metrics over the window (study.metrics.case_metrics against lubrication theory, the
probe series averaged over the window as a run averages its steady window), the uniform
depth's deviation from its mean over all windows [% h_n], the enclosed-area drift, the toe's
deviation from its mean [dp], and where the run has them the volume budget by zone
(enclosed / mass-implied area - 1: wall, body, front) and the interior disorder
h |sum V gradW|. Then the settling targets over those windows (depth within 0.5 % h_n, area
drift within 1 %, toe within 1 dp) and the toe's hold-out: the share of 2 s windows, one
every 0.1 s, whose mean toe lies beyond 1 dp of its mean.

    python -m benchmarks.window_metrics RUN.nc [RUN.nc ...] [--length 1 --stride 0.5 --from 1]
    python -m benchmarks.window_metrics RUN.nc --length 2 --stride 2 --from steady
    python -m benchmarks.window_metrics --quick [--set KEY=VALUE]    (runs a coarse front first)
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import xarray as xr

from benchmarks import common

QUICK_RUN = ["dp=0.004", "steady.max_time=3.0", "steady.stop=false"]


def window_run(run: xr.Dataset, t0: float, t1: float) -> xr.Dataset:
    """The run with its window means and front velocity taken over [t0, t1]."""
    from solver import steady
    t = run.time.values
    win = (t >= t0 - 1e-9) & (t <= t1 + 1e-9)
    avg = run.isel(time=win).mean("time")
    out = run.copy()
    for k in ("surface_elevation", "velocity_star", "uniform_depth"):
        out[f"mean_{k}"] = avg[k]
    out["front_velocity"] = ((), steady.front_velocity_fit(t[win], run.toe_position.values[win])[0])
    out = out.isel(time=win)  # zeta_f's standard error from this window's toe
    out.attrs["status"] = "completed"
    return out


def replay(run: xr.Dataset) -> tuple[float, list]:
    """(start of the first verified averaging window, withdrawn detections) of the current
    steady detection on the run's probe series."""
    from solver.steady import SteadyTracker
    case = common.run_case(run)
    t = run.time.values
    front, depth, stations = run.front_equivalent.values, run.uniform_depth.values, run.station_front.values
    tr = SteadyTracker(case.criteria(), case.belt.speed, case.h_n, case.steady.average)
    for k in range(2, t.size):
        if tr.update(t[:k + 1], front[:k + 1], depth[:k + 1], stations[:k + 1]) == "steady":
            return tr.t_steady, [a for a, _ in tr.rejected]
    return math.nan, [a for a, _ in tr.rejected]


def in_window(t: np.ndarray, t0: float, t1: float) -> np.ndarray:
    return (t >= t0 - 1e-9) & (t <= t1 + 1e-9)


def table(run: xr.Dataset, length: float, stride: float, start: float) -> list[dict]:
    """One row a window: its metrics and settling figures."""
    ref = common.reference(run)
    t, hn, dp = run.time.values, float(run.attrs["h_n_m"]), float(run.attrs["dp"])
    rows = []
    t0 = start
    while t0 + length <= float(t[-1]) + 1e-9:
        w = in_window(t, t0, t0 + length)
        row = {"t0": t0, "t1": t0 + length, **common.metrics(window_run(run, t0, t0 + length), ref),
               "depth": float(np.nanmean(run.uniform_depth.values[w])) / hn,
               "area_drift": float(np.nanmean(run.area_drift.values[w])) if "area_drift" in run else math.nan,
               "toe": float(np.mean(run.toe_position.values[w])) / dp}
        if "zone_enclosed_area" in run:
            e = run.zone_enclosed_area.values[w].mean(axis=0)
            m = run.zone_mass_area.values[w].mean(axis=0)
            row["zones"] = [float(x / y - 1) if y > 0 else math.nan for x, y in zip(e[:3], m[:3])]
        if "disorder" in run:
            grad_sum = run.disorder.values[in_window(run[run.disorder.dims[0]].values, t0, t0 + length)][:, -1]
            row["disorder"] = float(np.nanmean(grad_sum)) if np.isfinite(grad_sum).any() else math.nan
        rows.append(row)
        t0 = round(t0 + stride, 10)
    return rows


def sliding_toe(run: xr.Dataset, start: float, window: float = 2.0, step: float = 0.1) -> tuple[float, float, int]:
    """(share beyond 1 dp, largest |deviation| [dp], windows) of the toe's means over ``window``
    s windows every ``step`` s from ``start``, against its mean over [start, end]."""
    t, dp = run.time.values, float(run.attrs["dp"])
    toe = run.toe_position.values / dp
    mean = float(np.mean(toe[t >= start - 1e-9]))
    devs, a = [], start
    while a + window <= t[-1] + 1e-9:
        devs.append(abs(float(np.mean(toe[in_window(t, a, a + window)])) - mean))
        a += step
    if not devs:
        return math.nan, math.nan, 0
    return float(np.mean(np.array(devs) > 1.0)), float(max(devs)), len(devs)


def report(path: Path, length: float, stride: float, start: str) -> str:
    with xr.open_dataset(path) as ds:
        run = ds.load()
    a = run.attrs
    t_det, withdrawn = replay(run)
    t0 = (t_det if np.isfinite(t_det) else 2.0) if start == "steady" else float(start)
    print(f"\n{path.name}: {a.get('shifting', '?')}, dp = {float(a['dp']) * 1e3:g} mm, Ch = {a.get('ch', '?')}, "
          f"{a['status']} at {float(a['simulated_time_s']):.2f} s; steady detection replayed: "
          + (f"window from {t_det:.2f} s" if np.isfinite(t_det) else "no verified window")
          + (f", withdrawn at {', '.join(f'{v:.2f}' for v in withdrawn)} s" if withdrawn else ""))
    rows = table(run, length, stride, t0)
    if not rows:
        print(f"no {length:g} s window from {t0:g} s")
        return f"{path.name}: no window"
    stations = [k for k in rows[0] if k.startswith("zeta_u_")]
    depth = float(np.mean([r["depth"] for r in rows]))
    toe = float(np.mean([r["toe"] for r in rows]))
    print(common.table(
        ["window [s]", "zeta_f % (2 se)", "zeta_h %", "zeta_fs", *stations, "depth dev. % h_n", "area drift %",
         "toe dev. [dp]", "wall / body / front volume %", "disorder"],
        [[f"{r['t0']:.1f}-{r['t1']:.1f}", f"{100 * r['zeta_f']:.2f} ({200 * r['zeta_f_se']:.2f})",
          f"{100 * r['zeta_h']:.2f}", f"{r['zeta_fs']:.4f}", *(f"{r[k]:.4f}" for k in stations),
          f"{100 * (r['depth'] - depth):+.2f}", f"{100 * r['area_drift']:+.2f}", f"{r['toe'] - toe:+.2f}",
          " / ".join(f"{100 * v:+.1f}" for v in r.get("zones", [math.nan] * 3)), f"{r.get('disorder', math.nan):.4f}"]
         for r in rows]))
    dev_depth = max(abs(r["depth"] - depth) for r in rows)
    dev_area = max(abs(r["area_drift"]) for r in rows)
    dev_toe = max(abs(r["toe"] - toe) for r in rows)
    share, largest, n = sliding_toe(run, t0)
    print(f"targets from {t0:.2f} s: depth within 0.5 % h_n of its mean: {dev_depth <= 0.005} "
          f"({100 * dev_depth:.2f} %); area drift within 1 %: {dev_area <= 0.01} ({100 * dev_area:.2f} %); "
          f"toe within 1 dp: {dev_toe <= 1.0} ({dev_toe:.2f} dp)")
    print(f"toe over {n} 2 s windows every 0.1 s: {100 * share:.1f} % beyond 1 dp of its mean, "
          f"largest {largest:.2f} dp")
    return (f"{path.name}: {len(rows)} windows of {length:g} s from {t0:.2f} s, depth within {100 * dev_depth:.2f} % "
            f"h_n, area drift within {100 * dev_area:.2f} %, toe within {dev_toe:.2f} dp")


def main(argv=None) -> int:
    ap = common.parser(__doc__, sets=True, threads=2, out="window_metrics")
    ap.add_argument("runs", nargs="*", type=Path, help="front runs (NetCDF of python -m solver front)")
    ap.add_argument("--length", type=float, default=1.0, help="window length [s]")
    ap.add_argument("--stride", type=float, default=0.5, help="window start step [s]")
    ap.add_argument("--from", dest="start", default="1.0", help="first window start [s], or 'steady'")
    a = common.parse(ap, argv, {"length": 0.5, "stride": 0.5})
    runs = a.runs
    if not runs:
        if not a.quick:
            ap.error("give front runs, or --quick to run a coarse one first")
        runs = [common.front(common.EXAMPLES / "conveyor_fast.yaml", QUICK_RUN + a.sets, a.out / "quick.nc", a.threads)]
    common.summary("; ".join(report(p, a.length, a.stride, a.start) for p in runs))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
