"""Particle shifting from the concentration gradient gradC and the free-surface measure div r.

skillen: dr = -A h |u_a| dt gradC, zero where div r < thr, scaled by (div r - thr)/(2 - thr)
         up to div r = 2, each component clipped to MAX_SHIFT dp. With ``min_speed`` > 0 the
         speed is max(|u_a|, min_speed) where no wall particle is within 2h: |u_a| depends on
         the frame, and where the lab-frame velocity passes through zero inside a sheared layer
         the paper's shift vanishes while the shear keeps disordering the particles. Within reach of
         a wall the paper's |u_a| stays: slow fluid there is a stagnant corner (a free surface
         against a wall), which a floored shift pulls apart (docs/numerics.md, "Skillen's speed
         floor").
lind:    dr = -D gradC, D = A_L h^2 / 2, each component clipped to MAX_SHIFT dp; no shift for
         particles within 2h of a free-surface particle (div r < thr, or a scan-region test
         where thr <= div r < 1.9, see free_surface). With ``near_surface: tangential``
         (Lind et al. 2012) those particles shift too, by the part of gradC along the surface
         only: dr = -D (gradC - (gradC.n) n), n the weighted mean of the outward normals
         -gradC/|gradC| of the free-surface particles within 2h (``surface_normals``), except
         the free-surface particles within 2h of a wall (where the surface meets a wall: no
         shift, as the paper).
Density correction (default on): shifting moves particles relative to the fluid, so each
particle's volume changes by V div(dr); with its mass fixed its density becomes
rho (1 - div(dr)), div(dr)_a = sum_b V_b (dr_b - dr_a).gradW_ab, summed in the next
step's pair loop and applied after it (``limit_correction``). Without it, shifting that
spreads particles near a free surface inflates the fluid at constant density (measured on
the periodic film: +2.1 % area in 1 s with skillen; on the paper case at dp = 1 mm with
lind, +2 % of enclosed area by t = 2.1 s). Lind relocates particles by up to 0.1 dp every
step, as fast as the flow compresses them: a correction that followed each relocation in
full would reset the density and erase the compression the pressure needs (a channel at
rest then grows round-off into a 10 % density error in 454 steps). For lind the correction
of one step is therefore limited to |div(dr)| <= 1e-3 (``correction_limit``): the slow
spreading it exists for (median |div(dr)| 6e-6 per step on the paper case) is corrected in
full, the tail of fast relocations (0.02-0.1 % of particle-steps) is not.
Near a wall (n = kernel-weighted sum sum_b -F_ab n_b of the inward normals of the wall
particles in reach) the component of dr pointing into the wall is removed once the particle
is as close as the lattice puts it (|n| at least its value dp/2 from a flat wall): shifting
redistributes particles along a wall and away from it, never through it.
"""
from __future__ import annotations

import math

import numba as nb
import numpy as np

from .cells import cell_of, column_window, neighbour_cell, neighbour_column
from .kernel import grad_coefficient


def wall_proximity_at_half_dp(h: float, dp: float) -> float:
    """|sum_b -F(r_ab) n_b| for a particle dp/2 from a flat wall of lattice particles: the
    wall-normal sum of a fluid particle sitting where the lattice puts it."""
    fac = grad_coefficient(h)
    n = int(math.ceil(2 * h / dp)) + 1
    i = np.arange(-n, n + 1)
    X, K = np.meshgrid(i * dp, (np.arange(n) + 0.5) * dp + 0.5 * dp)
    r = np.hypot(X, K)
    q = np.clip(r / h, 0.0, 2.0)
    return float((-fac * (1 - 0.5 * q) ** 3).sum())


@nb.njit(inline="always", cache=True)
def _off_wall(dx, dz, nx, nz, s0):
    """Remove the part of (dx, dz) along -n (into the wall) when the particle is at least as
    close to the wall as the lattice puts it (|n| >= s0)."""
    nn = math.sqrt(nx * nx + nz * nz)
    if nn >= s0 and nn > 0.0:
        nx /= nn
        nz /= nn
        d = dx * nx + dz * nz
        if d < 0.0:
            dx -= d * nx
            dz -= d * nz
    return dx, dz


@nb.njit(parallel=True, cache=True)
def skillen_shift(kind, u, w, gcx, gcz, divr, wnx, wnz, s0, n_active, A, h, dt, thr, clip, min_speed,
                  dx_out, dz_out):
    """dr = -A h s dt f gradC, f = min((div r - thr) / (2 - thr), 1), zero below thr, each
    component clipped, never into a wall (``_off_wall``); s = max(|u|, min_speed) where no
    wall particle is within reach (the kernel-weighted wall-normal sum is zero), else |u|."""
    for i in nb.prange(n_active):
        dx_out[i] = 0.0
        dz_out[i] = 0.0
        if kind[i] != 0 or divr[i] < thr:
            continue
        f = min((divr[i] - thr) / (2.0 - thr), 1.0)
        speed = math.sqrt(u[i] * u[i] + w[i] * w[i])
        if wnx[i] == 0.0 and wnz[i] == 0.0:
            speed = max(speed, min_speed)
        c = -A * h * speed * dt * f
        dx_out[i], dz_out[i] = _off_wall(min(max(c * gcx[i], -clip), clip),
                                         min(max(c * gcz[i], -clip), clip), wnx[i], wnz[i], s0)


SCAN_UPPER = 1.9  # div r below this (and above the threshold): apply the scan-region test


@nb.njit(parallel=True, cache=True)
def free_surface(x, z, kind, gcx, gcz, divr, cl, n_active, h, thr, upper, flag):
    """flag[i] = 1 for free-surface fluid particles: div r < thr, or thr <= div r < upper and
    the scan region of Marrone et al. (2010) is empty. With n = -gradC/|gradC| the outward
    normal and T = r_i + h n, a neighbour j (fluid or wall) occupies it when
    |r_j - r_i| >= sqrt(2) h and |r_j - T| < h, or |r_j - r_i| < sqrt(2) h and
    |n.(r_j - T)| + |t.(r_j - T)| < h. This catches surfaces that a wall inside the kernel
    hides from div r, such as the wedge of a front on the bed."""
    four_h2 = 4.0 * h * h
    two_h2 = 2.0 * h * h
    for i in nb.prange(n_active):
        flag[i] = 0
        if kind[i] != 0:
            continue
        if divr[i] < thr:
            flag[i] = 1
            continue
        if divr[i] >= upper:
            continue
        g = math.sqrt(gcx[i] * gcx[i] + gcz[i] * gcz[i])
        if g == 0.0:
            continue
        nx, nz = -gcx[i] / g, -gcz[i] / g
        tx, tz = x[i] + h * nx, z[i] + h * nz
        ix, iz = cell_of(cl, x[i], z[i])
        occupied = False
        for ddx in range(-1, 2):
            for ddz in range(-1, 2):
                c, shift = neighbour_cell(cl, ix, iz, ddx, ddz)
                if c < 0:
                    continue
                for j in range(cl.start[c], cl.start[c + 1]):
                    if j == i:
                        continue
                    rx = x[j] + shift - x[i]
                    rz = z[j] - z[i]
                    r2 = rx * rx + rz * rz
                    if r2 >= four_h2:
                        continue
                    px = x[j] + shift - tx
                    pz = z[j] - tz
                    if r2 >= two_h2:
                        occupied = px * px + pz * pz < h * h
                    else:
                        occupied = abs(nx * px + nz * pz) + abs(-nz * px + nx * pz) < h
                    if occupied:
                        break
                if occupied:
                    break
            if occupied:
                break
        if not occupied:
            flag[i] = 1


@nb.njit(cache=True)
def near_surface(x, z, kind, surface, cl, n_active, h, near):
    """near[i] = 1 for fluid particles within 2h of a free-surface particle (surface ones
    included). Scattered from the surface particles, which are few: serial."""
    four_h2 = 4.0 * h * h
    for i in range(n_active):
        near[i] = 0
    for j in range(n_active):
        if not surface[j]:
            continue
        near[j] = 1
        ix, iz = cell_of(cl, x[j], z[j])
        for ddx in range(-1, 2):
            for ddz in range(-1, 2):
                c, shift = neighbour_cell(cl, ix, iz, ddx, ddz)
                if c < 0:
                    continue
                for i in range(cl.start[c], cl.start[c + 1]):
                    if kind[i] != 0:
                        continue
                    ex = x[i] + shift - x[j]
                    ez = z[i] - z[j]
                    if ex * ex + ez * ez < four_h2:
                        near[i] = 1


@nb.njit(inline="always", cache=True)
def _scatter_normals(x, z, kind, surface, gcx, gcz, cl, h, near, nx, nz, cx):
    """Add the normals of the free-surface particles of column cx to the fluid particles
    within 2h (``surface_normals``); writes columns cx - 1 .. cx + 1 only."""
    two_h = 2.0 * h
    four_h2 = 4.0 * h * h
    inv_h = 1.0 / h
    for j in range(cl.start[cx * cl.ncz], cl.start[(cx + 1) * cl.ncz]):
        if not surface[j]:
            continue
        near[j] = 1
        g = math.sqrt(gcx[j] * gcx[j] + gcz[j] * gcz[j])
        ox, oz = (-gcx[j] / g, -gcz[j] / g) if g > 0.0 else (0.0, 0.0)
        zj = z[j]
        iz = cell_of(cl, x[j], zj)[1]
        for ddx in range(-1, 2):
            jx, shift = neighbour_column(cl, cx, ddx)
            if jx < 0:
                continue
            i0, i1 = column_window(cl, z, jx, iz, zj - two_h)
            for i in range(i0, i1):
                ez = z[i] - zj
                if ez >= two_h:
                    break
                if kind[i] != 0:
                    continue
                ex = x[i] + shift - x[j]
                r2 = ex * ex + ez * ez
                if r2 < four_h2:
                    near[i] = 1
                    s = 1.0 - 0.5 * math.sqrt(r2) * inv_h
                    wgt = s * s * s * s
                    nx[i] += wgt * ox
                    nz[i] += wgt * oz


@nb.njit(parallel=True, cache=True)
def surface_normals(x, z, kind, surface, gcx, gcz, cl, n_active, h, near, nx, nz):
    """``near_surface``'s flags, and in the same pass (nx, nz)[i] = the unit vector along
    sum_j (1 - q_ij/2)^4 n_j over the free-surface particles j within 2h of fluid particle i
    (i itself included), n_j = -gradC_j / |gradC_j| their outward normals; zero where there is
    none. Scattered from the surface particles of each grid column (the column they were
    sorted into) to the neighbouring columns, in parallel over columns three apart, which
    write disjoint columns (the last ncx mod 3 columns each alone: a periodic x wraps)."""
    for i in nb.prange(n_active):
        near[i] = 0
        nx[i] = 0.0
        nz[i] = 0.0
    ncx = cl.ncx
    coloured = ncx - ncx % 3
    for colour in range(3):
        for k in nb.prange(coloured // 3):
            _scatter_normals(x, z, kind, surface, gcx, gcz, cl, h, near, nx, nz, colour + 3 * k)
    for cx in range(coloured, ncx):
        _scatter_normals(x, z, kind, surface, gcx, gcz, cl, h, near, nx, nz, cx)
    for i in nb.prange(n_active):
        nn = math.sqrt(nx[i] * nx[i] + nz[i] * nz[i])
        if nn > 0.0:
            nx[i] /= nn
            nz[i] /= nn


@nb.njit(parallel=True, cache=True)
def lind_shift_tangential(kind, gcx, gcz, near, surface, snx, snz, wnx, wnz, s0, n_active, D, clip, dx_out,
                          dz_out):
    """dr = -D gradC, each component clipped, never into a wall; within 2h of the free surface
    (``near``) only its part along the surface, -D (gradC - (gradC.n) n), n = (snx, snz)
    (``surface_normals``); no shift where n is zero, nor for a free-surface particle (``surface``)
    with a wall particle within 2h (where the surface meets a wall, as the paper's lind)."""
    for i in nb.prange(n_active):
        dx_out[i] = 0.0
        dz_out[i] = 0.0
        if kind[i] != 0:
            continue
        gx, gz = gcx[i], gcz[i]
        if near[i]:
            nx, nz = snx[i], snz[i]
            if (nx == 0.0 and nz == 0.0) or (surface[i] and (wnx[i] != 0.0 or wnz[i] != 0.0)):
                continue
            d = gx * nx + gz * nz
            gx -= d * nx
            gz -= d * nz
        dx_out[i], dz_out[i] = _off_wall(min(max(-D * gx, -clip), clip),
                                         min(max(-D * gz, -clip), clip), wnx[i], wnz[i], s0)


@nb.njit(parallel=True, cache=True)
def lind_shift(kind, gcx, gcz, near, wnx, wnz, s0, n_active, D, clip, dx_out, dz_out):
    """dr = -D gradC, each component clipped, zero near the free surface (``near``)."""
    for i in nb.prange(n_active):
        dx_out[i] = 0.0
        dz_out[i] = 0.0
        if kind[i] != 0 or near[i]:
            continue
        dx_out[i], dz_out[i] = _off_wall(min(max(-D * gcx[i], -clip), clip),
                                         min(max(-D * gcz[i], -clip), clip), wnx[i], wnz[i], s0)


@nb.njit(parallel=True, cache=True)
def limit_correction(rho, kind, div, n, limit):
    """rho *= 1 - div(dr) for fluid particles, |div(dr)| limited to ``limit``."""
    for i in nb.prange(n):
        if kind[i] == 0:
            d = min(max(div[i], -limit), limit)
            rho[i] *= 1.0 - d
