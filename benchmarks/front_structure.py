"""Where a front run's fluid is loosely packed: the final particle state of a front run
(NetCDF from `python -m solver front`) by distance from the toe.

Per band of 1 h_n in x* = (x_toe - x) / h_n it prints the kernel number density
C = sum_b dp^2 W_ab (fluid and wall particles; 1 on a lattice, below 1 where particles stand
further apart than their lattice cell) in four height bands z / eta (eta the run's last
free-surface sample) and in the interior (more than 2h from bed and surface), and the mean
rho / rho0 and pressure. In continuity-density SPH the density does not follow the spacing,
so C < 1 at rho ~ rho0 is volume that the fluid takes without mass: the "inflation" of the
volume budget (docs/numerics.md, "Where the volume goes").

    python benchmarks/front_structure.py results/front.nc [--bands 15]
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
import xarray as xr
import yaml

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from solver.kernel import kernel  # noqa: E402
from solver.probes import toe_position  # noqa: E402

HEIGHTS = ((0.0, 0.25), (0.25, 0.5), (0.5, 0.75), (0.75, 9.0))


def number_density(x, z, targets, dp: float, h: float) -> np.ndarray:
    """C_a = sum_b dp^2 W(|r_a - r_b|) over all particles b, for the particles ``targets``."""
    cs = 2.0 * h
    ix = np.floor((x - x.min()) / cs).astype(np.int64)
    iz = np.floor((z - z.min()) / cs).astype(np.int64)
    stride = int(iz.max()) + 3
    key = ix * stride + iz
    order = np.argsort(key)
    ks = key[order]
    out = np.zeros(targets.size)
    for di in (-1, 0, 1):
        for dj in (-1, 0, 1):
            kk = (ix[targets] + di) * stride + iz[targets] + dj
            lo = np.searchsorted(ks, kk, "left")
            hi = np.searchsorted(ks, kk, "right")
            for n, a in enumerate(targets):
                b = order[lo[n]:hi[n]]
                r = np.hypot(x[b] - x[a], z[b] - z[a])
                out[n] += dp * dp * kernel(r[r < 2.0 * h], h).sum()
    return out


def structure(ds: xr.Dataset, bands: int) -> list[dict]:
    case = yaml.safe_load(ds.attrs["case_yaml"])
    dp = float(case["dp"])
    h = float(case.get("ch", 1.8)) * dp
    hn = float(ds.attrs["h_n_m"])
    rho0 = float(case.get("density", 1383.0))
    s = ds.isel(snapshot=-1)
    ok = np.isfinite(s.x.values)
    x, z, kind = s.x.values[ok], s.z.values[ok], s.kind.values[ok]
    rho, p = s.rho.values[ok], s.p.values[ok]
    fluid = np.where(kind == 0)[0]
    c = number_density(x, z, fluid, dp, h)
    xf, zf = x[fluid], z[fluid]
    xs = (toe_position(xf, dp) - xf) / hn
    eta = np.interp(xs, ds.x_star.values, ds.surface_elevation.values[-1])
    frac = zf / eta
    rows = []
    for k in range(bands):
        m = (xs >= k) & (xs < k + 1)
        row = {"band": k, "n": int(m.sum())}
        for lo, hi in HEIGHTS:
            mm = m & (frac >= lo) & (frac < hi)
            row[f"C {lo:g}-{min(hi, 1):g}"] = float(c[mm].mean()) if mm.any() else np.nan
        mi = m & (zf > 2 * h) & (zf < eta - 2 * h)
        row["C interior"] = float(c[mi].mean()) if mi.any() else np.nan
        row["rho/rho0"] = float(rho[fluid][m].mean() / rho0) if m.any() else np.nan
        row["p [Pa]"] = float(p[fluid][m].mean()) if m.any() else np.nan
        rows.append(row)
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("runs", nargs="+")
    ap.add_argument("--bands", type=int, default=15, help="bands of 1 h_n from the toe")
    a = ap.parse_args(argv)
    for path in a.runs:
        with xr.open_dataset(path) as ds:
            rows = structure(ds, a.bands)
            print(f"\n{path}: {ds.attrs.get('status')} at {float(ds.attrs['simulated_time_s']):.2f} s")
        keys = list(rows[0])
        print("| x* | " + " | ".join(keys[1:]) + " |")
        print("|" + "---|" * len(keys))
        for r in rows:
            print(f"| {r['band']}-{r['band'] + 1} | {r['n']} | "
                  + " | ".join(f"{r[k]:.3f}" if k != "p [Pa]" else f"{r[k]:.0f}" for k in keys[2:]) + " |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
