"""Herschel-Bulkley rheology: each fluid particle's effective viscosity from its strain rate.

  gamma = sqrt(2 (du/dx)^2 + 2 (dw/dz)^2 + (du/dz + dw/dx)^2)     (sqrt(2 D:D) in 2D)
  mu(gamma) = min(mu_max, tau_y / gamma + K gamma^(n - 1))          (bi-viscous)
  mu(gamma) = min(mu_max, tau_y (1 - exp(-m gamma)) / gamma + K gamma^(n - 1))  (Papanastasiou)

Bingham is n = 1, power law tau_y = 0. The velocity gradient is the SPH sum
grad u_a = sum_b V_b (u_b - u_a) gradW_ab, summed in the pair loop of one step and used in
the next (the viscosity lags one step, first order in time like the velocity terms).
Walls take part in the sum with their mDBC (no-slip) velocities.
"""
from __future__ import annotations

import math

import numba as nb

from .forces import DUX, DUZ, DWX, DWZ


@nb.njit(inline="always", cache=True)
def strain_rate(out, i):
    """gamma of particle i from the gradient sums in ``out`` (module docstring)."""
    ux, uz, wx, wz = out[DUX, i], out[DUZ, i], out[DWX, i], out[DWZ, i]
    s = uz + wx
    return math.sqrt(2.0 * ux * ux + 2.0 * wz * wz + s * s)


@nb.njit(inline="always", cache=True)
def effective_viscosity(gamma, tau_y, K, n, mu_max, m):
    """mu(gamma) of the module docstring; m <= 0 selects the bi-viscous form."""
    if gamma <= 0.0:
        return mu_max
    mu = K * gamma ** (n - 1.0)
    if m > 0.0:
        mu += tau_y * (1.0 - math.exp(-m * gamma)) / gamma
    else:
        mu += tau_y / gamma
    return min(mu, mu_max)


@nb.njit(parallel=True, cache=True)
def update_viscosity(out, kind, nu_p, n_active, rho0, tau_y, K, n, mu_max, m):
    """nu_p[i] = mu(gamma_i) / rho0 for fluid particles from the gradient sums in ``out``;
    returns the largest nu_p (for the viscous time-step limit)."""
    numax = 0.0
    for i in nb.prange(n_active):
        if kind[i] != 0:
            continue
        nu_p[i] = effective_viscosity(strain_rate(out, i), tau_y, K, n, mu_max, m) / rho0
        numax = max(numax, nu_p[i])
    return numax

