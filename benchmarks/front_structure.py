"""Where a front run's fluid is loosely packed: the final particle state of a front run
(NetCDF from `python -m solver front`) by distance from the toe.

Per band of 1 h_n in x* = (x_toe - x) / h_n it prints, at the fluid particles, the kernel
concentration C = sum_b (m_b / rho_b) W_ab over fluid and wall particles (the free-surface
probe's C, solver/probes.py; 1 where the particles' own volumes fill the space, as on a
lattice) in four height bands z / eta (eta the run's last free-surface sample) and in the
interior (more than 2h from bed and surface), and the mean rho / rho0 and pressure. In
continuity-density SPH the density does not follow the spacing, so C < 1 at rho ~ rho0 is
room the fluid takes without mass: the "inflation" of the volume budget (docs/numerics.md,
"Where the volume goes").

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

from solver import cells  # noqa: E402
from solver.build import build_particles  # noqa: E402
from solver.conveyor import build_scene, case_from_dict  # noqa: E402
from solver.probes import sample_points, toe_position  # noqa: E402

HEIGHTS = ((0.0, 0.25), (0.25, 0.5), (0.5, 0.75), (0.75, 9.0))


def concentration(x, z, u, w, rho, mass, kind, h: float) -> np.ndarray:
    """C = sum_b (m_b / rho_b) W_ab (fluid and walls) at every fluid particle, by the probes'
    sampler on a cell list of the given particles."""
    grid = cells.Grid.cover(x.min() - h, x.max() + h, z.min() - h, z.max() + h, 2.0 * h, False)
    start = np.zeros(grid.ncells + 2, dtype=np.int64)
    cl = grid.cell_list(start)
    cell = np.zeros(x.size, dtype=np.int64)
    order = np.zeros(x.size, dtype=np.int64)
    cells.assign_cells(x, z, kind, cl, cell)
    cells.counting_sort(cell, grid.ncells + 1, order, start)
    f = kind == 0
    out = np.empty((5, int(f.sum())))
    sample_points(np.ascontiguousarray(x[f]), np.ascontiguousarray(z[f]),
                  *(np.ascontiguousarray(a[order]) for a in (x, z, u, w, rho, mass, kind)), cl, h, out)
    return out[0]


def structure(ds: xr.Dataset, bands: int) -> list[dict]:
    case = case_from_dict(yaml.safe_load(ds.attrs["case_yaml"]))
    dp, h, hn = case.dp, case.ch * case.dp, float(ds.attrs["h_n_m"])
    rho0 = case.density
    mass = build_particles(build_scene(case)).mass  # rho(t=0) dp^2, in snapshot order
    s = ds.isel(snapshot=-1)
    if s.x.size != mass.size:
        raise ValueError(f"the snapshot holds {s.x.size} particles, the case builds {mass.size}")
    ok = np.isfinite(s.x.values)
    x, z, u, w = (s[k].values[ok] for k in ("x", "z", "u", "w"))
    rho, p, kind, mass = s.rho.values[ok], s.p.values[ok], s.kind.values[ok], mass[ok]
    c = concentration(x, z, u, w, rho, mass, kind, h)
    fluid = np.where(kind == 0)[0]
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
