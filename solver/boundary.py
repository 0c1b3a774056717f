"""Wall particles: mDBC (English et al. 2021) and plain DBC velocities.

mDBC, for each boundary particle b near fluid, with ghost node g mirrored into the fluid:
first-order corrected interpolation of the fluid density at g,
  [sum W V, sum (r_j - r_g) W V; sum gradW V, sum gradW (r_j - r_g)^T V] [rho_g; grad rho]
      = [sum rho_j W V; sum rho_j gradW V],
(Shepard rho_g where the matrix is near-singular), extrapolated rho_b = rho_g + (r_b - r_g).grad rho
when that is not below rho_g (the wall is never weaker than the fluid at its ghost node),
and floored at rho0 (a wall pushes, never pulls: near a free surface the interpolation
would otherwise give wall tension that draws fluid into the wall);
no-slip velocity v_b = 2 v_wall - v_g with v_g the Shepard-interpolated fluid velocity
(or, as an option, interpolated with the same first-order correction as the density, limited
to the range of the fluid velocities it interpolates and faded to Shepard's value where the
ghost's support is lopsided along the wall: its first moment along the wall, over the Shepard
sum, from 0 to TANGENTIAL_MOMENT_MAX h, as where a free surface meets the wall).
"""
from __future__ import annotations

import functools
import math

import numba as nb
import numpy as np

from .cells import cell_of, column_window, neighbour_cell, neighbour_column
from .forces import FASTMATH
from .kernel import alpha_2d, grad_coefficient, grad_factor, kernel, w_value
from .sources import variant_named

DET_MIN = 1.0e-3  # on the matrix made dimensionless with h
TANGENTIAL_MOMENT_MAX = 0.1  # h: the corrected ghost velocity fades out up to this lopsidedness


def wall_velocities(walls, t: float) -> np.ndarray:
    """(n_walls, 2) imposed velocity of each wall at time t, with its linear ramp."""
    out = np.zeros((max(len(walls), 1), 2))
    for i, w in enumerate(walls):
        if w.ramp_time > 0:
            f = min(max((t - w.ramp_delay) / w.ramp_time, 0.0), 1.0)
        else:
            f = 1.0 if t >= w.ramp_delay else 0.0
        out[i] = f * np.asarray(w.velocity)
    return out


@nb.njit(parallel=True, cache=True)
def dbc_velocity(kind, wall, vwall, u, w, n_active):
    for i in nb.prange(n_active):
        if kind[i] == 1:
            u[i] = vwall[wall[i], 0]
            w[i] = vwall[wall[i], 1]


@nb.njit(inline="always", cache=True)
def _cramer(a00, a01, a02, a10, a11, a12, a20, a21, a22, det, b0, b1, b2):
    """Solution of the 3x3 system A y = b by Cramer's rule, given det A."""
    y0 = (b0 * (a11 * a22 - a12 * a21) - a01 * (b1 * a22 - a12 * b2)
          + a02 * (b1 * a21 - a11 * b2)) / det
    y1 = (a00 * (b1 * a22 - a12 * b2) - b0 * (a10 * a22 - a12 * a20)
          + a02 * (a10 * b2 - b1 * a20)) / det
    y2 = (a00 * (a11 * b2 - b1 * a21) - a01 * (a10 * b2 - b1 * a20)
          + b0 * (a10 * a21 - a11 * a20)) / det
    return y0, y1, y2


@nb.njit(inline="always", cache=True)
def number_density_floor(i, x, z, cl, h, alpha, dp2, rho0, n_lattice):
    """rho0 n_i / n_lattice, n_i = sum_j dp^2 W(r_i - r_j) over every particle (fluid and
    wall, i itself included) around boundary particle i: above rho0 only where particles
    crowd closer than the lattice, i.e. where fluid is pressed into the wall."""
    ix, iz = cell_of(cl, x[i], z[i])
    four_h2 = 4.0 * h * h
    n = 0.0
    for ddx in range(-1, 2):
        for ddz in range(-1, 2):
            c, shift = neighbour_cell(cl, ix, iz, ddx, ddz)
            if c < 0:
                continue
            for j in range(cl.start[c], cl.start[c + 1]):
                dx = x[i] - (x[j] + shift)
                dz = z[i] - z[j]
                r2 = dx * dx + dz * dz
                if r2 < four_h2:
                    n += w_value(math.sqrt(r2) / h, alpha)
    return rho0 * n * dp2 / n_lattice


def lattice_number_density(ch: float) -> float:
    """sum_j dp^2 W(r_j) over a full square lattice around one of its nodes, h = ch dp."""
    m = int(math.ceil(2.0 * ch)) + 1
    i = np.arange(-m, m + 1, dtype=float)
    return float(kernel(np.hypot(*np.meshgrid(i, i)), ch).sum())  # lengths in dp


@functools.cache
def make_mdbc_update(corrected_velocity: bool, no_penetration: bool = False):
    """Compile the mDBC update with the Shepard or the corrected ghost velocity; with
    ``no_penetration`` each boundary density is floored by ``number_density_floor``."""

    def mdbc_update(x, z, u, w, rho, mass, kind, wall, gxs, gzs, vwall, cl, n_active, h, rho0, dp2, n_lattice):
        """Set density and no-slip velocity of every active boundary particle from its ghost.

        v_g is Shepard-interpolated (the paper's), or first-order corrected like the density when
        ``corrected_velocity`` (and the matrix is well conditioned).
        """
        alpha = alpha_2d(h)
        fac = grad_coefficient(h)
        periodic, period, x0 = cl.periodic, cl.period, cl.x0
        four_h2 = 4.0 * h * h
        inv_h = 1.0 / h
        for i in nb.prange(n_active):
            if kind[i] != 1:
                continue
            gx, gz = gxs[i], gzs[i]
            vwx, vwz = vwall[wall[i], 0], vwall[wall[i], 1]
            floor = rho0
            if no_penetration:
                floor = max(rho0, number_density_floor(i, x, z, cl, h, alpha, dp2, rho0, n_lattice))
            if not math.isfinite(gx):
                rho[i] = floor
                u[i] = vwx
                w[i] = vwz
                continue
            if periodic:
                gx = x0 + (gx - x0) % period
            ix, iz = cell_of(cl, gx, gz)
            a00 = a01 = a02 = a10 = a11 = a12 = a20 = a21 = a22 = 0.0
            b0 = b1 = b2 = 0.0
            su = sw = 0.0
            bu1 = bu2 = bw1 = bw2 = 0.0
            umin = wmin = math.inf
            umax = wmax = -math.inf
            for ddx in range(-1, 2):
                jx, shift = neighbour_column(cl, ix, ddx)
                if jx < 0:
                    continue
                j0, j1 = column_window(cl, z, jx, iz, gz - 2.0 * h)
                for j in range(np.uint64(j0), np.uint64(j1)):  # unsigned: no wrap-around on loads
                    if z[j] >= gz + 2.0 * h:
                        break
                    if kind[j] != 0:
                        continue
                    dx = gx - (x[j] + shift)  # r_gj
                    dz = gz - z[j]
                    r2 = dx * dx + dz * dz
                    if r2 >= four_h2:
                        continue
                    q = math.sqrt(r2) * inv_h
                    Wv = w_value(q, alpha)
                    F = grad_factor(q, fac)
                    V = mass[j] / rho[j]
                    WV = Wv * V
                    gxv = F * dx * V
                    gzv = F * dz * V
                    # r_j - r_g = -(dx, dz); unknown gradient scaled by h
                    a00 += WV
                    a01 -= dx * WV * inv_h
                    a02 -= dz * WV * inv_h
                    a10 += gxv * h
                    a11 -= gxv * dx
                    a12 -= gxv * dz
                    a20 += gzv * h
                    a21 -= gzv * dx
                    a22 -= gzv * dz
                    b0 += rho[j] * WV
                    b1 += rho[j] * gxv * h
                    b2 += rho[j] * gzv * h
                    su += u[j] * WV
                    sw += w[j] * WV
                    if corrected_velocity:
                        umin, umax = min(umin, u[j]), max(umax, u[j])
                        wmin, wmax = min(wmin, w[j]), max(wmax, w[j])
                        bu1 += u[j] * gxv * h
                        bu2 += u[j] * gzv * h
                        bw1 += w[j] * gxv * h
                        bw2 += w[j] * gzv * h
            if a00 <= 0.0:
                rho[i] = floor
                u[i] = vwx
                w[i] = vwz
                continue
            det = (a00 * (a11 * a22 - a12 * a21) - a01 * (a10 * a22 - a12 * a20)
                   + a02 * (a10 * a21 - a11 * a20))
            well_posed = abs(det) >= DET_MIN
            if well_posed:
                rg, gdx, gdz = _cramer(a00, a01, a02, a10, a11, a12, a20, a21, a22, det, b0, b1, b2)
                ddxg = x[i] - gx
                if periodic:  # nearest image
                    ddxg -= period * math.floor(ddxg / period + 0.5)
                # extrapolate only outward-increasing density: a pressure that falls into the
                # wall (fluid pushed towards it) would leave the wall weaker than the fluid at
                # its ghost node, and the fluid would walk through it
                rb = max(rg + (ddxg * gdx + (z[i] - gz) * gdz) / h, rg)
            else:
                rb = b0 / a00
            ug = su / a00
            wg = sw / a00
            if corrected_velocity and well_posed:
                # within the range of the fluid velocities it interpolates: no overshoot where
                # the ghost's support is cut by a free surface as well as by the wall
                uc = min(max(_cramer(a00, a01, a02, a10, a11, a12, a20, a21, a22, det, su, bu1, bu2)[0],
                             umin), umax)
                wc = min(max(_cramer(a00, a01, a02, a10, a11, a12, a20, a21, a22, det, sw, bw1, bw2)[0],
                             wmin), wmax)
                # faded towards Shepard where the support is lopsided along the wall
                nx, nz = gx - x[i], gz - z[i]
                nn = math.sqrt(nx * nx + nz * nz)
                fade = 1.0
                if nn > 0.0:
                    mt = abs(a01 * nz - a02 * nx) / (nn * a00)  # first moment along the wall, / h
                    fade = max(0.0, 1.0 - mt / TANGENTIAL_MOMENT_MAX)
                ug += fade * (uc - ug)
                wg += fade * (wc - wg)
            rho[i] = max(rb, floor)  # walls push, never pull: no tension at a wall
            u[i] = 2.0 * vwx - ug
            w[i] = 2.0 * vwz - wg

    return nb.njit(parallel=True, cache=True, fastmath=FASTMATH)(
        variant_named(mdbc_update, (corrected_velocity, no_penetration)))
