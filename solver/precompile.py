"""Compile and cache the numba kernels that runs take, before a campaign's parallel jobs start
(``python -m solver warm``), so that no two runs compile the same kernel at once.

A conveyor case is run as its runs are, at a coarse dp (h_n / 5) for 0.05 s of simulated
time: the start (the film of a lubrication start), the steps, the probes, the steady
detection and the NetCDF output; a warm-started case then runs once more from that run's
file (the carried arrangement and the interpolated velocities); the disorder probe and a
sub-stepped viscous update over several RKC stages are called directly. A scene is stepped
twice as it is. Cases and scenes that select the same kernels are compiled once. With no case
or scene given, a tiny belt case with every shifting method, diffusion on and off, and both
boundaries.
"""
from __future__ import annotations

import json
import tempfile
import time
from dataclasses import replace
from pathlib import Path

COARSE_HN = 5  # the coarse dp of a case: h_n / 5, or its own where coarser
RUN_TIME = 0.05  # s simulated of each coarse run


def is_scene(data: dict) -> bool:
    """A scene (``python -m solver run``; walls are optional) rather than a conveyor case,
    which has no ``fluid`` key."""
    return "fluid" in data


def _step_twice(scene) -> None:
    from .simulation import Simulation
    sim = Simulation(scene)
    for _ in range(2):
        sim.step()


def _beyond_the_coarse_run(scene) -> None:
    """What a coarse run does not reach: the disorder probe (its uniform zone has no interior at
    h_n / 5) and, for a sub-stepped viscous update, a step long enough for several RKC stages."""
    import numpy as np

    from . import implicit
    from .forces import AX, AZ
    from .probes import disorder_moments
    from .simulation import Simulation
    sim = Simulation(scene)
    idx = np.arange(min(8, sim.n), dtype=np.int64)
    disorder_moments(idx, sim.x, sim.z, sim.rho, sim.mass, sim.cells, sim.h, np.empty((3, idx.size)))
    if scene.viscous_substeps:
        op, n = sim.viscous_operator(), sim.n_active
        bound = implicit.eigenvalue_bound(op[5], sim.kind, n)
        if bound > 0.0:  # dt bound = 10: three stages
            implicit.substep(op, sim.kind, 10.0 / bound, sim.out[AX].copy(), sim.out[AZ].copy(), n,
                             sim.solver_work)


def _cold(data: dict) -> dict:
    """A case dict without its warm start (a warm start's kernels are those of its cold start)."""
    data = {k: v for k, v in data.items() if k != "warm_from"}
    if data.get("start") == "warm":
        data["start"] = "lubrication"
    return data


def _coarse(data: dict):
    """The case, cold, at its coarse dp (h_n / COARSE_HN, or its own where coarser), run for
    RUN_TIME."""
    from .conveyor import case_from_dict
    data = _cold(data)
    case = case_from_dict(data)
    return case_from_dict({**data, "dp": max(case.dp, case.h_n / COARSE_HN),
                           "steady": {**(data.get("steady") or {}), "max_time": RUN_TIME}})


def _conveyor(coarse, warm: bool, scene, folder: Path) -> None:
    """Run the coarse case (``_coarse``) and, for a warm-started case, once more from its file."""
    from .front import run_front
    source = folder / "source.nc"
    run_front(coarse).to_netcdf(source)
    if warm:
        run_front(replace(coarse, start="warm", warm_from=str(source)))
    _beyond_the_coarse_run(scene)


def _generic() -> list[dict]:
    return [{"dp": 0.004, "ch": 1.5, "shifting": shifting, "numerics": {"density_diffusion": diffusion,
                                                                        "boundary": boundary}}
            for shifting in ("none", "skillen", "lind") for diffusion in (0.1, None)
            for boundary in ("mdbc", "dbc")]


def compile_kernels(entries: list[dict]) -> float:
    """Compile the kernels of each conveyor case dict and scene dict in ``entries`` (module
    docstring); none: the generic set. Returns the wall seconds taken."""
    from .conveyor import build_scene
    from .scene import scene_from_dict
    tic = time.perf_counter()
    seen = set()
    with tempfile.TemporaryDirectory(prefix="sph-surge-compile-") as tmp:
        for data in entries or _generic():
            if is_scene(data):
                fluid = {k: v for k, v in data["fluid"].items() if k not in ("blocks", "profiles")}
                key = json.dumps(["scene", data.get("numerics"), fluid, data.get("periodic_x") is not None],
                                 sort_keys=True)
                if key not in seen:
                    seen.add(key)
                    _step_twice(scene_from_dict(data))
                continue
            coarse = _coarse(data)
            warm = data.get("start") == "warm"
            scene = build_scene(coarse)
            d = scene.to_dict()
            fluid = {k: v for k, v in d["fluid"].items() if k not in ("blocks", "profiles")}
            key = json.dumps([d["numerics"], fluid, warm], sort_keys=True)
            if key not in seen:
                seen.add(key)
                _conveyor(coarse, warm, scene, Path(tmp))
    return time.perf_counter() - tic
