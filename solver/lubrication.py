"""Lubrication (long-wave) theory of a steady viscous front on a belt (docs/scheme.md sections 1, 5).

Belt frame, xi = distance upslope from the toe, eta = h / h_n:
  dh/dxi = tan(theta) (h_n^2 - h^2) / h^2   =>   xi tan(theta) / h_n = atanh(eta) - eta
Velocity in the belt frame at local depth h: u* = 3 (z/h - z^2 / (2 h^2)).
"""
from __future__ import annotations

import math

import numpy as np


def normal_depth(mu: float, u_b: float, rho: float, g: float, theta: float) -> float:
    """h_n = sqrt(3 mu u_b / (rho g sin theta)), theta in radians (paper eq. 13b)."""
    return math.sqrt(3.0 * mu * u_b / (rho * g * math.sin(theta)))


def xi_star(eta, theta: float):
    """x* = xi / h_n of a front depth ratio eta in [0, 1)."""
    eta = np.asarray(eta, dtype=float)
    return (np.arctanh(eta) - eta) / math.tan(theta)


def front_eta(x_star, theta: float):
    """Depth ratio eta = h / h_n at x* = xi / h_n upslope from the toe (inverse of xi_star).

    Solved by Newton iterations on f(eta) = atanh(eta) - eta - x* tan(theta), f' = eta^2/(1-eta^2),
    started from a bracket-safe guess; exact to round-off.
    """
    s = np.atleast_1d(np.asarray(x_star, dtype=float)) * math.tan(theta)
    out = np.zeros_like(s)
    far = s > 15.0  # atanh(eta) - eta = s  =>  eta = tanh(s + 1) to within e^(-2s)
    out[far] = np.tanh(s[far] + 1.0)
    pos = (s > 0) & ~far
    s = s[pos]
    # small s: eta^3/3 ~ s; large s: eta ~ tanh(s + 1)
    eta = np.where(s < 0.3, np.cbrt(3.0 * s), np.tanh(s + 1.0))
    eta = np.clip(eta, 1e-12, 1 - 1e-16)
    for _ in range(100):
        f = np.arctanh(eta) - eta - s
        step = f * (1.0 - eta * eta) / (eta * eta)
        new = np.clip(eta - step, 0.5 * eta, 0.5 * (eta + 1.0))
        if np.all(np.abs(new - eta) <= 1e-15 * np.maximum(1.0, eta)):
            eta = new
            break
        eta = new
    out[pos] = eta
    return out if np.ndim(x_star) else float(out[0])


def front_area_deficit(theta: float) -> float:
    """int_0^inf (1 - eta) dx*: how much less area the front holds than a block at h_n,
    per h_n^2. Equal to (ln 2 - 1/2) / tan(theta)."""
    return (math.log(2.0) - 0.5) / math.tan(theta)


def belt_velocity(z_star_local):
    """u* = u / u_b in the belt frame at height z/h (local depth h): 3 (s - s^2/2)."""
    s = np.asarray(z_star_local, dtype=float)
    return 3.0 * (s - 0.5 * s * s)
