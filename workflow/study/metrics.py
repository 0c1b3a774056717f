"""Error metrics of SPEC section 4 (paper eqs. 14-17), pure functions over xarray objects.

x* is measured upslope from the toe in units of the computed normal depth h_n, depths
are h/h_n, velocities u* = (u + u_b)/u_b in the belt frame; all from the steady-window
means of a run (``mean_*`` variables of the per-run NetCDF).
"""
from __future__ import annotations

import numpy as np
import xarray as xr


def zeta_f(front_velocity: float, u_b: float) -> float:
    """|u*_f - u*_b| / u*_b; the belt-frame front velocity is the lab toe velocity + u_b."""
    return abs(front_velocity) / u_b


def zeta_f_error(t, toe, u_b: float) -> float:
    """Standard error of zeta_f from the toe's own scatter: se of the least-squares toe slope
    over the last second of the record (the second zeta_f is measured over), widened for the
    residuals' lag-1 correlation (solver.steady.front_velocity_fit), over u_b. NaN with fewer
    than 4 samples in that second (no scatter to measure)."""
    from solver.steady import FRONT_VELOCITY_SPAN, front_velocity_fit
    t = np.asarray(t, dtype=float)
    if t.size == 0 or (t >= t[-1] - FRONT_VELOCITY_SPAN - 1e-9).sum() < 4:
        return float("nan")
    return front_velocity_fit(t, toe)[1] / u_b


def zeta_h(depth: float, h_ref: float) -> float:
    """|h*_u - h*_n| / h*_n with both depths normalised by h_ref."""
    return abs(depth - h_ref) / h_ref


def rms_difference(reference: xr.DataArray, numerical: xr.DataArray, dim: str) -> float:
    """sqrt(mean (ref - num)^2) over the reference's abscissas along ``dim`` where both are
    defined; the numerical curve is interpolated linearly onto them."""
    xs = numerical[dim].values
    ys = numerical.values
    ok = np.isfinite(ys)
    xr_ = reference[dim].values
    num = np.full(xr_.size, np.nan)
    if ok.sum() >= 2:
        inside = (xr_ >= xs[ok].min()) & (xr_ <= xs[ok].max())
        num[inside] = np.interp(xr_[inside], xs[ok], ys[ok])
        # no extrapolation, and no bridging over undefined stretches of the numerical curve
        gap = np.interp(xr_, xs, (~ok).astype(float)) > 0
        num[gap] = np.nan
    diff = reference.values - num
    ok = np.isfinite(diff)
    if not ok.any():
        return float("nan")
    return float(np.sqrt(np.mean(diff[ok] ** 2)))


def zeta_fs(ref_surface: xr.DataArray, num_surface: xr.DataArray) -> float:
    """Free-surface RMS error (normalised depths) over the reference abscissas."""
    return rms_difference(ref_surface, num_surface, "x_star")


def zeta_u(ref_velocity: xr.DataArray, num_velocity: xr.DataArray) -> float:
    """Velocity-profile RMS error at one station over the reference heights z*."""
    return rms_difference(ref_velocity, num_velocity, "z_star")


def case_metrics(run: xr.Dataset, ref: xr.Dataset, x_star_range=(0.0, 12.0),
                 measured: dict | None = None) -> xr.Dataset:
    """All metrics of one run against the reference (and measured data when given).

    Diverged runs give NaN metrics. A run that did not reach steady state gives its metrics
    over its final window, flagged by ``steady = 0`` (the report and figures mark them).
    """
    st = ref["station"].values
    out = {k: np.nan for k in ("zeta_f", "zeta_f_se", "zeta_h", "zeta_h_paper", "zeta_fs")}
    zu = np.full(st.size, np.nan)
    meas = {"zeta_fs_measured": np.nan}
    zu_meas = np.full(st.size, np.nan)
    ok = run.attrs.get("status") in ("completed", "not_steady") and "mean_surface_elevation" in run
    if ok:
        hn = float(run.attrs["h_n_m"])
        ub = float(run.attrs["belt_speed_m_s"])
        out["zeta_f"] = zeta_f(float(run["front_velocity"]), ub)
        if "toe_position" in run:  # the probe record (absent from hand-made means-only runs)
            out["zeta_f_se"] = zeta_f_error(run["time"].values, run["toe_position"].values, ub)
        depth = float(run["mean_uniform_depth"])
        out["zeta_h"] = zeta_h(depth, hn)
        out["zeta_h_paper"] = zeta_h(depth, float(run.attrs["normalising_depth_m"]))
        surf = run["mean_surface_elevation"] / hn
        lo, hi = x_star_range
        rs = ref["surface"].sel(x_star=slice(lo, hi))
        out["zeta_fs"] = zeta_fs(rs, surf)
        vel = run["mean_velocity_star"]
        for j, s in enumerate(st):
            zu[j] = zeta_u(ref["velocity"].sel(station=s), vel.sel(station=s, method="nearest"))
        if measured:
            if measured.get("surface") is not None:
                meas["zeta_fs_measured"] = zeta_fs(measured["surface"], surf)
            for j, s in enumerate(st):
                m = (measured.get("velocity") or {}).get(float(s))
                if m is not None:
                    zu_meas[j] = zeta_u(m, vel.sel(station=s, method="nearest"))
    data = {k: ((), v) for k, v in {**out, **meas}.items()}
    data["zeta_u"] = (("station",), zu)
    data["zeta_u_measured"] = (("station",), zu_meas)
    data["steady"] = ((), int(run.attrs.get("steady", 0)) if ok else 0)
    ds = xr.Dataset(data, coords={"station": st})
    ds["steady"].attrs.update(units="1", long_name="1: metrics over a steady window; 0: not steady or no metrics")
    attrs = {
        "zeta_f": "front velocity error |u*_f - u*_b| / u*_b",
        "zeta_f_se": "standard error of zeta_f from the toe's scatter over its second",
        "zeta_h": "uniform depth error against the computed h_n",
        "zeta_h_paper": "uniform depth error against the paper's normalising depth",
        "zeta_fs": "free-surface RMS error against the theory",
        "zeta_u": "velocity-profile RMS error against the theory",
        "zeta_fs_measured": "free-surface RMS error against measured data",
        "zeta_u_measured": "velocity-profile RMS error against measured data",
    }
    for k, v in attrs.items():
        ds[k].attrs.update(units="1", long_name=v)
    return ds
