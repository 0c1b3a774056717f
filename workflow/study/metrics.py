"""Error metrics of docs/scheme.md section 4 (paper eqs. 14-17), pure functions over xarray objects.

x* is measured upslope from the toe in units of the computed normal depth h_n, depths
are h/h_n, velocities u* = (u + u_b)/u_b in the belt frame; all from the steady-window
means of a run (``mean_*`` variables of the per-run NetCDF).

Sampling errors (docs/metrics.md, "Standard errors"): each the se of a window mean or slope
from its series' autocorrelation over the samples before the window (solver.timeseries):
zeta_f's of the toe's slope over its second (``zeta_f_error``); zeta_h's of the uniform depth's
mean; zeta_fs's and zeta_u's of the mean of their influence series, the RMS linearised about
the window's mean curve, each point weighted by the share of samples that define it
(``rms_influence``, ``window_errors``).

beyond the paper, a diagnostic beside zeta_f: zeta_f_body, the same error of the equivalent front
(``front_body_velocity_error``), which tells a front that moves from a toe that wanders.
"""
from __future__ import annotations

import numpy as np
import xarray as xr


def zeta_f(front_velocity: float, u_b: float) -> float:
    """|u*_f - u*_b| / u*_b; the belt-frame front velocity is the lab toe velocity + u_b."""
    return abs(front_velocity) / u_b


def last_second_velocity(t, position, u_b: float, context: float = 0.0) -> tuple[float, float]:
    """(|slope| / u_b, se / u_b) of a front position's least-squares slope over the last second
    of the record (the second zeta_f is measured over), its se reading ``context`` s of the
    samples before that second as well (solver.steady.front_velocity_fit). NaN, NaN with fewer
    than 4 samples in that second (no scatter to measure)."""
    from solver.steady import FRONT_VELOCITY_SPAN, front_velocity_fit
    t = np.asarray(t, dtype=float)
    if t.size == 0 or (t >= t[-1] - FRONT_VELOCITY_SPAN - 1e-9).sum() < 4:
        return float("nan"), float("nan")
    slope, se = front_velocity_fit(t, position, context)
    return abs(slope) / u_b, se / u_b


def zeta_f_error(t, toe, u_b: float, context: float = 0.0) -> float:
    """Standard error of zeta_f from the toe's own series (``last_second_velocity``)."""
    return last_second_velocity(t, toe, u_b, context)[1]


def front_body_velocity_error(t, front, u_b: float, context: float = 0.0) -> tuple[float, float]:
    """(|u_e| / u_b, se / u_b) of the equivalent front x0 + A / h_n (the fluid area A downstream
    of a lab-fixed point over h_n, ``front_equivalent`` of the run), u_e its slope over zeta_f's
    second (``last_second_velocity``). A front that advances at constant shape moves it as much
    as its toe; the nose's wander and particles joining or leaving the tip do not move it."""
    return last_second_velocity(t, front, u_b, context)


def zeta_h(depth: float, h_ref: float) -> float:
    """|h*_u - h*_n| / h*_n with both depths normalised by h_ref."""
    return abs(depth - h_ref) / h_ref


def on_abscissas(x_ref, x_run, y_run) -> np.ndarray:
    """A run's curve y_run(x_run) interpolated linearly onto the reference abscissas x_ref; NaN
    outside the run's defined samples (never extrapolated) and over a stretch where the run is
    undefined (never bridged)."""
    x_ref = np.asarray(x_ref, dtype=float)
    order = np.argsort(np.asarray(x_run, dtype=float), kind="stable")
    xs = np.asarray(x_run, dtype=float)[order]
    ys = np.asarray(y_run, dtype=float)[order]
    ok = np.isfinite(xs) & np.isfinite(ys)
    out = np.full(x_ref.size, np.nan)
    if ok.sum() < 2:
        return out
    inside = (x_ref >= xs[ok].min()) & (x_ref <= xs[ok].max())
    out[inside] = np.interp(x_ref[inside], xs[ok], ys[ok])
    fin = np.isfinite(xs)
    out[np.interp(x_ref, xs[fin], (~ok[fin]).astype(float)) > 0] = np.nan
    return out


def rms_difference(reference: xr.DataArray, numerical: xr.DataArray, dim: str) -> float:
    """sqrt(mean (ref - num)^2) over the reference's abscissas along ``dim`` where both are
    defined; the numerical curve is interpolated onto them (``on_abscissas``)."""
    diff = reference.values - on_abscissas(reference[dim].values, numerical[dim].values, numerical.values)
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


MIN_WINDOW_SAMPLES = 10  # fewer samples in a window: its errors are not measured (NaN)
PROFILE_METRICS = ("zeta_h", "zeta_h_paper", "zeta_fs")
DEFAULT_CONTEXT = 15.0  # s: steady.context of a run that does not record its own
DEFAULT_MIN_TIME = 3.0  # s: steady.min_time of a run that does not record its own (the start-up)


def profile_metrics(depth: float, surface: xr.DataArray, velocity: xr.DataArray, run: xr.Dataset,
                    ref: xr.Dataset, x_star_range=(0.0, 12.0)) -> tuple[dict, np.ndarray]:
    """zeta_h, zeta_h_paper, zeta_fs and zeta_u (per reference station) of one set of means:
    the uniform depth [m], the surface elevation (x_star) [m] and u* (station, z_star)."""
    hn = float(run.attrs["h_n_m"])
    lo, hi = x_star_range
    out = {"zeta_h": zeta_h(depth, hn),
           "zeta_h_paper": zeta_h(depth, float(run.attrs["normalising_depth_m"])),
           "zeta_fs": zeta_fs(ref["surface"].sel(x_star=slice(lo, hi)), surface / hn)}
    zu = np.array([zeta_u(ref["velocity"].sel(station=s), velocity.sel(station=s, method="nearest"))
                   for s in ref["station"].values])
    return out, zu


def _samples(run: xr.Dataset, start_attr: str, end_attr: str, open_start: bool = False) -> np.ndarray | None:
    """Indices of the time samples in [run.attrs[start_attr], run.attrs[end_attr]] (the start
    left out with ``open_start``; None where the run lacks the record or the window)."""
    if "uniform_depth" not in run or run.sizes.get("time", 0) == 0:
        return None
    a, b = float(run.attrs.get(start_attr, np.nan)), float(run.attrs.get(end_attr, np.nan))
    if not (np.isfinite(a) and np.isfinite(b)):
        return None
    t = run["time"].values
    after = (t > a + 1e-9) if open_start else (t >= a - 1e-9)
    idx = np.flatnonzero(after & (t <= b + 1e-9))
    return idx if idx.size else None


def window_samples(run: xr.Dataset) -> np.ndarray | None:
    """Indices of the time samples the run's ``mean_*`` were taken over (its averaging window,
    attrs window_start_s to window_end_s). None where the record lacks them or their mean does
    not reproduce the stored ``mean_uniform_depth``."""
    idx = _samples(run, "window_start_s", "window_end_s")
    if idx is None:
        return None
    depth = run["uniform_depth"].values[idx]
    if not np.isclose(np.nanmean(depth), float(run["mean_uniform_depth"]), rtol=1e-9, atol=0.0):
        return None
    return idx


def holdout_samples(run: xr.Dataset) -> np.ndarray | None:
    """Indices of the hold-out window's samples, (holdout_start_s, holdout_end_s] (its first
    instant is the averaging window's last sample), None where the run has none."""
    return _samples(run, "holdout_start_s", "holdout_end_s", open_start=True)


def context_samples(run: xr.Dataset, idx: np.ndarray) -> np.ndarray:
    """Indices of the samples a window's se reads before the window ``idx``: the run's
    steady.context s before it, from its steady.min_time on (attrs ``se_context_s`` and
    ``steady_min_time_s``; without them DEFAULT_CONTEXT and DEFAULT_MIN_TIME)."""
    t = run["time"].values
    context = float(run.attrs.get("se_context_s", DEFAULT_CONTEXT))
    t_min = float(run.attrs.get("steady_min_time_s", DEFAULT_MIN_TIME))
    t0 = t[idx[0]]
    return np.flatnonzero((t >= max(t0 - context, t_min) - 1e-9) & (t < t0 - 1e-9))


def _column_means(a: np.ndarray) -> np.ndarray:
    """Means over axis 0 of the finite values (NaN for a column with none, without a warning)."""
    ok = np.isfinite(a)
    n = ok.sum(axis=0)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(n > 0, np.where(ok, a, 0.0).sum(axis=0) / n, np.nan)


def _on_reference(x_ref, x_run, rows) -> np.ndarray:
    """Each row of ``rows`` (a curve over x_run) on the reference abscissas (``on_abscissas``)."""
    return np.array([on_abscissas(x_ref, x_run, r) for r in rows]).reshape(len(rows), np.size(x_ref))


def rms_influence(reference: np.ndarray, mean_curve: np.ndarray, curves: np.ndarray,
                  defined: np.ndarray | None = None) -> np.ndarray:
    """The first-order change of the RMS error sqrt(mean_x (c_x - r_x)^2) about the mean curve
    when the curve is one sample's: sum_x d_x (c_x(t) - cbar_x) / (p_x N_x rms), d = cbar - r,
    over the abscissas where the mean curve and the reference are defined; a sample's undefined
    points count as the mean's. p_x (``defined``, default 1) is the chance that a sample defines
    point x: cbar_x is the mean of the window's samples that do (a ratio estimator), so each one
    moves it by 1 / (p_x n) of its deviation. Its window mean's se is the RMS error's (delta
    method)."""
    d = mean_curve - reference
    ok = np.isfinite(d)
    if not ok.any():
        return np.full(len(curves), np.nan)
    rms = float(np.sqrt(np.mean(d[ok] ** 2)))
    if rms == 0.0:
        return np.zeros(len(curves))
    dev = np.where(np.isfinite(curves[:, ok]), curves[:, ok] - mean_curve[ok], 0.0)
    if defined is not None:  # a point no sample defines has no deviation to weight
        share = defined[ok]
        dev = np.divide(dev, share, out=np.zeros_like(dev), where=share > 0.0)
    return dev @ d[ok] / (ok.sum() * rms)


def _defined_share(rows: np.ndarray) -> np.ndarray:
    """The share of ``rows`` (samples, points) finite at each point."""
    return np.isfinite(rows).mean(axis=0) if len(rows) else np.ones(rows.shape[1])


def metric_series(run: xr.Dataset, ref: xr.Dataset, idx: np.ndarray, samples: np.ndarray,
                  x_star_range=(0.0, 12.0)) -> tuple[np.ndarray, np.ndarray]:
    """Over ``samples``: the uniform depth / h_n (column 0), the influence series of zeta_fs
    (column 1) and of zeta_u at each station (columns 2...), linearised about the means over the
    window ``idx``, each point weighted by the share of ``samples`` that define it
    (``rms_influence``): (time, series)."""
    hn = float(run.attrs["h_n_m"])
    lo, hi = x_star_range
    ref_s = ref["surface"].sel(x_star=slice(lo, hi))
    xr_, xs = ref_s["x_star"].values, run["x_star"].values
    surf = run["surface_elevation"].values / hn
    cols = [run["uniform_depth"].values[samples] / hn,
            rms_influence(ref_s.values, on_abscissas(xr_, xs, _column_means(surf[idx])),
                          _on_reference(xr_, xs, surf[samples]), _defined_share(_on_reference(xr_, xs, surf[samples])))]
    vel, z = run["velocity_star"], run["z_star"].values
    for s in ref["station"].values:
        ref_u = ref["velocity"].sel(station=s)
        zr = ref_u["z_star"].values
        v = vel.sel(station=s, method="nearest").values
        cols.append(rms_influence(ref_u.values, on_abscissas(zr, z, _column_means(v[idx])),
                                  _on_reference(zr, z, v[samples]), _defined_share(_on_reference(zr, z, v[samples]))))
    return run["time"].values[samples], np.array(cols)


def window_errors(run: xr.Dataset, ref: xr.Dataset, idx: np.ndarray,
                  x_star_range=(0.0, 12.0)) -> tuple[dict, np.ndarray]:
    """Standard errors of zeta_h, zeta_h_paper, zeta_fs and zeta_u (per station) over the
    window of time samples ``idx`` (contiguous): each the se of its series' window mean
    (``metric_series``, solver.timeseries.window_fits), its autocorrelation read over the window
    and the samples before it (``context_samples``). NaN with fewer than MIN_WINDOW_SAMPLES."""
    if idx.size < MIN_WINDOW_SAMPLES:
        return {k: np.nan for k in PROFILE_METRICS}, np.full(ref["station"].size, np.nan)
    from solver.timeseries import window_fits
    lead = context_samples(run, idx)
    t, ys = metric_series(run, ref, idx, np.concatenate([lead, idx]), x_star_range)
    _, se, _, _ = window_fits(t, ys, lead.size)
    hn = float(run.attrs["h_n_m"])
    out = {"zeta_h": float(se[0]), "zeta_h_paper": float(se[0]) * hn / float(run.attrs["normalising_depth_m"]),
           "zeta_fs": float(se[1])}
    return out, se[2:]


HOLDOUT_METRICS = ("zeta_f", "zeta_h", "zeta_fs")


def holdout_metrics(run: xr.Dataset, ref: xr.Dataset, idx: np.ndarray, x_star_range=(0.0, 12.0)):
    """zeta_f, zeta_h, zeta_fs and zeta_u over the samples ``idx`` (the hold-out window), each
    with its standard error as over the averaging window: ({name: (value, se)}, zeta_u, its se)."""
    sub = run.isel(time=idx)
    ub = float(run.attrs["belt_speed_m_s"])
    s, zu = profile_metrics(float(sub["uniform_depth"].mean("time")), sub["surface_elevation"].mean("time"),
                            sub["velocity_star"].mean("time"), run, ref, x_star_range)
    se, zu_se = window_errors(run, ref, idx, x_star_range)
    out = {k: (s[k], se[k]) for k in ("zeta_h", "zeta_fs")}
    t, toe, context = _front_record(run, idx[-1] + 1)
    out["zeta_f"] = last_second_velocity(t, toe, ub, context)
    return out, zu, zu_se


def _front_record(run: xr.Dataset, end: int, name: str = "toe_position"):
    """(time, the front series ``name``, the se's context [s]) of the samples before index
    ``end``, from the run's steady.min_time on (``context_samples``)."""
    t = run["time"].values[:end]
    keep = t >= float(run.attrs.get("steady_min_time_s", DEFAULT_MIN_TIME)) - 1e-9
    if keep.sum() < 4:
        keep[:] = True
    return t[keep], run[name].values[:end][keep], float(run.attrs.get("se_context_s", DEFAULT_CONTEXT))


def case_metrics(run: xr.Dataset, ref: xr.Dataset, x_star_range=(0.0, 12.0),
                 measured: dict | None = None) -> xr.Dataset:
    """All metrics of one run against the reference (and measured data when given), over its
    averaging window, and the same over its hold-out window (``*_holdout``) where it has one.

    Diverged runs give NaN metrics. A run that did not reach steady state gives its metrics
    over its final pair's averaging window, flagged by ``steady = 0`` (the report and figures mark them).
    """
    st = ref["station"].values
    out = {k: np.nan for k in ("zeta_f", "zeta_f_se", "zeta_f_body", "zeta_f_body_se") + PROFILE_METRICS
           + tuple(f"{k}_se" for k in PROFILE_METRICS)
           + tuple(f"{k}_holdout{e}" for k in HOLDOUT_METRICS for e in ("", "_se"))}
    zu, zu_se = np.full(st.size, np.nan), np.full(st.size, np.nan)
    zu_hold, zu_hold_se = np.full(st.size, np.nan), np.full(st.size, np.nan)
    meas = {"zeta_fs_measured": np.nan}
    zu_meas = np.full(st.size, np.nan)
    ok = run.attrs.get("status") in ("completed", "not_steady") and "mean_surface_elevation" in run
    if ok:
        hn = float(run.attrs["h_n_m"])
        ub = float(run.attrs["belt_speed_m_s"])
        out["zeta_f"] = zeta_f(float(run["front_velocity"]), ub)
        idx = window_samples(run)
        if "toe_position" in run:  # zeta_f's second: the window's last (the record's, without a window)
            end = idx[-1] + 1 if idx is not None else run.sizes["time"]
            t, toe, context = _front_record(run, end)
            out["zeta_f_se"] = zeta_f_error(t, toe, ub, context)
            if "front_equivalent" in run:
                t, front, context = _front_record(run, end, "front_equivalent")
                out["zeta_f_body"], out["zeta_f_body_se"] = front_body_velocity_error(t, front, ub, context)
        surf = run["mean_surface_elevation"]
        vel = run["mean_velocity_star"]
        scalars, zu = profile_metrics(float(run["mean_uniform_depth"]), surf, vel, run, ref, x_star_range)
        out.update(scalars)
        if idx is not None:
            se, zu_se = window_errors(run, ref, idx, x_star_range)
            out.update({f"{k}_se": v for k, v in se.items()})
        hold = holdout_samples(run)
        if hold is not None and idx is not None and "toe_position" in run:
            h, zu_hold, zu_hold_se = holdout_metrics(run, ref, hold, x_star_range)
            for k, (v, e) in h.items():
                out[f"{k}_holdout"], out[f"{k}_holdout_se"] = v, e
        if measured:
            if measured.get("surface") is not None:
                meas["zeta_fs_measured"] = zeta_fs(measured["surface"], surf / hn)
            for j, s in enumerate(st):
                m = (measured.get("velocity") or {}).get(float(s))
                if m is not None:
                    zu_meas[j] = zeta_u(m, vel.sel(station=s, method="nearest"))
    data = {k: ((), v) for k, v in {**out, **meas}.items()}
    data["zeta_u"] = (("station",), zu)
    data["zeta_u_se"] = (("station",), zu_se)
    data["zeta_u_measured"] = (("station",), zu_meas)
    data["zeta_u_holdout"] = (("station",), zu_hold)
    data["zeta_u_holdout_se"] = (("station",), zu_hold_se)
    data["steady"] = ((), int(run.attrs.get("steady", 0)) if ok else 0)
    ds = xr.Dataset(data, coords={"station": st})
    ds["steady"].attrs.update(units="1", long_name="1: metrics over a steady window; 0: not steady or no metrics")
    attrs = {
        "zeta_f": "front velocity error |u*_f - u*_b| / u*_b",
        "zeta_f_se": "standard error of zeta_f: of the toe's slope over its second",
        "zeta_f_body": "front velocity error of the front's body: |u_e| / u_b, u_e the equivalent "
                       "front's velocity over zeta_f's second (not the paper's metric; a diagnostic)",
        "zeta_f_body_se": "standard error of zeta_f_body: of the equivalent front's slope over its second",
        "zeta_h": "uniform depth error against the computed h_n",
        "zeta_h_paper": "uniform depth error against the paper's normalising depth",
        "zeta_fs": "free-surface RMS error against the theory",
        "zeta_u": "velocity-profile RMS error against the theory",
        "zeta_h_se": "standard error of zeta_h: of the window mean of the uniform depth",
        "zeta_h_paper_se": "standard error of zeta_h_paper: of the window mean of the uniform depth",
        "zeta_fs_se": "standard error of zeta_fs: of the window mean of its influence series",
        "zeta_u_se": "standard error of zeta_u: of the window mean of its influence series",
        "zeta_fs_measured": "free-surface RMS error against measured data",
        "zeta_u_measured": "velocity-profile RMS error against measured data",
        **{f"{k}_holdout": f"{k} over the hold-out window (the window after the averaging window)"
           for k in HOLDOUT_METRICS + ("zeta_u",)},
        **{f"{k}_holdout_se": f"standard error of {k}_holdout" for k in HOLDOUT_METRICS + ("zeta_u",)},
    }
    for k, v in attrs.items():
        ds[k].attrs.update(units="1", long_name=v)
    return ds
