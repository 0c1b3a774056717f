"""A flow run's errors against its reference, each with its sampling error (docs/flows.md).

Every error is an RMS over samples (times of a front, abscissas of a profile) of a deviation
d_i. Its sampling error comes from the scatter of d_i^2 about a least-squares line through
them, from their autocorrelation (solver.steady.line_fits): se(mean d^2) / (2 RMS). It is
the particle noise of the measurement, not the discretisation error.
"""
from __future__ import annotations

import math

import numpy as np

from ..references import film, slump, user
from . import measure

G = 9.81


def rms_with_se(s, d) -> tuple[float, float]:
    """(sqrt(mean d^2), its sampling error) of the deviations d at the abscissas s (module
    docstring); NaN, NaN without a finite sample, se NaN below 3 samples."""
    from solver.steady import line_fits
    s = np.asarray(s, dtype=float)
    d = np.asarray(d, dtype=float)
    ok = np.isfinite(s) & np.isfinite(d)
    if not ok.any():
        return math.nan, math.nan
    rms = float(np.sqrt(np.mean(d[ok] ** 2)))
    if ok.sum() < 3 or rms == 0.0:
        return rms, math.nan if ok.sum() < 3 else 0.0
    _, se_sq, _, _ = line_fits(s[ok], (d[ok] ** 2)[None, :])
    return rms, float(se_sq[0]) / (2.0 * rms)


def _front_scores(t, x, t_ref, x_ref, prefix="front"):
    """RMS relative front error over the reference times (run interpolated onto them), its se,
    and the signed relative error at the last compared time."""
    x_run = user.on_reference(t_ref, t, x)
    d = (x_run - x_ref) / x_ref
    err, se = rms_with_se(t_ref, d)
    ok = np.isfinite(d)
    last = float(d[ok][-1]) if ok.any() else math.nan
    return {f"{prefix}_error": err, f"{prefix}_error_se": se, f"{prefix}_final_error": last}


def slump_newtonian(ds, H0: float, L0: float, nu: float, memory_fraction: float) -> dict:
    """Front error against the similarity front over t >= t_c, t_c = ``slump.exponent_time``
    (memory_fraction) (the release's memory has faded), and the fitted exponent over the same
    times (both NaN where fewer than 3 snapshots reach t_c); the depth profile of the last
    snapshot (``measure.depth_profile``, interpolated onto them) against the similarity profile
    at 40 abscissas x <= 0.95 x_N (RMS over the reference's depth at the plane)."""
    A = H0 * L0
    t_c = slump.exponent_time(L0, A, nu, G, memory_fraction)
    xf = measure.front(ds, symmetric=True)
    t, x = xf["t"].values, xf.values
    late = t >= t_c
    out = {"compare_from": t_c, "front_final": float(x[-1]),
           "front_reference_final": float(slump.front_position(t[-1], A, nu, G))}
    if late.sum() >= 3:
        out |= _front_scores(t, x, t[late], slump.front_position(t[late], A, nu, G))
        b, b_se = slump.fit_front_exponent(t, x, (t_c, math.inf))
        out |= {"exponent": b, "exponent_se": b_se, "exponent_error": b / slump.SIMILARITY_EXPONENT - 1.0,
                "exponent_error_se": b_se / slump.SIMILARITY_EXPONENT}
    else:  # the run ends before the release has forgotten its start: nothing to compare
        out |= {k: math.nan for k in ("front_error", "front_error_se", "front_final_error", "exponent",
                                       "exponent_se", "exponent_error", "exponent_error_se")}
    k = ds.sizes["snapshot"] - 1
    xn = float(slump.front_position(t[k], A, nu, G))
    xs = np.linspace(0.0, 0.95 * xn, 40)
    h_ref = slump.depth_profile(xs, t[k], A, nu, G)
    h_run = user.on_reference(xs, *measure.depth_profile(ds, k, symmetric=True))
    err, se = rms_with_se(xs, (h_run - h_ref) / h_ref[0])
    return out | {"depth_error": err, "depth_error_se": se}


def stop_time(t, x, stop_speed: float, window: float) -> float:
    """The first time from which the front's speed, the slope of a line over the preceding
    ``window`` seconds, stays below ``stop_speed``; NaN if it never does."""
    from solver.steady import trend
    t = np.asarray(t, dtype=float)
    x = np.asarray(x, dtype=float)
    speeds = np.full(t.size, np.nan)
    for k in range(t.size):
        sel = (t > t[k] - window - 1e-12) & (t <= t[k])
        if sel.sum() >= 3 and t[k] - t[0] >= window - 1e-12:
            speeds[k] = trend(t[sel], x[sel])
    slow = np.isfinite(speeds) & (np.abs(speeds) < stop_speed)
    for k in range(t.size):
        if slow[k] and slow[k:].all():
            return float(t[k])
    return math.nan


def slump_yield(ds, H0: float, L0: float, tau_y: float, rho: float, stop_speed: float, window: float) -> dict:
    """Whether the front stops (``stop_time``), its runout where it stops against the reference
    runout, that of the perfectly plastic layer (``slump.release_runout_corrected``), and the
    last snapshot's depth against its arrested shape (``slump.release_shape_corrected``) (RMS over
    40 abscissas x <= 0.95 x_N, over its depth at the wall). The runout's se: the front's scatter
    over the stop window. ``runout_reference_shallow`` is the lubrication runout
    (``slump.release_runout``): its difference from ``runout_reference`` is the reference's own
    uncertainty, reported beside the error and not added to it."""
    xf = measure.front(ds, symmetric=True)
    t, x = xf["t"].values, xf.values
    x_ref = slump.release_runout_corrected(H0, L0, tau_y, rho, G)
    t_s = stop_time(t, x, stop_speed, window)
    out = {"runout_reference": x_ref, "runout_reference_shallow": slump.release_runout(H0, L0, tau_y, rho, G),
           "front_final": float(x[-1]), "stop_time": t_s, "stopped": float(np.isfinite(t_s))}
    if np.isfinite(t_s):
        k = int(np.argmin(np.abs(t - t_s)))
        sel = (t > t_s - window - 1e-12) & (t <= t_s)
        from solver.steady import line_fits
        _, se, _, _ = line_fits(t[sel], x[sel][None, :])
        out |= {"runout": float(x[k]), "runout_error": float(x[k] / x_ref - 1.0),
                "runout_error_se": float(se[0] / x_ref)}
    else:
        out |= {"runout": math.nan, "runout_error": math.nan, "runout_error_se": math.nan}
    k = ds.sizes["snapshot"] - 1
    xs = np.linspace(0.0, 0.95 * x_ref, 40)
    h_ref = slump.release_shape_corrected(xs, H0, L0, tau_y, rho, G)
    h_run = user.on_reference(xs, *measure.depth_profile(ds, k, symmetric=True))
    err, se = rms_with_se(xs, (h_run - h_ref) / h_ref[0])
    return out | {"shape_error": err, "shape_error_se": se}


def film_startup(ds, depth: float, nu: float, theta: float) -> dict:
    """The start-up profile at every snapshot after t = 0 against the exact series
    (``film.velocity``): RMS over the fluid particles of (u - u_exact) / u_max, its largest
    value over the snapshots (``profile_error``) and that snapshot's time."""
    u_max = film.u_max(depth, nu, G, theta)
    worst, worst_se, worst_t = -1.0, math.nan, math.nan
    times = ds["snapshot_time"].values
    for k in range(1, times.size):
        _, z, u = measure.fluid(ds, k)
        order = np.argsort(z)
        d = (u[order] - film.velocity(z[order], times[k], depth, nu, G, theta)) / u_max
        err, se = rms_with_se(z[order], d)
        if np.isfinite(err) and err > worst:
            worst, worst_se, worst_t = err, se, float(times[k])
    if worst < 0:
        worst = math.nan
    return {"profile_error": worst, "profile_error_se": worst_se, "profile_error_time": worst_t, "u_max": u_max}


def user_scores(ds, refs: dict, front_from: float, symmetric: bool) -> dict:
    """Against a user's reference files (study.references.user): the front (RMS relative error over
    the reference times >= front_from), each depth profile at its time (the snapshot at that
    time), each velocity profile at its station (the last snapshot, the particles within dp / 2
    of the station's x, or all of them in a scene periodic in x), the run's profile interpolated
    linearly onto the reference's abscissas (study.references.user.on_reference); a kind's error is
    the RMS over its profiles."""
    out = {}
    if "front" in refs:
        ref = refs["front"]
        keep = ref["t"].values >= front_from
        xf = measure.front(ds, symmetric=symmetric)
        out |= _front_scores(xf["t"].values, xf.values, ref["t"].values[keep], ref.values[keep])
    dp = float(ds.attrs["dp"])
    if "depth" in refs:
        ref = refs["depth"]
        errs, ses = [], []
        for tk in ref["t"].values:
            prof = ref.sel(t=tk).dropna("x")
            k = measure.snapshot_at(ds, float(tk))
            if k is None:
                continue
            h_run = user.on_reference(prof["x"].values, *measure.depth_profile(ds, k, symmetric=symmetric))
            e, se = rms_with_se(prof["x"].values, (h_run - prof.values) / np.abs(prof.values).max())
            errs.append(e)
            ses.append(se)
        out |= _combine("depth", errs, ses)
    if "velocity" in refs:
        import yaml
        ref = refs["velocity"]
        periodic = (yaml.safe_load(ds.attrs.get("scene_yaml", "")) or {}).get("periodic_x") is not None
        errs, ses = [], []
        k = ds.sizes["snapshot"] - 1
        for xk in ref["x"].values:
            prof = ref.sel(x=xk).dropna("z")
            x_range = None if periodic else (xk - dp / 2, xk + dp / 2)
            u_run = user.on_reference(prof["z"].values, *measure.velocity_profile(ds, k, x_range))
            e, se = rms_with_se(prof["z"].values, (u_run - prof.values) / np.abs(prof.values).max())
            errs.append(e)
            ses.append(se)
        out |= _combine("velocity", errs, ses)
    return out


def _combine(kind, errs, ses) -> dict:
    """RMS over profiles, se propagated."""
    e = np.asarray(errs, dtype=float)
    s = np.asarray(ses, dtype=float)
    if not e.size or not np.isfinite(e).any():
        return {f"{kind}_error": math.nan, f"{kind}_error_se": math.nan}
    rms = float(np.sqrt(np.nanmean(e ** 2)))
    se = float(np.sqrt(np.nansum((e * s) ** 2)) / (e.size * rms)) if rms > 0 else math.nan
    return {f"{kind}_error": rms, f"{kind}_error_se": se}
