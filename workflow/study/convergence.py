"""Observed order of convergence, Richardson extrapolation and the Grid Convergence Index
(Roache; Celik et al. 2008, J. Fluids Eng. 130:078001) for three resolutions.

Grids h1 < h2 < h3 (fine to coarse), r21 = h2/h1, r32 = h3/h2, solutions phi1..phi3,
eps21 = phi2 - phi1, eps32 = phi3 - phi2, s = sign(eps32/eps21), and the observed order
from the fixed point p = |ln|eps32/eps21| + q(p)| / ln r21, q(p) = ln((r21^p - s)/(r32^p - s)).
phi_ext = (r21^p phi1 - phi2)/(r21^p - 1), e_a = |(phi1 - phi2)/phi1|,
GCI_fine = 1.25 e_a / (r21^p - 1).
Only monotone convergence (0 < eps21/eps32 < 1) gets numbers; oscillatory (ratio < 0) and
divergent (ratio >= 1) sequences are flagged, not forced into a number.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass
class GCIResult:
    status: str  # monotone | oscillatory | divergent | insufficient
    order: float = math.nan
    extrapolated: float = math.nan
    gci_fine: float = math.nan  # relative
    error_fine: float = math.nan  # |phi1 - phi_ext| / |phi_ext|


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
    e21, e32 = f2 - f1, f3 - f2
    if e32 == 0 or e21 == 0:
        return GCIResult("insufficient" if e21 == e32 == 0 else "divergent")
    ratio = e21 / e32
    if ratio < 0:
        return GCIResult("oscillatory")
    if ratio >= 1:
        return GCIResult("divergent")
    r21, r32 = h2 / h1, h3 / h2
    s = math.copysign(1.0, e32 / e21)
    p = abs(math.log(abs(e32 / e21))) / math.log(r21)
    for _ in range(200):
        q = math.log((r21 ** p - s) / (r32 ** p - s))
        p_new = abs(math.log(abs(e32 / e21)) + q) / math.log(r21)
        if abs(p_new - p) < 1e-12:
            p = p_new
            break
        p = p_new
    ext = (r21 ** p * f1 - f2) / (r21 ** p - 1)
    ea = abs((f1 - f2) / f1) if f1 != 0 else math.nan
    return GCIResult("monotone", p, ext, safety * ea / (r21 ** p - 1),
                     abs(f1 - ext) / abs(ext) if ext != 0 else math.nan)
