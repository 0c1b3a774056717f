"""The pair loop (docs/scheme.md section 6): continuity with Fourtakas diffusion, pressure,
Lo & Shao laminar viscosity, and the shifting sums, over a half stencil.

Fluid-wall pairs never attract: their P_a + P_b is floored at zero. A fluid in suction next
to a wall (negative gauge pressure, as in the corner of a belt running into a fixed wall)
would otherwise be drawn through the wall by the symmetric pressure term.

Each pair (a, b) is visited once (b after a in a's grid column, or in the next column, and
within 2h of a in z: two ranges of the z-sorted columns, ``cells``) and its contributions are
added to both particles, into per-thread accumulators ``acc[t, i, q]`` (no write races; the
slots of one particle share a cache line), reduced afterwards; a's sums stay in registers
over the b loop (a tuple, ``add``). For each a the candidates b are first listed without a
branch (each one written, the count advanced only for those within 2h and not wall-wall), then
the pair terms run over that list: in a flowing arrangement the 2h test fails for about half
the candidates at random, and a branch per candidate then mispredicts. The slots q are
declared in SLOT_GROUPS; what a scene does not use is compiled out (``PairOptions``).

  drho_a/dt = rho_a sum_b u_ab.gradW_ab V_b + h c0 D_a
  D_a = 2 delta sum_b ((rho_a - rho_b) - rho_ab^H) (r_ab.gradW_ab) / (r^2 + eta^2) V_b
  rho_ab^H (reference "spec") = rho0 ((1 + rho0 g_n (z_b - z_a) / B)^(1/7) - 1), as the paper prints it;
  rho_ab^H (reference "column") = rho0 g_n (z_b - z_a) / c0^2 (rho0 / rho_m)^5, rho_m = (rho_a + rho_b)/2:
  the Tait column at rest (d rho/dz = -rho0^6 g_n / (c0^2 rho^5), g_n > 0) by the midpoint
  rule, antisymmetric in a and b and with no residual on such a column (docs/numerics.md)
  du_a/dt = -sum_b m_b (P_a + P_b)/(rho_a rho_b) gradW_ab   (P_a + P_b >= 0 for fluid-wall pairs)
            + sum_b m_b 4 nu (r_ab.gradW_ab) / ((rho_a + rho_b)(r^2 + eta^2)) u_ab  (+ g)
  gradC_a = sum_b dp^2 gradW_ab,  div r_a = -sum_b dp^2 r_ab.gradW_ab
  div(dr)_a = sum_b V_b (dr_b - dr_a).gradW_ab   (dr: the last shift, zero for walls)
In the two shifting sums every particle's volume is its lattice cell dp^2, not m/rho, so the
concentration measures particle number density, which is what shifting evens out. With m/rho,
a wall whose mDBC density follows the fluid pressure looks less concentrated than the fluid
beside it and draws fluid into it, and a particle compressed by shifting (density correction)
looks smaller and draws its neighbours further onto it: both feed back step after step.
"""
from __future__ import annotations

import functools
import math
import types
from typing import NamedTuple

import numba as nb
import numpy as np
from numba.cpython.unsafe.tuple import tuple_setitem

from .kernel import ETA2, alpha_2d, grad_coefficient, grad_factor, w_value
from .sources import variant_named

# ---- accumulator slots ------------------------------------------------------------------
# The pair sums of particle i are acc[thread, i, slot]. A loop variant holds the groups whose
# switch is on, in this order (``slot_layout``); this table is where every slot is declared.
SLOT_GROUPS = (
    ("always", ("AX", "AZ", "DRHO")),  # acceleration, drho/dt
    # packing: gradC, div r, the kernel-weighted inward normals of nearby wall particles (where
    # shifting must not push), div(dr) of the last shift (its density correction)
    ("packing", ("GCX", "GCZ", "DIVR", "WNX", "WNZ", "DIVDR")),
    # consistent laminar term: sum_b V_b gradW_ab, div r with m/rho, the normaliser N
    ("laminar_correction", ("VGX", "VGZ", "VDIVR", "NORM")),
    ("velocity_gradient", ("DUX", "DUZ", "DWX", "DWZ")),  # sum_b V_b (u_b - u_a) gradW_ab (rheology)
    ("stress_transpose", ("TX", "TZ")),  # div of nu (grad u)^T, sum_b V_b (S_b - S_a) . gradW_ab
    ("strain_correction", ("LAPG", "SUPP")),  # Laplacian of the last strain rate, the support
    ("volume", ("VOLC",)),  # the volume relaxation's concentration sum_b V_b W_ab
    ("implicit", ("DIAG",)),  # the diagonal sum_b c_ab of the implicit laminar system
)
Slots = NamedTuple("Slots", [(name, int) for _, names in SLOT_GROUPS for name in names] + [("nq", int)])
AX, AZ, DRHO = 0, 1, 2  # present in every variant


class PairOptions(NamedTuple):
    """The pair loop's compile-time switches: one compiled loop per distinct value."""
    diffusion: int = 0  # density diffusion: 0 off, 1 the paper's rho^H_ab, 2 the Tait column's
    # 0 off; 1 the packing sums that shifting reads; 2 and the volume relaxation's concentration
    packing: int = 0
    laminar_correction: bool = False  # the consistent, normalised laminar term's sums
    rheology: int = 0  # 0 one viscosity, 1 each particle's nu_p, 2 and the strain rate's Laplacian
    stress: bool = False  # with rheology: the divergence of the stress form's transpose term
    artificial: bool = False  # Monaghan's artificial viscosity
    implicit_walls: float = 0.0  # > 0: list the fluid pairs and sum the implicit diagonal

    def groups(self) -> dict[str, bool]:
        """Which slot groups of SLOT_GROUPS this variant sums."""
        return {"always": True, "packing": self.packing >= 1,
                "laminar_correction": self.laminar_correction,
                "velocity_gradient": self.rheology >= 1,
                "stress_transpose": self.stress and self.rheology >= 1,
                "strain_correction": self.rheology == 2, "volume": self.packing == 2,
                "implicit": self.implicit_walls > 0.0}


def slot_layout(options: PairOptions) -> Slots:
    """Each slot's index in this variant's accumulators (-1: not summed) and their number."""
    index, nq = {}, 0
    on = options.groups()
    for group, names in SLOT_GROUPS:
        for name in names:
            index[name] = nq if on[group] else -1
            nq += on[group]
    return Slots(**index, nq=nq)


class PairList(NamedTuple):
    """Fluid-fluid pairs (i, j) and their laminar weights k_ij = -4 nu_ij (r.gradW) /
    ((rho_i + rho_j)(r^2 + eta^2)) (symmetric, >= 0), listed by the thread that visited them:
    thread t's are [0, count[t]) of row t; more than the capacity counts but is not stored."""
    i: np.ndarray      # (threads, capacity) int32
    j: np.ndarray      # (threads, capacity) int32
    k: np.ndarray      # (threads, capacity) float64
    count: np.ndarray  # (threads,) int64


def pair_list(threads: int, capacity: int) -> PairList:
    return PairList(np.zeros((threads, capacity), dtype=np.int32),
                    np.zeros((threads, capacity), dtype=np.int32),
                    np.zeros((threads, capacity)), np.zeros(threads, dtype=np.int64))


# Binomial series of (1 + x)^(1/7) - 1 to x^5, split into even and odd powers: f(+-x) = E +- O.
C1 = 1.0 / 7.0
C2 = C1 * (C1 - 1.0) / 2.0
C3 = C2 * (C1 - 2.0) / 3.0
C4 = C3 * (C1 - 3.0) / 4.0
C5 = C4 * (C1 - 4.0) / 5.0
SERIES_MAX = 0.02  # |x| below which the series is used: truncation error |C6| x^6 < 1.1e-12

# No-NaN/no-infinity assumptions stay off, so that a diverging state still yields non-finite
# values for the guards; contraction (FMA), reciprocals and reassociation are allowed.
FASTMATH = {"contract", "arcp", "reassoc", "nsz"}


@nb.njit(inline="always", cache=True)
def hydrostatic_pair(x):
    """((1 + x)^(1/7) - 1, (1 - x)^(1/7) - 1): series for |x| < SERIES_MAX (x is
    rho0 g_n dz / B, about 0.01 for a pair 2h apart in the cases here), pow beyond."""
    if abs(x) < SERIES_MAX:
        x2 = x * x
        even = x2 * (C2 + x2 * C4)
        odd = x * (C1 + x2 * (C3 + x2 * C5))
        return even + odd, even - odd
    return (1.0 + x) ** (1.0 / 7.0) - 1.0, (1.0 - x) ** (1.0 / 7.0) - 1.0


@nb.njit(inline="always", cache=True)
def thread_rows(start, split, t, ncx, ncz):
    """Particle range [lo, hi) thread t writes: its columns and the next one (half stencil)."""
    return start[split[t] * ncz], start[min(split[t + 1] + 1, ncx) * ncz]


class PairFields(NamedTuple):
    """Particle arrays the pair loop reads, in cell order. sdx, sdz: the last shift (read
    only with the shifting density correction); wnx, wnz: inward wall normals; cell: each
    particle's lattice cell dx dz (the volume the shifting's concentration counts)."""
    x: np.ndarray
    z: np.ndarray
    u: np.ndarray
    w: np.ndarray
    rho: np.ndarray
    p: np.ndarray
    mass: np.ndarray
    kind: np.ndarray
    wnx: np.ndarray
    wnz: np.ndarray
    sdx: np.ndarray
    sdz: np.ndarray
    nu_p: np.ndarray  # each particle's kinematic viscosity (read with variable_viscosity only)
    gamma: np.ndarray  # each particle's last strain rate (read with strain_correction only)
    cell: np.ndarray  # lattice cell dx dz of each particle (read with shifting only)
    irho: np.ndarray  # 1 / rho of each particle (``pressure_and_inverse_density``)
    vscale: np.ndarray  # each particle's laminar-term factor (read with laminar_correction only)
    # each particle's c = 2 nu G / N of the last evaluation, its laminar term's first-order error
    # c . grad u (``viscous_scale_factors``; read with laminar_correction only)
    vcx: np.ndarray
    vcz: np.ndarray
    # the last transpose stress S_ij = nu d_i u_j (read with the stress form only)
    sxx: np.ndarray
    sxz: np.ndarray
    szx: np.ndarray
    szz: np.ndarray


class PairConstants(NamedTuple):
    """Scene constants of the pair loop: hc0 = h c0; k_hyd = rho0 g_z / B and
    k_col = rho0 g_z / c0^2 (g_z < 0) for the two diffusion references."""
    h: float
    nu: float
    hc0: float
    rho0: float
    k_hyd: float
    k_col: float
    delta: float
    av: float  # alpha h c0 of the artificial viscosity (0: off)


# ---- the paper's terms of one pair (a, b), gradW_ab = F r_ab, each inlined into the loop ----

@nb.njit(inline="always", cache=True)
def two_reciprocals(x, y):
    """(1 / x, 1 / y) from one division: 1 / (x y) times y, and times x."""
    inv = 1.0 / (x * y)
    return inv * y, inv * x


@nb.njit(inline="always", cache=True)
def continuity_terms(ra, rb, F, vdotr):
    """(rho_a, rho_b) u_ab . gradW_ab = rho F (u_ab . r_ab): a's term per V_b and b's per V_a
    (u_ba . gradW_ba is the same product)."""
    udotg = F * vdotr
    return ra * udotg, rb * udotg


@nb.njit(inline="always", cache=True)
def pressure_factor(pa, pb, ira, irb, F, fluid_wall):
    """pt = (P_a + P_b) / (rho_a rho_b) F, so that du_a/dt gets -m_b pt r_ab; for a
    fluid-wall pair P_a + P_b is floored at 0 (a wall pushes, never pulls)."""
    psum = pa + pb
    if fluid_wall and psum < 0.0:
        psum = 0.0
    return psum * (ira * irb) * F


@nb.njit(inline="always", cache=True)
def laminar_factor(nu, rdotg, inv_rsum, inv_r2e):
    """vt = 4 nu (r_ab . gradW_ab) / ((rho_a + rho_b)(r^2 + eta^2)), so that du_a/dt gets
    m_b vt u_ab (Lo & Shao); inv_rsum = 1 / (rho_a + rho_b)."""
    return 4.0 * nu * rdotg * inv_rsum * inv_r2e


@nb.njit(inline="always", cache=True)
def pair_viscosity(nu_a, nu_b, fluid_wall, a_is_fluid):
    """nu_ab: the geometric mean sqrt(nu_a nu_b) of two fluid particles; for a fluid-wall pair
    the fluid particle's own. Across a yield surface the two differ by up to mu_max / mu; the
    harmonic mean lets the plug edge shear too much, the arithmetic one too little
    (docs/numerics.md)."""
    if fluid_wall:
        return nu_a if a_is_fluid else nu_b
    return math.sqrt(nu_a * nu_b)


@nb.njit(inline="always", cache=True)
def artificial_factor(av, vdotr, inv_rsum, inv_r2e, F):
    """Monaghan's Pi_ab F, so that du_a/dt gets -m_b Pi_ab F r_ab:
    Pi_ab = -alpha h c0 (u_ab . r_ab) / (rho_ab (r^2 + eta^2)), rho_ab = (rho_a + rho_b) / 2,
    for approaching pairs (u_ab . r_ab < 0), 0 otherwise; av = alpha h c0,
    inv_rsum = 1 / (rho_a + rho_b)."""
    if vdotr >= 0.0:
        return 0.0
    return -2.0 * av * vdotr * inv_rsum * inv_r2e * F


@nb.njit(inline="always", cache=True)
def pair_scale(sca, scb, ka, kb):
    """The laminar factor of a pair: the mean of its two fluid particles' factors, or a
    fluid-wall pair's fluid particle's (``viscous_scale_factors``)."""
    if kb == 1:
        return sca
    if ka == 1:
        return scb
    return 0.5 * (sca + scb)


@nb.njit(inline="always", cache=True)
def diffusion_weight(delta, hc0, rdotg, inv_r2e):
    """g = 2 delta h c0 (r_ab . gradW_ab) / (r^2 + eta^2), the weight of D_a's pair term."""
    return 2.0 * delta * hc0 * rdotg * inv_r2e


@nb.njit(inline="always", cache=True)
def diffusion_spec(g, drab, dz, rho0, k_hyd):
    """(a's, b's) terms g ((rho_a - rho_b) - rho^H_ab), per V_b and V_a, with the paper's
    rho^H_ab = rho0 ((1 + k_hyd (z_a - z_b))^(1/7) - 1), k_hyd = rho0 g_z / B."""
    fa, fb = hydrostatic_pair(k_hyd * dz)
    return g * (drab - rho0 * fa), g * (-drab - rho0 * fb)


@nb.njit(inline="always", cache=True)
def diffusion_column(g, drab, dz, inv_rsum, rho0, k_col):
    """g ((rho_a - rho_b) - rho^H_ab) with the Tait column's
    rho^H_ab = k_col (z_a - z_b) (rho0 / rho_m)^5, rho_m = (rho_a + rho_b) / 2 = 1 / (2 inv_rsum);
    b gets its negative."""
    rm = 2.0 * rho0 * inv_rsum
    rm2 = rm * rm
    return g * (drab - k_col * dz * rm2 * rm2 * rm)


@nb.njit(inline="always", cache=True)
def concentration_terms(F, dx, dz, rdotg):
    """gradW_ab and -r_ab . gradW_ab: times c_b (b's lattice cell dx dz) they are a's shares of
    gradC = sum_b c_b gradW_ab and div r = -sum_b c_b r_ab . gradW_ab; times c_a, b's shares
    (gradC's with the opposite sign)."""
    return F * dx, F * dz, -rdotg


@nb.njit(inline="always", cache=True)
def add(s, q, v):
    """The running sums s (a tuple, kept in registers) with v added to slot q."""
    return tuple_setitem(s, q, s[q] + v)


@nb.njit(inline="always", cache=True)
def add_pair(s, at, b, q, to_a, to_b):
    """A pair's share of slot q: ``to_a`` to a's running sums s, ``to_b`` to b's row of at."""
    at[b, q] += to_b
    return tuple_setitem(s, q, s[q] + to_a)


@functools.cache
def make_pair_loop(options: PairOptions):
    """Compile the pair loop for ``options`` (``PairOptions``), its slots ``slot_layout(options)``.

    diffusion: D_a with the paper's rho^H_ab (1) or the Tait column's (2), fluid pairs only.
    packing: gradC, div r and the wall normals into GCX..WNZ, the last shift's div(dr) into
    DIVDR; at 2 also the concentration sum_b V_b W_ab (every pair with a fluid particle) into VOLC,
    for ``packing.relax_density``. laminar_correction: G = sum_b V_b gradW_ab into VGX, VGZ, div r
    with m/rho volumes into VDIVR and the normaliser N = sum_b V_b (-F) r^4 / (2 (r^2 + eta^2))
    into NORM (``viscous_scale_factors`` makes them the next evaluation's factors); each pair's
    laminar term times the mean of its two particles' factors ``f.vscale`` (a fluid-wall pair's by
    the fluid particle's), and each particle's first-order error c . grad u, c = ``f.vcx``,
    ``f.vcz``, subtracted in the same sums. rheology: each pair's viscosity from the particles'
    nu_p (``pair_viscosity``) and the velocity gradient into DUX..DWZ (``rheology``); with stress
    also the divergence of the last transpose stress S = nu (grad u)^T (``f.sxx`` .. ``f.szz``),
    sum_b V_b (S_b - S_a) . gradW_ab over fluid pairs, into TX, TZ (``add_stress_transpose``); at 2
    also the Laplacian
    2 sum_b V_b (g_a - g_b) F r^2 / (r^2 + eta^2) of the last strain rate g = ``f.gamma`` into LAPG
    and the support sum_b V_b (-F r^2) / 2 into SUPP, over fluid pairs. artificial: Monaghan's
    artificial viscosity (all pairs, walls included, as DualSPHysics). implicit_walls > 0: the
    fluid pairs and their laminar weights listed (``PairList``) and the diagonal sum_b m_b k_ab
    summed into DIAG, fluid-wall pairs weighted by implicit_walls (2 for mDBC, 1 for DBC walls)."""
    o = options
    diffusion, packing, rheology = o.diffusion, o.packing, o.rheology
    laminar_correction, artificial, implicit_walls = o.laminar_correction, o.artificial, o.implicit_walls
    implicit = implicit_walls > 0.0
    velocity_gradient = rheology >= 1
    stress = o.stress and rheology >= 1
    sl = slot_layout(o)
    NQ = sl.nq
    ZERO = (0.0,) * NQ  # a's running sums, one per slot
    GCX, GCZ, DIVR, WNX, WNZ, DIVDR = sl.GCX, sl.GCZ, sl.DIVR, sl.WNX, sl.WNZ, sl.DIVDR
    VGX, VGZ, VDIVR, NORM = sl.VGX, sl.VGZ, sl.VDIVR, sl.NORM
    DUX, DUZ, DWX, DWZ = sl.DUX, sl.DUZ, sl.DWX, sl.DWZ
    TX, TZ = sl.TX, sl.TZ
    LAPG, SUPP, VOLC, DIAG = sl.LAPG, sl.SUPP, sl.VOLC, sl.DIAG

    def thread_pairs(t, f, cl, split, k, acc, pair_i, pair_j, pair_k):
        """Thread t's share of ``pair_loop``: acc[t, i, :] = the pair sums of the particles of
        its columns and of the next column; returns (max h |u_ab . r_ab| / (r^2 + eta^2), the
        number of fluid pairs listed in row t of the ``PairList`` arrays)."""
        x, z, u, w, rho, p, mass, kind, irho = f.x, f.z, f.u, f.w, f.rho, f.p, f.mass, f.kind, f.irho
        start, ncx, ncz, periodic, period = cl.start, cl.ncx, cl.ncz, cl.periodic, cl.period
        h, nu, hc0, rho0 = k.h, k.nu, k.hc0, k.rho0
        fac = grad_coefficient(h)
        eta2 = ETA2 * h * h
        alpha = alpha_2d(h)
        four_h2 = 4.0 * h * h
        two_h = 2.0 * h
        inv_h = 1.0 / h
        at = acc[t]
        lo, hi = thread_rows(start, split, t, ncx, ncz)
        at[lo:hi] = 0.0
        if periodic and split[t + 1] == ncx:
            at[0:start[ncz]] = 0.0
        vm = 0.0
        npl = 0
        cap = pair_i.shape[1]
        # room for one particle's candidates: the rest of its column and the next column's window
        widest = 0
        for ix in range(ncx):
            widest = max(widest, start[(ix + 1) * ncz] - start[ix * ncz])
        near_b = np.empty(2 * widest + 1, dtype=np.uint64)
        near_dx = np.empty(2 * widest + 1)
        near_dz = np.empty(2 * widest + 1)
        near_r2 = np.empty(2 * widest + 1)
        for ix in range(split[t], split[t + 1]):
            # half stencil: b > a in this column and every b of the next column, each
            # within 2h of a in z. Columns are sorted by z (``cells.sort_cells_by``) and a
            # walks its column upwards, so both z windows are ranges whose ends only move up
            jx = ix + 1
            next_shift = 0.0
            has_next = True
            if jx == ncx:
                has_next = periodic
                jx = 0
                next_shift = period
            col_end = start[(ix + 1) * ncz]
            own_hi = start[ix * ncz]
            nx_lo = nx_hi = nx_end = 0
            if has_next:
                nx_lo = nx_hi = start[jx * ncz]
                nx_end = start[(jx + 1) * ncz]
            for a in range(start[ix * ncz], col_end):
                xa, za, ua, wa = x[a], z[a], u[a], w[a]
                ra, pa, ka, ma = rho[a], p[a], kind[a], mass[a]
                ira = irho[a]
                Va = ma * ira
                cell_a = f.cell[a]
                s = ZERO
                sca = f.vscale[a] if laminar_correction else 1.0
                cxa = f.vcx[a] if laminar_correction else 0.0
                cza = f.vcz[a] if laminar_correction else 0.0
                sxa = sza = 0.0
                if packing:
                    sxa, sza = f.sdx[a], f.sdz[a]
                z_lo, z_hi = za - two_h, za + two_h
                own_hi = max(own_hi, a + 1)
                while own_hi < col_end and z[own_hi] < z_hi:
                    own_hi += 1
                while nx_lo < nx_end and z[nx_lo] <= z_lo:
                    nx_lo += 1
                nx_hi = max(nx_hi, nx_lo)
                while nx_hi < nx_end and z[nx_hi] < z_hi:
                    nx_hi += 1
                # the candidates within 2h (and not wall-wall), listed without a branch
                # (module docstring)
                n_near = 0
                for side in range(2):
                    first, b1, shift = (a + 1, own_hi, 0.0) if side == 0 else (nx_lo, nx_hi, next_shift)
                    # unsigned: no negative-index wrap-around on the loads and stores of b
                    for b in range(np.uint64(first), np.uint64(b1)):
                        dx = xa - (x[b] + shift)
                        dz = za - z[b]
                        r2 = dx * dx + dz * dz
                        near_b[n_near] = b
                        near_dx[n_near] = dx
                        near_dz[n_near] = dz
                        near_r2[n_near] = r2
                        n_near += (r2 < four_h2) & (ka + kind[b] != 2)
                for m in range(n_near):
                    b = near_b[m]
                    kb = kind[b]
                    dx = near_dx[m]
                    dz = near_dz[m]
                    r2 = near_r2[m]
                    q = math.sqrt(r2) * inv_h
                    F = grad_factor(q, fac)
                    rb = rho[b]
                    du = ua - u[b]
                    dw = wa - w[b]
                    vdotr = du * dx + dw * dz
                    rdotg = F * r2
                    mb = mass[b]
                    irb = irho[b]
                    Vb = mb * irb
                    inv_r2e, inv_rsum = two_reciprocals(r2 + eta2, ra + rb)
                    ca, cb = continuity_terms(ra, rb, F, vdotr)
                    s = add(s, DRHO, ca * Vb)
                    drho_b = cb * Va
                    # momentum: pressure and laminar viscosity
                    pt = pressure_factor(pa, p[b], ira, irb, F, ka + kb == 1)
                    if rheology:
                        nu_ab = pair_viscosity(f.nu_p[a], f.nu_p[b], ka + kb == 1, ka == 0)
                        vt = laminar_factor(nu_ab, rdotg, inv_rsum, inv_r2e)
                    else:
                        vt = laminar_factor(nu, rdotg, inv_rsum, inv_r2e)
                    if laminar_correction:
                        vt *= pair_scale(sca, f.vscale[b], ka, kb)
                        e = -0.5 * rdotg * r2 * inv_r2e
                        s = add_pair(s, at, b, NORM, Vb * e, Va * e)
                    if artificial:
                        pt += artificial_factor(k.av, vdotr, inv_rsum, inv_r2e, F)
                    fx = -pt * dx + vt * du
                    fz = -pt * dz + vt * dw
                    if laminar_correction:
                        # -c . grad u, grad u_a = sum_b V_b (u_b - u_a) gradW_ab: a's share
                        # V_b (c_a . gradW_ab) u_ab, b's V_a (c_b . gradW_ab) u_ab
                        ga = Vb * F * (cxa * dx + cza * dz)
                        gb = Va * F * (f.vcx[b] * dx + f.vcz[b] * dz)
                        s = add_pair(s, at, b, AX, mb * fx + ga * du, gb * du - ma * fx)
                        s = add_pair(s, at, b, AZ, mb * fz + ga * dw, gb * dw - ma * fz)
                    else:
                        s = add_pair(s, at, b, AX, mb * fx, -(ma * fx))
                        s = add_pair(s, at, b, AZ, mb * fz, -(ma * fz))
                    if implicit:  # k_ab = -vt
                        if ka + kb == 0:
                            if npl < cap:
                                pair_i[t, npl] = a
                                pair_j[t, npl] = b
                                pair_k[t, npl] = -vt
                            npl += 1
                            s = add_pair(s, at, b, DIAG, -(mb * vt), -(ma * vt))
                        elif kb == 1:
                            s = add(s, DIAG, -(implicit_walls * mb * vt))
                        else:
                            at[b, DIAG] -= implicit_walls * ma * vt
                    vr = abs(h * vdotr * inv_r2e)
                    if vr > vm:
                        vm = vr
                    if diffusion:
                        if ka + kb == 0:  # fluid pairs only
                            g = diffusion_weight(k.delta, hc0, rdotg, inv_r2e)
                            if diffusion == 2:
                                ge = diffusion_column(g, ra - rb, dz, inv_rsum, rho0, k.k_col)
                                s = add(s, DRHO, ge * Vb)
                                drho_b -= ge * Va
                            else:
                                ea, eb = diffusion_spec(g, ra - rb, dz, rho0, k.k_hyd)
                                s = add(s, DRHO, ea * Vb)
                                drho_b += eb * Va
                    at[b, DRHO] += drho_b
                    if packing:
                        gx, gz, gdiv = concentration_terms(F, dx, dz, rdotg)
                        cell_b = f.cell[b]
                        s = add_pair(s, at, b, GCX, cell_b * gx, -(cell_a * gx))
                        s = add_pair(s, at, b, GCZ, cell_b * gz, -(cell_a * gz))
                        s = add_pair(s, at, b, DIVR, cell_b * gdiv, cell_a * gdiv)
                        if kb == 1:
                            s = add(s, WNX, -(F * f.wnx[b]))
                            s = add(s, WNZ, -(F * f.wnz[b]))
                        elif ka == 1:
                            at[b, WNX] -= F * f.wnx[a]
                            at[b, WNZ] -= F * f.wnz[a]
                    if laminar_correction:  # gradW_ab = F r_ab; gradW_ba = -gradW_ab
                        s = add_pair(s, at, b, VGX, Vb * F * dx, -(Va * F * dx))
                        s = add_pair(s, at, b, VGZ, Vb * F * dz, -(Va * F * dz))
                        s = add_pair(s, at, b, VDIVR, -(Vb * rdotg), -(Va * rdotg))
                    if velocity_gradient:
                        # (u_b - u_a) gradW_ab for a; (u_a - u_b) gradW_ba = same sign for b
                        s = add_pair(s, at, b, DUX, -(Vb * du * F * dx), -(Va * du * F * dx))
                        s = add_pair(s, at, b, DUZ, -(Vb * du * F * dz), -(Va * du * F * dz))
                        s = add_pair(s, at, b, DWX, -(Vb * dw * F * dx), -(Va * dw * F * dx))
                        s = add_pair(s, at, b, DWZ, -(Vb * dw * F * dz), -(Va * dw * F * dz))
                    if stress and ka + kb == 0:
                        # (S_b - S_a) . gradW_ab for a; (S_a - S_b) . gradW_ba, the same, for b
                        tx = ((f.sxx[b] - f.sxx[a]) * dx + (f.sxz[b] - f.sxz[a]) * dz) * F
                        tz = ((f.szx[b] - f.szx[a]) * dx + (f.szz[b] - f.szz[a]) * dz) * F
                        s = add_pair(s, at, b, TX, Vb * tx, Va * tx)
                        s = add_pair(s, at, b, TZ, Vb * tz, Va * tz)
                    if rheology == 2 and ka + kb == 0:
                        lg = 2.0 * (f.gamma[a] - f.gamma[b]) * rdotg * inv_r2e
                        s = add_pair(s, at, b, LAPG, Vb * lg, -(Va * lg))
                        s = add_pair(s, at, b, SUPP, -(0.5 * Vb * rdotg), -(0.5 * Va * rdotg))
                    if packing == 2:
                        Wab = w_value(q, alpha)
                        s = add_pair(s, at, b, VOLC, Vb * Wab, Va * Wab)
                    if packing:
                        # (dr_b - dr_a) . gradW_ab, with V_b into a, V_a into b
                        e = F * ((f.sdx[b] - sxa) * dx + (f.sdz[b] - sza) * dz)
                        s = add_pair(s, at, b, DIVDR, Vb * e, Va * e)
                for q in range(NQ):
                    at[a, q] += s[q]
        return vm, npl

    thread_pairs = nb.njit(cache=True, fastmath=FASTMATH)(variant_named(thread_pairs, options))

    def pair_loop(f, cl, split, k, acc, vmax, pair_i, pair_j, pair_k, pair_count):
        """acc[t, i, :] = the pair sums of the particles thread t writes (``PairFields`` f,
        ``cells.CellList`` cl, ``PairConstants`` k); vmax[t] = max h |u_ab . r_ab| / (r^2 + eta^2);
        with implicit viscosity, thread t's fluid pairs in row t of the ``PairList`` arrays.
        The threads' work is ``thread_pairs``, compiled without the parallel passes: run on
        its long body, they took about half of the loop's compile time."""
        options  # noqa: B018 -- in the closure, so that each variant has its own cache entry
        for t in nb.prange(split.size - 1):
            # the gufunc types t as uint64 and the loop outside it as int64: one signature
            vmax[t], pair_count[t] = _thread_pairs(  # noqa: F821 -- a global given below
                np.uint64(t), f, cl, split, k, acc, pair_i, pair_j, pair_k)

    # The kernel is a global of pair_loop alone, not a closure variable: numba's cache key
    # includes the closure's contents, and a dispatcher pickles with a random id, so that the
    # loop would be compiled afresh in every process.
    pair_loop = types.FunctionType(pair_loop.__code__, dict(globals(), _thread_pairs=thread_pairs),
                                   pair_loop.__name__, None, pair_loop.__closure__)
    return nb.njit(parallel=True, cache=True)(variant_named(pair_loop, options))


@nb.njit(cache=True)
def thread_bounds(start, split, ncx, ncz, periodic):
    """(lo, hi, wrap): thread t wrote particles [lo[t], hi[t]) (``thread_rows``) and, with a
    periodic x, the last thread also [0, wrap[t]) (column 0, the next column of the last one)."""
    nt = split.size - 1
    lo = np.empty(nt, dtype=np.int64)
    hi = np.empty(nt, dtype=np.int64)
    wrap = np.zeros(nt, dtype=np.int64)
    for t in range(nt):
        lo[t], hi[t] = thread_rows(start, split, t, ncx, ncz)
        if periodic and split[t + 1] == ncx:
            wrap[t] = start[ncz]
    return lo, hi, wrap


@nb.njit(inline="always", cache=True)
def wrote(lo, hi, wrap, t, i):
    """Whether thread t wrote particle i (``thread_bounds``)."""
    return (lo[t] <= i < hi[t]) or i < wrap[t]


@nb.njit(inline="always", cache=True)
def sum_row(acc, lo, hi, wrap, i, out):
    """out[:, i] = sum_t acc[t, i, :] over the threads that wrote particle i, in thread order
    (0 where none did; a copy where one did, as most rows are)."""
    nq = acc.shape[2]
    owners = 0
    last = 0
    for t in range(acc.shape[0]):
        if wrote(lo, hi, wrap, t, i):
            owners += 1
            last = t
    if owners == 1:
        for q in range(nq):
            out[q, i] = acc[last, i, q]
        return
    for q in range(nq):
        out[q, i] = 0.0
    for t in range(acc.shape[0]):
        if wrote(lo, hi, wrap, t, i):
            for q in range(nq):
                out[q, i] += acc[t, i, q]


@nb.njit(parallel=True, cache=True)
def sum_thread_rows(acc, start, split, ncx, ncz, periodic, out, n):
    """out[q, i] = sum_t acc[t, i, q] over the threads that wrote particle i of [0, n) (thread
    t writes the particles of its columns and of the next column, ``thread_rows``; with a
    periodic x the last thread's next column is column 0), 0 where none did. One pass."""
    lo, hi, wrap = thread_bounds(start, split, ncx, ncz, periodic)
    for i in nb.prange(n):
        sum_row(acc, lo, hi, wrap, i, out)


REDUCE_CHUNKS = 64  # particle chunks of the reductions over particles


@nb.njit(parallel=True, cache=True)
def reduce_accumulators(acc, kind, split, cl, gx, gz, out, n):
    """out = the threads' pair sums (``sum_thread_rows``), gravity added to fluid
    accelerations, in one pass.

    Returns max |a| over fluid particles (for dt1).
    """
    lo, hi, wrap = thread_bounds(cl.start, split, cl.ncx, cl.ncz, cl.periodic)
    part = np.zeros(REDUCE_CHUNKS)
    for c in nb.prange(REDUCE_CHUNKS):
        v = 0.0
        for i in range(c * n // REDUCE_CHUNKS, (c + 1) * n // REDUCE_CHUNKS):
            sum_row(acc, lo, hi, wrap, i, out)
            if kind[i] == 0:
                out[0, i] += gx
                out[1, i] += gz
                v = max(v, out[0, i] * out[0, i] + out[1, i] * out[1, i])
        part[c] = v
    return math.sqrt(part.max())


VISCOUS_CORRECTION_MIN_DIVR = 1.9  # div r (m/rho volumes) of a particle with (nearly) full support


@nb.njit(parallel=True, cache=True)
def add_stress_transpose(out, kind, rho, rho0, n, sl):
    """The stress form's second half (``numerics.viscous_form: stress``): with a variable
    viscosity, div(2 mu D) = div(mu grad u) + div(mu (grad u)^T). The pair loop's laminar term
    is the first part; this adds the second to each fluid particle,

      a_i += (rho0 / rho_a) d_j S_ij,   S_ij = nu d_i u_j,

    with d_j S_ij the pair loop's sum_b V_b (S_b - S_a)_ij d_j W_ab over fluid pairs (TX, TZ)
    and S the last evaluation's (``store_stress_transpose``). Explicit and one evaluation behind,
    like the viscosity: an implicit laminar update keeps it in the right-hand side. Returns the
    largest fluid |a| afterwards (dt1)."""
    part = np.zeros(REDUCE_CHUNKS)
    for c in nb.prange(REDUCE_CHUNKS):
        v = 0.0
        for i in range(c * n // REDUCE_CHUNKS, (c + 1) * n // REDUCE_CHUNKS):
            if kind[i] != 0:
                continue
            f = rho0 / rho[i]
            out[AX, i] += f * out[sl.TX, i]
            out[AZ, i] += f * out[sl.TZ, i]
            v = max(v, out[AX, i] * out[AX, i] + out[AZ, i] * out[AZ, i])
        part[c] = v
    return math.sqrt(part.max())


@nb.njit(parallel=True, cache=True)
def store_stress_transpose(out, kind, nu_p, n, sl, sxx, sxz, szx, szz):
    """S_ij = nu_a d_i u_j of each fluid particle, from this evaluation's velocity gradient
    (DUX .. DWZ) and the viscosity it gives (``rheology.update_viscosity``), for the next
    evaluation. nu times the strain rate is the fluid's stress over rho0, bounded by the
    rheology even where nu itself jumps between the cap and the yielded values; zero for walls."""
    for i in nb.prange(n):
        if kind[i] != 0:
            sxx[i] = sxz[i] = szx[i] = szz[i] = 0.0
            continue
        nu = nu_p[i]
        sxx[i] = nu * out[sl.DUX, i]
        sxz[i] = nu * out[sl.DWX, i]
        szx[i] = nu * out[sl.DUZ, i]
        szz[i] = nu * out[sl.DWZ, i]


@nb.njit(parallel=True, cache=True)
def viscous_scale_factors(out, kind, n, sl, nu, scale, cx, cz):
    """The consistent laminar term's factors for the next evaluation, from this one's sums: for
    fluid particles with div r >= 1.9 (m/rho volumes) scale = 1 / N and c = 2 nu G / N,
    elsewhere scale = 1 and c = 0 (N = out[sl.NORM], G = out[sl.VGX], out[sl.VGZ]).

    By Taylor expansion the laminar term sum_b 2 nu V_b F_ab u_ab approximates
    nu (M : grad grad u + 2 G . grad u), G = sum_b V_b gradW_ab, M = -sum_b V_b F r_ab r_ab.
    On a disordered arrangement G is not zero, and in a film its product with the large shear
    makes the term too weak: the pair loop subtracts c . grad u. For the isotropic
    u = |r|^2 / 4 (laplacian 1) the term gives nu N, N = sum_b V_b (-F) r^4 / (2 (r^2 + eta^2)),
    which a continuous kernel without eta makes 1; on a square lattice at Ch 1.8, N = 0.982
    (0.995 from div r / 2, the rest from eta), and so is the film's response nu u''. Dividing by
    N removes the isotropic part of that error. Near the free surface (div r < 1.9) G measures
    the missing neighbours rather than disorder and the support is cut: the term is left as it
    is. The pair loop applies these one evaluation later; G, a sum that nearly cancels, also
    moves with each step's density corrections, so that the lagged c is not the current one
    (docs/numerics.md, departure 3)."""
    for i in nb.prange(n):
        if kind[i] == 0 and out[sl.VDIVR, i] >= VISCOUS_CORRECTION_MIN_DIVR:
            s = 1.0 / out[sl.NORM, i]
            scale[i] = s
            cx[i] = 2.0 * nu * s * out[sl.VGX, i]
            cz[i] = 2.0 * nu * s * out[sl.VGZ, i]
        else:
            scale[i] = 1.0
            cx[i] = cz[i] = 0.0


@nb.njit(inline="always", cache=True)
def tait(rho, B, rho0):
    """P = B ((rho/rho0)^7 - 1)."""
    r = rho / rho0
    r2 = r * r
    return B * (r2 * r2 * r2 * r - 1.0)


@nb.njit(parallel=True, cache=True)
def equation_of_state(rho, p, B, rho0):
    """Tait: P = B ((rho/rho0)^7 - 1)."""
    for i in nb.prange(rho.size):
        p[i] = tait(rho[i], B, rho0)


@nb.njit(parallel=True, cache=True)
def pressure_and_inverse_density(rho, p, irho, B, rho0):
    """Tait's P (``equation_of_state``) and 1 / rho, which the pair loop reads."""
    for i in nb.prange(rho.size):
        p[i] = tait(rho[i], B, rho0)
        irho[i] = 1.0 / rho[i]
