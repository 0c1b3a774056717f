"""Where a scene's particles go at its dp (docs/scene.md, "Particle layout").

Fluid blocks and profile columns fill their stated extent exactly: n = round(L / dp) particles
L / n apart along each side (``stretched_points``), so the fluid's area is the scene's whatever
dp is. Each wall is laid from its fluid faces, away from the fluid: the layer nearest a face that fluid
lies beyond sits dp / 2 inside it, hence dp from the fluid lattice of a block that touches the
face (within dp / (4n) of it), and layers go on away from the fluid for the stated thickness or
for every layer a fluid particle can reach, whichever is deeper (``laid_walls``,
``support_layers``). Where every size is a whole number of dp and walls are at least that
thick, every position is the plain lattice lo + (i + 1/2) dp, bit for bit.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

SAME = 1e-9  # relative tolerance within which a length counts as a whole number of spacings
# the closest a fluid particle comes to a wall face, in dp: its lattice starts dp / 2 off the
# face and the wall's density keeps it off (0.13 dp at the least, the toe on the belt during the
# conveyor's start-up at dp = 2.25 mm, tests/test_conveyor.py)
FLUID_STANDOFF = 0.1


def support_layers(h: float, dp: float) -> int:
    """Wall layers, dp apart from dp / 2 inside the face, that lie within the kernel support 2h
    of a fluid particle FLUID_STANDOFF dp off the face: ceil(2h / dp - 1/2 - FLUID_STANDOFF).
    A deeper layer is outside the support of every fluid particle further off the face, so it
    would change no sum (3 layers at h / dp = 1.8, where 2h / dp = 3.6 rounds up to 4); a
    particle closer than that sees it at q >= 2 - FLUID_STANDOFF dp / h, where W is below
    3e-5 of W(0) (h >= dp)."""
    return math.ceil(2.0 * h / dp - 0.5 - FLUID_STANDOFF - SAME)


class LayoutError(ValueError):
    """A region of the scene holds no particle at its dp (scene validation reports it as a SceneError)."""


class Extent(NamedTuple):
    """An axis-aligned rectangle [x0, x1] x [z0, z1] (the fields of solver/scene.py's Rect)."""

    x: tuple[float, float]
    z: tuple[float, float]


def stretched_points(lo: float, hi: float, dp: float) -> tuple[np.ndarray, float]:
    """n = round((hi - lo) / dp) points (hi - lo) / n apart, the first half a spacing inside lo,
    and that spacing: the interval is filled exactly, its spacing within dp (1 +- 1 / (2n)); dp
    itself, bit for bit, where the length is a whole number of dp. n = 0 when the length is
    dp / 2 or less (``check_layout`` refuses such a block or wall)."""
    n = int(round((hi - lo) / dp))
    if n < 1:
        return np.zeros(0), dp
    step = (hi - lo) / n
    if abs(step - dp) <= SAME * dp:
        step = dp
    return lo + (np.arange(n) + 0.5) * step, step


def lattice(rect, dp: float) -> tuple[np.ndarray, np.ndarray, float, float]:
    """Points filling rect: ``stretched_points`` along x and along z, and their spacings (dx, dz):
    the rectangle's area is kept exactly, each cell dx dz."""
    xs, dx = stretched_points(*rect.x, dp)
    zs, dz = stretched_points(*rect.z, dp)
    X, Z = np.meshgrid(xs, zs, indexing="ij")
    return X.ravel(), Z.ravel(), dx, dz


def profile_lattice(profile, dp: float) -> tuple[np.ndarray, np.ndarray, float, float]:
    """Lattice points of a profile region: columns filling [x0, x1] (``stretched_points``), rows
    dz apart from base + dz/2 while below the surface (round((top - base) / dz) rows per column),
    and the spacings (dx, dz), dz the row spacing (``FluidProfile.row_spacing``)."""
    dz = profile.row_spacing(dp)
    xs, dx = stretched_points(*profile.x, dp)
    tops = profile.top(xs)
    X, Z = [], []
    for x, top in zip(xs, tops):
        n = int(np.floor((top - profile.base) / dz + 0.5))
        if n > 0:
            X.append(np.full(n, x))
            Z.append(profile.base + (np.arange(n) + 0.5) * dz)
    if not X:
        return np.zeros(0), np.zeros(0), dx, dz
    return np.concatenate(X), np.concatenate(Z), dx, dz


def _overlap(a: tuple[float, float], b: tuple[float, float]) -> bool:
    """Whether two intervals share a length (touching ends do not)."""
    return min(a[1], b[1]) > max(a[0], b[0])


def fluid_sides(wall, fluid: list, periodic) -> dict[int, tuple[bool, bool]]:
    """For axis 0 (x) and 1 (z): whether fluid lies beyond the wall's lower and upper side, i.e.
    some fluid region reaches past that side and shares a length with the wall along the other
    axis. A side on a periodic end never counts."""
    out = {}
    for axis in (0, 1):
        span = (wall.x, wall.z)[axis]
        other = (wall.z, wall.x)[axis]
        regions = [((r.x, r.z)[axis], (r.z, r.x)[axis]) for r in fluid]
        lower = any(s[0] < span[0] and _overlap(o, other) for s, o in regions)
        upper = any(s[1] > span[1] and _overlap(o, other) for s, o in regions)
        if axis == 0 and periodic is not None:
            eps = 1e-9 * (periodic[1] - periodic[0])
            lower = lower and abs(span[0] - periodic[0]) > eps
            upper = upper and abs(span[1] - periodic[1]) > eps
        out[axis] = (lower, upper)
    return out


@dataclass(frozen=True)
class LaidWall:
    """A wall's particle region ``rect`` (the stated one, its far side moved to
    max(round(T / dp), support_layers) dp from each fluid face, and its ends moved out to meet
    grown walls) and its columns ``xs`` and rows ``zs``, spacings ``dx`` and ``dz``."""

    rect: Extent
    xs: np.ndarray
    zs: np.ndarray
    dx: float
    dz: float

    def points(self) -> tuple[np.ndarray, np.ndarray]:
        X, Z = np.meshgrid(self.xs, self.zs, indexing="ij")
        return X.ravel(), Z.ravel()


def _from_face(lo: float, hi: float, dp: float, layers: int, face_upper: bool):
    """``layers`` positions dp apart from the face (hi if face_upper, else lo) away from it,
    their spacing and the interval they fill; the stated lattice itself where it already has that many."""
    if abs((hi - lo) - layers * dp) <= SAME * dp:
        return (*stretched_points(lo, hi, dp), (lo, hi))
    if face_upper:
        lo = hi - layers * dp
    else:
        hi = lo + layers * dp
    return lo + (np.arange(layers) + 0.5) * dp, dp, (lo, hi)


def laid_walls(scene) -> list[LaidWall]:
    """Every wall's particle lattice (module docstring), per axis:

    - fluid beyond one side: layers dp apart from that face, max(round(T / dp), support_layers)
      of them (T the stated thickness), the extra ones away from the fluid;
    - fluid beyond both sides: the stated thickness filled (``stretched_points``);
    - fluid beyond neither (along the wall): the stated length filled, its ends first moved out
      to the outer side of any wall they meet there that grew (so that corners stay closed).
    Raises LayoutError naming the wall and dp where an extent holds no particle.
    """
    dp = scene.dp
    fluid = scene.fluid.extents()
    depth_layers = support_layers(scene.h, dp)
    sides = [fluid_sides(w, fluid, scene.periodic_x) for w in scene.walls]
    laid: list[dict] = []
    for i, w in enumerate(scene.walls):
        entry = {}
        for axis in (0, 1):
            lo, hi = (w.x, w.z)[axis]
            lower, upper = sides[i][axis]
            if lower != upper:
                layers = max(int(round((hi - lo) / dp)), depth_layers)
                entry[axis] = _from_face(lo, hi, dp, layers, face_upper=upper)
        laid.append(entry)
    out = []
    for i, w in enumerate(scene.walls):
        pos, steps, spans = [], [], []
        for axis in (0, 1):
            lo, hi = (w.x, w.z)[axis]
            if axis in laid[i]:
                p, step, span = laid[i][axis]
            else:
                if not any(sides[i][axis]):
                    lo, hi = _meet_grown_walls(i, axis, lo, hi, scene.walls, laid)
                p, step = stretched_points(lo, hi, dp)
                span = (lo, hi)
            if p.size == 0:
                name = "x" if axis == 0 else "z"
                raise LayoutError(
                    f"walls[{i}] ({w.name}): its {name} extent {1e3 * (hi - lo):.4g} mm holds no "
                    f"particle at dp = {1e3 * dp:.4g} mm (it must be more than dp / 2)")
            pos.append(p)
            steps.append(step)
            spans.append(span)
        out.append(LaidWall(Extent(spans[0], spans[1]), pos[0], pos[1], *steps))
    return out


def _meet_grown_walls(i, axis, lo, hi, walls, laid):
    """Wall i's extent along ``axis`` with each end moved to the grown outer side of a wall
    whose stated outer side it shares and which it touches along the other axis."""
    tol = SAME * max(abs(hi - lo), 1.0)
    w = walls[i]
    for j, v in enumerate(walls):
        if j == i or axis not in laid[j]:
            continue
        other_w = (w.z, w.x)[axis]
        other_v = (v.z, v.x)[axis]
        if min(other_w[1], other_v[1]) < max(other_w[0], other_v[0]) - tol:
            continue  # they do not touch
        v_lo, v_hi = (v.x, v.z)[axis]
        g_lo, g_hi = laid[j][axis][2]
        if g_lo < v_lo and abs(lo - v_lo) <= tol:
            lo = g_lo
        if g_hi > v_hi and abs(hi - v_hi) <= tol:
            hi = g_hi
    return lo, hi


def check_layout(scene) -> None:
    """Raise LayoutError, naming the block, profile or wall and dp, for a scene that cannot be laid out at its
    dp: an extent that holds no particle (dp / 2 or less)."""
    dp = scene.dp
    regions = [(f"fluid.blocks[{i}]", b) for i, b in enumerate(scene.fluid.blocks)] + [
        (f"fluid.profiles[{i}]", Extent(p.x, (0.0, 1.0))) for i, p in enumerate(scene.fluid.profiles)]
    for key, r in regions:
        for name, (lo, hi) in (("x", r.x), ("z", r.z)):
            if round((hi - lo) / dp) < 1:
                raise LayoutError(
                    f"{key}: its {name} extent {1e3 * (hi - lo):.4g} mm holds no particle at "
                    f"dp = {1e3 * dp:.4g} mm (it must be more than dp / 2)")
    laid_walls(scene)
