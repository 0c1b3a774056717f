"""Run a scene to its end time, sampling diagnostics, snapshots and monitors; never raise on
divergence. A monitor may end the run early (steady state) or flag it as diverged."""
from __future__ import annotations

import math
import sys
import time as _time
from dataclasses import dataclass, field
from typing import Protocol

import numba as nb

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
    cg_iterations: int = 0  # of the implicit viscous solves, over the steps this process ran
    rkc_stages: int = 0  # of the sub-stepped viscous updates, over the steps this process ran
    started_unix: float = field(default_factory=_time.time)  # when the run first started (kept on resume)
    resumed: int = 0  # 1: this process resumed the run from a checkpoint
    diag_time: list = field(default_factory=list)
    diag: dict = field(default_factory=lambda: {k: [] for k in DIAGNOSTICS})
    snap_time: list = field(default_factory=list)
    snaps: list = field(default_factory=list)


class Monitor(Protocol):
    """Called every ``interval`` of simulated time; returns (status, reason) to end the run
    ('completed' or 'diverged'), or None to go on."""

    interval: float

    def __call__(self, sim: Simulation) -> tuple[str, str] | None: ...


class Progress:
    """Simulated time, dt, steps/s and time left on stderr, at most every ``every`` s."""

    def __init__(self, end: float, quiet: bool, every: float = 2.0):
        self.end, self.quiet, self.every = end, quiet, every
        self.t0 = self.last = _time.perf_counter()
        self.steps0 = None
        self.sim_t0 = None

    def __call__(self, sim: Simulation, force: bool = False):
        now = _time.perf_counter()
        if self.steps0 is None:
            self.steps0, self.sim_t0 = sim.steps, sim.t
        if self.quiet or (now - self.last < self.every and not force):
            return
        rate = (sim.steps - self.steps0) / max(now - self.last, 1e-9)
        elapsed = now - self.t0
        done = sim.t - self.sim_t0
        left = elapsed * (self.end - sim.t) / done if done > 0 else math.nan
        print(f"t = {sim.t:.4g}/{self.end:.4g} s  dt = {sim.info.dt:.3g} s  "
              f"{rate:.0f} steps/s  elapsed {elapsed:.0f} s  left <= {left:.0f} s",
              file=sys.stderr, flush=True)
        self.last, self.steps0 = now, sim.steps


class Runner:
    """Owns the time loop: diagnostics, snapshots and monitors at their own intervals.

    The runner's whole state (simulation arrays, results so far, next sampling times,
    monitors) can be checkpointed and resumed to give the same result.
    """

    def __init__(self, scene: Scene, sim: Simulation | None = None, monitors=(),
                 final_snapshot: bool = False):
        self.scene = scene
        self.sim = sim or Simulation(scene)
        self.monitors = list(monitors)
        self.final_snapshot = final_snapshot
        self.res = RunResult(scene=scene, threads=nb.get_num_threads(), n_particles=self.sim.n)
        tm = scene.time
        self.diag_every = tm.diagnostics_interval or tm.output_interval / 10.0
        self.next_out = self.next_diag = 0.0
        self.next_monitor = [0.0] * len(self.monitors)
        self.done = False
        self.tic = _time.perf_counter()

    def elapsed(self) -> float:
        """Wall time of this run so far, earlier (checkpointed) segments included."""
        return self.res.wall_time + _time.perf_counter() - self.tic

    def _record(self):
        sim, res = self.sim, self.res
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
        d["n_boundary_active"].append(int((sim.kind[:sim.n_active] == 1).sum()))

    def _snapshot(self):
        if not self.res.snap_time or self.res.snap_time[-1] != self.sim.t:
            self.res.snap_time.append(self.sim.t)
            self.res.snaps.append(self.sim.snapshot())

    def _end(self, status: str, reason: str):
        self.res.status, self.res.reason = status, reason
        self.done = True

    def run(self, quiet: bool = True, on_step=None) -> RunResult:
        """Advance until the end time, a monitor's stop or a divergence.

        ``on_step(runner)`` is called after every step (checkpointing hooks in here).
        """
        sim, res, tm = self.sim, self.res, self.scene.time
        tic = self.tic = _time.perf_counter()
        eps = 1e-9 * tm.end
        progress = Progress(tm.end, quiet)
        if sim.steps == 0 and not res.diag_time:
            reason = sim.health_reason()
            if reason:
                self._end("diverged", f"initial state: {reason}")
        while not self.done:
            if sim.t >= self.next_diag - eps:
                self._record()
                self.next_diag += self.diag_every
            if sim.t >= self.next_out - eps:
                self._snapshot()
                self.next_out += tm.output_interval
            for k, mon in enumerate(self.monitors):
                if sim.t >= self.next_monitor[k] - eps:
                    self.next_monitor[k] += mon.interval
                    verdict = mon(sim)
                    if verdict and not self.done:
                        self._end(*verdict)
            if self.done:
                break
            if sim.t >= tm.end - eps:
                self._end("completed", "")
                break
            target = min(self.next_out, tm.end)
            reason = sim.step(min(sim.info.dt, target - sim.t))
            if reason:
                self._end("diverged", reason)
                break
            progress(sim)
            if on_step is not None:
                on_step(self)
        if self.final_snapshot and res.status != "diverged":
            self._snapshot()
        progress(sim, force=True)
        res.steps = sim.steps
        res.cg_iterations = sim.solver_iterations
        res.rkc_stages = sim.rkc_stages
        res.wall_time += _time.perf_counter() - tic
        return res


CHECKPOINT_WALL_S = 60.0  # a scene run's checkpoint: at most this many wall seconds are lost


def run_scene(scene: Scene, quiet: bool = True, sim: Simulation | None = None, checkpoint=None,
              progress=None) -> RunResult:
    """Integrate to scene.time.end. Divergence ends the run with status 'diverged'.

    With ``checkpoint`` (a path), the run resumes from a matching checkpoint there
    (solver/checkpoint.py) and writes one every CHECKPOINT_WALL_S of wall time and at every
    snapshot interval; the caller removes it once the result is safely written. With
    ``progress`` (a path), its simulated time and time left are written there every few wall
    seconds (solver/progress.py)."""
    from .checkpoint import Checkpointer, run_key
    from .progress import ProgressFile, chain
    runner = Runner(scene, sim)
    ckpt = None
    if checkpoint is not None:
        ckpt = Checkpointer(checkpoint, scene.time.output_interval,
                            run_key(scene.to_yaml(), nb.get_num_threads()), wall_interval=CHECKPOINT_WALL_S)
        saved = ckpt.load()
        if saved is not None:
            ckpt.restore(runner, saved)
            runner.res.resumed = 1
    report = ProgressFile(progress, scene.name, None, scene.time.end) if progress else None
    res = runner.run(quiet, on_step=chain(ckpt, report))
    if report is not None:
        report.write(runner, res.status)
    return res
