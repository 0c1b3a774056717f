"""Time to a steady answer: a conveyor case run until its averaging window and the hold-out after it pass, per
shifting method and variant: wall time, steps, particle-steps/s, steady time, simulated time and
the metrics against lubrication theory (study.metrics.case_metrics).

Each run is ``python -m solver front CASE --set shifting=METHOD --set ...`` on --threads
threads. A variant is a name and its overrides (``--variant NAME KEY=VALUE ...``, repeatable);
``case`` is the case as given. --spread also runs the case on 1 thread: the two thread counts
sum the pair contributions in another order, so round-off starts two runs of the same physics
apart, and a metric that moves less than between them is noise. A variant whose every metric
lies within that spread of the case's is "equal" to it.

    python -m benchmarks.time_to_solution [--case examples/conveyor_fast.yaml] [--shifting skillen lind]
        [--set KEY=VALUE ...] [--variant NAME KEY=VALUE ...] [--spread] [--threads 2] [--out DIR] [--reuse]
"""
from __future__ import annotations

import json

from benchmarks import common

QUICK = {"shifting": ["skillen"], "sets": ["dp=0.004", "steady.max_time=1.5"]}


def main(argv=None) -> int:
    ap = common.parser(__doc__, case="examples/conveyor_fast.yaml", out="time_to_solution")
    ap.add_argument("--shifting", nargs="+", default=["skillen", "lind"])
    ap.add_argument("--variant", nargs="+", action="append", default=[], metavar="NAME KEY=VALUE",
                    help="a variant: its name, then its overrides on top of the case's (repeatable)")
    ap.add_argument("--spread", action="store_true", help="also run the case on 1 thread")
    ap.add_argument("--reuse", action="store_true", help="keep the runs already in --out")
    a = common.parse(ap, argv, QUICK)
    variants = {"case": []} | {v[0]: v[1:] for v in a.variant}
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
            verdict = "-"
            if spread and v not in ("case", "case, 1 thread"):
                equal = all(abs(m[k] - results["case"][k]) <= s for k, s in spread.items())
                verdict = "yes" if equal else "no"
            rows.append({"shifting": method, "variant": v, **m, "equal": verdict, "spread": spread})
    (a.out / "time_to_solution.json").write_text(json.dumps(rows, indent=1))
    zetas = [k for k in rows[0] if k.startswith("zeta_") and not k.endswith("_se")]
    print(f"case: {a.case.relative_to(common.ROOT) if a.case.is_relative_to(common.ROOT) else a.case} "
          f"{' '.join(a.sets)}; {a.threads} threads")
    print(common.table(
        ["shifting", "variant", "status", "steady at [s]", "simulated [s]", "steps", "wall [s]", "M particle-steps/s",
         *zetas, "equal to case"],
        [[r["shifting"], r["variant"], r["status"], f"{r['steady_at']:.2f}", f"{r['simulated']:.2f}", r["steps"],
          f"{r['wall']:.1f}", f"{r['rate'] / 1e6:.2f}", *(f"{r[k]:.4f}" for k in zetas), r["equal"]] for r in rows]))
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
