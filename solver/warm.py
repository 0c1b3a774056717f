"""Warm start of a conveyor case from the final state of a run at another resolution.

The fine lattice fills the region under the coarse run's free surface, from the upstream wall
to the toe: the C = 0.5 level of its last probe sample (``final_surface``, the surface its
metrics measure), held at its value 2h from the wall nearer the wall (where the wall's
particles enter C), or, in a run that lacks it, the top of each coarse particle column plus
dp/2 (which a disordered top row puts low). Rows are spaced to hold the source's last uniform
depth in a whole number of rows, so that the body starts at that depth, not rounded to the
fine dp. Densities start hydrostatic as for any profile; velocities are the Shepard
interpolation of the coarse fluid velocities, u(r) = sum_j u_j W(r - r_j) / sum_j W(r - r_j)
with the coarse h. The belt runs at full speed from t = 0.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import xarray as xr

from .kernel import alpha_2d, w_value


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
