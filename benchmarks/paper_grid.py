"""Projected wall time of config/paper.yaml on this machine, from measured short runs.

Measures, on --threads threads, a short run of every case of the paper grid (--time s of
simulated time at dp = 1 and 0.5 mm, --fine-time s at 0.25 mm, after a compile run): the
paper case (examples/conveyor.yaml with the paper grid's settings) at each (dp, Ch, method)
of config/paper.yaml. Each gives particles N, steps, mean dt, the viscous update the run took
(``viscous_update: auto`` picks one per case), particle-steps/s of the time stepping (the
run's own wall time) and the start-up (the rest: building the scene and the start's periodic
film). A case then costs

  wall = start-up + T_sim / dt * N / rate

with T_sim the simulated time a case needs: its steady time plus averaging window (--t-sim:
METHOD=T for every dp, METHOD@DP_MM=T for one dp; measured with
benchmarks/time_to_solution.py or a front run) and, as the upper bound, the grid's max_time.
With --coarse-only, only dp = 1 mm is measured at every Ch and the finer dp at Ch = 1.8; the
other cases are scaled from those by the ratio of the binding limit min(C h / c0, C_nu h^2 / nu)
(h / c0 alone with the implicit update) and the Ch ratio of the rate at dp = 1 mm.

With --set KEY=VALUE (case keys, e.g. viscous_update=auto cfl=0.4) every run takes those
settings.

The default T_sim is 4.0 s for every case: with steady.min_time 2 s no case can end sooner
(first span [2, 3] s, window [3, 4] s); at dp = 1 mm, Ch = 1.8 both methods ended at 4.0 s
(default campaign, 2026-12-02, sixth session), and so did Skillen at dp = 0.5 mm, Ch = 1.8
(seventh session). dp = 0.25 mm and the other Ch below 1 mm are not measured with it.

Usage: python benchmarks/paper_grid.py [--threads 2] [--time 0.05] [--fine-time 0.02]
           [--t-sim skillen=4.0 lind=4.0 skillen@0.5=4.2] [--set KEY=VALUE ...]
           [--shifting skillen lind]
           [--coarse-only] [--out results/paper_grid] [--reuse]
Prints the measured runs and the projection as Markdown.
"""
from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numba
import yaml

ROOT = Path(__file__).resolve().parents[1]


def measure(dp: float, ch: float, method: str, sim_time: float, settings: dict | None = None) -> dict:
    from solver.conveyor import case_from_dict
    from solver.front import run_front
    from solver.scene import read_yaml
    paper = yaml.safe_load((ROOT / "config" / "paper.yaml").read_text())["case"]
    d = read_yaml(ROOT / "examples" / "conveyor.yaml")
    d.update({k: v for k, v in paper.items() if k not in ("probes", "steady")})
    d.update(settings or {})
    d.update(dp=dp, ch=ch, shifting=method, name=f"dp{dp * 1e3:g}mm_ch{ch:g}_{method}")
    d["steady"].update(max_time=sim_time)
    tic = time.perf_counter()
    ds = run_front(case_from_dict(d))
    wall = time.perf_counter() - tic
    stepping = float(ds.attrs["wall_time_s"])  # the run's own loop, without the start-up
    steps = int(ds.attrs["steps"])
    n = int(ds.attrs["n_fluid"]) + int(ds.attrs["n_boundary"])
    return {"dp": dp, "ch": ch, "shifting": method, "particles": n, "steps": steps,
            "simulated": float(ds.attrs["simulated_time_s"]), "wall": wall,
            "startup": wall - stepping, "dt": float(ds.attrs["simulated_time_s"]) / steps,
            "rate": n * steps / stepping, "c0": float(ds.attrs["c0"]),
            "update": ds.attrs.get("viscous_update", "explicit"),
            "cg_per_step": int(ds.attrs.get("cg_iterations", 0)) / max(steps, 1),
            "rkc_per_step": int(ds.attrs.get("rkc_stages", 0)) / max(steps, 1)}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--time", type=float, default=0.05)
    ap.add_argument("--fine-time", type=float, default=0.02, help="simulated time at 0.25 mm")
    ap.add_argument("--t-sim", nargs="+", default=["skillen=4.0", "lind=4.0"])
    ap.add_argument("--out", default=str(ROOT / "results" / "paper_grid"))
    ap.add_argument("--reuse", action="store_true", help="project from OUT/runs.json, measure nothing")
    ap.add_argument("--set", nargs="*", default=[], metavar="KEY=VALUE", help="case settings of every run")
    ap.add_argument("--coarse-only", action="store_true",
                    help="measure every Ch at dp = 1 mm only, and scale the finer dp from Ch = 1.8")
    ap.add_argument("--shifting", nargs="+", default=["skillen", "lind"],
                    help="methods to measure and project (the grid's cases of the others are left out)")
    a = ap.parse_args(argv)
    settings = {k: yaml.safe_load(v) for k, v in (kv.split("=", 1) for kv in a.set)}
    numba.set_num_threads(a.threads)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    grid = yaml.safe_load((ROOT / "config" / "paper.yaml").read_text())
    chs = grid["grid"]["ch"]
    paper_ch = grid["grid"].get("paper_ch", 1.8)
    max_time = grid["case"]["steady"]["max_time"]
    t_sim = {k: float(v) for k, v in (s.split("=") for s in a.t_sim)}  # "skillen" or "skillen@0.5"
    # cases of the paper grid: every Ch with skillen, lind at paper_ch
    cases = [(dp, ch, "skillen") for dp in grid["grid"]["dp"] for ch in chs if "skillen" in a.shifting]
    cases += [(dp, paper_ch, "lind") for dp in grid["grid"]["dp"] if "lind" in a.shifting]
    if a.reuse:
        runs = json.loads((out / "runs.json").read_text())
    else:
        for method in a.shifting:  # compile each method's kernels before timing anything
            measure(0.002, 1.8, method, 0.01, settings)
        runs = []
        for method in a.shifting:
            for ch in (chs if method == "skillen" else [paper_ch]):  # the grid runs lind at paper_ch
                runs.append(measure(0.001, ch, method, a.time, settings))
            if a.coarse_only:
                runs.append(measure(0.0005, paper_ch, method, a.time, settings))
                runs.append(measure(0.00025, paper_ch, method, a.fine_time, settings))
        if not a.coarse_only:
            runs += [measure(dp, ch, m, a.fine_time if dp < 0.0004 else a.time, settings)
                     for dp, ch, m in cases if dp != 0.001]
        (out / "runs.json").write_text(json.dumps(runs, indent=1))
    print("| dp [mm] | Ch | shifting | viscous update | particles | simulated [s] | steps | dt [s] | wall [s] | "
          "start-up [s] | M particle-steps/s |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for r in runs:
        print(f"| {r['dp'] * 1e3:g} | {r['ch']:g} | {r['shifting']} | {r.get('update', 'explicit')} | "
              f"{r['particles']} | {r['simulated']:.3f} | {r['steps']} | {r['dt']:.3g} | {r['wall']:.1f} | "
              f"{r['startup']:.1f} | {r['rate'] / 1e6:.2f} |")

    def run_of(dp, ch, m):
        return next((r for r in runs if r["dp"] == dp and r["ch"] == ch and r["shifting"] == m), None)

    nu = grid["case"]["viscosity"] / grid["case"]["density"]
    cfl = float(settings.get("cfl", grid["case"].get("cfl", 0.2)))
    cfl_nu = float(settings.get("cfl_viscous") or cfl)

    def limit(h, c0, implicit):
        """The step the solver takes at smoothing length h: min(C h / c0, C_nu h^2 / nu)."""
        return cfl * h / c0 if implicit else min(cfl * h / c0, cfl_nu * h * h / nu)

    total_meas = total_max = 0.0
    rows = []
    for dp, ch, m in cases:
        own = run_of(dp, ch, m)
        if own is not None:  # measured
            base, dt, rate = own, own["dt"], own["rate"]
        else:
            # scaled from (dp, paper_ch) by the ratio of the binding limit between Ch and
            # paper_ch, and the rate by its Ch ratio at dp = 1 mm
            base = run_of(dp, paper_ch, m)
            c1, p1 = run_of(0.001, ch, m), run_of(0.001, paper_ch, m)
            imp = base.get("update") in ("implicit", "substepped")  # no viscous limit on dt
            dt = base["dt"] * limit(ch * dp, base["c0"], imp) / limit(paper_ch * dp, base["c0"], imp)
            rate = base["rate"] * c1["rate"] / p1["rate"]
        per_second = base["particles"] / (dt * rate)  # wall s per simulated s
        ts = t_sim.get(f"{m}@{dp * 1e3:g}", t_sim[m])
        to_steady = base["startup"] + ts * per_second
        to_max = base["startup"] + max_time * per_second
        rows.append((dp, ch, m, dt, rate, ts, to_steady, to_max))
        total_meas += to_steady
        total_max += to_max
    print("\n| dp [mm] | Ch | shifting | dt [s] | M particle-steps/s | T_sim [s] | to steady + window [h] | "
          f"to max_time {max_time:g} s [h] |")
    print("|---|---|---|---|---|---|---|---|")
    for dp, ch, m, dt, rate, ts, c, cm in rows:
        print(f"| {dp * 1e3:g} | {ch:g} | {m} | {dt:.3g} | {rate / 1e6:.2f} | {ts:g} | {c / 3600:.2f} | "
              f"{cm / 3600:.1f} |")
    print(f"| total | | | | | | {total_meas / 3600:.1f} | {total_max / 3600:.1f} |")


if __name__ == "__main__":
    main()
