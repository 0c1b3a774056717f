"""The figures of a scene flow's report: errors against dp, run time against error, and the
front against time (with the flow's own reference drawn by the flow)."""
from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import xarray as xr  # noqa: E402

from ..figures import _log_axes, _plain, _PlainLogFormatter  # noqa: E402
from ..grid import Case, axis_label  # noqa: E402
from .runs import LABELS, mm, sequences, series_label  # noqa: E402


def plain_log(ax):
    """Log axes whose every tick label is a plain number (study.figures' rule)."""
    ax.set_xscale("log")
    ax.set_yscale("log")
    for a in (ax.xaxis, ax.yaxis):
        a.set_major_formatter(matplotlib.ticker.FuncFormatter(_plain))
        a.set_minor_formatter(_PlainLogFormatter(_plain))


def errors(flow, cfg: dict, ds: xr.Dataset):
    errs = flow.all_errors(cfg)
    fig, axes = plt.subplots(1, len(errs), figsize=(4.2 * len(errs), 3.6), squeeze=False)
    for ax, e in zip(axes[0], errs):
        drawn = False
        for seq in sequences(ds):
            idx = [i for i in seq["cases"] if np.isfinite(ds[e].values[i])]
            if not idx:
                continue
            se = 2 * ds[f"{e}_se"].values[idx] if f"{e}_se" in ds else None
            ax.errorbar(1000 * ds["dp"].values[idx], np.abs(ds[e].values[idx]), yerr=se, marker="o", capsize=3,
                        label=series_label(seq))
            drawn = True
        _log_axes(ax, drawn, dp_ticks=sorted({1000 * float(d) for d in ds["dp"].values}))
        ax.set_ylabel(f"|{LABELS[e]} error|")
        ax.axhline(cfg["metrics"]["tolerance"], color="0.6", ls=":", lw=1)
        ax.grid(True, which="both", alpha=0.3)
        if drawn:
            ax.legend(fontsize=7)
    fig.tight_layout()
    return fig


def cost(flow, cfg: dict, ds: xr.Dataset):
    fig, ax = plt.subplots(figsize=(5.5, 4))
    fluids = flow.fluid_dicts(cfg)
    drawn = False
    for seq in sequences(ds):
        head = flow.errors_of(cfg, fluids.get(seq["fluid"]) or None)[0]
        idx = [i for i in seq["cases"] if np.isfinite(ds[head].values[i])]
        if idx:
            ax.plot(ds["wall_time_s"].values[idx], np.abs(ds[head].values[idx]), marker="o",
                    label=f"{series_label(seq)} ({LABELS[head]})")
            drawn = True
    _log_axes(ax, drawn, xlabel="run wall time [s]", invert_x=False)
    ax.set_ylabel("|headline error|")
    ax.axhline(cfg["metrics"]["tolerance"], color="0.6", ls=":", lw=1)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    return fig


def fronts(flow, cfg: dict, ds: xr.Dataset):
    """x_N(t) of every run, one panel a fluid, against the flow's reference front."""
    fluids = flow.fluid_dicts(cfg)
    names = [n for n in fluids if any(str(f) == n for f in ds["fluid"].values)]
    fig, axes = plt.subplots(1, len(names), figsize=(5.2 * len(names), 4), squeeze=False)
    keys = {axis_label(k): k for k, _ in flow.axes(cfg)}
    for ax, name in zip(axes[0], names):
        for seq in sequences(ds):
            if seq["fluid"] != name:
                continue
            for i in seq["cases"]:
                x = ds["x_front"].isel(case=i).dropna("front_time")
                ax.plot(x["front_time"], 1000 * x, lw=1, label=f"{series_label(seq)} dp {mm(ds['dp'].values[i])}")
        # the reference of each value of the physical axes (the campaign's own where it has none)
        for values in dict.fromkeys(seq["axes"] for seq in sequences(ds) if seq["fluid"] == name):
            own = flow.case_config(cfg, Case(0.0, 0.0, "", fluid=name or None,
                                             axes=tuple((keys[a], v) for a, v in values)))
            flow.front_reference(ax, own, flow.fluid_dicts(own)[name], ds, name)
        ax.set_xlabel("t [s]")
        ax.set_ylabel("front x_N [mm]")
        ax.set_title(name, fontsize=9)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    return fig


DRAW = {"errors": errors, "cost": cost, "fronts": fronts}


def write(flow, cfg: dict, ds: xr.Dataset, outdir, names, fmt: str = "png", dpi: int = 120) -> list[Path]:
    """Draw the figures ``names`` into outdir/<name>.<fmt>, each written atomically."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    paths = []
    for name in names:
        fig = DRAW[name](flow, cfg, ds)
        path = outdir / f"{name}.{fmt}"
        tmp = outdir / f".{name}.tmp.{fmt}"
        fig.savefig(tmp, dpi=dpi)
        plt.close(fig)
        tmp.replace(path)
        paths.append(path)
    return paths
