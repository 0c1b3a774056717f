"""The dam break of examples/dambreak.yaml: run it (or read a run) and print the surge front,
the run-up on the opposite wall and the guards' margins over time.

Usage: python benchmarks/dambreak.py [--end 0.8] [--threads 2] [--from RUN.nc]
The front is the largest x of the fluid on the bed (z < 2 dp); the run-up is the highest
fluid within 2 dp of the right wall; Ritter's ideal dam-break front moves at 2 sqrt(g H).
The energy E = KE + PE (PE from the bed) is per unit width, J/m.
"""
from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
A, H, RIGHT = 0.057, 0.114, 0.228  # column width and height, right wall [m]


def surge(x, z, kind, dp):
    """(front x, run-up z on the right wall, highest fluid z) of one snapshot."""
    f = kind == 0
    bed = f & (z < 2 * dp)
    wall = f & (x > RIGHT - 2 * dp)
    return float(x[bed].max()), float(z[wall].max()) if wall.any() else 0.0, float(z[f].max())


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--end", type=float, default=0.8)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--from", dest="run", default=None, help="a `python -m solver run` NetCDF")
    a = ap.parse_args(argv)
    if a.run:
        import xarray as xr
        ds = xr.open_dataset(a.run)
        times = ds.snapshot_time.values
        snaps = [{k: ds[k].values[i] for k in ("x", "z", "u", "w", "kind")} for i in range(times.size)]
        status, reason, wall = ds.attrs["status"], ds.attrs["reason"], ds.attrs["wall_time_s"]
        dens, pen = ds.max_density_deviation.values, ds.max_penetration.values
        dp = float(ds.attrs["dp"])
    else:
        import numba
        numba.set_num_threads(a.threads)
        from solver.run import run_scene
        from tests.conftest import example_scene
        scene = example_scene("dambreak", time={"end": a.end, "output_interval": 0.01})
        tic = time.perf_counter()
        res = run_scene(scene, quiet=False)
        wall = time.perf_counter() - tic
        times, snaps, status, reason = res.snap_time, res.snaps, res.status, res.reason
        dens, pen = np.array(res.diag["max_density_deviation"]), np.array(res.diag["max_penetration"])
        dp = scene.dp
    ritter = 2 * math.sqrt(9.81 * H)
    print(f"status {status} {reason}; wall time {wall:.0f} s")
    print(f"max density deviation {np.nanmax(dens):.4f} (guard 0.1); "
          f"max penetration {np.nanmax(pen):.3f} dp (guard 0.5)")
    print("| t [s] | T = t sqrt(2g/a) | front x / a | Ritter's bound x / a | run-up z / H | "
          "highest z / H | E [J/m] |")
    print("|---|---|---|---|---|---|---|")
    m = 1000.0 * dp * dp
    for t, s in zip(times, snaps):
        if round(t * 100) % 4:
            continue
        front, runup, top = surge(s["x"], s["z"], s["kind"], dp)
        f = s["kind"] == 0
        energy = m * (0.5 * (s["u"][f] ** 2 + s["w"][f] ** 2) + 9.81 * s["z"][f]).sum()
        print(f"| {t:.2f} | {t * math.sqrt(2 * 9.81 / A):.2f} | {front / A:.2f} | "
              f"{min(1 + ritter * t / A, RIGHT / A):.2f} | {runup / H:.2f} | {top / H:.2f} | {energy:.3f} |")


if __name__ == "__main__":
    main()
