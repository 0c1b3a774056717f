"""The report's figures, the paper's Figs. 2-10 and then ours, from the campaign dataset alone
(matplotlib, colour-blind safe), and their registry ``FIGURES``."""
from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.ticker  # noqa: E402
import numpy as np  # noqa: E402
import xarray as xr  # noqa: E402

from .convergence import MAX_ORDER  # noqa: E402


# Okabe-Ito palette
COLOURS = ["#0072B2", "#E69F00", "#009E73", "#D55E00", "#CC79A7", "#56B4E9", "#F0E442", "#000000"]
MARKERS = ["o", "s", "^", "D", "v", "P", "X", "*"]
STYLE = {"figure.dpi": 100, "axes.grid": True, "grid.alpha": 0.3, "font.size": 10,
         "axes.spines.top": False, "axes.spines.right": False, "legend.frameon": False,
         "axes.formatter.useoffset": False}  # linear axes: each tick its own plain number


@dataclass(frozen=True)
class Settings:
    """What a figure takes beyond the campaign dataset."""
    profile_ch: float  # Ch of the single-Ch figures (nearest in the grid)
    theory: xr.Dataset  # the reference velocity profiles at the stations (study.reference)


@dataclass(frozen=True)
class FigureSpec:
    """One figure of the report: its file name, title, caption and drawing function.
    ``caption`` may name {ch} (the profile Ch); ``hollow`` appends the marker note; a
    ``yield_stress_only`` figure is drawn only by a campaign with a yield-stress case, a
    ``sweep_only`` one only by a campaign with a physical axis."""
    name: str
    title: str
    caption: str
    draw: Callable[[xr.Dataset, Settings], object]
    hollow: bool = False
    yield_stress_only: bool = False
    sweep_only: bool = False  # drawn only by a campaign with a physical axis

    def full_caption(self, profile_ch: float) -> str:
        return self.caption.format(ch=profile_ch) + (HOLLOW if self.hollow else "")

    def caption_rst(self, profile_ch: float) -> str:
        """The caption as reStructuredText, for Snakemake's report: the plain text with every
        character that reStructuredText reads as markup escaped (|u| would be a substitution)."""
        return f"**{rst_text(self.title)}.** {rst_text(self.full_caption(profile_ch))}\n"


def rst_text(text: str) -> str:
    """``text`` as literal reStructuredText: backslash before each inline-markup character."""
    return re.sub(r"([\\`*_|<>\[\]])", r"\\\1", text)


def _dp_mm(ds):
    return ds["dp"].values * 1000.0


def _log_axes(ax, any_data: bool, xlabel: str = "particle spacing dp [mm]", invert_x: bool = True,
              dp_ticks=None):
    """Log axes when something was drawn (dp axes run coarse to fine, left to right, ticked
    at the campaign's dp values), every tick label a plain number (the y axis, an error, in per
    cent); otherwise say there is nothing to draw."""
    from matplotlib.ticker import FixedLocator, FuncFormatter, NullFormatter
    if any_data:
        ax.set_xscale("log")
        ax.set_yscale("log")
        if invert_x:
            ax.invert_xaxis()
        ax.xaxis.set_major_formatter(FuncFormatter(_plain))
        ax.xaxis.set_minor_formatter(_PlainLogFormatter(_plain))
        if dp_ticks is not None:
            ax.xaxis.set_major_locator(FixedLocator(np.asarray(dp_ticks, dtype=float)))
            ax.xaxis.set_minor_formatter(NullFormatter())
        ax.yaxis.set_major_formatter(FuncFormatter(_percent_tick))
        ax.yaxis.set_minor_formatter(_PlainLogFormatter(_percent_tick))
    else:
        ax.text(0.5, 0.5, "no run gave this metric\n(diverged)", transform=ax.transAxes,
                ha="center", va="center", color="0.4")
    ax.set_xlabel(xlabel)


def _plain(v, _pos=None) -> str:
    """A tick label without exponent notation: 0.003, 0.02, 1, 30."""
    return f"{v:.4g}" if 1e-4 <= abs(v) < 1e5 else f"{v:.0e}"


def _percent_tick(v, _pos=None) -> str:
    """A tick label of an error (a fraction) in per cent: 0.005 -> '0.5 %', 0.02 -> '2 %'."""
    return f"{_plain(100.0 * v)} %"


class _PlainLogFormatter(matplotlib.ticker.LogFormatter):
    """The minor ticks of a log axis that matplotlib labels (on an axis spanning about a decade
    or less: some or all of 2-9 times a power of ten, which it writes 3x10^1), written by
    ``text`` instead: plain numbers."""
    def __init__(self, text):
        super().__init__(labelOnlyBase=False)
        self.text = text

    def __call__(self, x, pos=None):
        return self.text(x) if super().__call__(x, pos) else ""


def _legend(axes, steadiness: bool = True, **kw):
    """One entry per label, on the first of ``axes`` that has labelled artists; with
    ``steadiness``, filled against hollow markers explained once."""
    from matplotlib.lines import Line2D
    for ax in axes:
        handles, labels = ax.get_legend_handles_labels()
        if handles:
            seen = dict(zip(labels, handles))
            if steadiness:
                seen["steady window"] = Line2D([], [], ls="none", marker="o", color="0.35")
                seen["final window, not steady"] = Line2D([], [], ls="none", marker="o", mfc="none",
                                                          color="0.35")
            ax.legend(list(seen.values()), list(seen.keys()), **kw)
            return


def _points(ax, x, y, steady, k, label, band=None, se=None):
    """Filled markers: steady window; hollow: final window of a run that was not steady.
    One legend entry (``label``) per call; ``band``: a GCI error bar on the finest point;
    ``se``: each point's sampling standard error, drawn as a thin capless bar of +- 2 se."""
    ok = np.isfinite(y) & (y > 0)
    c, m = COLOURS[k % 8], MARKERS[k % 8]
    if ok.any() and se is not None:
        e = 2.0 * np.asarray(se, dtype=float)
        bar = ok & np.isfinite(e) & (e > 0)
        if bar.any():  # on the log axis a bar reaching zero is drawn down to 5 % of the value
            ax.errorbar(x[bar], y[bar], yerr=[np.minimum(e[bar], 0.95 * y[bar]), e[bar]], ls="none",
                        color=c, lw=0.8, capsize=0, alpha=0.7)
    if ok.any():
        ax.plot(x[ok], y[ok], color=c, lw=1, alpha=0.6)
        ax.plot([], [], color=c, lw=1, marker=m, label=label)  # the legend entry
        st = ok & (steady > 0)
        un = ok & ~(steady > 0)
        ax.plot(x[st], y[st], ls="none", marker=m, color=c)
        ax.plot(x[un], y[un], ls="none", marker=m, mfc="none", color=c)
        if band is not None and np.isfinite(band):
            i = np.argmin(np.where(ok, x, np.inf))
            ax.errorbar(x[i], y[i], yerr=[[min(band, 0.95 * y[i])], [band]], color=c, capsize=3, lw=1)
    return bool(ok.any())


def _gci_band(dp, y) -> float:
    """Absolute GCI band of the finest value of a metric sequence (NaN unless monotone)."""
    from .verdict import extrapolate
    return extrapolate(dp, y).band


def _sampling_error(ds, var, station=None):
    """``{var}_se`` of the (sub)dataset (at ``station``), or None where the campaign has none."""
    if f"{var}_se" not in ds:
        return None
    se = ds[f"{var}_se"]
    return se if station is None else se.sel(station=station)


def _error_vs_dp(ax, ds, var, shifting, label_ch=True, station=None):
    drawn = False
    se_all = _sampling_error(ds, var, station)
    for k, ch in enumerate(ds["ch"].values):
        y = ds[var].sel(ch=ch, shifting=shifting)
        if station is not None:
            y = y.sel(station=station)
        steady = ds["steady"].sel(ch=ch, shifting=shifting).values
        se = None if se_all is None else se_all.sel(ch=ch, shifting=shifting).values
        drawn |= _points(ax, _dp_mm(ds), y.values, steady, k, f"Ch = {ch:g}" if label_ch else None,
                         band=_gci_band(ds["dp"].values, y.values), se=se)
    _log_axes(ax, drawn, dp_ticks=_dp_mm(ds))


def _metric_figure(ds, var, ylabel):
    shs = list(ds["shifting"].values)
    fig, axs = plt.subplots(1, len(shs), figsize=(4.6 * len(shs), 3.6), squeeze=False, sharey=True)
    for ax, sh in zip(axs[0], shs):
        _error_vs_dp(ax, ds, var, sh)
        ax.set_title(f"shifting: {sh}")
    axs[0][0].set_ylabel(ylabel)
    _legend(axs[0], fontsize=8)
    fig.tight_layout()
    return fig


HOLLOW = (" Filled markers: metrics over a steady window; hollow markers: over the final window "
          "of a run that did not reach steady state (read them as indicative only). Error bars on "
          "the finest dp: the GCI band of that value (Celik et al. 2008), where the three finest "
          f"dp converge monotonically at an observed order of at most {MAX_ORDER:g}; on the log "
          "axis a band that reaches zero is drawn down to 5 % of the value. Thin bars without "
          "caps: +- 2 standard errors of each run's sampling error over its averaging window, the "
          "same error the verdicts use.")


def fig_velocity_profiles(ds, ch, ref):
    ch = float(ds["ch"].sel(ch=ch, method="nearest"))
    st = ds["station"].values
    shs = list(ds["shifting"].values)
    fig, axs = plt.subplots(len(shs), st.size, figsize=(3.4 * st.size, 3.3 * len(shs)), squeeze=False, sharex=True)
    for i, sh in enumerate(shs):
        for j, s in enumerate(st):
            ax = axs[i][j]
            ax.plot(ref["velocity"].sel(station=s), ref["z_star"], color="k", lw=2, label="theory")
            for k, dp in enumerate(ds["dp"].values):
                u = ds["mean_velocity"].sel(dp=dp, ch=ch, shifting=sh, station=s)
                ax.plot(u, ds["z_star"], color=COLOURS[k % 8], marker=MARKERS[k % 8], ms=3,
                        lw=1, label=f"dp = {dp * 1000:g} mm")
            ax.set_title(f"x* = {s:g}, {sh}")
            ax.set_xlabel("u* = (u + u_b) / u_b")
            ax.tick_params(labelbottom=True)  # every labelled axis numbered, shared or not
            if j == 0:
                ax.set_ylabel("z* = z / h_n")
    axs[0][-1].legend(fontsize=8)
    fig.tight_layout()
    return fig


def _front_panels(ds, ch, draw):
    """One panel per shifting method of the final particles within 3 h_n of the toe at the
    finest dp and the Ch nearest ``ch``; ``draw(ax, sh, x, z)`` fills each panel."""
    ch = float(ds["ch"].sel(ch=ch, method="nearest"))
    dp = ds["dp"].values[-1]
    shs = list(ds["shifting"].values)
    fig, axs = plt.subplots(len(shs), 1, figsize=(8, 2.4 * len(shs)), squeeze=False, sharex=True)
    for ax, sh in zip(axs[:, 0], shs):
        sel = dict(dp=dp, ch=ch, shifting=sh)
        draw(ax, sel, ds["front_x"].sel(**sel).values, ds["front_z"].sel(**sel).values)
        ax.set_title(f"{sh}, dp = {dp * 1000:g} mm, Ch = {ch:g}")
        ax.set_ylabel("z / h_n")
    axs[0, 0].invert_xaxis()  # once: the panels share x; the toe on the right, as the flow runs
    axs[-1, 0].set_xlabel("x* upslope from the toe")
    fig.tight_layout()
    return fig


def fig_front_particles(ds, ch):
    """The final particles at the front coloured by their lab-frame speed |u| / u_b (one
    colour where the campaign dataset has no speeds)."""
    speed = ds["front_speed"] if "front_speed" in ds else ds["front_x"] * np.nan
    coloured = bool(np.isfinite(speed.values).any())
    vmax = float(np.nanmax(speed.values)) if coloured else 1.0
    artists = []

    def draw(ax, sel, x, z):
        v = speed.sel(**sel).values
        ok = np.isfinite(x) & (np.isfinite(v) if coloured else True)
        if coloured:
            artists.append(ax.scatter(x[ok], z[ok], s=4, c=v[ok], cmap="viridis", vmin=0.0, vmax=vmax))
        else:
            ax.scatter(x[ok], z[ok], s=4, color=COLOURS[0])
        ax.set_aspect("equal")
    fig = _front_panels(ds, ch, draw)
    if artists:
        fig.colorbar(artists[0], ax=fig.axes, label="|u| / u_b (lab frame)", shrink=0.8)
    return fig


def fig_plug_map(ds, ch):
    """Yielded (vermillion) and unyielded (blue) fluid at the front, finest dp."""
    def draw(ax, sel, x, z):
        y = ds["front_yielded"].sel(**sel).values if "front_yielded" in ds else x * np.nan
        ok = np.isfinite(x) & np.isfinite(y)
        if ok.any():
            ax.scatter(x[ok & (y > 0.5)], z[ok & (y > 0.5)], s=4, color=COLOURS[3], label="yielded")
            ax.scatter(x[ok & (y < 0.5)], z[ok & (y < 0.5)], s=4, color=COLOURS[0], label="unyielded (plug)")
            ax.legend(fontsize=7, loc="upper right")  # above the toe, where there is no fluid
            ax.set_aspect("equal")
        else:
            ax.text(0.5, 0.5, "no yield stress in this run (or no final state)",
                    transform=ax.transAxes, ha="center", va="center", color="0.4")
    return _front_panels(ds, ch, draw)


def fig_shifting_comparison(ds, var, ch, station_panels=False):
    ch = float(ds["ch"].sel(ch=ch, method="nearest"))
    sub = ds.sel(ch=ch)
    panels = list(ds["station"].values) if station_panels else [None]
    fig, axs = plt.subplots(1, len(panels), figsize=(4.2 * len(panels), 3.5), squeeze=False)
    for ax, s in zip(axs[0], panels):
        drawn = False
        se_all = _sampling_error(sub, var, s)
        for k, sh in enumerate(sub["shifting"].values):
            y = sub[var].sel(shifting=sh)
            if s is not None:
                y = y.sel(station=s)
            se = None if se_all is None else se_all.sel(shifting=sh).values
            drawn |= _points(ax, _dp_mm(sub), y.values, sub["steady"].sel(shifting=sh).values, k, sh,
                             band=_gci_band(sub["dp"].values, y.values), se=se)
        _log_axes(ax, drawn, dp_ticks=_dp_mm(sub))
        ax.set_ylabel(var)
        if s is not None:
            ax.set_title(f"x* = {s:g}")
    _legend(axs[0][::-1], fontsize=8)
    fig.tight_layout()
    return fig


COST_METRICS = (("zeta_f", None), ("zeta_h", None), ("zeta_fs", None), ("zeta_u", 9.7))


def _flat(ds, var, station=None):
    """(values, labels) of a (dp, ch, shifting) variable over every grid case."""
    da = ds[var] if station is None else ds[var].sel(station=station, method="nearest")
    vals, labels = [], []
    for dp in ds["dp"].values:
        for ch in ds["ch"].values:
            for sh in ds["shifting"].values:
                vals.append(float(da.sel(dp=dp, ch=ch, shifting=sh)))
                labels.append(f"{dp * 1000:g} mm, Ch {ch:g}, {sh}")
    return np.array(vals), labels


def fig_cost_vs_error(ds):
    from .pareto import pareto_front
    cost, labels = _flat(ds, "wall_time")
    fig, axs = plt.subplots(1, len(COST_METRICS), figsize=(4.2 * len(COST_METRICS), 3.8), squeeze=False)
    shs = list(ds["shifting"].values)
    for ax, (var, st) in zip(axs[0], COST_METRICS):
        err, _ = _flat(ds, var, st)
        ok = np.isfinite(err) & (err > 0) & np.isfinite(cost)
        for k, sh in enumerate(shs):
            m = ok & np.array([lab.endswith(sh) for lab in labels])
            ax.plot(cost[m], err[m], ls="none", marker=MARKERS[k], color=COLOURS[k], label=sh, alpha=0.8)
        front = pareto_front(np.where(ok, cost, np.nan), np.where(ok, err, np.nan))
        order = np.argsort(cost[front])
        ax.plot(cost[front][order], err[front][order], color="k", lw=1, drawstyle="steps-post",
                label="Pareto front")
        for i in np.where(front)[0]:
            ax.annotate(labels[i], (cost[i], err[i]), fontsize=6, xytext=(3, 3), textcoords="offset points")
        _log_axes(ax, bool(ok.any()), xlabel="wall time [s]", invert_x=False)
        ax.set_ylabel(var if st is None else f"{var} (x* = {st:g})")
    axs[0][0].legend(fontsize=8)
    fig.tight_layout()
    return fig


def fig_stability_map(ds):
    """One row per case: each guarded margin as a fraction of its guard, the peak kinetic
    energy, and, for a diverged run, the detector that fired and when."""
    from matplotlib.colors import ListedColormap
    from .stability import MARGINS
    cases = [str(c) for c in ds["case"].values]
    n = len(cases)
    if "case_density_margin" in ds:
        vals = np.stack([ds[f"case_{k}"].values for k in MARGINS], axis=1)
    else:
        vals = np.full((n, 3), np.nan)
    fig, ax = plt.subplots(figsize=(9.5, 0.9 + 0.28 * n))
    cmap = ListedColormap(["#009E73", "#F0E442", "#E69F00", "#D55E00"])  # <0.25, <0.5, <1, >=1
    level = np.digitize(np.nan_to_num(vals, nan=-1.0), [0.25, 0.5, 1.0]).astype(float)
    level[~np.isfinite(vals)] = np.nan
    ax.imshow(level, cmap=cmap, vmin=-0.5, vmax=3.5, aspect="auto", interpolation="nearest")
    for i in range(n):
        for j in range(vals.shape[1]):
            ax.text(j, i, "-" if not np.isfinite(vals[i, j]) else f"{vals[i, j]:.2f}", ha="center",
                    va="center", fontsize=7)
        status = str(ds["case_status"].values[i]) if "case_status" in ds else ""
        det = str(ds["case_detector"].values[i]) if "case_detector" in ds else ""
        e = float(ds["case_energy_ratio"].values[i]) if "case_energy_ratio" in ds else np.nan
        t = float(ds["case_end_time"].values[i]) if "case_end_time" in ds else np.nan
        note = f"{e:.2g}" if np.isfinite(e) else "-"
        note += f"   DIVERGED: {det}, t = {t:.2f} s" if status == "diverged" else f"   {status}, to {t:.2f} s"
        ax.text(len(MARGINS) - 0.4, i, note, va="center", fontsize=7,
                color=COLOURS[3] if status == "diverged" else "0.2")
    ax.set_yticks(range(n), cases, fontsize=7)
    ax.set_xticks(range(len(MARGINS)) , ["density\ndeviation", "wall\npenetration", "area\ndrift"], fontsize=8)
    ax.set_xlim(-0.5, len(MARGINS) + 2.6)
    ax.text(len(MARGINS) - 0.4, -0.9, "peak KE / (0.5 M u_b^2), outcome", fontsize=8)
    ax.grid(False)
    for sp in ax.spines.values():
        sp.set_visible(False)
    fig.tight_layout()
    return fig


def fig_zeta_u(ds):
    st = ds["station"].values
    shs = list(ds["shifting"].values)
    fig, axs = plt.subplots(len(shs), st.size, figsize=(3.6 * st.size, 3.2 * len(shs)),
                            squeeze=False, sharey=True)
    for i, sh in enumerate(shs):
        for j, s in enumerate(st):
            _error_vs_dp(axs[i][j], ds, "zeta_u", sh, station=s)
            axs[i][j].set_title(f"x* = {s:g}, {sh}")
        axs[i][0].set_ylabel("zeta_u")
    _legend(axs.ravel(), fontsize=8)
    fig.tight_layout()
    return fig


SWEEP_METRICS = ("zeta_f", "zeta_h", "zeta_fs", "zeta_u")


def fig_sweep(ds):
    """Each metric against dp from the flat case table, one line per value of the physical axes
    (``case_axis_*``), shifting method and Ch."""
    axes = [a for a in str(ds.attrs.get("axes", "")).split(",") if a]
    on = (ds["case_on_grid"].values > 0) & (ds["case_realisation"].values == 0)
    fig, panels = plt.subplots(1, len(SWEEP_METRICS), figsize=(4.0 * len(SWEEP_METRICS), 3.8), squeeze=False)
    groups: dict = {}
    for i in np.flatnonzero(on):
        key = tuple(ds[f"case_axis_{a}"].values[i].item() for a in axes) + (str(ds["case_shifting"].values[i]),
                                                                       float(ds["case_ch"].values[i]))
        groups.setdefault(key, []).append(i)
    for ax, var in zip(panels[0], SWEEP_METRICS):
        drawn = False
        for k, (key, idx) in enumerate(groups.items()):
            idx = sorted(idx, key=lambda i: -float(ds["case_dp"].values[i]))
            y = ds[f"case_{var}"].values[idx]
            se = ds[f"case_{var}_se"].values[idx] if f"case_{var}_se" in ds else None
            if y.ndim == 2:  # zeta_u: the mean over the stations, its se combined
                y = np.nanmean(y, axis=1)
                se = None if se is None else np.sqrt(np.nansum(se ** 2, axis=1)) / se.shape[1]
            ok = np.isfinite(y)
            if not ok.any():
                continue
            label = ", ".join([f"{a} {_plain(v) if isinstance(v, float) else v}" for a, v in zip(axes, key[:-2])]
                              + [f"{key[-2]} Ch {key[-1]:g}"])
            ax.errorbar(1000 * ds["case_dp"].values[idx][ok], np.abs(y[ok]),
                        yerr=None if se is None else 2 * se[ok], marker=MARKERS[k % len(MARKERS)],
                        color=COLOURS[k % len(COLOURS)], capsize=3, label=label)
            drawn = True
        _log_axes(ax, drawn, dp_ticks=sorted({1000 * float(d) for d in ds["case_dp"].values[on]}))
        ax.set_ylabel(var)
        if drawn:
            ax.legend(fontsize=7)
    fig.tight_layout()
    return fig


# The report's figures, in the paper's order and then ours: the rules, the captions of
# Snakemake's report and the HTML report all read this list.
FIGURES = (
    FigureSpec("fig02_zeta_f", "Fig. 2 - front velocity error",
               "Front velocity error zeta_f = |u*_f - u*_b| / u*_b against dp for each Ch (one "
               "panel per shifting method). The paper found zeta_f below a few per cent, "
               "decreasing with dp, with the smallest Ch the least accurate.",
               lambda ds, st: _metric_figure(ds, "zeta_f", "zeta_f"), hollow=True),
    FigureSpec("fig03_zeta_h", "Fig. 3 - uniform depth error",
               "Uniform-zone depth error zeta_h (against the computed h_n) against dp for each "
               "Ch. The paper reported depth errors of a few per cent against its normalising "
               "depth; the campaign table gives both.",
               lambda ds, st: _metric_figure(ds, "zeta_h", "zeta_h"), hollow=True),
    FigureSpec("fig04_zeta_fs", "Fig. 4 - free-surface error",
               "RMS free-surface error zeta_fs (normalised depths) against dp for each Ch, against "
               "lubrication theory. The paper found it small and converging.",
               lambda ds, st: _metric_figure(ds, "zeta_fs", "zeta_fs"), hollow=True),
    FigureSpec("fig05_velocity_profiles", "Fig. 5 - velocity profiles",
               "Steady velocity profiles u*(z*) in the belt frame at the three stations for "
               "Ch = {ch:g} (or the grid's nearest) and every dp, against lubrication theory "
               "(black). The paper found the profiles well reproduced away from the toe, with "
               "the largest deviations at x* = 0.76 where the theory itself is approximate.",
               lambda ds, st: fig_velocity_profiles(ds, st.profile_ch, st.theory)),
    FigureSpec("fig06_zeta_u", "Fig. 6 - velocity-profile errors",
               "RMS velocity-profile error zeta_u,j at each station against dp for each Ch. The "
               "paper found the errors largest near the toe (x* = 0.76) and smallest in the "
               "uniform zone (x* = 9.7).",
               lambda ds, st: fig_zeta_u(ds), hollow=True),
    FigureSpec("fig07_front_particles", "Fig. 7 - particles at the front",
               "Final fluid particle distribution within 3 h_n of the toe for each shifting "
               "method at the finest dp and Ch = {ch:g} (or the grid's nearest), coloured by the "
               "particle speed in the lab frame, |u| / u_b (the belt moves at 1). The paper found "
               "the Lind shifting smoother and less ordered near the free surface than the "
               "Skillen (DualSPHysics release) shifting.",
               lambda ds, st: fig_front_particles(ds, st.profile_ch)),
    FigureSpec("fig08_shifting_zeta_u", "Fig. 8 - shifting: velocity errors",
               "zeta_u,j for the two shifting methods at Ch = {ch:g}. The paper found the "
               "shifting method marginally affects the velocity-profile error.",
               lambda ds, st: fig_shifting_comparison(ds, "zeta_u", st.profile_ch, station_panels=True),
               hollow=True),
    FigureSpec("fig09_shifting_zeta_f", "Fig. 9 - shifting: front velocity",
               "zeta_f for the two shifting methods at Ch = {ch:g}. The paper found the Lind "
               "shifting better for the front velocity.",
               lambda ds, st: fig_shifting_comparison(ds, "zeta_f", st.profile_ch), hollow=True),
    FigureSpec("fig10_shifting_zeta_h", "Fig. 10 - shifting: uniform depth",
               "zeta_h for the two shifting methods at Ch = {ch:g}. The paper found the Lind "
               "shifting better for the uniform depth.",
               lambda ds, st: fig_shifting_comparison(ds, "zeta_h", st.profile_ch), hollow=True),
    FigureSpec("fig11_cost_vs_error", "Run time against error",
               "Wall time of each case against each error metric (log-log), with the Pareto "
               "front (no case is both cheaper and more accurate) labelled by dp, Ch and "
               "shifting (steady and not-steady runs alike; the Accuracy and cost table counts steady runs "
               "only). Not in the paper: it answers which run is the cheapest one to trust.",
               lambda ds, st: fig_cost_vs_error(ds)),
    FigureSpec("fig12_stability_map", "Stability map",
               "Each case (row): the largest value reached by each guarded quantity as a "
               "fraction of its guard (green < 0.25, yellow < 0.5, orange < 1, vermillion: the "
               "guard fired), the peak kinetic energy in units of 0.5 M u_b^2 (about 1 for the "
               "belt flow), and the outcome: the detector that stopped a diverged run and when. "
               "Not in the paper: it shows where explicit SPH breaks on this flow and how close "
               "the survivors came.",
               lambda ds, st: fig_stability_map(ds)),
    FigureSpec("fig13_plug_map", "Where the plug is",
               "For a Herschel-Bulkley fluid: the final fluid particles within 3 h_n of the toe "
               "at the finest dp and Ch = {ch:g}, yielded (viscosity below the cap max_viscosity) "
               "or unyielded (at the cap: the plug). Not in the paper; drawn only for a campaign "
               "with a Herschel-Bulkley case.",
               lambda ds, st: fig_plug_map(ds, st.profile_ch), yield_stress_only=True),
    FigureSpec("fig14_sweep", "Errors against dp for each value of the physical axes",
               "zeta_f, zeta_h, zeta_fs and zeta_u (the mean over the stations) of every grid run "
               "(realisation 0) against dp, one line for each value of the campaign's physical axes, "
               "shifting method and Ch, each run against the theory of its own physical case; bars: "
               "2 se. Not in the paper: it shows where the scheme holds as the physics changes. The "
               "verdict and Figs. 2-11 and 13 take the axes' first values.",
               lambda ds, st: fig_sweep(ds), sweep_only=True),
)
FIGURE_NAMES = tuple(f.name for f in FIGURES)


def figures_for(yield_stress: bool, sweep: bool = False) -> tuple[FigureSpec, ...]:
    """The registered figures that a campaign draws, with or without a yield-stress case and a
    physical axis: the rules' outputs, Snakemake's report and the HTML report take these."""
    return tuple(spec for spec in FIGURES if (yield_stress or not spec.yield_stress_only)
                 and (sweep or not spec.sweep_only))


def write_all(ds: xr.Dataset, outdir, settings: Settings, fmt: str = "png", dpi: int = 120,
              specs=FIGURES) -> list[Path]:
    """Draw the figures ``specs`` (default: every registered one) into outdir/<name>.<fmt>
    (each written atomically)."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    paths = []
    for spec in specs:
        with plt.rc_context(STYLE):
            fig = spec.draw(ds, settings)
        p = outdir / f"{spec.name}.{fmt}"
        tmp = p.with_suffix(p.suffix + ".tmp")
        fig.savefig(tmp, dpi=dpi, format=fmt)
        plt.close(fig)
        tmp.replace(p)
        paths.append(p)
    return paths
