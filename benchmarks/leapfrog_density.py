"""A leapfrog density update, tried on conveyor cases (an experiment, not a solver option).

The prototype of ``physics.density_update: leapfrog`` (docs/numerics.md): the density's
second half step takes the continuity rate at v^{n+1},

    rho_h = rho^n + dt/2 D_prev; evaluate at x^{n+1/2} with v^n; kick v^{n+1};
    evaluate again at x^{n+1/2} with v^{n+1} and rho_h: D_new; rho^{n+1} = rho_h + dt/2 D_new;
    D_prev = D_new; drift,

where the solver's option gets D_new from a continuity pass over the velocity change
(``forces.continuity_of_change``), this script from the whole second evaluation
(``Simulation._evaluate``, about twice the step's cost), for this process only. With
--shipped it runs the solver's step as the case sets it. Prints the run's line and the median
of the run's largest fluid density deviation from --from s on.

    python benchmarks/leapfrog_density.py CASE.yaml --set cfl=0.6 --set cfl_rule=fixed \\
        --set steady.stop=false --set steady.max_time=4 [--shipped] [-o OUT.nc]
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

from sampled_run import load_case, report  # noqa: E402


def second_evaluation(self, t: float, dt: float, u0, w0, rho_h):
    """``Simulation._leapfrog_density`` by the whole evaluation at v^{n+1}: the walls, the
    density diffusion and every pair term again, at the evaluation's positions and rho_h."""
    from solver import forces
    self.rho[:] = rho_h
    reason = self._evaluate(t)
    if reason:
        raise RuntimeError(reason)
    n = self.n_active
    d_new = self.out[forces.DRHO][:n]
    self.rho[:n] += 0.5 * dt * d_new
    self.drho_prev[:n] = d_new


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("case")
    ap.add_argument("--set", action="append", default=[])
    ap.add_argument("--shipped", action="store_true", help="run the case as it is, without the prototype")
    ap.add_argument("--from", dest="start", type=float, default=0.2)
    ap.add_argument("-o", "--out", default="")
    a = ap.parse_args(argv)
    from solver import front, simulation
    sets = a.set
    if not a.shipped:
        simulation.Simulation._leapfrog_density = second_evaluation
        sets = sets + ["density_update=leapfrog"]
    case = load_case(a.case, sets)
    ds = front.run_front(case, quiet=True)
    report(case, ds, a.out or "(not saved)")
    if a.out:
        ds.to_netcdf(a.out)
    t = ds.diag_time.values
    dev = ds.max_density_deviation.values[t >= a.start]
    print(f"steps {int(ds.attrs['steps'])}; median largest fluid |rho / rho0 - 1| from {a.start:g} s: "
          f"{np.median(dev):.4f} (largest {dev.max():.4f})")


if __name__ == "__main__":
    main()
