"""Run a scene to its end time, sampling diagnostics and snapshots; never raise on divergence."""
from __future__ import annotations

import math
import sys
import time as _time
from dataclasses import dataclass, field

import numba as nb
import numpy as np

from . import guards
from .scene import Scene
from .simulation import Simulation

DIAGNOSTICS = ("dt", "dt_limit", "dt_force", "dt_acoustic", "dt_viscous", "kinetic_energy",
               "max_density_deviation", "max_penetration", "n_fluid", "n_boundary_active")


@dataclass
class RunResult:
    scene: Scene
    status: str = "completed"
    reason: str = ""
    steps: int = 0
    wall_time: float = 0.0
    threads: int = 1
    n_particles: int = 0
    diag_time: list = field(default_factory=list)
    diag: dict = field(default_factory=lambda: {k: [] for k in DIAGNOSTICS})
    snap_time: list = field(default_factory=list)
    snaps: list = field(default_factory=list)


class Progress:
    """Simulated time, dt, steps/s and time left on stderr, at most every ``every`` s."""

    def __init__(self, end: float, quiet: bool, every: float = 2.0):
        self.end, self.quiet, self.every = end, quiet, every
        self.t0 = self.last = _time.perf_counter()
        self.steps0 = 0

    def __call__(self, sim: Simulation, force: bool = False):
        now = _time.perf_counter()
        if self.quiet or (now - self.last < self.every and not force):
            return
        rate = (sim.steps - self.steps0) / max(now - self.last, 1e-9)
        elapsed = now - self.t0
        left = elapsed * (self.end - sim.t) / sim.t if sim.t > 0 else math.nan
        print(f"t = {sim.t:.4g}/{self.end:.4g} s  dt = {sim.info.dt:.3g} s  "
              f"{rate:.0f} steps/s  elapsed {elapsed:.0f} s  left ~{left:.0f} s",
              file=sys.stderr, flush=True)
        self.last, self.steps0 = now, sim.steps


def _record(sim: Simulation, res: RunResult):
    h = sim.check_health()
    d = res.diag
    res.diag_time.append(sim.t)
    d["dt"].append(sim.info.dt)
    d["dt_limit"].append(sim.info.limit)
    for k, v in zip(("dt_force", "dt_acoustic", "dt_viscous"), sim.info.dt_limits):
        d[k].append(v)
    d["kinetic_energy"].append(h[3])
    d["max_density_deviation"].append(h[1])
    d["max_penetration"].append(h[2])
    d["n_fluid"].append(sim.n_fluid)
    d["n_boundary_active"].append(int(((sim.kind[:sim.n_active]) == 1).sum()))


def run_scene(scene: Scene, quiet: bool = True, sim: Simulation | None = None) -> RunResult:
    """Integrate to scene.time.end. Divergence ends the run with status 'diverged'."""
    tic = _time.perf_counter()
    sim = sim or Simulation(scene)
    res = RunResult(scene=scene, threads=nb.get_num_threads(), n_particles=sim.n)
    tm = scene.time
    diag_every = tm.diagnostics_interval or tm.output_interval / 10.0
    next_out, next_diag = 0.0, 0.0
    eps = 1e-9 * tm.end
    progress = Progress(tm.end, quiet)
    reason = guards.check(sim.check_health(), scene.guards, scene.dp)
    if reason:
        res.status, res.reason = "diverged", f"initial state: {reason}"
    while not reason:
        if sim.t >= next_diag - eps:
            _record(sim, res)
            next_diag += diag_every
        if sim.t >= next_out - eps:
            res.snap_time.append(sim.t)
            res.snaps.append(sim.snapshot())
            next_out += tm.output_interval
        if sim.t >= tm.end - eps:
            break
        target = min(next_out, tm.end)
        reason = sim.step(min(sim.info.dt, target - sim.t))
        if reason:
            res.status, res.reason = "diverged", reason
        progress(sim)
    progress(sim, force=True)
    res.steps = sim.steps
    res.wall_time = _time.perf_counter() - tic
    return res
