"""Observed order of convergence, Richardson extrapolation and the Grid Convergence Index
(Roache; Celik et al. 2008, J. Fluids Eng. 130:078001) for three resolutions.

Grids h1 < h2 < h3 (fine to coarse), r21 = h2/h1, r32 = h3/h2, solutions phi1..phi3,
eps21 = phi2 - phi1, eps32 = phi3 - phi2, and the observed order p > 0 of a monotone
sequence from eps21 / eps32 = (r21^p - 1) / (r21^p (r32^p - 1)) (Celik's relation for
s = sign(eps32 / eps21) = 1), whose right side falls strictly from ln r21 / ln r32 (p -> 0)
to 0 (p -> inf).
phi_ext = (r21^p phi1 - phi2)/(r21^p - 1), e_a = |(phi1 - phi2)/phi1|,
GCI_fine = 1.25 e_a / (r21^p - 1).
Only monotone convergence (0 < eps21/eps32 < ln r21 / ln r32, which is 1 for a constant ratio)
gets numbers; oscillatory (ratio < 0) and divergent sequences (no order p > 0 fits) are
flagged, not forced into a number.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from solver.roots import bisect

# an observed order below this is no asymptotic convergence: no dp is projected from it
MIN_ORDER = 0.5
# an observed order above this is unreliable: three values whose differences happen to shrink
# fast, not convergence; r21^p so large would shrink the GCI band to nothing. Nothing is
# extrapolated from it (no limit, no band, no dp projected)
MAX_ORDER = 4.0


@dataclass
class GCIResult:
    status: str  # monotone | oscillatory | divergent | insufficient
    order: float = math.nan
    extrapolated: float = math.nan
    gci_fine: float = math.nan  # relative
    error_fine: float = math.nan  # |phi1 - phi_ext| / |phi_ext|


def observed_order(ratio: float, r21: float, r32: float) -> float:
    """p > 0 with (r21^p - 1) / (r21^p (r32^p - 1)) = ratio, for 0 < ratio < ln r21 / ln r32
    (bisection on a strictly decreasing function)."""
    def f(p):
        return (1.0 - r21 ** -p) / (r32 ** p - 1.0) - ratio
    hi = 1.0
    while f(hi) > 0:
        hi *= 2.0
    return bisect(lambda p: -f(p), 0.5 * hi if hi > 1.0 else 1e-9, hi, rel=1e-14)


def gci(h, phi, safety: float = 1.25) -> GCIResult:
    """Three (or more: the three finest are used) resolutions h and solutions phi."""
    h = np.asarray(h, dtype=float)
    phi = np.asarray(phi, dtype=float)
    ok = np.isfinite(h) & np.isfinite(phi)
    h, phi = h[ok], phi[ok]
    if h.size < 3:
        return GCIResult("insufficient")
    order = np.argsort(h)[:3]
    (h1, h2, h3), (f1, f2, f3) = h[order], phi[order]
    r21, r32 = h2 / h1, h3 / h2
    if not (r21 > 1.0 and r32 > 1.0):  # two runs at the same resolution
        return GCIResult("insufficient")
    e21, e32 = f2 - f1, f3 - f2
    if e32 == 0 or e21 == 0:
        return GCIResult("insufficient" if e21 == e32 == 0 else "divergent")
    ratio = e21 / e32
    if ratio < 0:
        return GCIResult("oscillatory")
    if ratio >= math.log(r21) / math.log(r32):
        return GCIResult("divergent")
    p = observed_order(ratio, r21, r32)
    ext = (r21 ** p * f1 - f2) / (r21 ** p - 1)
    ea = abs((f1 - f2) / f1) if f1 != 0 else math.nan
    return GCIResult("monotone", p, ext, safety * ea / (r21 ** p - 1),
                     abs(f1 - ext) / abs(ext) if ext != 0 else math.nan)
