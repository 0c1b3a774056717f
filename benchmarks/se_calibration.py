"""Calibration of the standard error of a window mean (solver/timeseries.py) against series whose
window-to-window scatter is known.

Synthetic: AR(1) series with correlation times 0.1, 1 and 5 s, and a slowly wandering series
(white noise plus an AR(1) of 2 s), sampled as the probes are (0.02 s), W = 3 s windows, each
se read with ``steady.context`` s of samples before its window. Ratio: the RMS of the reported
se over the true standard deviation of the window mean (over --series independent series).

Real runs: front runs carried on far past steady (``--runs``, written by the command below),
cut into non-overlapping W windows from --skip s on. For each window the signed window means
that the metrics fold: the toe's velocity over the window's last second (zeta_f), the uniform
depth / h_n (zeta_h), the surface error's and each station's velocity error's influence series
linearised about the run's mean (zeta_fs, zeta_u: study.metrics.metric_series), and, for the
detector, every component of the surface and of the station profiles. Ratio: the RMS of the
reported se over the standard deviation of the window means across windows, per metric and
pooled over its components and the runs.

    python -m solver front examples/conveyor_fast.yaml -o results/benchmarks/se_calibration/long_skillen.nc \\
        --threads 1 --set dp=1.5e-3 --set steady.stop=false --set steady.max_time=110   (and shifting=lind)
    python -m benchmarks.se_calibration --runs results/benchmarks/se_calibration/long_*.nc
    python -m benchmarks.se_calibration --quick            (synthetic series only, fewer of them)
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import xarray as xr

from benchmarks import common

DT = 0.02
WINDOW = 3.0


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
    of ``kind`` ('ar1 TAU' or 'wander'), one window each, read with ``context`` s before it."""
    from solver.timeseries import window_fits
    rng = np.random.default_rng(seed)
    n_w, n_c = round(WINDOW / DT), round(context / DT)
    n = n_w + n_c
    if kind == "wander":
        y = 0.5 * rng.standard_normal((rows, n)) + ar1(n, DT, 2.0, rng, rows)
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


def ratio(means: np.ndarray, ses: np.ndarray) -> tuple[float, int]:
    """(RMS se / RMS sd of the window means, pooled over the components with a finite se in
    every window and a nonzero scatter; how many components)."""
    ok = np.isfinite(means).all(axis=0) & np.isfinite(ses).all(axis=0)
    ok &= np.nanstd(means, axis=0, ddof=1) > 0
    if not ok.any():
        return math.nan, 0
    sd2 = np.var(means[:, ok], axis=0, ddof=1)
    se2 = np.mean(ses[:, ok] ** 2, axis=0)
    return float(np.sqrt(se2.sum() / sd2.sum())), int(ok.sum())


def main(argv=None) -> int:
    ap = common.parser(__doc__, threads=None)
    ap.add_argument("--runs", nargs="*", type=Path, default=[], help="long front runs (module docstring)")
    ap.add_argument("--skip", type=float, default=20.0, help="s of each run left out as its start (default 20)")
    ap.add_argument("--context", type=float, default=None,
                    help="s of samples before each window in its se (default: steady.context's default)")
    ap.add_argument("--series", type=int, default=2000, help="synthetic series per kind")
    a = common.parse(ap, argv, quick={"series": 300})
    from solver.conveyor import Steady
    context = Steady().context if a.context is None else a.context
    print(f"## The se of a {WINDOW:g} s window mean, read with {context:g} s of samples before the window\n")
    print("### Synthetic series (probe interval 0.02 s)\n")
    rows = []
    for kind in ("ar1 0.1", "ar1 1", "ar1 5", "wander"):
        r_m, r_b = synthetic_ratio(kind, context, a.series)
        name = f"AR(1), tau = {kind.split()[1]} s" if kind != "wander" else "white noise + AR(1) of 2 s"
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
            sd2 = sum(np.var(m[:, np.isfinite(se).all(0)], axis=0, ddof=1).sum() for m, se in parts)
            se2 = sum(np.mean(se[:, np.isfinite(se).all(0)] ** 2, axis=0).sum() for m, se in parts)
            rows.append(["pooled", k, "", "", f"{math.sqrt(se2 / sd2):.2f}"])
        print(common.table(["run", "metric", "windows", "components", "se / sd"], rows))
        metrics = [r for r in rows if r[0] == "pooled" and r[1].startswith("zeta")]
        print("\nsummary: " + ", ".join(f"{r[1]} {r[4]}" for r in metrics))
    else:
        print("\nsummary: synthetic " + ", ".join(f"{r[0].split(',')[0]} {r[1]}" for r in rows))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
