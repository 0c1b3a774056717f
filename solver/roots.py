"""Root of a monotone scalar function by bisection."""
from __future__ import annotations

REL = 1e-13  # the bracket's width at which the halving stops, relative to its upper end


def bisect(f, lo: float, hi: float, rel: float = REL) -> float:
    """x in [lo, hi] with f(x) = 0 for an increasing f with f(lo) < 0 <= f(hi): halves the
    bracket until hi - lo <= rel hi (at most 200 halvings)."""
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if f(mid) < 0:
            lo = mid
        else:
            hi = mid
        if hi - lo <= rel * hi:
            break
    return 0.5 * (lo + hi)
