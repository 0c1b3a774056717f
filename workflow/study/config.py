"""Campaign configuration: schema validation, defaults, and the per-case solver files."""
from __future__ import annotations

import copy
import re
from pathlib import Path

import yaml

from .grid import Case, expand, matches

SCHEMA = Path(__file__).resolve().parent / "config.schema.yaml"

# Campaign keys that every solver case takes as well: (campaign path) -> (solver case path).
# The schema's default of each must be the solver's default (tests/test_defaults.py).
SOLVER_KEYS = {
    ("reference", "normalising_depth"): ("normalising_depth",),
    ("metrics", "stations"): ("probes", "stations"),
    ("metrics", "uniform_zone"): ("probes", "uniform_zone"),
}


class ConfigError(ValueError):
    """The campaign configuration is invalid; the message names the key."""


def load_schema() -> dict:
    with open(SCHEMA) as fh:
        return yaml.safe_load(fh)


def _path(err) -> str:
    p = ".".join(str(x) for x in err.absolute_path)
    return p or "(top level)"


_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")
_INTEGER = re.compile(r"[-+]?\d+")
_BOOLEAN = {"true": True, "false": False}


def coerce_scalars(value, schema: dict):
    """``value`` with every string that the schema types as a number, an integer or a boolean
    read as one: YAML 1.1 (PyYAML, Snakemake's loader) reads ``3e-3`` as a string, YAML 1.2 and
    users as 3e-3; ``snakemake --config 'ensemble={realisations: 4}'`` passes every nested value
    as a string."""
    types = schema.get("type")
    types = [types] if isinstance(types, str) else (types or [])
    if isinstance(value, str):
        text = value.strip()
        if "integer" in types and _INTEGER.fullmatch(text):
            return int(text)
        if "number" in types and _NUMBER.fullmatch(text):
            return float(text)
        if "boolean" in types and text.lower() in _BOOLEAN:
            return _BOOLEAN[text.lower()]
    if isinstance(value, dict):
        props = schema.get("properties", {})
        return {k: coerce_scalars(v, props[k]) if k in props else v for k, v in value.items()}
    if isinstance(value, list) and isinstance(schema.get("items"), dict):
        return [coerce_scalars(v, schema["items"]) for v in value]
    return value


GRID_KEYS = ("dp", "ch", "shifting", "name")  # each case's own: not in case nor case_overrides


def _message(err) -> str:
    """The schema's message, or for a case mapping that sets what the grid sets, which keys."""
    if err.validator == "required" and not err.absolute_path and "'case'" in err.message:
        return ("'case' is required: the solver-case keys every run shares (docs/conveyor.md); "
                "case: {} runs the paper's case with the shipped scheme (scheme: surge), "
                "case: {scheme: spec} the paper's scheme as written. A file given by --configfile is "
                "complete in itself: nothing is taken from config/config.yaml")
    if err.validator == "not" and isinstance(err.instance, dict):
        found = [k for k in GRID_KEYS if k in err.instance]
        if found:
            return (f"sets {', '.join(found)}, which each case takes from the grid (grid.dp, grid.ch, "
                    "grid.shifting; the name from its case id); remove it here, or add an extra_cases "
                    "entry for a single case")
    return err.message


def with_defaults(config: dict, schema: dict):
    """(a copy of ``config`` with its scalars read as the schema types them and the schema's
    defaults filled in, the schema's errors sorted by key path)."""
    import jsonschema
    cfg = coerce_scalars(copy.deepcopy(config), schema)
    validator_cls = jsonschema.validators.validator_for(schema)

    def set_defaults(validator, properties, instance, schema):  # fill defaults while validating
        for name, sub in properties.items():
            if isinstance(instance, dict) and "default" in sub and name not in instance:
                instance[name] = copy.deepcopy(sub["default"])
        yield from validator_cls.VALIDATORS["properties"](validator, properties, instance, schema)

    Defaulting = jsonschema.validators.extend(validator_cls, {"properties": set_defaults})
    return cfg, sorted(Defaulting(schema).iter_errors(cfg), key=lambda e: list(e.absolute_path))


def validate(config: dict) -> dict:
    """Validate against the JSON schema (filling defaults) and check what a schema cannot.

    Returns the config with defaults; raises ConfigError naming the key. A campaign whose
    ``flow`` is not the conveyor has its own schema (study.flowconfig).
    """
    from .flowconfig import FLOWS, FlowConfigError
    flow = config.get("flow", "conveyor") if isinstance(config, dict) else "conveyor"
    if flow not in FLOWS:
        raise ConfigError(f"config key flow: {flow!r} is not one of {', '.join(FLOWS)}")
    if flow != "conveyor":
        from . import flowconfig
        try:
            return flowconfig.validate(config)
        except FlowConfigError as exc:
            raise ConfigError(str(exc)) from None
    cfg, errors = with_defaults(config, load_schema())
    if errors:  # every problem at once, each naming its key
        raise ConfigError("; ".join(f"config key {_path(e)}: {_message(e)}" for e in errors))
    try:
        expanded = cases(cfg)
    except ValueError as exc:
        raise ConfigError(str(exc)) from None
    if not expanded:
        raise ConfigError("config key grid.exclude: it leaves out every combination of grid.dp, grid.ch "
                          "and grid.shifting, and extra_cases is empty: there is no case to run")
    # every case must make a valid solver case: check now, before any job starts
    from solver.conveyor import case_from_dict
    from solver.scene import SceneError
    for c in expanded:
        try:
            case_from_dict(case_dict(cfg, c))
        except SceneError as exc:
            raise ConfigError(f"case {c.id}: {exc}") from None
    return cfg


def load(path) -> dict:
    with open(path) as fh:
        return validate(yaml.safe_load(fh) or {})


def cases(cfg: dict) -> list[Case]:
    """The grid's cases, the extra cases, then the start checks (``start_checks``)."""
    found = configured_cases(cfg)
    return found + start_checks(cfg, found)


def configured_cases(cfg: dict) -> list[Case]:
    """The grid's cases and the extra cases, as the config lists them."""
    return expand(cfg["grid"], cfg.get("extra_cases"), lambda *point: realisations(cfg, *point))


START_CHECK_TAG = "paper-start"
PAPER_START = {"start": "block", "start_velocity": "rest"}  # a block at rest, the belt ramped from rest


def start_checks(cfg: dict, found: list[Case]) -> list[Case]:
    """With ``start_check``: at the finest grid dp, for each shifting method, the grid case at the
    Ch nearest grid.paper_ch run once more from the paper's start (``PAPER_START``), tagged
    START_CHECK_TAG. None where the campaign's own cases start that way already."""
    grid = [c for c in found if c.on_grid and c.realisation == 0]
    if not cfg.get("start_check", True) or not grid:
        return []
    finest = min(c.dp for c in grid)
    paper_ch = float(cfg["grid"].get("paper_ch", 1.8))
    checks = []
    for sh in dict.fromkeys(c.shifting for c in grid if c.dp == finest):
        c = min((c for c in grid if c.dp == finest and c.shifting == sh), key=lambda c: (abs(c.ch - paper_ch), c.ch))
        checks.append(Case(c.dp, c.ch, sh, START_CHECK_TAG, dict(PAPER_START)))
    from solver.conveyor import case_from_dict
    from solver.scene import SceneError
    try:
        own = case_from_dict(case_dict(cfg, grid[0]))
    except SceneError:  # validate() reports it, naming the case
        own = None
    if own is not None and all(getattr(own, k) == v for k, v in PAPER_START.items()):
        return []
    taken = {c.id for c in found}
    return [c for c in checks if c.id not in taken]


def realisations(cfg: dict, dp: float, ch: float, shifting: str) -> int:
    """Realisations of the grid case (dp, ch, shifting): ``ensemble.realisations`` (1 where the
    key is absent), or that of the last ``ensemble.overrides`` entry whose ``where`` it matches."""
    ensemble = cfg.get("ensemble") or {}
    n = ensemble.get("realisations", 1)
    for entry in ensemble.get("overrides") or []:
        if matches(entry["where"], dp, ch, shifting):
            n = entry["realisations"]
    return int(n)


def _merge(base: dict, changes: dict) -> dict:
    from solver.schemes import merge
    return merge(base, changes)


def warm_source(cfg: dict, case: Case) -> Case | None:
    """With ``warm_start``: the grid case at the next coarser dp with the same Ch and shifting,
    whose final state starts this one: its same realisation, or its realisation 0 where that
    grid point ran fewer; None for the coarsest and extra cases."""
    if not cfg.get("warm_start") or not case.on_grid:
        return None
    coarser = [c for c in configured_cases(cfg) if c.on_grid and c.ch == case.ch and c.shifting == case.shifting
               and c.dp > case.dp]
    if not coarser:
        return None
    dp = min(c.dp for c in coarser)
    point = {c.realisation: c for c in coarser if c.dp == dp}
    return point.get(case.realisation, point[0])


def run_path(case: Case) -> str:
    """Where the campaign writes a case's run (relative to the working directory)."""
    return f"results/cases/{case.id}/run.nc"


def solver_case(cfg: dict, case: Case | None = None):
    """The parsed solver case (solver.conveyor.ConveyorCase) of one campaign case (default:
    the first); the physical numbers (slope, depth) come from here, not from literals."""
    from solver.conveyor import case_from_dict
    return case_from_dict(case_dict(cfg, case if case is not None else cases(cfg)[0]))


def case_dict(cfg: dict, case: Case) -> dict:
    """The solver's case file (solver.conveyor) for one campaign case: ``case``, then each
    ``case_overrides`` entry whose ``where`` the case matches (in order), then an extra
    case's own ``overrides``."""
    d = copy.deepcopy(cfg["case"])
    for entry in cfg.get("case_overrides") or []:
        if matches(entry["where"], case.dp, case.ch, case.shifting):
            d = _merge(d, entry["case"])
    d = _merge(d, case.overrides)
    src = warm_source(cfg, case)
    if src is not None:
        d.update(start="warm", warm_from=run_path(src))
    d.update(name=case.id, dp=case.dp, ch=case.ch, shifting=case.shifting)
    if case.realisation:
        d.update(start_perturbation=cfg["ensemble"]["perturbation"], perturbation_seed=case.realisation)
        stagger = cfg["ensemble"]["window_stagger"]
        if stagger:  # realisation k's window k * stagger later (ensemble.window_stagger)
            steady = d.setdefault("steady", {})
            steady["min_time"] = steady.get("min_time", default_min_time(steady)) + case.realisation * stagger
    for cfg_path, case_path in SOLVER_KEYS.items():  # the metrics read what the runs probed
        node = d
        for key in case_path[:-1]:
            node = node.setdefault(key, {})
        node[case_path[-1]] = copy.deepcopy(_get(cfg, cfg_path))
    return d


def default_min_time(steady: dict) -> float:
    """The solver case's start-up where its ``steady`` keys do not set min_time: one window."""
    from solver.conveyor import Steady
    s = Steady()
    return float(steady.get("average", s.average)) if s.min_time is None else s.min_time


def _get(tree: dict, path: tuple):
    for key in path:
        tree = tree[key]
    return tree
