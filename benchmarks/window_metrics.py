"""Metrics over successive windows of one front run: when the start's transient ends and whether
the front stays settled (best on runs with steady.stop: false and a long max_time).

With --late T0 T1 it first compares the metrics over the averaging window that the steady
detection (solver/steady.py, replayed on the run's probe series) picks with those over
[T0, T1], each with its se, and says which agree within 2 se of their difference. Then, for
each window [t0, t0 + length], t0 from --from (seconds, or ``steady``: the detected window's
start, 2 s where none is found) in steps of --stride, it prints the
study's metrics over the window (study.metrics.case_metrics against lubrication theory, the
probe series averaged over the window as a run averages its steady window), the uniform
depth's deviation from its mean over all windows [% h_n], the enclosed-area drift, the toe's
deviation from its mean [dp], and where the run has them the volume budget by zone
(enclosed / mass-implied area - 1: wall, body, front) and the interior disorder
h |sum V gradW|. Then the settling targets over those windows (depth within 0.5 % h_n, area
drift within 1 %, toe within 1 dp) and the toe's sliding-window check: the share of 2 s windows, one
every 0.1 s, whose mean toe lies beyond 1 dp of its mean.

    python -m benchmarks.window_metrics RUN.nc [RUN.nc ...] [--length 1 --stride 0.5 --from 1]
    python -m benchmarks.window_metrics RUN.nc --length 2 --stride 2 --from steady --late 10 14
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
    """The run with its averaging window [t0, t1] (its means, its front velocity over the
    window's last second) and no hold-out: what the metrics read."""
    from solver import steady
    t = run.time.values
    win = (t >= t0 - 1e-9) & (t <= t1 + 1e-9)
    avg = run.isel(time=win).mean("time")
    out = run.copy()
    for k in ("surface_elevation", "velocity_star", "uniform_depth"):
        out[f"mean_{k}"] = avg[k]
    out["front_velocity"] = ((), steady.front_velocity_fit(t[win], run.toe_position.values[win])[0])
    out.attrs.update(status="completed", window_start_s=float(t[win][0]), window_end_s=float(t[win][-1]),
                     holdout_start_s=math.nan, holdout_end_s=math.nan)
    return out


def replay(run: xr.Dataset, sets=()) -> tuple[float, float]:
    """(start, end) of the averaging window the steady detection (solver/steady.py, the run's own
    steady keys with ``sets`` applied, KEY=VALUE) finds on the run's probe series; NaN, NaN where
    it finds none."""
    from solver.front import recorded_case, replay as replay_detection
    found = replay_detection(run, recorded_case(run, sets))
    return found.averaging if found is not None else (math.nan, math.nan)


METRICS = ("zeta_f", "zeta_h", "zeta_fs")


def against_late(run: xr.Dataset, window: tuple[float, float], late: tuple[float, float]) -> list[list[str]]:
    """Each metric over ``window`` and over ``late`` (each +- 2 se) and whether they agree within
    2 se of their difference."""
    from study.metrics import case_metrics
    ref = common.reference(run)
    a = case_metrics(window_run(run, *window), ref, common.X_STAR_RANGE)
    b = case_metrics(window_run(run, *late), ref, common.X_STAR_RANGE)
    rows = []
    names = [(k, a[k], a[f"{k}_se"], b[k], b[f"{k}_se"]) for k in METRICS]
    names += [(f"zeta_u {s:g}", a.zeta_u.values[j], a.zeta_u_se.values[j], b.zeta_u.values[j], b.zeta_u_se.values[j])
              for j, s in enumerate(a.station.values)]
    for name, va, ea, vb, eb in names:
        va, ea, vb, eb = (float(v) for v in (va, ea, vb, eb))
        se = math.hypot(ea, eb)
        rows.append([name, f"{100 * va:.3f} ± {200 * ea:.3f}", f"{100 * vb:.3f} ± {200 * eb:.3f}",
                     f"{100 * (vb - va):+.3f} ± {200 * se:.3f}", "yes" if abs(vb - va) <= 2 * se else "no"])
    return rows


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


def report(path: Path, length: float, stride: float, start: str, late: tuple[float, float] | None,
           sets=()) -> str:
    with xr.open_dataset(path) as ds:
        run = ds.load()
    a = run.attrs
    w0, w1 = replay(run, sets)
    t0 = (w0 if np.isfinite(w0) else 2.0) if start == "steady" else float(start)
    print(f"\n{path.name}: {a.get('shifting', '?')}, dp = {float(a['dp']) * 1e3:g} mm, Ch = {a.get('ch', '?')}, "
          f"{a['status']} at {float(a['simulated_time_s']):.2f} s; steady detection replayed: "
          + (f"averaging window {w0:.2f}-{w1:.2f} s" if np.isfinite(w0) else "not steady"))
    agree = ""
    if late is not None and np.isfinite(w0):
        rows = against_late(run, (w0, w1), late)
        print(f"metrics [%] over the detected window and over {late[0]:g}-{late[1]:g} s:")
        print(common.table(["metric", "detected window (± 2 se)", f"{late[0]:g}-{late[1]:g} s (± 2 se)",
                            "difference (± 2 se)", "within 2 se"], rows))
        agree = f"; {sum(r[-1] == 'yes' for r in rows)} of {len(rows)} metrics agree with {late[0]:g}-{late[1]:g} s"
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
            f"h_n, area drift within {100 * dev_area:.2f} %, toe within {dev_toe:.2f} dp{agree}")


def main(argv=None) -> int:
    ap = common.parser(__doc__, sets=True, threads=2, out="window_metrics")
    ap.add_argument("runs", nargs="*", type=Path, help="front runs (NetCDF of python -m solver front)")
    ap.add_argument("--length", type=float, default=1.0, help="window length [s]")
    ap.add_argument("--stride", type=float, default=0.5, help="window start step [s]")
    ap.add_argument("--from", dest="start", default="1.0", help="first window start [s], or 'steady'")
    ap.add_argument("--late", type=float, nargs=2, metavar=("T0", "T1"),
                    help="compare the metrics over the detected window with those over [T0, T1]")
    a = common.parse(ap, argv, {"length": 0.5, "stride": 0.5})
    runs = a.runs
    if not runs:
        if not a.quick:
            ap.error("give front runs, or --quick to run a coarse one first")
        runs = [common.front(common.EXAMPLES / "conveyor_fast.yaml", QUICK_RUN + a.sets, a.out / "quick.nc", a.threads)]
    common.summary("; ".join(report(p, a.length, a.stride, a.start, a.late, a.sets if a.runs else ())
                             for p in runs))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
