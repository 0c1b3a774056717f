"""The acoustic edge of C_CFL: the largest C at which the laminar term and the density diffusion
still damp the step's acoustic pair (docs/numerics.md).

Linearised about fluid at rest on a square lattice (spacing dp, V = dp^2, rho = rho0), a plane
wave exp(i k.x) sees the solver's pair sums (solver/forces.py) through their symbols, with
x_ba = x_b - x_a, gradW_ab = F(r) x_ab and the sums over the lattice points b within 2h:
- the pressure gradient and the continuity sum: G(k) = -sum_b V F x_ba sin(k.x_ba), so that
  omega = c0 |G| (G -> k for k h -> 0);
- the laminar term (Lo & Shao) and the density diffusion: L(k) = sum_b V (-2F) r^2 / (r^2 + eta^2)
  (1 - cos(k.x_ba)), damping rates g = nu L and d = delta h c0 L (L -> k^2).
Under the explicit density update (``Simulation.step``) the mode's amplification on
(rho, v, dt D^{n-1}) is, with a = omega dt, b = g dt, e = d dt:
- rho_h = rho^n + dt/2 D^{n-1}; D = -omega v^n - d rho_h (the previous step's rate drifts it);
- v^{n+1} = exp(-b) v^n + a rho_h, rho^{n+1} = rho^n + dt D. exp(-b) is the laminar term
  sub-stepped or implicit. An explicit one damps as (1 - b), at least as much for b up to 1.28;
  its own stability at larger b is the viscous limit's (dt3), so the edge takes exp(-b) for
  every update (``amplification`` has both forms).
With dt = C h / c0 and r = nu / (c0 h): a = C h|G|, b = C r h^2 L, e = delta C h^2 L. Undamped
(b = e = 0) every mode grows; C*(Ch, r, delta) is the first C at which some k of the lattice's
quarter zone has spectral radius above 1. Nothing here is fitted to runs; the measured edges it
is checked against are in docs/numerics.md.
"""
from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from .kernel import ETA2, grad_coefficient

MARGIN = 0.85  # the rule's C is at most this fraction of C*
N_K = 16  # wavenumbers per axis of the quarter zone (0, pi / dp]
C_STEP = 0.01  # the edge's search steps in C, then bisection
C_SEARCH_MAX = 3.0  # beyond this C the search stops (the force limit binds long before)


def symbols(ch: float, kx, kz) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(h G_x, h G_z, h^2 L) at the wavenumbers (kx, kz) dp (arrays), for h = ch dp: dimensionless,
    the same for every dp."""
    h = ch  # dp = 1
    n = int(math.ceil(2.0 * ch)) + 1
    i, j = np.meshgrid(np.arange(-n, n + 1), np.arange(-n, n + 1), indexing="ij")
    x, z = i.ravel().astype(float), j.ravel().astype(float)  # x_ba
    r = np.hypot(x, z)
    inside = (r > 0) & (r < 2.0 * h)
    x, z, r = x[inside], z[inside], r[inside]
    F = grad_coefficient(h) * (1.0 - 0.5 * r / h) ** 3  # gradW_ab = F x_ab (solver/kernel.py)
    lap_weight = -2.0 * F * r * r / (r * r + ETA2 * h * h)
    phase = np.ravel(kx)[:, None] * x + np.ravel(kz)[:, None] * z
    s = np.sin(phase)
    return (-h * (s * (F * x)).sum(axis=1), -h * (s * (F * z)).sum(axis=1),
            h * h * ((1.0 - np.cos(phase)) * lap_weight).sum(axis=1))


@lru_cache(maxsize=16)
def lattice_symbols(ch: float, n_k: int = N_K) -> tuple[np.ndarray, np.ndarray]:
    """(h |G(k)|, h^2 L(k)) over k dp in (0, pi] x [0, pi] (n_k by n_k + 1 points)."""
    kx, kz = np.meshgrid(np.linspace(0.0, math.pi, n_k + 1)[1:], np.linspace(0.0, math.pi, n_k + 1),
                         indexing="ij")
    hgx, hgz, h2l = symbols(ch, kx, kz)
    return np.hypot(hgx, hgz), h2l


def _matrices(a, b, e, rows) -> np.ndarray:
    """3x3 step matrices, one per entry of the broadcast arrays a, b, e; ``rows(a, b, e)`` gives
    the three rows, each a list of three arrays."""
    a, b, e = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (a, b, e)))
    return np.stack([np.stack(row, axis=-1) for row in rows(a, b, e)], axis=-2)


def amplification(a, b, e, explicit_viscosity: bool = False) -> np.ndarray:
    """The explicit density update's step matrices on (rho, v, dt D^{n-1}), one per entry of the
    arrays a = omega dt, b = g dt, e = d dt."""
    def rows(a, b, e):
        damp = (1.0 - b) if explicit_viscosity else np.exp(-b)
        return ([1.0 - e, -a, -0.5 * e],  # rho^n + dt D
                [a, damp, 0.5 * a],  # damp v^n + a rho_h
                [-e, -a, -0.5 * e])  # dt D
    return _matrices(a, b, e, rows)


def spectral_radius(m: np.ndarray) -> np.ndarray:
    return np.abs(np.linalg.eigvals(m)).max(axis=-1)


def held(c: float, ch: float, r: float, delta: float, step=amplification) -> bool:
    """Whether every lattice mode is held (spectral radius <= 1) at C = ``c`` under ``step``
    (the explicit density update by default), the laminar term damping as exp(-b)."""
    hg, h2l = lattice_symbols(ch)
    m = step(c * hg, c * r * h2l, delta * c * h2l)
    return bool(spectral_radius(m).max() <= 1.0 + 1e-12)


@lru_cache(maxsize=256)
def edge(ch: float, r: float, delta: float, step=amplification) -> float:
    """C*(Ch, r, delta): the first C from 0 upwards at which a lattice mode grows under ``step``
    (steps of C_STEP, then bisection to 1e-4); ``C_SEARCH_MAX`` where none grows below it; below
    C_STEP where C_STEP itself is not held (0 without any damping)."""
    c = C_STEP
    while held(c, ch, r, delta, step):
        c += C_STEP
        if c > C_SEARCH_MAX:
            return C_SEARCH_MAX
    lo, hi = c - C_STEP, c
    while hi - lo > 1e-4:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if held(mid, ch, r, delta, step) else (lo, mid)
    return lo


def damped_cfl(cfl: float, ch: float, r: float, delta: float | None) -> float:
    """The acoustic C of ``cfl_rule: damping``: min(cfl, MARGIN C*(Ch, r, delta))."""
    return min(cfl, MARGIN * edge(ch, r, delta or 0.0))
