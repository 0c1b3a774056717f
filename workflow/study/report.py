"""Self-contained HTML report: the verdict on the paper's conclusions first, then accuracy and
cost, figures with captions, the case table, convergence, stability, configuration, provenance."""
from __future__ import annotations

import html
import warnings
from pathlib import Path

import numpy as np
import xarray as xr

from .campaign import ensemble_size
from .numbers import percent, with_error as _with_error
from .page import figure_html, page, provenance_html, reason_html, write  # noqa: F401 (write for callers)

def _fmt(v, digits=3):
    if isinstance(v, str):
        return html.escape(v)
    try:
        v = float(v)
    except (TypeError, ValueError):
        return html.escape(str(v))
    if not np.isfinite(v):
        return "&ndash;"
    if v != 0 and (abs(v) < 1e-3 or abs(v) >= 1e5):
        return f"{v:.{digits}e}"
    return f"{v:.{digits}g}"






def case_table(ds: xr.Dataset) -> str:
    st = ds["station"].values
    head = ["case", "status", "steady", "wall time [s]", "steps", "C_CFL used", "particles",
            "averaging window from [s]", "zeta_f [%] (± 2 se)", "zeta_f of the front's body [%] (± 2 se)",
            "zeta_h [%] (h_n, ± 2 se)", "zeta_h [%] (paper, ± 2 se)", "zeta_fs [%] (± 2 se)"] + [
                f"zeta_u x*={s:g} [%] (± 2 se)" for s in st]
    head.append("hold-out: metrics that moved by more than 2 se")
    rows = []
    for i, cid in enumerate(ds["case"].values):
        status = str(ds["case_status"].values[i])
        reason = str(ds["case_reason"].values[i])
        cells = [f'<td class="l">{html.escape(str(cid))}</td>',
                 f'<td class="l" title="{html.escape(reason)}">{html.escape(status)}'
                 + (f"<br><small>{reason_html(reason)}</small>" if reason else "") + "</td>",
                 f'<td>{"yes" if int(ds["case_steady"].values[i]) else "no"}</td>']
        for k in ("case_wall_time", "case_steps", "case_cfl_acoustic", "case_n_particles", "case_steady_state_time"):
            cells.append(f"<td>{_fmt(ds[k].values[i])}</td>")
        for k in ("case_zeta_f", "case_zeta_f_body", "case_zeta_h", "case_zeta_h_paper", "case_zeta_fs"):
            value = ds[k].values[i] if k in ds else np.nan  # zeta_f_body: absent from older datasets
            se = ds[f"{k}_se"].values[i] if f"{k}_se" in ds else None
            cells.append(f"<td>{_with_error(value, se)}</td>")
        for j in range(st.size):
            se = ds["case_zeta_u_se"].values[i, j] if "case_zeta_u_se" in ds else None
            cells.append(f"<td>{_with_error(ds['case_zeta_u'].values[i, j], se)}</td>")
        cells.append(f'<td class="l">{holdout_note(ds, i)}</td>')
        rows.append(f'<tr class="{html.escape(status)}">' + "".join(cells) + "</tr>")
    th = "".join(f'<th class="{"l" if k < 2 else ""}">{html.escape(h)}</th>' for k, h in enumerate(head))
    return f"<table><tr>{th}</tr>{''.join(rows)}</table>"


def holdout_note(ds: xr.Dataset, i: int) -> str:
    """The metrics of case i whose hold-out window differs by more than 2 se, with the change."""
    from .campaign import holdout_moves
    if "case_zeta_h_holdout" not in ds or not np.isfinite(ds["case_zeta_h_holdout"].values[i]):
        return "no hold-out"
    moves = holdout_moves(ds, i)
    return "; ".join(f"{html.escape(k)} {'+' if d > 0 else ''}{percent(d)} (2 se {percent(2 * e)})"
                     for k, d, e in moves) or "none"


def start_check_section(ds: xr.Dataset) -> str:
    """Each start check: the metrics of both runs side by side, their difference and whether
    they agree within 2 se; empty without start checks."""
    from . import startcheck
    tab = startcheck.table(ds)
    if tab.sizes["check"] == 0:
        return ""
    out = []
    for c in tab["check"].values:
        row = tab.sel(check=c)
        agree = row["agree"].values
        ok = bool(agree.all())
        moved = [str(m) for m, a in zip(tab["metric"].values, agree) if not a]
        note = "" if bool(row["steady"]) else " (<b>not both steady</b>: indicative only)"
        ids = list(ds["case"].values)
        since = [float(ds["case_steady_state_time"].values[ids.index(k)]) if "case_steady_state_time" in ds
                 else float("nan") for k in (str(row["own_case"].values), str(c))]
        if all(np.isfinite(since)):
            note += f"; averaging windows from {since[0]:.1f} s and {since[1]:.1f} s"
        words = startcheck.CHECK_START_WORDS[str(row["start"].values)]
        out.append(f"<p><b>{html.escape(str(row['own_case'].values))}</b> against <b>{html.escape(str(c))}</b> "
                   f"(from {html.escape(words)}): "
                   + ("the two starts agree within 2 se on every metric" if ok else
                      f"the two starts <b>differ</b> on {len(moved)} of {agree.size} metrics by more than 2 se "
                      f"({html.escape(', '.join(moved))}): a real difference, not sampling noise")
                   + note + ".</p>")
        cells = "".join(
            f"<tr><td class='l'>{html.escape(str(m))}</td>"
            f"<td>{_with_error(row['own'].values[k], row['own_se'].values[k])}</td>"
            f"<td>{_with_error(row['other'].values[k], row['other_se'].values[k])}</td>"
            f"<td>{_with_error(row['difference'].values[k], row['difference_se'].values[k])}</td>"
            f"<td class='{'ok' if agree[k] else 'warn'}'>{'yes' if agree[k] else 'no'}</td></tr>"
            for k, m in enumerate(tab["metric"].values))
        out.append("<table><tr><th class='l'>metric</th><th>campaign's start (&plusmn; 2 se)</th>"
                   "<th>check's start (&plusmn; 2 se)</th><th>difference (&plusmn; 2 se)</th>"
                   f"<th>within 2 se</th></tr>{cells}</table>")
    return ("<p>At the finest dp, each shifting method ran once more from another start: the paper's (a "
            "block at rest at the normal depth, the belt ramped up from rest), or, where the campaign's run "
            "starts as the paper does, a warm start from the next coarser dp (the moving film without one). "
            "Each se holds the metric's wander from one "
            "window to the next (its autocorrelation over the seconds before the window, calibrated on runs "
            "carried on for 110 s: docs/metrics.md). Where the two runs agree within 2 se, the answer does not "
            "depend on the start. Where they differ by more, the difference is real: the start changes the "
            "answer, or one of the runs was averaged before its steady state (its hold-out column says if a "
            "metric moved after the window).</p>" + "".join(out))


def convergence_table(ds: xr.Dataset) -> str:
    """Observed order, Richardson-extrapolated value and GCI of the uniform depth h_u/h_n and
    of the station depth-mean u*, for each Ch and shifting with three or more resolutions: the
    (Ch, shifting) sequences that have data (a grid's excluded or wholly diverged ones do not)."""
    from .convergence import gci
    from .convergence import MAX_ORDER
    if ds.sizes["dp"] < 3:
        return "<p>Fewer than three resolutions: no observed order or GCI.</p>"
    st = ds["station"].values
    rows = []
    for sh in ds["shifting"].values:
        for ch in ds["ch"].values:
            sub = ds.sel(ch=ch, shifting=sh)
            quantities = [("h_u / h_n", sub["uniform_depth"].values)]
            with warnings.catch_warnings():  # an all-NaN profile (a missing run) gives NaN, quietly
                warnings.simplefilter("ignore", RuntimeWarning)
                means = np.nanmean(sub["mean_velocity"].values, axis=2)
            quantities += [(f"mean u* at x* = {s:g}", means[:, j]) for j, s in enumerate(st)]
            if not any(np.isfinite(phi).any() for _, phi in quantities):
                continue  # never run, or every run diverged: no sequence to judge
            for name, phi in quantities:
                r = gci(sub["dp"].values, phi)
                order = _fmt(r.order)
                if r.status == "monotone" and r.order > MAX_ORDER:  # its order alone, flagged
                    order += f" (above {MAX_ORDER:g}: unreliable)"
                    r = type(r)("unreliable", r.order)
                rows.append(f'<tr><td class="l">{html.escape(str(sh))}</td><td>{ch:g}</td>'
                            f'<td class="l">{html.escape(name)}</td><td class="l">{r.status}</td>'
                            f"<td>{order}</td><td>{_fmt(r.extrapolated, 4)}</td>"
                            f"<td>{percent(r.gci_fine, '&ndash;')}</td>"
                            f"<td>{percent(r.error_fine, '&ndash;')}</td></tr>")
    if not rows:
        return "<p>No run finished: no observed order or GCI.</p>"
    head = ("<tr><th class='l'>shifting</th><th>Ch</th><th class='l'>quantity</th>"
            "<th class='l'>sequence</th><th>observed order</th><th>extrapolated</th>"
            "<th>GCI fine [%]</th><th>finest vs extrapolated [%]</th></tr>")
    return ("<p>Grid Convergence Index (Celik et al. 2008) over the three finest resolutions; "
            "oscillatory or divergent sequences are flagged and given no number, and a monotone one "
            f"whose observed order is above {MAX_ORDER:g} is flagged unreliable and given its order "
            "alone. Runs that were not steady enter with their final-window values.</p>"
            f"<table>{head}{''.join(rows)}</table>")


VERDICT_CLASS = {"reproduced": "ok", "not reproduced": "warn", "contradicted": "bad", "no data": "warn"}


def verdict_table(ds: xr.Dataset) -> str:
    """One row per conclusion of the paper: our numbers and the verdict (study.verdict)."""
    from .verdict import PAPER_FINEST_DP, verdicts
    from .startcheck import CHECK_START_WORDS, pairs
    rows = []
    notes = {c: holdout_note(ds, i) for i, c in enumerate(ds["case"].values)}
    for v in verdicts(ds):
        caveat = ""
        if v.unsteady:
            caveat = (f"<br><small><b>Rests on {len(v.unsteady)} of {len(v.cases)} runs that are not "
                      f"steady</b> ({html.escape(', '.join(v.unsteady))}): indicative only.</small>")
        moved = [f"{c}: {notes[c]}" for c in v.cases if notes.get(c, "none") not in ("none", "no hold-out")]
        if moved:
            caveat += ("<br><small>Metrics that moved by more than 2 se from the averaging window to the "
                       "hold-out window after it: " + "; ".join(moved) + ".</small>")
        rows.append(f'<tr><td class="l">{html.escape(v.claim)}</td>'
                    f'<td class="l {VERDICT_CLASS[v.verdict]}"><b>{html.escape(v.verdict)}</b>'
                    f'{"*" if v.unsteady else ""}</td>'
                    f'<td class="l">{html.escape(v.evidence)}{caveat}</td></tr>')
    finest = float(np.min(ds["dp"].values)) * 1000
    schemes = ds.attrs.get("schemes", "")
    start = ""
    if schemes:
        departs = ("departs from the paper's (docs/scheme.md section 6) as "
                   '<a href="../docs/numerics.md">docs/numerics.md</a> lists' if schemes != "spec"
                   else "is the paper's as written (docs/scheme.md section 6)")
        tags = dict.fromkeys(str(ds["case_tag"].values[j]) for _, j in pairs(ds))
        check = (" (the start checks, from " + "; ".join(CHECK_START_WORDS[t] for t in tags) + ")" if tags else "")
        start = (f"<p>The runs start from {html.escape(ds.attrs.get('starts', ''))}{check}; their scheme, "
                 f"{html.escape(schemes)}, {departs}.</p>")
    return (start + f"<p>Each conclusion of the paper, judged on this campaign's own runs at its finest dp "
            f"({finest:g} mm; the paper's finest is {PAPER_FINEST_DP * 1000:g} mm). "
            "<b>reproduced</b>: our numbers show it; <b>contradicted</b>: they show the opposite "
            "beyond their uncertainty (for a threshold: even the GCI extrapolation to dp &rarr; 0 "
            "misses it); <b>not reproduced</b>: neither, at these resolutions. * : the verdict rests "
            "on runs that are not steady.</p>"
            "<table class='verdict'><tr><th class='l'>the paper's conclusion</th><th class='l'>verdict</th>"
            "<th class='l'>evidence (metrics at the finest dp where the runs finished)</th></tr>"
            + "".join(rows) + "</table>")


def accuracy_table(ds: xr.Dataset, thresholds=(0.01, 0.05)) -> str:
    """Per metric: the cheapest steady run under each threshold, and per shifting method at
    the paper's Ch the GCI-extrapolated value, its band and the dp needed for 1 %."""
    from .convergence import MAX_ORDER, MIN_ORDER
    from .verdict import accuracy_rows
    rows = accuracy_rows(ds, thresholds)
    out, last = [], None
    for r in rows:
        first = r["metric"] != last
        last = r["metric"]
        cells = [f'<td class="l">{html.escape(r["metric"]) if first else ""}</td>']
        for thr in thresholds:
            c = r["cheapest"][thr]
            txt = "none" if c is None else (f"{c[0]} ({c[1]:.0f} s, {percent(c[2])}"
                                            + ("" if c[3] is None else f" ± {percent(c[3])}") + ")")
            cells.append(f'<td class="l">{html.escape(txt) if first else ""}</td>')
        x = r["extrapolation"]
        if x.status == "monotone":
            lim = f"{percent(x.extrapolated)} &plusmn; {percent(x.band)} (p = {x.order:.2g})"
            need = (f"&ndash; (order below {MIN_ORDER:g}: not converging yet)" if np.isnan(x.dp_needed)
                    else "never (limit above 1 %)" if not np.isfinite(x.dp_needed)
                    else f"{x.dp_needed * 1000:.3g} mm")
        elif x.status == "unreliable":
            lim = f"not extrapolated: observed order p = {x.order:.2g}, above {MAX_ORDER:g} (unreliable)"
            need = (f"{x.dp_needed * 1000:.3g} mm" if np.isfinite(x.dp_needed)
                    else f"&ndash; (order above {MAX_ORDER:g}: unreliable)")
        else:
            lim, need = html.escape(x.status), "&ndash;"
        two_se = r["finest_two_se"]
        finest = percent(x.finest, "&ndash;") + ("" if two_se == 0 or not np.isfinite(x.finest)
                                                 else " &plusmn; (se unknown)" if not np.isfinite(two_se)
                                                 else f" &plusmn; {percent(two_se)}")
        cells += [f'<td class="l">{html.escape(r["shifting"])}</td>', f"<td>{finest}</td>",
                  f'<td class="l">{lim}</td>', f'<td class="l">{need}</td>']
        out.append("<tr>" + "".join(cells) + "</tr>")
    ch = rows[0]["ch"] if rows else float("nan")
    ensemble = ensemble_size(ds) > 1
    unit = "grid point" if ensemble else "run"
    head = ("<tr><th class='l'>metric</th>"
            + "".join(f"<th class='l'>cheapest steady {unit} &le; {percent(t)}</th>"
                      for t in thresholds)
            + f"<th class='l'>shifting (Ch {ch:g})</th><th>finest dp [%] &plusmn; 2 se</th>"
            "<th class='l'>GCI limit dp &rarr; 0 [%] &plusmn; band</th><th class='l'>dp for 1 %</th></tr>")
    what = ("grid point (a realisation's mean wall time, the realisations' mean error and the ensemble's se)"
            if ensemble else "run (wall time, error)")
    return (f"<p>The cheapest steady {what} meeting each threshold over the whole "
            "grid (with its sampling error: below by more than 2 se); then, at the paper's "
            "Ch, the metric at the finest dp, its Richardson limit with the GCI band of the finest "
            "value (Celik et al. 2008; only for monotone sequences over the three finest dp) and "
            "the dp at which zeta = limit + C dp^p reaches 1 % (not projected from an observed "
            f"order p below {MIN_ORDER:g}; an order above {MAX_ORDER:g} is unreliable, and neither "
            "limit, band nor dp is extrapolated from it).</p>"
            f"<table>{head}{''.join(out)}</table>")


def stability_section(ds: xr.Dataset) -> str:
    """Counts, detectors, per-setting outcome and the recommended settings."""
    from .stability import SAFE_FRACTION, recommended, settings_summary
    if "case_detector" not in ds:
        return "<p>No stability data in this campaign dataset.</p>"
    status = [str(s) for s in ds["case_status"].values]
    det = [str(d) for d in ds["case_detector"].values]
    n, nd = len(status), status.count("diverged")
    caught = sum(1 for s, d in zip(status, det) if s == "diverged" and d not in ("", "other"))
    counts = {d: det.count(d) for d in sorted(set(det)) if d}
    text = (f"<p>{n} combinations tried; {nd} diverged, {caught} of them stopped by a named "
            "detector (" + (", ".join(f"{v} {html.escape(k)}" for k, v in counts.items()) or "none")
            + f"); {n - nd} survived, {int(ds['case_safe'].values.sum())} of them <b>safe</b> (every "
            f"guarded quantity below {SAFE_FRACTION:g} of its guard). Margins per case: Fig. 12.</p>")
    rows = settings_summary(ds)
    if rows:
        def alone(r):
            return "-" if r["alone"] is None else f"{r['alone'][0]} ({r['alone'][1]:.2f})"
        text += ("<table><tr><th class='l'>setting</th><th class='l'>value</th><th>tried</th>"
                 "<th>survived</th><th>safe</th><th class='l'>detectors that fired</th>"
                 "<th class='l'>others at base: outcome (worst margin)</th></tr>"
                 + "".join(f"<tr><td class='l'>{html.escape(r['setting'])}</td>"
                           f"<td class='l'>{html.escape(r['value'])}</td>"
                           f"<td>{r['tried']}</td><td>{r['survived']}</td><td>{r['safe']}</td>"
                           f"<td class='l'>{html.escape(', '.join(r['detectors']))}</td>"
                           f"<td class='l'>{html.escape(alone(r))}</td></tr>" for r in rows)
                 + "</table>")
    rec = recommended(ds)
    if rec["settings"]:
        base = ", ".join(f"{k} = {v}" for k, v in rec["base"].items())
        items = "".join(
            f"<li>{html.escape(k)}: survived {html.escape(', '.join(e['survived']) or 'none')}"
            + (f"; diverged {html.escape(', '.join(e['diverged']))}" if e["diverged"] else "")
            + (f"; recommended <b>{html.escape(e['best'])}</b> (largest margin)" if e["best"] else "")
            + "</li>" for k, e in rec["settings"].items())
        text += (f"<p><b>Recommended settings</b>, one setting at a time with the others at the base "
                 f"({html.escape(base)}):</p><ul>{items}</ul>"
                 + (f"<p>Largest margin among the safe cases: <b>{html.escape(rec['safest_case'])}</b>.</p>"
                    if rec["safest_case"] else "<p>No case was safe.</p>"))
    return text


def ensemble_counts(ds: xr.Dataset) -> str:
    """How many realisations the grid points ran: 'every grid case ran in 4 realisations', or
    per count, 'grid points ran in 8 realisations: dp1mm_ch1.8_lind, ...; in 1 realisation:
    ...' (most first)."""
    grid = ds["realisations"].stack(point=("dp", "ch", "shifting"))
    ran = grid.values > 0
    counts = grid.values[ran]
    names = ds["case_id"].stack(point=("dp", "ch", "shifting")).values[ran]
    sizes = sorted(set(counts.tolist()), reverse=True)
    if len(sizes) == 1:
        return f"every grid case ran in {sizes[0]} realisations"
    return "grid points ran in " + "; in ".join(
        f"{n} realisation{'s' if n > 1 else ''}: " + ", ".join(html.escape(str(c)) for c in names[counts == n])
        for n in sizes)


def ensemble_paragraph(ds: xr.Dataset) -> str:
    """What a grid point's value and se are when the campaign ran an ensemble; empty without."""
    if ensemble_size(ds) <= 1:
        return ""
    amp = float(ds.attrs.get("start_perturbation", np.nan))
    stagger = float(ds.attrs.get("window_stagger", 0.0))
    later = (f", and realisation k's steady.min_time is raised by k &times; {stagger:g} s, so that "
             "its averaging window opens no earlier than that, and the windows may sample a motion the "
             "runs share rather than one phase of it") if stagger > 0 else ""
    return (f"<p><b>Ensemble:</b> {ensemble_counts(ds)}. Realisation 0 is the case as configured, "
            f"the others move each fluid particle's start by up to {amp:g} dp (ids ending in _r1, "
            f"_r2, ...; all in the case table){later}. A grid point's metrics are the means over its "
            "n realisations, and its se is sqrt(max(s<sup>2</sup>, mean se<sub>i</sub><sup>2</sup>) / n) "
            "(a single run's: its window's se): s, the realisations' spread, holds what one "
            "window's se misses; the windows' own se bound it from below. A grid point counts as "
            "completed and steady only if every realisation is. Its wall time is a realisation's mean.</p>")


def render(ds: xr.Dataset, figures: list[tuple[Path, str, str]], config_text: str,
           extra_sections: list[tuple[str, str]] = ()) -> str:
    """HTML text; ``figures`` as (image path, title, caption); images are embedded."""
    n = ds.sizes["case"]
    statuses = [str(s) for s in ds["case_status"].values]
    counts = {s: statuses.count(s) for s in sorted(set(statuses))}
    wall = np.nansum(ds["case_wall_time"].values)
    mixed = ds.attrs.get("physics_differ")
    summary = (f"<p>{n} cases: " + ", ".join(f"{v} {html.escape(k)}" for k, v in counts.items())
               + f". Total simulation wall time {wall:.0f} s.</p>"
               + (f"<p><b>Cases of different physics.</b> {html.escape(mixed)}.</p>" if mixed else "")
               + "<p>Metrics (docs/scheme.md section 4) are computed against lubrication theory over the "
               "steady averaging window of each run. A run that did not reach steady state by its "
               "maximum time is shown with its metrics over its final window, marked "
               "<b>steady: no</b> (hollow markers in the figures): indicative only. Diverged runs "
               "have no metrics. "
               f"zeta_h is given against the computed normal depth h_n = "
               f"{_fmt(ds.attrs.get('h_n_m', np.nan) * 1000, 4)} mm and against the paper's "
               f"normalising depth {_fmt(ds.attrs.get('normalising_depth_m', np.nan) * 1000, 4)} mm. "
               "&plusmn; 2 se: the sampling error of a run's window, from each metric's series and its "
               "autocorrelation over the seconds before the window (docs/metrics.md, 'Standard "
               "errors'). It is not the discretisation error, and the verdicts and "
               "the cheapest runs use it: a value is below a threshold only by more than 2 se, two "
               "runs within 2 se tie. It is meant to hold how far a metric wanders from one window to "
               "the next; the case table's hold-out column shows where a run's metrics still moved by "
               "more than 2 se into the window after. The campaign key "
               "ensemble runs each grid case in several realisations and puts their spread into the se. "
               "The case table's zeta_f of the front's body, beyond the paper, is the same error of the "
               "equivalent front (the fluid area downstream of a lab-fixed point over h_n) over the same "
               "second: where zeta_f reads more than it, the toe wandered or particles joined or left the "
               "tip while the front itself held.</p>"
               + ensemble_paragraph(ds) + axes_paragraph(ds))
    figs = [figure_html(path, title, caption) for path, title, caption in figures]
    prov_html = provenance_html(str(ds.attrs.get("version_numba", "")))
    newtonian = ds.attrs.get("rheology", "newtonian") == "newtonian"
    verdict = verdict_table(ds) if newtonian else (
        f"<p>The paper's conclusions are about a Newtonian fluid; this campaign's fluid is "
        f"{html.escape(ds.attrs['rheology'])}, so they are not judged here. Its errors are against "
        "the lubrication reference for that fluid: see Accuracy and cost, and the figures.</p>")
    start_check = start_check_section(ds)
    body = [("Verdict", verdict), ("Accuracy and cost", accuracy_table(ds)),
            *([("Start check", start_check)] if start_check else []),
            ("Summary", summary), ("Figures", "".join(figs)), ("Cases", case_table(ds)),
            ("Convergence", convergence_table(ds)), ("Stability", stability_section(ds)),
            *extra_sections, ("Configuration", f"<pre>{html.escape(config_text)}</pre>"),
            ("Provenance", prov_html)]
    n_steady = int(np.sum(ds["case_steady"].values > 0))
    question = ("Does this campaign reproduce the conclusions of Lapillonne et al. (SPHERIC 2022)?"
                if newtonian else f"A {html.escape(ds.attrs['rheology'])} fluid: how close are its fronts to "
                "the lubrication reference, and at what cost?")
    ensemble = "" if ensemble_size(ds) <= 1 else (
        f" ({int(np.sum(ds['realisations'].values > 0))} grid points; {ensemble_counts(ds)})")
    lead = (f"<p class='lead'>{n} cases{ensemble}, {n_steady} steady, {counts.get('diverged', 0)} diverged; "
            f"{campaign_wall(ds)}{wall / 60:.0f} min of simulation wall time summed over the cases. {question}</p>")
    return page("sph-surge campaign report", "sph-surge campaign report", lead, body)


def axes_paragraph(ds: xr.Dataset) -> str:
    """What a campaign with physical axes reports where ('' without)."""
    axes = [a for a in str(ds.attrs.get("axes", "")).split(",") if a]
    if not axes:
        return ""
    values = "; ".join(f"{html.escape(a)} = " + ", ".join(
        html.escape(str(v)) for v in dict.fromkeys(ds[f"case_axis_{a}"].values.tolist())) for a in axes)
    return (f"<p><b>Physical axes</b>: {values}. Every run is scored against the theory of its own "
            "physical case. The verdict, the accuracy table and Figs. 2-11 and 13 take each axis's "
            "first value; the case table, the stability map (Fig. 12) and the sweep figure (errors "
            "against dp for each value) every value.</p>")


def campaign_wall(ds: xr.Dataset) -> str:
    """'the runs took X min of wall time (first start to last end); ' or '' where unrecorded."""
    if "case_started" not in ds or "case_ended" not in ds:
        return ""
    start, end = np.nanmin(ds["case_started"].values), np.nanmax(ds["case_ended"].values)
    if not (np.isfinite(start) and np.isfinite(end)):
        return ""
    return f"the runs took {(end - start) / 60:.1f} min of wall time (first start to last end); "





