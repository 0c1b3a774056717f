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

With --calibrate it checks the standard error of a window mean (solver/timeseries.py) against
series whose window-to-window scatter is known. Synthetic: AR(1) series with correlation times
0.1, 1 and 5 s, a slow wander (white noise plus an AR(1) of 2 s) and a faint one (white noise
plus 0.3 times an AR(1) of 3 s), sampled every 0.02 s, 3 s
windows read with steady.context s of samples before them; ratio: the RMS reported se over the
true standard deviation of the window mean (over --series series). Real: front runs carried on
far past steady (by default examples/conveyor_fast.yaml at dp = 1.5 mm, each shifting method,
steady.stop=false, steady.max_time=110: about 25 min each on one thread, kept in --out and
reused), cut into non-overlapping 3 s windows from --skip s on; per window the signed means the
metrics fold: the toe's velocity over the window's last second (zeta_f), the uniform depth / h_n
(zeta_h), the influence series of zeta_fs and of each station's zeta_u linearised about the
run's mean (study.metrics.metric_series), and every component of the surface and the station
profiles the steady detection reads. Ratio: RMS se over the standard deviation of the window
means, per metric, pooled over its components and the runs. Then zeta_u itself at each
station: its reported se (study.metrics) over the scatter of its values over those windows.
--quick: synthetic series only.

    python -m benchmarks.window_metrics --calibrate [RUN.nc ...] [--skip 20] [--series 2000]
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


DT = 0.02
WINDOW = 3.0
LONG_RUN = ["dp=1.5e-3", "steady.stop=false", "steady.max_time=110"]


def ar1(n: int, dt: float, tau: float, rng, rows: int) -> np.ndarray:
    """Unit-variance AR(1) series with correlation time ``tau``: rho(lag) = exp(-lag / tau)."""
    phi = math.exp(-dt / tau)
    x = np.empty((rows, n))
    x[:, 0] = rng.standard_normal(rows)
    s = math.sqrt(1.0 - phi * phi)
    for i in range(1, n):
        x[:, i] = phi * x[:, i - 1] + s * rng.standard_normal(rows)
    return x


def synthetic_ratio(kind: str, context: float, rows: int, seed: int = 0) -> tuple[float, float]:
    """(RMS reported se / sd of the window means, the same for the slope) over ``rows`` series
    of ``kind`` ('ar1 TAU', 'wander' or 'faint'), one window each, read with ``context`` s before it."""
    from solver.timeseries import window_fits
    rng = np.random.default_rng(seed)
    n_w, n_c = round(WINDOW / DT), round(context / DT)
    n = n_w + n_c
    if kind == "wander":
        y = 0.5 * rng.standard_normal((rows, n)) + ar1(n, DT, 2.0, rng, rows)
    elif kind == "faint":
        y = rng.standard_normal((rows, n)) + 0.3 * ar1(n, DT, 3.0, rng, rows)
    else:
        y = ar1(n, DT, float(kind.split()[1]), rng, rows)
    t = np.arange(n) * DT
    m, se, b, sb = window_fits(t, y, n_c)
    return float(np.sqrt(np.mean(se ** 2)) / np.std(m)), float(np.sqrt(np.mean(sb ** 2)) / np.std(b))


def run_windows(run: xr.Dataset, skip: float, window: float = WINDOW):
    """Index arrays of the run's non-overlapping windows from ``skip`` on."""
    t = run["time"].values
    out, t0 = [], skip
    while t0 + window <= t[-1] + 1e-9:
        out.append(np.flatnonzero((t >= t0 - 1e-9) & (t < t0 + window - 1e-9)))
        t0 += window
    return out


def real_components(run: xr.Dataset, skip: float, context: float) -> dict:
    """{metric: (window means (window, component), reported se (window, component))} of one run
    (module docstring); the context starts no earlier than ``skip``."""
    from solver.steady import front_velocity_fit
    from solver.timeseries import window_fits
    from study.metrics import metric_series
    from study.reference import recorded_case, theory_for_case
    case = recorded_case(run)
    x = np.round(np.arange(0.0, 12.0 + 1e-9, 0.1), 10)
    ref = theory_for_case(case, x, run["station"].values, run["z_star"].values)
    t = run["time"].values
    steady_idx = np.flatnonzero(t >= skip - 1e-9)
    hn = float(run.attrs["h_n_m"])
    out = {k: ([], []) for k in ("zeta_f", "zeta_h", "zeta_fs", "zeta_u", "surface", "profiles")}
    for idx in run_windows(run, skip):
        lead = np.flatnonzero((t >= max(skip, t[idx[0]] - context) - 1e-9) & (t < t[idx[0]] - 1e-9))
        sam = np.concatenate([lead, idx])
        # metric influence series, linearised about the run's mean after skip
        ts, ys = metric_series(run, ref, steady_idx, sam)
        m, se, _, _ = window_fits(ts, ys, lead.size)
        for key, cols in (("zeta_h", [0]), ("zeta_fs", [1]), ("zeta_u", list(range(2, ys.shape[0])))):
            out[key][0].append(m[cols])
            out[key][1].append(se[cols])
        keep = np.flatnonzero(t[: idx[-1] + 1] >= skip - 1e-9)
        b, sb = front_velocity_fit(t[keep], run["toe_position"].values[keep], context)
        out["zeta_f"][0].append([b])
        out["zeta_f"][1].append([sb])
        # the detector's components
        surf = run["surface_elevation"].values[sam] / hn
        ms, ses, _, _ = window_fits(t[sam], surf[:, :121].T, lead.size)
        out["surface"][0].append(ms)
        out["surface"][1].append(ses)
        vel = run["velocity_star"].values[sam].reshape(sam.size, -1)
        mv, sev, _, _ = window_fits(t[sam], vel.T, lead.size)
        out["profiles"][0].append(mv)
        out["profiles"][1].append(sev)
    return {k: (np.array(a, dtype=float), np.array(b, dtype=float)) for k, (a, b) in out.items()}


def station_values(paths, skip: float) -> list[list[str]]:
    """Per run and station: zeta_u and its reported se (study.metrics, each window with its
    context) over the run's non-overlapping windows from ``skip`` on, and the ratio of the RMS se
    to the standard deviation of the values (RMS values fold near zero: read where zeta_u is
    well above its scatter)."""
    rows = []
    for path in paths:
        with xr.open_dataset(path) as ds:
            run = ds.load()
        values = table(run, WINDOW, WINDOW, skip)
        for s in run["station"].values:
            v = np.array([r[f"zeta_u_{s:g}"] for r in values])
            e = np.array([r[f"zeta_u_{s:g}_se"] for r in values])
            ok = np.isfinite(v) & np.isfinite(e)
            sd, rms = np.std(v[ok], ddof=1), math.sqrt(np.mean(e[ok] ** 2))
            rows.append([Path(path).name, f"{s:g}", str(int(ok.sum())), f"{sd:.4f}", f"{rms:.4f}", f"{rms / sd:.2f}"])
    return rows


def ratio(means: np.ndarray, ses: np.ndarray) -> tuple[float, int]:
    """(RMS se / RMS sd of the window means, pooled over the components with a finite se in
    every window and a nonzero scatter; how many components)."""
    ok = np.isfinite(means).all(axis=0) & np.isfinite(ses).all(axis=0)
    ok[ok] &= np.std(means[:, ok], axis=0) > 0
    if not ok.any():
        return math.nan, 0
    sd2 = np.var(means[:, ok], axis=0, ddof=1)
    se2 = np.mean(ses[:, ok] ** 2, axis=0)
    return float(np.sqrt(se2.sum() / sd2.sum())), int(ok.sum())


def calibrate(a) -> str:
    if a.quick:
        a.runs, a.series = [], min(a.series, 300)
    elif not a.runs:
        a.runs = [common.front(common.EXAMPLES / "conveyor_fast.yaml", LONG_RUN + [f"shifting={m}"],
                               a.out / f"long_{m}.nc", 1, reuse=True) for m in ("skillen", "lind")]
    from solver.conveyor import Steady
    context = Steady().context
    print(f"## The se of a {WINDOW:g} s window mean, read with {context:g} s of samples before the window\n")
    print("### Synthetic series (probe interval 0.02 s)\n")
    rows = []
    names = {"wander": "white noise + AR(1) of 2 s", "faint": "white noise + 0.3 x AR(1) of 3 s"}
    for kind in ("ar1 0.1", "ar1 1", "ar1 5", "wander", "faint"):
        r_m, r_b = synthetic_ratio(kind, context, a.series)
        name = names.get(kind) or f"AR(1), tau = {kind.split()[1]} s"
        rows.append([name, f"{r_m:.2f}", f"{r_b:.2f}"])
    print(common.table(["series", "se / sd of the mean", "se / sd of the slope"], rows))
    pooled = {}
    if a.runs:
        print(f"\n### Long runs: windows from {a.skip:g} s on\n")
        rows = []
        for path in a.runs:
            with xr.open_dataset(path) as ds:
                run = ds.load()
            comps = real_components(run, a.skip, context)
            for k, (m, se) in comps.items():
                r, n = ratio(m, se)
                pooled.setdefault(k, []).append((m, se))
                rows.append([path.name, k, str(m.shape[0]), str(n), f"{r:.2f}"])
        for k, parts in pooled.items():
            use = [np.isfinite(m).all(0) & np.isfinite(se).all(0) for m, se in parts]
            sd2 = sum(np.var(m[:, u], axis=0, ddof=1).sum() for (m, _), u in zip(parts, use))
            se2 = sum(np.mean(se[:, u] ** 2, axis=0).sum() for (_, se), u in zip(parts, use))
            rows.append(["pooled", k, "", "", f"{math.sqrt(se2 / sd2):.2f}"])
        print(common.table(["run", "metric", "windows", "components", "se / sd"], rows))
        print("\n### zeta_u itself: its reported se over the scatter of its values, one a window\n")
        print(common.table(["run", "station x*", "windows", "sd of zeta_u", "RMS se", "se / sd"],
                           station_values(a.runs, a.skip)))
        metrics = [r for r in rows if r[0] == "pooled" and r[1].startswith("zeta")]
        return ("se / sd of a window mean over the long runs' windows, pooled: "
                + ", ".join(f"{r[1]} {r[4]}" for r in metrics))
    return "se / sd of a window mean, synthetic: " + ", ".join(f"{r[0]}: {r[1]}" for r in rows)


def main(argv=None) -> int:
    ap = common.parser(__doc__, sets=True, threads=2, out="window_metrics")
    ap.add_argument("runs", nargs="*", type=Path, help="front runs (NetCDF of python -m solver front)")
    ap.add_argument("--length", type=float, default=1.0, help="window length [s]")
    ap.add_argument("--stride", type=float, default=0.5, help="window start step [s]")
    ap.add_argument("--from", dest="start", default="1.0", help="first window start [s], or 'steady'")
    ap.add_argument("--late", type=float, nargs=2, metavar=("T0", "T1"),
                    help="compare the metrics over the detected window with those over [T0, T1]")
    ap.add_argument("--calibrate", action="store_true", help="calibrate the se of a window mean (module docstring)")
    ap.add_argument("--skip", type=float, default=20.0, help="--calibrate: s of each long run left out as its start")
    ap.add_argument("--series", type=int, default=2000, help="--calibrate: synthetic series per kind")
    a = common.parse(ap, argv, {"length": 0.5, "stride": 0.5})
    if a.calibrate:
        common.summary(calibrate(a))
        return 0
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
