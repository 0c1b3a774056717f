"""Scene -> particle arrays: fluid lattice, wall particles and their mDBC ghost nodes."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .layout import laid_walls, lattice, profile_lattice
from .scene import Scene

FLUID, BOUNDARY = 0, 1


@dataclass
class Particles:
    """Structure of arrays, all of length N; boundary-only fields are NaN/-1 for fluid."""

    x: np.ndarray
    z: np.ndarray
    u: np.ndarray
    w: np.ndarray
    rho: np.ndarray
    mass: np.ndarray  # rho(t=0) dx dz: particle volumes match the lattice cells
    cell_volume: np.ndarray  # dx dz, the lattice cell (solver/layout.py; dp^2 where dp divides the sizes)
    kind: np.ndarray  # int8: 0 fluid, 1 boundary
    wall: np.ndarray  # int32: wall index, -1 for fluid
    gx: np.ndarray  # ghost node of a boundary particle
    gz: np.ndarray
    pid: np.ndarray  # int64: original particle number

    @property
    def n(self) -> int:
        return self.x.size


def hydrostatic_density(scene: Scene, z: np.ndarray, top) -> np.ndarray:
    """Density of a Tait column at rest with free surface at ``top`` (bed-normal gravity g_n):
    dP/dz = -rho g_n with dP/drho = c0^2 (rho/rho0)^6 makes rho^6 linear in depth d,
    rho = rho0 (1 + 6 g_n d / c0^2)^(1/6)."""
    rho0, c0 = scene.fluid.density, scene.c0
    d = np.maximum(top - z, 0.0)
    return rho0 * (1.0 + 6.0 * (-scene.gravity[1]) * d / (c0 * c0)) ** (1.0 / 6.0)


def column_tops(x: np.ndarray, z: np.ndarray, dp: float, qx=None, qz=None,
                dz=None) -> np.ndarray:
    """Free-surface height above each query point: the top (+ dz/2) of the contiguous run of
    fluid lattice points in the nearest fluid column (within dp / 2 of the query's x) that
    starts at or just above it.

    Fluid points are (x, z) with row spacings ``dz`` (default dp); points with the same x (to
    1e-6 dp) form a column. Queries default to the fluid points themselves.
    """
    qx = x if qx is None else qx
    qz = z if qz is None else qz
    dz = np.full(x.size, dp) if dz is None else np.asarray(dz, dtype=float)
    col = np.round(x / (1e-6 * dp)).astype(np.int64)
    order = np.lexsort((z, col))
    cs, zs = col[order], z[order]
    # top of each contiguous run (same column, gaps of at most 1.5 rows)
    n = zs.size
    rows = dz[order]
    run_top = zs + 0.5 * rows
    for i in range(n - 2, -1, -1):
        if cs[i + 1] == cs[i] and zs[i + 1] - zs[i] < 1.5 * rows[i]:
            run_top[i] = run_top[i + 1]
    out = np.full(qx.size, -np.inf)
    keys = np.unique(cs)
    key_x = keys * (1e-6 * dp)
    for k in range(qx.size):
        m = int(np.searchsorted(key_x, qx[k]))
        near = [j for j in (m - 1, m) if 0 <= j < keys.size]
        if not near:
            continue
        j_col = min(near, key=lambda j: abs(key_x[j] - qx[k]))
        if abs(key_x[j_col] - qx[k]) > 0.5 * dp * (1.0 + 1e-9):
            continue
        lo = np.searchsorted(cs, keys[j_col], side="left")
        hi = np.searchsorted(cs, keys[j_col], side="right")
        j = lo + np.searchsorted(zs[lo:hi], qz[k] - 0.5 * dp, side="left")
        if j < hi and zs[j] - qz[k] < 1.5 * dp:
            out[k] = run_top[j]
    return out


def _inside_any(px, pz, walls, periodic):
    for w in walls:
        xx = px
        if periodic is not None:
            x0, x1 = periodic
            xx = x0 + np.mod(px - x0, x1 - x0)
        if w.x[0] < xx < w.x[1] and w.z[0] < pz < w.z[1]:
            return True
    return False


def _interface_edges(walls, blocks, periodic, eps):
    """Wall edges that face fluid: the open half-plane beyond the edge holds some fluid
    block, and the edge is not on a periodic end. Each as ((ax, az), (bx, bz))."""
    edges = []
    for w in walls:
        sides = [  # (edge, does the half-plane beyond it hold fluid?)
            (((w.x[0], w.z[0]), (w.x[1], w.z[0])), any(b.z[0] < w.z[0] for b in blocks)),
            (((w.x[0], w.z[1]), (w.x[1], w.z[1])), any(b.z[1] > w.z[1] for b in blocks)),
            (((w.x[0], w.z[0]), (w.x[0], w.z[1])), any(b.x[0] < w.x[0] for b in blocks)),
            (((w.x[1], w.z[0]), (w.x[1], w.z[1])), any(b.x[1] > w.x[1] for b in blocks)),
        ]
        for edge, faces_fluid in sides:
            (ax, az), (bx, bz) = edge
            on_period_end = periodic is not None and ax == bx and (
                abs(ax - periodic[0]) < eps or abs(ax - periodic[1]) < eps)
            if faces_fluid and not on_period_end:
                edges.append(edge)
    return edges


def ghost_node(px: float, pz: float, edges, walls, periodic, eps: float) -> tuple[float, float]:
    """Mirror of (px, pz) through the nearest point of the wall/fluid interface.

    Candidates are the projections on every interface edge and the edge ends; a candidate
    counts when a step beyond it, away from the particle, is outside all walls (so shared
    edges between touching walls are skipped and inner corners mirror diagonally).
    Returns NaNs when no interface is found.
    """
    best, best_d2 = None, np.inf
    for (ax, az), (bx, bz) in edges:
        ex, ez = bx - ax, bz - az
        t = ((px - ax) * ex + (pz - az) * ez) / (ex * ex + ez * ez)
        for tt in (min(max(t, 0.0), 1.0), 0.0, 1.0):
            cx, cz = ax + tt * ex, az + tt * ez
            dx, dz = cx - px, cz - pz
            d2 = dx * dx + dz * dz
            if d2 >= best_d2 or d2 == 0.0:
                continue
            d = np.sqrt(d2)
            if _inside_any(cx + eps * dx / d, cz + eps * dz / d, walls, periodic):
                continue
            best, best_d2 = (cx, cz), d2
    if best is None:
        return np.nan, np.nan
    return 2 * best[0] - px, 2 * best[1] - pz


def build_particles(scene: Scene) -> Particles:
    """Fill fluid regions and walls (``layout``: fluid extents filled exactly, walls laid from
    their fluid faces).

    Density starts hydrostatic (bed-normal gravity) below the local free surface of each
    column, for fluid and for the wall particles under it; each particle's mass is
    rho dx dz so that m/rho is its lattice cell's volume.
    """
    dp = scene.dp
    fx, fz, fu, fw, fdx, fdz = [], [], [], [], [], []
    regions = [(b, lattice(b, dp)) for b in scene.fluid.blocks] + [
        (p, profile_lattice(p, dp)) for p in scene.fluid.profiles]
    for region, (x, z, dx, dz) in regions:
        fx.append(x), fz.append(z), fdx.append(np.full(x.size, dx)), fdz.append(np.full(x.size, dz))
        fu.append(np.full(x.size, region.velocity[0])), fw.append(np.full(x.size, region.velocity[1]))
    fx, fz, fdx, fdz = (np.concatenate(a) for a in (fx, fz, fdx, fdz))
    fu, fw = np.concatenate(fu), np.concatenate(fw)
    frho = hydrostatic_density(scene, fz, column_tops(fx, fz, dp, dz=fdz))

    walls = laid_walls(scene)
    bx, bz, bwall, bdx, bdz = [], [], [], [], []
    for i, lw in enumerate(walls):
        x, z = lw.points()
        bx.append(x), bz.append(z), bwall.append(np.full(x.size, i, dtype=np.int32))
        bdx.append(np.full(x.size, lw.dx)), bdz.append(np.full(x.size, lw.dz))
    if bx:
        bx, bz, bwall, bdx, bdz = (np.concatenate(a) for a in (bx, bz, bwall, bdx, bdz))
    else:
        bx, bz, bdx, bdz = np.zeros(0), np.zeros(0), np.zeros(0), np.zeros(0)
        bwall = np.zeros(0, dtype=np.int32)
    # wall particles under fluid: continue the column above the wall top
    wall_top = np.array([scene.walls[i].z[1] for i in bwall]) if bx.size else np.zeros(0)
    btop = column_tops(fx, fz, dp, bx, wall_top + 0.5 * dp, dz=fdz)
    brho = hydrostatic_density(scene, bz, np.where(np.isfinite(btop), btop, -np.inf))
    gx = np.full(bx.size, np.nan)
    gz = np.full(bx.size, np.nan)
    eps = 1e-6 * dp
    rects = [lw.rect for lw in walls]
    edges = _interface_edges(rects, scene.fluid.extents(), scene.periodic_x, eps)
    for k in range(bx.size):
        gx[k], gz[k] = ghost_node(bx[k], bz[k], edges, rects, scene.periodic_x, eps)

    nf, nb = fx.size, bx.size
    return Particles(
        x=np.concatenate([fx, bx]), z=np.concatenate([fz, bz]),
        u=np.concatenate([fu, np.zeros(nb)]), w=np.concatenate([fw, np.zeros(nb)]),
        rho=np.concatenate([frho, brho]),
        mass=np.concatenate([frho * fdz * fdx, brho * bdz * bdx]),
        cell_volume=np.concatenate([fdz * fdx, bdz * bdx]),
        kind=np.concatenate([np.full(nf, FLUID, np.int8), np.full(nb, BOUNDARY, np.int8)]),
        wall=np.concatenate([np.full(nf, -1, np.int32), bwall]),
        gx=np.concatenate([np.full(nf, np.nan), gx]), gz=np.concatenate([np.full(nf, np.nan), gz]),
        pid=np.arange(nf + nb, dtype=np.int64),
    )
