"""Start-up from rest of a film on an incline (docs/flow-film.md).

A film of depth h on a plane inclined at theta, at rest at t = 0: no slip at z = 0, a free
surface (u_z = 0) at z = h, z normal to the plane:

  u_t = nu u_zz + g sin(theta),   u(0, t) = 0,   u_z(h, t) = 0,   u(z, 0) = 0.

Solution: the steady film minus a decaying sine series,

  u = (g sin(theta) / nu) (h z - z^2 / 2)
      - sum_n>=0 (2 g sin(theta) / (nu h lambda_n^3)) sin(lambda_n z) exp(-nu lambda_n^2 t),
  lambda_n = (2 n + 1) pi / (2 h).

The sin(lambda_n z) are the eigenfunctions with u = 0 at z = 0 and u_z = 0 at z = h; the
coefficients are the sine coefficients of the steady profile f(z) = h z - z^2 / 2 (f'' = -1,
f(0) = f'(h) = 0, cos(lambda_n h) = 0): (2 / h) int_0^h f sin(lambda_n z) dz = 2 / (h lambda_n^3)
by two integrations by parts. The film is the lower half of the start-up plane Poiseuille flow
between plates at z = 0 and z = 2 h (its midplane is a symmetry plane, u_z = 0), term for term:
with L = 2 h, 4 F L^2 / (nu pi^3 k^3) = 2 F / (nu h lambda_n^3) for k = 2 n + 1 and
k^2 pi^2 / L^2 = lambda_n^2. ``velocity`` therefore evaluates solver.exact.poiseuille.
"""
from __future__ import annotations

import math

import numpy as np

from solver import exact


def u_max(h: float, nu: float, g: float, theta: float) -> float:
    """Steady surface velocity g sin(theta) h^2 / (2 nu), the largest velocity of the film at
    any time (theta in radians)."""
    return g * math.sin(theta) * h * h / (2.0 * nu)


def velocity(z, t: float, h: float, nu: float, g: float, theta: float, terms: int = 200):
    """u(z, t) of the start-up film (module docstring) from its first ``terms`` terms, for
    0 <= z <= h (NaN outside), theta in radians. The truncation error is below
    8 / (pi^3 (2 terms - 1)^2) u_max at t = 0 (the coefficients fall as 1/k^3) and falls as
    exp(-nu lambda_terms^2 t)."""
    z = np.asarray(z, dtype=float)
    u = exact.poiseuille(z, t, 2.0 * h, g * math.sin(theta), nu, terms=terms)
    return np.where((z >= 0.0) & (z <= h), u, np.nan)


def settling_time(h: float, nu: float, fraction: float) -> float:
    """The time past which the surface velocity is within ``fraction`` of u_max, from the
    slowest term: u_max - u(h, t) = u_max (32 / pi^3) exp(-nu lambda_0^2 t) (the next term is
    smaller by the factor exp(-8 nu lambda_0^2 t) / 27), so t = (4 h^2 / (pi^2 nu)) ln(32 / (pi^3 fraction));
    for fraction <= 0.5 the neglected terms move t by less than 1e-3 of it."""
    return 4.0 * h * h / (math.pi ** 2 * nu) * math.log(32.0 / (math.pi ** 3 * fraction))
