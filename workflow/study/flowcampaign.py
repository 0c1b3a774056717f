"""A flow campaign's numbers: each run scored (metrics.nc), the runs reduced into one dataset
over ``case`` (campaign.nc), and what the report says of them: convergence, the cheapest
trustworthy run, the answer in one sentence (docs/flows.md)."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import xarray as xr

from .flowconfig import G, FlowCase, cases, fluid_of, read_references, scene_dict  # noqa: F401 (G for callers)
from .flows import scores

# each flow's errors, the headline first (an error is a fraction; each has an _se)
ERRORS = {
    ("slump", True): ("front_error", "exponent_error", "depth_error"),
    ("slump", False): ("runout_error", "shape_error"),
    ("film", True): ("profile_error",),
    ("user", True): ("front_error", "depth_error", "velocity_error"),
}
# the measured quantity whose convergence the GCI states (Celik et al. 2008), per flow and fluid
QUANTITIES = {("slump", True): ("front_final",), ("slump", False): ("runout",)}
LABELS = {
    "front_final": "front x_N at the end", "runout": "runout",
    "front_error": "front x_N", "exponent_error": "exponent of x_N (t)", "depth_error": "depth profile",
    "runout_error": "runout", "shape_error": "arrested shape", "profile_error": "velocity profile",
    "velocity_error": "velocity profiles",
}


def newtonian(fluid: dict) -> bool:
    return fluid.get("rheology", "newtonian") == "newtonian"


def errors_of(cfg: dict, fluid: dict | None = None) -> tuple[str, ...]:
    """The error names of the campaign's flow (and fluid); for a user flow those its reference
    files give."""
    flow = cfg["flow"]
    if flow == "user":
        kinds = cfg["scene"]["reference"]
        return tuple(f"{k}_error" for k in ("front", "depth", "velocity") if k in kinds)
    return ERRORS[(flow, True if fluid is None else newtonian(fluid))]


def all_errors(cfg: dict) -> list[str]:
    """The error names of every fluid of the campaign, each once, in order."""
    out: list[str] = []
    for fl in fluid_dicts(cfg).values():
        out += [e for e in errors_of(cfg, fl or None) if e not in out]
    return out


def case_by_id(cfg: dict, case_id: str) -> FlowCase:
    for c in cases(cfg):
        if c.id == case_id:
            return c
    raise KeyError(f"no case {case_id} in this campaign")


def score(cfg: dict, case: FlowCase, run: xr.Dataset) -> xr.Dataset:
    """The run's errors (study.flows.scores) and its cost and status, as scalars; the front
    series x_N(t) where the flow has a front."""
    flow, s = cfg["flow"], cfg["scene"]
    status = str(run.attrs.get("status", "unknown"))
    values: dict = {}
    series = None
    if status != "diverged" and run.sizes.get("snapshot", 0) > 1:
        if flow == "slump":
            fl = fluid_of(cfg, case)
            if newtonian(fl):
                values = scores.slump_newtonian(run, s["height"], s["length"], fl["viscosity"] / fl["density"],
                                                cfg["metrics"]["memory_fraction"])
            else:
                values = scores.slump_yield(run, s["height"], s["length"], fl["yield_stress"], fl["density"],
                                            cfg["metrics"]["stop_speed"], cfg["metrics"]["stop_window"])
            from .flows import measure
            series = measure.front(run, symmetric=True)
        elif flow == "film":
            fl = fluid_of(cfg, case)
            depth = scene_dict(cfg, case)["fluid"]["blocks"][0]["z"][1]
            values = scores.film_startup(run, depth, fl["viscosity"] / fl["density"], math.radians(s["angle"]))
        else:
            values = scores.user_scores(run, read_references(s), s["front_from"], s["symmetric"])
            if "front" in s["reference"]:
                from .flows import measure
                series = measure.front(run, symmetric=s["symmetric"])
    data = {k: float(v) for k, v in values.items()}
    ds = xr.Dataset({k: ((), v) for k, v in data.items()})
    if series is not None:
        ds["x_front"] = series.rename({"t": "front_time"})
    ds.attrs.update(case=case.id, status=status, reason=str(run.attrs.get("reason", "")),
                    wall_time_s=float(run.attrs.get("wall_time_s", math.nan)),
                    steps=int(run.attrs.get("steps", 0)), n_particles=int(run.attrs.get("n_particles", 0)),
                    end_time_s=float(run["snapshot_time"].values[-1]) if run.sizes.get("snapshot", 0) else math.nan)
    return ds


def reduce(cfg: dict, results: Path) -> xr.Dataset:
    """Every case's metrics.nc into one dataset over ``case`` (coords dp, ch, shifting, scheme,
    fluid; status, wall time, steps; every error and its se; x_front over (case, front_time))."""
    rows, fronts = [], []
    names: list[str] = []
    for c in cases(cfg):
        m = xr.load_dataset(Path(results) / c.id / "metrics.nc")
        rows.append(m)
        names += [k for k in m.data_vars if k != "x_front" and k not in names]
        if "x_front" in m:
            fronts.append(m["x_front"].expand_dims(case=[c.id]))
    cs = cases(cfg)
    coords = {"case": [c.id for c in cs], "dp": ("case", [c.dp for c in cs]), "ch": ("case", [c.ch for c in cs]),
              "shifting": ("case", [c.shifting for c in cs]), "scheme": ("case", [c.scheme for c in cs]),
              "fluid": ("case", [c.fluid or "" for c in cs])}
    data = {k: ("case", [float(m[k]) if k in m else math.nan for m in rows]) for k in names}
    data["status"] = ("case", [m.attrs["status"] for m in rows])
    data["reason"] = ("case", [m.attrs["reason"] for m in rows])
    for k in ("wall_time_s", "steps", "n_particles", "end_time_s"):
        data[k] = ("case", [m.attrs[k] for m in rows])
    ds = xr.Dataset(data, coords=coords)
    if fronts:
        ds["x_front"] = xr.concat(fronts, dim="case", join="outer").reindex(case=ds["case"].values)
    ds.attrs["flow"] = cfg["flow"]
    return ds


def sequences(ds: xr.Dataset) -> list[dict]:
    """The (fluid, scheme, ch, shifting) groups of cases, each with its case indices by
    falling dp."""
    keys = {}
    for i in range(ds.sizes["case"]):
        k = tuple(str(ds[c].values[i]) for c in ("fluid", "scheme", "shifting")) + (float(ds["ch"].values[i]),)
        keys.setdefault(k, []).append(i)
    out = []
    for (fluid, scheme, shifting, ch), idx in keys.items():
        idx = sorted(idx, key=lambda i: -float(ds["dp"].values[i]))
        out.append({"fluid": fluid, "scheme": scheme, "shifting": shifting, "ch": ch, "cases": idx})
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
    from .convergence import gci
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


def fluid_dicts(cfg: dict) -> dict:
    """name -> fluid of the campaign; a user flow's one unnamed fluid ({"": {}}) is its scene's."""
    return dict(cfg.get("fluids") or {"": {}})

