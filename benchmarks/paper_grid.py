"""Projected wall time of a campaign's grid runs and start checks (default config/paper.yaml) on this
host, from short runs.

Each grid case of the config runs --time s of simulated time (--fine-time below dp = 0.4 mm) on
--threads threads, after a compile run, from the solver case file the campaign writes for it
(study.flows.conveyor.case_dict; cold start, --set overrides on top). A run gives particles N, steps,
mean dt, particle-steps/s of its time stepping and its start-up (the rest of its wall time),
and a case then costs

    wall = start-up + T_sim / dt * N / rate

with T_sim from --t-sim (T, METHOD=T or METHOD@DP_MM=T: the simulated time at which a run ends
steady, the end of its hold-out window; a start check's METHOD is its method and start, e.g.
``skillen-paper``, ``skillen-warm`` or ``skillen-film``, and falls back to the method's) and, as the upper bound,
the case's steady.max_time. The defaults are where dp = 1 mm runs of the default campaign ended
(T_SIM_MEASURED). A start check costs what its grid case does per simulated second.
Realisations of an ensemble cost what their case does. --coarse-only measures the coarsest dp
at every Ch and the finer dp at the paper Ch (grid.paper_ch, else the middle Ch); a finer case at
another Ch takes its paper-Ch run's dt, rate and N times their Ch ratio at the coarsest dp.

    python -m benchmarks.paper_grid [--config config/paper.yaml] [--threads 2] [--time 0.05] [--fine-time 0.02]
        [--t-sim 12.5 lind=16.5 skillen@0.25=10] [--shifting skillen lind] [--coarsest N] [--paper-ch-only]
        [--coarse-only] [--set KEY=VALUE ...] [--out DIR] [--reuse]

--shifting, --coarsest and --paper-ch-only project only part of the grid (--quick: Skillen's
cases at the paper Ch and the two coarsest dp).
"""
from __future__ import annotations

import copy
import json
from pathlib import Path

from benchmarks import common

QUICK = {"paper_ch_only": True, "shifting": ["skillen"], "coarsest": 2, "time": 0.01}


def paper_ch(cfg: dict) -> float:
    """The grid's paper Ch (grid.paper_ch where the grid has it, else its middle Ch)."""
    chs = sorted(cfg["grid"]["ch"])
    return cfg["grid"].get("paper_ch") if cfg["grid"].get("paper_ch") in chs else chs[len(chs) // 2]


def grid_cases(cfg: dict, methods=None, coarsest: int | None = None, paper_ch_only: bool = False) -> dict:
    """{(dp, ch, method): (solver case dict of realisation 0, realisations)} of the grid (only
    ``methods``, the ``coarsest`` dp and the paper Ch where given)."""
    from study.flows.conveyor import case_dict, cases
    dps = sorted({c.dp for c in cases(cfg) if c.on_grid}, reverse=True)[:coarsest]
    out: dict = {}
    for c in cases(cfg):
        if (not c.on_grid or (methods and c.shifting not in methods) or c.dp not in dps
                or (paper_ch_only and c.ch != paper_ch(cfg))):
            continue
        key = (c.dp, c.ch, c.shifting)
        if c.realisation == 0:
            d = case_dict(cfg, c)
            if d.get("start") == "warm":  # a campaign's warm start: run from the case's own start here
                d.pop("start")
                d.pop("warm_from", None)
                if "start" in cfg["case"]:
                    d["start"] = cfg["case"]["start"]
            out[key] = [d, 0]
        out[key][1] += 1
    return out


def measure(data: dict, sets, sim_time: float) -> dict:
    from solver.conveyor import case_from_dict
    from solver.front import run_front
    d = common.override(copy.deepcopy(data), sets)
    d.setdefault("steady", {})["max_time"] = sim_time
    with common.Timer() as t:
        ds = run_front(case_from_dict(d))
    a = ds.attrs
    stepping = float(a["wall_time_s"])  # the run's own loop, without the start-up
    steps, n = int(a["steps"]), int(a["n_fluid"]) + int(a["n_boundary"])
    return {"particles": n, "steps": steps, "simulated": float(a["simulated_time_s"]), "wall": t.seconds,
            "startup": t.seconds - stepping, "dt": float(a["simulated_time_s"]) / max(steps, 1),
            "rate": n * steps / stepping, "update": str(a.get("viscous_update", "")), "status": a["status"]}


T_SIM = ["12.5"]  # s, every case: --t-sim's default before the entries below
# where the dp = 1 mm runs of config/config.yaml ended (2026-12-06): from the paper's start (its
# start checks; the grid's own start at that dp, and a paper-start check), warm from dp = 1.5 mm
# (its grid runs; a warm-start check) and from the moving film (the campaign without warm starts;
# a film-start check; Lind's not steady by its max_time, 20 s)
T_SIM_MEASURED = ["skillen=10.68", "lind=10.04", "skillen-paper=10.68", "lind-paper=10.04",
                  "skillen-warm=10.16", "lind-warm=11.46", "skillen-film=17.1", "lind-film=20"]


def t_sim_of(specs, method: str, dp: float) -> float:
    """T_sim of a case from --t-sim entries: T, METHOD=T or METHOD@DP_MM=T, the most specific wins;
    a start check's METHOD (``skillen-paper``, ``-warm``, ``-film``) falls back to its method's entries."""
    best, rank = 12.5, -1
    names = [method] + ([method.split("-")[0]] if "-" in method else [])
    for s in specs:
        key, _, value = s.rpartition("=")
        for depth, name in enumerate(names):  # the start check's own entries outrank its method's
            r = (-1 if key not in ("", name, f"{name}@{dp * 1e3:g}") else 0 if not key
                 else 2 * (2 - depth) if key == f"{name}@{dp * 1e3:g}" else 2 * (2 - depth) - 1)
            if r > rank:
                best, rank = float(value), r
    return best


def start_checks(cfg: dict) -> list[tuple[float, float, str, str]]:
    """(dp, ch, method, start) of the campaign's start checks (study.flows.conveyor.start_checks),
    the start ``paper``, ``warm`` or ``film``."""
    from study.flows.conveyor import CHECK_STARTS, cases
    return [(c.dp, c.ch, c.shifting, c.tag.split("-")[0]) for c in cases(cfg) if c.tag in CHECK_STARTS]


def main(argv=None) -> int:
    ap = common.parser(__doc__, case=None, sets=True, out="paper_grid")
    ap.add_argument("--config", type=Path, default=common.ROOT / "config" / "paper.yaml")
    ap.add_argument("--time", type=float, default=0.05, help="simulated seconds of each run")
    ap.add_argument("--fine-time", type=float, default=0.02, help="simulated seconds below dp = 0.4 mm")
    ap.add_argument("--t-sim", nargs="+", default=T_SIM + T_SIM_MEASURED, metavar="[METHOD[@DP_MM]=]T")
    ap.add_argument("--shifting", nargs="+", default=None, help="only these methods' cases (default: all)")
    ap.add_argument("--coarsest", type=int, default=None, metavar="N", help="only the N coarsest dp (default: all)")
    ap.add_argument("--paper-ch-only", action="store_true", help="only the paper Ch")
    ap.add_argument("--coarse-only", action="store_true",
                    help="measure every Ch at the coarsest dp only, the finer dp at the paper Ch")
    ap.add_argument("--reuse", action="store_true", help="project from OUT/runs.json, measure nothing")
    a = common.parse(ap, argv, QUICK)
    from study.config import load
    cfg = load(a.config)
    a.threads = common.set_threads(a.threads)
    grid = grid_cases(cfg, a.shifting, a.coarsest, a.paper_ch_only)
    dps = sorted({k[0] for k in grid}, reverse=True)
    pch, coarse = paper_ch(cfg), dps[0]
    to_measure = [k for k in grid if not a.coarse_only or k[0] == coarse or k[1] == pch]
    a.out.mkdir(parents=True, exist_ok=True)
    runs_file = a.out / "runs.json"
    if a.reuse:
        runs = {tuple(r["key"]): r for r in json.loads(runs_file.read_text())}
    else:
        for method in sorted({k[2] for k in to_measure}):  # compile each method's kernels first
            key = next(k for k in to_measure if k[2] == method and k[0] == coarse)
            measure(grid[key][0], a.sets, 0.002)
        runs = {k: {"key": list(k), **measure(grid[k][0], a.sets, a.fine_time if k[0] < 0.0004 else a.time)}
                for k in to_measure}
        runs_file.write_text(json.dumps(list(runs.values()), indent=1))
    print(f"{a.config.name}: {sum(n for _, n in grid.values())} grid runs, {a.threads} threads, measured:")
    print(common.table(
        ["dp [mm]", "Ch", "shifting", "viscous update", "status", "particles", "simulated [s]", "steps", "dt [s]",
         "wall [s]", "start-up [s]", "M particle-steps/s"],
        [[f"{k[0] * 1e3:g}", f"{k[1]:g}", k[2], r["update"], r["status"], r["particles"], f"{r['simulated']:.3f}",
          r["steps"], f"{r['dt']:.3g}", f"{r['wall']:.1f}", f"{r['startup']:.1f}", f"{r['rate'] / 1e6:.2f}"]
         for k, r in runs.items()]))
    rows, total, total_max = [], 0.0, 0.0
    for (dp, ch, m), (d, count) in sorted(grid.items(), key=lambda kv: (-kv[0][0], kv[0][1], kv[0][2])):
        own = runs.get((dp, ch, m))
        if own is not None:
            n, dt, rate, startup, how = own["particles"], own["dt"], own["rate"], own["startup"], "measured"
        else:  # the paper-Ch run at this dp, times the Ch ratios at the coarsest dp
            base, c1, p1 = runs[(dp, pch, m)], runs[(coarse, ch, m)], runs[(coarse, pch, m)]
            n = base["particles"] * c1["particles"] / p1["particles"]
            dt, rate = base["dt"] * c1["dt"] / p1["dt"], base["rate"] * c1["rate"] / p1["rate"]
            startup, how = base["startup"], "scaled"
        ts = t_sim_of(a.t_sim, m, dp)
        max_time = float(d.get("steady", {}).get("max_time", ts))
        per_second = n / (dt * rate)  # wall s a simulated s
        to_steady = count * (startup + min(ts, max_time) * per_second)
        to_max = count * (startup + max_time * per_second)
        total, total_max = total + to_steady, total_max + to_max
        rows.append([f"{dp * 1e3:g}", f"{ch:g}", m, count, how, f"{dt:.3g}", f"{rate / 1e6:.2f}", f"{ts:g}",
                     f"{to_steady / 3600:.2f}", f"{max_time:g}", f"{to_max / 3600:.2f}"])
    checks = [k for k in start_checks(cfg) if k[:3] in grid and (k[:3] in runs or (k[0], pch, k[2]) in runs)]
    for dp, ch, m, start in checks:  # a start check: its grid case's cost per simulated second
        own = runs.get((dp, ch, m)) or runs[(dp, pch, m)]
        ts, max_time = t_sim_of(a.t_sim, f"{m}-{start}", dp), float(grid[(dp, ch, m)][0]["steady"].get("max_time", 30))
        per_second = own["particles"] / (own["dt"] * own["rate"])
        to_steady, to_max = own["startup"] + min(ts, max_time) * per_second, own["startup"] + max_time * per_second
        total, total_max = total + to_steady, total_max + to_max
        rows.append([f"{dp * 1e3:g}", f"{ch:g}", f"{m}, {start} start", 1, "as its grid case", f"{own['dt']:.3g}",
                     f"{own['rate'] / 1e6:.2f}", f"{ts:g}", f"{to_steady / 3600:.2f}", f"{max_time:g}",
                     f"{to_max / 3600:.2f}"])
    n_runs = sum(n for _, n in grid.values()) + len(checks)
    rows.append(["total", "", "", n_runs, "", "", "", "", f"{total / 3600:.2f}", "", f"{total_max / 3600:.2f}"])
    print()
    print(common.table(["dp [mm]", "Ch", "shifting", "runs", "how", "dt [s]", "M particle-steps/s", "T_sim [s]",
                        "to steady + window [h]", "max_time [s]", "to max_time [h]"], rows))
    part = (" and ".join(sorted({k[2] for k in grid})) + ", dp " + ", ".join(f"{dp * 1e3:g}" for dp in dps) + " mm, Ch "
            + ", ".join(f"{ch:g}" for ch in sorted({k[1] for k in grid})))
    common.summary(f"{a.config.name} ({part}, {len(checks)} start checks), one run at a time on {a.threads} threads: "
                   f"{total / 3600:.1f} h to steady (T_sim {' '.join(a.t_sim)} s), "
                   f"{total_max / 3600:.1f} h to max_time")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
