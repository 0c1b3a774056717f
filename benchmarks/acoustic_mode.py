"""The step's amplification of one linear acoustic mode, and the damping it needs.

One mode of the linearised acoustic pair rho' = -omega v - d rho, v' = omega rho - g v (scaled
density and velocity; d from the density diffusion, g from the laminar term) under the solver's
step (solver/simulation.py, ``step``; solver/integrate.py):
- the density drifts half a step with the previous step's rate, rho_h = rho^n + dt/2 D^{n-1};
- one evaluation at the half step: D = -omega v^n - d rho_h, and the pressure force omega rho_h;
- v^{n+1} = exp(-g dt) v^n + dt omega rho_h (the laminar term damped as the sub-stepped
  update damps it, or ``--explicit-viscosity``: (1 - g dt) v^n), rho^{n+1} = rho^n + dt D.
With a = omega dt, b = g dt, e = d dt it prints the spectral radius of the step's
amplification matrix on (rho, v, dt D^{n-1}) for b = e = 0 (above 1: the undamped mode grows),
and the least damping per step, b alone or e alone, that brings the radius to 1. The last
column is the undamped radius of a leapfrog the solver does not run: the density's second
half step takes the continuity rate at v^{n+1} (rho^{n+1} = rho_h + dt/2 D(v^{n+1}), which
in a particle code is a second pass over the pairs, continuity only).

Usage: python benchmarks/acoustic_mode.py [--a 0.2 0.4 0.6 0.8 1.0 1.2]
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from solver.acoustic_edge import amplification, leapfrog_amplification, spectral_radius  # noqa: E402


def radius(a: float, b: float = 0.0, e: float = 0.0, explicit_viscosity: bool = False) -> float:
    """The solver's step: rho_h = rho^n + dt/2 D^{n-1}, D = -omega v^n - d rho_h."""
    return float(spectral_radius(amplification(a, b, e, explicit_viscosity)))


def leapfrog_radius(a: float) -> float:
    """Undamped, the leapfrog: rho_h = rho^n + dt/2 D(v^n), v^{n+1} = v^n + dt omega rho_h,
    rho^{n+1} = rho_h + dt/2 D(v^{n+1})."""
    return float(spectral_radius(leapfrog_amplification(a, 0.0, 0.0)))


def least_damping(a: float, which: str, explicit_viscosity: bool = False) -> float:
    """Least b (which = "b") or e ("e") per step with radius <= 1: the first crossing found by
    steps of 0.01 from 0 (too much damping is unstable in its own right), then bisection."""
    def r(x):
        b, e = (x, 0.0) if which == "b" else (0.0, x)
        return radius(a, b, e, explicit_viscosity)
    x = 0.0
    while r(x) > 1.0 + 1e-12:
        x += 0.01
        if x > 2.0:
            return float("nan")
    lo, hi = max(x - 0.01, 0.0), x
    for _ in range(40):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if r(mid) > 1.0 + 1e-12 else (lo, mid)
    return hi


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--a", type=float, nargs="+", default=[0.2, 0.4, 0.6, 0.8, 1.0, 1.2])
    ap.add_argument("--explicit-viscosity", action="store_true")
    args = ap.parse_args(argv)
    print("| a = omega dt | radius, undamped | least b = g dt (e = 0) | least e = d dt (b = 0) "
          "| leapfrog's radius, undamped |")
    print("|---|---|---|---|---|")
    for a in args.a:
        print(f"| {a:g} | {radius(a, explicit_viscosity=args.explicit_viscosity):.4f} | "
              f"{least_damping(a, 'b', args.explicit_viscosity):.4f} | "
              f"{least_damping(a, 'e', args.explicit_viscosity):.4f} | {leapfrog_radius(a):.4f} |")


if __name__ == "__main__":
    main()
