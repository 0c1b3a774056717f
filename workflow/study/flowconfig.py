"""Campaigns of the flows beyond the conveyor (``flow: slump | film | user``): the config's
schema and per-flow keys, the case grid dp x Ch x shifting x scheme (x fluid), and each case's
solver scene (docs/flows.md)."""
from __future__ import annotations

import copy
import math
from dataclasses import dataclass
from pathlib import Path

import yaml

from .grid import fmt

SCHEMA = Path(__file__).resolve().parent / "flow.schema.yaml"
FLOWS = ("conveyor", "slump", "film", "user")
CASE_ID = r"dp[0-9]+(?:\.[0-9]+)?mm_ch[0-9]+(?:\.[0-9]+)?_(?:none|skillen|lind)_(?:surge|spec)(?:_[a-z0-9-]+)?"
G = 9.81

# each flow's scene keys: name -> (default or REQUIRED, check, what it is)
REQUIRED = object()


def _positive(v):
    return isinstance(v, (int, float)) and not isinstance(v, bool) and v > 0


SCENE_KEYS = {
    "slump": {
        "height": (REQUIRED, _positive, "release height H0, m"),
        "length": (REQUIRED, _positive, "release length L0 from the symmetry plane, m"),
        "end_time": (REQUIRED, _positive, "simulated seconds"),
        "output_interval": (0.05, _positive, "seconds between snapshots"),
        "coefsound": (10.0, _positive, "c0 / sqrt(g H0)"),
        "bed_length": (None, _positive, "bed length from the symmetry plane, m (default: 1.3 times "
                                        "the farthest reference front, at least 2 L0)"),
    },
    "film": {
        "depth": (REQUIRED, _positive, "film depth h, m"),
        "angle": (REQUIRED, lambda v: _positive(v) and v < 90, "incline angle, degrees"),
        "end_time": (REQUIRED, _positive, "simulated seconds"),
        "output_interval": (None, _positive, "seconds between snapshots (default: end_time / 6)"),
        "coefsound": (10.0, _positive, "c0 / sqrt(g h)"),
    },
    "user": {
        "file": (REQUIRED, lambda v: isinstance(v, str), "the scene YAML file"),
        "speed": (REQUIRED, _positive, "the flow's velocity scale, m/s (surge's shifting floor is half of it)"),
        "reference": (REQUIRED, lambda v: isinstance(v, dict) and bool(v), "CSV files: front, depth, velocity"),
        "front_from": (0.0, lambda v: isinstance(v, (int, float)) and v >= 0,
                       "the front is compared from this time, s"),
        "symmetric": (False, lambda v: isinstance(v, bool), "a two-sided release about x = 0"),
    },
}
REFERENCE_KINDS = ("front", "depth", "velocity")


class FlowConfigError(ValueError):
    """The flow campaign's configuration is invalid; the message names the key."""


@dataclass(frozen=True)
class FlowCase:
    dp: float
    ch: float
    shifting: str
    scheme: str
    fluid: str | None = None

    @property
    def id(self) -> str:
        cid = f"dp{fmt(self.dp * 1000.0)}mm_ch{fmt(self.ch)}_{self.shifting}_{self.scheme}"
        return f"{cid}_{self.fluid}" if self.fluid else cid


def _schema_errors(cfg: dict) -> dict:
    """The config with the flow schema's defaults; FlowConfigError listing every schema error."""
    from .config import with_defaults
    with open(SCHEMA) as fh:
        cfg, errors = with_defaults(cfg, yaml.safe_load(fh))
    if errors:
        raise FlowConfigError("; ".join(
            f"config key {'.'.join(str(x) for x in e.absolute_path) or '(top level)'}: {e.message}" for e in errors))
    return cfg


def _scene_keys(cfg: dict) -> None:
    """Fill the flow's scene defaults; FlowConfigError naming a key that is unknown, missing or
    out of range, with the allowed keys."""
    flow, scene = cfg["flow"], cfg["scene"]
    keys = SCENE_KEYS[flow]
    for k in scene:
        if k not in keys:
            raise FlowConfigError(f"config key scene.{k}: not a key of flow {flow}; its keys are "
                                  + ", ".join(f"{n} ({d[2]})" for n, d in keys.items()))
    from .config import coerce_scalars
    for name, (default, check, what) in keys.items():
        if name in scene:
            scene[name] = coerce_scalars(scene[name], {"type": ["number", "boolean"]})
            if not (scene[name] is None and default is None) and not check(scene[name]):
                raise FlowConfigError(f"config key scene.{name}: {scene[name]!r} is not valid: {what}")
        elif default is REQUIRED:
            raise FlowConfigError(f"config key scene.{name}: required for flow {flow} ({what})")
        else:
            scene[name] = default
    if flow == "user":
        ref = scene["reference"]
        for k in ref:
            if k not in REFERENCE_KINDS:
                raise FlowConfigError(f"config key scene.reference.{k}: not a kind of reference; "
                                      f"allowed: {', '.join(REFERENCE_KINDS)}")
        read_references(scene)  # a malformed file is refused now, with its line
    if flow in ("slump", "film") and not cfg.get("fluids"):
        raise FlowConfigError(f"config key fluids: flow {flow} needs at least one fluid, e.g. "
                              "fluids: {newtonian: {density: 1383.0, viscosity: 5.6}}")
    if flow == "slump":
        for name, fl in cfg["fluids"].items():
            if fl.get("rheology", "newtonian") != "newtonian" and not _positive(fl.get("yield_stress")):
                raise FlowConfigError(f"config key fluids.{name}.yield_stress: a yield-stress slump needs "
                                      "tau_y > 0 (its reference is the arrested shape); a Newtonian fluid "
                                      "takes viscosity instead")
    if flow == "film":
        for name, fl in cfg["fluids"].items():
            if fl.get("rheology", "newtonian") != "newtonian" or "viscosity" not in fl:
                raise FlowConfigError(f"config key fluids.{name}: flow film compares with the Newtonian start-up "
                                      "series; give a Newtonian fluid (density, viscosity)")
    if flow == "user" and cfg.get("fluids"):
        raise FlowConfigError("config key fluids: flow user takes its fluid from its scene file (scene.file)")


def read_references(scene: dict) -> dict:
    """{kind: DataArray} of a user flow's reference files (study.flows.user readers)."""
    from .flows import user
    readers = {"front": user.read_front, "depth": user.read_depth_profiles,
               "velocity": user.read_velocity_profiles}
    out = {}
    for kind, path in scene["reference"].items():
        try:
            out[kind] = readers[kind](path)
        except OSError as exc:
            raise FlowConfigError(f"config key scene.reference.{kind}: {exc}") from None
        except ValueError as exc:
            raise FlowConfigError(f"config key scene.reference.{kind}: {exc}") from None
    return out


def validate(config: dict) -> dict:
    """Schema, then the flow's scene keys, then every case's scene as the solver reads it."""
    cfg = _schema_errors(config)
    _scene_keys(cfg)
    from solver.scene import SceneError, scene_from_dict
    for name, fl in (cfg.get("fluids") or {}).items():  # each fluid as the solver reads it
        try:
            scene_from_dict({"dp": 1.0, "fluid": {**fl, "blocks": [{"x": [0.0, 2.0], "z": [0.0, 2.0]}]},
                             "time": {"end": 1.0, "output_interval": 1.0}, "sound": {"c0": 1.0}})
        except SceneError as exc:
            raise FlowConfigError(f"config key fluids.{name}: {exc}") from None
    for c in cases(cfg):
        try:
            scene_from_dict(scene_dict(cfg, c))
        except (SceneError, OSError) as exc:
            where = f"fluids.{c.fluid}" if c.fluid else "scene"
            raise FlowConfigError(f"case {c.id} ({where}): {exc}") from None
    return cfg


def cases(cfg: dict) -> list[FlowCase]:
    """fluid x scheme x shifting x Ch x dp (each in the config's order), one case each."""
    g = cfg["grid"]
    fluids = list(cfg.get("fluids") or {}) or [None]
    return [FlowCase(float(dp), float(ch), sh, scheme, fl)
            for fl in fluids for scheme in g["scheme"] for sh in g["shifting"] for ch in g["ch"]
            for dp in g["dp"]]


def fluid_of(cfg: dict, case: FlowCase) -> dict:
    fluids = cfg.get("fluids") or {}
    name = case.fluid or next(iter(fluids))
    return copy.deepcopy(fluids[name])


def _numerics(scheme: str, speed: float, newtonian: bool, particles_across: float, shifting: str,
              own: dict | None = None) -> dict:
    """The scene's numerics: its own (or the paper's: mDBC, delta 0.1), with the scheme's preset
    over them (solver.schemes, the conveyor's, its speeds scaled by ``speed``); spec with a
    yield-stress fluid takes the implicit laminar term, since the explicit step would be bound by
    the viscosity cap (docs/flows.md)."""
    from solver.schemes import merge, preset
    base = merge({"boundary": "mdbc", "density_diffusion": 0.1}, own or {})
    num = merge(base, preset(scheme, speed, newtonian, particles_across).get("numerics", {}))
    if scheme == "spec" and not newtonian:
        num["viscous_update"] = "implicit"
    num["shifting"] = merge(num.get("shifting", {}), {"method": shifting})
    return num


def scene_dict(cfg: dict, case: FlowCase) -> dict:
    """The solver scene (solver.scene) of one case."""
    flow = cfg["flow"]
    return {"slump": _slump_scene, "film": _film_scene, "user": _user_scene}[flow](cfg, case)


def slump_speed(cfg: dict, case: FlowCase) -> float:
    """The slump's velocity scale for surge's shifting floor: the similarity front's speed
    x_N / (5 t) at t = 1 s, with the fluid's viscosity (its consistency for a yield-stress fluid)."""
    from .flows import slump
    s = cfg["scene"]
    fl = fluid_of(cfg, case)
    nu = (fl.get("viscosity") or fl.get("consistency")) / fl["density"]
    return 0.2 * float(slump.front_position(1.0, s["height"] * s["length"], nu, G))


def reference_runout(cfg: dict, fluid: dict) -> float:
    """The farthest front the slump's reference predicts by its end time: the similarity front
    (Newtonian) or the lubrication runout (yield stress)."""
    from .flows import slump
    s = cfg["scene"]
    H0, L0 = s["height"], s["length"]
    if fluid.get("rheology", "newtonian") == "newtonian":
        return float(slump.front_position(s["end_time"], H0 * L0, fluid["viscosity"] / fluid["density"], G))
    return slump.release_runout(H0, L0, fluid["yield_stress"], fluid["density"], G)


def _slump_scene(cfg: dict, case: FlowCase) -> dict:
    s = cfg["scene"]
    H0, L0, dp = s["height"], s["length"], case.dp
    fl = fluid_of(cfg, case)
    newtonian = fl.get("rheology", "newtonian") == "newtonian"
    X = s["bed_length"] or max(1.3 * reference_runout(cfg, fl), 2.0 * L0)
    X = dp * math.ceil(X / dp)
    layers = 3 * dp * max(1, math.ceil(case.ch / 1.5))  # the wall covers the 2h support
    fl["blocks"] = [{"x": [-L0, L0], "z": [0.0, H0]}]
    return {
        "name": case.id, "dp": dp, "ch": case.ch, "fluid": fl,
        "walls": [{"name": "bed", "x": [-X - layers, X + layers], "z": [-layers, 0.0]}],
        "domain": {"x": [-X - layers - 2 * dp, X + layers + 2 * dp], "z": [-layers - 2 * dp, 3.0 * H0]},
        "gravity": [0.0, -G], "sound": {"coefsound": s["coefsound"], "depth": H0},
        "numerics": _numerics(case.scheme, slump_speed(cfg, case), newtonian, H0 / dp, case.shifting),
        "time": {"end": s["end_time"], "output_interval": s["output_interval"]},
    }


def film_u_max(cfg: dict, case: FlowCase | None = None) -> float:
    from .flows import film
    s = cfg["scene"]
    fl = fluid_of(cfg, case) if case is not None else next(iter(cfg["fluids"].values()))
    return film.u_max(s["depth"], fl["viscosity"] / fl["density"], G, math.radians(s["angle"]))


def _film_scene(cfg: dict, case: FlowCase) -> dict:
    s = cfg["scene"]
    dp = case.dp
    n = max(1, round(s["depth"] / dp))
    h = n * dp  # a whole number of rows: the depth is the film's
    fl = fluid_of(cfg, case)
    width = dp * max(n, math.ceil(6.0 * case.ch) + 1)  # the period holds 3 kernel supports
    theta = math.radians(s["angle"])
    layers = 3 * dp * max(1, math.ceil(case.ch / 1.5))
    fl["blocks"] = [{"x": [0.0, width], "z": [0.0, h]}]
    out = s["output_interval"] or s["end_time"] / 6.0
    return {
        "name": case.id, "dp": dp, "ch": case.ch, "fluid": fl,
        "walls": [{"name": "bed", "x": [0.0, width], "z": [-layers, 0.0]}],
        "periodic_x": [0.0, width],
        "gravity": [G * math.sin(theta), -G * math.cos(theta)],
        "sound": {"coefsound": s["coefsound"], "depth": h},
        "numerics": _numerics(case.scheme, 2.0 / 3.0 * film_u_max(cfg, case), True, n, case.shifting),
        "time": {"end": s["end_time"], "output_interval": out},
    }


def _user_scene(cfg: dict, case: FlowCase) -> dict:
    from solver.scene import read_yaml
    s = cfg["scene"]
    d = read_yaml(s["file"]) or {}
    if not isinstance(d, dict):
        raise FlowConfigError(f"config key scene.file: {s['file']} does not hold a scene mapping")
    fl = d.get("fluid", {})
    newtonian = fl.get("rheology", "newtonian") == "newtonian"
    depth = (d.get("sound") or {}).get("depth") or 15.0 * case.dp
    d.update(name=case.id, dp=case.dp, ch=case.ch)
    d["numerics"] = _numerics(case.scheme, s["speed"], newtonian, depth / case.dp, case.shifting,
                              own=d.get("numerics"))
    return d


def load(path) -> dict:
    with open(path) as fh:
        return validate(yaml.safe_load(fh) or {})
