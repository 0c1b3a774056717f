"""What the flows run as scenes (slump, film, user) share (docs/flows.md): the campaign keys and
grid dp x Ch x shifting x scheme (x fluid), each scene's numerics, the reduction of the runs into
one dataset over ``case``, and the report: the answer, the reference, then accuracy and cost,
convergence, stability, the figures, the configuration and provenance. Each flow says what is its own: its
scene keys and scene, its errors and the reference they are against."""
from __future__ import annotations

import copy
import html
import math
import sys
from pathlib import Path

import numpy as np
import xarray as xr

from ..convergence import MAX_ORDER, MIN_ORDER
from ..grid import Case, axis_label, axis_values, physical_axes, set_key, unique
from ..numbers import percent, with_error
from ..page import figure_html, page, provenance_html, reason_html
from ..schema import ConfigError, checked, coerce_scalars
from .base import Flow
from .runs import LABELS, cheapest, convergence, falls_with_dp, group_label, mm, seconds, sequences, series_label

SCHEMA = Path(__file__).resolve().parent / "scene.schema.yaml"
G = 9.81
REQUIRED = object()  # a scene key without a default


def positive(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool) and v > 0


def newtonian(fluid: dict) -> bool:
    return fluid.get("rheology", "newtonian") == "newtonian"


def numerics(scheme: str, speed: float, is_newtonian: bool, particles_across: float, shifting: str,
             own: dict | None = None) -> dict:
    """The scene's numerics: its own (or the paper's: mDBC, delta 0.1), with the scheme's preset
    over them (solver.schemes, the conveyor's, its speeds scaled by ``speed``); spec with a
    yield-stress fluid takes the implicit laminar term, since the explicit step would be bound by
    the viscosity cap (docs/flows.md)."""
    from solver.schemes import merge, preset
    base = merge({"boundary": "mdbc", "density_diffusion": 0.1}, own or {})
    num = merge(base, preset(scheme, speed, is_newtonian, particles_across).get("numerics", {}))
    if scheme == "spec" and not is_newtonian:
        num["viscous_update"] = "implicit"
    num["shifting"] = merge(num.get("shifting", {}), {"method": shifting})
    return num


def _value(v) -> str:
    """A physical axis's value in a table cell: numbers shortest, NaN (a case without it) blank."""
    if isinstance(v, float):
        return "" if v != v else f"{v:g}"
    return str(v)


class SceneFlow(Flow):
    """A flow whose cases are scenes run to their end time (``python -m solver run``)."""

    schema = SCHEMA
    solver = "run"
    metric_keys = ("scene", "fluids", "metrics")
    scene_keys: dict = {}  # name -> (default or REQUIRED, check, what it is)

    # ---- what each flow gives -----------------------------------------------------------
    def check(self, cfg: dict) -> None:
        """The flow's own checks beyond its scene keys (ConfigError naming the key)."""

    def scene(self, cfg: dict, case: Case) -> dict:
        raise NotImplementedError

    def errors_of(self, cfg: dict, fluid: dict | None) -> tuple[str, ...]:
        """The error names of a run of ``fluid`` (None: the scene's own), the headline first."""
        raise NotImplementedError

    def quantities(self, fluid: dict | None) -> tuple[str, ...]:
        """The measured quantities whose convergence the GCI states (Celik et al. 2008)."""
        return ()

    def measure(self, cfg: dict, case: Case, run: xr.Dataset) -> tuple[dict, xr.DataArray | None]:
        """(the run's errors and measured values, its front series x_N(t) or None)."""
        raise NotImplementedError

    def reference_text(self, cfg: dict, ds: xr.Dataset) -> str:
        raise NotImplementedError

    def front_figure(self, cfg: dict) -> str | None:
        """The caption of the front-against-time figure, None where the flow draws none."""
        return None

    def front_reference(self, ax, cfg: dict, fluid: dict, ds: xr.Dataset, name: str) -> None:
        """Draw the reference front on the front figure's panel of ``fluid``."""

    # ---- shared ---------------------------------------------------------------------------
    def metric_sources(self) -> list[Path]:
        from .. import references
        here = Path(__file__).resolve().parent
        return [Path(__file__), Path(sys.modules[type(self).__module__].__file__),
                here / "scores.py", here / "measure.py", here / "base.py",
                *sorted(Path(references.__file__).parent.glob("*.py"))]

    def validate(self, cfg: dict) -> dict:
        """Schema, then the flow's scene keys and checks, the physical axes, then every case's
        scene as the solver reads it."""
        cfg = checked(cfg, self.schema)
        self._scene_keys(cfg)
        self.check(cfg)
        self._check_axes(cfg)
        from solver.scene import SceneError, scene_from_dict
        for name, fl in (cfg.get("fluids") or {}).items():  # each fluid as the solver reads it
            try:
                scene_from_dict({"dp": 1.0, "fluid": {**fl, "blocks": [{"x": [0.0, 2.0], "z": [0.0, 2.0]}]},
                                 "time": {"end": 1.0, "output_interval": 1.0}, "sound": {"c0": 1.0}})
            except SceneError as exc:
                raise ConfigError(f"config key fluids.{name}: {exc}") from None
        for c in self.cases(cfg):
            try:
                scene_from_dict(self.case_dict(cfg, c))
            except (SceneError, OSError) as exc:
                where = f"fluids.{c.fluid}" if c.fluid else "scene"
                raise ConfigError(f"case {c.id} ({where}): {exc}") from None
        return cfg

    def _scene_keys(self, cfg: dict) -> None:
        """Fill the flow's scene defaults; ConfigError naming a key that is unknown, missing or
        out of range, with the allowed keys."""
        scene, keys = cfg["scene"], self.scene_keys
        for k in scene:
            if k not in keys:
                raise ConfigError(f"config key scene.{k}: not a key of flow {self.name}; its keys are "
                                  + ", ".join(f"{n} ({d[2]})" for n, d in keys.items()))
        for name, (default, check, what) in keys.items():
            if name in scene:
                scene[name] = coerce_scalars(scene[name], {"type": ["number", "boolean"]})
                if not (scene[name] is None and default is None) and not check(scene[name]):
                    raise ConfigError(f"config key scene.{name}: {scene[name]!r} is not valid: {what}")
            elif default is REQUIRED:
                raise ConfigError(f"config key scene.{name}: required for flow {self.name} ({what})")
            else:
                scene[name] = default

    def needs_fluids(self, cfg: dict) -> None:
        if not cfg.get("fluids"):
            raise ConfigError(f"config key fluids: flow {self.name} needs at least one fluid, e.g. "
                              "fluids: {newtonian: {density: 1383.0, viscosity: 5.6}}")

    @staticmethod
    def axes(cfg: dict) -> list[tuple[str, list]]:
        """The physical axes of the grid: (dotted campaign key, values), in the config's order."""
        return physical_axes(cfg["grid"])

    def _check_axes(self, cfg: dict) -> None:
        """ConfigError for an axis that names no scene key of the flow or no key of a fluid."""
        fluids = cfg.get("fluids") or {}
        for key, values in self.axes(cfg):
            parts = key.split(".")
            if parts[0] == "scene" and (len(parts) != 2 or parts[1] not in self.scene_keys):
                raise ConfigError(f"config key grid.{key}: a scene axis is scene.KEY with KEY one of "
                                  + ", ".join(self.scene_keys))
            if parts[0] == "scene":
                _, check, what = self.scene_keys[parts[1]]
                for v in values:
                    if not check(v):
                        raise ConfigError(f"config key grid.{key}: {v!r} is not valid: {what}")
            if parts[0] == "fluids" and (len(parts) != 3 or parts[1] not in fluids):
                raise ConfigError(f"config key grid.{key}: a fluid axis is fluids.NAME.KEY with NAME one of "
                                  + (", ".join(fluids) or "the campaign's fluids (it has none)"))

    def cases(self, cfg: dict) -> list[Case]:
        """fluid x axes x scheme x shifting x Ch x dp (each in the config's order), one case each;
        an axis on one fluid's key varies that fluid's cases only."""
        import itertools
        g = cfg["grid"]
        fluids = list(cfg.get("fluids") or {}) or [None]
        out = []
        for fl in fluids:
            own = [(k, v) for k, v in self.axes(cfg) if not k.startswith("fluids.") or k.split(".")[1] == fl]
            for values in itertools.product(*(v for _, v in own)):
                axes = tuple((k, v) for (k, _), v in zip(own, values))
                out += [Case(float(dp), float(ch), sh, scheme=scheme, fluid=fl, axes=axes)
                        for scheme in g["scheme"] for sh in g["shifting"] for ch in g["ch"] for dp in g["dp"]]
        try:
            return unique(out, "give the grid's axes keys whose last parts differ")
        except ValueError as exc:
            raise ConfigError(f"config key grid: {exc}") from None

    @staticmethod
    def case_config(cfg: dict, case: Case) -> dict:
        """The campaign as ``case`` sees it: each physical axis's key set to the case's value."""
        if not case.axes:
            return cfg
        cfg = copy.deepcopy(cfg)
        for key, value in case.axes:
            set_key(cfg, key, value)
        return cfg

    def case_dict(self, cfg: dict, case: Case) -> dict:
        return self.scene(self.case_config(cfg, case), case)

    def fluid_of(self, cfg: dict, case: Case | None) -> dict:
        fluids = cfg.get("fluids") or {}
        name = (case.fluid if case is not None else None) or next(iter(fluids))
        return copy.deepcopy(fluids[name])

    def fluid_dicts(self, cfg: dict) -> dict:
        """name -> fluid of the campaign; a scene's own unnamed fluid is {"": {}}."""
        return dict(cfg.get("fluids") or {"": {}})

    def all_errors(self, cfg: dict) -> list[str]:
        """The error names of every fluid of the campaign, each once, in order."""
        out: list[str] = []
        for fl in self.fluid_dicts(cfg).values():
            out += [e for e in self.errors_of(cfg, fl or None) if e not in out]
        return out

    def score(self, cfg: dict, case_id: str, run: xr.Dataset) -> xr.Dataset:
        """The run's errors (study.flows.scores) and its cost and status, as scalars; the front
        series x_N(t) where the flow has a front."""
        case = self.case_by_id(cfg, case_id)
        status = str(run.attrs.get("status", "unknown"))
        values: dict = {}
        series = None
        if status != "diverged" and run.sizes.get("snapshot", 0) > 1:
            values, series = self.measure(self.case_config(cfg, case), case, run)  # its own theory
        ds = xr.Dataset({k: ((), float(v)) for k, v in values.items()})
        if series is not None:
            ds["x_front"] = series.rename({"t": "front_time"})
        ds.attrs.update(case=case.id, status=status, reason=str(run.attrs.get("reason", "")),
                        wall_time_s=float(run.attrs.get("wall_time_s", math.nan)),
                        steps=int(run.attrs.get("steps", 0)), n_particles=int(run.attrs.get("n_particles", 0)),
                        end_time_s=float(run["snapshot_time"].values[-1]) if run.sizes.get("snapshot", 0)
                        else math.nan)
        return ds

    def reduce(self, cfg: dict, results: Path) -> xr.Dataset:
        """Every case's metrics.nc into one dataset over ``case`` (coords dp, ch, shifting, scheme,
        fluid; status, wall time, steps; every error and its se; x_front over (case, front_time))."""
        import yaml
        cs = self.cases(cfg)
        rows, fronts = [], []
        names: list[str] = []
        for c in cs:
            m = xr.load_dataset(Path(results) / c.id / "metrics.nc")
            rows.append(m)
            names += [k for k in m.data_vars if k != "x_front" and k not in names]
            if "x_front" in m:
                fronts.append(m["x_front"].expand_dims(case=[c.id]))
        coords = {"case": [c.id for c in cs], "dp": ("case", [c.dp for c in cs]),
                  "ch": ("case", [c.ch for c in cs]), "shifting": ("case", [c.shifting for c in cs]),
                  "scheme": ("case", [c.scheme for c in cs]), "fluid": ("case", [c.fluid or "" for c in cs])}
        for key, _ in self.axes(cfg):  # a physical axis: each case's value
            coords[axis_label(key)] = ("case", axis_values(cs, key))
        data = {k: ("case", [float(m[k]) if k in m else math.nan for m in rows]) for k in names}
        data["status"] = ("case", [m.attrs["status"] for m in rows])
        data["reason"] = ("case", [m.attrs["reason"] for m in rows])
        for k in ("wall_time_s", "steps", "n_particles", "end_time_s"):
            data[k] = ("case", [m.attrs[k] for m in rows])
        ds = xr.Dataset(data, coords=coords)
        if fronts:
            ds["x_front"] = xr.concat(fronts, dim="case", join="outer").reindex(case=ds["case"].values)
        ds.attrs["flow"] = self.name
        ds.attrs["axes"] = ",".join(axis_label(k) for k, _ in self.axes(cfg))  # the physical axes' coords
        ds.attrs["config_yaml"] = yaml.safe_dump(cfg, sort_keys=False)
        return ds

    # ---- report ---------------------------------------------------------------------------
    def answer(self, cfg: dict, ds: xr.Dataset) -> str:
        """One plain sentence per fluid and value of the physical axes: the finest run of each
        scheme and the cheapest trustworthy run."""
        tol = cfg["metrics"]["tolerance"]
        out = []
        groups: dict = {}  # (fluid, values of the physical axes) -> case indices
        for seq in sequences(ds):
            groups.setdefault((seq["fluid"], seq["axes"]), []).extend(seq["cases"])
        fluids = self.fluid_dicts(cfg)
        for (fname, values), idx in groups.items():
            errs = self.errors_of(cfg, fluids.get(fname) or None)
            head = errs[0]
            idx = sorted(idx)
            parts = []
            for scheme in dict.fromkeys(str(ds["scheme"].values[i]) for i in idx):
                sub = [i for i in idx if str(ds["scheme"].values[i]) == scheme]
                fine = min(sub, key=lambda i: float(ds["dp"].values[i]))
                if str(ds["status"].values[fine]) == "diverged":
                    parts.append(f"{scheme} diverged at dp = {mm(ds['dp'].values[fine])}")
                    continue
                se = float(ds[f"{head}_se"].values[fine]) if f"{head}_se" in ds else math.nan
                txt = (f"{scheme}'s {LABELS[head]} error at dp = {mm(ds['dp'].values[fine])} is "
                       f"{with_error(ds[head].values[fine], se)}")
                if head == "front_error" and "exponent" in ds and np.isfinite(ds["exponent"].values[fine]):
                    last = float(ds["front_final_error"].values[fine])
                    b, b_se = ds["exponent"].values[fine], ds["exponent_se"].values[fine]
                    txt += (f" (at the end {'ahead of' if last > 0 else 'behind'} the reference by "
                            f"{percent(abs(last))}; exponent {b:.4f} &plusmn; {2 * b_se:.2g})")
                if head == "runout_error":
                    txt += " (stopped)" if ds["stopped"].values[fine] > 0 else " (not stopped by the end)"
                parts.append(txt)
            best = cheapest(ds, idx, errs, tol)
            if best is None:
                cheap = f"no run has every error below {percent(tol)} by more than 2 se"
            else:
                cheap = (f"the cheapest run with every error below {percent(tol)} is "
                         f"{html.escape(str(ds['case'].values[best]))} "
                         f"({seconds(ds['wall_time_s'].values[best])} s)")
            label = group_label(fname, values)
            who = f"<b>{html.escape(label)}</b>: " if label else ""
            out.append(f"<li>{who}{'; '.join(parts)}; {cheap}.</li>")
        return "<ul>" + "".join(out) + "</ul>"

    def case_table(self, cfg: dict, ds: xr.Dataset) -> str:
        errs_all = self.all_errors(cfg)
        axes = [axis_label(k) for k, _ in self.axes(cfg)]
        head = ("<tr><th>dp</th><th class='l'>fluid</th>" + "".join(f"<th>{html.escape(a)}</th>" for a in axes)
                + "<th class='l'>scheme</th><th class='l'>shifting</th><th>Ch</th>"
                + "".join(f"<th>{html.escape(LABELS[e])}</th>" for e in errs_all)
                + "<th>status</th><th>wall time [s]</th><th>steps</th><th>particles</th></tr>")
        rows = []
        for i in range(ds.sizes["case"]):
            status = str(ds["status"].values[i])
            cells = [f"<td title='{html.escape(str(ds['case'].values[i]))}'>{mm(ds['dp'].values[i])}</td>",
                     f"<td class='l'>{html.escape(str(ds['fluid'].values[i]))}</td>",
                     *(f"<td>{html.escape(_value(ds[a].values[i].item()))}</td>" for a in axes),
                     f"<td class='l'>{html.escape(str(ds['scheme'].values[i]))}</td>",
                     f"<td class='l'>{html.escape(str(ds['shifting'].values[i]))}</td>",
                     f"<td>{ds['ch'].values[i]:g}</td>"]
            for e in errs_all:
                v = ds[e].values[i] if e in ds else math.nan
                se = ds[f"{e}_se"].values[i] if f"{e}_se" in ds else math.nan
                cells.append(f"<td style='white-space:nowrap'>{with_error(v, se)}</td>")
            note = status
            if "stopped" in ds and np.isfinite(ds["stopped"].values[i]):
                note += ", stopped" if ds["stopped"].values[i] > 0 else ", still moving"
            if ds["reason"].values[i]:
                note += f": {ds['reason'].values[i]}"
            cells += [f"<td class='l'>{reason_html(note)}</td>", f"<td>{seconds(ds['wall_time_s'].values[i])}</td>",
                      f"<td>{int(ds['steps'].values[i])}</td>", f"<td>{int(ds['n_particles'].values[i])}</td>"]
            cls = " class='diverged'" if status == "diverged" else ""
            rows.append(f"<tr{cls}>{''.join(cells)}</tr>")
        return f"<table>{head}{''.join(rows)}</table>"

    def convergence_table(self, cfg: dict, ds: xr.Dataset) -> str:
        rows = []
        fluids = self.fluid_dicts(cfg)
        for seq in sequences(ds):
            fl = fluids.get(seq["fluid"]) or None
            idx = seq["cases"]
            for e in self.errors_of(cfg, fl):
                vals = [percent(ds[e].values[i]) for i in idx]
                g = convergence(ds, e, idx)
                reliable = g.status == "monotone" and MIN_ORDER <= g.order <= MAX_ORDER
                order = (f"{g.order:.2g}" + ("" if reliable else " (unreliable)")) if g.status == "monotone" \
                    else "&ndash;"
                limit = percent(g.extrapolated) if reliable else "&ndash;"
                rows.append(f"<tr><td class='l'>{html.escape(series_label(seq))}</td><td class='l'>{LABELS[e]}</td>"
                            f"<td class='l'>{', '.join(mm(ds['dp'].values[i]) for i in idx)}</td>"
                            f"<td class='l'>{', '.join(vals)}</td><td class='l'>{falls_with_dp(ds[e].values[idx])}</td>"
                            f"<td class='l'>{g.status}</td><td>{order}</td><td>{limit}</td></tr>")
        for seq in sequences(ds):
            fl = fluids.get(seq["fluid"]) or None
            idx = seq["cases"]
            for q in self.quantities(fl):
                g = convergence(ds, q, idx)
                reliable = g.status == "monotone" and MIN_ORDER <= g.order <= MAX_ORDER
                limit = f"{1000 * g.extrapolated:.4g} mm, GCI {percent(g.gci_fine)}" if reliable else "&ndash;"
                rows.append(f"<tr><td class='l'>{html.escape(series_label(seq))}</td><td class='l'>{LABELS[q]}</td>"
                            f"<td class='l'>{', '.join(mm(ds['dp'].values[i]) for i in idx)}</td>"
                            f"<td class='l'>{', '.join(f'{1000 * ds[q].values[i]:.4g} mm' for i in idx)}</td>"
                            f"<td class='l'>&ndash;</td><td class='l'>{g.status}</td>"
                            f"<td>{f'{g.order:.2g}' if g.status == 'monotone' else '&ndash;'}"
                            f"{'' if reliable or g.status != 'monotone' else ' (unreliable)'}</td>"
                            f"<td>{limit}</td></tr>")
        return ("<p>Each error's magnitude over falling dp; from the three finest dp, where they converge "
                "monotonically, the observed order and the error Richardson-extrapolated to dp &rarr; 0 (Celik et "
                "al. 2008): near 0 where the runs converge to the reference, away from it where the scheme's limit "
                "differs from the reference (or the reference from the flow). For the measured front and runout: "
                f"their extrapolated value and the fine grid's GCI. An order above {MAX_ORDER:g} or below "
                f"{MIN_ORDER:g} is flagged unreliable and nothing is extrapolated from it.</p>"
                "<table><tr><th class='l'>sequence</th>"
                "<th class='l'>error</th><th class='l'>dp</th><th class='l'>values</th><th class='l'>with dp</th>"
                "<th class='l'>convergence</th><th>order</th><th>error at dp &rarr; 0</th></tr>"
                + "".join(rows) + "</table>")

    @staticmethod
    def stability_text(ds: xr.Dataset) -> str:
        """The stability map: each sequence's status at each dp (diverged cells with their reason)."""
        dps = sorted({float(d) for d in ds["dp"].values}, reverse=True)
        head = "<tr><th class='l'>sequence</th>" + "".join(f"<th>{mm(d)}</th>" for d in dps) + "</tr>"
        rows = []
        for seq in sequences(ds):
            by_dp = {float(ds["dp"].values[i]): i for i in seq["cases"]}
            cells = []
            for d in dps:
                i = by_dp.get(d)
                if i is None:
                    cells.append("<td></td>")
                    continue
                status = str(ds["status"].values[i])
                reason = f": {ds['reason'].values[i]}" if ds["reason"].values[i] else ""
                cells.append(f"<td class='{'ok' if status == 'completed' else 'bad'} l'>"
                             f"{reason_html(status + reason)}</td>")
            rows.append(f"<tr><td class='l'>{html.escape(series_label(seq))}</td>{''.join(cells)}</tr>")
        n_bad = sum(str(s) != "completed" for s in ds["status"].values)
        lead = (f"<p>All {ds.sizes['case']} runs completed: none diverged.</p>" if not n_bad else
                f"<p>{n_bad} of {ds.sizes['case']} runs did not complete; they have no errors.</p>")
        return lead + f"<table>{head}{''.join(rows)}</table>"

    def figures(self, cfg: dict) -> list[tuple[str, str, str]]:
        figs = [("errors", "Errors against dp",
                 "Each error's magnitude against the particle spacing (finer to the right), one line per "
                 "fluid, scheme, shifting method and Ch; bars: 2 se (sampling error). Dotted: the tolerance."),
                ("cost", "Run time against error",
                 "The headline error of each run against its wall time: the runs toward the lower left are "
                 "the cheapest for their accuracy. Dotted: the tolerance.")]
        fronts = self.front_figure(cfg)
        return figs + ([("fronts", "Front against time", fronts)] if fronts else [])

    def write_figures(self, cfg: dict, ds: xr.Dataset, outdir) -> list[Path]:
        from . import scene_figures
        fmt, dpi = cfg["figures"]["format"], cfg["figures"]["dpi"]
        return scene_figures.write(self, cfg, ds, outdir, [name for name, _, _ in self.figures(cfg)], fmt, dpi)

    def render(self, cfg: dict, ds: xr.Dataset, figure_dir) -> str:
        import yaml
        fmt = cfg["figures"]["format"]
        figs = [figure_html(Path(figure_dir) / f"{name}.{fmt}", title, caption)
                for name, title, caption in self.figures(cfg)]
        n = ds.sizes["case"]
        wall = float(np.nansum(ds["wall_time_s"].values))
        lead = (f"<p class='lead'>Flow: {self.title}. {n} runs, "
                f"{sum(str(s) == 'diverged' for s in ds['status'].values)} diverged; {wall / 60:.0f} min of "
                "simulation wall time summed over the runs. The paper's conclusions are about the conveyor "
                "front and are not judged here: this report answers how close each run comes to its reference, "
                "at what cost, and whether surge's departures from the paper's scheme (spec) help or hurt on "
                "this flow.</p>")
        axes = self.axes(cfg)
        sweep = ("" if not axes else "<p>Physical axes: " + "; ".join(
            f"{html.escape(k)} = {', '.join(map(str, v))}" for k, v in axes)
            + ". Each run is scored against the reference of its own values; the text below states the "
            "campaign's base values. Each value of an axis is its own convergence sequence.</p>")
        body = [("Answer", self.answer(cfg, ds)), ("Reference", sweep + self.reference_text(cfg, ds)),
                ("Accuracy and cost", "<p>One row a run (its case id shows over its dp). Errors in "
                 "per cent &plusmn; 2 se, the sampling error from the particle noise of the measurement (not "
                 "the discretisation error).</p>" + self.case_table(cfg, ds)),
                ("Convergence", self.convergence_table(cfg, ds)), ("Stability", self.stability_text(ds)),
                ("Figures", "".join(figs)),
                ("Configuration", f"<pre>{html.escape(yaml.safe_dump(cfg, sort_keys=False))}</pre>"),
                ("Provenance", provenance_html())]
        return page(f"sph-surge {self.name} campaign", f"sph-surge campaign report: {self.name}", lead, body)
