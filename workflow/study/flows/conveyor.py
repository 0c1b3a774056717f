"""The conveyor-belt front of the paper (docs/conveyor.md): its campaign keys, the grid
dp x Ch x shifting (with extra cases, realisations, start checks and warm starts), each case's
solver case file, and the run's metrics, dataset, figures and report (study.metrics,
study.campaign, study.figures, study.report; the paper's verdict lives there)."""
from __future__ import annotations

import copy
from pathlib import Path

import xarray as xr

from .. import layout
from ..grid import Case, expand, matches, physical_axes, set_key
from ..startcheck import CHECK_STARTS, WARM_CHECK, check_tag
from ..schema import ConfigError, checked
from .base import Flow

SCHEMA = Path(__file__).resolve().parent / "conveyor.schema.yaml"

# Campaign keys that every solver case takes as well: (campaign path) -> (solver case path).
# The schema's default of each must be the solver's default (tests/test_defaults.py).
SOLVER_KEYS = {
    ("reference", "normalising_depth"): ("normalising_depth",),
    ("metrics", "stations"): ("probes", "stations"),
    ("metrics", "uniform_zone"): ("probes", "uniform_zone"),
}


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


def base_axes(cfg: dict) -> tuple:
    """The physical axes at their first values: the point the verdict and the paper's figures
    take (() without axes)."""
    return tuple((k, v[0]) for k, v in physical_axes(cfg["grid"]))


def validate(config: dict) -> dict:
    """The schema (with its defaults), then every case as the solver reads it."""
    cfg = checked(config, SCHEMA, _message)
    for extra in cfg.get("extra_cases") or []:
        if extra.get("tag") in CHECK_STARTS:
            raise ConfigError(f"config key extra_cases: tag {extra['tag']!r} is the start checks' "
                              f"({', '.join(CHECK_STARTS)}); give the case another tag")
    for key, _ in physical_axes(cfg["grid"]):
        if key.split(".")[1] in GRID_KEYS:
            raise ConfigError(f"config key grid.{key}: {key.split('.')[1]} is set by the grid itself "
                              "(grid.dp, grid.ch, grid.shifting), not by a physical axis")
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


def cases(cfg: dict) -> list[Case]:
    """The grid's cases, the extra cases, then the start checks (``start_checks``)."""
    found = configured_cases(cfg)
    return found + start_checks(cfg, found)


def configured_cases(cfg: dict) -> list[Case]:
    """The grid's cases and the extra cases, as the config lists them."""
    return expand(cfg["grid"], cfg.get("extra_cases"), lambda *point: realisations(cfg, *point))


def start_checks(cfg: dict, found: list[Case]) -> list[Case]:
    """With ``start_check``: at the finest grid dp, for each shifting method, the grid case at the
    Ch nearest grid.paper_ch run once more from another start (``startcheck.check_tag``: the
    paper's; where that case starts as the paper does, a warm start from the next coarser grid
    run (``coarser_case``) or, with none, the moving film), tagged with it."""
    grid = [c for c in found if c.on_grid and c.realisation == 0 and c.axes == base_axes(cfg)]
    if not cfg.get("start_check", True) or not grid:
        return []
    from solver.conveyor import case_from_dict
    from solver.scene import SceneError
    finest = min(c.dp for c in grid)
    paper_ch = float(cfg["grid"].get("paper_ch", 1.8))
    checks = []
    for sh in dict.fromkeys(c.shifting for c in grid if c.dp == finest):
        c = min((c for c in grid if c.dp == finest and c.shifting == sh), key=lambda c: (abs(c.ch - paper_ch), c.ch))
        try:
            own = case_from_dict(case_dict(cfg, c))
        except SceneError:  # validate() reports it, naming the case
            continue
        tag = check_tag(own.start, own.start_velocity, coarser_case(cfg, c) is not None)
        checks.append(Case(c.dp, c.ch, sh, tag, dict(CHECK_STARTS[tag]), axes=c.axes))
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
    """The run whose final state starts this one: with ``warm_start``, for a grid case, and for a
    warm-start check (``startcheck.WARM_CHECK``) always, ``coarser_case``; else None."""
    if case.tag == WARM_CHECK or (cfg.get("warm_start") and case.on_grid):
        return coarser_case(cfg, case)
    return None


def coarser_case(cfg: dict, case: Case) -> Case | None:
    """The grid case at the next coarser dp with the same Ch, shifting and physical axes: its same
    realisation, or its realisation 0 where that grid point ran fewer; None for the coarsest."""
    coarser = [c for c in configured_cases(cfg) if c.on_grid and c.ch == case.ch and c.shifting == case.shifting
               and c.axes == case.axes and c.dp > case.dp]
    if not coarser:
        return None
    dp = min(c.dp for c in coarser)
    point = {c.realisation: c for c in coarser if c.dp == dp}
    return point.get(case.realisation, point[0])


def solver_case(cfg: dict, case: Case | None = None):
    """The parsed solver case (solver.conveyor.ConveyorCase) of one campaign case (default:
    the first); the physical numbers (slope, depth) come from here, not from literals."""
    from solver.conveyor import case_from_dict
    return case_from_dict(case_dict(cfg, case if case is not None else cases(cfg)[0]))


def case_dict(cfg: dict, case: Case) -> dict:
    """The solver's case file (solver.conveyor) for one campaign case: ``case``, then each
    ``case_overrides`` entry whose ``where`` the case matches (in order), then an extra
    case's own ``overrides``, then the case's values of the physical axes."""
    d = copy.deepcopy(cfg["case"])
    for entry in cfg.get("case_overrides") or []:
        if matches(entry["where"], case.dp, case.ch, case.shifting):
            d = _merge(d, entry["case"])
    d = _merge(d, case.overrides)
    for key, value in case.axes:  # a physical axis: case.KEY (dotted) set to this case's value
        set_key(d, key.partition(".")[2], value)
    src = warm_source(cfg, case)
    if src is not None:
        d.update(start="warm", warm_from=layout.run_path(cfg, src.id))
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


# ---- the run's metrics, the campaign dataset, figures and report -----------------------------

def reference_for(cfg: dict, case):
    """The reference of one run: the theory of ``case`` (the physical case the run recorded) and
    the campaign's measured profiles, if any."""
    import numpy as np
    from ..reference import read_surface_csv, read_velocity_csv, theory_for_case
    lo, hi = cfg["metrics"]["free_surface_x_star"]
    x = np.round(np.arange(lo, hi + 1e-9, 0.1), 10)
    z = np.round(np.arange(0.0, 1.3 + 1e-9, 0.025), 10)
    ref = theory_for_case(case, x, cfg["metrics"]["stations"], z)
    m = cfg["reference"]["measured"]
    measured = {"surface": read_surface_csv(m["free_surface"]) if m.get("free_surface") else None,
                "velocity": {float(k): read_velocity_csv(v) for k, v in (m.get("velocity") or {}).items()}}
    return ref, measured


def has_yield_stress(cfg: dict) -> bool:
    """Whether any case of the validated campaign, grid or extra, runs a yield-stress
    (Herschel-Bulkley) fluid: the plug map's condition."""
    return any(not solver_case(cfg, c).newtonian for c in cases(cfg))


def figure_settings(cfg: dict, ds: xr.Dataset):
    import numpy as np
    from ..figures import Settings
    from ..reference import theory_for_case
    profiles = theory_for_case(solver_case(cfg), np.array([0.0]), ds["station"].values, ds["z_star"].values)
    return Settings(profile_ch=float(cfg["figures"]["profile_ch"]), theory=profiles)


class Conveyor(Flow):
    name = "conveyor"
    title = "the conveyor-belt front of the paper"
    schema = SCHEMA
    solver = "front"
    metric_keys = ("reference", "metrics")

    def metric_sources(self) -> list[Path]:
        from .. import metrics, reference
        return [Path(metrics.__file__), Path(reference.__file__)]

    def file_keys(self, cfg: dict) -> list[tuple]:
        measured = ((cfg.get("reference") or {}).get("measured") or {})
        keys = [("reference", "measured", "free_surface")] if measured.get("free_surface") else []
        keys += [("case", "warm_from")] if isinstance((cfg.get("case") or {}).get("warm_from"), str) else []
        return keys + [("reference", "measured", "velocity", k) for k in (measured.get("velocity") or {})]

    def validate(self, cfg: dict) -> dict:
        return validate(cfg)

    def cases(self, cfg: dict) -> list[Case]:
        return cases(cfg)

    def case_dict(self, cfg: dict, case: Case) -> dict:
        return case_dict(cfg, case)

    def warm_source(self, cfg: dict, case: Case) -> Case | None:
        return warm_source(cfg, case)

    def score(self, cfg: dict, case_id: str, run: xr.Dataset) -> xr.Dataset:
        """The metrics of study.metrics, against the theory of the case the run recorded (a run
        that recorded none: its case's in this campaign)."""
        from ..metrics import case_metrics
        from ..reference import recorded_case
        physical = recorded_case(run) or solver_case(cfg, self.case_by_id(cfg, case_id))  # its own physics
        ref, measured = reference_for(cfg, physical)
        m = case_metrics(run, ref, tuple(cfg["metrics"]["free_surface_x_star"]), measured)
        m.attrs["case"] = case_id
        return m

    def reduce(self, cfg: dict, results: Path) -> xr.Dataset:
        import yaml
        from ..campaign import build
        from ..reference import physics_of, recorded_case, start_description
        cs = cases(cfg)
        runs, metrics = [], []
        for c in cs:
            with xr.open_dataset(Path(results) / c.id / "run.nc") as r:
                runs.append(r.load())
            with xr.open_dataset(Path(results) / c.id / "metrics.nc") as m:
                metrics.append(m.load())
        ds = build(cs, runs, metrics)
        recorded = [recorded_case(r) or solver_case(cfg, c) for r, c in zip(runs, cs)]
        physics = [physics_of(case) for case in recorded]
        ds.attrs["schemes"] = ", ".join(sorted({case.scheme for case in recorded}))
        ds.attrs["starts"] = "; ".join(sorted({start_description(case) for case, c in zip(recorded, cs)
                                               if c.tag not in CHECK_STARTS}))
        mixed = [c.id for c, p in zip(cs, physics) if p != physics[0]]
        if mixed:  # each run was scored against its own theory; one h_n or slope would misstate them
            ds.attrs["physics_differ"] = (f"{', '.join(mixed)} differ in physics from {cs[0].id}: each run's "
                                          "metrics are against its own theory, but the figures' theory "
                                          "curves and the campaign's h_n and slope are the first case's")
        ds.attrs.update(h_n_m=float(runs[0].attrs.get("h_n_m", float("nan"))),
                        normalising_depth_m=float(cfg["reference"]["normalising_depth"]),
                        slope_deg=float(solver_case(cfg).slope_deg),
                        config_yaml=yaml.safe_dump(cfg, sort_keys=False),
                        realisations=int(ds["realisations"].max()),
                        start_perturbation=float(cfg["ensemble"]["perturbation"]),
                        window_stagger=float(cfg["ensemble"]["window_stagger"]),
                        version_numba=str(runs[0].attrs.get("version_numba", "")))
        return ds

    def figures(self, cfg: dict) -> list[tuple[str, str, str]]:
        from ..figures import figures_for
        ch = cfg["figures"]["profile_ch"]
        specs = figures_for(has_yield_stress(cfg), bool(physical_axes(cfg["grid"])))
        return [(spec.name, spec.title, spec.full_caption(ch)) for spec in specs]

    def write_figures(self, cfg: dict, ds: xr.Dataset, outdir) -> list[Path]:
        from ..figures import figures_for, write_all
        f = cfg["figures"]
        return write_all(ds, outdir, figure_settings(cfg, ds), fmt=f["format"], dpi=f["dpi"],
                         specs=figures_for(has_yield_stress(cfg), bool(physical_axes(cfg["grid"]))))

    def render(self, cfg: dict, ds: xr.Dataset, figure_dir) -> str:
        import yaml
        from ..report import render
        figs = []
        for name, title, caption in self.figures(cfg):
            p = Path(figure_dir) / f"{name}.{cfg['figures']['format']}"
            if not p.exists():
                raise ConfigError(f"missing figure {p}; run the figures step first")
            figs.append((p, title, caption))
        return render(ds, figs, yaml.safe_dump(cfg, sort_keys=False))


FLOW = Conveyor()
