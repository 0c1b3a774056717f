"""Scene: a generic 2D SPH case as plain dataclasses, read from YAML or a dict.

Every value is checked here, before anything is compiled: unknown keys, wrong
types and impossible values raise :class:`SceneError` naming the key.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import Any, get_args, get_origin, get_type_hints

import numpy as np
import yaml

from .layout import LayoutError, check_layout, laid_walls

SHIFTING_METHODS = ("none", "skillen", "lind")
# lind within 2h of the free surface: the paper's no shift, or the shift along the surface only
NEAR_SURFACE = ("none", "tangential")
BOUNDARY_METHODS = ("mdbc", "dbc")
MDBC_VELOCITY = ("shepard", "corrected")
DIFFUSION_REFERENCES = ("spec", "column")
VISCOUS_UPDATES = ("explicit", "implicit", "substepped")
VISCOUS_FORMS = ("laminar", "stress")
CFL_RULES = ("fixed", "damping")
MIN_DAMPED_CFL = 0.05  # the damping rule refuses a scene it would take below this acoustic C
CH_RANGE = (1.0, 4.0)  # h / dp: below 1 a particle's support holds too few neighbours to be stable
LIND_MIN_CH = 1.1  # below it Lind shifting fails on the conveyor case (docs/numerics.md)
BYTES_PER_PARTICLE = 400  # state, sort buffers and per-thread accumulators (2 threads)


class SceneError(ValueError):
    """A scene value is missing, of the wrong type or physically impossible."""


@dataclass
class Rect:
    """Axis-aligned rectangle [x0, x1] x [z0, z1] in metres."""

    x: tuple[float, float]
    z: tuple[float, float]

    def overlap_area(self, other: "Rect") -> float:
        dx = min(self.x[1], other.x[1]) - max(self.x[0], other.x[0])
        dz = min(self.z[1], other.z[1]) - max(self.z[0], other.z[0])
        return max(dx, 0.0) * max(dz, 0.0)

    @property
    def area(self) -> float:
        return (self.x[1] - self.x[0]) * (self.z[1] - self.z[0])


@dataclass
class FluidBlock(Rect):
    """A fluid rectangle filled on the dp lattice, optionally with an initial velocity."""

    velocity: tuple[float, float] = (0.0, 0.0)


@dataclass
class FluidProfile:
    """Fluid between z = ``base`` and a piecewise-linear free surface through the
    ``surface`` points [[x, z], ...] (x increasing), over [x0, x1]."""

    x: tuple[float, float]
    base: float
    surface: list[tuple[float, float]]
    velocity: tuple[float, float] = (0.0, 0.0)
    row_depth: float | None = None  # rows dz = row_depth / round(row_depth / dp) apart; null: dp

    def row_spacing(self, dp: float) -> float:
        """Vertical spacing of the fill: a column of depth ``row_depth`` holds a whole number
        of rows exactly (no lattice rounding of its depth); dp without ``row_depth``."""
        if self.row_depth is None:
            return dp
        return self.row_depth / max(round(self.row_depth / dp), 1)

    def top(self, x):
        pts = np.asarray(self.surface, dtype=float)
        return np.interp(x, pts[:, 0], pts[:, 1])

    @property
    def bbox(self) -> Rect:
        return Rect(self.x, (self.base, max(z for _, z in self.surface)))

    @property
    def area(self) -> float:
        xs = np.linspace(self.x[0], self.x[1], 2001)
        return float(np.trapezoid(np.maximum(self.top(xs) - self.base, 0.0), xs))


@dataclass
class Wall(Rect):
    """A solid rectangle filled with boundary particles.

    ``velocity`` is the wall velocity seen by the fluid (no-slip target). A wall with
    ``moving: false`` keeps its particles in place while carrying that velocity (a belt);
    ``moving: true`` translates them. The velocity ramps linearly from 0 at
    ``ramp_delay`` to its full value at ``ramp_delay + ramp_time``.
    """

    name: str = "wall"
    velocity: tuple[float, float] = (0.0, 0.0)
    moving: bool = False
    ramp_time: float = 0.0
    ramp_delay: float = 0.0


@dataclass
class Fluid:
    density: float
    viscosity: float | None = None  # dynamic viscosity mu [Pa s] (newtonian)
    blocks: list[FluidBlock] = field(default_factory=list)
    profiles: list[FluidProfile] = field(default_factory=list)
    # herschel_bulkley: tau = tau_y + K gamma^n where yielded, mu = min(mu_max, tau / gamma)
    rheology: str = "newtonian"
    yield_stress: float = 0.0  # tau_y [Pa]
    consistency: float | None = None  # K [Pa s^n]
    index: float = 1.0  # n
    max_viscosity: float | None = None  # mu_max [Pa s]: the regularisation's cap
    papanastasiou: float | None = None  # m [s]: tau_y (1 - exp(-m gamma)) / gamma below the cap
    # remove the kernel smoothing's second-order error from the strain rate (solver/rheology.py)
    strain_rate_correction: bool = False

    @property
    def newtonian(self) -> bool:
        return self.rheology == "newtonian"

    def extents(self) -> list[Rect]:
        """Bounding rectangles of every fluid region."""
        return list(self.blocks) + [p.bbox for p in self.profiles]


@dataclass
class Sound:
    """c0 directly, or c0 = coefsound * sqrt(|g| depth)."""

    c0: float | None = None
    coefsound: float | None = None
    depth: float | None = None


# Lind moves particles by up to 0.1 dp every step; a density correction that followed each
# such move in full would erase the compression the pressure needs (docs/numerics.md)
LIND_CORRECTION_LIMIT = 1.0e-3
SURFACE_THRESHOLD = 1.5  # div r below this marks the free surface (docs/scheme.md section 6)
MAX_SHIFT = 0.1  # clip of each shift component per step, in units of dp


@dataclass
class Shifting:
    """Particle shifting (docs/scheme.md section 6). The density follows each shift's volume
    change, rho *= 1 - div(dr) (Lind's limited to LIND_CORRECTION_LIMIT per step)."""

    method: str = "none"
    coefficient: float | None = None  # A (skillen, default 2) or A_L (lind, default 1)
    # skillen: the speed in dr = -A h |u| dt gradC is max(|u|, min_speed) [m/s] (0: |u|)
    min_speed: float = 0.0
    # lind within 2h of the free surface: "none" (no shift) or "tangential" (the part of the
    # shift along the surface)
    near_surface: str = "none"


@dataclass
class Numerics:
    """Every numerics choice of a run; the defaults are the paper's scheme (docs/scheme.md
    section 6), the departures are described in docs/numerics.md."""

    cfl: float = 0.2  # C of dt = C min(dt1, dt2, dt3)
    # fixed: the acoustic limit's C is cfl; damping: at most 0.85 times the edge C* at which the
    # laminar term and the density diffusion still damp the acoustic pair (solver/acoustic_edge.py)
    cfl_rule: str = "fixed"
    boundary: str = "mdbc"
    mdbc_velocity: str = "shepard"  # ghost velocity: shepard (the paper's) or corrected (first order)
    # floor each wall density by the particle number density around it (fluid pressed into a wall)
    no_penetration: bool = False
    density_diffusion: float | None = 0.1  # delta; null/false switches it off
    # rho^H_ab of the diffusion: spec (the paper's form) or column (the Tait column at rest)
    density_diffusion_reference: str = "spec"
    # the consistent laminar term: its first-order error 2 nu G . grad u removed and the term
    # divided by its lattice normaliser N where the support is full (forces.viscous_scale_factors)
    viscous_correction: bool = False
    # beta: interior density relaxes towards the particles' packing at a rate beta c0 / h
    # (solver/packing.py); null: off
    volume_relaxation: float | None = None
    # explicit (the laminar term at v^n, dt bounded by h^2 / nu), implicit (backward Euler in the
    # laminar term) or substepped (the same operator over the step by Runge-Kutta-Chebyshev
    # stages); the last two lift the viscous limit on dt (solver/implicit.py)
    viscous_update: str = "explicit"
    # laminar: the pair term discretises div(mu grad u); stress: div(2 mu D), the laminar term
    # plus div(mu (grad u)^T), explicit (forces.add_stress_transpose; differs only where mu varies)
    viscous_form: str = "laminar"
    # Monaghan's artificial viscosity alpha (DualSPHysics' default 0.01); null: off
    artificial_viscosity: float | None = None
    # floor the fluid density at rho0 after each step: no negative pressure, no tensile clumping
    no_tension: bool = False
    shifting: Shifting = field(default_factory=Shifting)


@dataclass
class Time:
    end: float
    output_interval: float
    diagnostics_interval: float | None = None  # default: output_interval / 10


@dataclass
class Guards:
    max_density_deviation: float = 0.1  # max |rho/rho0 - 1|
    min_dt_fraction: float = 1.0e-3  # dt below this fraction of the first dt = collapse
    penetration: float = 0.5  # depth inside a wall, in units of dp, that counts as crossing


@dataclass
class Domain(Rect):
    """Box that fluid particles must stay in; default: walls and fluid plus a margin."""


class YamlData:
    """to_dict / to_yaml for the validated dataclasses (scene, case)."""

    def to_dict(self) -> dict:
        return _plain(dataclasses.asdict(self))

    def to_yaml(self) -> str:
        return yaml.safe_dump(self.to_dict(), sort_keys=False)


@dataclass
class Scene(YamlData):
    dp: float
    fluid: Fluid
    time: Time
    sound: Sound
    name: str = "scene"
    ch: float = 1.5
    walls: list[Wall] = field(default_factory=list)
    gravity: tuple[float, float] = (0.0, -9.81)
    periodic_x: tuple[float, float] | None = None
    domain: Domain | None = None
    numerics: Numerics = field(default_factory=Numerics)
    guards: Guards = field(default_factory=Guards)
    memory_budget_gb: float = 4.0

    # ---- derived quantities -------------------------------------------------
    @property
    def h(self) -> float:
        return self.ch * self.dp

    @property
    def nu(self) -> float:
        """Kinematic viscosity; for a Herschel-Bulkley fluid its cap mu_max / rho (the largest
        one, which bounds the viscous time step)."""
        f = self.fluid
        return (f.viscosity if f.newtonian else f.max_viscosity) / f.density

    @property
    def c0(self) -> float:
        if self.sound.c0 is not None:
            return self.sound.c0
        g = math.hypot(*self.gravity)
        return self.sound.coefsound * math.sqrt(g * self.sound.depth)

    @property
    def acoustic_damping_ratio(self) -> float:
        """r = nu / (c0 h): the laminar term's damping of an acoustic mode of given h k, per step
        and per unit C, relative to its frequency (solver/acoustic_edge.py)."""
        return self.nu / (self.c0 * self.h)

    @property
    def cfl_acoustic(self) -> float:
        """C of the acoustic limit dt2: ``numerics.cfl``, or with ``cfl_rule: damping``
        min(cfl, 0.85 C*(Ch, nu / (c0 h), delta)) (``acoustic_edge.damped_cfl``)."""
        n = self.numerics
        if n.cfl_rule == "fixed":
            return n.cfl
        from .acoustic_edge import damped_cfl
        return damped_cfl(n.cfl, self.ch, self.acoustic_damping_ratio, n.density_diffusion)

    @property
    def implicit_viscosity(self) -> bool:
        """Whether the laminar term leaves the explicit step (its operator listed by the pair
        loop, no viscous limit on dt): ``viscous_update`` implicit or substepped."""
        return self.numerics.viscous_update != "explicit"

    @property
    def viscous_substeps(self) -> bool:
        """Whether the laminar term's operator is integrated by Runge-Kutta-Chebyshev stages
        (``solver.implicit.substep``) rather than solved by backward Euler."""
        return self.numerics.viscous_update == "substepped"

    @property
    def shift_correction_limit(self) -> float:
        """Per-step limit of |div(dr)| in the shift's density correction (inf: none)."""
        return LIND_CORRECTION_LIMIT if self.numerics.shifting.method == "lind" else math.inf

    @property
    def shifting_coefficient(self) -> float:
        s = self.numerics.shifting
        if s.coefficient is not None:
            return s.coefficient
        return 2.0 if s.method == "skillen" else 1.0

    def estimated_particles(self) -> int:
        """The fluid's area over dp^2 and the particles of the walls as laid (at least 2h deep)."""
        fluid = sum(b.area for b in self.fluid.blocks) + sum(p.area for p in self.fluid.profiles)
        return int(round(fluid / (self.dp * self.dp))) + sum(w.xs.size * w.zs.size for w in laid_walls(self))


# ---- reading and validation -------------------------------------------------

def read_yaml(path):
    """Plain data of a YAML file; SceneError (naming the file) if it is not valid YAML."""
    with open(path) as fh:
        try:
            return yaml.safe_load(fh)
        except yaml.YAMLError as exc:
            raise SceneError(f"{path}: not valid YAML: {exc}") from None


def load_scene(path) -> Scene:
    """Read a YAML scene file and validate it."""
    return scene_from_dict(read_yaml(path))


def refuse_moved_keys(data: Any, moved: dict[str, str], where: str) -> None:
    """SceneError for a key of an older layout, saying where it lives now."""
    if isinstance(data, dict):
        for key, now in moved.items():
            if key in data:
                raise SceneError(f"{where}{key}: {now}")


# keys of the scene's top level that moved into ``numerics`` (or were removed)
MOVED_SCENE_KEYS = {
    "physics": "renamed numerics (which also holds cfl and cfl_rule)",
    "cfl": "now numerics.cfl",
    "cfl_rule": "now numerics.cfl_rule",
    "cfl_viscous": "removed: one C for the force and viscous limits (numerics.cfl)",
}


def scene_from_dict(data: Any) -> Scene:
    """Build a Scene from plain data, check types and values; raise SceneError."""
    refuse_moved_keys(data, MOVED_SCENE_KEYS, "")
    scene = parse_into(Scene, data, "scene")
    validate(scene)
    return scene


def _plain(obj):
    if isinstance(obj, dict):
        return {k: _plain(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_plain(v) for v in obj]
    return obj


def _as_float(value, key):
    if isinstance(value, bool):
        raise SceneError(f"{key}: expected a number, got {value!r}")
    if isinstance(value, (int, float)):
        return float(value)
    if isinstance(value, str):  # YAML 1.1 reads 1e-5 as a string
        try:
            return float(value)
        except ValueError:
            pass
    raise SceneError(f"{key}: expected a number, got {value!r}")


def parse_into(tp, value, key):
    """Build dataclass ``tp`` (or a typed value) from plain data; SceneError names the key."""
    origin = get_origin(tp)
    args = get_args(tp)
    if origin is None and dataclasses.is_dataclass(tp):
        if not isinstance(value, dict):
            raise SceneError(f"{key}: expected a mapping, got {value!r}")
        hints = get_type_hints(tp)
        fields = {f.name: f for f in dataclasses.fields(tp)}
        unknown = sorted(set(value) - set(fields))
        if unknown:
            raise SceneError(
                f"{key}: unknown key(s) {', '.join(map(str, unknown))}; allowed: {', '.join(fields)}")
        kwargs = {}
        for name, f in fields.items():
            if name in value:
                kwargs[name] = parse_into(hints[name], value[name], f"{key}.{name}")
            elif f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING:
                raise SceneError(f"{key}.{name}: required key is missing")
        return tp(**kwargs)
    if origin is type(None) or tp is type(None):
        return None
    if args and type(None) in args:  # Optional[...]
        inner = [a for a in args if a is not type(None)][0]
        if value is None or (value is False and inner is not bool):  # `false` switches off
            return None
        return parse_into(inner, value, key)
    if origin is tuple:
        if not isinstance(value, (list, tuple)) or len(value) != len(args):
            raise SceneError(f"{key}: expected a list of {len(args)} numbers, got {value!r}")
        return tuple(parse_into(a, v, f"{key}[{i}]") for i, (a, v) in enumerate(zip(args, value)))
    if origin is list:
        if not isinstance(value, list):
            raise SceneError(f"{key}: expected a list, got {value!r}")
        return [parse_into(args[0], v, f"{key}[{i}]") for i, v in enumerate(value)]
    if tp is float:
        return _as_float(value, key)
    if tp is int:
        if isinstance(value, bool) or not isinstance(value, (int, float)) or value != int(value):
            raise SceneError(f"{key}: expected an integer, got {value!r}")
        return int(value)
    if tp is bool:
        if not isinstance(value, bool):
            raise SceneError(f"{key}: expected true or false, got {value!r}")
        return value
    if tp is str:
        if not isinstance(value, str):
            raise SceneError(f"{key}: expected a string, got {value!r}")
        return value
    raise TypeError(f"unsupported scene type {tp} at {key}")  # pragma: no cover


def _positive(value, key):
    if not (value > 0 and math.isfinite(value)):
        raise SceneError(f"{key}: must be a positive finite number, got {value!r}")


def _interval(pair, key):
    if not pair[1] > pair[0]:
        raise SceneError(f"{key}: upper bound must exceed lower bound, got {list(pair)}")


RHEOLOGIES = ("newtonian", "herschel_bulkley")


def _validate_rheology(scene: Scene) -> None:
    f = scene.fluid
    if f.rheology not in RHEOLOGIES:
        raise SceneError(f"fluid.rheology: {f.rheology!r} is not one of {', '.join(RHEOLOGIES)}")
    if f.newtonian:
        if f.viscosity is None:
            raise SceneError("fluid.viscosity: required for rheology newtonian (mu [Pa s])")
        _positive(f.viscosity, "fluid.viscosity")
        for key in ("consistency", "max_viscosity", "papanastasiou"):
            if getattr(f, key) is not None:
                raise SceneError(f"fluid.{key}: only for rheology herschel_bulkley")
        if f.strain_rate_correction:
            raise SceneError("fluid.strain_rate_correction: only for rheology herschel_bulkley")
        if f.yield_stress != 0.0 or f.index != 1.0:
            raise SceneError("fluid.yield_stress, fluid.index: only for rheology herschel_bulkley")
        return
    if f.viscosity is not None:
        raise SceneError("fluid.viscosity: not used by rheology herschel_bulkley "
                         "(give consistency K, index n, yield_stress and max_viscosity)")
    for key in ("consistency", "max_viscosity"):
        if getattr(f, key) is None:
            raise SceneError(f"fluid.{key}: required for rheology herschel_bulkley")
        _positive(getattr(f, key), f"fluid.{key}")
    _positive(f.index, "fluid.index")
    if not (f.yield_stress >= 0 and math.isfinite(f.yield_stress)):
        raise SceneError(f"fluid.yield_stress: must be >= 0, got {f.yield_stress}")
    if f.papanastasiou is not None:
        _positive(f.papanastasiou, "fluid.papanastasiou")
    if scene.numerics.viscous_correction:
        raise SceneError("numerics.viscous_correction: only for rheology newtonian")


def _one_of(value, allowed, key):
    if value not in allowed:
        raise SceneError(f"{key}: {value!r} is not one of {', '.join(allowed)}")


def _validate_cfl_rule(scene: Scene) -> None:
    n = scene.numerics
    _one_of(n.cfl_rule, CFL_RULES, "numerics.cfl_rule")
    if n.cfl_rule == "fixed":
        return
    if not scene.fluid.newtonian:
        raise SceneError("numerics.cfl_rule: damping needs one viscosity (rheology newtonian); a "
                         f"{scene.fluid.rheology} fluid's laminar damping varies with its strain rate. "
                         "Set numerics.cfl_rule: fixed with a numerics.cfl you have checked (0.4 with "
                         "viscous_update: implicit holds the shipped yield-stress campaign)")
    c = scene.cfl_acoustic
    if c < n.cfl and c < MIN_DAMPED_CFL:  # the rule, not the user's cfl, takes C this low
        raise SceneError(
            f"numerics.cfl_rule: damping gives an acoustic C of {c:.3g} (nu / (c0 h) = "
            f"{scene.acoustic_damping_ratio:.3g}, density_diffusion = {n.density_diffusion}): "
            "the laminar term and the density diffusion barely damp the acoustic modes. Use "
            "cfl_rule: fixed with a C you have checked")


def _validate_shifting(scene: Scene) -> None:
    sh = scene.numerics.shifting
    _one_of(sh.method, SHIFTING_METHODS, "numerics.shifting.method")
    if sh.method == "lind" and scene.ch < LIND_MIN_CH:
        raise SceneError(
            f"numerics.shifting.method: lind needs ch >= {LIND_MIN_CH:g}, got ch = {scene.ch:g}: with "
            "h = dp a particle has only 8 neighbours within 2h, and Lind's shift inflates or "
            "diverges the fluid at rest. Use ch >= 1.1, or shifting skillen or none (docs/numerics.md)")
    if sh.coefficient is not None:
        _positive(sh.coefficient, "numerics.shifting.coefficient")
    if not (sh.min_speed >= 0 and math.isfinite(sh.min_speed)):
        raise SceneError(f"numerics.shifting.min_speed: must be a finite number >= 0 [m/s], got {sh.min_speed!r}")
    _one_of(sh.near_surface, NEAR_SURFACE, "numerics.shifting.near_surface")


def _validate_numerics(scene: Scene) -> None:
    """The numerics block: each key's allowed values (min_speed is skillen's and near_surface
    lind's; each method ignores the other's key, so that one scheme serves both)."""
    n = scene.numerics
    _positive(n.cfl, "numerics.cfl")
    _one_of(n.boundary, BOUNDARY_METHODS, "numerics.boundary")
    _one_of(n.mdbc_velocity, MDBC_VELOCITY, "numerics.mdbc_velocity")
    _one_of(n.viscous_update, VISCOUS_UPDATES, "numerics.viscous_update")
    _one_of(n.viscous_form, VISCOUS_FORMS, "numerics.viscous_form")
    _one_of(n.density_diffusion_reference, DIFFUSION_REFERENCES, "numerics.density_diffusion_reference")
    if n.density_diffusion is not None and not n.density_diffusion >= 0:
        raise SceneError(f"numerics.density_diffusion: must be >= 0, got {n.density_diffusion}")
    _validate_cfl_rule(scene)
    if n.artificial_viscosity is not None and not 0 <= n.artificial_viscosity <= 1:
        raise SceneError("numerics.artificial_viscosity: must lie in [0, 1] (DualSPHysics' default "
                         f"is 0.01) or be null, got {n.artificial_viscosity}")
    _validate_shifting(scene)
    if n.volume_relaxation is not None and not n.volume_relaxation > 0:
        raise SceneError("numerics.volume_relaxation: a rate beta > 0 (0.1 in the surge scheme) "
                         f"or null, got {n.volume_relaxation!r}")


def validate(scene: Scene) -> None:
    """Check physical and geometric consistency; raise SceneError naming the key."""
    _positive(scene.dp, "dp")
    _positive(scene.ch, "ch")
    lo, hi = CH_RANGE
    if not lo <= scene.ch <= hi:
        raise SceneError(f"ch: h/dp must lie in [{lo:g}, {hi:g}], got {scene.ch:g}: below 1 the kernel "
                         "support 2h holds too few neighbours for a stable sum")
    _positive(scene.fluid.density, "fluid.density")
    _validate_rheology(scene)
    if not scene.fluid.blocks and not scene.fluid.profiles:
        raise SceneError("fluid: at least one of fluid.blocks or fluid.profiles is required")
    s = scene.sound
    if s.c0 is not None:
        _positive(s.c0, "sound.c0")
        if s.coefsound is not None:
            raise SceneError("sound: give either c0 or coefsound with depth, not both")
    else:
        if s.coefsound is None or s.depth is None:
            raise SceneError("sound: give c0, or coefsound and depth")
        _positive(s.coefsound, "sound.coefsound")
        _positive(s.depth, "sound.depth")
        if math.hypot(*scene.gravity) == 0:
            raise SceneError("sound.coefsound: needs non-zero gravity; give sound.c0 instead")
    _positive(scene.time.end, "time.end")
    _positive(scene.time.output_interval, "time.output_interval")
    if scene.time.diagnostics_interval is not None:
        _positive(scene.time.diagnostics_interval, "time.diagnostics_interval")
    _validate_numerics(scene)
    g = scene.guards
    _positive(g.max_density_deviation, "guards.max_density_deviation")
    _positive(g.min_dt_fraction, "guards.min_dt_fraction")
    _positive(g.penetration, "guards.penetration")
    _positive(scene.memory_budget_gb, "memory_budget_gb")

    for i, b in enumerate(scene.fluid.blocks):
        _interval(b.x, f"fluid.blocks[{i}].x")
        _interval(b.z, f"fluid.blocks[{i}].z")
    for i, pr in enumerate(scene.fluid.profiles):
        key = f"fluid.profiles[{i}]"
        _interval(pr.x, f"{key}.x")
        xs = [x for x, _ in pr.surface]
        if len(xs) < 2 or any(b <= a for a, b in zip(xs, xs[1:])):
            raise SceneError(f"{key}.surface: needs at least 2 points with increasing x")
        if xs[0] > pr.x[0] or xs[-1] < pr.x[1]:
            raise SceneError(f"{key}.surface: the points must span {key}.x")
        if max(z for _, z in pr.surface) <= pr.base:
            raise SceneError(f"{key}.surface: lies entirely below {key}.base")
        if pr.row_depth is not None and not (0.5 * scene.dp <= pr.row_depth):
            raise SceneError(f"{key}.row_depth: must be at least dp / 2, or null, got {pr.row_depth}")
    regions = [(f"fluid.blocks[{j}]", b) for j, b in enumerate(scene.fluid.blocks)] + [
        (f"fluid.profiles[{j}]", p.bbox) for j, p in enumerate(scene.fluid.profiles)]
    for i, w in enumerate(scene.walls):
        _interval(w.x, f"walls[{i}].x")
        _interval(w.z, f"walls[{i}].z")
        if w.ramp_time < 0 or w.ramp_delay < 0:
            raise SceneError(f"walls[{i}] ({w.name}): ramp_time and ramp_delay must be >= 0")
        for key, b in regions:
            if w.overlap_area(b) > 1e-12 * scene.dp ** 2:
                raise SceneError(
                    f"walls[{i}] ({w.name}): overlaps {key}; walls and fluid must not share area")
    if scene.periodic_x is not None:
        _interval(scene.periodic_x, "periodic_x")
        x0, x1 = scene.periodic_x
        period = x1 - x0
        if period < 3 * 2 * scene.h:
            raise SceneError(f"periodic_x: the period must hold at least 3 kernel supports (6 h = {6 * scene.h:g} m)")
        n = period / scene.dp
        if abs(n - round(n)) > 1e-6:
            raise SceneError(f"periodic_x: the period {1e3 * period:.6g} mm is not a whole number of "
                             f"particles at dp = {1e3 * scene.dp:.6g} mm ({n:.4g} of them); choose dp "
                             f"dividing it")
        for r in scene.fluid.extents() + list(scene.walls):
            if r.x[0] < x0 - 1e-12 or r.x[1] > x1 + 1e-12:
                raise SceneError(f"periodic_x: every block and wall must lie within {list(scene.periodic_x)}")
    if scene.domain is not None:
        _interval(scene.domain.x, "domain.x")
        _interval(scene.domain.z, "domain.z")
    try:
        check_layout(scene)
    except LayoutError as exc:
        raise SceneError(str(exc)) from None
    n = scene.estimated_particles()
    per_particle = BYTES_PER_PARTICLE
    if scene.implicit_viscosity:
        from .implicit import bytes_per_particle
        per_particle += bytes_per_particle(scene.ch, scene.viscous_substeps)
    need = n * per_particle / 1e9
    if need > scene.memory_budget_gb:
        raise SceneError(
            f"dp: {n} particles need about {need:.1f} GB, over memory_budget_gb = "
            f"{scene.memory_budget_gb:g}; raise dp or the budget")
