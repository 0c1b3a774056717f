"""The acoustic edge of C_CFL, predicted (solver/acoustic_edge.py) against runs.

Each line of RUNS (default: benchmarks/acoustic_edge_runs.txt) names a run and its case
overrides, e.g. ``dp2-ch2.5-c0.62 dp=0.002 ch=2.5 cfl=0.62``. Every run starts from CASE
(default: examples/conveyor_fast.yaml, the campaigns' scheme) with ``cfl_rule=fixed`` unless
the line sets it, ``steady.stop=false`` and
``steady.max_time=TO``, on one thread, JOBS at a time (``python -m solver front``), and the table
gives nu / (c0 h), the acoustic C the run used, the model's edge C* (Ch, nu / (c0 h), delta), their
ratio, and whether the run held to TO or where a guard stopped it. ``--predict`` prints the model
alone, without running; ``--leapfrog`` adds the edge of the leapfrog density update
(``acoustic_edge.leapfrog_amplification``) under the same symbols.

Usage: python benchmarks/acoustic_edge.py [--runs FILE] [--case CASE] [--to 6] [--jobs 2]
       [--out DIR] [--predict] [--leapfrog]
"""
from __future__ import annotations

import argparse
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from solver import acoustic_edge, conveyor  # noqa: E402
from solver.cli import apply_overrides  # noqa: E402


def read_runs(path: Path) -> list[tuple[str, list[str]]]:
    runs = []
    for line in path.read_text().splitlines():
        line = line.split("#")[0].strip()
        if line:
            name, *sets = line.split()
            runs.append((name, ["cfl_rule=fixed", *sets]))  # a line's own cfl_rule comes later and wins
    return runs


def scene_of(case_file: Path, sets: list[str]):
    with open(case_file) as fh:
        data = yaml.safe_load(fh)
    return conveyor.build_scene(conveyor.case_from_dict(apply_overrides(data, sets)))


def run_one(case_file: Path, out: Path, name: str, sets: list[str], to: float) -> str:
    """Run one case; its NetCDF's status and reason as one line."""
    nc = out / f"{name}.nc"
    args = [sys.executable, "-m", "solver", "front", str(case_file), "-o", str(nc), "--threads", "1",
            "--allow-diverged", "--quiet", "--no-checkpoint", "--set", "steady.stop=false",
            "--set", f"steady.max_time={to}"]
    for s in sets:
        args += ["--set", s]
    proc = subprocess.run(args, cwd=ROOT, capture_output=True, text=True)
    if proc.returncode != 0:
        return f"failed: {proc.stderr.strip().splitlines()[-1] if proc.stderr.strip() else proc.returncode}"
    import xarray as xr
    with xr.open_dataset(nc) as ds:
        status, t = ds.attrs["status"], float(ds.attrs["simulated_time_s"])
    return f"guard at {t:.2f} s" if status == "diverged" else f"held to {t:.2f} s"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--runs", type=Path, default=ROOT / "benchmarks" / "acoustic_edge_runs.txt")
    ap.add_argument("--case", type=Path, default=ROOT / "examples" / "conveyor_fast.yaml")
    ap.add_argument("--to", type=float, default=6.0)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--out", type=Path, default=ROOT / "results" / "acoustic_edge")
    ap.add_argument("--predict", action="store_true", help="the model only, no runs")
    ap.add_argument("--leapfrog", action="store_true",
                    help="add the leapfrog update's edge (density_update: leapfrog) as a column")
    args = ap.parse_args(argv)
    runs = read_runs(args.runs)
    rows = []
    for name, sets in runs:
        sc = scene_of(args.case, sets)
        r, delta = sc.acoustic_damping_ratio, sc.physics.density_diffusion or 0.0
        c_star = acoustic_edge.edge(sc.ch, r, delta)
        rows.append((name, sc, r, delta, c_star))
    outcomes = [""] * len(runs)
    if not args.predict:
        args.out.mkdir(parents=True, exist_ok=True)
        with ThreadPoolExecutor(args.jobs) as pool:
            outcomes = list(pool.map(lambda nr: run_one(args.case, args.out, nr[0], nr[1], args.to), runs))
    lf_head = " leapfrog's C* |" if args.leapfrog else ""
    print(f"| run | dp [mm] | Ch | delta | nu / (c0 h) | C used | C* | C / C* |{lf_head} outcome |")
    print("|---|---|---|---|---|---|---|---|" + ("---|" if args.leapfrog else "") + "---|")
    for (name, sc, r, delta, c_star), outcome in zip(rows, outcomes):
        c = sc.cfl_acoustic
        lf = (f" {acoustic_edge.edge(sc.ch, r, delta, acoustic_edge.leapfrog_amplification):.3f} |"
              if args.leapfrog else "")
        print(f"| {name} | {sc.dp * 1e3:g} | {sc.ch:g} | {delta:g} | {r:.3f} | {c:.3f} | {c_star:.3f} | "
              f"{c / c_star:.2f} |{lf} {outcome} |")


if __name__ == "__main__":
    main()
