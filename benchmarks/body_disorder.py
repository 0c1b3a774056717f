"""Where a conveyor body's particle disorder comes from, and what it does to the body's depth.

Three commands:

  film CASE T AMP [KEY=VALUE ...]
      The start's periodic film (solver/film_depth.py) run for T s, its fluid particles first
      moved by uniform offsets of up to AMP dp (0: the lattice): every 0.5 s its volume flux
      over the exact film's, r = q_SPH / q, and the disorder of its core (``probes.disorder``
      h |sum V gradW|, particles more than 2h from the bed and the surface).
  run CASE AMP OUT [KEY=VALUE ...]
      The conveyor case from a start whose fluid particles are moved by up to AMP dp, beyond the
      ``start_perturbation`` key's cap of 0.01 (an experiment; one thread).
  table RUN.nc [RUN.nc ...]
      Per simulated second of finished runs: the uniform depth over h_n, the toe, the toe's and
      the equivalent front's velocities (least-squares slopes over the second, % u_b) and the
      core's disorder.

Usage: python benchmarks/body_disorder.py film examples/conveyor_fast.yaml 4 0.2 shifting=lind
       python benchmarks/body_disorder.py run examples/conveyor_fast.yaml 0.1 out.nc
           shifting=lind steady.stop=false steady.max_time=8   (one line)
       python benchmarks/body_disorder.py table out.nc
"""
from __future__ import annotations

import dataclasses
import sys
from pathlib import Path

import numba
import numpy as np
import yaml

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from solver.cli import apply_overrides  # noqa: E402
from solver.conveyor import case_from_dict, start_offsets  # noqa: E402


def load_case(path, overrides):
    return case_from_dict(apply_overrides(yaml.safe_load(Path(path).read_text()), overrides))


def film(path, t_end, amp, overrides):
    from solver.build import build_particles
    from solver.film_depth import exact_flux, film_scene_dict
    from solver.probes import FieldSampler
    from solver.scene import scene_from_dict
    from solver.simulation import Simulation
    case = load_case(path, overrides)
    d = film_scene_dict(case)
    d["time"] = {"end": t_end, "output_interval": t_end}
    scene = scene_from_dict(d)
    parts = build_particles(scene)
    f = parts.kind == 0
    if amp > 0:
        dx, dz = start_offsets(int(f.sum()), amp * case.dp, 7)
        parts.x[f] += dx
        parts.z[f] += dz
    sim = Simulation(scene, parts)
    length = scene.periodic_x[1] - scene.periodic_x[0]
    block, depth, flux, dis = 0.5, [], [], []
    t_next = block
    print("t [s] | depth / h_n | r = q_SPH / q | core disorder")
    while sim.t < t_end - 1e-12:
        reason = sim.step()
        if reason:
            print("stopped:", reason)
            return
        fl = sim.kind == 0
        vol = sim.mass[fl] / sim.rho[fl]
        depth.append(vol.sum() / length)
        flux.append((vol * sim.u[fl]).sum() / length)
        if sim.steps % 50 == 0:
            n = sim.n_active
            core = np.flatnonzero((sim.kind[:n] == 0) & (sim.z[:n] > 2.0 * sim.h)
                                  & (sim.z[:n] < case.h_n - 2.0 * sim.h))
            dis.append(FieldSampler(sim).disorder(core)[2].mean())
        if sim.t >= t_next:
            h = float(np.mean(depth))
            print(f"{sim.t:5.2f} | {h / case.h_n:.5f} | {np.mean(flux) / exact_flux(case, h):.5f} | "
                  f"{np.mean(dis):.4f}", flush=True)
            depth, flux, dis = [], [], []
            t_next += block


def run(path, amp, out, overrides):
    from solver.front import run_front
    from solver.output import write_atomic
    case = dataclasses.replace(load_case(path, overrides), start_perturbation=amp, perturbation_seed=11)
    ds = run_front(case, quiet=True)
    write_atomic(ds, out)
    print(out, ds.attrs["status"], f"{ds.attrs['simulated_time_s']:.2f} s simulated",
          f"{ds.attrs['wall_time_s']:.0f} s wall")


def table(paths):
    import xarray as xr
    for path in paths:
        with xr.open_dataset(path) as ds:
            ub, hn = ds.attrs["belt_speed_m_s"], ds.attrs["h_n_m"]
            t, toe, eq = ds.time.values, ds.toe_position.values, ds.front_equivalent.values
            depth, dis = ds.uniform_depth.values, ds.disorder.values[:, 2]
            print(f"{path} (steady at {ds.attrs['steady_state_time_s']:.2f} s)")
            print("second | depth / h_n | toe [mm] | toe velocity [% u_b] | equivalent front velocity "
                  "[% u_b] | core disorder")
            for a in range(int(t[-1])):
                s = (t >= a) & (t <= a + 1)
                v_toe = np.polyfit(t[s], toe[s], 1)[0] / ub
                v_eq = np.polyfit(t[s], eq[s], 1)[0] / ub
                print(f"{a}-{a + 1} | {np.nanmean(depth[s]) / hn:.4f} | {1e3 * toe[s].mean():.2f} | "
                      f"{100 * v_toe:+.2f} | {100 * v_eq:+.2f} | {np.nanmean(dis[s]):.4f}")


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    if not argv or argv[0] not in ("film", "run", "table"):
        print(__doc__)
        return 0 if argv and argv[0] in ("-h", "--help") else 2
    numba.set_num_threads(1)
    cmd, rest = argv[0], argv[1:]
    if cmd == "film":
        film(rest[0], float(rest[1]), float(rest[2]), rest[3:])
    elif cmd == "run":
        run(rest[0], float(rest[1]), rest[2], rest[3:])
    else:
        table(rest)
    return 0


if __name__ == "__main__":
    sys.exit(main())
