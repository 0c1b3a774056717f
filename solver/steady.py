"""Steady-state detection on probe time series (pure functions).

Over the trailing window [t_end - window, t_end] each signal is fitted by a straight line
(least squares); the state is steady when every drift is within its tolerance:
  front:    |d x_toe / dt|                  <= front_velocity * u_b
  depth:    |d h_u / dt| * window           <= depth * h_n
  velocity: |d u*_j / dt| * window          <= velocity    (depth-mean u* at each station)
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class SteadyCriteria:
    window: float = 1.0  # s
    front_velocity: float = 0.01  # fraction of u_b
    depth: float = 0.005  # fraction of h_n over the window
    velocity: float = 0.02  # change of station depth-mean u* over the window
    min_time: float = 0.0  # s: not before (e.g. the end of the belt ramp)


def trend(t: np.ndarray, y: np.ndarray) -> float:
    """Least-squares slope dy/dt (NaN if fewer than 3 finite samples)."""
    t = np.asarray(t, dtype=float)
    y = np.asarray(y, dtype=float)
    ok = np.isfinite(y)
    if ok.sum() < 3:
        return np.nan
    t, y = t[ok], y[ok]
    tc = t - t.mean()
    return float((tc * (y - y.mean())).sum() / (tc * tc).sum())


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


def is_steady(t, toe, depth, station_u, crit: SteadyCriteria, u_b: float, h_n: float) -> bool:
    """True when the last ``crit.window`` seconds meet every tolerance (and the samples span
    the whole window, after ``crit.min_time``)."""
    t = np.asarray(t, dtype=float)
    if t.size < 3 or t[-1] - crit.window < max(crit.min_time, t[0]) - 1e-12:
        return False
    d = drifts(t, toe, depth, station_u, crit.window)
    values = (abs(d["front_velocity"]) / u_b, abs(d["depth_change"]) / h_n, d["velocity_change"])
    limits = (crit.front_velocity, crit.depth, crit.velocity)
    return all(np.isfinite(v) and v <= lim for v, lim in zip(values, limits))
