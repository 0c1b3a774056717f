"""What a conveyor run can skip, measured: wall time and the change in every metric.

The paper case (examples/conveyor.yaml) at --dp, one saving switched off at a time from
the defaults (all savings on):
  default     lubrication-shaped start, stop once steady (+ the averaging window), cold start
  fixed_end   run to --fixed-end s whatever the state (steady.stop: false), final window
  block       block start instead of the lubrication shape
  warm        warm start from the final state of the same case at --coarse-dp (the coarse
              run's own wall time is listed apart: it is also the coarse point of a campaign)
Each metric's change against `default` is compared with the two-grid GCI of that metric,
GCI = Fs |phi(dp) - phi(coarse dp)| / (r^p - 1) with Fs = 3, r = coarse/fine, p = 1
(Roache's two-grid form with an assumed first order): a saving is kept when every change
stays within it.
Physics compiled out: particle-steps/s of the throughput layer (benchmarks/throughput.py)
with density diffusion compiled out (delta = 0) against compiled in with delta = 0, and
without shifting against the shifting sums compiled in but unused.

Usage: python benchmarks/savings.py [--dp 0.001] [--coarse-dp 0.002] [--shifting skillen]
           [--threads 2] [--fixed-end 8] [--max-time 12] [--coarse-max-time 6]
           [--out results/savings] [--only coarse default fixed_end block warm compiled]
Runs already in --out are reused (delete them to rerun). Prints a Markdown table.
"""
from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import xarray as xr

ROOT = Path(__file__).resolve().parents[1]
METRICS = ("zeta_f", "zeta_h", "zeta_fs", "zeta_u_0.76", "zeta_u_1.5", "zeta_u_9.7")


def run_case(out: Path, name: str, sets: list[str], threads: int) -> Path:
    path = out / f"{name}.nc"
    if not path.exists():
        cmd = [sys.executable, "-m", "solver", "front", str(ROOT / "examples" / "conveyor.yaml"),
               "-o", str(path), "--threads", str(threads), "--quiet", "--no-checkpoint",
               "--allow-diverged"] + [a for s in sets for a in ("--set", s)]
        print(f"# {name}: {' '.join(cmd[2:])}", file=sys.stderr, flush=True)
        subprocess.run(cmd, check=True, cwd=ROOT)
    return path


def metrics_of(path: Path) -> dict:
    from study.cli import _cfg, _reference
    from study.metrics import case_metrics
    cfg = _cfg(ROOT / "config" / "config.yaml")
    ref, measured = _reference(cfg)
    with xr.open_dataset(path) as run:
        run = run.load()
    m = case_metrics(run, ref, tuple(cfg["metrics"]["free_surface_x_star"]), measured)
    out = {k: float(m[k]) for k in ("zeta_f", "zeta_h", "zeta_fs")}
    for s, v in zip(m["station"].values, m["zeta_u"].values):
        out[f"zeta_u_{s:g}"] = float(v)
    out.update(wall=float(run.attrs["wall_time_s"]), simulated=float(run.attrs["simulated_time_s"]),
               steady_at=float(run.attrs["steady_state_time_s"]), status=run.attrs["status"],
               steady=int(run.attrs["steady"]))
    return out


def compiled_out(threads: int, steps: int = 150) -> list[dict]:
    """Throughput with physics compiled out against compiled in but switched off."""
    import numba
    sys.path.insert(0, str(ROOT / "benchmarks"))
    from throughput import layer_scene

    from solver import forces
    from solver.scene import scene_from_dict
    from solver.simulation import Simulation
    numba.set_num_threads(threads)

    def rate(shifting, delta, force_diffusion=False, force_shift_sums=False):
        d = layer_scene(1.5, shifting, 40000)
        d["physics"]["density_diffusion"] = delta
        sim = Simulation(scene_from_dict(d))
        if force_diffusion or force_shift_sums:
            sim.diffusion = sim.diffusion or force_diffusion
            if force_shift_sums:
                sim.nq = forces.NQ_SHIFT
                sim.acc = np.zeros((sim.nthreads, sim.n, sim.nq))
                sim.out = np.zeros((sim.nq, sim.n))
            sim.pair_loop = forces.make_pair_loop(sim.diffusion, force_shift_sums or shifting != "none", False)
        for _ in range(5):
            sim.step()
        tic = time.perf_counter()
        for _ in range(steps):
            sim.step()
        return sim.n * steps / (time.perf_counter() - tic)

    rows = []
    a, b = rate("none", None), rate("none", None, force_diffusion=True)
    rows.append({"physics": "density diffusion (delta = 0)", "compiled_out": a, "compiled_in": b})
    a, b = rate("none", 0.1), rate("none", 0.1, force_shift_sums=True)
    rows.append({"physics": "shifting sums (method none)", "compiled_out": a, "compiled_in": b})
    return rows


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--dp", type=float, default=0.001)
    ap.add_argument("--coarse-dp", type=float, default=0.002)
    ap.add_argument("--shifting", default="skillen")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--fixed-end", type=float, default=8.0)
    ap.add_argument("--max-time", type=float, default=12.0)
    ap.add_argument("--coarse-max-time", type=float, default=6.0,
                    help="the coarse run's max_time (the default campaign's)")
    ap.add_argument("--out", default=str(ROOT / "results" / "savings"))
    ap.add_argument("--only", nargs="*", default=None)
    a = ap.parse_args(argv)
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    base = [f"shifting={a.shifting}", f"steady.max_time={a.max_time:g}"]
    fine, coarse = f"dp={a.dp:g}", f"dp={a.coarse_dp:g}"
    tag = f"{a.shifting}_dp{a.dp * 1000:g}mm"
    ctag = f"{a.shifting}_dp{a.coarse_dp * 1000:g}mm"
    plan = {
        "coarse": (f"coarse_{ctag}", [coarse] + base[:1] + [f"steady.max_time={a.coarse_max_time:g}"]),
        "default": (f"default_{tag}", [fine] + base),
        "fixed_end": (f"fixed_end_{tag}",
                      [fine] + base[:1] + [f"steady.max_time={a.fixed_end:g}", "steady.stop=false"]),
        "block": (f"block_{tag}", [fine] + base + ["start=block"]),
        "warm": (f"warm_{tag}", [fine] + base + ["start=warm", f"warm_from={out / ('coarse_' + ctag + '.nc')}"]),
    }
    results = {}
    for key, (name, sets) in plan.items():
        if a.only and key not in a.only and not (key == "coarse" and "warm" in a.only):
            continue
        results[key] = metrics_of(run_case(out, name, sets, a.threads))
    (out / f"savings_{tag}.json").write_text(json.dumps(results, indent=1))

    ref, crs = results.get("default"), results.get("coarse")
    r = a.coarse_dp / a.dp
    gci = {k: 3.0 * abs(ref[k] - crs[k]) / (r - 1.0) for k in METRICS} if ref and crs else {}
    head = "| variant | status | steady at [s] | simulated [s] | wall [s] | " + " | ".join(METRICS) + " | within GCI |"
    print(head)
    print("|" + "---|" * (head.count("|") - 1))
    for key, m in results.items():
        cells = []
        ok = True
        for k in METRICS:
            cell = f"{m[k]:.4f}"
            if ref and key not in ("default", "coarse") and gci:
                d = m[k] - ref[k]
                ok &= bool(abs(d) <= gci[k])
                cell += f" ({d:+.4f})"
            cells.append(cell)
        verdict = "-" if key in ("default", "coarse") or not gci else ("yes" if ok else "no")
        print(f"| {key} | {m['status']} | {m['steady_at']:.2f} | {m['simulated']:.2f} | {m['wall']:.0f} | "
              + " | ".join(cells) + f" | {verdict} |")
    if gci:
        print("| two-grid GCI | | | | | " + " | ".join(f"{gci[k]:.4f}" for k in METRICS) + " | |")
    if not a.only or "compiled" in a.only:
        print("\n| physics | compiled out [M particle-steps/s] | compiled in, off [M particle-steps/s] | saving |")
        print("|---|---|---|---|")
        for row in compiled_out(a.threads):
            print(f"| {row['physics']} | {row['compiled_out'] / 1e6:.2f} | {row['compiled_in'] / 1e6:.2f} | "
                  f"{100 * (1 - row['compiled_in'] / row['compiled_out']):.0f} % |")


if __name__ == "__main__":
    main()
