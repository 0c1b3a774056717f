"""Exact solutions of SPEC section 7, for validation."""
from __future__ import annotations

import numpy as np


def hydrostatic_pressure(z, depth: float, rho0: float, g: float):
    """p = rho0 g (H - z)."""
    return rho0 * g * (depth - np.asarray(z))


def poiseuille(y, t: float, L: float, F: float, nu: float, terms: int = 200):
    """Start-up plane Poiseuille flow between plates at y = 0 and y = L, body force F."""
    y = np.asarray(y, dtype=float)
    u = F / (2 * nu) * y * (L - y)
    for n in range(terms):
        k = 2 * n + 1
        u -= (4 * F * L ** 2 / (nu * np.pi ** 3 * k ** 3) * np.sin(k * np.pi * y / L)
              * np.exp(-k ** 2 * np.pi ** 2 * nu * t / L ** 2))
    return u


def couette(y, t: float, L: float, U0: float, nu: float, terms: int = 400):
    """Start-up plane Couette flow, bottom plate at rest, top plate (y = L) at U0."""
    y = np.asarray(y, dtype=float)
    u = U0 * y / L
    for n in range(1, terms + 1):
        u += (2 * U0 / (n * np.pi) * (-1) ** n * np.sin(n * np.pi * y / L)
              * np.exp(-n ** 2 * np.pi ** 2 * nu * t / L ** 2))
    return u


def film(z, depth: float, g_along: float, nu: float):
    """Steady film on an incline: u = (g sin theta / nu)(H z - z^2 / 2)."""
    z = np.asarray(z, dtype=float)
    return g_along / nu * (depth * z - z ** 2 / 2)
