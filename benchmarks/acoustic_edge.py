"""The acoustic edge of C_CFL: the model (solver/acoustic_edge.py) against runs.

Each line of --runs (default benchmarks/acoustic_edge_runs.txt) is a run's name and its
overrides of --case (``dp2-ch2.5-c0.62 dp=0.002 ch=2.5 numerics.cfl=0.62``); a line named ``*`` holds
overrides of every run, applied before the run's own, and --set some more. Each run goes to
--to s with ``steady.stop=false`` (``python -m solver front``, one thread, --jobs at a time),
and the table gives nu / (c0 h), the acoustic C the run used, the model's edge
C*(Ch, nu / (c0 h), delta), their ratio, and whether the run held to --to or where a guard
stopped it. --predict gives the model alone, without running.

    python -m benchmarks.acoustic_edge [--predict] [--only NAME ...] [--to 6] [--jobs 2]
        [--runs benchmarks/acoustic_edge_runs.txt] [--case examples/conveyor_fast.yaml] [--set KEY=VALUE ...]
"""
from __future__ import annotations

import copy
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

from benchmarks import common

QUICK = {"only": ["dp2.25-ch1.8-c0.60", "dp2.25-ch1.8-c0.55", "rule-dp3-ch2.2"], "to": 0.2}


def read_runs(path: Path) -> list[tuple[str, list[str]]]:
    """(name, overrides) of every run, the ``*`` line's overrides first."""
    every, runs = [], []
    for line in path.read_text().splitlines():
        line = line.split("#")[0].strip()
        if line:
            name, *sets = line.split()
            if name == "*":
                every += sets
            else:
                runs.append((name, sets))
    return [(name, every + sets) for name, sets in runs]


def predict(scene) -> tuple[float, float, float, float]:
    """(nu / (c0 h), delta, the acoustic C the scene takes, the model's C*)."""
    from solver import acoustic_edge
    numerics = getattr(scene, "numerics", None) or scene.physics
    r, delta = scene.acoustic_damping_ratio, numerics.density_diffusion or 0.0
    return r, delta, scene.cfl_acoustic, acoustic_edge.edge(scene.ch, r, delta)


def run(case: Path, out: Path, name: str, sets: list[str], to: float) -> Path | str:
    """Run one case: its NetCDF, or why the solver refused it."""
    try:
        return common.front(case, ["steady.stop=false", f"steady.max_time={to:g}", *sets], out / f"{name}.nc", 1)
    except Exception as exc:  # a case the solver refuses: the row says so
        return f"failed: {exc}"


def outcome(result: Path | str) -> str:
    """A run's status as one line (read in one thread: the NetCDF library is not thread-safe)."""
    import xarray as xr
    if isinstance(result, str):
        return result
    with xr.open_dataset(result) as ds:
        status, t = ds.attrs["status"], float(ds.attrs["simulated_time_s"])
    return f"guard at {t:.2f} s" if status == "diverged" else f"held to {t:.2f} s"


def main(argv=None) -> int:
    ap = common.parser(__doc__, case="examples/conveyor_fast.yaml", threads=None, out="acoustic_edge")
    ap.add_argument("--runs", type=Path, default=common.ROOT / "benchmarks" / "acoustic_edge_runs.txt")
    ap.add_argument("--only", nargs="+", default=None, metavar="NAME", help="only these runs of the file")
    ap.add_argument("--to", type=float, default=6.0, help="simulated seconds of each run")
    ap.add_argument("--jobs", type=int, default=2, help="runs at a time (one thread each)")
    ap.add_argument("--predict", action="store_true", help="the model only, no runs")
    a = common.parse(ap, argv, QUICK)
    runs = [(n, s + a.sets) for n, s in read_runs(a.runs) if not a.only or n in a.only]
    base = common.read_yaml(a.case)
    rows = []
    for name, sets in runs:
        rows.append((name, common.build_scene(common.override(copy.deepcopy(base), sets))))
    outcomes = [""] * len(runs)
    if not a.predict:
        with ThreadPoolExecutor(a.jobs) as pool:
            results = list(pool.map(lambda r: run(a.case, a.out, r[0], r[1], a.to), runs))
        outcomes = [outcome(r) for r in results]
    table, ratios = [], []
    for (name, scene), result in zip(rows, outcomes):
        r, delta, c, c_star = predict(scene)
        ratios.append((c / c_star, result))
        table.append([name, f"{scene.dp * 1e3:g}", f"{scene.ch:g}", f"{delta:g}", f"{r:.3f}", f"{c:.3f}",
                      f"{c_star:.3f}", f"{c / c_star:.2f}", result or "-"])
    print(f"{a.case.name}{''.join(' ' + s for s in a.sets)}" + ("" if a.predict else f", runs to {a.to:g} s"))
    print(common.table(["run", "dp [mm]", "Ch", "delta", "nu / (c0 h)", "C used", "C*", "C / C*", "outcome"], table))
    if a.predict:
        common.summary(f"{len(rows)} cases predicted, C / C* from {min(x for x, _ in ratios):.2f} "
                       f"to {max(x for x, _ in ratios):.2f}")
    else:
        held = [x for x, res in ratios if res.startswith("held")]
        stopped = [x for x, res in ratios if res.startswith("guard")]
        common.summary(f"{len(held)} of {len(rows)} runs held to {a.to:g} s"
                       + (f" (C / C* up to {max(held):.2f})" if held else "")
                       + (f"; {len(stopped)} stopped by a guard (C / C* from {min(stopped):.2f})" if stopped else ""))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
