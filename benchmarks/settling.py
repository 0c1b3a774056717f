"""Does a front settle and stay settled? Reads front runs (NetCDF from `python -m solver front`,
best with steady.stop: false and a long max_time) and prints, per run:

- the steady detection of solver/steady.py replayed on the run's probe series (so that runs
  written by an older detector are judged by the current one);
- per 2 s window from the detection (or from 2 s) to the end: mean uniform depth / h_n and
  its deviation from the long-time mean (the mean over the windows after detection), the
  enclosed-area drift, the toe range in dp, the volume budget by zone (enclosed / mass-implied
  area - 1 in the wall, body and front zones) and the particle disorder in the uniform zone;
- the issue targets: every window's depth within 0.5 % h_n of the long-time mean, area drift
  within 1 %, toe within 1 dp of its long-time mean;
- the toe's hold-out over 2 s windows starting every 0.1 s (``sliding_toe``): the share of them
  whose mean lies beyond 1 dp of the toe's mean over the whole stretch, and the largest such
  deviation.

    python benchmarks/settling.py results/issue10/*.nc [--markdown]
"""
from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np
import xarray as xr
import yaml

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from solver.conveyor import case_from_dict  # noqa: E402
from solver.steady import SteadyTracker  # noqa: E402

WINDOW = 2.0


def front_position(ds: xr.Dataset) -> np.ndarray:
    """The front at h_n / 2 from the stored surface (x* grid from the toe), lab frame; the
    runs' own series when they have it."""
    if "front_position" in ds:
        return ds.front_position.values
    hn = ds.attrs["h_n_m"]
    xs = ds.x_star.values
    out = np.full(ds.sizes["time"], np.nan)
    for k, surf in enumerate(ds.surface_elevation.values):
        above = np.flatnonzero(np.nan_to_num(surf) >= 0.5 * hn)
        if above.size and above[0] > 0:
            j = above[0]  # first x* (from the toe) at or above half depth
            a, b = surf[j - 1], surf[j]
            xstar = xs[j - 1] + (0.5 * hn - a) / (b - a) * (xs[j] - xs[j - 1])
            out[k] = ds.toe_position.values[k] - xstar * hn
    return out


def replay(ds: xr.Dataset, case) -> tuple[float, list]:
    """(start of the first verified averaging window, withdrawn detections) of the current
    detector on the stored series (runs written before the detector's own signals existed:
    the h_n / 2 front position for the equivalent front, and the front for the station
    fronts, which such runs do not hold)."""
    t = ds.time.values
    front = ds.front_equivalent.values if "front_equivalent" in ds else front_position(ds)
    depth = ds.uniform_depth.values
    su = ds.station_front.values if "station_front" in ds else front[:, None]
    tr = SteadyTracker(case.criteria(), case.belt.speed, case.h_n, case.steady.average)
    for k in range(2, t.size):
        if tr.update(t[:k + 1], front[:k + 1], depth[:k + 1], su[:k + 1]) == "steady":
            return tr.t_steady, [a for a, _ in tr.rejected]
    return math.nan, [a for a, _ in tr.rejected]


def windows(ds: xr.Dataset, start: float) -> list[dict]:
    t = ds.time.values
    hn, dp = ds.attrs["h_n_m"], float(ds.attrs["dp"])
    rows = []
    a = start
    while a + WINDOW <= t[-1] + 1e-9:
        w = (t >= a - 1e-9) & (t <= a + WINDOW + 1e-9)
        row = {"t0": a, "depth": float(np.nanmean(ds.uniform_depth.values[w])) / hn,
               "area_drift": float(np.nanmean(ds.area_drift.values[w])),
               "toe": float(np.mean(ds.toe_position.values[w])) / dp,
               "toe_range": float(np.ptp(ds.toe_position.values[w])) / dp}
        if "zone_enclosed_area" in ds:
            e = ds.zone_enclosed_area.values[w].mean(axis=0)
            m = ds.zone_mass_area.values[w].mean(axis=0)
            row["zones"] = [float(x / y - 1) if y > 0 else math.nan for x, y in zip(e[:3], m[:3])]
            row["disorder"] = [float(v) for v in np.nanmean(ds.disorder.values[w], axis=0)]
        rows.append(row)
        a += WINDOW
    return rows


def sliding_toe(ds: xr.Dataset, start: float, step: float = 0.1) -> tuple[float, float, int]:
    """(share beyond 1 dp, largest |deviation| [dp], windows) of the toe's means over 2 s
    windows starting every ``step`` s from ``start``, against its mean over [start, end]."""
    t, dp = ds.time.values, float(ds.attrs["dp"])
    toe = ds.toe_position.values / dp
    mean = float(np.mean(toe[t >= start - 1e-9]))
    devs = []
    a = start
    while a + WINDOW <= t[-1] + 1e-9:
        w = (t >= a - 1e-9) & (t <= a + WINDOW + 1e-9)
        devs.append(abs(float(np.mean(toe[w])) - mean))
        a += step
    if not devs:
        return math.nan, math.nan, 0
    devs = np.array(devs)
    return float(np.mean(devs > 1.0)), float(devs.max()), devs.size


def report(path: str, markdown: bool) -> None:
    ds = xr.open_dataset(path)
    case = case_from_dict(yaml.safe_load(ds.attrs["case_yaml"]))
    t_det, withdrawn = replay(ds, case)
    start = t_det if np.isfinite(t_det) else WINDOW
    rows = windows(ds, start)
    print(f"\n{Path(path).name}: {case.shifting}, dp = {case.dp * 1e3:g} mm, Ch = {case.ch:g}, "
          f"{ds.attrs['status']} at {ds.attrs['simulated_time_s']:.2f} s ({ds.attrs.get('reason', '')[:90]})")
    print(f"  current detector: verified window from {t_det:.2f} s" if np.isfinite(t_det)
          else "  current detector: no verified steady window", end="")
    print(f"; withdrawn: {', '.join(f'{v:.2f}' for v in withdrawn)} s" if withdrawn else "")
    if not rows:
        return
    mean_depth = float(np.mean([r["depth"] for r in rows]))
    mean_toe = float(np.mean([r["toe"] for r in rows]))
    sep = " | " if markdown else "  "
    head = ["window [s]", "depth / h_n", "dev. % h_n", "area drift %", "toe dev. / dp",
            "wall / body / front drift %", "M_zz", "h |sum V gradW|"]
    if markdown:
        print("| " + " | ".join(head) + " |\n|" + "---|" * len(head))
    else:
        print("  " + sep.join(head))
    for r in rows:
        z = r.get("zones", [math.nan] * 3)
        d = r.get("disorder", [math.nan] * 3)
        cells = [f"{r['t0']:.1f}-{r['t0'] + WINDOW:.1f}", f"{r['depth']:.4f}",
                 f"{100 * (r['depth'] - mean_depth):+.2f}", f"{100 * r['area_drift']:+.2f}",
                 f"{r['toe'] - mean_toe:+.1f}", " / ".join(f"{100 * v:+.1f}" for v in z),
                 f"{d[1]:.4f}", f"{d[2]:.4f}"]
        print(("| " + " | ".join(cells) + " |") if markdown else "  " + sep.join(cells))
    ok_depth = all(abs(r["depth"] - mean_depth) <= 0.005 for r in rows)
    ok_area = all(abs(r["area_drift"]) <= 0.01 for r in rows)
    ok_toe = all(abs(r["toe"] - mean_toe) <= 1.0 for r in rows)
    print(f"  targets from {start:.2f} s: depth within 0.5 % h_n of {mean_depth:.4f}: {ok_depth}; "
          f"area drift within 1 %: {ok_area}; toe within 1 dp: {ok_toe}")
    share, largest, n = sliding_toe(ds, start)
    print(f"  toe, {n} 2 s windows every 0.1 s: {100 * share:.1f} % beyond 1 dp of its mean, "
          f"largest {largest:.2f} dp")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("runs", nargs="+")
    ap.add_argument("--markdown", action="store_true")
    args = ap.parse_args(argv)
    for p in args.runs:
        report(p, args.markdown)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
