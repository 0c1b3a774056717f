"""Volume relaxation: the density of loosely packed interior fluid follows its packing.

Continuity density has no restoring force towards a particle spacing, only towards a change
of it: fluid whose particles stand further apart than their volumes m/rho say keeps its
density and with it its pressure, and the room it takes without mass stays (the conveyor
front's inflation, docs/numerics.md). With the kernel concentration

    C_a = sum_b (m_b / rho_b) W_ab   (fluid and wall particles, a itself included)

which is C_0 = sum_lattice dp^2 W on a lattice of the particles' own volumes (1.0021 at
Ch = 1.8), each step moves an interior fluid particle's density towards its packing,

    rho_a <- rho_a (1 + d),  d = lambda (C_a / C_0 - 1) limited to |d| <= LIMIT,
    lambda = beta c0 dt / h                        (a rate beta c0 / h per second),

so that loose packing (C < C_0) lowers the pressure and draws the particles together, and
crowding raises it. Interior: h |gradC| < GRAD_MAX with the shifting's gradC = sum_b c_b
gradW_ab, c_b b's lattice cell (small inside the fluid, large at a free surface, where
C < C_0 is the truncated kernel, not loose packing).
"""
from __future__ import annotations

import math

import numba as nb

LIMIT = 1.0e-3  # largest relative density change per step
# h |gradC| below which a particle counts as interior (the tank's row 1.5 dp under its
# surface, next to a side wall, has 0.09)
GRAD_MAX = 0.05


@nb.njit(parallel=True, cache=True)
def relax_density(rho, mass, kind, c_sum, gcx, gcz, n_active, alpha, h, c0_lattice, lam):
    """rho_a *= 1 + clip(lam (C_a / C_0 - 1)) for interior fluid particles; c_sum holds
    sum_b V_b W_ab without a's own term V_a W(0) = V_a alpha."""
    for i in nb.prange(n_active):
        if kind[i] != 0 or h * math.sqrt(gcx[i] * gcx[i] + gcz[i] * gcz[i]) >= GRAD_MAX:
            continue
        c = c_sum[i] + mass[i] / rho[i] * alpha
        d = min(max(lam * (c / c0_lattice - 1.0), -LIMIT), LIMIT)
        rho[i] *= 1.0 + d
