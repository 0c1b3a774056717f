"""The study's metrics over successive windows of one front run: how long the start's
transient lasts (best on runs with steady.stop: false).

For each window [t0, t0 + length] (t0 from --from in steps of --stride), the run's probe
series are averaged over the window as the run averages its steady window, and
``study.metrics.case_metrics`` scores them against the theory on the default campaign's
metric grids (x* in [0, 12] by 0.1, z* in [0, 1.3] by 0.025): zeta_f, zeta_h, zeta_fs and
zeta_u at each probed station.

    python benchmarks/window_metrics.py results/s27/*.nc [--length 1 --stride 0.5 --from 1]
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
import xarray as xr
import yaml

ROOT = Path(__file__).resolve().parent.parent
sys.path[:0] = [str(ROOT), str(ROOT / "workflow")]

from solver import steady  # noqa: E402
from solver.conveyor import case_from_dict  # noqa: E402
from study.metrics import case_metrics  # noqa: E402
from study.reference import theory_for_case  # noqa: E402

X_STAR = np.round(np.arange(0.0, 12.0 + 1e-9, 0.1), 10)
Z_STAR = np.round(np.arange(0.0, 1.3 + 1e-9, 0.025), 10)


def window_run(run: xr.Dataset, t0: float, t1: float) -> xr.Dataset:
    """The run with its window means and front velocity taken over [t0, t1]."""
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


def table(path: str, length: float, stride: float, start: float) -> list[dict]:
    with xr.open_dataset(path) as ds:
        run = ds.load()
    case = case_from_dict(yaml.safe_load(run.attrs["case_yaml"]))
    ref = theory_for_case(case, X_STAR, run.station.values, Z_STAR)
    rows = []
    t0 = start
    while t0 + length <= float(run.time.values[-1]) + 1e-9:
        m = case_metrics(window_run(run, t0, t0 + length), ref)
        rows.append({"t0": t0, "t1": t0 + length, "zeta_f": float(m.zeta_f), "zeta_f_se": float(m.zeta_f_se),
                     "zeta_h": float(m.zeta_h), "zeta_fs": float(m.zeta_fs),
                     "zeta_u": [float(v) for v in m.zeta_u.values], "stations": list(m.station.values)})
        t0 = round(t0 + stride, 10)
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("runs", nargs="+")
    ap.add_argument("--length", type=float, default=1.0, help="window length [s]")
    ap.add_argument("--stride", type=float, default=0.5, help="window start step [s]")
    ap.add_argument("--from", dest="start", type=float, default=1.0, help="first window start [s]")
    a = ap.parse_args(argv)
    for p in a.runs:
        with xr.open_dataset(p) as ds:
            attrs = dict(ds.attrs)
        print(f"\n{Path(p).name}: {yaml.safe_load(attrs['case_yaml'])['shifting']}, dp = "
              f"{float(attrs['dp']) * 1e3:g} mm, Ch = {attrs.get('ch', '?')}, steady at "
              f"{attrs.get('steady_state_time_s', float('nan')):.2f} s, ran to {attrs['simulated_time_s']:.2f} s")
        rows = table(p, a.length, a.stride, a.start)
        if not rows:
            continue
        st = " / ".join(f"{s:g}" for s in rows[0]["stations"])
        print(f"| window [s] | zeta_f % (2 se) | zeta_h % | zeta_fs | zeta_u {st} |\n|---|---|---|---|---|")
        for r in rows:
            print(f"| {r['t0']:.1f}-{r['t1']:.1f} | {100 * r['zeta_f']:.2f} ({200 * r['zeta_f_se']:.2f}) | "
                  f"{100 * r['zeta_h']:.2f} | {r['zeta_fs']:.4f} | "
                  + " / ".join(f"{v:.4f}" for v in r["zeta_u"]) + " |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
