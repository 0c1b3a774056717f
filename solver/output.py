"""RunResult -> xarray Dataset with units, and atomic NetCDF writes."""
from __future__ import annotations

import os
import platform
import tempfile
import time

import numba
import numpy as np
import xarray as xr

from .integrate import DT_LIMITS
from .run import RunResult

_DIAG_META = {
    "dt": ("s", "time step"),
    "dt_limit": ("1", "index of the limiting term of eq. 7: " + ", ".join(
        f"{i} {n}" for i, n in enumerate(DT_LIMITS))),
    "dt_force": ("s", "dt1 = sqrt(h / max|a|)"),
    "dt_acoustic": ("s", "dt2 = h / (c0 + max|h u_ab.r_ab / (r^2 + eta^2)|)"),
    "dt_viscous": ("s", "dt3 = h^2 / nu"),
    "kinetic_energy": ("J m-1", "fluid kinetic energy per unit width"),
    "max_density_deviation": ("1", "max |rho/rho0 - 1| over fluid"),
    "max_penetration": ("m", "deepest fluid particle inside a wall rectangle"),
    "n_fluid": ("1", "fluid particle count"),
    "n_boundary_active": ("1", "boundary particles within reach of fluid"),
}
_SNAP_META = {
    "x": ("m", "position along x"), "z": ("m", "position along z"),
    "u": ("m s-1", "velocity along x"), "w": ("m s-1", "velocity along z"),
    "rho": ("kg m-3", "density"), "p": ("Pa", "pressure"),
    "kind": ("1", "0 fluid, 1 boundary"),
    "mu": ("Pa s", "effective viscosity (Herschel-Bulkley; max_viscosity where unyielded)"),
}


def versions() -> dict[str, str]:
    import netCDF4
    import pandas
    from . import __version__
    return {"sph_surge": __version__, "python": platform.python_version(),
            "numpy": np.__version__, "numba": numba.__version__, "xarray": xr.__version__,
            "pandas": pandas.__version__, "netcdf4": netCDF4.__version__}


def to_dataset(res: RunResult) -> xr.Dataset:
    """Diagnostics over ``time``, snapshots over (``snapshot``, ``particle``), run metadata."""
    data = {}
    for k, v in res.diag.items():
        units, long = _DIAG_META[k]
        data[k] = xr.Variable(("time",), np.asarray(v), {"units": units, "long_name": long})
    if res.snaps:
        for k, (units, long) in _SNAP_META.items():
            if k not in res.snaps[0]:
                continue
            arr = np.stack([s[k] for s in res.snaps])
            data[k] = xr.Variable(("snapshot", "particle"), arr, {"units": units, "long_name": long})
    coords = {
        "time": ("time", np.asarray(res.diag_time), {"units": "s", "long_name": "simulated time"}),
        "snapshot_time": ("snapshot", np.asarray(res.snap_time),
                          {"units": "s", "long_name": "simulated time of the snapshot"}),
    }
    sc = res.scene
    attrs = {
        "title": f"sph-surge run of scene '{sc.name}'",
        "status": res.status,
        "reason": res.reason,
        "steps": res.steps,
        "wall_time_s": res.wall_time,
        "started_unix": res.started_unix,
        "resumed_from_checkpoint": int(res.resumed),
        "ended_unix": time.time(),
        "threads": res.threads,
        "n_particles": res.n_particles,
        "dp": sc.dp, "h": sc.h, "c0": sc.c0, "rho0": sc.fluid.density,
        "viscous_update": sc.numerics.viscous_update,
        "cfl_acoustic": sc.cfl_acoustic,
        "cg_iterations": res.cg_iterations,
        "rkc_stages": res.rkc_stages,
        "scene_yaml": sc.to_yaml(),
    }
    attrs.update({f"version_{k}": v for k, v in versions().items()})
    return xr.Dataset(data, coords=coords, attrs=attrs)


def write_atomic(ds: xr.Dataset, path) -> None:
    """Write NetCDF to a temporary file in the same folder, then rename over ``path``."""
    path = os.fspath(path)
    folder = os.path.dirname(os.path.abspath(path))
    os.makedirs(folder, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=os.path.basename(path) + ".", suffix=".tmp", dir=folder)
    os.close(fd)
    try:
        enc = {k: {"zlib": True, "complevel": 1} for k in ds.data_vars}
        ds.to_netcdf(tmp, encoding=enc)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.remove(tmp)
        raise
