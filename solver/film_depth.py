"""The scheme's own normal depth, measured on a short periodic film.

The conveyor's body settles where its film, relative to the belt, carries u_b h (zero flux
in the lab frame). An SPH film carries a flux q_SPH(h) a little off the exact q(h)
(g sin(theta) h^3 / (3 nu), docs/scheme.md section 7, or the Herschel-Bulkley film's), so the scheme's
body settles off h_n, and a start filled to h_n drains or fills its body through the front
for seconds.

Here a film of depth h_n (rows filling it exactly), periodic in x over a strip of at least
3 kernel supports, flows on a fixed bed under the case's gravity with every numerical choice
of the case (dp, Ch, shifting, density diffusion, boundary, viscous term, CFL). Over
[FILM_TIME - FILM_AVERAGE, FILM_TIME] its volume flux sum(V u) / L gives r = q_SPH / q at
the film's mean depth. The scheme then behaves as the fluid whose exact film carries r q:
viscosity mu / r (Herschel-Bulkley: consistency K r^-n), whose normal depth is

    h_s = h_n / sqrt(r)   (newtonian; Herschel-Bulkley: zero lab-frame flux of that fluid),

the body depth the lubrication start is filled to, with that fluid's front
(``conveyor.scheme_fluid``; ``ConveyorCase.start_depth: film``). The film starts from rest;
its slowest viscous mode decays with 4 h^2 / (pi^2 nu) (35 ms for the paper's fluid), so
FILM_TIME is many of them.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from .conveyor import build_scene_dict, scheme_fluid, wall_thickness
from .scene import scene_from_dict
from .simulation import Simulation

FILM_TIME = 0.5  # s simulated
FILM_AVERAGE = 0.2  # s: the flux is averaged over the film's last FILM_AVERAGE seconds
R_RANGE = (0.25, 4.0)  # a flux ratio outside is no film of this fluid (h_s would be off 2-fold)


@dataclass
class FilmDepth:
    depth: float  # h_s / h_n
    flux_ratio: float  # r = q_SPH / q at the film's depth
    steps: int
    wall_time: float  # s

    def describe(self) -> str:
        return (f"film: SPH flux / exact flux {self.flux_ratio:.4f} over "
                f"[{FILM_TIME - FILM_AVERAGE:g}, {FILM_TIME:g}] s ({self.steps} steps, "
                f"{self.wall_time:.1f} s wall), body depth {self.depth:.4f} h_n")


def film_scene_dict(case) -> dict:
    """The periodic film of the case's scheme: depth h_n, bed fixed, strip of whole dp."""
    d = build_scene_dict(case)
    hn, dp = case.h_n, case.dp
    n = math.ceil(6.0 * case.ch - 1e-9) + 1  # columns: the period holds 3 kernel supports 2h
    length = n * dp
    fluid = {k: v for k, v in d["fluid"].items() if k not in ("blocks", "profiles")}
    fluid["profiles"] = [{"x": [0.0, length], "base": 0.0, "surface": [[0.0, hn], [length, hn]],
                          "row_depth": hn}]
    d.update(name=f"{case.name} film", fluid=fluid, periodic_x=[0.0, length],
             walls=[{"name": "bed", "x": [0.0, length], "z": [-wall_thickness(case), 0.0]}],
             time={"end": FILM_TIME, "output_interval": FILM_TIME})
    return d


def scheme_normal_depth(case) -> FilmDepth:
    """Run the film and return r and h_s / h_n; RuntimeError if the film stops (a guard fired)
    or r falls outside R_RANGE."""
    start = time.perf_counter()
    scene = scene_from_dict(film_scene_dict(case))
    sim = Simulation(scene)
    length = scene.periodic_x[1] - scene.periodic_x[0]
    depth, flux = [], []
    while sim.t < FILM_TIME - 1e-12:
        reason = sim.step()
        if reason:
            raise RuntimeError(f"the film stopped at t = {sim.t:.3g} s: {reason}")
        if sim.t >= FILM_TIME - FILM_AVERAGE:
            fluid = sim.kind == 0  # the arrays are re-sorted as the particles move
            volume = sim.mass[fluid] / sim.rho[fluid]
            depth.append(volume.sum() / length)
            flux.append((volume * sim.u[fluid]).sum() / length)
    h = float(np.mean(depth))
    r = float(np.mean(flux)) / exact_flux(case, h)
    if not R_RANGE[0] <= r <= R_RANGE[1]:  # NaN included
        raise RuntimeError(f"the film's flux ratio {r:.4g} lies outside {list(R_RANGE)}")
    return FilmDepth(depth=scheme_fluid(case, r).h_n / case.h_n, flux_ratio=r, steps=sim.steps,
                     wall_time=time.perf_counter() - start)


def exact_flux(case, h: float) -> float:
    """Volume flux per unit width of the exact film of depth h on the case's slope."""
    g, sin = case.gravity, math.sin(case.theta)
    if case.newtonian:
        return g * sin * h ** 3 / (3.0 * case.viscosity / case.density)
    return case.hb_fluid.flux(h, sin, g)
