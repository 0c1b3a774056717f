"""Particle-steps per second of the solver on a viscous layer over a no-slip bed.

Layer: rho 1383, mu 5.6, slope 15.3 deg, periodic in x, ~40k particles (fluid + bed),
mDBC and density diffusion on. One JSON object per configuration on stdout:
  {"ch", "threads", "particles", "shifting", "steps", "wall_s", "particle_steps_per_s",
   "ns_per_particle_step", "bytes_per_particle", ...}
particle_steps_per_s = (all particles, fluid and boundary) x steps / wall seconds;
bytes_per_particle = the solver's numpy arrays (state, sort buffers, per-thread
accumulators, work arrays) over the particle count.

Usage: python benchmarks/throughput.py [--steps 200] [--ch 1.5 1.8] [--threads 1 2]
                                       [--shifting none lind skillen] [--particles 40000 ...]
                                       [--jitter 0.05]
--jitter DP moves the fluid particles by up to DP dp first: the layer from rest stays a lattice
(skillen's shifts there are 1e-13 m), whose exact rows make the pair loop's branches predictable,
which no flow's arrangement is; lind's shifts (median 5e-18 m) already reorder the rows.
"""
from __future__ import annotations

import argparse
import json
import math
import time

import numba
import numpy as np
import yaml

from solver.scene import scene_from_dict
from solver.simulation import Simulation


def layer_scene(ch: float, shifting: str, particles: int, dp: float = 1.0e-3) -> dict:
    """A periodic viscous layer whose fluid + bed particle count is close to ``particles``."""
    depth_n = 100
    bed_n = int(math.ceil(2 * ch))
    length_n = int(round(particles / (depth_n + bed_n)))
    L, H, T = length_n * dp, depth_n * dp, bed_n * dp
    theta = math.radians(15.3)
    return {
        "name": f"layer-ch{ch}-{shifting}",
        "dp": dp, "ch": ch,
        "fluid": {"density": 1383.0, "viscosity": 5.6,
                  "blocks": [{"x": [0.0, L], "z": [0.0, H]}]},
        "walls": [{"name": "bed", "x": [0.0, L], "z": [-T, 0.0]}],
        "gravity": [9.81 * math.sin(theta), -9.81 * math.cos(theta)],
        "sound": {"coefsound": 10.0, "depth": H},
        "cfl": 0.2,
        "periodic_x": [0.0, L],
        "physics": {"boundary": "mdbc", "density_diffusion": 0.1,
                    "shifting": {"method": shifting}},
        "time": {"end": 1.0, "output_interval": 1.0},
    }


def set_physics(scene: dict, items) -> dict:
    """Apply KEY=VALUE overrides below the scene's ``physics`` (KEY dotted, VALUE in YAML)."""
    for item in items:
        key, value = item.split("=", 1)
        *path, last = key.split(".")
        node = scene.setdefault("physics", {})
        for k in path:
            node = node.setdefault(k, {})
        node[last] = yaml.safe_load(value)
    return scene


def array_bytes(sim: Simulation) -> int:
    """Bytes held in the simulation's numpy arrays (sort buffers included)."""
    seen, total = set(), 0
    arrays = [v for v in vars(sim).values() if isinstance(v, np.ndarray)]
    arrays += list(sim._buf.values())
    for a in arrays:
        if id(a) not in seen:
            seen.add(id(a))
            total += a.nbytes
    return total


def jitter(sim: Simulation, amplitude: float, seed: int = 1) -> None:
    """Move every fluid particle by uniform offsets of up to ``amplitude`` dp in x and in z: an
    arrangement as disordered as a flow's. On the lattice the rows are exact and the pair
    loop's 2h test repeats from particle to particle, which a branch predictor learns; in a
    flow it does not (benchmarks/pair_loop.py). The next step sorts the particles again."""
    rng = np.random.default_rng(seed)
    fluid = sim.kind == 0
    for arr in (sim.x, sim.z):
        arr[fluid] += rng.uniform(-1.0, 1.0, int(fluid.sum())) * amplitude * sim.scene.dp


def measure(ch: float, threads: int, shifting: str, steps: int, particles: int,
            scheme: dict | None = None, jitter_dp: float = 0.0) -> dict:
    """Time ``steps`` steps of the layer. ``scheme``: scene keys (``physics``, ``cfl``,
    ``cfl_viscous``, ``sound``) that replace the layer's, to time another case's scheme;
    ``jitter_dp`` > 0: the fluid particles first moved by up to that many dp (``jitter``)."""
    numba.set_num_threads(threads)
    sim = Simulation(scene_from_dict({**layer_scene(ch, shifting, particles), **(scheme or {})}))
    if jitter_dp > 0:
        jitter(sim, jitter_dp)
    for _ in range(5):  # warm-up (compilation is cached after the first configuration)
        sim.step()
    tic = time.perf_counter()
    for _ in range(steps):
        reason = sim.step()
        if reason:
            raise RuntimeError(reason)
    wall = time.perf_counter() - tic
    return {"ch": ch, "threads": threads, "particles": sim.n, "fluid": sim.n_fluid,
            "shifting": shifting, "jitter_dp": jitter_dp, "steps": steps, "wall_s": round(wall, 4),
            "particle_steps_per_s": round(sim.n * steps / wall),
            "ns_per_particle_step": round(1e9 * wall / (sim.n * steps), 1),
            "steps_per_s": round(steps / wall, 1),
            # an older tree (benchmarks/paired.py) has no stage counter
            "rkc_stages_per_step": round(getattr(sim, "rkc_stages", 0) / (steps + 5), 2),
            "bytes_per_particle": round(array_bytes(sim) / sim.n)}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--steps", type=int, default=200)
    ap.add_argument("--ch", type=float, nargs="+", default=[1.5, 1.8])
    ap.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--shifting", nargs="+", default=["none", "lind", "skillen"])
    ap.add_argument("--particles", type=int, nargs="+", default=[40000])
    ap.add_argument("--jitter", type=float, default=0.0, metavar="DP",
                    help="fluid particles first moved by up to DP dp (0: the lattice)")
    a = ap.parse_args(argv)
    for particles in a.particles:
        for ch in a.ch:
            for shifting in a.shifting:
                for threads in a.threads:
                    print(json.dumps(measure(ch, threads, shifting, a.steps, particles, jitter_dp=a.jitter)),
                          flush=True)


if __name__ == "__main__":
    main()
