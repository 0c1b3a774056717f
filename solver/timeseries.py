"""Standard errors of a window's mean and least-squares slope for an autocorrelated series
(steady-state output analysis; pure functions).

A window holds n samples y_1..y_n at equal spacing; its context is the samples before it. With
gamma_k the autocovariance of the series at lag k,

  Var(mean)  = (1/n^2) sum_ij gamma_|i-j| = (1/n) [gamma_0 + 2 sum_{k=1}^{M} (1 - k/n) gamma_k]
  Var(slope) = sum_ij w_i w_j gamma_|i-j|,   w_i = (t_i - tbar) / sum_i (t_i - tbar)^2,

the finite-window forms, which hold however long the correlation is against the window.
gamma_k is estimated from the residuals e about the least-squares line over N samples: the
context where it holds at least n samples, else the context and the window together (so an
event inside the window is judged against what came before it). gamma_k = sum_i e_i e_(i+k) / N
is low by about 2 V / N, V = gamma_0 + 2 sum_{k<=M} gamma_k the long-run variance, because the
line was fitted to the same samples; each gamma_k is raised by that, V solved for with it,
V = V_raw / (1 - 2 (2M + 1) / N). The sum stops at Sokal's window M, the smallest lag with
M >= C tau(M), tau(M) = V / gamma_0 (C = 5, as emcee.autocorr.integrated_time), M < n, and
before the correction exceeds MAX_CORRECTION. A variance below FLOOR times the uncorrelated
series' (anticorrelated samples) is raised to it.

A window alone cannot see a correlation as long as itself: callers pass up to
``steady.context`` s of samples before it (solver/steady.py, study/metrics.py). A context of a
few seconds still reads a 1 s correlation short (the se low by about half with 3 s), and a
transient inside the context widens the se until it leaves it. Particle noise over a faint
wander of seconds (white noise plus 0.3 times an AR(1) of 3 s) stops the sum inside the noise's
correlation and reads the se of the mean at 0.55 of its scatter (docs/metrics.md).
"""
from __future__ import annotations

import math

import numba as nb
import numpy as np

C_SOKAL = 5.0  # Sokal's window: the autocorrelation is summed to M >= C tau(M)
LINE_BIAS = 2.0  # residuals about a fitted line: gamma_k is low by about 2 V / N (module docstring)
FLOOR = 0.25  # a variance is at least this fraction of the uncorrelated series' (anticorrelated samples)
MAX_CORRECTION = 4.0  # the window stops before the correction 1 / (1 - 2 (2M + 1) / N) exceeds this


def window_fits(t, ys, lead: int = 0) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(mean, se of the mean, slope, se of the slope) over each row of ``ys`` (times ``t``),
    the window being the finite samples from index ``lead`` on, the ones before it its context
    (module docstring). NaN with fewer than 3 samples in the window, se 0 where the residuals
    are 0."""
    t = np.ascontiguousarray(t, dtype=float)
    ys = np.ascontiguousarray(np.atleast_2d(np.asarray(ys, dtype=float)))
    return _window_fits(t, ys, int(lead), C_SOKAL)


@nb.njit(cache=True)
def _line(tt, yy, lo, hi):
    """(mean t, mean y, slope, sum (t - tbar)^2) of the least-squares line over [lo, hi)."""
    n = hi - lo
    tm = 0.0
    ym = 0.0
    for i in range(lo, hi):
        tm += tt[i]
        ym += yy[i]
    tm /= n
    ym /= n
    stt = 0.0
    sty = 0.0
    for i in range(lo, hi):
        stt += (tt[i] - tm) ** 2
        sty += (tt[i] - tm) * (yy[i] - ym)
    b = sty / stt if stt > 0.0 else 0.0
    return tm, ym, b, stt


@nb.njit(cache=True)
def _span(tt, yy, e, gam, j, n_all, n, c):
    """Over the samples [j, n_all): residuals e about their least-squares line, their
    autocovariance gam (``_cut``); (M, V, gamma_0, whether the residuals are all 0)."""
    ctm, cym, cb, _ = _line(tt, yy, j, n_all)
    ss = 0.0
    for i in range(j, n_all):
        e[i - j] = yy[i] - cym - cb * (tt[i] - ctm)
        ss += e[i - j] * e[i - j]
    if ss == 0.0:
        return 0, 0.0, 0.0, True
    gam[0] = ss / (n_all - j)
    m_cut, v = _cut(e, gam, n_all - j, n, c)
    return m_cut, v, gam[0], False


@nb.njit(cache=True)
def _cut(e, gam, n_all, n, c):
    """Sokal's window M (< n) over the bias-corrected autocovariance, filling gam[1..M], and the
    long-run variance V = (gamma_0 + 2 sum_{k<=M} gamma_k) / (1 - LINE_BIAS (2M + 1) / N)."""
    s = gam[0]
    v = gam[0]
    m_cut = 0
    for k in range(1, n):
        den = 1.0 - LINE_BIAS * (2.0 * k + 1.0) / n_all
        if den < 1.0 / MAX_CORRECTION:
            break
        g = 0.0
        for i in range(n_all - k):
            g += e[i] * e[i + k]
        gam[k] = g / n_all
        s_k = s + 2.0 * gam[k]
        v_k = s_k / den
        tau = v_k / (gam[0] + LINE_BIAS * v_k / n_all)
        s, v, m_cut = s_k, v_k, k
        if k >= c * tau:
            break
    if m_cut == 0:
        v = gam[0] / (1.0 - LINE_BIAS / n_all)
    return m_cut, max(v, 0.0)


@nb.njit(cache=True, parallel=True)
def _window_fits(t, ys, lead, c):
    rows = ys.shape[0]
    mean = np.full(rows, np.nan)
    se_mean = np.full(rows, np.nan)
    slope = np.full(rows, np.nan)
    se_slope = np.full(rows, np.nan)
    for r in nb.prange(rows):
        tt = np.empty(t.size)
        yy = np.empty(t.size)
        e = np.empty(t.size)
        gam = np.empty(t.size)
        n_all = 0
        n_lead = 0
        for i in range(t.size):
            if np.isfinite(ys[r, i]):
                tt[n_all] = t[i]
                yy[n_all] = ys[r, i]
                n_all += 1
                if i < lead:
                    n_lead += 1
        n = n_all - n_lead
        if n < 3:
            continue
        tm, ym, b, stt = _line(tt, yy, n_lead, n_all)
        if stt <= 0.0:
            continue
        mean[r] = ym
        slope[r] = b
        # the autocovariance: over the context before the window where it holds at least the
        # window's samples, else over the context and the window
        hi = n_lead if n_lead >= n else n_all
        m_cut, v, g0, flat = _span(tt, yy, e, gam, 0, hi, n, c)
        if flat:
            se_mean[r] = 0.0
            se_slope[r] = 0.0
            continue
        shift = LINE_BIAS * v / hi
        var_mean = g0 + shift
        for k in range(1, m_cut + 1):
            var_mean += 2.0 * (1.0 - k / n) * (gam[k] + shift)
        var_mean = max(var_mean, FLOOR * (g0 + shift)) / n
        # slope: sum_ij w_i w_j gamma_|i-j| over the window
        var_b = 0.0
        for k in range(0, m_cut + 1):
            s = 0.0
            for i in range(n_lead, n_all - k):
                s += (tt[i] - tm) * (tt[i + k] - tm)
            var_b += (g0 + shift if k == 0 else 2.0 * (gam[k] + shift)) * s
        var_b /= stt * stt
        var_b = max(var_b, FLOOR * (g0 + shift) / stt)
        se_mean[r] = math.sqrt(var_mean)
        se_slope[r] = math.sqrt(var_b)
    return mean, se_mean, slope, se_slope
