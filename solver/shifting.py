"""Particle shifting from the concentration gradient gradC and the free-surface measure div r.

skillen: dr = -A h |u_a| dt gradC, zero where div r < thr, scaled by (div r - thr)/(2 - thr)
         up to div r = 2, each component clipped to max_shift dp.
lind:    dr = -D gradC, D = A_L h^2 / 2; no shift for particles within 2h of a free-surface
         particle (div r < thr).
Near a wall (n = normalised kernel-weighted sum of the inward normals of the wall particles
in reach) the component of dr pointing into the wall is removed: shifting redistributes
particles along a wall and away from it, never through it.
"""
from __future__ import annotations

import math

import numba as nb
import numpy as np


@nb.njit(inline="always", cache=True)
def _off_wall(dx, dz, nx, nz):
    """Remove the part of (dx, dz) along -n (into the wall) when n is non-zero."""
    nn = math.sqrt(nx * nx + nz * nz)
    if nn > 0.0:
        nx /= nn
        nz /= nn
        d = dx * nx + dz * nz
        if d < 0.0:
            dx -= d * nx
            dz -= d * nz
    return dx, dz


@nb.njit(parallel=True, cache=True)
def skillen_shift(kind, u, w, gcx, gcz, divr, wnx, wnz, n_active, A, h, dt, thr, clip, dx_out, dz_out):
    for i in nb.prange(n_active):
        dx_out[i] = 0.0
        dz_out[i] = 0.0
        if kind[i] != 0 or divr[i] < thr:
            continue
        f = min((divr[i] - thr) / (2.0 - thr), 1.0)
        c = -A * h * math.sqrt(u[i] * u[i] + w[i] * w[i]) * dt * f
        dx_out[i], dz_out[i] = _off_wall(min(max(c * gcx[i], -clip), clip),
                                         min(max(c * gcz[i], -clip), clip), wnx[i], wnz[i])


@nb.njit(parallel=True, cache=True)
def lind_shift(x, z, kind, gcx, gcz, divr, wnx, wnz, start, n_active, ncx, ncz, periodic, period,
               x0, z0, csx, csz, D, h, thr, dx_out, dz_out):
    four_h2 = 4.0 * h * h
    for i in nb.prange(n_active):
        dx_out[i] = 0.0
        dz_out[i] = 0.0
        if kind[i] != 0 or divr[i] < thr:
            continue
        ix = int(math.floor((x[i] - x0) / csx))
        iz = int(math.floor((z[i] - z0) / csz))
        near_surface = False
        for ddx in range(-1, 2):
            jx = ix + ddx
            shift = 0.0
            if jx < 0:
                if not periodic:
                    continue
                jx += ncx
                shift = -period
            elif jx >= ncx:
                if not periodic:
                    continue
                jx -= ncx
                shift = period
            for ddz in range(-1, 2):
                jz = iz + ddz
                if jz < 0 or jz >= ncz:
                    continue
                c = jx * ncz + jz
                for j in range(start[c], start[c + 1]):
                    if kind[j] != 0 or divr[j] >= thr:
                        continue
                    ex = x[i] - (x[j] + shift)
                    ez = z[i] - z[j]
                    if ex * ex + ez * ez < four_h2:
                        near_surface = True
                        break
                if near_surface:
                    break
            if near_surface:
                break
        if not near_surface:
            dx_out[i], dz_out[i] = _off_wall(-D * gcx[i], -D * gcz[i], wnx[i], wnz[i])
