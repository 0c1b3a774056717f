"""Run time against error: the Pareto front and the cheapest case meeting a threshold."""
from __future__ import annotations

import numpy as np


def pareto_front(cost, error) -> np.ndarray:
    """Boolean mask of the non-dominated points (lower cost and lower error are better;
    NaN points are never on the front)."""
    cost = np.asarray(cost, dtype=float)
    error = np.asarray(error, dtype=float)
    ok = np.isfinite(cost) & np.isfinite(error)
    front = np.zeros(cost.size, dtype=bool)
    idx = np.where(ok)[0]
    for i in idx:
        dominated = np.any((cost[idx] <= cost[i]) & (error[idx] <= error[i])
                           & ((cost[idx] < cost[i]) | (error[idx] < error[i])))
        front[i] = not dominated
    return front


def cheapest_meeting(cost, error, threshold: float):
    """Index of the cheapest case with error <= threshold, or None."""
    cost = np.asarray(cost, dtype=float)
    error = np.asarray(error, dtype=float)
    ok = np.isfinite(cost) & np.isfinite(error) & (error <= threshold)
    if not ok.any():
        return None
    idx = np.where(ok)[0]
    return int(idx[np.argmin(cost[idx])])
