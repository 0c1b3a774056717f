"""The report of a flow campaign (slump, film, user): the answer first, then accuracy and cost,
convergence, stability, the figures, the configuration and provenance. The paper's verdicts
are the conveyor's and are not judged here."""
from __future__ import annotations

import html
import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import xarray as xr  # noqa: E402

from . import flowcampaign as fc  # noqa: E402
from .flowconfig import read_references, reference_runout  # noqa: E402
from .numbers import percent  # noqa: E402
from .report import _commit, _with_error, figure_html, page  # noqa: E402

FLOW_TITLES = {"slump": "a viscous gravity current from a rectangular release (slump)",
               "film": "the start-up from rest of a film on an incline",
               "user": "a user's scene against the user's reference data"}


def _series_label(seq) -> str:
    parts = [seq["fluid"]] if seq["fluid"] else []
    return " ".join(parts + [seq["scheme"], seq["shifting"], f"Ch {seq['ch']:g}"])


def _seconds(v) -> str:
    """A wall time: whole seconds from 10 s, two significant digits below."""
    v = float(v)
    return f"{v:.0f}" if v >= 10 else f"{v:.2g}"


def _mm(dp) -> str:
    return f"{1000 * float(dp):.4g} mm"


def reference_text(cfg: dict, ds: xr.Dataset) -> str:
    """What each run is compared with, and from when (the memory criterion of the slump)."""
    flow, s = cfg["flow"], cfg["scene"]
    if flow == "slump":
        lines = [f"<p>Release: height H0 = {1000 * s['height']:.3g} mm, length L0 = {1000 * s['length']:.3g} mm "
                 "from the symmetry plane (a two-sided release of length 2 L0 on a no-slip bed; both fronts "
                 "are measured and averaged, so the plane is the free-slip end wall of the half). The front "
                 "x_N is the outermost fluid particle plus dp / 2.</p><ul>"]
        for name, fl in (cfg.get("fluids") or {}).items():
            if fc.newtonian(fl):
                f = cfg["metrics"]["memory_fraction"]
                mine = ds["fluid"].values == name
                t_c = float(np.nanmax(ds["compare_from"].values[mine])) if "compare_from" in ds else math.nan
                lines.append(
                    f"<li><b>{html.escape(name)}</b> (nu = {fl['viscosity'] / fl['density']:.4g} m2/s): "
                    "Huppert's similarity solution (J. Fluid Mech. 121, 1982), x_N = 1.411 (g A^3 t / (3 nu))^(1/5) "
                    "and its depth profile. The release's memory has faded, and the runs are compared, from "
                    f"t_c = {t_c:.3g} s: the time past which lubrication theory started from the rectangle has "
                    f"its front's local exponent within {100 * f:.3g} % of 1/5 (and its front within "
                    f"{100 * ((1 - f) ** -0.2 - 1):.2g} % of the similarity front). Front error: RMS of "
                    "x_N / x_ref - 1 over the snapshots from t_c; exponent: the least-squares slope of ln x_N "
                    "against ln t over the same snapshots; depth profile: the last snapshot, RMS over x &le; 0.95 x_N "
                    "over the reference's depth at the plane.</li>")
            else:
                ratio = reference_runout(cfg, fl) / s["height"]
                lines.append(
                    f"<li><b>{html.escape(name)}</b> (tau_y = {fl['yield_stress']:.4g} Pa): the arrested shape "
                    "of the lubrication limit, h^2 = 2 tau_y (x_N - x) / (rho g), and its runout "
                    f"x_N = {1000 * reference_runout(cfg, fl):.4g} mm ({ratio:.2f} H0 from the plane). "
                    f"The front has stopped once its speed, fitted over {cfg['metrics']['stop_window']:g} s, "
                    f"stays below {1000 * cfg['metrics']['stop_speed']:.3g} mm/s (the regularised fluid "
                    "creeps at about tau_y h / mu_max); the runout is the front then.</li>")
        return "".join(lines) + "</ul>"
    if flow == "film":
        nus = ", ".join(f"{html.escape(n)} nu = {f['viscosity'] / f['density']:.4g} m2/s"
                        for n, f in cfg["fluids"].items())
        return (f"<p>Film depth {1000 * s['depth']:.4g} mm on a plane inclined at {s['angle']:g} deg ({nus}), "
                "at rest at t = 0, periodic along the plane. "
                "Reference: the exact start-up series of u_t = nu u_zz + g sin(theta) with no slip at the bed "
                "and no stress at the surface. Error: at every snapshot after t = 0 the RMS over the fluid "
                "particles of (u - u_exact) / u_max; the largest over the snapshots is reported.</p>")
    refs = ", ".join(f"{k}: {html.escape(str(v))}" for k, v in s["reference"].items())
    return (f"<p>Scene {html.escape(s['file'])}; reference files {refs} (docs/flow-user.md gives their format). "
            f"Front error: RMS of x_N / x_ref - 1 over the reference times from {s['front_from']:g} s; a depth "
            "profile at its time, a velocity profile at its station at the run's last snapshot, each as the "
            "RMS of the difference over the reference's largest value; a kind's error is the RMS over its "
            "profiles.</p>")


def answer(cfg: dict, ds: xr.Dataset) -> str:
    """One plain sentence per (fluid): the finest run of each scheme and the cheapest
    trustworthy run."""
    tol = cfg["metrics"]["tolerance"]
    out = []
    for fname, fl in fc.fluid_dicts(cfg).items():
        errs = fc.errors_of(cfg, fl or None)
        head = errs[0]
        idx = [i for i in range(ds.sizes["case"]) if str(ds["fluid"].values[i]) == fname]
        if not idx:
            continue
        parts = []
        for scheme in dict.fromkeys(str(ds["scheme"].values[i]) for i in idx):
            sub = [i for i in idx if str(ds["scheme"].values[i]) == scheme]
            fine = min(sub, key=lambda i: float(ds["dp"].values[i]))
            if str(ds["status"].values[fine]) == "diverged":
                parts.append(f"{scheme} diverged at dp = {_mm(ds['dp'].values[fine])}")
                continue
            se = float(ds[f"{head}_se"].values[fine]) if f"{head}_se" in ds else math.nan
            txt = (f"{scheme}'s {fc.LABELS[head]} error at dp = {_mm(ds['dp'].values[fine])} is "
                   f"{_with_error(ds[head].values[fine], se)}")
            if head == "front_error" and "exponent" in ds and np.isfinite(ds["exponent"].values[fine]):
                last = float(ds["front_final_error"].values[fine])
                b, b_se = ds["exponent"].values[fine], ds["exponent_se"].values[fine]
                txt += (f" (at the end {'ahead of' if last > 0 else 'behind'} the reference by {percent(abs(last))}; "
                        f"exponent {b:.4f} &plusmn; {2 * b_se:.2g})")
            if head == "runout_error":
                txt += " (stopped)" if ds["stopped"].values[fine] > 0 else " (not stopped by the end)"
            parts.append(txt)
        best = fc.cheapest(ds, idx, errs, tol)
        if best is None:
            cheap = f"no run has every error below {percent(tol)} by more than 2 se"
        else:
            cheap = (f"the cheapest run with every error below {percent(tol)} is "
                     f"{html.escape(str(ds['case'].values[best]))} "
                     f"({_seconds(ds['wall_time_s'].values[best])} s)")
        who = f"<b>{html.escape(fname)}</b>: " if fname else ""
        out.append(f"<li>{who}{'; '.join(parts)}; {cheap}.</li>")
    return "<ul>" + "".join(out) + "</ul>"


def case_table(cfg: dict, ds: xr.Dataset) -> str:
    errs_all = fc.all_errors(cfg)
    head = ("<tr><th>dp</th><th class='l'>fluid</th><th class='l'>scheme</th>"
            "<th class='l'>shifting</th><th>Ch</th>"
            + "".join(f"<th>{html.escape(fc.LABELS[e])}</th>" for e in errs_all)
            + "<th>status</th><th>wall time [s]</th><th>steps</th><th>particles</th></tr>")
    rows = []
    for i in range(ds.sizes["case"]):
        status = str(ds["status"].values[i])
        cells = [f"<td title='{html.escape(str(ds['case'].values[i]))}'>{_mm(ds['dp'].values[i])}</td>",
                 f"<td class='l'>{html.escape(str(ds['fluid'].values[i]))}</td>",
                 f"<td class='l'>{html.escape(str(ds['scheme'].values[i]))}</td>",
                 f"<td class='l'>{html.escape(str(ds['shifting'].values[i]))}</td>", f"<td>{ds['ch'].values[i]:g}</td>"]
        for e in errs_all:
            v = ds[e].values[i] if e in ds else math.nan
            se = ds[f"{e}_se"].values[i] if f"{e}_se" in ds else math.nan
            cells.append(f"<td>{_with_error(v, se)}</td>")
        note = status
        if "stopped" in ds and np.isfinite(ds["stopped"].values[i]):
            note += ", stopped" if ds["stopped"].values[i] > 0 else ", still moving"
        if ds["reason"].values[i]:
            note += f": {html.escape(str(ds['reason'].values[i]))}"
        cells += [f"<td class='l'>{note}</td>", f"<td>{_seconds(ds['wall_time_s'].values[i])}</td>",
                  f"<td>{int(ds['steps'].values[i])}</td>", f"<td>{int(ds['n_particles'].values[i])}</td>"]
        cls = " class='diverged'" if status == "diverged" else ""
        rows.append(f"<tr{cls}>{''.join(cells)}</tr>")
    return f"<table style='white-space:nowrap'>{head}{''.join(rows)}</table>"


def convergence_table(cfg: dict, ds: xr.Dataset) -> str:
    rows = []
    fluids = fc.fluid_dicts(cfg)
    for seq in fc.sequences(ds):
        fl = fluids.get(seq["fluid"]) or None
        for e in fc.errors_of(cfg, fl):
            idx = seq["cases"]
            vals = [percent(ds[e].values[i]) for i in idx]
            g = fc.convergence(ds, e, idx)
            reliable = g.status == "monotone" and 0.5 <= g.order <= 4
            order = (f"{g.order:.2g}" + ("" if reliable else " (unreliable)")) if g.status == "monotone" else "&ndash;"
            limit = percent(g.extrapolated) if reliable else "&ndash;"
            rows.append(f"<tr><td class='l'>{html.escape(_series_label(seq))}</td><td class='l'>{fc.LABELS[e]}</td>"
                        f"<td class='l'>{', '.join(_mm(ds['dp'].values[i]) for i in idx)}</td>"
                        f"<td class='l'>{', '.join(vals)}</td><td class='l'>{fc.falls_with_dp(ds[e].values[idx])}</td>"
                        f"<td class='l'>{g.status}</td><td>{order}</td><td>{limit}</td></tr>")
    for seq in fc.sequences(ds):
        fl = fluids.get(seq["fluid"]) or None
        for q in fc.QUANTITIES.get((cfg["flow"], fl is None or fc.newtonian(fl)), ()):
            idx = seq["cases"]
            g = fc.convergence(ds, q, idx)
            reliable = g.status == "monotone" and 0.5 <= g.order <= 4
            rows.append(f"<tr><td class='l'>{html.escape(_series_label(seq))}</td><td class='l'>{fc.LABELS[q]}</td>"
                        f"<td class='l'>{', '.join(_mm(ds['dp'].values[i]) for i in idx)}</td>"
                        f"<td class='l'>{', '.join(f'{1000 * ds[q].values[i]:.4g} mm' for i in idx)}</td>"
                        f"<td class='l'>&ndash;</td><td class='l'>{g.status}</td>"
                        f"<td>{f'{g.order:.2g}' if g.status == 'monotone' else '&ndash;'}"
                        f"{'' if reliable or g.status != 'monotone' else ' (unreliable)'}</td>"
                        f"<td>{f'{1000 * g.extrapolated:.4g} mm, GCI {percent(g.gci_fine)}' if reliable else '&ndash;'}"
                        "</td></tr>")
    return ("<p>Each error's magnitude over falling dp; from the three finest dp, where they converge "
            "monotonically, the observed order and the error Richardson-extrapolated to dp &rarr; 0 (Celik et al. "
            "2008): near 0 where the runs converge to the reference, away from it where the scheme's limit differs "
            "from the reference (or the reference from the flow). For the measured front and runout: their "
            "extrapolated value and the fine grid's GCI. An order above 4 or below 0.5 is flagged "
            "unreliable and nothing is extrapolated from it.</p><table><tr><th class='l'>sequence</th>"
            "<th class='l'>error</th><th class='l'>dp</th><th class='l'>values</th><th class='l'>with dp</th>"
            "<th class='l'>convergence</th><th>order</th><th>error at dp &rarr; 0</th></tr>"
            + "".join(rows) + "</table>")


def stability_text(ds: xr.Dataset) -> str:
    """The stability map: each sequence's status at each dp (diverged cells with their reason)."""
    dps = sorted({float(d) for d in ds["dp"].values}, reverse=True)
    head = "<tr><th class='l'>sequence</th>" + "".join(f"<th>{_mm(d)}</th>" for d in dps) + "</tr>"
    rows = []
    for seq in fc.sequences(ds):
        by_dp = {float(ds["dp"].values[i]): i for i in seq["cases"]}
        cells = []
        for d in dps:
            i = by_dp.get(d)
            if i is None:
                cells.append("<td></td>")
                continue
            status = str(ds["status"].values[i])
            reason = f": {html.escape(str(ds['reason'].values[i]))}" if ds["reason"].values[i] else ""
            cells.append(f"<td class='{'ok' if status == 'completed' else 'bad'}'>{html.escape(status)}{reason}</td>")
        rows.append(f"<tr><td class='l'>{html.escape(_series_label(seq))}</td>{''.join(cells)}</tr>")
    n_bad = sum(str(s) != "completed" for s in ds["status"].values)
    lead = (f"<p>All {ds.sizes['case']} runs completed: none diverged.</p>" if not n_bad else
            f"<p>{n_bad} of {ds.sizes['case']} runs did not complete; they have no errors.</p>")
    return lead + f"<table>{head}{''.join(rows)}</table>"


# ---- figures ---------------------------------------------------------------

def _plain_log(ax):
    """Log axes whose every tick label is a plain number (study.figures' rule)."""
    from .figures import _PlainLogFormatter, _plain
    ax.set_xscale("log")
    ax.set_yscale("log")
    for a in (ax.xaxis, ax.yaxis):
        a.set_major_formatter(matplotlib.ticker.FuncFormatter(_plain))
        a.set_minor_formatter(_PlainLogFormatter(_plain))


def fig_errors(cfg: dict, ds: xr.Dataset):
    errs = fc.all_errors(cfg)
    from .figures import _log_axes
    fig, axes = plt.subplots(1, len(errs), figsize=(4.2 * len(errs), 3.6), squeeze=False)
    for ax, e in zip(axes[0], errs):
        drawn = False
        for seq in fc.sequences(ds):
            idx = [i for i in seq["cases"] if np.isfinite(ds[e].values[i])]
            if not idx:
                continue
            se = 2 * ds[f"{e}_se"].values[idx] if f"{e}_se" in ds else None
            ax.errorbar(1000 * ds["dp"].values[idx], np.abs(ds[e].values[idx]), yerr=se, marker="o", capsize=3,
                        label=_series_label(seq))
            drawn = True
        _log_axes(ax, drawn, dp_ticks=sorted({1000 * float(d) for d in ds["dp"].values}))
        ax.set_ylabel(f"|{fc.LABELS[e]} error|")
        ax.axhline(cfg["metrics"]["tolerance"], color="0.6", ls=":", lw=1)
        ax.grid(True, which="both", alpha=0.3)
        if drawn:
            ax.legend(fontsize=7)
    fig.tight_layout()
    return fig


def fig_cost(cfg: dict, ds: xr.Dataset):
    from .figures import _log_axes
    fig, ax = plt.subplots(figsize=(5.5, 4))
    fluids = fc.fluid_dicts(cfg)
    drawn = False
    for seq in fc.sequences(ds):
        head = fc.errors_of(cfg, fluids.get(seq["fluid"]) or None)[0]
        idx = [i for i in seq["cases"] if np.isfinite(ds[head].values[i])]
        if idx:
            ax.plot(ds["wall_time_s"].values[idx], np.abs(ds[head].values[idx]), marker="o",
                    label=f"{_series_label(seq)} ({fc.LABELS[head]})")
            drawn = True
    _log_axes(ax, drawn, xlabel="run wall time [s]", invert_x=False)
    ax.set_ylabel("|headline error|")
    ax.axhline(cfg["metrics"]["tolerance"], color="0.6", ls=":", lw=1)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    return fig


def fig_fronts(cfg: dict, ds: xr.Dataset):
    """x_N(t) of every run against the reference (the similarity front, or the runout)."""
    from .flows import slump
    fluids = fc.fluid_dicts(cfg)
    names = [n for n in fluids if any(str(f) == n for f in ds["fluid"].values)]
    fig, axes = plt.subplots(1, len(names), figsize=(5.2 * len(names), 4), squeeze=False)
    s = cfg["scene"]
    for ax, name in zip(axes[0], names):
        fl = fluids[name]
        for i in range(ds.sizes["case"]):
            if str(ds["fluid"].values[i]) != name:
                continue
            x = ds["x_front"].isel(case=i).dropna("front_time")
            ax.plot(x["front_time"], 1000 * x, lw=1, label=f"{ds['scheme'].values[i]} dp {_mm(ds['dp'].values[i])}")
        t = ds["front_time"].values
        t = t[t > 0]
        if cfg["flow"] == "slump" and fc.newtonian(fl):
            ax.plot(t, 1000 * slump.front_position(t, s["height"] * s["length"], fl["viscosity"] / fl["density"], fc.G),
                    "k--", lw=1.5, label="similarity (Huppert 1982)")
            if "compare_from" in ds:
                mine = ds["fluid"].values == name
                ax.axvline(float(np.nanmax(ds["compare_from"].values[mine])), color="0.5", ls=":", lw=1)
            _plain_log(ax)
            ax.set_xlim(left=max(0.1, float(t.min())))
        elif cfg["flow"] == "slump":
            ax.axhline(1000 * reference_runout(cfg, fl), color="k", ls="--", lw=1.5, label="lubrication runout")
        else:  # a user's front reference
            ref = read_references(s)["front"]
            ax.plot(ref["t"], 1000 * ref, "ko", ms=4, label="reference (CSV)")
        ax.set_xlabel("t [s]")
        ax.set_ylabel("front x_N [mm]")
        ax.set_title(name, fontsize=9)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    return fig


def figures_for(cfg: dict) -> list[tuple[str, str, str]]:
    """(name, title, caption) of the figures this campaign draws."""
    figs = [("errors", "Errors against dp",
             "Each error's magnitude against the particle spacing (finer to the right), one line per "
             "fluid, scheme, shifting method and Ch; bars: 2 se (sampling error). Dotted: the tolerance."),
            ("cost", "Run time against error",
             "The headline error of each run against its wall time: the runs toward the lower left are "
             "the cheapest for their accuracy. Dotted: the tolerance.")]
    if cfg["flow"] == "slump":
        figs.append(("fronts", "Front against time",
                     "x_N(t) of every run; Newtonian: against the similarity front (log axes; dotted: t_c, "
                     "where the comparison starts); yield stress: against the lubrication runout."))
    elif cfg["flow"] == "user" and "front" in cfg["scene"]["reference"]:
        figs.append(("fronts", "Front against time", "x_N(t) of every run against the reference front (points)."))
    return figs


def write_figures(cfg: dict, ds: xr.Dataset, outdir, fmt: str = "png", dpi: int = 120) -> list[Path]:
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    draw = {"errors": fig_errors, "cost": fig_cost, "fronts": fig_fronts}
    paths = []
    for name, _, _ in figures_for(cfg):
        fig = draw[name](cfg, ds)
        path = outdir / f"{name}.{fmt}"
        tmp = outdir / f".{name}.tmp.{fmt}"
        fig.savefig(tmp, dpi=dpi)
        plt.close(fig)
        tmp.replace(path)
        paths.append(path)
    return paths


def render(cfg: dict, ds: xr.Dataset, figure_dir, config_text: str) -> str:
    import datetime as _dt
    import platform
    fmt = cfg["figures"]["format"]
    figs = [figure_html(Path(figure_dir) / f"{name}.{fmt}", title, caption)
            for name, title, caption in figures_for(cfg)]
    n = ds.sizes["case"]
    wall = float(np.nansum(ds["wall_time_s"].values))
    lead = (f"<p class='lead'>Flow: {FLOW_TITLES[cfg['flow']]}. {n} runs, "
            f"{sum(str(s) == 'diverged' for s in ds['status'].values)} diverged; {wall / 60:.0f} min of simulation "
            "wall time summed over the runs. The paper's conclusions are about the conveyor front and are not "
            "judged here: this report answers how close each run comes to its reference, at what cost, and "
            "whether surge's departures from the paper's scheme (spec) help or hurt on this flow.</p>")
    prov = {"date (UTC)": _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M"), "commit": _commit(),
            "host": platform.node(), "python": platform.python_version()}
    body = [("Answer", answer(cfg, ds)), ("Reference", reference_text(cfg, ds)),
            ("Accuracy and cost", "<p>One row a run (its case id shows over its dp). Errors in "
             "per cent &plusmn; 2 se, the sampling error from the particle noise of the measurement (not the "
             "discretisation error).</p>" + case_table(cfg, ds)),
            ("Convergence", convergence_table(cfg, ds)), ("Stability", stability_text(ds)),
            ("Figures", "".join(figs)), ("Configuration", f"<pre>{html.escape(config_text)}</pre>"),
            ("Provenance", "<table>" + "".join(
                f"<tr><th class='l'>{k}</th><td class='l'>{html.escape(str(v))}</td></tr>" for k, v in prov.items())
             + "</table>")]
    return page(f"sph-surge {cfg['flow']} campaign", f"sph-surge campaign report: {cfg['flow']}", lead, body)

