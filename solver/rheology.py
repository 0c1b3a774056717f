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


@nb.njit(inline="always", cache=True)
def strain_rate(out, i, sl):
    """gamma of particle i from the gradient sums in ``out`` (slots ``sl``, module docstring)."""
    ux, uz, wx, wz = out[sl.DUX, i], out[sl.DUZ, i], out[sl.DWX, i], out[sl.DWZ, i]
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


# kappa of the strain-rate correction: the kernel-averaged derivative of a profile u(z) is
# u' + kappa h^2 u''' + ..., kappa = -(1/6) int F z^4 dA / h^2 = 5/36 for the 2D Wendland C2
# kernel (int -F z^2 dA = 1); on the dp lattice at Ch = 1.5 the sum gives 0.1435
SMOOTHING_KAPPA = 5.0 / 36.0
FULL_SUPPORT = 0.95  # support sum_b V_b (-F r^2) / 2 (1 inside the fluid) above which it applies


@nb.njit(parallel=True, cache=True)
def update_viscosity(out, kind, nu_p, n_active, rho0, tau_y, K, n, mu_max, m, gamma_p, kh2, sl):
    """nu_p[i] = mu(gamma_i) / rho0 for fluid particles from the gradient sums in ``out``;
    returns the largest nu_p (for the viscous time-step limit); ``sl``: the pair loop's ``Slots``.

    With ``kh2`` = kappa h^2 > 0 (``fluid.strain_rate_correction``) the kernel smoothing's
    second-order error is removed where the support is full (SUPP >= FULL_SUPPORT):
    gamma_c = max(0, gamma - kappa h^2 lap(gamma)), with lap(gamma) summed in this
    evaluation's pair loop from the previous strain rates (one step behind, like the
    viscosity); ``gamma_p`` keeps this step's uncorrected gamma for the next Laplacian."""
    numax = 0.0
    for i in nb.prange(n_active):
        if kind[i] != 0:
            continue
        g = strain_rate(out, i, sl)
        if kh2 > 0.0:
            gamma_p[i] = g
            if out[sl.SUPP, i] >= FULL_SUPPORT:
                g = max(0.0, g - kh2 * out[sl.LAPG, i])
        nu_p[i] = effective_viscosity(g, tau_y, K, n, mu_max, m) / rho0
        numax = max(numax, nu_p[i])
    return numax
