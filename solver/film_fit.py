"""Effective viscosity and bed slip of a film profile (pure functions over arrays).

In the belt frame a uniform film of local depth h on slope theta has
  u*(z*) = 3 (nu / nu_eff) (h* z* - z*^2 / 2) + s,   u* = u / u_b,  z* = z / h_n,
with h_n^2 = 3 nu u_b / (g sin theta) (docs/scheme.md section 5) and s the slip of the fluid on the bed
(0 for no slip). A least-squares quadratic u* = c0 + c1 z* + c2 z*^2 gives
  nu_eff / nu = -3 / (2 c2),   s = c0,
from the curvature alone, whatever the depth: a surface slope adds a pressure gradient that
this ignores (small in the uniform zone: 1 % of the driving per 0.003 h_n per h_n of slope).
"""
from __future__ import annotations

import numpy as np


def fit_film_profile(z_star, u_star, depth_star, margin_star: float):
    """(nu_eff / nu, slip s) from the profile points with margin <= z* <= depth - margin
    (away from the bed and the surface, where the interpolation stencil is one-sided).
    NaN where fewer than 5 finite points remain or the profile is not concave."""
    z = np.asarray(z_star, dtype=float)
    u = np.asarray(u_star, dtype=float)
    ok = np.isfinite(u) & (z >= margin_star) & (z <= depth_star - margin_star)
    if not np.isfinite(depth_star) or ok.sum() < 5:
        return np.nan, np.nan
    c2, c1, c0 = np.polyfit(z[ok], u[ok], 2)
    if not c2 < 0:
        return np.nan, np.nan
    return float(-3.0 / (2.0 * c2)), float(c0)


def fit_series(z_star, velocity, depth, margin_star: float):
    """fit_film_profile over time: velocity (time, z_star), depth (time,) in h_n.
    Returns two arrays (time,): nu_eff / nu and slip."""
    velocity = np.asarray(velocity, dtype=float)
    depth = np.asarray(depth, dtype=float)
    out = np.array([fit_film_profile(z_star, velocity[k], depth[k], margin_star)
                    for k in range(velocity.shape[0])]).reshape(-1, 2)
    return out[:, 0], out[:, 1]
