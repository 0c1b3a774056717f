"""A leapfrog density update, tried on conveyor cases (an experiment, not a solver option).

The solver's step (solver/simulation.py, ``step``) advances the density by dt D(v^n): the
evaluation's continuity rate sees the start-of-step velocities, and the density's half-step
drift takes the previous step's rate. For one linear acoustic mode that step grows unless it
is damped (benchmarks/acoustic_mode.py). Here the step is replaced, for this process only, by
one whose density's second half step takes the continuity rate at v^{n+1}:

    rho_h = rho^n + dt/2 D_prev; evaluate at x^{n+1/2} with v^n; kick v^{n+1};
    evaluate again at x^{n+1/2} with v^{n+1} and rho_h: D_new; rho^{n+1} = rho_h + dt/2 D_new;
    D_prev = D_new; drift.

The second evaluation is the whole pair loop (about twice the step's cost): enough to see
whether the acoustic edge moves, not a way to run it. Prints the run's line and the median of
the run's largest fluid density deviation from --from s on.

    python benchmarks/leapfrog_density.py CASE.yaml --set cfl=0.6 --set steady.stop=false \\
        --set steady.max_time=4 [--shipped] [-o OUT.nc]
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


def leapfrog_step(self, dt: float | None = None) -> str:
    """``Simulation.step`` with the density's second half step at v^{n+1} (module docstring)."""
    from solver import forces, guards, integrate
    dt = self.info.dt if dt is None else dt
    s = self.scene
    t = self.t
    vw = self.wall_velocities(t)
    integrate.drift(self.x, self.z, self.u, self.w, self.kind, self.wall, self.gx, self.gz,
                    vw, self.moving, 0.5 * dt, self.n)
    integrate.advance_density(self.rho, self.drho_prev, self.n_active, 0.5 * dt)
    self._wrap()
    reason = self._evaluate(t + 0.5 * dt)
    if not reason and self.implicit:
        reason = self._solve_viscous(dt)
    if reason:
        return self._stop(reason)
    if self.volume_relaxation:
        self._relax_volume(dt)
    rho_h = self.rho.copy()
    o = self.out
    integrate.kick(self.u, self.w, self.rho, self.kind, o[forces.AX], o[forces.AZ], o[forces.DRHO],
                   self.drho_prev, self.n_active, dt, self.rho0, not self.mdbc,
                   bool(s.physics.no_tension))
    self.rho[:] = rho_h
    reason = self._evaluate(t + 0.5 * dt)  # the same positions, v^{n+1}
    if reason:
        return self._stop(reason)
    n = self.n_active
    d_new = self.out[forces.DRHO][:n]
    self.rho[:n] += 0.5 * dt * d_new
    self.drho_prev[:n] = d_new
    vw = self.wall_velocities(t + dt)
    integrate.drift(self.x, self.z, self.u, self.w, self.kind, self.wall, self.gx, self.gz,
                    vw, self.moving, 0.5 * dt, self.n)
    if self.shift_method != "none":
        self._shift(dt)
    self._wrap()
    self.t = t + dt
    self.steps += 1
    reason = guards.check(self.check_health(), s.guards, s.dp)
    if reason:
        return self._stop(reason)
    self._update_dt()
    reason = guards.check_dt(self.info.dt, self.dt_first, s.guards)
    if reason:
        return self._stop(reason)
    return ""


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("case")
    ap.add_argument("--set", action="append", default=[])
    ap.add_argument("--shipped", action="store_true", help="run the solver's own step instead")
    ap.add_argument("--from", dest="start", type=float, default=0.2)
    ap.add_argument("-o", "--out", default="")
    a = ap.parse_args(argv)
    from solver import front, simulation
    if not a.shipped:
        simulation.Simulation.step = leapfrog_step
    case = load_case(a.case, a.set)
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
