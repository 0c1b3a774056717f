"""A scene flow's campaign dataset (one row a ``case``): its sequences over dp, their
convergence, and which runs can be trusted. Pure functions over xarray objects."""
from __future__ import annotations

import numpy as np
import xarray as xr

from ..convergence import gci

LABELS = {
    "front_final": "front x_N at the end", "runout": "runout",
    "front_error": "front x_N", "exponent_error": "exponent of x_N (t)", "depth_error": "depth profile",
    "runout_error": "runout", "shape_error": "arrested shape", "profile_error": "velocity profile",
    "velocity_error": "velocity profiles",
}


def mm(dp) -> str:
    return f"{1000 * float(dp):.4g} mm"


def seconds(v) -> str:
    """A wall time: whole seconds from 10 s, two significant digits below."""
    v = float(v)
    return f"{v:.0f}" if v >= 10 else f"{v:.2g}"


def group_label(fluid: str, axes=()) -> str:
    """A fluid and its physical axes' values, e.g. 'newtonian angle 5'."""
    parts = [fluid] if fluid else []
    return " ".join(parts + [f"{k} {v:g}" if isinstance(v, float) else f"{k} {v}" for k, v in axes])


def series_label(seq) -> str:
    head = group_label(seq["fluid"], seq.get("axes", ()))
    return " ".join(([head] if head else []) + [seq["scheme"], seq["shifting"], f"Ch {seq['ch']:g}"])


def sequences(ds: xr.Dataset) -> list[dict]:
    """The (fluid, physical axes' values, scheme, ch, shifting) groups of cases, each with its
    case indices by falling dp: one convergence sequence a value of each physical axis."""
    axes = [a for a in str(ds.attrs.get("axes", "")).split(",") if a]
    keys = {}
    for i in range(ds.sizes["case"]):
        values = tuple((a, ds[a].values[i].item()) for a in axes)
        values = tuple((a, v) for a, v in values if v == v and v != "")  # this case's own axes
        k = tuple(str(ds[c].values[i]) for c in ("fluid", "scheme", "shifting")) + (float(ds["ch"].values[i]), values)
        keys.setdefault(k, []).append(i)
    out = []
    for (fluid, scheme, shifting, ch, values), idx in keys.items():
        idx = sorted(idx, key=lambda i: -float(ds["dp"].values[i]))
        out.append({"fluid": fluid, "scheme": scheme, "shifting": shifting, "ch": ch, "axes": values, "cases": idx})
    return out


def falls_with_dp(values, se=None) -> str:
    """'falls', 'rises', 'not monotone' or 'too few' for an error's magnitudes over falling dp."""
    v = np.abs(np.asarray(values, dtype=float))
    v = v[np.isfinite(v)]
    if v.size < 2:
        return "too few"
    d = np.diff(v)
    if np.all(d < 0):
        return "falls"
    if np.all(d > 0):
        return "rises"
    return "not monotone"


def convergence(ds: xr.Dataset, var: str, idx: list[int]):
    """Observed order and GCI of ``var``'s magnitude over the sequence's three finest dp
    (study.convergence.gci)."""
    return gci(ds["dp"].values[idx], np.abs(ds[var].values[idx]))


def trustworthy(ds: xr.Dataset, i: int, errs, tolerance: float) -> bool:
    """Completed (and, for a yield-stress slump, stopped), every error below the tolerance by
    more than 2 se."""
    if str(ds["status"].values[i]) != "completed":
        return False
    if "stopped" in ds and np.isfinite(ds["stopped"].values[i]) and not ds["stopped"].values[i] \
            and "runout_error" in errs:
        return False
    for e in errs:
        v = float(ds[e].values[i])
        se = float(ds[f"{e}_se"].values[i]) if f"{e}_se" in ds else 0.0
        if not np.isfinite(v) or abs(v) + 2.0 * (se if np.isfinite(se) else 0.0) >= tolerance:
            return False
    return True


def cheapest(ds: xr.Dataset, idx, errs, tolerance: float) -> int | None:
    ok = [i for i in idx if trustworthy(ds, i, errs, tolerance)]
    return min(ok, key=lambda i: float(ds["wall_time_s"].values[i])) if ok else None
