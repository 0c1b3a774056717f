"""Probes of a flow front, computed from the particles (cheap next to a time step).

- toe: downstream end of the fluid on the bed. Fluid particles are binned by dp along x;
  from the fullest bin the occupied bins are followed downstream until two empty bins in a
  row; the toe is the largest particle x in the last occupied bin plus dp/2. A stray
  particle more than two bins ahead is ignored.
- free surface z_max(x): the highest z where the kernel concentration
  C(x, z) = sum_j V_j W(r - r_j) (fluid and wall particles) equals 0.5, by descending
  from above the fluid in steps of dp/2 and interpolating linearly. For a uniform half
  space C = 1/2 exactly on its boundary, so the level sits on the continuum surface
  (dp/2 above the top particle row); over a dry bed it gives the bed.
- line profiles: fluid velocity where C >= 0.5 (inside the fluid; NaN above the surface),
  by the linear moving-least-squares fit over fluid particles, u(r) = a with
  (a, b) = argmin sum_j V_j W_j (u_j - a - b.(r_j - r))^2. It is exact for a linear field
  even where the stencil is one-sided (at the bed and the surface), where the Shepard mean
  sum u_j V_j W / sum V_j W is biased by about h |grad u|; the Shepard mean is used where
  the fit is singular (a single row of particles).
- number density: sum_j W(r - r_j) dp^2 over fluid particles (1.005 on the square lattice
  at Ch = 1.5, 1.002 at Ch = 1.8): falls when particles spread apart.
"""
from __future__ import annotations

import math

import numba as nb
import numpy as np

from .cells import cell_of, neighbour_cell
from .kernel import alpha_2d, grad_coefficient, w_value

C_SURFACE = 0.5
MLS_MIN_DET = 1.0e-3  # det(M) / M_00^3 below which the linear fit falls back to Shepard


@nb.njit(inline="always", cache=True)
def _concentration(px, pz, x, z, rho, mass, cl, h, alpha):
    """C = sum_j V_j W(r - r_j) over fluid and wall particles at point (px, pz)."""
    c_all = 0.0
    if cl.periodic:
        px = cl.x0 + (px - cl.x0) % cl.period
    ix, iz = cell_of(cl, px, pz)
    four_h2 = 4.0 * h * h
    for ddx in range(-1, 2):
        for ddz in range(-1, 2):
            c, shift = neighbour_cell(cl, ix, iz, ddx, ddz)
            if c < 0:
                continue
            for j in range(cl.start[c], cl.start[c + 1]):
                dx = px - (x[j] + shift)
                dz = pz - z[j]
                r2 = dx * dx + dz * dz
                if r2 < four_h2:
                    c_all += mass[j] / rho[j] * w_value(math.sqrt(r2) / h, alpha)
    return c_all


@nb.njit(inline="always", cache=True)
def _point_values(px, pz, x, z, u, w, rho, mass, kind, cl, h, alpha):
    """(C all, C fluid, u, w, sum W fluid) at (px, pz), in one pass over the neighbours.
    (u, w) is the first-order (linear) moving-least-squares fit over fluid particles:
    minimise sum_j V_j W_j (u_j - a - b (x_j - px) - c (z_j - pz))^2 and return a. Exact for
    a linear field however one-sided the stencil; the Shepard mean sum u V W / sum V W is
    returned where the normalised moment matrix is near-singular (det < MLS_MIN_DET: a line
    of particles, a lone tip); NaN without fluid."""
    if cl.periodic:
        px = cl.x0 + (px - cl.x0) % cl.period
    ix, iz = cell_of(cl, px, pz)
    four_h2 = 4.0 * h * h
    c_all = nw = 0.0
    m00 = m01 = m02 = m11 = m12 = m22 = 0.0
    bu0 = bu1 = bu2 = bw0 = bw1 = bw2 = 0.0
    for ddx in range(-1, 2):
        for ddz in range(-1, 2):
            c, shift = neighbour_cell(cl, ix, iz, ddx, ddz)
            if c < 0:
                continue
            for j in range(cl.start[c], cl.start[c + 1]):
                dx = (x[j] + shift) - px
                dz = z[j] - pz
                r2 = dx * dx + dz * dz
                if r2 >= four_h2:
                    continue
                W = w_value(math.sqrt(r2) / h, alpha)
                VW = mass[j] / rho[j] * W
                c_all += VW
                if kind[j] != 0:
                    continue
                nw += W
                ex = dx / h
                ez = dz / h
                m00 += VW
                m01 += VW * ex
                m02 += VW * ez
                m11 += VW * ex * ex
                m12 += VW * ex * ez
                m22 += VW * ez * ez
                bu0 += VW * u[j]
                bu1 += VW * u[j] * ex
                bu2 += VW * u[j] * ez
                bw0 += VW * w[j]
                bw1 += VW * w[j] * ex
                bw2 += VW * w[j] * ez
    if m00 <= 0.0:
        return c_all, 0.0, np.nan, np.nan, nw
    # Cramer's rule for the first unknown of the symmetric 3x3 system M a = b
    c11 = m11 * m22 - m12 * m12
    c12 = m02 * m12 - m01 * m22
    c13 = m01 * m12 - m02 * m11
    det = m00 * c11 + m01 * c12 + m02 * c13
    if det < MLS_MIN_DET * m00 * m00 * m00:
        return c_all, m00, bu0 / m00, bw0 / m00, nw
    return c_all, m00, (bu0 * c11 + bu1 * c12 + bu2 * c13) / det, (bw0 * c11 + bw1 * c12 + bw2 * c13) / det, nw


@nb.njit(parallel=True, cache=True)
def sample_points(px, pz, x, z, u, w, rho, mass, kind, cl, h, out):
    """out[:, k] = (C all, C fluid, u, w, sum W fluid) at point k (``cells.CellList`` cl);
    u and w by the linear fit of ``_point_values`` (Shepard where it is singular)."""
    alpha = alpha_2d(h)
    for k in nb.prange(px.size):
        out[0, k], out[1, k], out[2, k], out[3, k], out[4, k] = _point_values(
            px[k], pz[k], x, z, u, w, rho, mass, kind, cl, h, alpha)


@nb.njit(parallel=True, cache=True)
def surface_elevation(xs, ztop, zfloor, step, x, z, rho, mass, cl, h, out):
    """Highest z in [zfloor, ztop[k]] where C = 0.5 on the vertical line x = xs[k]
    (zfloor if C < 0.5 all the way down)."""
    alpha = alpha_2d(h)
    for k in nb.prange(xs.size):
        zc = ztop[k]
        c_prev = _concentration(xs[k], zc, x, z, rho, mass, cl, h, alpha)
        out[k] = zfloor
        while zc > zfloor:
            zn = max(zc - step, zfloor)
            c = _concentration(xs[k], zn, x, z, rho, mass, cl, h, alpha)
            if c >= 0.5:
                if c_prev < 0.5:
                    out[k] = zn + (c - 0.5) / (c - c_prev) * (zc - zn)
                else:
                    out[k] = zc
                break
            zc, c_prev = zn, c


@nb.njit(parallel=True, cache=True)
def disorder_moments(idx, x, z, rho, mass, cl, h, out):
    """At particles idx, with gradW_ab = F r_ab and V = m / rho (fluid and walls):
    out[:, k] = (M_xx, M_zz, h |sum_b V_b gradW_ab|), M = -sum_b V_b F r_ab r_ab.
    On a regular lattice M = I and the gradient sum is 0; the viscous term sum_b 2 V F u_ab
    approximates M : grad grad u + 2 (sum_b V gradW) . grad u, so both measure how far the
    particle arrangement is from one that makes it the Laplacian."""
    fac = grad_coefficient(h)
    four_h2 = 4.0 * h * h
    for k in nb.prange(idx.size):
        a = idx[k]
        ix, iz = cell_of(cl, x[a], z[a])
        mxx = mzz = gx = gz = 0.0
        for ddx in range(-1, 2):
            for ddz in range(-1, 2):
                c, shift = neighbour_cell(cl, ix, iz, ddx, ddz)
                if c < 0:
                    continue
                for j in range(cl.start[c], cl.start[c + 1]):
                    dx = x[a] - (x[j] + shift)
                    dz = z[a] - z[j]
                    r2 = dx * dx + dz * dz
                    if r2 >= four_h2 or j == a:
                        continue
                    s = 1.0 - 0.5 * math.sqrt(r2) / h
                    VF = mass[j] / rho[j] * fac * s * s * s
                    mxx -= VF * dx * dx
                    mzz -= VF * dz * dz
                    gx += VF * dx
                    gz += VF * dz
        out[0, k] = mxx
        out[1, k] = mzz
        out[2, k] = h * math.sqrt(gx * gx + gz * gz)


def last_crossing(xs, v, level: float) -> float:
    """The largest x on the ascending grid xs where v falls through ``level`` (linear between
    nodes); NaN where v never reaches it or is still at it on the last node."""
    above = np.flatnonzero(v >= level)
    if not above.size or above[-1] + 1 >= xs.size:
        return math.nan
    k = above[-1]
    return float(xs[k] + (v[k] - level) / (v[k] - v[k + 1]) * (xs[k + 1] - xs[k]))


def toe_position(xf: np.ndarray, dp: float, gap_bins: int = 2) -> float:
    """Downstream end of the fluid body (see module docstring)."""
    if xf.size == 0:
        return math.nan
    lo = xf.min()
    b = np.floor((xf - lo) / dp).astype(np.int64)
    counts = np.bincount(b)
    k = int(np.argmax(counts))
    empty = 0
    last = k
    while k + 1 < counts.size:
        k += 1
        if counts[k] == 0:
            empty += 1
            if empty >= gap_bins:
                break
        else:
            empty, last = 0, k
    return float(xf[b == last].max() + 0.5 * dp)


class FieldSampler:
    """Evaluates probes on a Simulation's current (sorted) particle arrays."""

    def __init__(self, sim):
        self.sim = sim

    def _grid_args(self):
        s = self.sim
        return (s.x, s.z, s.u, s.w, s.rho, s.mass, s.kind, s.cells, s.h)

    def points(self, px, pz) -> np.ndarray:
        px = np.ascontiguousarray(px, dtype=float).ravel()
        pz = np.ascontiguousarray(pz, dtype=float).ravel()
        out = np.empty((5, px.size))
        sample_points(px, pz, *self._grid_args(), out)
        return out

    def disorder(self, idx) -> np.ndarray:
        """(M_xx, M_zz, h |sum V gradW|) at the particles idx (see ``disorder_moments``)."""
        s = self.sim
        idx = np.ascontiguousarray(idx, dtype=np.int64)
        out = np.empty((3, idx.size))
        disorder_moments(idx, s.x, s.z, s.rho, s.mass, s.cells, s.h, out)
        return out

    def surface(self, xs, zfloor: float) -> np.ndarray:
        """z_max on the vertical lines xs, starting 2h above the highest nearby fluid."""
        s = self.sim
        xs = np.ascontiguousarray(xs, dtype=float)
        fl = s.kind[:s.n_active] == 0
        xf, zf = s.x[:s.n_active][fl], s.z[:s.n_active][fl]
        reach = 2.0 * s.h
        order = np.argsort(xf)
        xf, zf = xf[order], zf[order]
        lo = np.searchsorted(xf, xs - reach)
        hi = np.searchsorted(xf, xs + reach)
        ztop = np.full(xs.size, zfloor)
        for k in range(xs.size):  # highest fluid within reach of each line
            if hi[k] > lo[k]:
                ztop[k] = zf[lo[k]:hi[k]].max() + reach
        out = np.empty(xs.size)
        surface_elevation(xs, ztop, zfloor, 0.5 * s.scene.dp, s.x, s.z, s.rho, s.mass, s.cells, s.h, out)
        return out
