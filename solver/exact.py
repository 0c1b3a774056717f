"""Exact solutions of docs/scheme.md section 7, for validation."""
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


def film_rms_error(z, u, depth: float, g_along: float, nu: float) -> float:
    """sqrt(mean (u - u_film(z))^2) / u_film(H): particles' velocity error against ``film``,
    relative to the exact surface velocity g H^2 / (2 nu)."""
    err = np.asarray(u, dtype=float) - film(z, depth, g_along, nu)
    return float(np.sqrt(np.mean(err ** 2)) / (g_along / nu * 0.5 * depth * depth))


def herschel_bulkley_channel(y, L: float, F: float, rho: float, tau_y: float, K: float, n: float):
    """Steady plane Poiseuille flow of a Herschel-Bulkley fluid between plates at y = 0 and
    y = L, body force F per unit mass. The stress grows linearly from the centre,
    tau(s) = rho F s (s = |y - L/2|); it is yielded where tau > tau_y, i.e. s > s0 = tau_y /
    (rho F), and there du/ds = -((rho F s - tau_y) / K)^(1/n), with no slip at s = L/2:
      u(s) = n / (n + 1) / (rho F) ((rho F L/2 - tau_y)^((n+1)/n) - (rho F s - tau_y)^((n+1)/n)) K^(-1/n),
    and the plug |s| <= s0 moves at u(s0). Bingham: n = 1; power law: tau_y = 0."""
    y = np.asarray(y, dtype=float)
    G = rho * F
    s = np.maximum(np.abs(y - L / 2), tau_y / G)
    p = (n + 1) / n
    return n / (n + 1) / G * K ** (-1 / n) * ((G * L / 2 - tau_y) ** p - (G * s - tau_y) ** p)


def herschel_bulkley_film(z, depth: float, g_along: float, rho: float, tau_y: float, K: float, n: float):
    """Steady Herschel-Bulkley film of depth H on an incline, g_along = g sin(theta): yielded
    below h0 = H - tau_y / (rho g_along),
      u(z) = n / (n + 1) (rho g_along / K)^(1/n) (h0^((n+1)/n) - (h0 - z)^((n+1)/n)),
    a plug moving at u(h0) above it."""
    z = np.minimum(np.asarray(z, dtype=float), depth)
    h0 = depth - tau_y / (rho * g_along)
    p = (n + 1) / n
    zz = np.minimum(z, h0)
    return n / (n + 1) * (rho * g_along / K) ** (1 / n) * (h0 ** p - (h0 - zz) ** p)
