"""Time to a steady answer: a conveyor case run until its averaging window and the hold-out after it pass, per
shifting method and variant: wall time, steps, particle-steps/s, steady time, simulated time and
the metrics against lubrication theory (study.metrics.case_metrics).

Each run is ``python -m solver front CASE --set shifting=METHOD --set ...`` on --threads
threads. A variant is a name and its overrides (``--variant NAME KEY=VALUE ...``, repeatable);
``case`` is the case as given. --spread also runs the case on 1 thread: the two thread counts
sum the pair contributions in another order, so round-off starts two runs of the same physics
apart, and a metric that moves less than between them is noise. A variant whose every metric
lies within that spread of the case's is "equal" to it. "largest shift / se" is each variant's
largest |metric - case's| / sqrt(se^2 + se_case^2) over the metrics (benchmarks.common.largest_shift),
with its metric: above 2, that metric moved beyond 2 se. "max |rho/rho0 - 1|" is the largest over
the run. A sound-speed sweep is ``--variant c8 coefsound=8.0 --variant c9 coefsound=9.0``.

With --campaign FILE it times whole campaigns instead: ``snakemake --cores --threads --configfile
FILE --config name=timing_STEM_VARIANT KEY=VALUE ...`` for each variant (its KEY=VALUE campaign
keys, ``case`` the file as given), one after the other, each under its own name
(results/ and reports/timing_STEM_VARIANT/, replaced by each timing; with --reuse a variant whose folder
holds a reduced campaign is read, not run again, and its wall time is not known). It prints
each campaign's wall time, the span and the summed wall of its runs, how many are steady, how
many start checks agree on every metric, and each run's averaging window, end and wall; the
particle-steps summed over the runs are the campaign's work, which a busy host does not change.

    python -m benchmarks.time_to_solution [--case examples/conveyor_fast.yaml] [--shifting skillen lind]
        [--set KEY=VALUE ...] [--variant NAME KEY=VALUE ...] [--spread] [--threads 2] [--out DIR] [--reuse]
    python -m benchmarks.time_to_solution --campaign config/config.yaml [--variant cold warm_start=false]
        [--threads 2] [--reuse]
"""
from __future__ import annotations

import json
import shutil
import subprocess
import sys
import time
from pathlib import Path

from benchmarks import common

QUICK = {"shifting": ["skillen"], "sets": ["dp=0.004", "steady.max_time=1.5"]}


def campaign_summary(folder: Path) -> tuple[list[dict], tuple[int, int]]:
    """From a reduced campaign (its campaign.nc): each run's case, start and end (unix s),
    window, simulated end, wall, work (particle-steps), steadiness and status; and (start
    checks agreeing within 2 se on every metric, start checks)."""
    import xarray as xr
    from study import startcheck
    with xr.open_dataset(folder / "campaign.nc") as ds:
        ds = ds.load()
    v = {k: ds[f"case_{k}"].values for k in ("started", "ended", "steady_state_time", "simulated_time",
                                             "wall_time", "steps", "n_particles", "steady", "status")}
    runs = [{"case": str(c), "started": v["started"][i], "ended": v["ended"][i],
             "window": v["steady_state_time"][i], "end": v["simulated_time"][i], "wall": v["wall_time"][i],
             "work": v["steps"][i] * v["n_particles"][i], "steady": int(v["steady"][i]), "status": str(v["status"][i])}
            for i, c in enumerate(ds["case"].values)]
    t = startcheck.table(ds)
    return runs, (int(t["agree"].all("metric").sum()), int(t.sizes["check"]))


def campaigns(a, variants: dict) -> int:
    """The ``--campaign`` mode (module docstring)."""
    stem = a.campaign.stem
    rows, runs = [], {}
    for name, sets in variants.items():
        label = f"timing_{stem}_{name}"  # not a name a campaign takes: its folder is replaced
        folder = common.ROOT / "results" / label
        wall = "-"
        if not (a.reuse and (folder / "campaign.nc").exists()):
            for old in (folder, common.ROOT / "reports" / label):  # with its report left, nothing would rerun
                if old.exists():
                    shutil.rmtree(old)
            cmd = [sys.executable, "-m", "snakemake", "--cores", str(a.threads), "--configfile", str(a.campaign),
                   "--config", f"name={label}", *sets]
            start = time.perf_counter()
            res = subprocess.run(cmd, cwd=common.ROOT, capture_output=True, text=True)
            wall = f"{time.perf_counter() - start:.0f}"
            if res.returncode != 0:
                print(res.stderr[-3000:], file=sys.stderr)
                return res.returncode
        runs[name], (agree, checks) = campaign_summary(folder)
        r = runs[name]
        span = max(x["ended"] for x in r) - min(x["started"] for x in r)
        rows.append([name, " ".join(sets) or "-", wall, f"{span:.0f}", f"{sum(x['wall'] for x in r):.0f}",
                     f"{sum(x['work'] for x in r) / 1e9:.2f}", f"{sum(x['steady'] for x in r)} of {len(r)}",
                     f"{agree} of {checks}"])
    print(f"campaign: {a.campaign.relative_to(common.ROOT) if a.campaign.is_relative_to(common.ROOT) else a.campaign}"
          f"; {a.threads} cores")
    print(common.table(["variant", "campaign keys", "wall [s]", "runs' span [s]", "runs' wall summed [s]",
                        "G particle-steps", "steady", "start checks agreeing"], rows))
    for name, r in runs.items():
        print(f"\n{name}:")
        print(common.table(["case", "averaging window from [s]", "ends at [s]", "wall [s]", "M particle-steps",
                            "status"],
                           [[x["case"], f"{x['window']:.2f}", f"{x['end']:.2f}", f"{x['wall']:.0f}",
                             f"{x['work'] / 1e6:.0f}", x["status"]] for x in r]))
    common.summary("; ".join(f"{row[0]}: {row[2]} s wall, runs over {row[3]} s, {row[5]} G particle-steps, "
                             f"{row[6]} steady, start checks {row[7]}" for row in rows))
    return 0


def main(argv=None) -> int:
    ap = common.parser(__doc__, case="examples/conveyor_fast.yaml", out="time_to_solution")
    ap.add_argument("--campaign", type=Path, default=None,
                    help="time whole campaigns of this file instead (module docstring)")
    ap.add_argument("--shifting", nargs="+", default=["skillen", "lind"])
    ap.add_argument("--variant", nargs="+", action="append", default=[], metavar="NAME KEY=VALUE",
                    help="a variant: its name, then its overrides on top of the case's (repeatable)")
    ap.add_argument("--spread", action="store_true", help="also run the case on 1 thread")
    ap.add_argument("--reuse", action="store_true", help="keep the runs already in --out")
    a = common.parse(ap, argv, QUICK)
    variants = {"case": []} | {v[0]: v[1:] for v in a.variant}
    if a.campaign is not None:
        a.campaign = a.campaign.absolute()
        return campaigns(a, variants)
    rows = []
    for method in a.shifting:
        def run(variant, threads, method=method):
            name = f"{method}_{variant}_t{threads}"
            sets = a.sets + [f"shifting={method}"] + variants[variant]
            return common.describe(common.front(a.case, sets, a.out / f"{name}.nc", threads, a.reuse))
        results = {v: run(v, a.threads) for v in variants}
        spread = None
        if a.spread:
            one = run("case", 1)
            spread = {k: abs(one[k] - results["case"][k]) for k in one
                      if k.startswith("zeta_") and not k.endswith("_se")}
            results["case, 1 thread"] = one
        for v, m in results.items():
            verdict, shift = "-", "-"
            if spread and v not in ("case", "case, 1 thread"):
                equal = all(abs(m[k] - results["case"][k]) <= s for k, s in spread.items())
                verdict = "yes" if equal else "no"
            if v != "case":
                z, k = common.largest_shift(m, results["case"])
                shift = f"{z:.1f} ({k})" if k else "-"
            rows.append({"shifting": method, "variant": v, **m, "equal": verdict, "shift": shift, "spread": spread})
    (a.out / "time_to_solution.json").write_text(json.dumps(rows, indent=1))
    zetas = [k for k in rows[0] if k.startswith("zeta_") and not k.endswith("_se")]
    print(f"case: {a.case.relative_to(common.ROOT) if a.case.is_relative_to(common.ROOT) else a.case} "
          f"{' '.join(a.sets)}; {a.threads} threads")
    print(common.table(
        ["shifting", "variant", "status", "steady at [s]", "simulated [s]", "steps", "wall [s]", "M particle-steps/s",
         *zetas, "max \\|rho/rho0 - 1\\| %", "largest shift / se", "equal to case"],
        [[r["shifting"], r["variant"], r["status"], f"{r['steady_at']:.2f}", f"{r['simulated']:.2f}", r["steps"],
          f"{r['wall']:.1f}", f"{r['rate'] / 1e6:.2f}", *(f"{r[k]:.4f}" for k in zetas),
          f"{100 * r['density_deviation']:.2f}", r["shift"], r["equal"]] for r in rows]))
    for r in rows:
        if r["spread"] and r["variant"] == "case":
            print(f"\nrun-to-run spread ({r['shifting']}, 1 against {a.threads} threads): "
                  + ", ".join(f"{k} {v:.4f}" for k, v in r["spread"].items()))
    common.summary("; ".join(f"{r['shifting']}: {r['status']} at {r['simulated']:.2f} s (steady at "
                             f"{r['steady_at']:.2f} s), {r['wall']:.1f} s wall, zeta_h {r['zeta_h']:.4f}"
                             for r in rows if r["variant"] == "case"))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
