"""The start check: at the finest dp, each shifting method's run from the campaign's start beside
the same case run from the paper's start (a block at rest, the belt ramped up from rest). Pure
functions over the campaign dataset (study.campaign.build)."""
from __future__ import annotations

import numpy as np
import xarray as xr

START_CHECK_TAG = "paper-start"  # the tag of a start check's case id
Z = 2.0  # two runs agree on a metric where |difference| <= Z se of the difference


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
    """(index of the campaign-start case, index of its paper-start check) in the case table."""
    if "case_tag" not in ds:
        return []
    ids = list(ds["case"].values)
    out = []
    for i, tag in enumerate(ds["case_tag"].values):
        if tag == START_CHECK_TAG:
            base = ids[i][: -len(START_CHECK_TAG) - 1]
            if base in ids:
                out.append((ids.index(base), i))
    return out


def table(ds: xr.Dataset) -> xr.Dataset:
    """Per start check (dim ``check``, named by its case) and metric: both runs' values and se,
    the difference paper-start minus campaign-start with its se, and ``agree`` (|difference|
    <= Z se; False where either is missing). Empty ``check`` dimension without checks."""
    names = metric_names(ds)
    rows = pairs(ds)
    data = {k: np.full((len(rows), len(names)), np.nan) for k in ("own", "own_se", "paper", "paper_se")}
    for r, (i, j) in enumerate(rows):
        data["own"][r], data["own_se"][r] = _values(ds, i)
        data["paper"][r], data["paper_se"][r] = _values(ds, j)
    diff = data["paper"] - data["own"]
    diff_se = np.hypot(data["own_se"], data["paper_se"])
    with np.errstate(invalid="ignore"):
        agree = np.isfinite(diff) & np.isfinite(diff_se) & (np.abs(diff) <= Z * diff_se)
    dims = ("check", "metric")
    both_steady = [bool(ds["case_steady"].values[i] and ds["case_steady"].values[j]) for i, j in rows]
    return xr.Dataset(
        {**{k: (dims, v) for k, v in data.items()}, "difference": (dims, diff), "difference_se": (dims, diff_se),
         "agree": (dims, agree), "steady": (("check",), np.array(both_steady, dtype=bool)),
         "own_case": (("check",), np.array([str(ds["case"].values[i]) for i, _ in rows], dtype=str))},
        coords={"check": np.array([str(ds["case"].values[j]) for _, j in rows], dtype=str),
                "metric": np.array(names, dtype=str)})
