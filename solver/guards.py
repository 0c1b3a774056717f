"""Divergence detectors. Each returns a reason string, or '' when the state is sound."""
from __future__ import annotations

import math

import numba as nb
import numpy as np

from .forces import REDUCE_CHUNKS as CHUNKS


@nb.njit(parallel=True, cache=True)
def fluid_health(x, z, u, w, rho, mass, kind, n, rho0, walls, periodic, px0, period, out):
    """One pass over fluid particles, in CHUNKS chunks (the sums do not depend on the threads).

    out[0]: number of non-finite fluid values, out[1]: max |rho/rho0 - 1|,
    out[2]: max depth of a fluid particle inside a wall rectangle (0 if none),
    out[3]: kinetic energy sum 0.5 m |v|^2.
    """
    part = np.zeros((CHUNKS, 4))
    inv_rho0 = 1.0 / rho0
    for c in nb.prange(CHUNKS):
        nbad = dev = pen = ke = 0.0
        for i in range(c * n // CHUNKS, (c + 1) * n // CHUNKS):
            if kind[i] != 0:
                continue
            if not (math.isfinite(x[i]) and math.isfinite(z[i]) and math.isfinite(u[i])
                    and math.isfinite(w[i]) and math.isfinite(rho[i])):
                nbad += 1.0
                continue
            dev = max(dev, abs(rho[i] * inv_rho0 - 1.0))
            ke += 0.5 * mass[i] * (u[i] * u[i] + w[i] * w[i])
            xi, zi = x[i], z[i]
            if periodic and not (px0 <= xi < px0 + period):
                xi = px0 + (xi - px0) % period
            for k in range(walls.shape[0]):
                if walls[k, 0] < xi < walls[k, 1] and walls[k, 2] < zi < walls[k, 3]:
                    pen = max(pen, min(xi - walls[k, 0], walls[k, 1] - xi, zi - walls[k, 2],
                                       walls[k, 3] - zi))
        part[c, 0], part[c, 1], part[c, 2], part[c, 3] = nbad, dev, pen, ke
    out[0] = part[:, 0].sum()
    out[1] = part[:, 1].max()
    out[2] = part[:, 2].max()
    out[3] = part[:, 3].sum()


def check(health, guards, dp: float) -> str:
    """Reason for divergence from the fluid_health summary, or ''."""
    if health[0] > 0:
        return f"non-finite values in {int(health[0])} fluid particles"
    if health[1] > guards.max_density_deviation:
        return (f"density deviation max|rho/rho0 - 1| = {health[1]:.3g} exceeds "
                f"guards.max_density_deviation = {guards.max_density_deviation:g}")
    if health[2] > guards.penetration * dp:
        return (f"a fluid particle crossed a wall: {health[2] / dp:.2f} dp inside "
                f"(guards.penetration = {guards.penetration:g} dp)")
    return ""


def worst_density(x, z, rho, kind, n: int, rho0: float) -> str:
    """Where the fluid's largest finite |rho/rho0 - 1| lies, for a density-deviation reason:
    ' (rho/rho0 - 1 = DEV at x = X m, z = Z m)', in the scene's frame; '' without fluid."""
    fluid = np.flatnonzero(kind[:n] == 0)
    dev = np.abs(rho[fluid] / rho0 - 1.0)
    dev = np.where(np.isfinite(dev), dev, -1.0)
    if fluid.size == 0 or dev.max() < 0:
        return ""
    i = fluid[int(np.argmax(dev))]
    return f" (rho/rho0 - 1 = {rho[i] / rho0 - 1.0:+.3g} at x = {x[i]:.4g} m, z = {z[i]:.4g} m)"


def check_dt(dt: float, dt_first: float, guards) -> str:
    if not math.isfinite(dt) or dt < guards.min_dt_fraction * dt_first:
        return (f"time step collapsed: dt = {dt:.3g} s below guards.min_dt_fraction = "
                f"{guards.min_dt_fraction:g} of the first dt ({dt_first:.3g} s)")
    return ""
