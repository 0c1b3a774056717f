"""Time integration: drift-kick-drift, one force evaluation a step.

  r^{n+1/2}   = r^n + dt/2 v^n,            rho^{n+1/2} = rho^n + dt/2 (drho/dt)^{n-1/2}
  forces, drho/dt and shifting sums at r^{n+1/2}, rho^{n+1/2} and v^n (first order in time
  for the velocity-dependent terms)
  v^{n+1}     = v^n + dt a^{n+1/2},        rho^{n+1}   = rho^n + dt (drho/dt)^{n+1/2}
  r^{n+1}     = r^{n+1/2} + dt/2 v^{n+1} (+ shifting)
  dt          = C_CFL min(sqrt(h / max|a|), h / (c0 + max|h u_ab.r_ab/(r^2+eta^2)|), h^2 / nu)
"""
from __future__ import annotations

import math

import numba as nb
import numpy as np

DT_LIMITS = ("force", "acoustic", "viscous")


@nb.njit(parallel=True, cache=True)
def drift(x, z, u, w, kind, wall, gx, gz, vwall, moving, c, n):
    """Move fluid by c v and moving-wall particles (and their ghosts) by c v_wall."""
    for i in nb.prange(n):
        if kind[i] == 0:
            x[i] += c * u[i]
            z[i] += c * w[i]
        elif moving[wall[i]]:
            dx = c * vwall[wall[i], 0]
            dz = c * vwall[wall[i], 1]
            x[i] += dx
            z[i] += dz
            gx[i] += dx
            gz[i] += dz


@nb.njit(parallel=True, cache=True)
def wrap_periodic(x, gx, x0, period):
    for i in nb.prange(x.size):
        if x[i] < x0 or x[i] >= x0 + period:
            s = math.floor((x[i] - x0) / period) * period
            x[i] -= s
            gx[i] -= s


@nb.njit(parallel=True, cache=True)
def advance_density(rho, drho, n, c):
    for i in nb.prange(n):
        rho[i] += c * drho[i]


@nb.njit(parallel=True, cache=True)
def kick(u, w, rho, kind, ax, az, drho, drho_prev, n, dt, rho0, clamp_boundary, clamp_fluid):
    """v += dt a (fluid); rho^{n+1} = rho^{n+1/2} + dt (drho - drho_prev / 2); rho floored at
    rho0 for boundary particles (``clamp_boundary``, DBC) and fluid (``clamp_fluid``: no tension)."""
    for i in nb.prange(n):
        rho[i] += dt * (drho[i] - 0.5 * drho_prev[i])
        if kind[i] == 0:
            u[i] += dt * ax[i]
            w[i] += dt * az[i]
            if clamp_fluid and rho[i] < rho0:
                rho[i] = rho0
        elif clamp_boundary and rho[i] < rho0:
            rho[i] = rho0
        drho_prev[i] = drho[i]


def time_step(cfl, h, amax, vmax, c0, nu, viscous_limit=True, cfl_acoustic=None):
    """(dt, index of the limiting term, (dt1, dt2, dt3)) of docs/scheme.md section 6:
    dt = min(C dt1, C_a dt2, C dt3), C = ``cfl``, C_a = ``cfl_acoustic`` (default C, which gives
    C min(dt1, dt2, dt3) as the paper writes it). Without ``viscous_limit`` (an implicit or
    sub-stepped laminar term) dt = min(C dt1, C_a dt2); dt3 is still reported."""
    dt1 = math.sqrt(h / amax) if amax > 0 else math.inf
    dt2 = h / (c0 + vmax)
    dt3 = h * h / nu
    c_nu = cfl if viscous_limit else math.inf
    c_a = cfl if cfl_acoustic is None else cfl_acoustic
    scaled = (cfl * dt1, c_a * dt2, c_nu * dt3)
    k = int(np.argmin(scaled))
    return scaled[k], k, (dt1, dt2, dt3)
