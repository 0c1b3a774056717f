"""The conveyor-belt flow-front case (docs/scheme.md sections 1-2): physical numbers -> Scene + probes.

Lab frame, x downslope along the belt, z bed-normal, gravity g (sin theta, -cos theta).
The belt is the bottom wall z < 0, fixed particles carrying the velocity -u_b (upslope),
ramped from 0 after a rest; a fixed wall closes the upstream end at x = 0. The fluid starts
as a block of depth h_n and length ``fluid_length`` h_n, or as the steady lubrication front
of the fluid the scheme behaves as (``scheme_fluid``; ``start_depth``), of area
fluid_length h_n h_s. The toe stands still in the lab frame at steady state.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field, replace

import numpy as np

from . import lubrication, schemes, viscoplastic
from .layout import support_layers
from .scene import (SHIFTING_METHODS, Numerics, Scene, SceneError, YamlData, parse_into, refuse_moved_keys,
                    scene_from_dict)
from .steady import SteadyCriteria

START_SHAPES = ("block", "lubrication", "warm")
START_VELOCITIES = ("rest", "lubrication")
START_DEPTHS = ("film", "theory")
MAX_PERTURBATION = 0.01  # of dp: a realisation's start differs by rounding-sized moves, not a new start


def start_offsets(n: int, amplitude: float, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """(dx, dz): independent uniform offsets in [-amplitude, amplitude] for n points, drawn
    from numpy's default generator seeded with ``seed``."""
    rng = np.random.default_rng(seed)
    return rng.uniform(-amplitude, amplitude, n), rng.uniform(-amplitude, amplitude, n)


@dataclass
class Probes:
    interval: float = 0.02  # s of simulated time between probe samples
    stations: list[float] = field(default_factory=lambda: [0.76, 1.5, 9.7])  # x* upslope of toe
    x_star_max: float = 14.0  # free-surface grid from the toe up to this x*
    x_star_step: float = 0.1
    z_star_step: float = 0.025  # velocity-profile grid z / h_n from 0 to z_star_max
    z_star_max: float = 1.3
    uniform_zone: tuple[float, float] = (9.0, 12.0)  # x* range of the uniform depth


@dataclass
class Steady:
    average: float = 3.0  # W [s]: the averaging window and its hold-out window, each (solver/steady.py)
    fraction: float = 5.0e-4  # a drift below this fraction of a quantity's value passes however small its se
    max_time: float = 30.0  # s: give up (status not_steady) after this
    min_time: float | None = None  # s after the belt's ramp: the start-up, never averaged nor read (None: average)
    stop: bool = True  # false: run to max_time; the window pair is the final 2W (fixed end time)
    context: float = 15.0  # s of samples before each window (from min_time on) that its se reads

    @property
    def start_up(self) -> float:
        """The start-up after the ramp: min_time, or one averaging window where it is not set."""
        return self.average if self.min_time is None else self.min_time


@dataclass
class Belt:
    speed: float = 0.075  # u_b [m/s], belt moves upslope
    rest: float = 0.05  # s at rest before the ramp
    ramp: float = 0.25  # s to reach full speed
    margin: float = 8.0  # belt length downstream of the initial toe, in h_n
    taper_length: float = 1.0  # in h_n: the belt speed rises from the upstream wall over this length
    taper_segments: int = 5


@dataclass
class ConveyorCase(YamlData):
    dp: float
    name: str = "conveyor"
    ch: float = 1.8
    shifting: str = "lind"
    # the numerics preset (solver/schemes.py): surge, the shipped scheme, or spec, the paper's;
    # ``numerics`` holds the resolved choices, the preset's with the case's own keys over them
    scheme: str = schemes.DEFAULT_SCHEME
    numerics: Numerics | None = None
    density: float = 1383.0
    viscosity: float = 5.6  # mu [Pa s] of a newtonian fluid (not used by herschel_bulkley)
    rheology: str = "newtonian"  # or herschel_bulkley (the scene's fluid keys below)
    yield_stress: float = 0.0
    consistency: float | None = None
    index: float = 1.0
    max_viscosity: float | None = None
    papanastasiou: float | None = None
    strain_rate_correction: bool = False  # herschel_bulkley: the smoothing bias of gamma removed
    slope_deg: float = 15.3
    gravity: float = 9.81
    belt: Belt = field(default_factory=Belt)
    fluid_length: float = 20.0  # in h_n, of the initial block (the lubrication start keeps its area)
    start: str = "lubrication"
    start_depth: str = "film"  # lubrication start: film (the scheme's own normal depth) or theory
    # rest, or lubrication: the steady film profile, belt running from t = 0 (a warm start takes
    # its velocities from warm_from instead)
    start_velocity: str = "rest"
    warm_from: str | None = None  # start: warm: a front run's NetCDF (another dp) to start from
    # a realisation of the run: every fluid particle's start position moved by up to
    # start_perturbation dp in x and in z (uniform, drawn with perturbation_seed); 0: none
    start_perturbation: float = 0.0
    perturbation_seed: int = 0
    wall_height: float = 2.5  # upstream wall, in h_n
    normalising_depth: float = 0.0186  # m: the paper's h_n used to normalise its data
    coefsound: float = 10.0
    max_area_drift: float = 0.05  # guard: |enclosed / mass-implied area - 1|
    probes: Probes = field(default_factory=Probes)
    steady: Steady = field(default_factory=Steady)
    checkpoint_interval: float = 1.0  # s of simulated time
    memory_budget_gb: float = 4.0

    def __post_init__(self):
        if self.numerics is None:  # built in Python without numerics: the scheme's own
            self.numerics = Numerics()  # the physics first: the preset depends on h_n / dp
            self.numerics = parse_into(Numerics, preset_numerics(self), "case.numerics")
        self.numerics.shifting.method = self.shifting  # the grid's axis, recorded with the rest

    @property
    def theta(self) -> float:
        return math.radians(self.slope_deg)

    @property
    def newtonian(self) -> bool:
        return self.rheology == "newtonian"

    @property
    def hb_fluid(self) -> viscoplastic.HBFluid:
        return viscoplastic.HBFluid(self.density, self.yield_stress, self.consistency, self.index)

    @property
    def h_n(self) -> float:
        """Normal depth from the flux balance: eq. 13b, or zero lab-frame flux of the
        Herschel-Bulkley film (``viscoplastic.normal_depth``)."""
        if self.newtonian:
            return lubrication.normal_depth(self.viscosity, self.belt.speed, self.density,
                                            self.gravity, self.theta)
        return viscoplastic.normal_depth(self.hb_fluid, self.belt.speed, self.gravity, self.theta)

    def front_shape(self):
        """(x*, eta) of the steady lubrication front from the toe, for either rheology."""
        if self.newtonian:
            eta = np.concatenate([np.linspace(0.0, 0.99, 300, endpoint=False),
                                  1 - np.geomspace(0.01, 1e-9, 300)])
            return lubrication.xi_star(eta, self.theta), eta
        return viscoplastic.front_profile(self.hb_fluid, self.belt.speed, self.gravity, self.theta,
                                          eta_max=1 - 1e-6)

    @property
    def running_start(self) -> bool:
        """The fluid starts moving (warm start, or the lubrication velocity profile) and the
        belt runs at full speed from t = 0, without rest or ramp."""
        return self.start == "warm" or self.start_velocity == "lubrication"

    @property
    def ramp_end(self) -> float:
        """End of the belt start-up (0 for a running start)."""
        return 0.0 if self.running_start else self.belt.rest + self.belt.ramp

    def criteria(self) -> SteadyCriteria:
        s = self.steady
        return SteadyCriteria(window=s.average, fraction=s.fraction, min_time=self.ramp_end + s.start_up,
                              context=s.context)


# flat numerics keys of an older case layout: where each lives now
_NUMERICS_KEYS = ("cfl", "cfl_rule", "density_diffusion", "density_diffusion_reference", "viscous_correction",
                  "volume_relaxation", "viscous_update", "no_tension", "boundary", "mdbc_velocity")
MOVED_CASE_KEYS = {
    **{k: f"now numerics.{k} (under the case's numerics: block)" for k in _NUMERICS_KEYS},
    "shifting_coefficient": "now numerics.shifting.coefficient",
    "shift_min_speed": "now numerics.shifting.min_speed, in m/s",
    "shift_near_surface": "now numerics.shifting.near_surface",
    "viscous_normalisation": "removed: numerics.viscous_correction corrects and normalises the laminar term",
    "cfl_viscous": "removed: one C for the force and viscous limits (numerics.cfl)",
    "density_update": "removed: the density is updated with the evaluation's rate",
    "shift_density_correction": "removed: shifting always corrects the density for its volume change",
    "shift_correction_limit": "removed: Lind's per-step limit is fixed (scene.LIND_CORRECTION_LIMIT)",
    "shift_max": "removed: each shift component is clipped to 0.1 dp",
}


def particles_across(case: "ConveyorCase") -> float:
    """h_n / dp, the resolution a preset reads; for physics too wrong to give h_n, the presets'
    default (the case's validation then names the wrong key)."""
    try:
        ratio = case.h_n / case.dp
    except (ArithmeticError, ValueError, TypeError):
        return schemes.RESOLVED_DEPTH
    return ratio if math.isfinite(ratio) else schemes.RESOLVED_DEPTH


def preset_numerics(case: "ConveyorCase") -> dict:
    """The numerics block of the case's scheme (``schemes.preset``)."""
    return schemes.preset(case.scheme, case.belt.speed, case.newtonian, particles_across(case)).get("numerics", {})


def cold_start(case: "ConveyorCase") -> str:
    """The start shape of the case's scheme (``schemes.preset``, else the default): where a warm
    start cannot load its source, the run starts this way instead."""
    preset = schemes.preset(case.scheme, case.belt.speed, case.newtonian, particles_across(case))
    return preset.get("start", ConveyorCase.start)


def resolve_scheme(data: dict) -> dict:
    """The case data with its scheme's preset under it (``schemes.preset``); SceneError for
    an unknown scheme, a moved key or a shifting method set inside numerics."""
    refuse_moved_keys(data, MOVED_CASE_KEYS, "case.")
    name = data.get("scheme", schemes.DEFAULT_SCHEME)
    if name not in schemes.SCHEMES:
        raise SceneError(f"case.scheme: {name!r} is not one of {', '.join(schemes.SCHEMES)}")
    numerics = data.get("numerics")
    shifting = numerics.get("shifting") if isinstance(numerics, dict) else None
    method = shifting.get("method") if isinstance(shifting, dict) else None
    if method is not None and method != data.get("shifting", ConveyorCase.shifting):
        raise SceneError(f"case.numerics.shifting.method: {method!r}, but the case's shifting key, which "
                         f"sets the method, is {data.get('shifting', ConveyorCase.shifting)!r}: set shifting only")
    # the physical case alone (the paper's numerics, which change nothing physical): the preset
    # takes the belt speed, the rheology and h_n / dp from it
    physical = parse_into(ConveyorCase, {**{k: v for k, v in data.items() if k != "numerics"},
                                         "scheme": "spec"}, "case")
    return schemes.merge(schemes.preset(name, physical.belt.speed, physical.newtonian,
                                        particles_across(physical)), data)


def case_from_dict(data) -> ConveyorCase:
    if not isinstance(data, dict):
        raise SceneError(f"case: expected a mapping, got {data!r}")
    steady = data.get("steady")
    gone = sorted(set(steady) & {"velocity", "window", "front_velocity", "depth"}) if isinstance(steady, dict) else []
    if gone:
        raise SceneError(f"case.steady.{gone[0]}: no longer a key; a run is steady when every reported "
                         "quantity's drift is within its sampling error (steady.average sets the window, "
                         "steady.fraction the drift that passes regardless; docs/conveyor.md)")
    case = parse_into(ConveyorCase, resolve_scheme(data), "case")
    validate_case(case)
    return case


def validate_case(c: ConveyorCase) -> None:
    """Case-level checks; the generated scene is validated by the scene rules too."""
    def positive(v, key):
        if not (v > 0 and math.isfinite(v)):
            raise SceneError(f"{key}: must be a positive finite number, got {v!r}")

    for key in ("dp", "density", "viscosity", "gravity", "fluid_length", "wall_height",
                "normalising_depth", "coefsound", "max_area_drift", "checkpoint_interval"):
        positive(getattr(c, key), f"case.{key}")
    if c.scheme not in schemes.SCHEMES:
        raise SceneError(f"case.scheme: {c.scheme!r} is not one of {', '.join(schemes.SCHEMES)}")
    if c.shifting not in SHIFTING_METHODS:
        raise SceneError(f"case.shifting: {c.shifting!r} is not one of {', '.join(SHIFTING_METHODS)}")
    if c.newtonian and c.strain_rate_correction:
        raise SceneError("case.strain_rate_correction: only for rheology herschel_bulkley")
    if not 0 < c.slope_deg < 90:
        raise SceneError(f"case.slope_deg: must lie in (0, 90), got {c.slope_deg}")
    if c.start not in START_SHAPES:
        raise SceneError(f"case.start: {c.start!r} is not one of {', '.join(START_SHAPES)}")
    if c.start_velocity not in START_VELOCITIES:
        raise SceneError(f"case.start_velocity: {c.start_velocity!r} is not one of "
                         f"{', '.join(START_VELOCITIES)}")
    if c.start_depth not in START_DEPTHS:
        raise SceneError(f"case.start_depth: {c.start_depth!r} is not one of {', '.join(START_DEPTHS)}")
    if not 0.0 <= c.start_perturbation <= MAX_PERTURBATION:
        raise SceneError(f"case.start_perturbation: must lie in [0, {MAX_PERTURBATION:g}] (a fraction of dp), "
                         f"got {c.start_perturbation!r}")
    if c.perturbation_seed < 0:
        raise SceneError(f"case.perturbation_seed: must be an integer >= 0, got {c.perturbation_seed!r}")
    if c.start == "warm" and not c.warm_from:
        raise SceneError("case.warm_from: start: warm needs the path of a front run (NetCDF) to start from")
    positive(c.belt.speed, "case.belt.speed")
    positive(c.belt.margin, "case.belt.margin")
    if c.belt.rest < 0 or c.belt.ramp < 0 or c.belt.taper_length < 0:
        raise SceneError("case.belt.rest, case.belt.ramp, case.belt.taper_length: must be >= 0")
    if c.belt.taper_segments < 1:
        raise SceneError("case.belt.taper_segments: must be >= 1")
    p = c.probes
    for key in ("interval", "x_star_max", "x_star_step", "z_star_step", "z_star_max"):
        positive(getattr(p, key), f"case.probes.{key}")
    if not p.stations or min(p.stations) <= 0:
        raise SceneError("case.probes.stations: need at least one station, all x* > 0")
    if not 0 < p.uniform_zone[0] < p.uniform_zone[1]:
        raise SceneError(f"case.probes.uniform_zone: need 0 < lower < upper, got {list(p.uniform_zone)}")
    if p.uniform_zone[1] > p.x_star_max or max(p.stations) > p.x_star_max:
        raise SceneError("case.probes.x_star_max: must cover the uniform zone and every station")
    reach = c.fluid_length - 2.0  # keep the upstream wall region out of the probes
    if p.x_star_max > reach:
        raise SceneError(
            f"case.fluid_length: {c.fluid_length:g} h_n leaves no room for probes up to "
            f"x* = {p.x_star_max:g} (need fluid_length >= x_star_max + 2)")
    s = c.steady
    for key in ("average", "max_time"):
        positive(getattr(s, key), f"case.steady.{key}")
    if s.min_time is not None and not s.min_time >= 0:
        raise SceneError("case.steady.min_time: must be >= 0")
    if not s.context >= 0.0:
        raise SceneError(f"case.steady.context: {s.context!r} must be >= 0 (s)")
    if not 0.0 <= s.fraction < 0.1:
        raise SceneError(f"case.steady.fraction: {s.fraction!r} is not in [0, 0.1)")
    if s.average < 10 * p.interval:
        raise SceneError("case.steady.average: must hold at least 10 probe intervals")
    scene_from_dict(build_scene_dict(c))  # scene-level checks (budget, keys, geometry)


def wall_thickness(c: ConveyorCase) -> float:
    """The belt's depth: the layers within the kernel support of the fluid (layout.support_layers)."""
    return support_layers(c.ch * c.dp, c.dp) * c.dp


def scheme_fluid(c: ConveyorCase, flux_ratio: float) -> ConveyorCase:
    """The case with the fluid whose exact film carries ``flux_ratio`` r times the real one's
    flux, i.e. the fluid the scheme behaves as (``film_depth``): mu / r, or K r^-n for
    Herschel-Bulkley (the film flux scales as K^(-1/n) at a fixed yield depth). Its h_n is the
    scheme's normal depth h_s; its fluid_length is rescaled so the start keeps the area
    fluid_length h_n h_s."""
    if flux_ratio == 1.0:
        return c
    if c.newtonian:
        s = replace(c, viscosity=c.viscosity / flux_ratio)
    else:
        s = replace(c, consistency=c.consistency * flux_ratio ** -c.index)
    return replace(s, fluid_length=c.fluid_length * c.h_n / s.h_n)


def initial_toe(c: ConveyorCase, warm=None) -> float:
    """x of the toe at t = 0."""
    hn = c.h_n
    if warm is not None:
        return warm.toe
    if c.start == "block":
        return c.fluid_length * hn
    if c.newtonian:
        return (c.fluid_length + lubrication.front_area_deficit(c.theta)) * hn
    xs, eta = c.front_shape()
    deficit = float(np.sum(np.diff(xs) * (1 - 0.5 * (eta[1:] + eta[:-1]))))
    return (c.fluid_length + deficit) * hn


def front_surface(c: ConveyorCase) -> list[list[float]]:
    """Points of the lubrication front surface from the wall (x = 0) to the toe, with the
    area of a block of length fluid_length h_n at depth h_n."""
    hn, x_toe = c.h_n, initial_toe(c)
    xs, eta = c.front_shape()
    xi = xs * hn
    if c.newtonian:
        eta_wall = lubrication.front_eta(x_toe / hn, c.theta)
    else:
        eta_wall = float(np.interp(x_toe / hn, xs, eta))
    x = x_toe - xi
    keep = x > 0
    x, z = x[keep][::-1], (eta * hn)[keep][::-1]
    x = np.concatenate([[0.0], x])
    z = np.concatenate([[hn * eta_wall], z])
    distinct = np.concatenate([[True], np.diff(x) > 1e-9 * hn])  # the tip's points crowd at x_toe
    x, z = x[distinct], z[distinct]
    return [[float(a), float(b)] for a, b in zip(x, z)]


def build_scene_dict(c: ConveyorCase, warm=None, flux_ratio: float = 1.0) -> dict:
    """The generic scene of docs/scheme.md section 2 as plain data. ``warm`` (a ``warm.WarmState``)
    gives the free surface of a warm start; without it a warm case is built with the
    lubrication shape (for validation before the run it starts from exists). The lubrication
    start is the steady front of ``scheme_fluid(c, flux_ratio)``, its rows filling that
    fluid's normal depth h_s exactly."""
    hn, th, g = c.h_n, c.theta, c.gravity
    T = wall_thickness(c)
    start = scheme_fluid(c, flux_ratio)
    x_toe = initial_toe(start, warm)
    rest, ramp = (0.0, 0.0) if c.running_start else (c.belt.rest, c.belt.ramp)
    belt_end = c.dp * math.ceil((x_toe + c.belt.margin * hn) / c.dp)
    wall_top = c.dp * math.ceil(c.wall_height * hn / c.dp)
    # a belt running at full speed into the fixed wall is a corner singularity that squeezes
    # particles through the wall; over taper_length from the wall the belt speed rises in
    # taper_segments steps, (k + 1/2) / n u_b on the k-th
    n = c.belt.taper_segments if c.belt.taper_length > 0 else 0
    edges = [c.dp * round(k * c.belt.taper_length * hn / max(n, 1) / c.dp) for k in range(n + 1)]
    taper = [{"name": f"belt_taper{k}", "x": [edges[k], edges[k + 1]], "z": [-T, 0.0],
              "velocity": [-(k + 0.5) / n * c.belt.speed, 0.0], "moving": False,
              "ramp_time": ramp, "ramp_delay": rest}
             for k in range(n) if edges[k + 1] > edges[k]]
    belt_start = edges[-1] if n else 0.0
    if c.start == "block":
        fluid = {"blocks": [{"x": [0.0, x_toe], "z": [0.0, hn]}]}
    else:
        surface = warm.surface() if warm is not None else front_surface(start)
        fluid = {"profiles": [{"x": [0.0, c.dp * math.floor(x_toe / c.dp)], "base": 0.0,
                               "surface": surface,
                               "row_depth": warm.depth if warm is not None else start.h_n}]}
    return {
        "name": c.name,
        "dp": c.dp, "ch": c.ch,
        "fluid": {"density": c.density, **_rheology(c), **fluid},
        "walls": [
            {"name": "belt", "x": [belt_start, belt_end], "z": [-T, 0.0],
             "velocity": [-c.belt.speed, 0.0], "moving": False,
             "ramp_time": ramp, "ramp_delay": rest},
            {"name": "upstream", "x": [-T, 0.0], "z": [-T, wall_top]},
        ] + taper,
        "gravity": [g * math.sin(th), -g * math.cos(th)],
        "sound": {"coefsound": c.coefsound, "depth": hn},
        "numerics": dataclasses.asdict(c.numerics),
        "time": {"end": c.steady.max_time, "output_interval": c.steady.max_time,
                 "diagnostics_interval": max(c.probes.interval, 0.01)},
        "memory_budget_gb": c.memory_budget_gb,
    }


def _rheology(c: ConveyorCase) -> dict:
    if c.newtonian:
        return {"viscosity": c.viscosity}
    return {"rheology": c.rheology, "yield_stress": c.yield_stress, "consistency": c.consistency,
            "index": c.index, "max_viscosity": c.max_viscosity, "papanastasiou": c.papanastasiou,
            "strain_rate_correction": c.strain_rate_correction}


def build_scene(c: ConveyorCase, warm=None, flux_ratio: float = 1.0) -> Scene:
    return scene_from_dict(build_scene_dict(c, warm, flux_ratio))


def lubrication_velocity(c: ConveyorCase, scene: Scene, x: np.ndarray, z: np.ndarray):
    """Lab-frame (u, w) of the steady film at fluid points, w = 0: at the local depth h of
    the initial surface and under a bed moving upslope at U (the belt, or its taper near the
    upstream wall), u = u_rel(z) - U with u_rel the film relative to the bed whose flux is
    U h. Newtonian: u_rel = U 3 (s - s^2/2), s = z / h (docs/scheme.md section 5). Herschel-Bulkley:
    u_rel = ``HBFluid.film`` at the driving slope S(h) of q(h, S) = U h. The depth-mean lab
    velocity is then zero: no net flux."""
    if scene.fluid.profiles:
        prof = scene.fluid.profiles[0]
        depth = prof.top(x) - prof.base
    else:
        depth = np.full(np.shape(x), c.h_n)
    speed = np.zeros(np.shape(x))
    for w in scene.walls:
        if w.z[1] <= 0.0:  # bed walls: the belt and its taper segments
            speed[(x >= w.x[0]) & (x < w.x[1])] = -w.velocity[0]
    depth = np.maximum(depth, 1e-12)
    if c.newtonian:
        s = np.clip(z / depth, 0.0, 1.0)
        u = speed * (lubrication.belt_velocity(s) - 1.0)
        return u, np.zeros_like(u)
    u = -speed.copy()
    fluid = c.hb_fluid
    # one driving slope per (depth, bed speed): the particles of a lattice column share both
    keys = np.stack([np.round(depth / c.dp, 6), speed], axis=1)
    uniq, inverse = np.unique(keys, axis=0, return_inverse=True)
    order = np.argsort(inverse.ravel(), kind="stable")
    groups = np.split(order, np.cumsum(np.bincount(inverse.ravel(), minlength=len(uniq)))[:-1])
    for (_, U), sel in zip(uniq, groups):
        if U <= 0.0 or sel.size == 0:
            continue
        h = float(depth[sel[0]])
        S = viscoplastic.driving_slope(fluid, h, U, c.gravity)
        u[sel] = fluid.film(np.clip(z[sel], 0.0, h), h, S, c.gravity) - U
    return u, np.zeros_like(u)
