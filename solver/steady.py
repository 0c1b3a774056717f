"""Steady state from the probe series: a run is steady once every quantity it reports holds
still to within its own sampling error, or within a small fraction of its value (pure functions).

Quantities, each a set of components sampled every probe interval:

  toe      the toe's distance from the upstream wall (zeta_f)         1 component
  depth    the uniform depth h_u / h_n (zeta_h)                      1 component
  surface  the free surface z / h_n at each x* in [0, uniform_zone[1]] (zeta_fs)
  station  u* at each z* of one station (zeta_u), one quantity a station

A window pair is an averaging window A = [t - 2W, t - W] and a hold-out window B = (t - W, t].
Over each window every component y_i gets a least-squares line: mean m_i with standard error
s_i, slope b_i with standard error sb_i, both from the series' autocorrelation over the
``context`` s before the window (solver.timeseries.window_fits: samples from min_time on; the
window's own only where fewer than a window's samples precede it). Each component's two
drifts, over its allowance:

  hold-out change  d_i = (m_B,i - m_A,i) / max(Z sqrt(s_A,i^2 + s_B,i^2), f |m_A,i|)
  fitted change    e_i = b_A,i W / max(Z sb_A,i W, f |m_A,i|)

Z = 2, f = steady.fraction. A quantity's ratios are R_D = rms_i d_i and R_F = rms_i e_i over
the components measured in both windows (none: the quantity fails); the pair is steady when
every R is at most 1. The toe's fitted change is its mean velocity over A times W: with a fixed
volume of fluid, a front that
creeps by a fraction of the layer's length thins the layer by that fraction, which the same
fraction of the depth bounds. A pair is judged every JUDGE_EVERY s from min_time + 2W on; the
first that is steady ends the run; its A is the averaging window and its B the hold-out.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .timeseries import window_fits

Z = 2.0  # standard errors a drift may reach before it counts as real
JUDGE_EVERY = 0.1  # s of simulated time between the pairs judged (each reads up to 2W + context of samples)


@dataclass
class SteadyCriteria:
    window: float = 3.0  # W [s]: the averaging window and the hold-out window, each
    fraction: float = 5.0e-4  # f: a drift below f times the quantity's value passes however small its se
    min_time: float = 0.0  # s: earliest start of the averaging window
    context: float = 15.0  # s of samples before each window (never before min_time) in its se


@dataclass
class Record:
    """The probe series the detector reads, over time (axis 0)."""
    t: np.ndarray  # (n,) s
    toe: np.ndarray  # (n,) m
    depth: np.ndarray  # (n,) h_u / h_n
    surface: np.ndarray  # (n, nx) z / h_n over x* in [0, uniform_zone[1]]
    stations: np.ndarray  # (n, ns, nz) u*

    def span(self, start: float, end: float = math.inf) -> Record:
        """The samples from ``start`` to ``end``."""
        i = int(np.searchsorted(self.t, start - 1e-9))
        j = int(np.searchsorted(self.t, end + 1e-9, side="right"))
        return Record(self.t[i:j], self.toe[i:j], self.depth[i:j], self.surface[i:j], self.stations[i:j])


@dataclass
class Judgement:
    """One window pair: for each quantity, (R_D, R_F); steady when every one is at most 1."""
    t_end: float
    window: float
    drifts: dict = field(default_factory=dict)

    @property
    def ratios(self) -> dict:
        """Each quantity's larger drift over its allowance (NaN: not measurable)."""
        return {q: max(d, f) if math.isfinite(d) and math.isfinite(f) else math.nan
                for q, (d, f) in self.drifts.items()}

    @property
    def steady(self) -> bool:
        return bool(self.drifts) and all(math.isfinite(r) and r <= 1.0 for r in self.ratios.values())

    @property
    def averaging(self) -> tuple[float, float]:
        return self.t_end - 2.0 * self.window, self.t_end - self.window

    @property
    def holdout(self) -> tuple[float, float]:
        return self.t_end - self.window, self.t_end

    def describe(self) -> str:
        """The quantities that drift, by how much of their allowance."""
        bad = [f"{q} {r:.1f}x" if math.isfinite(r) else f"{q} not measurable"
               for q, r in self.ratios.items() if not (math.isfinite(r) and r <= 1.0)]
        a0, a1 = self.averaging
        span = f"window {a0:.2f}-{a1:.2f} s against its hold-out to {self.t_end:.2f} s"
        return f"{span}: drift / allowance " + ", ".join(bad) if bad else f"{span}: steady"


def line_fits(t, ys, lead: int = 0) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(mean, se of the mean, slope, se of the slope) of each row of ys (times t) over its
    finite samples from index ``lead`` on, the ``lead`` samples before them the context of
    their standard errors (solver.timeseries.window_fits)."""
    return window_fits(t, ys, lead)


def trend_bound(t, y) -> tuple[float, float]:
    """(slope, its standard error) of the least-squares line of y(t) (``line_fits``)."""
    _, _, b, sb = line_fits(t, np.asarray(y, dtype=float)[None, :])
    return float(b[0]), float(sb[0])


def trend(t, y) -> float:
    """Least-squares slope dy/dt (NaN with fewer than 3 finite samples)."""
    return trend_bound(t, y)[0]


FRONT_VELOCITY_SPAN = 1.0  # s: zeta_f's toe velocity is averaged over one second (docs/scheme.md section 4)


def front_velocity_fit(t, toe, context: float = 0.0) -> tuple[float, float]:
    """(toe slope, its standard error) over the last FRONT_VELOCITY_SPAN of the samples, the
    ``context`` s of samples before that second joining the se (``line_fits``): the front
    velocity of zeta_f and its sampling error."""
    t = np.asarray(t, dtype=float)
    t0 = t[-1] - FRONT_VELOCITY_SPAN - 1e-9
    use = t >= t0 - context
    lead = int((use & (t < t0)).sum())
    _, _, b, sb = line_fits(t[use], np.asarray(toe, dtype=float)[use][None, :], lead)
    return float(b[0]), float(sb[0])


def _drift_ratios(t, y, a, b, lead_a, lead_b, window: float, fraction: float) -> tuple[float, float]:
    """(R_D, R_F) of a quantity whose components are the columns of y (times t): window A is the
    samples a, its context lead_a and a; B is b, its context lead_b and b (module docstring),
    over the components measured in both windows."""
    ia, ib = np.concatenate([lead_a, a]), np.concatenate([lead_b, b])
    ma, sa, ba, sba = line_fits(t[ia], y[ia].T, lead_a.size)
    mb, sb, _, _ = line_fits(t[ib], y[ib].T, lead_b.size)
    ok = np.isfinite(ma) & np.isfinite(mb) & np.isfinite(sa) & np.isfinite(sb) & np.isfinite(ba)
    if not ok.any():
        return math.nan, math.nan
    floor = fraction * np.abs(ma[ok])
    with np.errstate(divide="ignore", invalid="ignore"):
        r_d = (mb[ok] - ma[ok]) / np.maximum(Z * np.hypot(sa[ok], sb[ok]), floor)
        r_f = ba[ok] * window / np.maximum(Z * sba[ok] * window, floor)
    r_d = np.where((mb[ok] == ma[ok]), 0.0, r_d)  # 0 / 0: no drift
    r_f = np.where(ba[ok] == 0.0, 0.0, r_f)
    return float(np.sqrt(np.mean(r_d * r_d))), float(np.sqrt(np.mean(r_f * r_f)))


def judge(rec: Record, t_end: float, crit: SteadyCriteria) -> Judgement:
    """The window pair ending at ``t_end``: A = [t_end - 2W, t_end - W], B = (t_end - W, t_end];
    each window's se also reads the ``crit.context`` s of samples before it, from min_time on.
    Not judged (no drifts: not steady) with fewer than 8 samples in A or 4 in B."""
    w, f, eps = crit.window, crit.fraction, 1e-9
    out = Judgement(t_end, w)
    t = rec.t
    in_a = np.flatnonzero((t >= t_end - 2.0 * w - eps) & (t <= t_end - w + eps))
    in_b = np.flatnonzero((t > t_end - w + eps) & (t <= t_end + eps))
    if in_a.size < 8 or in_b.size < 4:
        return out
    lo = crit.min_time - eps
    lead_a = np.flatnonzero((t >= max(lo, t_end - 2.0 * w - crit.context - eps)) & (t < t_end - 2.0 * w - eps))
    lead_b = np.flatnonzero((t >= max(lo, t_end - w - crit.context - eps)) & (t <= t_end - w + eps))
    quantities = {"toe": rec.toe[:, None], "depth": rec.depth[:, None], "surface": rec.surface}
    quantities.update({f"station {k + 1}": rec.stations[:, k] for k in range(rec.stations.shape[1])})
    for q, y in quantities.items():
        out.drifts[q] = _drift_ratios(t, y, in_a, in_b, lead_a, lead_b, w, f)
    return out


class SteadyDetector:
    """Judges the window pair ending at a probe time every JUDGE_EVERY s from max(crit.min_time,
    first sample) + 2W on; the first steady pair is the run's (``found``)."""

    def __init__(self, crit: SteadyCriteria):
        self.crit = crit
        self.found: Judgement | None = None
        self.last: Judgement | None = None  # the latest pair judged
        self.next_judgement = -math.inf
        self.t_first = math.nan  # the record's first sample time

    @property
    def t_steady(self) -> float:
        """Start of the averaging window (NaN: not steady yet)."""
        return self.found.averaging[0] if self.found is not None else math.nan

    @property
    def earliest_end(self) -> float:
        """The first probe time a pair may end at."""
        return max(self.crit.min_time, self.t_first) + 2.0 * self.crit.window

    def update(self, rec: Record) -> bool:
        """Judge the pair ending at the record's last sample (after the first call, the record
        needs to hold only the last 2W); True once a pair has been steady."""
        if rec.t.size and math.isnan(self.t_first):
            self.t_first = float(rec.t[0])
        due = rec.t.size and rec.t[-1] >= max(self.earliest_end, self.next_judgement) - 1e-9
        if self.found is None and due:
            self.next_judgement = float(rec.t[-1]) + JUDGE_EVERY
            j = judge(rec, float(rec.t[-1]), self.crit)
            self.last = j
            if j.steady:
                self.found = j
        return self.found is not None
