"""Where a conveyor run's time goes: cProfile of a conveyor case, one row per function.

Runs a conveyor case file (--case, default examples/conveyor.yaml, the paper case; with
--set overrides) for --time seconds of simulated time on --threads threads after a short
compile run, profiles the front run (the scene's build, probes, monitors, guards and Python
glue included; the start's periodic film is run before, unprofiled, so that the calls a step
are the run's own) and prints a Markdown table of the functions with the most own time per
step. Then, from a second run without the profiler, the particle-steps/s of its time
stepping (the run's own loop: probes, monitors, guards included, the start-up not) beside
the throughput layer's (benchmarks/throughput.py) at the same particle count, Ch and
method, once with the layer's SPEC scheme and once with the case's (its physics, C_CFL and
sound speed c0, so that the step and the RKC stage count match), and the start-up's wall
time (the scene and the start's periodic film) apart.

Usage: python benchmarks/profile_case.py [--case FILE] [--time 0.4] [--threads 2] [--set shifting=skillen]
           [--rows 14] [--steps-layer 400]
"""
from __future__ import annotations

import argparse
import cProfile
import pstats
import sys
import time
from pathlib import Path

import numba

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--case", type=Path, default=ROOT / "examples" / "conveyor.yaml")
    ap.add_argument("--time", type=float, default=0.4)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--set", action="append", default=[])
    ap.add_argument("--rows", type=int, default=14)
    ap.add_argument("--steps-layer", type=int, default=400)
    a = ap.parse_args(argv)
    numba.set_num_threads(a.threads)
    from solver.cli import apply_overrides
    from solver.conveyor import case_from_dict
    from solver import front
    from solver.front import run_front
    from solver.scene import read_yaml
    from throughput import measure

    d = apply_overrides(read_yaml(a.case), a.set)
    d.setdefault("steady", {})["max_time"] = 0.02
    run_front(case_from_dict(d))  # compile
    d["steady"]["max_time"] = a.time
    case = case_from_dict(d)
    start = front.start_flux_ratio(case, None)  # the start's film, outside the profile
    measure_start = front.start_flux_ratio
    front.start_flux_ratio = lambda *args, **kwargs: start
    prof = cProfile.Profile()
    tic = time.perf_counter()
    prof.enable()
    ds = run_front(case)
    prof.disable()
    wall = time.perf_counter() - tic
    front.start_flux_ratio = measure_start
    steps = int(ds.attrs["steps"])
    n = int(ds.attrs["n_fluid"]) + int(ds.attrs["n_boundary"])
    st = pstats.Stats(prof)
    rows = sorted(((v[2], v[0], k) for k, v in st.stats.items()), reverse=True)[:a.rows]
    total = sum(v[2] for v in st.stats.values())
    print(f"case {case.name}, shifting {case.shifting}, Ch {case.ch}, dp {case.dp:g} m, "
          f"{n} particles, {steps} steps, {a.threads} threads: {wall:.1f} s wall "
          f"({1e3 * wall / steps:.2f} ms/step, profiled)\n")
    print("| function | calls/step | ms/step | share |")
    print("|---|---|---|---|")
    for own, calls, (path, line, name) in rows:
        where = f"{Path(path).parent.name}/{Path(path).name}:{name}" if line else name
        print(f"| `{where}` | {calls / steps:.2f} | {1e3 * own / steps:.3f} | {100 * own / total:.1f} % |")
    tic = time.perf_counter()
    ds = run_front(case)  # unprofiled
    total = time.perf_counter() - tic
    stepping = float(ds.attrs["wall_time_s"])
    rate = n * int(ds.attrs["steps"]) / stepping
    stages = float(ds.attrs.get("rkc_stages", 0)) / int(ds.attrs["steps"])
    print(f"\nconveyor run (not profiled): {rate / 1e6:.2f} M particle-steps/s over its {stepping:.1f} s "
          f"of time stepping ({stages:.2f} RKC stages a step), start-up {total - stepping:.1f} s apart")
    layer = measure(case.ch, a.threads, case.shifting, a.steps_layer, n)
    print(f"throughput layer at {layer['particles']} particles, same Ch and method, SPEC's scheme: "
          f"{layer['particle_steps_per_s'] / 1e6:.2f} M; ratio {rate / layer['particle_steps_per_s']:.2f}")
    layer = measure(case.ch, a.threads, case.shifting, a.steps_layer, n, case_scheme(case))
    print(f"throughput layer with the case's scheme (physics, C_CFL, c0; "
          f"{layer['rkc_stages_per_step']:.2f} RKC stages a step): "
          f"{layer['particle_steps_per_s'] / 1e6:.2f} M; ratio {rate / layer['particle_steps_per_s']:.2f}")


def case_scheme(case) -> dict:
    """The scene keys of a conveyor case's scheme, for the throughput layer: its physics, the
    acoustic C_CFL it runs at (after ``cfl_rule``) and its sound speed c0 (so that the layer's
    step and RKC stage count match)."""
    from solver.conveyor import build_scene_dict
    from solver.scene import scene_from_dict
    d = build_scene_dict(case)
    scene = scene_from_dict(d)
    return {"physics": d["physics"], "cfl": scene.cfl_acoustic, "cfl_viscous": d["cfl_viscous"],
            "sound": {"c0": scene.c0}}


if __name__ == "__main__":
    main()
