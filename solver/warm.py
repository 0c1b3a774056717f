"""Warm start of a conveyor case from the final state of a run at another resolution.

The fine lattice fills the region under the coarse run's free surface, from the upstream wall
to the toe: the C = 0.5 level of its last probe sample (``final_surface``, the surface its
metrics measure), held at its value 2h from the wall nearer the wall (where the wall's
particles enter C), or, in a run that lacks it, the top of each coarse particle column plus
dp/2 (which a disordered top row puts low). Rows are spaced to hold the source's last uniform
depth in a whole number of rows, so that the body starts at that depth, not rounded to the
fine dp. The fluid particles then take the source's own arrangement (``carry_arrangement``):
a block of its body, scaled to hold one particle per dp^2 of the finer run and tiled over
that region, so that the finer run starts with the disorder the shear has made, not from a
lattice that the shear takes seconds to break. Densities start hydrostatic as for any
profile; velocities are the Shepard interpolation of the coarse fluid velocities,
u(r) = sum_j u_j W(r - r_j) / sum_j W(r - r_j) with the coarse h. The belt runs at full speed
from t = 0.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
import xarray as xr

from .build import hydrostatic_density
from .kernel import alpha_2d, w_value

BLOCK = (0.25, 0.75)  # the body block: this share of the wall-to-toe length
SURFACE_ROWS = 1.5  # the block stops this many source dp below the source's uniform depth
MIN_GAP = 0.45  # a tiled particle closer than this (in dp) to one kept already is dropped
MIN_BLOCK = 50  # fewer source particles in the block: the lattice fill is kept


@dataclass
class WarmState:
    x: np.ndarray  # fluid particles of the final snapshot
    z: np.ndarray
    u: np.ndarray
    w: np.ndarray
    dp: float
    h: float
    toe: float
    status: str
    surface_x: np.ndarray | None = None  # the source run's final C = 0.5 surface, if it has one
    surface_z: np.ndarray | None = None
    depth: float | None = None  # its last uniform depth: the fill's row spacing (``layout.profile_lattice``)

    def surface(self) -> list[list[float]]:
        """(x, z) points of the free surface from x = 0 to the toe."""
        if self.surface_x is not None and self.surface_x.size:
            keep = (self.surface_x < self.toe) & np.isfinite(self.surface_z)
            xs, zs = self.surface_x[keep], self.surface_z[keep]
            off_wall = xs >= 2.0 * self.h
            zs = np.where(off_wall, zs, zs[np.argmax(off_wall)])
            return [[0.0, float(zs[0])]] + [[float(a), float(b)] for a, b in zip(xs, zs)] + [[float(self.toe), 0.0]]
        edges = np.arange(0.0, self.toe + self.dp, self.dp)
        col = np.digitize(self.x, edges) - 1
        top = np.full(edges.size - 1, np.nan)
        np.fmax.at(top, np.clip(col, 0, top.size - 1), self.z)
        xs = 0.5 * (edges[:-1] + edges[1:])
        ok = np.isfinite(top)
        pts = [[0.0, float(top[ok][0] + 0.5 * self.dp)]]
        pts += [[float(a), float(b + 0.5 * self.dp)] for a, b in zip(xs[ok], top[ok]) if a < self.toe]
        pts.append([float(self.toe), 0.0])
        return pts

    def velocity_at(self, px: np.ndarray, pz: np.ndarray, chunk: int = 2000) -> tuple[np.ndarray, np.ndarray]:
        alpha = alpha_2d(self.h)
        u, w = np.zeros(px.size), np.zeros(px.size)
        for k in range(0, px.size, chunk):
            r = np.hypot(px[k:k + chunk, None] - self.x[None], pz[k:k + chunk, None] - self.z[None])
            W = np.where(r < 2 * self.h, w_value(np.minimum(r / self.h, 2.0), alpha), 0.0)
            s = W.sum(1)
            near = np.argmin(r, axis=1)  # no coarse particle in reach: the nearest one
            u[k:k + chunk] = np.where(s > 0, (W * self.u).sum(1) / np.where(s > 0, s, 1), self.u[near])
            w[k:k + chunk] = np.where(s > 0, (W * self.w).sum(1) / np.where(s > 0, s, 1), self.w[near])
        return u, w


def load(path) -> WarmState:
    """The final fluid state of a front run (``python -m solver front`` output)."""
    with xr.open_dataset(path) as ds:
        if "snapshot" not in ds.dims or "toe_position" not in ds:
            raise ValueError(f"{path}: no final particle snapshot to start from")
        if ds.attrs.get("status") == "diverged":
            raise ValueError(f"{path}: the run diverged ({ds.attrs.get('reason', '')}); no state to start from")
        s = ds.isel(snapshot=-1)
        f = s["kind"].values == 0
        line = ds["final_surface"] if "final_surface" in ds else None
        return WarmState(x=s["x"].values[f], z=s["z"].values[f], u=s["u"].values[f], w=s["w"].values[f],
                         dp=float(ds.attrs["dp"]), h=float(ds.attrs["h"]),
                         toe=float(ds["toe_position"].values[-1]), status=str(ds.attrs.get("status")),
                         surface_x=None if line is None else line["surface_x"].values,
                         surface_z=None if line is None else line.values,
                         depth=_last_finite(ds["uniform_depth"].values) if "uniform_depth" in ds else None)


def _last_finite(values) -> float | None:
    ok = np.isfinite(values) & (values > 0)
    return float(values[ok][-1]) if ok.any() else None


def tiled_arrangement(state: WarmState, dp: float, length: float, height: float):
    """(x, z) filling [0, length] x [0, height]: the source's fluid particles in its body block
    (x from BLOCK of the wall-to-toe length, z below its uniform depth less SURFACE_ROWS dp),
    scaled about the block's lower-left corner to a number density of 1 / dp^2 and repeated
    along x and z; of two points closer than MIN_GAP dp (at the tiles' seams) the later is
    dropped. None where the block holds fewer than MIN_BLOCK particles."""
    if state.depth is None:
        return None
    x0, x1 = BLOCK[0] * state.toe, BLOCK[1] * state.toe
    top = state.depth - SURFACE_ROWS * state.dp
    inside = (state.x >= x0) & (state.x < x1) & (state.z >= 0.0) & (state.z < top)
    if inside.sum() < MIN_BLOCK or top <= 0.0:
        return None
    scale = dp * math.sqrt(inside.sum() / ((x1 - x0) * top))
    bx, bz = (state.x[inside] - x0) * scale, state.z[inside] * scale
    width, depth = (x1 - x0) * scale, top * scale
    jz, ix = np.meshgrid(np.arange(math.ceil(height / depth)), np.arange(math.ceil(length / width)), indexing="ij")
    x = (bx[None] + width * ix.reshape(-1, 1)).ravel()  # tiles along x, then the next row of tiles
    z = (bz[None] + depth * jz.reshape(-1, 1)).ravel()
    keep = (x <= length) & (z <= height)
    x, z = x[keep], z[keep]
    keep = _spaced(x, z, MIN_GAP * dp)
    return x[keep], z[keep]


def _spaced(x: np.ndarray, z: np.ndarray, gap: float) -> np.ndarray:
    """Mask keeping each point unless an earlier kept point lies closer than ``gap``."""
    cells: dict[tuple[int, int], list[int]] = {}
    keep = np.ones(x.size, dtype=bool)
    for i in range(x.size):
        cx, cz = int(x[i] // gap), int(z[i] // gap)
        near = any((x[i] - x[j]) ** 2 + (z[i] - z[j]) ** 2 < gap * gap
                   for a in (-1, 0, 1) for b in (-1, 0, 1) for j in cells.get((cx + a, cz + b), ()))
        if near:
            keep[i] = False
        else:
            cells.setdefault((cx, cz), []).append(i)
    return keep


def carry_arrangement(parts, scene, state: WarmState):
    """``parts`` (fluid first, as ``build.build_particles`` lays them) with its fluid replaced by
    ``tiled_arrangement`` under the scene's fluid profile, off the wall and bed by MIN_GAP dp:
    densities hydrostatic below that surface; each particle's volume the profile's area over
    their number (dp^2 but for the seams' thinning), so that the fluid holds that area; masses
    rho times it. Unchanged where the source gives no arrangement."""
    profile = scene.fluid.profiles[0]
    dp = scene.dp
    length = profile.x[1]
    tiles = tiled_arrangement(state, dp, length, float(np.max(np.asarray(profile.surface)[:, 1])))
    if tiles is None:
        return parts
    x, z = tiles
    top = profile.top(x)
    keep = (x >= MIN_GAP * dp) & (z >= MIN_GAP * dp) & (z < top)
    x, z, top = x[keep], z[keep], top[keep]
    n = x.size
    rho = hydrostatic_density(scene, z, top)
    volume = profile.area / n
    wall = parts.kind != 0
    nan = np.full(n, np.nan)

    def joined(fluid, a):
        return np.concatenate([np.asarray(fluid, dtype=a.dtype), a[wall]])

    return replace(parts, x=joined(x, parts.x), z=joined(z, parts.z), u=joined(np.zeros(n), parts.u),
                   w=joined(np.zeros(n), parts.w), rho=joined(rho, parts.rho),
                   mass=joined(rho * volume, parts.mass), cell_volume=joined(np.full(n, volume), parts.cell_volume),
                   kind=joined(np.zeros(n), parts.kind), wall=joined(np.full(n, -1), parts.wall),
                   gx=joined(nan, parts.gx), gz=joined(nan, parts.gz),
                   pid=np.arange(n + int(wall.sum()), dtype=parts.pid.dtype))
