"""The step's passes other than the pair loop, of two solver trees, on the same arrays: us per call.

Times the free-surface normals of lind's shift along the surface (``shifting.surface_normals``,
where the scene has it), the mDBC update of the wall particles (``boundary.make_mdbc_update``, with the scene's
ghost velocity; on copies of rho, u, w, so that every call starts from the same state), the
guards' pass (``guards.fluid_health``), the accumulators' reduction
(``forces.reduce_accumulators``), the cell assignment (``cells.assign_cells``) and the counting
sort (``cells.counting_sort``) of OLD_TREE and NEW_TREE (default: this tree), each imported as
a copy (as ``benchmarks/pair_loop.py`` does: a copy against the tree imported as ``solver``
read 0.90-1.12 for identical code), alternated call by call: the median of
--calls calls each, and the largest difference of their outputs. The arrays are a simulation
of this tree stepped --warmup times: the throughput layer (benchmarks/throughput.py) or, with
--case, a conveyor case (its scheme sets how many slots the reduction sums; --set KEY=VALUE
overrides its keys). One JSON line per pass.

Usage: python benchmarks/step_passes.py OLD_TREE [NEW_TREE] [--case examples/conveyor_fast.yaml [--set shifting=lind]]
           [--ch 1.5] [--shifting none] [--particles 40000] [--threads 2] [--calls 200]
"""
from __future__ import annotations

import argparse
import importlib
import json
import sys
import time
from pathlib import Path

import numba
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))
from pair_loop import import_tree  # noqa: E402
from throughput import layer_scene  # noqa: E402


def simulation(case: str | None, ch: float, shifting: str, particles: int, warmup: int, overrides=()):
    from solver.scene import scene_from_dict
    from solver.simulation import Simulation
    if case:
        from solver.cli import apply_overrides
        from solver.conveyor import build_scene, case_from_dict
        from solver.scene import read_yaml
        scene = build_scene(case_from_dict(apply_overrides(read_yaml(case), list(overrides))))
    else:
        scene = scene_from_dict(layer_scene(ch, shifting, particles))
    sim = Simulation(scene)
    for _ in range(warmup):
        sim.step()
    return sim


def passes(s) -> dict:
    """name -> (call(module package), output arrays to compare): each pass on copies of its
    inputs where it writes them, so that every call sees the same state."""
    g = s.grid
    gravity = s.scene.gravity
    health = [np.zeros(4), np.zeros(4)]
    out = [s.out.copy(), s.out.copy()]
    cell = [np.zeros_like(s.cell), np.zeros_like(s.cell)]
    order = [np.zeros_like(s.order), np.zeros_like(s.order)]
    start = [np.zeros_like(s.start), np.zeros_like(s.start)]
    sorted_cell = s.cell.copy()
    walls = [np.stack([s.u, s.w, s.rho]) for _ in range(2)]  # rows written by the update

    def mdbc(m, k):
        u, w, rho = walls[k]
        u[:], w[:], rho[:] = s.u, s.w, s.rho
        m.boundary.make_mdbc_update(s.scene.physics.mdbc_velocity == "corrected",
                                    bool(s.scene.physics.no_penetration))(
            s.x, s.z, u, w, rho, s.mass, s.kind, s.wall, s.gx, s.gz, s.wall_velocities(s.t), s.cells,
            s.n_active, s.h, s.rho0, s.scene.dp ** 2, s.n_lattice)

    passes = {} if not s.mdbc else {"mdbc_update": (mdbc, walls)}
    sh = s.scene.physics.shifting
    if sh.method == "lind" and sh.near_surface == "tangential":
        from solver.forces import GCX, GCZ
        near = [np.zeros_like(s.near_flag) for _ in range(2)]
        normals = [np.zeros((3, s.n)) for _ in range(2)]  # nx, nz, and the near flags copied

        def surface(m, k):
            m.shifting.surface_normals(s.x, s.z, s.kind, s.surface_flag, s.out[GCX], s.out[GCZ], s.cells,
                                       s.n_active, s.h, near[k], normals[k][0], normals[k][1])
            normals[k][2] = near[k]

        passes["surface_normals"] = (surface, normals)
    return passes | {
        "fluid_health": (lambda m, k: m.guards.fluid_health(
            s.x, s.z, s.u, s.w, s.rho, s.mass, s.kind, s.n_active, s.rho0, s.walls, g.periodic, g.x0,
            g.period, health[k]), health),
        "reduce_accumulators": (lambda m, k: m.forces.reduce_accumulators(
            s.acc, s.kind, s.split, s.cells, gravity[0], gravity[1], out[k], s.n), out),
        "assign_cells": (lambda m, k: m.cells.assign_cells(s.x, s.z, s.kind, s.cells, cell[k]), cell),
        "counting_sort": (lambda m, k: m.cells.counting_sort(sorted_cell, g.ncells + 1, order[k], start[k]),
                          order),
    }


def rel_difference(a, b) -> float:
    """Largest |a - b| over the largest |a| (0 when both are zero); of 2D outputs, the largest
    of their rows' (each row a field: velocities and densities apart)."""
    a, b = np.atleast_2d(np.asarray(a, dtype=float)), np.atleast_2d(np.asarray(b, dtype=float))
    out = 0.0
    for ra, rb in zip(a, b):
        scale = float(np.abs(ra).max())
        out = max(out, float(np.abs(ra - rb).max()) / scale if scale > 0 else float(np.abs(rb).max()))
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("old", type=Path)
    ap.add_argument("new", type=Path, nargs="?", default=ROOT)
    ap.add_argument("--case", default=None)
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    ap.add_argument("--ch", type=float, default=1.5)
    ap.add_argument("--shifting", default="none")
    ap.add_argument("--particles", type=int, default=40000)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--calls", type=int, default=200)
    ap.add_argument("--warmup", type=int, default=5)
    a = ap.parse_args(argv)
    numba.set_num_threads(a.threads)
    names = [import_tree(tree.resolve(), name).__name__ for tree, name in ((a.old, "solver_old"),
                                                                          (a.new, "solver_new"))]
    trees = [type("tree", (), {k: importlib.import_module(f"{pkg}.{k}")
                               for k in ("guards", "forces", "cells", "boundary", "shifting")})
             for pkg in names]
    s = simulation(a.case, a.ch, a.shifting, a.particles, a.warmup, a.set)
    for name, (call, outputs) in passes(s).items():
        for k in (0, 1):
            call(trees[k], k)  # compile
        times = [[], []]
        for c in range(a.calls):
            for k in ((0, 1) if c % 2 == 0 else (1, 0)):
                tic = time.perf_counter()
                call(trees[k], k)
                times[k].append(time.perf_counter() - tic)
        old, new = (1e6 * float(np.median(t)) for t in times)
        print(json.dumps({"pass": name, "case": a.case or f"layer ch {a.ch} {a.shifting}", "particles": s.n,
                          "slots": s.acc.shape[2], "threads": a.threads, "calls": a.calls,
                          "old_us": round(old, 1), "new_us": round(new, 1), "new_over_old": round(new / old, 3),
                          "max_rel_difference": rel_difference(*outputs)}), flush=True)


if __name__ == "__main__":
    main()
