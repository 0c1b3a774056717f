"""The slump (docs/flow-slump.md): a two-sided release [-L0, L0] x [0, H0] on a no-slip bed,
its front against Huppert's similarity solution (Newtonian) or its arrested shape and runout
against those of a perfectly plastic layer, with the lubrication runout as the reference's own
uncertainty (yield stress)."""
from __future__ import annotations

import html
import math

import numpy as np
import xarray as xr

from ..grid import Case
from ..references import slump as theory
from ..schema import ConfigError
from . import measure, scores
from .scene import REQUIRED, G, SceneFlow, newtonian, numerics, positive


class Slump(SceneFlow):
    name = "slump"
    title = "a viscous gravity current from a rectangular release (slump)"
    scene_keys = {
        "height": (REQUIRED, positive, "release height H0, m"),
        "length": (REQUIRED, positive, "release length L0 from the symmetry plane, m"),
        "end_time": (REQUIRED, positive, "simulated seconds"),
        "output_interval": (0.05, positive, "seconds between snapshots"),
        "coefsound": (10.0, positive, "c0 / sqrt(g H0)"),
        "bed_length": (None, positive, "bed length from the symmetry plane, m (default: 1.3 times "
                                       "the farthest reference front, at least 2 L0)"),
    }

    def check(self, cfg: dict) -> None:
        self.needs_fluids(cfg)
        for name, fl in cfg["fluids"].items():
            if not newtonian(fl) and not positive(fl.get("yield_stress")):
                raise ConfigError(f"config key fluids.{name}.yield_stress: a yield-stress slump needs "
                                  "tau_y > 0 (its reference is the arrested shape); a Newtonian fluid "
                                  "takes viscosity instead")

    def speed(self, cfg: dict, case: Case) -> float:
        """The velocity scale for surge's shifting floor: the similarity front's speed
        x_N / (5 t) at t = 1 s, with the fluid's viscosity (its consistency for a yield-stress fluid)."""
        s = cfg["scene"]
        fl = self.fluid_of(cfg, case)
        nu = (fl.get("viscosity") or fl.get("consistency")) / fl["density"]
        return 0.2 * float(theory.front_position(1.0, s["height"] * s["length"], nu, G))

    def reference_runout(self, cfg: dict, fluid: dict, shallow: bool = False) -> float:
        """The farthest front the reference predicts by the end time: the similarity front
        (Newtonian) or the runout of the perfectly plastic layer (yield stress;
        ``theory.release_runout_corrected``), with ``shallow`` the lubrication runout
        (``theory.release_runout``), the reference's uncertainty."""
        s = cfg["scene"]
        H0, L0 = s["height"], s["length"]
        if newtonian(fluid):
            return float(theory.front_position(s["end_time"], H0 * L0, fluid["viscosity"] / fluid["density"], G))
        runout = theory.release_runout if shallow else theory.release_runout_corrected
        return runout(H0, L0, fluid["yield_stress"], fluid["density"], G)

    def scene(self, cfg: dict, case: Case) -> dict:
        s = cfg["scene"]
        H0, L0, dp = s["height"], s["length"], case.dp
        fl = self.fluid_of(cfg, case)
        # the farther of the yield-stress runouts (the lubrication one) sets the bed
        X = s["bed_length"] or max(1.3 * self.reference_runout(cfg, fl),
                                   1.3 * self.reference_runout(cfg, fl, shallow=True), 2.0 * L0)
        X = dp * math.ceil(X / dp)
        layers = 3 * dp * max(1, math.ceil(case.ch / 1.5))  # the wall covers the 2h support
        fl["blocks"] = [{"x": [-L0, L0], "z": [0.0, H0]}]
        return {
            "name": case.id, "dp": dp, "ch": case.ch, "fluid": fl,
            "walls": [{"name": "bed", "x": [-X - layers, X + layers], "z": [-layers, 0.0]}],
            "domain": {"x": [-X - layers - 2 * dp, X + layers + 2 * dp], "z": [-layers - 2 * dp, 3.0 * H0]},
            "gravity": [0.0, -G], "sound": {"coefsound": s["coefsound"], "depth": H0},
            "numerics": numerics(case.scheme, self.speed(cfg, case), newtonian(fl), H0 / dp, case.shifting),
            "time": {"end": s["end_time"], "output_interval": s["output_interval"]},
        }

    def errors_of(self, cfg: dict, fluid: dict | None) -> tuple[str, ...]:
        if fluid is None or newtonian(fluid):
            return ("front_error", "exponent_error", "depth_error")
        return ("runout_error", "shape_error")

    def quantities(self, fluid: dict | None) -> tuple[str, ...]:
        return ("front_final",) if fluid is None or newtonian(fluid) else ("runout",)

    def measure(self, cfg: dict, case: Case, run: xr.Dataset):
        s, m = cfg["scene"], cfg["metrics"]
        fl = self.fluid_of(cfg, case)
        if newtonian(fl):
            values = scores.slump_newtonian(run, s["height"], s["length"], fl["viscosity"] / fl["density"],
                                            m["memory_fraction"])
        else:
            values = scores.slump_yield(run, s["height"], s["length"], fl["yield_stress"], fl["density"],
                                        m["stop_speed"], m["stop_window"])
        return values, measure.front(run, symmetric=True)

    def reference_text(self, cfg: dict, ds: xr.Dataset) -> str:
        s = cfg["scene"]
        lines = [f"<p>Release: height H0 = {1000 * s['height']:.3g} mm, length L0 = {1000 * s['length']:.3g} mm "
                 "from the symmetry plane (a two-sided release of length 2 L0 on a no-slip bed; both fronts "
                 "are measured and averaged, so the plane is the free-slip end wall of the half). The front "
                 "x_N is the outermost fluid particle plus dp / 2.</p><ul>"]
        for name, fl in (cfg.get("fluids") or {}).items():
            if newtonian(fl):
                f = cfg["metrics"]["memory_fraction"]
                mine = ds["fluid"].values == name
                t_c = float(np.nanmax(ds["compare_from"].values[mine])) if "compare_from" in ds else math.nan
                lines.append(
                    f"<li><b>{html.escape(name)}</b> (nu = {fl['viscosity'] / fl['density']:.4g} m2/s): "
                    "Huppert's similarity solution (J. Fluid Mech. 121, 1982), x_N = 1.411 (g A^3 t / (3 nu))^(1/5) "
                    "and its depth profile. The release's memory has faded, and the runs are compared, from "
                    f"t_c = {t_c:.3g} s: the time past which lubrication theory started from the rectangle has "
                    f"its front's local exponent within {100 * f:.3g} % of 1/5 (and its front within "
                    f"{100 * ((1 - f) ** -0.2 - 1):.2g} % of the similarity front). Front error: RMS of "
                    "x_N / x_ref - 1 over the snapshots from t_c; exponent: the least-squares slope of ln x_N "
                    "against ln t over the same snapshots; depth profile: the last snapshot, RMS over x &le; 0.95 x_N "
                    "over the reference's depth at the plane.</li>")
            else:
                x_ref = self.reference_runout(cfg, fl)
                x_lub = self.reference_runout(cfg, fl, shallow=True)
                ell = theory.yield_length(fl["yield_stress"], fl["density"], G)
                lines.append(
                    f"<li><b>{html.escape(name)}</b> (tau_y = {fl['yield_stress']:.4g} Pa, "
                    f"l = tau_y / (rho g) = {1000 * ell:.3g} mm): "
                    "the arrested shape of a perfectly plastic layer yielded throughout, h^2 - pi l h = 2 l (x_N - x) "
                    "(the lubrication balance with the layer's longitudinal plastic stress: its O(l / h) "
                    "correction, higher orders not claimed; after Dubash et al., J. Non-Newtonian Fluid "
                    "Mech. 158, 2009), cut at its "
                    f"front step h = pi l, and its runout x_N = {1000 * x_ref:.1f} mm "
                    f"({x_ref / s['height']:.2f} H0 from the plane). The lubrication limit, h^2 = 2 l (x_N - x), "
                    f"runs out to {1000 * x_lub:.1f} mm: the difference, {1000 * (x_lub - x_ref):.1f} mm "
                    f"({100 * (x_lub / x_ref - 1):.2g} % of the reference), is the reference's own uncertainty, "
                    "reported here and not added to the runout error. "
                    f"The front has stopped once its speed, fitted over {cfg['metrics']['stop_window']:g} s, "
                    f"stays below {1000 * cfg['metrics']['stop_speed']:.3g} mm/s (the regularised fluid "
                    "creeps at about tau_y h / mu_max); the runout is the front then.</li>")
        return "".join(lines) + "</ul>"

    def front_figure(self, cfg: dict) -> str | None:
        return ("x_N(t) of every run; Newtonian: against the similarity front (log axes; dotted: t_c, "
                "where the comparison starts); yield stress: against the runout of the plastic layer "
                "(dashed) and the lubrication runout (dotted), their difference the reference's uncertainty.")

    def front_reference(self, ax, cfg: dict, fluid: dict, ds: xr.Dataset, name: str) -> None:
        from .scene_figures import plain_log
        s = cfg["scene"]
        if not newtonian(fluid):
            ax.axhline(1000 * self.reference_runout(cfg, fluid), color="k", ls="--", lw=1.5,
                       label="plastic-layer runout")
            ax.axhline(1000 * self.reference_runout(cfg, fluid, shallow=True), color="0.4", ls=":", lw=1.5,
                       label="lubrication runout")
            return
        t = ds["front_time"].values
        t = t[t > 0]
        ax.plot(t, 1000 * theory.front_position(t, s["height"] * s["length"], fluid["viscosity"] / fluid["density"], G),
                "k--", lw=1.5, label="similarity (Huppert 1982)")
        if "compare_from" in ds:
            mine = ds["fluid"].values == name
            ax.axvline(float(np.nanmax(ds["compare_from"].values[mine])), color="0.5", ls=":", lw=1)
        plain_log(ax)
        ax.set_xlim(left=max(0.1, float(t.min())))


FLOW = Slump()
