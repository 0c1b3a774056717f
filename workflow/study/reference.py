"""Reference solution (docs/scheme.md section 5): lubrication theory, and optional measured CSV data."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import xarray as xr

from solver import lubrication


def theory(x_star: np.ndarray, stations, z_star: np.ndarray, slope_deg: float) -> xr.Dataset:
    """Free surface eta(x*) and belt-frame velocity u*(z*) at each station (local depth
    h = eta h_n; NaN above it), as functions of x* = xi/h_n and z* = z/h_n."""
    theta = math.radians(slope_deg)
    eta = lubrication.front_eta(np.asarray(x_star, dtype=float), theta)
    st = np.asarray(stations, dtype=float)
    eta_st = lubrication.front_eta(st, theta)
    zs = np.asarray(z_star, dtype=float)
    s = zs[None, :] / eta_st[:, None]
    u = np.where(s <= 1.0 + 1e-12, lubrication.belt_velocity(np.minimum(s, 1.0)), np.nan)
    return xr.Dataset(
        {"surface": ("x_star", eta, {"units": "1", "long_name": "theory free surface h/h_n"}),
         "station_depth": ("station", eta_st, {"units": "1", "long_name": "theory depth h/h_n at the station"}),
         "velocity": (("station", "z_star"), u, {"units": "1", "long_name": "theory u* (belt frame)"})},
        coords={"x_star": np.asarray(x_star, dtype=float), "station": st, "z_star": zs},
        attrs={"source": "lubrication theory (docs/scheme.md section 5)"})


# the case keys that set the physics a reference depends on (the rest are numerics and probes)
PHYSICAL_KEYS = ("density", "viscosity", "rheology", "yield_stress", "consistency", "index", "slope_deg",
                 "gravity", "belt", "normalising_depth")


def recorded_case(run: xr.Dataset):
    """The solver case a run recorded (its ``case_yaml``), or None for a run without one."""
    from solver.front import recorded_case as from_record
    return from_record(run) if run.attrs.get("case_yaml") else None


def physics_of(case) -> dict:
    """The physical keys of a solver case (``PHYSICAL_KEYS``), as plain data."""
    d = case.to_dict()
    return {k: d[k] for k in PHYSICAL_KEYS}


def start_description(case) -> str:
    """What a run starts from, in words."""
    if case.start == "warm":
        return "the final state of a coarser run (warm start)"
    shape = ("a block at rest at the normal depth" if case.start == "block" else
             "the steady lubrication front at the scheme's own film depth")
    if case.start_velocity == "lubrication":
        return shape.replace(" at rest", "") + ", moving with the film's velocity profile, the belt at full speed"
    return shape + ", the belt ramped up from rest"


def theory_for_case(case, x_star, stations, z_star) -> xr.Dataset:
    """``theory`` for a solver case (solver.conveyor.ConveyorCase) of either rheology. For a
    Herschel-Bulkley fluid: the front of ``solver.viscoplastic.front_profile`` and, at each
    station's depth h, the belt-frame film profile u(z) / u_b under its driving slope S(h)."""
    if case.newtonian:
        return theory(x_star, stations, z_star, case.slope_deg)
    from solver import viscoplastic
    xs, eta_tab = case.front_shape()
    x = np.asarray(x_star, dtype=float)
    st = np.asarray(stations, dtype=float)
    zs = np.asarray(z_star, dtype=float)
    eta = np.interp(x, xs, eta_tab)
    eta_st = np.interp(st, xs, eta_tab)
    hn, u_b, g, fluid = case.h_n, case.belt.speed, case.gravity, case.hb_fluid
    u = np.full((st.size, zs.size), np.nan)
    for k, e in enumerate(eta_st):
        h = e * hn
        S = viscoplastic.driving_slope(fluid, h, u_b, g)
        inside = zs <= e + 1e-12
        u[k, inside] = fluid.film(zs[inside] * hn, h, S, g) / u_b
    return xr.Dataset(
        {"surface": ("x_star", eta, {"units": "1", "long_name": "theory free surface h/h_n"}),
         "station_depth": ("station", eta_st, {"units": "1", "long_name": "theory depth h/h_n at the station"}),
         "velocity": (("station", "z_star"), u, {"units": "1", "long_name": "theory u* (belt frame)"})},
        coords={"x_star": x, "station": st, "z_star": zs},
        attrs={"source": "Herschel-Bulkley lubrication theory (solver/viscoplastic.py)"})


def read_surface_csv(path) -> xr.DataArray:
    """Measured free surface: CSV with columns x_star, z_star."""
    df = _read(path, ("x_star", "z_star"))
    return xr.DataArray(df["z_star"].to_numpy(), coords={"x_star": df["x_star"].to_numpy()},
                        dims="x_star", name="surface", attrs={"source": str(path)})


def read_velocity_csv(path) -> xr.DataArray:
    """Measured velocity profile at one station: CSV with columns z_star, u_star."""
    df = _read(path, ("z_star", "u_star"))
    return xr.DataArray(df["u_star"].to_numpy(), coords={"z_star": df["z_star"].to_numpy()},
                        dims="z_star", name="velocity", attrs={"source": str(path)})


def _read(path, columns) -> pd.DataFrame:
    path = Path(path)
    df = pd.read_csv(path, comment="#")
    missing = [c for c in columns if c not in df.columns]
    if missing:
        raise ValueError(f"{path}: missing column(s) {', '.join(missing)}; expected {', '.join(columns)}")
    df = df[list(columns)].astype(float).dropna().sort_values(columns[0])
    if len(df) < 2:
        raise ValueError(f"{path}: needs at least two rows")
    return df
