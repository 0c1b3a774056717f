"""Stability margins of each run, the detector that stopped a diverged one, and the safe
settings of a sweep. Pure functions over the per-run and campaign datasets.

Margins, each as a fraction of the guard that would stop the run (1 = the guard fires):
- density: max over the run of max|rho/rho0 - 1| / guards.max_density_deviation;
- penetration: deepest fluid particle inside a wall / guards.penetration (in dp);
- area drift: max |enclosed / mass-implied area - 1| / max_area_drift;
and, unguarded, the peak kinetic energy in units of 0.5 M u_b^2 (M the fluid mass, u_b the
belt speed): about 1 for the belt flow (in the lab frame most of the fluid moves at close to
the belt speed), it grows without bound in a blow-up.
The diagnostics are sampled at an interval, so the sample that tripped a guard may not be
among them: the margin of the guard that stopped a run is at least 1.
"""
from __future__ import annotations

import numpy as np
import xarray as xr
import yaml

# reason text of each solver / monitor guard -> short detector name
DETECTORS = (
    ("non-finite", "non-finite values"),
    ("density deviation", "density deviation"),
    ("crossed a wall", "wall crossing"),
    ("left the domain", "left domain"),
    ("time step collapsed", "time-step collapse"),
    ("enclosed area", "area drift"),
)
GUARD_DEFAULTS = {"max_density_deviation": 0.1, "penetration": 0.5}
MARGINS = ("density_margin", "penetration_margin", "area_drift_margin")
TIE = 0.02  # worst margins closer than this are not told apart
SAFE_FRACTION = 0.5  # a survivor is "safe" when every margin stays below this fraction
# the swept settings: a case key, or a numerics key by its path in the case's numerics block
SETTINGS = ("dp", "ch", "shifting", "shifting.coefficient", "cfl", "cfl_rule", "coefsound",
            "density_diffusion", "boundary")
CASE_LEVEL = ("dp", "ch", "shifting", "coefsound")


def detector(status: str, reason: str) -> str:
    """Short name of the guard that ended a diverged run ('' for a run that survived)."""
    if status != "diverged":
        return ""
    for key, name in DETECTORS:
        if key in reason:
            return name
    return "other"


def margins(run: xr.Dataset) -> dict[str, float]:
    """The margins of one run (NaN where the run recorded nothing)."""
    nan = float("nan")
    scene = yaml.safe_load(run.attrs.get("scene_yaml", "")) or {}
    guards = {**GUARD_DEFAULTS, **(scene.get("guards") or {})}
    case = yaml.safe_load(run.attrs.get("case_yaml", "")) or {}

    def peak(name):
        v = run[name].values if name in run else np.zeros(0)
        v = v[np.isfinite(v)]
        return float(np.max(np.abs(v))) if v.size else nan

    dp = float(run.attrs.get("dp", nan))
    out = {"density_margin": peak("max_density_deviation") / guards["max_density_deviation"],
           "penetration_margin": peak("max_penetration") / (guards["penetration"] * dp),
           "area_drift_margin": peak("area_drift") / float(case.get("max_area_drift", 0.05))}
    ke = peak("kinetic_energy")
    ub = float(run.attrs.get("belt_speed_m_s", nan))
    mass = nan
    if "mass_area" in run and run.sizes.get("time", 0):
        mass = float(run["mass_area"].values[0]) * float(run.attrs.get("rho0", nan))
    fired = {"density deviation": "density_margin", "wall crossing": "penetration_margin",
             "area drift": "area_drift_margin"}.get(detector(run.attrs.get("status", ""), run.attrs.get("reason", "")))
    if fired:
        out[fired] = max(out[fired], 1.0) if np.isfinite(out[fired]) else 1.0
    out["energy_ratio"] = ke / (0.5 * mass * ub * ub) if mass > 0 else nan
    out["end_time"] = float(run.attrs.get("simulated_time_s", nan))
    return out


def case_settings(run: xr.Dataset) -> dict:
    """The swept settings of one run, from its case configuration."""
    case = yaml.safe_load(run.attrs.get("case_yaml", "")) or {}
    numerics = case.get("numerics") or {}

    def numerics_value(path):
        node = numerics
        for part in path.split("."):
            node = node.get(part) if isinstance(node, dict) else None
        return node

    return {k: case.get(k) if k in CASE_LEVEL else numerics_value(k) for k in SETTINGS}


def is_safe(status: str, m: dict) -> bool:
    """Survived, and every guarded margin below SAFE_FRACTION of its guard."""
    return status != "diverged" and all(np.isfinite(m[k]) and m[k] < SAFE_FRACTION for k in MARGINS)


def _fmt(v) -> str:
    """A setting's value as written in the YAML config."""
    return "null" if v is None else str(v)


def _order(v):
    return (v is None, isinstance(v, str), v if isinstance(v, (int, float, str)) else 0)


def base_settings(settings: list[dict]) -> dict:
    """The most common value of each setting: the base case of a one-at-a-time sweep."""
    base = {}
    for key in SETTINGS:
        vals = [repr(s.get(key)) for s in settings]
        top = max(dict.fromkeys(vals), key=vals.count)
        base[key] = next(s.get(key) for s in settings if repr(s.get(key)) == top)
    return base


def worst_margin(ds: xr.Dataset) -> np.ndarray:
    """Per case, the largest of its guarded margins."""
    m = np.stack([ds[f"case_{k}"].values for k in MARGINS])
    return np.where(np.isfinite(m).any(axis=0), np.nanmax(np.where(np.isfinite(m), m, -np.inf), axis=0), np.nan)


def settings_summary(ds: xr.Dataset) -> list[dict]:
    """For each setting that takes more than one value: per value, the cases tried, survived
    and safe, the detectors that fired, and the outcome with every other setting at its base
    value (``alone``: status and worst margin of that case, None if the sweep has none)."""
    settings = [yaml.safe_load(s) for s in ds["case_settings"].values]
    status = [str(s) for s in ds["case_status"].values]
    det = [str(s) for s in ds["case_detector"].values]
    safe = [bool(s) for s in ds["case_safe"].values]
    worst = worst_margin(ds)
    base = base_settings(settings)
    rows = []
    for key in SETTINGS:
        values = [s.get(key) for s in settings]
        distinct = sorted({repr(v): v for v in values}.values(), key=_order)
        if len(distinct) < 2:
            continue
        for v in distinct:
            idx = [i for i, x in enumerate(values) if repr(x) == repr(v)]
            alone = [i for i in idx if all(repr(settings[i].get(k)) == repr(base[k]) for k in SETTINGS if k != key)]
            rows.append({"setting": key, "value": _fmt(v), "tried": len(idx),
                         "survived": sum(status[i] != "diverged" for i in idx),
                         "safe": sum(safe[i] for i in idx),
                         "detectors": sorted({det[i] for i in idx if det[i]}),
                         "alone": (status[alone[0]], float(worst[alone[0]])) if alone else None})
    return rows


def recommended(ds: xr.Dataset) -> dict:
    """One setting at a time, all others at the base: the values that survived, and among them
    the one with the largest margin (for a setting with at least two values tried alone); plus the
    case with the largest margin among the safe ones."""
    base = {k: _fmt(v) for k, v in base_settings([yaml.safe_load(s) for s in ds["case_settings"].values]).items()}
    out = {}
    for r in settings_summary(ds):
        if r["alone"] is None:
            continue
        entry = out.setdefault(r["setting"], {"survived": [], "diverged": [], "best": None, "_w": np.inf})
        st, w = r["alone"]
        entry["diverged" if st == "diverged" else "survived"].append(r["value"])
        # a margin better by less than TIE is a tie, and the base value keeps its place
        is_base = r["value"] == base[r["setting"]]
        if st != "diverged" and np.isfinite(w) and (w < entry["_w"] - TIE or (is_base and w <= entry["_w"] + TIE)):
            entry["best"], entry["_w"] = r["value"], w
    for key in [k for k, e in out.items() if len(e["survived"]) + len(e["diverged"]) < 2]:
        del out[key]  # one value tried alone: nothing to recommend it over
    for entry in out.values():
        entry.pop("_w")
    safe = ds["case_safe"].values.astype(bool)
    worst = worst_margin(ds)
    best = str(ds["case"].values[np.where(safe)[0][np.argmin(worst[safe])]]) if safe.any() else ""
    return {"settings": out, "base": base, "safest_case": best}
