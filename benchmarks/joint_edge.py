"""The joint acoustic-viscous stability edge of the time integrator, for a damped oscillator.

One mode x'' = -omega^2 x - gamma x' under the solver's step (solver/simulation.py, `step`):
drift x += dt/2 v; evaluate a = -omega^2 x - gamma v (the laminar term at v^n); the velocity
change delta over the step; drift x += dt/2 v^{n+1}. The velocity change is
- explicit: delta = dt a;
- sub-stepped: delta integrates d delta / ds = a - gamma delta from 0 over dt by the solver's own
  first-order RKC stages (solver/implicit.py, `rkc_coefficients`), as many as `rkc_stages` asks
  for dt times the Gershgorin bound, which overestimates the largest eigenvalue by KAPPA (14.9
  against 8.5 nu / h^2 on the jittered Couette channel, docs/numerics.md);
- backward Euler: delta = dt a / (1 + gamma dt).
For each z = gamma dt it prints the largest omega dt with every eigenvalue of the step's
amplification matrix within the unit circle (the undamped edge is 2).

A scalar mode carries both the acoustic and the viscous extreme at once, which SPH modes need not
(the stiffest acoustic and the stiffest shear modes differ), so these edges are a pessimistic
guide, not a bound the particle runs must obey.

Usage: python benchmarks/joint_edge.py [--z 0 0.5 1 1.5 2 3 4 6]
"""
from __future__ import annotations

import argparse

import numpy as np

from solver.implicit import rkc_coefficients, rkc_stages

KAPPA = 14.9 / 8.5  # Gershgorin bound over the largest eigenvalue (jittered Couette channel)


def rkc_gain(z: float, s: int) -> float:
    """delta / (dt a) after s RKC stages of d delta / ds = a - gamma delta, z = gamma dt."""
    _, mu, nu, mut = rkc_coefficients(s)
    y2, y1 = 0.0, mut[1]
    for j in range(2, s + 1):
        y2, y1 = y1, mu[j] * y1 + nu[j] * y2 + mut[j] * (1.0 - z * y1)
    return y1


def gain(z: float, update: str) -> float:
    if update == "explicit":
        return 1.0
    if update == "backward_euler":
        return 1.0 / (1.0 + z)
    return rkc_gain(z, rkc_stages(KAPPA * z))


def spectral_radius(w: float, z: float, update: str) -> float:
    """Of the step's amplification matrix on (x, dt v), w = omega dt, z = gamma dt."""
    g = gain(z, update)
    m = np.empty((2, 2))
    for col, (x, v) in enumerate(((1.0, 0.0), (0.0, 1.0))):
        xh = x + 0.5 * v
        v1 = v + g * (-w * w * xh - z * v)
        m[:, col] = (xh + 0.5 * v1, v1)
    return float(max(abs(np.linalg.eigvals(m))))


def edge(z: float, update: str, w_max: float = 4.0, resolution: float = 1e-3) -> float:
    """Largest omega dt (up to w_max) below which the step is stable at z = gamma dt."""
    w = 0.0
    while w + resolution <= w_max and spectral_radius(w + resolution, z, update) <= 1.0 + 1e-12:
        w += resolution
    return w


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--z", type=float, nargs="+", default=[0, 0.5, 1, 1.5, 2, 2.5, 3, 3.5, 4, 5, 6])
    a = ap.parse_args(argv)
    print("| gamma dt | explicit | sub-stepped (stages) | backward Euler |")
    print("|---|---|---|---|")
    for z in a.z:
        explicit = edge(z, "explicit") if z < 2.0 else 0.0
        print(f"| {z:g} | {explicit:.2f} | {edge(z, 'substepped'):.2f} ({rkc_stages(KAPPA * z)}) | "
              f"{edge(z, 'backward_euler'):.2f} |")


if __name__ == "__main__":
    main()
