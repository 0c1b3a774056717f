"""Does the block-jackknife sampling error of a window's metrics (``study.metrics.window_errors``)
describe how much they move from one window to the next?

For each run (best run on with steady.stop: false), the settled span [--settled, end] is cut
into back-to-back windows of --length s. Per window: zeta_h, zeta_fs and zeta_u at each
station, and their jackknife se over --blocks blocks. Per metric: the standard deviation of
the window values, the mean se, their ratio, and how many pairs of adjacent windows differ by
less than 2 sqrt(se1^2 + se2^2) (the verdicts' tie rule; about 95 % if the se is right and
the run does not drift).

    python benchmarks/metric_noise.py RUN.nc:SETTLED [RUN.nc:SETTLED ...] [--length 1 --blocks 5]
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
import xarray as xr
import yaml

ROOT = Path(__file__).resolve().parent.parent
sys.path[:0] = [str(ROOT), str(ROOT / "workflow"), str(ROOT / "benchmarks")]

from solver.conveyor import case_from_dict  # noqa: E402
from study.metrics import profile_metrics, window_errors  # noqa: E402
from study.reference import theory_for_case  # noqa: E402
from window_metrics import X_STAR, Z_STAR  # noqa: E402

NAMES = ("zeta_h", "zeta_fs")


def window_rows(run: xr.Dataset, ref: xr.Dataset, settled: float, length: float, blocks: int):
    """(values, se) per window, each (windows, 2 + stations)."""
    t = run["time"].values
    vals, ses = [], []
    t0 = settled
    while t0 + length <= t[-1] + 1e-9:
        idx = np.flatnonzero((t >= t0 - 1e-9) & (t <= t0 + length + 1e-9))
        w = run.isel(time=idx)
        s, zu = profile_metrics(float(w["uniform_depth"].mean("time")), w["surface_elevation"].mean("time"),
                                w["velocity_star"].mean("time"), run, ref)
        e, zu_e = window_errors(run, ref, idx, blocks=blocks)
        vals.append([s[k] for k in NAMES] + list(zu))
        ses.append([e[k] for k in NAMES] + list(zu_e))
        t0 = round(t0 + length, 10)
    return np.array(vals), np.array(ses)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("runs", nargs="+", help="RUN.nc:SETTLED (the time [s] from which the run has settled)")
    ap.add_argument("--length", type=float, default=1.0, help="window length [s]")
    ap.add_argument("--blocks", type=int, default=5, help="jackknife blocks a window")
    a = ap.parse_args(argv)
    print("| run | metric | windows | sd of window values | mean jackknife se | sd / se | adjacent pairs within 2 se |")
    print("|---|---|---|---|---|---|---|")
    for spec in a.runs:
        path, settled = spec.rsplit(":", 1)
        with xr.open_dataset(path) as ds:
            run = ds.load()
        case = case_from_dict(yaml.safe_load(run.attrs["case_yaml"]))
        ref = theory_for_case(case, X_STAR, run["station"].values, Z_STAR)
        vals, ses = window_rows(run, ref, float(settled), a.length, a.blocks)
        if len(vals) < 2:
            continue
        names = list(NAMES) + [f"zeta_u({s:g})" for s in run["station"].values]
        label = f"{Path(path).parent.name}/{Path(path).name} {case.shifting} dp {case.dp * 1e3:g} mm"
        for j, name in enumerate(names):
            sd = vals[:, j].std(ddof=1)
            se = ses[:, j].mean()
            within = np.abs(np.diff(vals[:, j])) <= 2 * np.hypot(ses[1:, j], ses[:-1, j])
            print(f"| {label} | {name} | {len(vals)} | {sd:.2g} | {se:.2g} | {sd / se:.2f} | "
                  f"{within.sum()} of {within.size} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
