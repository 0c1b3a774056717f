"""Lubrication theory of a Herschel-Bulkley front on a belt (generalising docs/scheme.md section 5).

A film of depth h on a bed at rest, driven by g S along the bed (S: the effective slope),
is yielded below h0 = h - tau_y / (rho g S) and carries a plug above it:
  u(z) = n/(n+1) A (h0^p - (h0 - z)^p) for z < h0, u_p = n/(n+1) A h0^p above,
  A = (rho g S / K)^(1/n), p = (n + 1) / n,
  q(h, S) = int_0^h u dz = u_p (h - h0 / (p + 1))        (0 when h <= tau_y / (rho g S)).
On the belt (speed u_b upslope) the lab-frame flux vanishes where the flow is steady, so the
flux relative to the belt is q(h, S) = u_b h:
- the normal depth h_n solves q(h_n, sin theta) = u_b h_n;
- at each depth h < h_n the driving slope S(h) solves q(h, S) = u_b h, and
  S = sin theta + cos theta dh/dxi (xi upslope from the toe), so
  xi(h) = int_0^h cos theta / (S(h') - sin theta) dh'.
Newtonian (tau_y = 0, n = 1, K = mu): h_n = sqrt(3 mu u_b / (rho g sin theta)) and
xi tan(theta) / h_n = atanh(eta) - eta, as in ``lubrication``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .roots import REL as ROOT_REL
from .roots import bisect


@dataclass(frozen=True)
class HBFluid:
    rho: float
    tau_y: float
    K: float
    n: float

    def film(self, z, h: float, S: float, g: float):
        """u(z) of the film of depth h under driving slope S (bed at rest)."""
        z = np.minimum(np.asarray(z, dtype=float), h)
        h0 = max(h - self.tau_y / (self.rho * g * S), 0.0)
        p = (self.n + 1) / self.n
        A = (self.rho * g * S / self.K) ** (1 / self.n)
        return self.n / (self.n + 1) * A * (h0 ** p - (h0 - np.minimum(z, h0)) ** p)

    def flux(self, h: float, S: float, g: float) -> float:
        """q(h, S) of the module docstring (``fluxes`` at one point)."""
        return float(self.fluxes(np.float64(h), np.float64(S), g))

    def fluxes(self, h, S, g: float):
        """q(h, S) of the module docstring, elementwise over arrays (0 where h <= the yield depth)."""
        h0 = h - self.tau_y / (self.rho * g * S)
        yielded = h0 > 0
        h0 = np.where(yielded, h0, 0.0)
        p = (self.n + 1) / self.n
        A = (self.rho * g * S / self.K) ** (1 / self.n)
        u_p = self.n / (self.n + 1) * A * h0 ** p
        return np.where(yielded, u_p * (h - h0 / (p + 1)), 0.0)


def normal_depth(fluid: HBFluid, u_b: float, g: float, theta: float) -> float:
    """h_n: q(h_n, sin theta) = u_b h_n (q / h grows with h, from 0 at the yield depth)."""
    S = math.sin(theta)
    h_y = fluid.tau_y / (fluid.rho * g * S)
    hi = max(2.0 * h_y, 1e-6)
    while fluid.flux(hi, S, g) < u_b * hi:
        hi *= 2.0
    return bisect(lambda h: fluid.flux(h, S, g) - u_b * h, h_y, hi)


def driving_slope(fluid: HBFluid, h: float, u_b: float, g: float) -> float:
    """S(h): q(h, S) = u_b h (q grows with S, from 0 at S = tau_y / (rho g h)); ``driving_slopes``
    at one depth."""
    return float(driving_slopes(fluid, np.array([h], dtype=float), u_b, g)[0])


def driving_slopes(fluid: HBFluid, h, u_b: float, g: float) -> np.ndarray:
    """S at each depth of ``h``: from the bracket [tau_y / (rho g h), the first doubling of
    max(2 lo, 1e-6) with q >= u_b h], halved as ``roots.bisect`` halves, all depths at once."""
    h = np.asarray(h, dtype=float)
    lo = fluid.tau_y / (fluid.rho * g * h)
    hi = np.maximum(2.0 * lo, 1e-6)
    short = fluid.fluxes(h, hi, g) < u_b * h
    while short.any():
        hi = np.where(short, 2.0 * hi, hi)
        short &= fluid.fluxes(h, hi, g) < u_b * h
    active = np.ones(h.shape, dtype=bool)
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        below = fluid.fluxes(h, mid, g) - u_b * h < 0
        lo = np.where(active & below, mid, lo)
        hi = np.where(active & ~below, mid, hi)
        active &= ~(hi - lo <= ROOT_REL * hi)
        if not active.any():
            break
    return 0.5 * (lo + hi)


def front_profile(fluid: HBFluid, u_b: float, g: float, theta: float, eta_max: float = 0.999,
                  points: int = 4000):
    """(xi / h_n, eta = h / h_n) of the steady front from the toe up to eta_max, by the
    midpoint rule on a grid refined towards both ends."""
    h_n = normal_depth(fluid, u_b, g, theta)
    s = 0.5 * (1 - np.cos(np.linspace(0.0, math.pi, points)))  # clusters at 0 and 1
    eta = s * eta_max
    mid = 0.5 * (eta[1:] + eta[:-1])
    slope = driving_slopes(fluid, mid * h_n, u_b, g)
    dxi = math.cos(theta) / (slope - math.sin(theta)) * np.diff(eta)  # in units of h_n
    return np.concatenate([[0.0], np.cumsum(dxi)]), eta
