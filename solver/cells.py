"""Cell-linked list: cells of side >= 2h, particles kept sorted by cell.

Cell id = ix * ncz + iz, so the cells of a grid column are consecutive; within each cell the
particles are sorted by z, so each column is sorted by z and a neighbour search can take a
z window of a column as one range (the pair loop, the mDBC update). Boundary particles whose
3x3 cell neighbourhood holds no fluid go to a sentinel bucket after the last cell: they take
part in no pair loop.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numba as nb
import numpy as np

@dataclass(frozen=True)
class Grid:
    x0: float
    z0: float
    csx: float
    csz: float
    ncx: int
    ncz: int
    periodic: bool
    period: float

    @property
    def ncells(self) -> int:
        return self.ncx * self.ncz

    @classmethod
    def cover(cls, x0, x1, z0, z1, reach, periodic):
        """Grid over [x0, x1] x [z0, z1] with cells no smaller than ``reach``."""
        ncx = max(int(math.floor((x1 - x0) / reach)), 1) if periodic else int(math.ceil((x1 - x0) / reach))
        ncz = max(int(math.ceil((z1 - z0) / reach)), 1)
        csx = (x1 - x0) / ncx if periodic else reach
        if periodic and ncx < 3:
            raise ValueError("periodic grid needs at least 3 cells across the period")
        return cls(x0, z0, csx, reach, max(ncx, 1), ncz, periodic, (x1 - x0) if periodic else 0.0)

    def cell_list(self, start: np.ndarray) -> CellList:
        """The grid with its sorted particle ranges, as the kernels take it."""
        return CellList(start, float(self.x0), float(self.z0), float(self.csx), float(self.csz),
                        int(self.ncx), int(self.ncz), bool(self.periodic), float(self.period))


class CellList(NamedTuple):
    """What a kernel needs to walk neighbours: cell c = ix * ncz + iz holds the particles
    start[c] .. start[c + 1] - 1; cells of csx x csz from (x0, z0); periodic in x with
    ``period`` when ``periodic``."""
    start: np.ndarray
    x0: float
    z0: float
    csx: float
    csz: float
    ncx: int
    ncz: int
    periodic: bool
    period: float


@nb.njit(inline="always", cache=True)
def cell_of(cl, px, pz):
    """(ix, iz) of the cell holding point (px, pz) (possibly outside the grid)."""
    return int(math.floor((px - cl.x0) / cl.csx)), int(math.floor((pz - cl.z0) / cl.csz))


@nb.njit(inline="always", cache=True)
def neighbour_cell(cl, ix, iz, ddx, ddz):
    """(cell id, x shift to add to its particles) of cell (ix + ddx, iz + ddz), wrapping in x
    when periodic; cell -1 when outside the grid."""
    jx = ix + ddx
    jz = iz + ddz
    shift = 0.0
    if jz < 0 or jz >= cl.ncz:
        return -1, shift
    if jx < 0 or jx >= cl.ncx:
        if not cl.periodic:
            return -1, shift
        shift = -cl.period if jx < 0 else cl.period
        jx = jx + cl.ncx if jx < 0 else jx - cl.ncx
    return jx * cl.ncz + jz, shift


@nb.njit(inline="always", cache=True)
def neighbour_column(cl, ix, ddx):
    """(column, x shift to add to its particles) of column ix + ddx, wrapping in x when
    periodic; column -1 when outside the grid."""
    jx = ix + ddx
    if 0 <= jx < cl.ncx:
        return jx, 0.0
    if not cl.periodic:
        return -1, 0.0
    return (jx + cl.ncx, -cl.period) if jx < 0 else (jx - cl.ncx, cl.period)


@nb.njit(inline="always", cache=True)
def column_window(cl, z, jx, iz, z_lo):
    """[lo, hi): the particles of column jx's cells iz - 1 .. iz + 1 (those in the grid), lo
    moved up to the first with z >= z_lo (bisection: a column is sorted by z). A caller
    walking up from lo stops at its own upper z."""
    jlo = max(iz - 1, 0)
    jhi = min(iz + 1, cl.ncz - 1)
    if jlo > jhi:
        return 0, 0
    lo = cl.start[jx * cl.ncz + jlo]
    hi = cl.start[jx * cl.ncz + jhi + 1]
    a, b = lo, hi
    while a < b:
        m = (a + b) // 2
        if z[m] < z_lo:
            a = m + 1
        else:
            b = m
    return a, hi


@nb.njit(parallel=True, cache=True)
def assign_cells(x, z, kind, cl, cell):
    """Write each particle's cell (sentinel ncx*ncz for idle boundary particles).

    Returns the index of a fluid particle outside the grid, or -1.
    """
    n = x.size
    ncx, ncz = cl.ncx, cl.ncz
    ncells = ncx * ncz
    for i in nb.prange(n):
        ix, iz = cell_of(cl, x[i], z[i])
        if ix < 0 or ix >= ncx or iz < 0 or iz >= ncz or not (math.isfinite(x[i]) and math.isfinite(z[i])):
            cell[i] = ncells
        else:
            cell[i] = ix * ncz + iz
    has_fluid = np.zeros(ncells + 1, dtype=np.bool_)
    for i in range(n):
        if kind[i] == 0:
            has_fluid[cell[i]] = True
    bad = -1
    if has_fluid[ncells]:
        for i in range(n):
            if kind[i] == 0 and cell[i] == ncells:
                bad = i
                break
    for i in nb.prange(n):
        if kind[i] == 0 or cell[i] == ncells:
            continue
        c = cell[i]
        ix = c // ncz
        iz = c - ix * ncz
        near = False
        for dx in range(-1, 2):
            jx = ix + dx
            if jx < 0:
                jx += ncx
            elif jx >= ncx:
                jx -= ncx
            for dz in range(-1, 2):
                jz = iz + dz
                if jz < 0 or jz >= ncz:
                    continue
                if has_fluid[jx * ncz + jz]:
                    near = True
        if not near:
            cell[i] = ncells
    return bad


SORT_CHUNKS = 2  # particle chunks of the counting sort (placed in parallel, in chunk order)


@nb.njit(parallel=True, cache=True)
def counting_sort(cell, nbuckets, order, start):
    """order: particle indices sorted by cell, stable; start[c]..start[c+1] is cell c's range.
    Each chunk of particles counts its cells, then places its particles after those of the
    chunks before it in the same cell."""
    n = cell.size
    slots = np.zeros((SORT_CHUNKS, nbuckets), dtype=np.int64)
    for k in nb.prange(SORT_CHUNKS):
        for i in range(k * n // SORT_CHUNKS, (k + 1) * n // SORT_CHUNKS):
            slots[k, cell[i]] += 1
    total = 0
    for c in range(nbuckets):
        start[c] = total
        for k in range(SORT_CHUNKS):
            count = slots[k, c]
            slots[k, c] = total
            total += count
    start[nbuckets] = total
    for k in nb.prange(SORT_CHUNKS):
        for i in range(k * n // SORT_CHUNKS, (k + 1) * n // SORT_CHUNKS):
            c = cell[i]
            order[slots[k, c]] = i
            slots[k, c] += 1


@nb.njit(parallel=True, cache=True)
def sort_cells_by(key, order, start, ncells):
    """Within each of the first ``ncells`` cells, order its particles by ascending key[i]
    (insertion sort: the last step's order, which the stable counting sort keeps, is nearly
    sorted already). With key = z every grid column is then sorted by z."""
    for c in nb.prange(ncells):
        lo, hi = start[c], start[c + 1]
        for i in range(lo + 1, hi):
            v = order[i]
            kv = key[v]
            j = i - 1
            while j >= lo and key[order[j]] > kv:
                order[j + 1] = order[j]
                j -= 1
            order[j + 1] = v


@nb.njit(parallel=True, cache=True)
def gather(src, order, dst):
    for i in nb.prange(order.size):
        dst[i] = src[order[i]]


@nb.njit(cache=True)
def column_split(cl, nthreads, split):
    """Columns [split[t], split[t+1]) for thread t, balancing particle counts."""
    start, ncx, ncz = cl.start, cl.ncx, cl.ncz
    total = start[ncx * ncz]
    split[0] = 0
    t = 1
    for ix in range(ncx):
        if t >= nthreads:
            break
        if start[(ix + 1) * ncz] >= total * t / nthreads:
            split[t] = ix + 1
            t += 1
    while t <= nthreads:
        split[t] = ncx
        t += 1
