"""Steady-state detection on probe time series (pure functions).

Over the trailing window [t_end - window, t_end] each signal y(t) is fitted by a straight
line (least squares). Its drift over the window, |slope| * window, must be below the
signal's tolerance with confidence: the upper bound |slope| + Z * se(slope) of the drift
rate, times the window, must not exceed it. se(slope) comes from the fit's residuals,
widened for their correlation from sample to sample (effective sample count
n (1 - r1) / (1 + r1), r1 the lag-1 autocorrelation of the residuals, r1 >= 0). So a trend
is weighed against the signal's own sampling noise: noise alone lengthens the time to
detection. (A lag-1 estimate understates slow wander: with a 3 s correlation time, a drift
of 1.25 times the tolerance passed in 3 of 40 synthetic series; twice it in none.)

Verification: once detected at t_s, the averaging window [t_s, t_s + average] must itself
meet the tolerances (1 se: the detection was already confident). A window that fails there
without a confident drift (every signal's lower bound |slope| - 2 se within its tolerance)
is too noisy to judge, not drifting: it is extended, and the longer window must then pass
at 2 se, up to the longest detection span (SPANS[-1] windows). A confident drift at the
nominal end, or a window that reaches that length without passing, withdraws the detection.

Signals: the equivalent front (front), the uniform depth (depth) and one equivalent front
from each station (station): x_s + (fluid area downstream of x_s) / h_n, x_s fixed in the lab
frame. A steady front holds every one of them; together they hold the areas between the
stations, a coarse measure of the front's shape (the tip's shape within the nearest station
they do not resolve: the case's min_time leaves out its relaxation after the start). A
station's depth-mean velocity is the time derivative of that area, q / h: the same balance,
with the particles' flux noise undamped.

Tolerances (the probes of a coarse run fluctuate by a fraction of dp, so a tolerance fixed
in h_n or u_b alone cannot be met at every dp):
  front, station: drift <= max(front_velocity * u_b * window, NOISE_DP * dp)
  depth:          drift <= max(depth * h_n, NOISE_DP * dp)
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numba as nb
import numpy as np

Z = 2.0  # detection: confidence multiplier on the slope's standard error
VERIFY_Z = 1.0  # verification of an averaging window (detection already was confident)
NOISE_DP = 0.1  # fraction of dp a surface or toe probe may drift over a window, at any dp


@dataclass
class SteadyCriteria:
    window: float = 1.0  # s
    front_velocity: float = 0.01  # fraction of u_b
    depth: float = 0.005  # fraction of h_n over the window
    min_time: float = 0.0  # s: not before (e.g. the end of the belt ramp)
    dp: float = 0.0  # m: particle spacing, for the noise floor of the tolerances


def trend(t: np.ndarray, y: np.ndarray) -> float:
    """Least-squares slope dy/dt (NaN if fewer than 3 finite samples)."""
    return trend_bound(t, y)[0]


def trend_bound(t, y) -> tuple[float, float]:
    """(slope, standard error of the slope) of the least-squares line, the error widened
    for lag-1 correlation of the residuals; NaNs if fewer than 3 finite samples."""
    slope, se = trend_bounds(t, np.asarray(y, dtype=float)[None, :])
    return float(slope[0]), float(se[0])


def trend_bounds(t, ys, first: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """``trend_bound`` of each row of ys over the samples from index ``first`` on (times t),
    each row over its finite samples."""
    t = np.ascontiguousarray(t, dtype=float)
    ys = np.ascontiguousarray(np.atleast_2d(np.asarray(ys, dtype=float)))
    return _line_fits(t, ys, first)


@nb.njit(cache=True)
def _line_fits(t, ys, first):
    """The kernel of ``trend_bounds``: per row, the least-squares slope b over its finite
    samples (t_i, y_i), its residuals e_i, ss = sum e_i^2, r1 = sum e_i e_(i+1) / ss clipped
    to [0, 0.95], n_eff = max(n (1 - r1) / (1 + r1), 3) and se = sqrt(ss / (n - 2) / stt * n / n_eff)
    (0 with fewer than 4 samples or ss = 0; NaN with fewer than 3 or stt = 0)."""
    rows = ys.shape[0]
    slope = np.full(rows, np.nan)
    se = np.full(rows, np.nan)
    tt = np.empty(t.size)
    yy = np.empty(t.size)
    for r in range(rows):
        n = 0
        for i in range(first, t.size):
            if np.isfinite(ys[r, i]):
                tt[n] = t[i]
                yy[n] = ys[r, i]
                n += 1
        if n < 3:
            continue
        tm = 0.0
        ym = 0.0
        for i in range(n):
            tm += tt[i]
            ym += yy[i]
        tm /= n
        ym /= n
        stt = 0.0
        sty = 0.0
        for i in range(n):
            stt += (tt[i] - tm) ** 2
            sty += (tt[i] - tm) * (yy[i] - ym)
        if stt <= 0.0:
            continue
        b = sty / stt
        slope[r] = b
        ss = 0.0
        s1 = 0.0
        prev = 0.0
        for i in range(n):
            e = yy[i] - ym - b * (tt[i] - tm)
            ss += e * e
            if i > 0:
                s1 += e * prev
            prev = e
        if n < 4 or ss == 0.0:
            se[r] = 0.0
            continue
        r1 = min(max(s1 / ss, 0.0), 0.95)
        n_eff = max(n * (1.0 - r1) / (1.0 + r1), 3.0)
        se[r] = math.sqrt(ss / (n - 2) / stt * (n / n_eff))
    return slope, se


FRONT_VELOCITY_SPAN = 1.0  # s: zeta_f's toe velocity is averaged over one second (docs/scheme.md section 4)


def front_velocity_fit(t, toe) -> tuple[float, float]:
    """(toe slope, its standard error) over the last FRONT_VELOCITY_SPAN of the samples
    (``trend_bound``): the front velocity of zeta_f and its sampling error."""
    t = np.asarray(t, dtype=float)
    last = t >= t[-1] - FRONT_VELOCITY_SPAN - 1e-9
    return trend_bound(t[last], np.asarray(toe, dtype=float)[last])


def window_mask(t: np.ndarray, t_end: float, window: float) -> np.ndarray:
    return (t >= t_end - window - 1e-12) & (t <= t_end + 1e-12)


def drifts(t, toe, depth, station_u, window: float) -> dict[str, float]:
    """Trend of each signal over the last ``window`` seconds of the samples.

    Returns front velocity [m/s] (toe slope), depth change over the window [m], and the
    largest change over the window of the station depth-mean velocities [u*]."""
    t = np.asarray(t, dtype=float)
    m = window_mask(t, t[-1], window)
    su = np.asarray(station_u, dtype=float).reshape(len(t), -1)
    return {
        "front_velocity": trend(t[m], np.asarray(toe)[m]),
        "depth_change": trend(t[m], np.asarray(depth)[m]) * window,
        "velocity_change": max(abs(trend(t[m], su[m, j]) * window) for j in range(su.shape[1])),
    }


def tolerances(crit: SteadyCriteria, u_b: float, h_n: float) -> dict[str, float]:
    """Allowed drift over one window of each signal (see the module docstring)."""
    floor = NOISE_DP * crit.dp
    front = max(crit.front_velocity * u_b * crit.window, floor)
    return {"front": front, "depth": max(crit.depth * h_n, floor), "station": front}


def assess(t, front, depth, stations, crit: SteadyCriteria, u_b: float, h_n: float,
           t_start: float | None = None, z: float = Z) -> dict:
    """Confident drift bounds against tolerances over [t_start, t_end] (default: the
    trailing ``crit.window``). Drift bounds are scaled to the span of ``crit.window``, so a
    longer span (an averaging window) is judged by the same rates.

    Returns {"steady": bool, "ratio": {signal: upper bound / tolerance} (ratio <= 1
    passes), "lower": {signal: (|slope| - Z se) * window / tolerance} (> 1: a confident
    drift beyond the tolerance)}."""
    t, ys, names = _signals(t, front, depth, stations)
    start = t[-1] - crit.window if t_start is None else t_start
    return _assess(t, ys, names, start, crit, tolerances(crit, u_b, h_n), z)


def _signals(t, front, depth, stations) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """The times (ascending) and the signals as rows: front, depth, each station's front."""
    t = np.asarray(t, dtype=float)
    sf = np.asarray(stations, dtype=float).reshape(len(t), -1)
    ys = np.vstack([np.asarray(front, dtype=float), np.asarray(depth, dtype=float), sf.T])
    return t, ys, ["front", "depth"] + ["station"] * sf.shape[1]


def _assess(t, ys, names, start, crit, tol, z) -> dict:
    """``assess`` over the samples from ``start`` on, of the rows of ``_signals``."""
    slopes, ses = trend_bounds(t, ys, int(np.searchsorted(t, start - 1e-12)))
    ratio = {"front": 0.0, "depth": 0.0, "station": 0.0}
    lower = dict(ratio)
    for name, s, se in zip(names, slopes.tolist(), ses.tolist()):
        if math.isnan(s) or math.isnan(ratio[name]):
            ratio[name] = lower[name] = math.nan
            continue
        ratio[name] = max(ratio[name], (abs(s) + z * se) * crit.window / tol[name])
        lower[name] = max(lower[name], (abs(s) - Z * se) * crit.window / tol[name])
    ok = all(v <= 1.0 for v in ratio.values())  # False for NaN
    return {"steady": bool(ok), "ratio": ratio, "lower": lower}


# trailing spans tried, in windows: a longer span resolves a noisier trend. Every whole number
# of windows up to 8, so that a noisy signal is declared at the first span long enough to
# resolve its noise (not at the next power of two); the spans are nested, each containing the
# shorter ones, so their fits are strongly correlated and trying all of them raises the
# chance that a drift beyond its tolerance passes only a little (tests/test_steady.py)
SPANS = tuple(range(1, 9))


def is_steady(t, front, depth, stations, crit: SteadyCriteria, u_b: float, h_n: float) -> bool:
    """True when a trailing span of SPANS windows, after ``crit.min_time``, meets every
    tolerance with confidence. A noisy signal needs a longer span to show that its drift
    is small; a real drift fails on every span."""
    t = np.asarray(t, dtype=float)
    if t.size < 3:
        return False
    first = max(crit.min_time, t[0])
    t, ys, names = _signals(t, front, depth, stations)
    tol = tolerances(crit, u_b, h_n)
    for k in SPANS:
        start = t[-1] - k * crit.window
        if start < first - 1e-12:
            break
        if _assess(t, ys, names, start, crit, tol, Z)["steady"]:
            return True
    return False


class SteadyTracker:
    """Steady detection followed by verification of the averaging window.

    ``update`` takes the probe series so far. Once ``is_steady`` fires at t_s the run
    averages over [t_s, t_s + average]; when that window is complete it must itself meet
    the tolerances (``judge_window``). A window too noisy to judge is extended (``t_end``
    moves on); a drifting one is withdrawn (recorded in ``rejected``) and detection starts
    again. States: "transient", "averaging", "steady". A steady window is [t_steady, t_end].
    """

    def __init__(self, crit: SteadyCriteria, u_b: float, h_n: float, average: float):
        self.crit, self.u_b, self.h_n, self.average = crit, u_b, h_n, average
        self.t_steady = math.nan
        self.t_end = math.nan  # end of the verified averaging window
        self.rejected: list[tuple[float, float]] = []  # (detected at, withdrawn at)

    @property
    def max_average(self) -> float:
        """The longest an averaging window may be extended to."""
        return max(self.average, SPANS[-1] * self.crit.window)

    def update(self, t, front, depth, stations) -> str:
        t_end = float(np.asarray(t)[-1])
        if math.isnan(self.t_steady):
            if is_steady(t, front, depth, stations, self.crit, self.u_b, self.h_n):
                self.t_steady = t_end
                return "averaging"
            return "transient"
        if t_end < self.t_steady + self.average - 1e-9:
            return "averaging"
        verdict = self.judge_window(t, front, depth, stations, self.t_steady)
        if verdict == "steady":
            self.t_end = t_end
            return "steady"
        if verdict != "drift" and t_end < self.t_steady + self.max_average - 1e-9:
            return "averaging"  # too noisy to judge yet: the window is extended
        self.rejected.append((self.t_steady, t_end))
        self.t_steady = math.nan
        return "transient"

    def judge_window(self, t, front, depth, stations, t_start: float) -> str:
        """The averaging window from t_start to the last sample: "steady" when it meets the
        tolerances (the nominal window at 1 se, an extended one at 2 se); otherwise, at the
        nominal end, "drift" when a signal's drift exceeds its tolerance with confidence
        (lower bound |slope| - 2 se) and "noisy" when none does; past it, "extended"."""
        t = np.asarray(t, dtype=float)
        extended = t.size > 1 and t[-2] >= t_start + self.average - 1e-9  # past its nominal end
        r = assess(t, front, depth, stations, self.crit, self.u_b, self.h_n, t_start=t_start,
                   z=Z if extended else VERIFY_Z)
        if r["steady"]:
            return "steady"
        if extended:
            return "extended"
        return "noisy" if all(np.isfinite(v) and v <= 1.0 for v in r["lower"].values()) else "drift"

    def verify(self, t, front, depth, stations, t_start: float) -> bool:
        """Whether the samples from t_start on meet the tolerances (a fixed-end window, 1 se)."""
        return assess(t, front, depth, stations, self.crit, self.u_b, self.h_n, t_start=t_start,
                      z=VERIFY_Z)["steady"]
