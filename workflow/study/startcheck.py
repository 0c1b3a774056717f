"""The start check: at the finest dp, each shifting method's run from the campaign's start beside
the same case run from another start: the paper's (a block at rest, the belt ramped up from rest),
or, where the campaign's run starts that way already, the final state of the next coarser run
(a warm start), or the moving film (the steady lubrication front with the film's velocity
profile, the belt at full speed from t = 0) where there is no coarser run. Pure functions over the
campaign dataset (study.campaign.build)."""
from __future__ import annotations

import numpy as np
import xarray as xr

from solver.schemes import FILM_START, PAPER_START

# a start check's tag (the end of its case id) -> the case keys of its start (a warm start's
# source is set where the case file is written), and the start in words
CHECK_STARTS = {"paper-start": PAPER_START, "warm-start": {}, "film-start": FILM_START}
WARM_CHECK = "warm-start"
CHECK_START_WORDS = {
    "paper-start": "the paper's start: a block at rest at the normal depth, the belt ramped up from rest",
    "warm-start": "a warm start: the final state of the run at the next coarser dp",
    "film-start": ("the film start: the steady lubrication front moving with the film's velocity profile, "
                   "the belt at full speed from t = 0"),
}
Z = 2.0  # two runs agree on a metric where |difference| <= Z se of the difference


def check_tag(start: str, start_velocity: str, coarser: bool) -> str:
    """The tag of the check for a run that starts this way: the paper's start; where the run
    starts as the paper does, a warm start from the next coarser run (``coarser``: there is one)
    or else the moving film."""
    if {"start": start, "start_velocity": start_velocity} != PAPER_START:
        return "paper-start"
    return WARM_CHECK if coarser else "film-start"


def metric_names(ds: xr.Dataset) -> list[str]:
    """zeta_f, zeta_h, zeta_fs and zeta_u at each station, as the case table holds them."""
    return ["zeta_f", "zeta_h", "zeta_fs"] + [f"zeta_u {s:g}" for s in ds["station"].values]


def _values(ds: xr.Dataset, i: int) -> tuple[np.ndarray, np.ndarray]:
    """(values, se) of case i over ``metric_names``."""
    v = [float(ds[f"case_{k}"].values[i]) for k in ("zeta_f", "zeta_h", "zeta_fs")]
    e = [float(ds[f"case_{k}_se"].values[i]) for k in ("zeta_f", "zeta_h", "zeta_fs")]
    return (np.concatenate([v, ds["case_zeta_u"].values[i]]),
            np.concatenate([e, ds["case_zeta_u_se"].values[i]]))


def pairs(ds: xr.Dataset) -> list[tuple[int, int]]:
    """(index of the campaign-start case, index of its start check) in the case table."""
    if "case_tag" not in ds:
        return []
    ids = list(ds["case"].values)
    out = []
    for i, tag in enumerate(ds["case_tag"].values):
        if tag in CHECK_STARTS:
            base = ids[i][: -len(tag) - 1]
            if base in ids:
                out.append((ids.index(base), i))
    return out


def table(ds: xr.Dataset) -> xr.Dataset:
    """Per start check (dim ``check``, named by its case; ``start``: its tag) and metric: both
    runs' values and se (``own``, ``other``), the difference check minus campaign-start with its
    se, and ``agree`` (|difference| <= Z se; False where either is missing). Empty ``check``
    dimension without checks."""
    names = metric_names(ds)
    rows = pairs(ds)
    data = {k: np.full((len(rows), len(names)), np.nan) for k in ("own", "own_se", "other", "other_se")}
    for r, (i, j) in enumerate(rows):
        data["own"][r], data["own_se"][r] = _values(ds, i)
        data["other"][r], data["other_se"][r] = _values(ds, j)
    diff = data["other"] - data["own"]
    diff_se = np.hypot(data["own_se"], data["other_se"])
    with np.errstate(invalid="ignore"):
        agree = np.isfinite(diff) & np.isfinite(diff_se) & (np.abs(diff) <= Z * diff_se)
    dims = ("check", "metric")
    both_steady = [bool(ds["case_steady"].values[i] and ds["case_steady"].values[j]) for i, j in rows]
    return xr.Dataset(
        {**{k: (dims, v) for k, v in data.items()}, "difference": (dims, diff), "difference_se": (dims, diff_se),
         "agree": (dims, agree), "steady": (("check",), np.array(both_steady, dtype=bool)),
         "own_case": (("check",), np.array([str(ds["case"].values[i]) for i, _ in rows], dtype=str)),
         "start": (("check",), np.array([str(ds["case_tag"].values[j]) for _, j in rows], dtype=str))},
        coords={"check": np.array([str(ds["case"].values[j]) for _, j in rows], dtype=str),
                "metric": np.array(names, dtype=str)})
