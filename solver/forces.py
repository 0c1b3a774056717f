"""The pair loop (SPEC section 6): continuity with Fourtakas diffusion, pressure,
Lo & Shao laminar viscosity, and the shifting sums, over a half stencil.

Fluid-wall pairs never attract: their P_a + P_b is floored at zero. A fluid in suction next
to a wall (negative gauge pressure, as in the corner of a belt running into a fixed wall)
would otherwise be drawn through the wall by the symmetric pressure term.

Each pair (a, b) is visited once and its contributions are added to both particles,
into per-thread accumulators ``acc[t, q, i]`` (no write races), reduced afterwards.
Quantities q: 0 ax, 1 az, 2 drho/dt, 3 gradC_x, 4 gradC_z, 5 div r, 6-7 the kernel-weighted
sum of the inward normals of nearby wall particles (where shifting must not push).
Density diffusion and the shifting sums are compiled in or out (``make_pair_loop``).

  drho_a/dt = rho_a sum_b u_ab.gradW_ab V_b + h c0 D_a
  D_a = 2 delta sum_b ((rho_a - rho_b) - rho_ab^H) (r_ab.gradW_ab) / (r^2 + eta^2) V_b
  du_a/dt = -sum_b m_b (P_a + P_b)/(rho_a rho_b) gradW_ab   (P_a + P_b >= 0 for fluid-wall pairs)
            + sum_b m_b 4 nu (r_ab.gradW_ab) / ((rho_a + rho_b)(r^2 + eta^2)) u_ab  (+ g)
  gradC_a = sum_b dp^2 gradW_ab,  div r_a = -sum_b dp^2 r_ab.gradW_ab
In the two shifting sums every particle's volume is its lattice cell dp^2, not m/rho, so the
concentration measures particle number density, which is what shifting evens out. With m/rho,
a wall whose mDBC density follows the fluid pressure looks less concentrated than the fluid
beside it and draws fluid into it, and a particle compressed by shifting (density correction)
looks smaller and draws its neighbours further onto it: both feed back step after step.
"""
from __future__ import annotations

import functools
import math

import numba as nb
import numpy as np

from .kernel import grad_factor

NQ = 8
# Binomial series of (1 + x)^(1/7) - 1, split into even and odd powers: f(+-x) = E +- O.
_C = [1.0]
for _k in range(1, 12):
    _C.append(_C[-1] * (1.0 / 7.0 - (_k - 1)) / _k)
C1, C2, C3, C4, C5, C6, C7, C8, C9, C10, C11 = _C[1:]


@nb.njit(inline="always", cache=True)
def hydrostatic_pair(x):
    """((1 + x)^(1/7) - 1, (1 - x)^(1/7) - 1): series for |x| < 0.1 (error < 1e-13), pow beyond."""
    if abs(x) < 0.1:
        x2 = x * x
        even = x2 * (C2 + x2 * (C4 + x2 * (C6 + x2 * (C8 + x2 * C10))))
        odd = x * (C1 + x2 * (C3 + x2 * (C5 + x2 * (C7 + x2 * (C9 + x2 * C11)))))
        return even + odd, even - odd
    return (1.0 + x) ** (1.0 / 7.0) - 1.0, (1.0 - x) ** (1.0 / 7.0) - 1.0


@functools.cache
def make_pair_loop(diffusion: bool, shifting: bool):
    """Compile the pair loop with density diffusion and shifting sums in or out."""

    @nb.njit(parallel=True, cache=True, fastmath=False)
    def pair_loop(x, z, u, w, rho, p, mass, kind, wnx, wnz, start, ncx, ncz, periodic, period, split,
                  h, nu, hc0, rho0, k_hyd, delta, dp2, acc, vmax):
        nt = split.size - 1
        fac = -5.0 * (7.0 / (4.0 * math.pi * h * h)) / (h * h)
        eta2 = 0.01 * h * h
        four_h2 = 4.0 * h * h
        inv_h = 1.0 / h
        acc[:] = 0.0
        for t in nb.prange(nt):
            vm = 0.0
            for ix in range(split[t], split[t + 1]):
                for iz in range(ncz):
                    ca = ix * ncz + iz
                    for k in range(5):
                        # half stencil: self, (0,+1), (+1,-1), (+1,0), (+1,+1)
                        jx = ix if k < 2 else ix + 1
                        jz = iz + 1 if k == 1 else (iz if k < 2 else iz + k - 3)
                        shift = 0.0
                        if jx == ncx:
                            if not periodic:
                                continue
                            jx = 0
                            shift = period
                        if jz < 0 or jz >= ncz:
                            continue
                        cb = jx * ncz + jz
                        b0, b1 = start[cb], start[cb + 1]
                        if b0 == b1:
                            continue
                        for a in range(start[ca], start[ca + 1]):
                            xa, za, ua, wa = x[a], z[a], u[a], w[a]
                            ra, pa, ka, ma = rho[a], p[a], kind[a], mass[a]
                            first = a + 1 if k == 0 else b0
                            for b in range(first, b1):
                                kb = kind[b]
                                if ka + kb == 2:
                                    continue
                                dx = xa - (x[b] + shift)
                                dz = za - z[b]
                                r2 = dx * dx + dz * dz
                                if r2 >= four_h2:
                                    continue
                                F = grad_factor(math.sqrt(r2) * inv_h, fac)
                                rb = rho[b]
                                du = ua - u[b]
                                dw = wa - w[b]
                                vdotr = du * dx + dw * dz
                                rdotg = F * r2
                                mb = mass[b]
                                Va = ma / ra
                                Vb = mb / rb
                                inv_r2e = 1.0 / (r2 + eta2)
                                # continuity
                                udotg = F * vdotr
                                acc[t, 2, a] += ra * udotg * Vb
                                acc[t, 2, b] += rb * udotg * Va
                                # pressure and laminar viscosity
                                psum = pa + p[b]
                                if ka + kb == 1 and psum < 0.0:
                                    psum = 0.0  # a wall pushes, never pulls
                                pt = psum / (ra * rb) * F
                                vt = 4.0 * nu * rdotg / (ra + rb) * inv_r2e
                                fx = -pt * dx + vt * du
                                fz = -pt * dz + vt * dw
                                acc[t, 0, a] += mb * fx
                                acc[t, 1, a] += mb * fz
                                acc[t, 0, b] -= ma * fx
                                acc[t, 1, b] -= ma * fz
                                vr = abs(h * vdotr * inv_r2e)
                                if vr > vm:
                                    vm = vr
                                if diffusion:
                                    if ka + kb == 0:
                                        fa, fb = hydrostatic_pair(k_hyd * dz)
                                        g = 2.0 * delta * hc0 * rdotg * inv_r2e
                                        drab = ra - rb
                                        acc[t, 2, a] += g * (drab - rho0 * fa) * Vb
                                        acc[t, 2, b] += g * (-drab - rho0 * fb) * Va
                                if shifting:
                                    # concentration counts particles: volume dp^2 each
                                    sx = dp2 * F * dx
                                    sz = dp2 * F * dz
                                    acc[t, 3, a] += sx
                                    acc[t, 4, a] += sz
                                    acc[t, 3, b] -= sx
                                    acc[t, 4, b] -= sz
                                    acc[t, 5, a] -= dp2 * rdotg
                                    acc[t, 5, b] -= dp2 * rdotg
                                    if kb == 1:
                                        acc[t, 6, a] -= F * wnx[b]
                                        acc[t, 7, a] -= F * wnz[b]
                                    elif ka == 1:
                                        acc[t, 6, b] -= F * wnx[a]
                                        acc[t, 7, b] -= F * wnz[a]
            vmax[t] = vm

    return pair_loop


@nb.njit(parallel=True, cache=True)
def reduce_accumulators(acc, kind, gx, gz, out, nq):
    """out[q, i] = sum_t acc[t, q, i]; gravity added to fluid accelerations.

    Returns max |a| over fluid particles (for dt1).
    """
    nt = acc.shape[0]
    n = acc.shape[2]
    amax = np.zeros(n)
    for i in nb.prange(n):
        for q in range(nq):
            s = 0.0
            for t in range(nt):
                s += acc[t, q, i]
            out[q, i] = s
        if kind[i] == 0:
            out[0, i] += gx
            out[1, i] += gz
            amax[i] = math.sqrt(out[0, i] ** 2 + out[1, i] ** 2)
    return amax.max() if n > 0 else 0.0


@nb.njit(parallel=True, cache=True)
def equation_of_state(rho, p, B, rho0):
    """Tait: P = B ((rho/rho0)^7 - 1)."""
    for i in nb.prange(rho.size):
        r = rho[i] / rho0
        r2 = r * r
        p[i] = B * (r2 * r2 * r2 * r - 1.0)
