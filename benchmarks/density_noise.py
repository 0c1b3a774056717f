"""Where a conveyor run's density noise sits, and how large it is: for the acoustic edge of C_CFL.

Runs a case (with --set overrides) and, at every probe sample (``sampled_run``), records the
fluid particle and the boundary particle with the largest |rho / rho0 - 1|: position, deviation
and velocity. Prints the run's status, RKC stages a step and, over [--from, --to] s, the median
of the two largest deviations and the heights at which the fluid's sits. With
``--stage-margin M`` (M < 1) the sub-stepped laminar term takes the fewest RKC stages s with
z <= M beta_s instead of z <= beta_s (``solver.implicit.rkc_stages``), for this run only.

    python benchmarks/density_noise.py CASE.yaml --set cfl=0.6 --set cfl_rule=fixed \\
        --set steady.stop=false --set steady.max_time=2 [--stage-margin 0.5] [-o OUT.npz]
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

from sampled_run import load_case, report, run_sampled  # noqa: E402


def largest_deviations(sim, d, case) -> dict:
    """(x, z, rho / rho0 - 1, u, w) of the fluid (``fluid``) and the boundary (``boundary``)
    particle with the largest |rho / rho0 - 1|."""
    n = sim.n
    dev = sim.rho[:n] / sim.rho0 - 1.0
    fluid = sim.kind[:n] == 0
    out = {}
    for key, mask in (("fluid", fluid), ("boundary", ~fluid)):
        idx = np.flatnonzero(mask)
        i = idx[np.argmax(np.abs(dev[idx]))]
        out[key] = (sim.x[i], sim.z[i], dev[i], sim.u[i], sim.w[i])
    out["time"] = sim.t
    return out


def with_stage_margin(margin: float) -> None:
    """Make ``solver.implicit.rkc_stages`` pick stages for z / margin (this process only)."""
    from solver import implicit
    shipped = implicit.rkc_stages
    implicit.rkc_stages = lambda z, damping=implicit.RKC_DAMPING: shipped(z / margin, damping)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("case")
    ap.add_argument("--set", action="append", default=[])
    ap.add_argument("--stage-margin", type=float, default=1.0)
    ap.add_argument("--from", dest="start", type=float, default=0.2)
    ap.add_argument("--to", dest="end", type=float, default=np.inf)
    ap.add_argument("-o", "--out", default="")
    a = ap.parse_args(argv)
    if a.stage_margin < 1.0:
        with_stage_margin(a.stage_margin)
    case = load_case(a.case, a.set)
    ds, s = run_sampled(case, largest_deviations)
    report(case, ds, a.out or "(not saved)")
    if a.out:
        np.savez(a.out, **s)
    t = s["time"]
    w = (t >= a.start) & (t <= a.end)
    fluid, boundary = s["fluid"][w], s["boundary"][w]
    steps = int(ds.attrs["steps"])
    z = fluid[:, 1] * 1e3
    print(f"RKC stages a step {int(ds.attrs.get('rkc_stages', 0)) / max(steps, 1):.2f}; over "
          f"[{a.start:g}, {min(a.end, float(t[-1])):.2f}] s ({w.sum()} samples): median largest "
          f"|rho / rho0 - 1| fluid {np.median(np.abs(fluid[:, 2])):.4f}, boundary "
          f"{np.median(np.abs(boundary[:, 2])):.4f}; the fluid's at z = {np.percentile(z, 25):.1f} / "
          f"{np.median(z):.1f} / {np.percentile(z, 75):.1f} mm (quartiles), h_n "
          f"{case.h_n * 1e3:.1f} mm")


if __name__ == "__main__":
    main()
