"""What the benchmarks share: their options, a wall-clock timer, the host description, the way
to load a case (a YAML file plus ``--set KEY=VALUE`` overrides, as ``python -m solver front``
takes them), front runs and their metrics, and Markdown tables.

Every benchmark prints Markdown and ends with one ``summary:`` line, which
``python -m benchmarks.report`` collects. ``python -m benchmarks.common`` prints the host line.
"""
from __future__ import annotations

import argparse
import datetime
import math
import os
import platform
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).absolute().parents[1]  # not resolved: a linked package (benchmarks.paired) keeps its tree
EXAMPLES = ROOT / "examples"
RESULTS = ROOT / "results" / "benchmarks"

# the metric grids of the default campaign (metrics.free_surface_x_star's default in
# workflow/study/flows/conveyor.schema.yaml)
X_STAR_RANGE = (0.0, 12.0)


# ---- options ------------------------------------------------------------------------------
def parser(doc: str, *, case: str | None = None, sets: bool | None = None, threads: int | list[int] | None = 2,
           rounds: int | None = None, out: str | None = None) -> argparse.ArgumentParser:
    """The options every benchmark spells the same way: ``--quick``, and where it has them
    ``--case`` (default ``case``, relative to the repository root), ``--set KEY=VALUE``
    (repeatable), ``--threads`` (a list when ``threads`` is one), ``--rounds`` and ``--out``
    (a folder under results/benchmarks by default)."""
    ap = argparse.ArgumentParser(description=doc, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quick", action="store_true",
                    help="the smallest mode (seconds to a minute): the smoke tests and the report run it")
    if case is not None:
        ap.add_argument("--case", type=Path, default=ROOT / case,
                        help="a conveyor case file or a scene YAML (default: %(default)s)")
    if sets if sets is not None else case is not None:
        ap.add_argument("--set", dest="sets", action="append", default=[], metavar="KEY=VALUE",
                        help="override a key of the case (dotted for nested keys, VALUE read as YAML), "
                             "as python -m solver front --set does; repeatable")
    if isinstance(threads, list):
        ap.add_argument("--threads", type=int, nargs="+", default=threads, help="numba threads, one run each")
    elif threads is not None:
        ap.add_argument("--threads", type=int, default=threads, help="numba threads (default: %(default)s)")
    if rounds is not None:
        ap.add_argument("--rounds", type=int, default=rounds, help="repeats (default: %(default)s)")
    if out is not None:
        ap.add_argument("--out", type=Path, default=RESULTS / out, help="folder for its runs (default: %(default)s)")
    return ap


def parse(ap: argparse.ArgumentParser, argv=None, quick: dict | None = None) -> argparse.Namespace:
    """Parse the options; with ``--quick``, ``quick`` replaces the defaults (options given on
    the command line still win)."""
    first, _ = ap.parse_known_args(argv)
    if first.quick and quick:
        ap.set_defaults(**quick)
    return ap.parse_args(argv)


# ---- timing and host ----------------------------------------------------------------------
class Timer:
    """Wall-clock seconds of a ``with`` block: ``with Timer() as t: ...`` then ``t.seconds``."""

    def __enter__(self) -> Timer:
        self.start = time.perf_counter()
        self.seconds = math.nan
        return self

    def __exit__(self, *exc) -> None:
        self.seconds = time.perf_counter() - self.start


def cpu_model() -> str:
    try:
        with open("/proc/cpuinfo") as fh:
            for line in fh:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def usable_cores() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:
        return os.cpu_count() or 1


def now() -> str:
    return datetime.datetime.now().astimezone().strftime("%Y-%m-%d %H:%M %Z")


def load() -> str:
    """The host's load average over 1, 5 and 15 minutes (a busy host times everything slower)."""
    try:
        return "load " + " / ".join(f"{v:.1f}" for v in os.getloadavg())
    except OSError:
        return "load unknown"


def host() -> str:
    """CPU model, usable cores, OS, Python and numba versions."""
    try:
        from importlib.metadata import version
        numba = f", numba {version('numba')}"
    except Exception:  # a description, not a requirement
        numba = ""
    return (f"{cpu_model()}, {usable_cores()} cores, {platform.system()} {platform.release()}, "
            f"Python {platform.python_version()}{numba}")


def commit() -> str:
    """The repository's commit, with ``+`` when the tree has uncommitted changes (but for
    RESULTS.md, which the report rewrites)."""
    try:
        rev = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True, text=True,
                             check=True).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no", "--", ".",
                                ":!benchmarks/RESULTS.md"], cwd=ROOT, capture_output=True, text=True).stdout.strip()
        return rev + ("+" if dirty else "")
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


def max_threads() -> int:
    """The most threads numba may run here (NUMBA_NUM_THREADS, else the usable cores)."""
    return int(os.environ.get("NUMBA_NUM_THREADS") or usable_cores())


def set_threads(threads: int) -> int:
    """Run numba on ``threads`` threads (at most ``max_threads()``); the number it runs on."""
    import numba
    numba.set_num_threads(max(1, min(threads, numba.config.NUMBA_NUM_THREADS)))
    return numba.get_num_threads()


# ---- cases -----------------------------------------------------------------------------------
def solver_root() -> Path:
    """The source tree whose ``solver`` this process imported (another tree's, under
    ``benchmarks.paired``), where it has examples/, else this repository."""
    import solver
    tree = Path(solver.__file__).resolve().parents[1]
    return tree if (tree / "examples").is_dir() else ROOT


def read_yaml(path) -> dict:
    import yaml
    with open(path) as fh:
        return yaml.safe_load(fh) or {}


def override(data: dict, sets) -> dict:
    """``--set KEY=VALUE`` overrides of a case or scene dict, as ``python -m solver front``
    applies them (``solver.overrides.apply_overrides``)."""
    from solver.overrides import apply_overrides
    return apply_overrides(data, list(sets))


def read_case(path, sets=()) -> dict:
    """The case or scene YAML at ``path`` with ``sets`` applied."""
    return override(read_yaml(path), sets)


def is_scene(data: dict) -> bool:
    """A scene YAML (``python -m solver run``) rather than a conveyor case file."""
    return "fluid" in data and "walls" in data


def build_scene(data: dict):
    """The solver scene of a scene dict or of a conveyor case dict."""
    if is_scene(data):
        from solver.scene import scene_from_dict
        return scene_from_dict(data)
    from solver.conveyor import build_scene as conveyor_scene
    from solver.conveyor import case_from_dict
    return conveyor_scene(case_from_dict(data))


def simulation(data: dict):
    from solver.simulation import Simulation
    return Simulation(build_scene(data))


def numerics_block(scene: dict) -> dict:
    """A scene dict's block of scheme settings (``numerics``; ``physics`` in older trees)."""
    key = "physics" if "physics" in scene and "numerics" not in scene else "numerics"
    return scene.setdefault(key, {})


def set_shifting(data: dict, method: str | None) -> dict:
    """Set the shifting method of a case (its flat ``shifting`` key) or a scene (its numerics
    block's ``shifting.method``)."""
    if method is not None:
        if is_scene(data):
            numerics_block(data).setdefault("shifting", {})["method"] = method
        else:
            data["shifting"] = method
    return data


def layer(particles: int = 40000, ch: float = 1.5, shifting: str | None = "none", sets=(), dp: float = 1.0e-3,
          rows: int = 100) -> dict:
    """The throughput layer: examples/film.yaml (the paper fluid on its 15.3 deg incline,
    periodic, mDBC, density diffusion) ``rows`` dp deep on a bed stated one dp thick, which the
    solver's layout deepens to the layers its kernel reaches, as long as makes about
    ``particles`` fluid and bed particles, its sound speed set by its own depth."""
    d = read_yaml(solver_root() / "examples" / "film.yaml")
    length = int(round(particles / (rows + 2.0 * ch)))  # the bed: about 2h deep
    L, H, T = length * dp, rows * dp, dp
    d.update(name=f"layer-ch{ch:g}-{shifting}", dp=dp, ch=ch, periodic_x=[0.0, L],
             time={"end": 1.0, "output_interval": 1.0})
    d["fluid"]["blocks"] = [{"x": [0.0, L], "z": [0.0, H]}]
    d["walls"] = [{"name": "bed", "x": [0.0, L], "z": [-T, 0.0]}]
    d.setdefault("sound", {})["depth"] = H
    return override(set_shifting(d, shifting), sets)


# ---- front runs and their metrics -----------------------------------------------------------
def front(case: Path, sets, out: Path, threads: int, reuse: bool = False) -> Path:
    """Run ``python -m solver front CASE --set ...`` (no checkpoint, a diverged run written
    too) to ``out``; with ``reuse`` an existing ``out`` is kept."""
    if not (reuse and out.exists()):
        out.parent.mkdir(parents=True, exist_ok=True)
        cmd = [sys.executable, "-m", "solver", "front", str(case), "-o", str(out),
               "--threads", str(max(1, min(threads, max_threads()))),
               "--quiet", "--no-checkpoint", "--allow-diverged"] + [a for s in sets for a in ("--set", s)]
        print(f"# {' '.join(cmd[1:])}", file=sys.stderr, flush=True)
        subprocess.run(cmd, check=True, cwd=ROOT)
    return out


def run_case(run):
    """The solver case a front run (its dataset) ran (solver.front.recorded_case)."""
    from solver.front import recorded_case
    return recorded_case(run)


def reference(run):
    """Lubrication theory for a front run's own case on the default campaign's metric grids."""
    import numpy as np

    from study.reference import theory_for_case
    x = np.round(np.arange(X_STAR_RANGE[0], X_STAR_RANGE[1] + 1e-9, 0.1), 10)
    z = np.round(np.arange(0.0, 1.3 + 1e-9, 0.025), 10)
    return theory_for_case(run_case(run), x, run.station.values, z)


def metrics(run, ref=None) -> dict:
    """zeta_f, zeta_h, zeta_fs and zeta_u at each station (``zeta_u_0.76``...) of a front run,
    each with its standard error (``zeta_h_se``...; study.metrics.case_metrics; NaN for a
    diverged run)."""
    from study.metrics import case_metrics
    m = case_metrics(run, reference(run) if ref is None else ref, X_STAR_RANGE)
    out = {k: float(m[k]) for k in ("zeta_f", "zeta_f_se", "zeta_h", "zeta_h_se", "zeta_fs", "zeta_fs_se")}
    for s, v, e in zip(m["station"].values, m["zeta_u"].values, m["zeta_u_se"].values):
        out[f"zeta_u_{s:g}"], out[f"zeta_u_{s:g}_se"] = float(v), float(e)
    return out


def largest_shift(new: dict, old: dict) -> tuple[float, str]:
    """(largest |new - old| / sqrt(se_new^2 + se_old^2) over the metrics, its metric) of two
    ``metrics`` dicts: a shift above 2 is a change beyond 2 se; NaN where no metric has both se."""
    shifts = {k: abs(new[k] - old[k]) / math.hypot(new[f"{k}_se"], old[f"{k}_se"])
              for k in new if k.startswith("zeta_") and f"{k}_se" in new and f"{k}_se" in old}
    shifts = {k: v for k, v in shifts.items() if math.isfinite(v)}
    if not shifts:
        return math.nan, ""
    k = max(shifts, key=shifts.get)
    return shifts[k], k


def describe(path: Path) -> dict:
    """A front run's metrics, status, steady time, simulated time, steps, particles, wall time
    of its time stepping, particle-steps/s and largest max |rho/rho0 - 1| over the run."""
    import xarray as xr
    with xr.open_dataset(path) as ds:
        run = ds.load()
    a = run.attrs
    n = int(a["n_fluid"]) + int(a["n_boundary"])
    wall = float(a["wall_time_s"])
    dev = float(run["max_density_deviation"].max()) if "max_density_deviation" in run else math.nan
    return {**metrics(run), "status": a["status"], "steady_at": float(a["steady_state_time_s"]),
            "density_deviation": dev,
            "simulated": float(a["simulated_time_s"]), "steps": int(a["steps"]), "particles": n,
            "wall": wall, "rate": n * int(a["steps"]) / wall if wall > 0 else math.nan}


# ---- output ----------------------------------------------------------------------------------
def table(headers, rows) -> str:
    """A Markdown table; cells are printed as given (format them first), a ``|`` escaped."""
    lines = ["| " + " | ".join(headers) + " |", "|" + "---|" * len(headers)]
    lines += ["| " + " | ".join(str(c).replace("|", "\\|") for c in row) + " |" for row in rows]
    return "\n".join(lines)


def summary(text: str) -> None:
    """The one line ``benchmarks.report`` puts in RESULTS.md's table."""
    print(f"summary: {text}", flush=True)


if __name__ == "__main__":
    print(f"{now()}; {host()}; {load()}; commit {commit()}")
