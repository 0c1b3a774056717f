"""What a scene run's snapshots say about its flow: front, depth and velocity profiles.

Pure functions over the run dataset of ``python -m solver run`` (snapshots of x, z, u, kind
over (snapshot, particle)). A particle stands for a square of side dp around its centre, so
the fluid reaches dp / 2 beyond the outermost centres.
"""
from __future__ import annotations

import numpy as np
import xarray as xr


def fluid(ds: xr.Dataset, k: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """x, z, u of the fluid particles of snapshot k."""
    fl = ds["kind"].values[k] == 0
    return ds["x"].values[k][fl], ds["z"].values[k][fl], ds["u"].values[k][fl]


def front(ds: xr.Dataset, symmetric: bool = False) -> xr.DataArray:
    """x_N over the snapshots' times: the largest fluid x plus dp / 2; ``symmetric`` (a
    two-sided release about x = 0): the half-width (max x - min x) / 2 + dp / 2, the mean of
    the two fronts' distances from the symmetry plane."""
    dp = float(ds.attrs["dp"])
    out = []
    for k in range(ds.sizes["snapshot"]):
        x = fluid(ds, k)[0]
        out.append((x.max() - x.min()) / 2.0 + dp / 2.0 if symmetric else x.max() + dp / 2.0)
    return xr.DataArray(np.asarray(out), coords={"t": ds["snapshot_time"].values}, dims="t",
                        name="x_front", attrs={"units": "m"})


def _bins(s, width):
    """Labels of the bins of the given width that the values s fall into."""
    return np.floor(np.asarray(s) / width).astype(np.int64)


def depth_profile(ds: xr.Dataset, k: int, bed: float = 0.0, symmetric: bool = False):
    """(x, h) of snapshot k: the fluid's columns, bins dp wide along x, each at the mean x of its
    particles, h the highest centre plus dp / 2 above the bed level. ``symmetric`` folds the two
    sides of x = 0 together (|x|)."""
    dp = float(ds.attrs["dp"])
    px, pz, _ = fluid(ds, k)
    if symmetric:
        px = np.abs(px)
    labels = _bins(px, dp)
    cols = np.unique(labels)
    x = np.array([px[labels == c].mean() for c in cols])
    h = np.array([pz[labels == c].max() + 0.5 * dp - bed for c in cols])
    return x, h


def velocity_profile(ds: xr.Dataset, k: int, x_range=None):
    """(z, u) of snapshot k: the fluid's rows, bins dp wide along z (of the particles with x in
    ``x_range`` if given), each at the mean z and mean u of its particles."""
    dp = float(ds.attrs["dp"])
    px, pz, pu = fluid(ds, k)
    if x_range is not None:
        keep = (px >= x_range[0]) & (px <= x_range[1])
        pz, pu = pz[keep], pu[keep]
    labels = _bins(pz, dp)
    rows = np.unique(labels)
    return (np.array([pz[labels == r].mean() for r in rows]), np.array([pu[labels == r].mean() for r in rows]))


def snapshot_at(ds: xr.Dataset, t: float) -> int | None:
    """Index of the snapshot at time t (within a thousandth of the output interval), or None."""
    times = ds["snapshot_time"].values
    if times.size == 0:
        return None
    k = int(np.argmin(np.abs(times - t)))
    tol = 1e-3 * (np.median(np.diff(times)) if times.size > 1 else 1.0)
    return k if abs(times[k] - t) <= tol else None
