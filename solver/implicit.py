"""Implicit laminar viscosity (``numerics.viscous_update: implicit``): backward Euler in the
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
(``implicit_walls`` 2 in the pair loop); a DBC wall's velocity is imposed, delta_b = 0
(``implicit_walls`` 1).
Lagging the wall instead (delta_b = 0 with mDBC) leaves the mirror mode undamped: measured
at 3.4 times the explicit step, the start-up Poiseuille flow's velocity error grew to 19
times u_max within 0.225 s. Multiplied by m_a the system is
symmetric positive definite (m_a c_ab = m_a m_b k_ab with k symmetric), and
Jacobi-preconditioned conjugate gradients solve it for both velocity components, starting
from the explicit step plus the previous step's implicit correction, delta = dt (a + c) with
c = delta / dt - a of that step (carried with the particles): a fifth fewer iterations
(12.2 against 15.2 a step at dp = 0.25 mm, Ch = 1.8, ``benchmarks/cg_solve.py``).

The pair loop lists the fluid pairs with k_ab = c_ab / m_b (``forces.PairList``, per thread,
each pair once) and sums the diagonal sum_b c_ab. Every product with C (CG's and the
sub-stepped update's) runs over those per-thread lists: thread t adds c_ab y_b to row a and
c_ba y_a to row b of its own accumulator, on the rows it writes (``forces.thread_rows``), and
the threads' shares are summed as the pair loop's are (``offdiagonal_products``,
``forces.sum_thread_rows``; a sub-stepped stage sums them in its own pass over the rows). The
list is never arranged by rows.
"""
from __future__ import annotations

import functools
import math

import numba as nb
import numpy as np

from .forces import REDUCE_CHUNKS, sum_thread_rows, thread_bounds, thread_rows, wrote

TOLERANCE = 1.0e-6  # CG stops when |residual| <= TOLERANCE |right-hand side| (2-norm, each component)
MAX_ITERATIONS = 1000
WORK_ROWS = 13  # CG's scratch rows
SUBSTEP_WORK_ROWS = 6  # the sub-stepped update's: Y_{j-2}, Y_{j-1}, Y_j


def pairs_per_particle(ch: float) -> float:
    """Pairs allocated a particle: half the neighbours within 2h on a lattice, pi (2 Ch)^2 / 2,
    with 50 % to spare (a list that overflows is reallocated and the evaluation repeated)."""
    return 1.5 * 0.5 * math.pi * (2.0 * ch) ** 2


def pair_capacity(n: int, ch: float, threads: int) -> int:
    """Pairs per thread to allocate, for an equal share of n particles."""
    return int(pairs_per_particle(ch) * n / threads) + 1024


def bytes_per_particle(ch: float, substeps: bool = False) -> float:
    """Memory this update adds (2 threads): the pair list (16 B a pair), the two threads'
    product shares (4 numbers) and the scratch rows (13 for CG, 6 sub-stepped): 0.62 and
    0.57 kB a particle at Ch = 1.8."""
    return pairs_per_particle(ch) * 16.0 + 8.0 * (4 + (SUBSTEP_WORK_ROWS if substeps else WORK_ROWS))


def product_shares(threads: int, n: int) -> np.ndarray:
    """Per-thread scratch of the products: each thread's share of C's off-diagonal sums."""
    return np.zeros((threads, n, 2))


def operator(pairs, cl, split, diag, mass, shares) -> tuple:
    """What a product with C reads: the pair loop's lists (``forces.PairList`` pairs), the
    rows each thread writes (``cells.CellList`` cl, column ``split``), the diagonal
    sum_b c_ab, the masses, and the scratch ``product_shares``."""
    return (pairs.i, pairs.j, pairs.k, pairs.count, mass, diag, shares, cl.start, split, cl.ncx, cl.ncz,
            cl.periodic)


@nb.njit(parallel=True, cache=True)
def _offdiagonal_shares(pair_i, pair_j, pair_k, pair_count, mass, yx, yz, acc, start, split, ncx, ncz,
                        periodic):
    """acc[t, a] = sum over thread t's listed pairs (a, b) of c_ab y_b, c_ab = m_b k_ab (both
    directions of each pair), on the rows thread t writes (``forces.thread_rows``). Row a's
    share is summed in registers over each run of consecutive pairs with the same a (the pair
    loop lists a particle's pairs together) and added once per run."""
    for t in nb.prange(pair_count.size):
        at = acc[t]
        lo, hi = thread_rows(start, split, t, ncx, ncz)
        at[lo:hi] = 0.0
        if periodic and split[t + 1] == ncx:
            at[0:start[ncz]] = 0.0
        count = np.uint64(pair_count[t])
        if count == 0:
            continue
        a = np.uint64(pair_i[t, 0])
        ma, yax, yaz = mass[a], yx[a], yz[a]
        sx = sz = 0.0
        for q in range(count):
            i = np.uint64(pair_i[t, q])
            if i != a:  # a new run: add the last one's sum to its row
                at[a, 0] += sx
                at[a, 1] += sz
                a = i
                ma, yax, yaz = mass[a], yx[a], yz[a]
                sx = sz = 0.0
            b = np.uint64(pair_j[t, q])
            k = pair_k[t, q]
            wa = mass[b] * k
            wb = ma * k
            sx += wa * yx[b]
            sz += wa * yz[b]
            at[b, 0] += wb * yax
            at[b, 1] += wb * yaz
        at[a, 0] += sx
        at[a, 1] += sz


@nb.njit(cache=True)
def offdiagonal_shares(op, yx, yz):
    """The threads' shares of the products sum_b c_ab (yx, yz)_b (``_offdiagonal_shares``), in
    ``op``'s scratch; ``op`` from ``operator``."""
    pair_i, pair_j, pair_k, pair_count, mass, _, acc, start, split, ncx, ncz, periodic = op
    _offdiagonal_shares(pair_i, pair_j, pair_k, pair_count, mass, yx, yz, acc, start, split, ncx, ncz,
                        periodic)


@nb.njit(cache=True)
def offdiagonal_products(op, yx, yz, s, n):
    """s[:, a] = sum_b c_ab (yx, yz)_b over the listed fluid pairs, for every row of [0, n)
    (0 on rows with none: walls); ``op`` from ``operator``, ``s`` of shape (2, >= n)."""
    offdiagonal_shares(op, yx, yz)
    _, _, _, _, _, _, acc, start, split, ncx, ncz, periodic = op
    sum_thread_rows(acc, start, split, ncx, ncz, periodic, s, n)


@nb.njit(parallel=True, cache=True)
def _scaled_system(mass, diag, kind, dt, px, pz, sx, sz, yx, yz, n):
    """y = M ((1 + dt diag) p - dt s) on the fluid rows, s the off-diagonal products of p."""
    for a in nb.prange(n):
        if kind[a] != 0:
            continue
        d = 1.0 + dt * diag[a]
        yx[a] = mass[a] * (d * px[a] - dt * sx[a])
        yz[a] = mass[a] * (d * pz[a] - dt * sz[a])


@nb.njit(cache=True)
def _apply(op, kind, dt, px, pz, yx, yz, s, n):
    """y = A p, A = M (I + dt C) on the fluid rows (module docstring); s: scratch (2, >= n)."""
    offdiagonal_products(op, px, pz, s, n)
    _scaled_system(op[4], op[5], kind, dt, px, pz, s[0], s[1], yx, yz, n)


@nb.njit(parallel=True, cache=True)
def _dot(kind, ax, bx, az, bz, n):
    sx = 0.0
    sz = 0.0
    for a in nb.prange(n):
        if kind[a] == 0:
            sx += ax[a] * bx[a]
            sz += az[a] * bz[a]
    return sx, sz


@nb.njit(parallel=True, cache=True)
def solve(op, kind, dt, ax, az, cx, cz, n, tol, max_iterations, work):
    """Overwrite (ax, az) of the fluid rows of [0, n) with delta / dt, delta solving
    M (I + dt C) delta = M dt a by Jacobi-preconditioned CG, for each component, from
    delta0 = dt (a + c); (cx, cz): c, the implicit correction delta / dt - a of the previous
    step (zeros for none), overwritten with this step's. ``op``: C (``operator``);
    ``work``: scratch of shape (WORK_ROWS, >= n).

    Returns (iterations, largest relative residual); the residual exceeds ``tol`` when
    ``max_iterations`` did not suffice."""
    dx, dz, rx, rz, zx, zz, px, pz, qx, qz, pre = (work[0], work[1], work[2], work[3], work[4],
                                                   work[5], work[6], work[7], work[8], work[9],
                                                   work[10])
    s = work[11:13]  # the off-diagonal products
    mass, diag = op[4], op[5]
    bbx = 0.0
    bbz = 0.0
    for a in nb.prange(n):
        if kind[a] == 0:
            dx[a] = dt * (ax[a] + cx[a])
            dz[a] = dt * (az[a] + cz[a])
            pre[a] = 1.0 / (mass[a] * (1.0 + dt * diag[a]))
            bbx += (mass[a] * dt * ax[a]) ** 2
            bbz += (mass[a] * dt * az[a]) ** 2
        else:
            dx[a] = dz[a] = pre[a] = px[a] = pz[a] = 0.0
    # r = b - A delta0 with b = M dt a
    _apply(op, kind, dt, dx, dz, qx, qz, s, n)
    for a in nb.prange(n):
        if kind[a] == 0:
            rx[a] = mass[a] * dt * ax[a] - qx[a]
            rz[a] = mass[a] * dt * az[a] - qz[a]
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
        _apply(op, kind, dt, px, pz, qx, qz, s, n)
        pqx, pqz = _dot(kind, px, qx, pz, qz, n)
        alx = rzx / pqx if rrx > limx and pqx > 0.0 else 0.0
        alz = rzz / pqz if rrz > limz and pqz > 0.0 else 0.0
        nzx = nzz = 0.0
        rrx = rrz = 0.0
        for a in nb.prange(n):  # one pass: update, precondition, and the two products
            if kind[a] == 0:
                dx[a] += alx * px[a]
                dz[a] += alz * pz[a]
                rx[a] -= alx * qx[a]
                rz[a] -= alz * qz[a]
                zx[a] = pre[a] * rx[a]
                zz[a] = pre[a] * rz[a]
                nzx += rx[a] * zx[a]
                nzz += rz[a] * zz[a]
                rrx += rx[a] * rx[a]
                rrz += rz[a] * rz[a]
        bex = nzx / rzx if rzx > 0.0 else 0.0
        bez = nzz / rzz if rzz > 0.0 else 0.0
        for a in nb.prange(n):
            if kind[a] == 0:
                px[a] = zx[a] + bex * px[a]
                pz[a] = zz[a] + bez * pz[a]
        rzx, rzz = nzx, nzz
        it += 1
    inv_dt = 1.0 / dt
    for a in nb.prange(n):
        if kind[a] == 0:
            cx[a] = dx[a] * inv_dt - ax[a]
            cz[a] = dz[a] * inv_dt - az[a]
            ax[a] = dx[a] * inv_dt
            az[a] = dz[a] * inv_dt
    return it, math.sqrt(max(rrx / max(bbx, 1e-300), rrz / max(bbz, 1e-300)))


# ---- sub-stepped update: Runge-Kutta-Chebyshev on the same operator -------------------------

RKC_DAMPING = 0.4  # epsilon of the damped Chebyshev stability polynomial: interior |R| <= 0.70


def rkc_stages(z: float, damping: float = RKC_DAMPING) -> int:
    """Fewest stages s of first-order RKC whose real stability interval [-beta_s, 0] holds
    [-z, 0], z = dt times a bound on the operator's largest eigenvalue (s = 1 is forward
    Euler with a damping; beta_s grows as s^2, about 1.93 s^2 at eps = 0.05 and 1.6 s^2 at 0.4)."""
    s = 1
    while rkc_coefficients(s, damping)[0] < z:
        s += 1
    return s


@functools.lru_cache(maxsize=64)
def rkc_coefficients(s: int, damping: float = RKC_DAMPING):
    """(beta, mu, nu, mut) of s-stage first-order RKC (Verwer, Hundsdorfer & Sommeijer 2004):
    w0 = 1 + eps / s^2, w1 = T_s(w0) / T_s'(w0), b_j = 1 / T_j(w0); stage j >= 2:
    Y_j = mu_j Y_{j-1} + nu_j Y_{j-2} + (1 - mu_j - nu_j) Y_0 + mut_j dt F(Y_{j-1}),
    mu_j = 2 w0 b_j / b_{j-1}, nu_j = -b_j / b_{j-2}, mut_j = 2 w1 b_j / b_{j-1}; stage 1:
    Y_1 = Y_0 + mut_1 dt F(Y_0), mut_1 = w1 / w0. Its stability polynomial
    T_s(w0 + w1 z) / T_s(w0) stays within [-1, 1] on z in [-beta, 0], beta = (1 + w0) / w1.
    Cached: the arrays returned are shared and must not be written."""
    w0 = 1.0 + damping / (s * s)
    T = [1.0, w0]
    U = [1.0, 2.0 * w0]  # Chebyshev polynomials of the second kind: T_j' = j U_{j-1}
    for _ in range(2, s + 1):
        T.append(2.0 * w0 * T[-1] - T[-2])
        U.append(2.0 * w0 * U[-1] - U[-2])
    w1 = T[s] / (s * U[s - 1])
    b = [1.0 / t for t in T]
    mu, nu, mut = np.zeros(s + 1), np.zeros(s + 1), np.zeros(s + 1)
    mut[1] = w1 / w0
    for j in range(2, s + 1):
        mu[j] = 2.0 * w0 * b[j] / b[j - 1]
        nu[j] = -b[j] / b[j - 2]
        mut[j] = 2.0 * w1 * b[j] / b[j - 1]
    for c in (mu, nu, mut):
        c.setflags(write=False)
    return (1.0 + w0) / w1, mu, nu, mut


@nb.njit(parallel=True, cache=True)
def _largest_diagonal(diag, kind, n):
    chunks = REDUCE_CHUNKS
    m = np.zeros(chunks)
    for c in nb.prange(chunks):
        v = 0.0
        for a in range(c * n // chunks, (c + 1) * n // chunks):
            if kind[a] == 0 and diag[a] > v:
                v = diag[a]
        m[c] = v
    return m.max()


def eigenvalue_bound(diag, kind, n: int) -> float:
    """Gershgorin's bound on the eigenvalues of C: each row's diagonal sum_b c_ab (walls
    twice) plus its off-diagonal sum over fluid b, at most twice the largest diagonal."""
    return 2.0 * float(_largest_diagonal(diag, kind, n))


@nb.njit(parallel=True, cache=True)
def _rkc_stage(op, kind, ax, az, y1x, y1z, y2x, y2z, outx, outz, mu, nu, mut_dt, n):
    """out = mu y1 + nu y2 + mut dt (a - C y1) on the fluid rows, 0 elsewhere (Y_0 = 0), with
    (C y1)_a = diag_a y1_a - s_a, s_a the threads' shares of row a (``_offdiagonal_shares`` of
    y1, summed here in thread order as ``forces.sum_thread_rows`` would)."""
    _, _, _, _, _, diag, shares, start, split, ncx, ncz, periodic = op
    lo, hi, wrap = thread_bounds(start, split, ncx, ncz, periodic)
    for a in nb.prange(n):
        if kind[a] == 0:
            sx = sz = 0.0
            for t in range(shares.shape[0]):
                if wrote(lo, hi, wrap, t, a):
                    sx += shares[t, a, 0]
                    sz += shares[t, a, 1]
            outx[a] = mu * y1x[a] + nu * y2x[a] + mut_dt * (ax[a] - diag[a] * y1x[a] + sx)
            outz[a] = mu * y1z[a] + nu * y2z[a] + mut_dt * (az[a] - diag[a] * y1z[a] + sz)
        else:
            outx[a] = outz[a] = 0.0


@nb.njit(parallel=True, cache=True)
def _first_stage(kind, ax, az, y0x, y0z, y1x, y1z, mut_dt, n):
    """Y_0 = 0, Y_1 = mut_1 dt a on the fluid rows."""
    for a in nb.prange(n):
        y0x[a] = y0z[a] = 0.0
        if kind[a] == 0:
            y1x[a] = mut_dt * ax[a]
            y1z[a] = mut_dt * az[a]
        else:
            y1x[a] = y1z[a] = 0.0


@nb.njit(parallel=True, cache=True)
def _take_increment(kind, dx, dz, ax, az, inv_dt, n):
    for a in nb.prange(n):
        if kind[a] == 0:
            ax[a] = dx[a] * inv_dt
            az[a] = dz[a] * inv_dt


def substep(op, kind, dt: float, ax, az, n: int, work) -> int:
    """Overwrite (ax, az) of the fluid rows of [0, n) with delta / dt, delta integrating
    d delta / dt = a - C delta from 0 over dt (the laminar term at v^n + delta, the rest at
    the evaluation) by first-order RKC with as many stages as ``rkc_stages`` asks for dt
    times ``eigenvalue_bound``: explicit stages, each one product with C (``op``, from
    ``operator``); ``work``: scratch of shape (SUBSTEP_WORK_ROWS, >= n). Returns the stages."""
    diag = op[5]
    s = rkc_stages(dt * eigenvalue_bound(diag, kind, n))
    _, mu, nu, mut = rkc_coefficients(s)
    ys = [(work[0], work[1]), (work[2], work[3]), (work[4], work[5])]  # Y_{j-2}, Y_{j-1}, Y_j
    _first_stage(kind, ax, az, *ys[0], *ys[1], mut[1] * dt, n)
    for j in range(2, s + 1):
        (y2x, y2z), (y1x, y1z), (ox, oz) = ys
        offdiagonal_shares(op, y1x, y1z)
        _rkc_stage(op, kind, ax, az, y1x, y1z, y2x, y2z, ox, oz, mu[j], nu[j], mut[j] * dt, n)
        ys = [ys[1], ys[2], ys[0]]
    _take_increment(kind, *ys[1], ax, az, 1.0 / dt, n)
    return s


@nb.njit(parallel=True, cache=True)
def largest_fluid_acceleration(ax, az, kind, n):
    """max |a| over the fluid particles of [0, n) (0 for none)."""
    chunks = REDUCE_CHUNKS
    m = np.zeros(chunks)
    for c in nb.prange(chunks):
        v = 0.0
        for a in range(c * n // chunks, (c + 1) * n // chunks):
            if kind[a] == 0:
                v = max(v, ax[a] * ax[a] + az[a] * az[a])
        m[c] = v
    return math.sqrt(m.max())
