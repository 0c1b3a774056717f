"""Implicit laminar viscosity (``physics.viscous_update: implicit``): backward Euler in the
viscous term, so that the viscous limit dt3 = h^2 / nu no longer bounds the step.

The laminar term of the pair loop is linear in the velocities,

  (L v)_a = - sum_b c_ab (v_a - v_b),   c_ab = -m_b 4 nu_ab (r_ab . gradW_ab) / ((rho_a + rho_b)(r^2 + eta^2)) >= 0,

with the coefficients of the evaluation at r^{n+1/2}, rho^{n+1/2} (and the pair viscosities
nu_ab that the pair loop used). The step's velocity change delta = v^{n+1} - v^n solves

  delta_a + dt sum_b c_ab (delta_a - delta_b) = dt a_a,

where a_a is the pair loop's acceleration (pressure, gravity and L v^n): then
v^{n+1} = v^n + dt (a_other + L v^{n+1}), backward Euler for the viscous term, and a steady
state (delta = 0) is the explicit scheme's. A wall particle b next to fluid particle a changes
its velocity with the fluid: mDBC's no-slip v_b = 2 v_wall - v_ghost follows the fluid at its
ghost node, taken as delta_b = -delta_a, so the pair enters a's diagonal twice
(``wall_factor`` 2); a DBC wall's velocity is imposed, delta_b = 0 (``wall_factor`` 1).
Lagging the wall instead (delta_b = 0 with mDBC) leaves the mirror mode undamped: measured,
the start-up Poiseuille flow diverges at dt = 3.4 dt3. Multiplied by m_a the system is
symmetric positive definite (m_a c_ab = m_a m_b k_ab with k symmetric), and
Jacobi-preconditioned conjugate gradients solve it for both velocity components, starting
from the explicit step delta = dt a.

The coefficients are stored per fluid row in a fixed-width table (``Neighbours``), built by
one pass over the full 3x3 cell stencil of each fluid particle.
"""
from __future__ import annotations

import functools
import math
from typing import NamedTuple

import numba as nb
import numpy as np

from .cells import cell_of, neighbour_cell
from .forces import pair_viscosity
from .kernel import grad_coefficient, grad_factor

TOLERANCE = 1.0e-8  # CG stops when |residual| <= TOLERANCE |right-hand side| (2-norm, each component)
MAX_ITERATIONS = 1000


class Neighbours(NamedTuple):
    """Row a's fluid neighbours b = cols[a, :count[a]] with weights c_ab = wts[a, :count[a]];
    diag[a] = the sum of c_ab over fluid neighbours plus wall_factor times that over walls."""
    cols: np.ndarray   # (n, width) int32
    wts: np.ndarray    # (n, width) float64
    count: np.ndarray  # (n,) int64
    diag: np.ndarray   # (n,) float64


def table_width(ch: float) -> int:
    """Neighbours within 2h of a particle on a lattice, pi (2 Ch)^2, with room for 50 %
    compression (the density guard stops a run long before)."""
    return int(1.5 * math.pi * (2.0 * ch) ** 2) + 8


def allocate(n: int, width: int) -> Neighbours:
    return Neighbours(np.zeros((n, width), dtype=np.int32), np.zeros((n, width)),
                      np.zeros(n, dtype=np.int64), np.zeros(n))


@functools.cache
def make_assembly(variable_viscosity: bool):
    """Compile the coefficient pass; ``variable_viscosity`` takes nu_ab from the particles'
    nu_p as the pair loop does (``forces.pair_viscosity``), otherwise the scene's nu."""

    @nb.njit(cache=True)
    def fill_row(a, x, z, rho, mass, kind, nu_p, nu, h, wall_factor, cl, tab):
        """Row a of ``tab``: its fluid neighbours and weights, count and diagonal."""
        cols, wts = tab.cols, tab.wts
        width = cols.shape[1]
        fac = grad_coefficient(h)
        eta2 = 0.01 * h * h
        four_h2 = 4.0 * h * h
        inv_h = 1.0 / h
        xa, za, ra = x[a], z[a], rho[a]
        ix, iz = cell_of(cl, xa, za)
        k = 0
        d = 0.0
        for ddx in range(-1, 2):
            for ddz in range(-1, 2):
                c, shift = neighbour_cell(cl, ix, iz, ddx, ddz)
                if c < 0:
                    continue
                for b in range(cl.start[c], cl.start[c + 1]):
                    dx = xa - (x[b] + shift)
                    dz = za - z[b]
                    r2 = dx * dx + dz * dz
                    if b == a or r2 >= four_h2:
                        continue
                    F = grad_factor(math.sqrt(r2) * inv_h, fac)
                    kb = kind[b]
                    if variable_viscosity:
                        nu_ab = pair_viscosity(nu_p[a], nu_p[b], kb != 0, True)
                    else:
                        nu_ab = nu
                    cab = -mass[b] * 4.0 * nu_ab * F * r2 / ((ra + rho[b]) * (r2 + eta2))
                    if kb == 0:
                        d += cab
                        if k < width:
                            cols[a, k] = b
                            wts[a, k] = cab
                        k += 1
                    else:
                        d += wall_factor * cab
        tab.count[a] = k
        tab.diag[a] = d

    @nb.njit(parallel=True, cache=True)
    def assemble(x, z, rho, mass, kind, nu_p, nu, h, wall_factor, cl, n_active, tab):
        """Fill ``tab`` (``Neighbours``) for the fluid rows of [0, n_active). A row that does
        not fit the table is truncated and its count exceeds the width: the caller widens the
        table and assembles again."""
        for a in nb.prange(n_active):
            if kind[a] == 0:
                fill_row(a, x, z, rho, mass, kind, nu_p, nu, h, wall_factor, cl, tab)
            else:
                tab.count[a] = 0
                tab.diag[a] = 0.0

    return assemble


@nb.njit(parallel=True, cache=True)
def _apply(tab, mass, kind, dt, px, pz, yx, yz, n):
    """y = A p, A = M (I + dt C) restricted to fluid rows (module docstring)."""
    cols, wts, count, diag = tab.cols, tab.wts, tab.count, tab.diag
    for a in nb.prange(n):
        if kind[a] != 0:
            continue
        sx = 0.0
        sz = 0.0
        for j in range(count[a]):
            b = cols[a, j]
            sx += wts[a, j] * px[b]
            sz += wts[a, j] * pz[b]
        s = 1.0 + dt * diag[a]
        yx[a] = mass[a] * (s * px[a] - dt * sx)
        yz[a] = mass[a] * (s * pz[a] - dt * sz)


@nb.njit(parallel=True, cache=True)
def _dot(kind, ax, bx, az, bz, n):
    sx = 0.0
    sz = 0.0
    for a in nb.prange(n):
        if kind[a] == 0:
            sx += ax[a] * bx[a]
            sz += az[a] * bz[a]
    return sx, sz


WORK_ROWS = 11


@nb.njit(parallel=True, cache=True)
def solve(tab, mass, kind, dt, ax, az, n, tol, max_iterations, work):
    """Overwrite (ax, az) of the fluid rows of [0, n) with delta / dt, delta solving
    M (I + dt C) delta = M dt a by Jacobi-preconditioned CG, for each component; ``work``
    is scratch of shape (WORK_ROWS, >= n).

    Returns (iterations, largest relative residual); the residual exceeds ``tol`` when
    ``max_iterations`` did not suffice."""
    dx, dz, rx, rz, zx, zz, px, pz, qx, qz, pre = (work[0], work[1], work[2], work[3], work[4],
                                                   work[5], work[6], work[7], work[8], work[9],
                                                   work[10])
    bbx = 0.0
    bbz = 0.0
    for a in nb.prange(n):
        if kind[a] == 0:
            dx[a] = dt * ax[a]
            dz[a] = dt * az[a]
            pre[a] = 1.0 / (mass[a] * (1.0 + dt * tab.diag[a]))
            bbx += (mass[a] * dx[a]) ** 2
            bbz += (mass[a] * dz[a]) ** 2
        else:
            dx[a] = dz[a] = pre[a] = px[a] = pz[a] = 0.0
    # r = b - A delta0 with b = M dt a = M delta0
    _apply(tab, mass, kind, dt, dx, dz, qx, qz, n)
    for a in nb.prange(n):
        if kind[a] == 0:
            rx[a] = mass[a] * dx[a] - qx[a]
            rz[a] = mass[a] * dz[a] - qz[a]
            zx[a] = pre[a] * rx[a]
            zz[a] = pre[a] * rz[a]
            px[a] = zx[a]
            pz[a] = zz[a]
    limx = tol * tol * max(bbx, 1e-300)
    limz = tol * tol * max(bbz, 1e-300)
    rzx, rzz = _dot(kind, rx, zx, rz, zz, n)
    rrx, rrz = _dot(kind, rx, rx, rz, rz, n)
    it = 0
    while it < max_iterations and (rrx > limx or rrz > limz):
        _apply(tab, mass, kind, dt, px, pz, qx, qz, n)
        pqx, pqz = _dot(kind, px, qx, pz, qz, n)
        alx = rzx / pqx if rrx > limx and pqx > 0.0 else 0.0
        alz = rzz / pqz if rrz > limz and pqz > 0.0 else 0.0
        for a in nb.prange(n):
            if kind[a] == 0:
                dx[a] += alx * px[a]
                dz[a] += alz * pz[a]
                rx[a] -= alx * qx[a]
                rz[a] -= alz * qz[a]
                zx[a] = pre[a] * rx[a]
                zz[a] = pre[a] * rz[a]
        nzx, nzz = _dot(kind, rx, zx, rz, zz, n)
        bex = nzx / rzx if rzx > 0.0 else 0.0
        bez = nzz / rzz if rzz > 0.0 else 0.0
        for a in nb.prange(n):
            if kind[a] == 0:
                px[a] = zx[a] + bex * px[a]
                pz[a] = zz[a] + bez * pz[a]
        rzx, rzz = nzx, nzz
        rrx, rrz = _dot(kind, rx, rx, rz, rz, n)
        it += 1
    inv_dt = 1.0 / dt
    for a in nb.prange(n):
        if kind[a] == 0:
            ax[a] = dx[a] * inv_dt
            az[a] = dz[a] * inv_dt
    return it, math.sqrt(max(rrx / max(bbx, 1e-300), rrz / max(bbz, 1e-300)))
