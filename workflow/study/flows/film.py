"""The film (docs/flow-film.md): a Newtonian film at rest on an incline at t = 0, periodic
along the plane, against the exact start-up series."""
from __future__ import annotations

import html
import math

import xarray as xr

from ..grid import Case
from ..references import film as theory
from ..schema import ConfigError
from . import scores
from .scene import REQUIRED, G, SceneFlow, newtonian, numerics, positive


class Film(SceneFlow):
    name = "film"
    title = "the start-up from rest of a film on an incline"
    scene_keys = {
        "depth": (REQUIRED, positive, "film depth h, m"),
        "angle": (REQUIRED, lambda v: positive(v) and v < 90, "incline angle, degrees"),
        "end_time": (REQUIRED, positive, "simulated seconds"),
        "output_interval": (None, positive, "seconds between snapshots (default: end_time / 6)"),
        "coefsound": (10.0, positive, "c0 / sqrt(g h)"),
    }

    def check(self, cfg: dict) -> None:
        self.needs_fluids(cfg)
        for name, fl in cfg["fluids"].items():
            if not newtonian(fl) or "viscosity" not in fl:
                raise ConfigError(f"config key fluids.{name}: flow film compares with the Newtonian start-up "
                                  "series; give a Newtonian fluid (density, viscosity)")

    def u_max(self, cfg: dict, case: Case | None = None) -> float:
        s = cfg["scene"]
        fl = self.fluid_of(cfg, case)
        return theory.u_max(s["depth"], fl["viscosity"] / fl["density"], G, math.radians(s["angle"]))

    def scene(self, cfg: dict, case: Case) -> dict:
        s = cfg["scene"]
        dp = case.dp
        n = max(1, round(s["depth"] / dp))
        h = n * dp  # a whole number of rows: the depth is the film's
        fl = self.fluid_of(cfg, case)
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
            "numerics": numerics(case.scheme, 2.0 / 3.0 * self.u_max(cfg, case), True, n, case.shifting),
            "time": {"end": s["end_time"], "output_interval": out},
        }

    def errors_of(self, cfg: dict, fluid: dict | None) -> tuple[str, ...]:
        return ("profile_error",)

    def measure(self, cfg: dict, case: Case, run: xr.Dataset):
        s = cfg["scene"]
        fl = self.fluid_of(cfg, case)
        depth = self.scene(cfg, case)["fluid"]["blocks"][0]["z"][1]
        return scores.film_startup(run, depth, fl["viscosity"] / fl["density"], math.radians(s["angle"])), None

    def reference_text(self, cfg: dict, ds: xr.Dataset) -> str:
        s = cfg["scene"]
        nus = ", ".join(f"{html.escape(n)} nu = {f['viscosity'] / f['density']:.4g} m2/s"
                        for n, f in cfg["fluids"].items())
        return (f"<p>Film depth {1000 * s['depth']:.4g} mm on a plane inclined at {s['angle']:g} deg ({nus}), "
                "at rest at t = 0, periodic along the plane. "
                "Reference: the exact start-up series of u_t = nu u_zz + g sin(theta) with no slip at the bed "
                "and no stress at the surface. Error: at every snapshot after t = 0 the RMS over the fluid "
                "particles of (u - u_exact) / u_max; the largest over the snapshots is reported.</p>")


FLOW = Film()
