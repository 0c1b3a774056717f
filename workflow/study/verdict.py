"""Does the campaign reproduce the paper's conclusions? Pure functions over the campaign
dataset (study.campaign.build): one verdict per conclusion, and per metric the cheapest
steady run under a threshold, the GCI-extrapolated value and the dp needed for 1 %.

Verdicts:
- ``reproduced``: our numbers at the finest dp show the claim;
- ``contradicted``: they show the opposite beyond their uncertainty (a threshold that even
  the extrapolation to dp -> 0 misses by more than its GCI band; a difference of the other
  sign that is resolved; errors growing with refinement);
- ``not reproduced``: neither (e.g. the error is above the threshold at our finest dp but
  the extrapolation does not rule the threshold out);
- ``no data``: the runs the claim needs are missing or diverged.
A verdict whose evidence includes runs that were not steady says so (``unsteady``).
A metric with a sampling error in the campaign dataset (``{var}_se``: the se of the window mean or
slope of each metric's series, study.metrics and solver.timeseries) is
below or above a threshold only by more than 2 se, and two runs within 2 se of each other
tie; a run whose sampling error could not be measured (NaN: too few samples) is neither below
nor above, and ties. Along dp, a change within 2 se of its two runs counts as none (``trend``).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import xarray as xr

from .campaign import ensemble_size
from .convergence import gci
from .convergence import MAX_ORDER, MIN_ORDER
from .numbers import percent

PAPER_CH = 1.8
PAPER_FINEST_DP = 0.25e-3
RESOLVED = 0.10  # a difference between two runs below this fraction of the larger is a tie
MARGINAL_U = 0.01  # |delta zeta_u| below which shifting "marginally" affects zeta_u (1 % of u_b)


@dataclass
class Verdict:
    claim: str
    verdict: str  # reproduced | not reproduced | contradicted | no data
    evidence: str
    cases: list[str] = field(default_factory=list)  # the runs the verdict rests on
    unsteady: list[str] = field(default_factory=list)  # those of them that were not steady


@dataclass
class Extrapolation:
    """GCI over the three finest dp of one metric sequence, and what it implies. ``status``:
    study.convergence's, or ``unreliable`` for a monotone sequence whose observed order is above
    MAX_ORDER (the order is kept; nothing is extrapolated)."""
    status: str
    finest: float = math.nan
    extrapolated: float = math.nan
    band: float = math.nan  # absolute uncertainty of the finest value: GCI_fine |finest|
    order: float = math.nan
    dp_needed: float = math.nan  # dp [m] at which the metric reaches the target; inf: never;
    # NaN: not projected (an order below MIN_ORDER or above MAX_ORDER)


def main_method(ds: xr.Dataset) -> str:
    """The shifting method run at the most Ch values (the first listed on a tie): the
    paper's Figs. 2-6 method."""
    shs = [str(s) for s in ds["shifting"].values]
    counts = [int((ds["status"].sel(shifting=s) != "missing").any("dp").sum()) for s in shs]
    return shs[int(np.argmax(counts))]


def paper_ch(ds: xr.Dataset) -> float:
    return float(ds["ch"].sel(ch=PAPER_CH, method="nearest"))


def _finite_dp(da: xr.DataArray) -> xr.DataArray:
    """A (dp,) sequence with only its finite values (diverged and missing runs drop out)."""
    return da.where(np.isfinite(da), drop=True)


def extrapolate(dp, phi, target: float = 0.01) -> Extrapolation:
    """GCI of a metric over dp; the dp at which phi(dp) = phi_ext + C dp^p reaches ``target``.
    The metrics are errors, never negative: a negative Richardson limit is reported as 0. An
    observed order below MIN_ORDER is not projected (dp_needed NaN): such a sequence is not in
    its asymptotic range, and dp^p with p near 0 would put the target at absurdly small dp. An
    order above MAX_ORDER is unreliable (status ``unreliable``): no limit, no band and no
    projected dp; dp_needed is the finest dp only where that already meets the target."""
    dp = np.asarray(dp, dtype=float)
    phi = np.asarray(phi, dtype=float)
    ok = np.isfinite(dp) & np.isfinite(phi)
    dp, phi = dp[ok], phi[ok]
    if dp.size == 0:
        return Extrapolation("no data")
    i1 = int(np.argmin(dp))
    r = gci(dp, phi)
    out = Extrapolation(r.status, finest=float(phi[i1]))
    if r.status != "monotone":
        return out
    if r.order > MAX_ORDER:
        out.status, out.order = "unreliable", r.order
        if out.finest <= target:
            out.dp_needed = float(dp[i1])
        return out
    out.extrapolated, out.order = max(r.extrapolated, 0.0), r.order
    out.band = r.gci_fine * abs(out.finest)
    if out.finest <= target:
        out.dp_needed = float(dp[i1])
    elif r.order < MIN_ORDER:
        pass  # not projected: dp_needed stays NaN
    elif out.extrapolated >= target:
        out.dp_needed = math.inf
    else:
        out.dp_needed = float(dp[i1] * ((target - out.extrapolated) / (out.finest - out.extrapolated)) ** (1 / r.order))
    return out


def _status_note(ds, sel_list):
    """Case ids of the selections, and those not steady (finished but flagged)."""
    cases, unsteady = [], []
    for sel in sel_list:
        cid = str(ds["case_id"].sel(**sel).values)
        if not cid:
            continue
        cases.append(cid)
        if str(ds["status"].sel(**sel).values) != "diverged" and not float(ds["steady"].sel(**sel)) > 0:
            unsteady.append(cid)
    return cases, unsteady


def _series(ds, var, ch, sh, station=None) -> xr.DataArray:
    """``var`` over dp for one Ch and shifting method (and station)."""
    da = ds[var].sel(ch=ch, shifting=sh)
    return da if station is None else da.sel(station=station)


def _finest_dp(da: xr.DataArray):
    """The finest dp of a (dp,) sequence with a finite value; None if it has none."""
    da = _finite_dp(da)
    return None if da.sizes["dp"] == 0 else float(da["dp"].min())


def _pct(v):
    return percent(v)


def _mm(dp):
    return f"{dp * 1000:g} mm"


def _se(ds, var, dp, ch, sh, station=None) -> float:
    """The sampling standard error of ``var`` at one run (and station) (``{var}_se`` in the
    campaign dataset): 0 where the campaign has no such variable, NaN where the run's could
    not be measured."""
    if f"{var}_se" not in ds:
        return 0.0
    return float(_series(ds, f"{var}_se", ch, sh, station).sel(dp=dp))


def threshold_claim(ds, var, threshold, chs, sh, need, claim):
    """``var`` below ``threshold`` at the finest dp for at least ``need`` of ``chs``. A value
    with a sampling error (``{var}_se``) counts as below only when it is below by more than
    2 se; it counts as ruled out only when it is above by more than 2 se and the GCI limit
    minus its band is above as well."""
    met, ruled_out, parts, sels = 0, 0, [], []
    for ch in chs:
        da = _series(ds, var, ch, sh)
        dp = _finest_dp(da)
        if dp is None:
            parts.append(f"Ch {ch:g}: no run")
            continue
        x = extrapolate(da["dp"].values, da.values, threshold)
        v = float(da.sel(dp=dp))
        two_se = 2.0 * _se(ds, var, dp, ch, sh)
        sels.append(dict(dp=dp, ch=ch, shifting=sh))
        if not np.isfinite(two_se):  # neither below nor above
            noise = " (sampling error unknown)"
        else:
            if v + two_se < threshold:
                met += 1
            elif v - two_se > threshold and x.status == "monotone" and x.extrapolated - x.band > threshold:
                ruled_out += 1
            noise = f" ± {_pct(two_se)} (2 se)" if two_se > 0 else ""
        note = f" (limit {_pct(x.extrapolated)} ± {_pct(x.band)})" if x.status == "monotone" else ""
        parts.append(f"Ch {ch:g}: {_pct(v)}{noise} at {_mm(dp)}{note}")
    if not sels:
        return Verdict(claim, "no data", "no finished run", [], [])
    need = min(need, len(chs))
    if met >= need:
        verdict = "reproduced"
    elif len(sels) - ruled_out < need:
        verdict = "contradicted"
    else:
        verdict = "not reproduced"
    evidence = f"{sh}: " + "; ".join(parts) + f". Below {_pct(threshold)}: {met} of {len(chs)} Ch"
    if "2 se" in evidence:
        evidence += " (by more than 2 se)"
    return Verdict(claim, verdict, evidence, *_status_note(ds, sels))


def trend(dp, phi, se=None) -> str:
    """'decreasing' (each finer dp no worse, the finest better than the coarsest),
    'increasing' (the reverse), 'mixed', or 'insufficient' (fewer than two values). With
    sampling errors ``se`` (one a value; NaN unknown, taken as 0), a change between two
    values within 2 se of the two combined counts as none, and a sequence with no other
    change is 'flat'."""
    dp = np.asarray(dp, dtype=float)
    phi = np.asarray(phi, dtype=float)
    err = np.zeros_like(phi) if se is None else np.nan_to_num(np.asarray(se, dtype=float), nan=0.0)
    ok = np.isfinite(dp) & np.isfinite(phi)
    if ok.sum() < 2:
        return "insufficient"
    order = np.argsort(dp[ok])[::-1]  # coarse to fine
    v, e = phi[ok][order], err[ok][order]
    d = np.diff(v)
    d[np.abs(d) <= 2.0 * np.hypot(e[1:], e[:-1])] = 0.0
    if np.all(d <= 0) and d.sum() < 0:
        return "decreasing"
    if np.all(d >= 0) and d.sum() > 0:
        return "increasing"
    return "flat" if se is not None and np.all(d == 0) else "mixed"


def converging_claim(ds, var, chs, sh, claim, about=None):
    """``var`` falls with refinement, beyond its sampling errors (``trend``), for most of
    ``chs``; with ``about`` = (value, factor),
    also that its GCI limit at the paper's Ch lies within that factor of the value
    (contradicted when the whole GCI band lies outside it, not reproduced when only the
    limit does)."""
    counts = {"decreasing": 0, "increasing": 0, "mixed": 0, "flat": 0, "insufficient": 0}
    sels, parts = [], []
    for ch in chs:
        da = _finite_dp(_series(ds, var, ch, sh))
        se = None if f"{var}_se" not in ds else _series(ds, f"{var}_se", ch, sh).sel(dp=da["dp"]).values
        t = trend(da["dp"].values, da.values, se)
        counts[t] += 1
        sels += [dict(dp=float(d), ch=ch, shifting=sh) for d in da["dp"].values]
        if da.sizes["dp"]:
            seq = ", ".join(_pct(float(v)) for v in da.values)
            parts.append(f"Ch {ch:g}: {seq} ({t})")
    if not sels:
        return Verdict(claim, "no data", "no finished run", [], [])
    n = len(chs) - counts["insufficient"]
    if n == 0:
        verdict = "not reproduced"
    elif counts["decreasing"] > n / 2:
        verdict = "reproduced"
    elif counts["increasing"] > n / 2:
        verdict = "contradicted"
    else:
        verdict = "not reproduced"
    evidence = f"{sh}, dp coarse to fine: " + "; ".join(parts)
    if about is not None and verdict == "reproduced":
        value, factor = about
        ch = paper_ch(ds)
        da = _series(ds, var, ch, sh)
        x = extrapolate(da["dp"].values, da.values)
        if x.status != "monotone":
            verdict = "not reproduced"
            how = (f"monotone at an observed order of {x.order:.2g}, above {MAX_ORDER:g}: unreliable"
                   if x.status == "unreliable" else x.status)
            evidence += f". At Ch {ch:g} the sequence is {how}: no limit to compare with {_pct(value)}"
        else:
            lo, hi = x.extrapolated - x.band, x.extrapolated + x.band
            evidence += f". Limit at Ch {ch:g}: {_pct(x.extrapolated)} ± {_pct(x.band)}"
            if hi < value / factor or lo > value * factor:
                verdict = "contradicted"
                evidence += f", not about {_pct(value)} (outside a factor {factor:g})"
            elif not value / factor <= x.extrapolated <= value * factor:
                verdict = "not reproduced"
                evidence += (f": the limit lies outside a factor {factor:g} of {_pct(value)}, "
                             "its band does not")
    return Verdict(claim, verdict, evidence, *_status_note(ds, sels))


def _value(ds, var, dp, ch, sh, station=None) -> float:
    return float(_series(ds, var, ch, sh, station).sel(dp=dp))


def _both_methods(ds, quantities):
    """(Ch, dp, None): the paper's Ch and the finest dp where Lind and Skillen both gave
    every (var, station) of ``quantities``; or (Ch, None, why not) when there is none."""
    ch = paper_ch(ds)
    if not {"lind", "skillen"} <= {str(s) for s in ds["shifting"].values}:
        return ch, None, "the campaign does not run both methods"
    both = [float(d) for d in ds["dp"].values
            if all(np.isfinite(_value(ds, v, d, ch, s, x)) for v, x in quantities for s in ("lind", "skillen"))]
    if not both:
        return ch, None, f"no dp where both methods finished at Ch {ch:g}"
    return ch, min(both), None


def lind_better_claim(ds, claim):
    """Lind below Skillen on zeta_f and zeta_h at the paper's Ch, at the finest dp where both
    finished. A difference below RESOLVED of the larger value, or within 2 se of the two
    values' sampling errors combined (``{var}_se``), is a tie."""
    ch, dp, why_not = _both_methods(ds, [("zeta_f", None), ("zeta_h", None)])
    if dp is None:
        return Verdict(claim, "no data", why_not, [], [])
    better, worse, parts = 0, 0, []
    for var in ("zeta_f", "zeta_h"):
        lv, sv = (_value(ds, var, dp, ch, s) for s in ("lind", "skillen"))
        lse, sse = (_se(ds, var, dp, ch, s) for s in ("lind", "skillen"))
        two_se = 2.0 * math.hypot(lse, sse)
        if not np.isfinite(two_se):
            word = "tie: sampling error unknown"
        elif abs(lv - sv) <= max(RESOLVED * max(lv, sv), two_se):
            word = "tie"
        elif lv < sv:
            word, better = "lind better", better + 1
        else:
            word, worse = "skillen better", worse + 1
        err = lambda se: f" ± {_pct(2 * se)}" if np.isfinite(se) and se > 0 else ""  # noqa: E731
        parts.append(f"{var}: lind {_pct(lv)}{err(lse)}, skillen {_pct(sv)}{err(sse)} ({word})")
    verdict = "reproduced" if better == 2 else "contradicted" if worse == 2 else "not reproduced"
    evidence = f"Ch {ch:g}, dp = {_mm(dp)}: " + "; ".join(parts) + (" (± 2 se)" if "±" in "".join(parts) else "")
    sels = [dict(dp=dp, ch=ch, shifting=s) for s in ("lind", "skillen")]
    return Verdict(claim, verdict, evidence, *_status_note(ds, sels))


def marginal_shifting_claim(ds, claim):
    """At the paper's Ch and the finest dp where both finished: reproduced when at every
    station |zeta_u(lind) - zeta_u(skillen)| is below MARGINAL_U or a tie (RESOLVED);
    contradicted when at some station one method's error is more than twice the other's
    and the difference exceeds MARGINAL_U by more than 2 se of the two runs' sampling errors
    combined (``zeta_u_se``; an unknown se never contradicts)."""
    st = ds["station"].values
    ch, dp, why_not = _both_methods(ds, [("zeta_u", x) for x in st])
    if dp is None:
        return Verdict(claim, "no data", why_not, [], [])
    marginal, large, parts = 0, 0, []
    for x in st:
        lv, sv = (_value(ds, "zeta_u", dp, ch, s, x) for s in ("lind", "skillen"))
        two_se = 2.0 * math.hypot(*(_se(ds, "zeta_u", dp, ch, s, x) for s in ("lind", "skillen")))
        diff = abs(lv - sv)
        if diff <= MARGINAL_U or diff <= RESOLVED * max(lv, sv):
            marginal += 1
        elif max(lv, sv) > 2 * min(lv, sv) and diff - two_se > MARGINAL_U:
            large += 1
        noise = "" if two_se == 0 else (" (difference ± 2 se unknown)" if not np.isfinite(two_se)
                                        else f" (difference {_pct(diff)} ± {_pct(two_se)}, 2 se)")
        parts.append(f"x* = {x:g}: lind {_pct(lv)}, skillen {_pct(sv)}{noise}")
    verdict = ("reproduced" if marginal == st.size else "contradicted" if large else "not reproduced")
    evidence = f"Ch {ch:g}, dp = {_mm(dp)}: " + "; ".join(parts)
    sels = [dict(dp=dp, ch=ch, shifting=s) for s in ("lind", "skillen")]
    return Verdict(claim, verdict, evidence, *_status_note(ds, sels))


def velocity_claim(ds, claim):
    """zeta_u below 5 % at every station and largest at the station nearest the toe, for every
    Ch of the main method at its finest dp (where every station has a value), by the rules of
    the other claims: below only by more than 2 se, and a station larger than the toe's only by
    more than 2 se of the two. Contradicted when, in every Ch, the toe's station is below every
    other by more than 2 se."""
    sh = main_method(ds)
    st = ds["station"].values
    toe = int(np.argmin(st))
    below, toe_largest, toe_smallest, n, parts, sels = 0, 0, 0, 0, [], []
    for ch in ds["ch"].values:
        dps = [_finest_dp(_series(ds, "zeta_u", ch, sh, x)) for x in st]
        if any(d is None for d in dps):
            continue
        dp = max(dps)  # the finest dp where every station has a value
        u = np.array([_value(ds, "zeta_u", dp, ch, sh, x) for x in st])
        se = np.array([_se(ds, "zeta_u", dp, ch, sh, x) for x in st])
        n += 1
        below += bool(np.all(u + 2.0 * se < 0.05))  # an unknown se (NaN) never counts as below
        others = np.delete(np.arange(u.size), toe)
        gap = 2.0 * np.hypot(se[toe], se[others])
        toe_largest += bool(np.all(u[others] - u[toe] <= gap))
        toe_smallest += bool(others.size and np.all(u[others] - u[toe] > gap))
        sels.append(dict(dp=dp, ch=float(ch), shifting=sh))
        parts.append(f"Ch {ch:g} at {_mm(dp)}: " + ", ".join(
            _pct(v) + (f" ± {_pct(2 * e)}" if np.isfinite(e) and e > 0 else "") for v, e in zip(u, se)))
    if n == 0:
        return Verdict(claim, "no data", "no finished run", [], [])
    if below == n and toe_largest == n:
        verdict = "reproduced"
    elif toe_smallest == n:
        verdict = "contradicted"
    else:
        verdict = "not reproduced"
    evidence = (f"{sh}, zeta_u (± 2 se) at x* = " + ", ".join(f"{x:g}" for x in st) + ": " + "; ".join(parts)
                + f". Below 5 % by more than 2 se: {below} of {n} Ch; largest at x* = {st[toe]:g} "
                f"(no other station above it by more than 2 se): {toe_largest} of {n}")
    return Verdict(claim, verdict, evidence, *_status_note(ds, sels))


def verdicts(ds: xr.Dataset) -> list[Verdict]:
    """One verdict per conclusion of the paper, in its order."""
    sh = main_method(ds)
    chs = [float(c) for c in ds["ch"].values if (ds["status"].sel(ch=c, shifting=sh) != "missing").any()]
    return [
        threshold_claim(ds, "zeta_f", 0.01, chs, sh, 3,
                        "zeta_f below 1 % at the finest dp for three Ch"),
        converging_claim(ds, "zeta_h_paper", chs, sh,
                         "zeta_h converges, to about 5 % (against the paper's normalising depth)",
                         about=(0.05, 2.0)),
        converging_claim(ds, "zeta_fs", chs, sh, "zeta_fs converges"),
        velocity_claim(ds, "zeta_u below 5 % at the finest dp, largest near the toe"),
        lind_better_claim(ds, "Lind better than Skillen on zeta_f and zeta_h at Ch = 1.8"),
        marginal_shifting_claim(ds, "the shifting method affects zeta_u only marginally"),
    ]


METRICS = (("zeta_f", None), ("zeta_h", None), ("zeta_h_paper", None), ("zeta_fs", None),
           ("zeta_u", "station"))


def accuracy_rows(ds: xr.Dataset, thresholds=(0.01, 0.05)) -> list[dict]:
    """Per metric (zeta_u per station) and shifting method at the paper's Ch: the cheapest
    steady run meeting each threshold (over every run; with an ensemble, over the grid points,
    each its realisations' mean at a realisation's mean cost; a metric with a sampling error,
    ``case_{var}_se``, meets it only when below by more than 2 se), the GCI limit and band, and the
    dp that the observed order says is needed for 1 %. ``cheapest[thr]`` is None or (case,
    wall time, value, 2 se or None); ``finest_two_se`` is 2 se of the value at the finest dp (0
    where the campaign has no se of the metric, NaN where it could not be measured)."""
    from .pareto import cheapest_meeting
    ch = paper_ch(ds)
    if ensemble_size(ds) > 1:  # a grid point's ensemble mean and se, at a realisation's mean cost
        table, prefix = ds.stack(point=("dp", "ch", "shifting")), ""
        names = table["case_id"].values
    else:  # every run, extra cases included
        table, prefix = ds, "case_"
        names = ds["case"].values
    cost = np.where(table[f"{prefix}steady"].values > 0, table[f"{prefix}wall_time"].values, np.nan)
    rows = []
    for var, dim in METRICS:
        stations = ds["station"].values if dim else [None]
        for x in stations:
            label = var if x is None else f"{var} (x* = {x:g})"
            err = table[f"{prefix}{var}"].values if x is None else table[f"{prefix}zeta_u"].sel(station=x).values
            se_name = f"{prefix}{var}_se"
            two_se = None if se_name not in table else (
                2.0 * table[se_name].values if x is None else 2.0 * table[se_name].sel(station=x).values)
            bound = err if two_se is None else err + two_se  # NaN where the se is unknown
            cheapest = {}
            for thr in thresholds:
                i = cheapest_meeting(cost, bound, thr)
                cheapest[thr] = None if i is None else (str(names[i]), float(cost[i]), float(err[i]),
                                                        None if two_se is None else float(two_se[i]))
            for sh in ds["shifting"].values:
                da = _series(ds, var, ch, sh, x)
                dp = _finest_dp(da)
                rows.append(dict(metric=label, shifting=str(sh), ch=ch, cheapest=cheapest,
                                 extrapolation=extrapolate(da["dp"].values, da.values, 0.01),
                                 finest_two_se=math.nan if dp is None else 2.0 * _se(ds, var, dp, ch, sh, x)))
    return rows
