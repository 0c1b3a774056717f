"""A conveyor case with the fluid density floored at rho0 only within 2h of a wall: an
experiment beside ``no_tension`` (which floors it everywhere), not an option of the solver.

After every step each fluid particle within 2h of a wall rectangle whose density is below rho0
gets rho0. It asks whether holding the upstream wall's contact line alone (docs/numerics.md,
"The damping rule of C_CFL") spares the free surface what the global floor costs it.

Usage: python benchmarks/near_wall_floor.py CASE OUT.nc [KEY=VALUE ...]
(KEY=VALUE: case overrides, as ``--set`` of ``python -m solver front``)
"""
from __future__ import annotations

import sys
from pathlib import Path

import numba as nb

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))


@nb.njit(cache=True)
def floor_near_walls(x, z, rho, kind, walls, n, reach, rho0):
    """rho = rho0 for every fluid particle below it within ``reach`` of a wall rectangle
    (rows x0, x1, z0, z1 of ``walls``)."""
    for i in range(n):
        if kind[i] != 0 or rho[i] >= rho0:
            continue
        for k in range(walls.shape[0]):
            dx = max(walls[k, 0] - x[i], 0.0, x[i] - walls[k, 1])
            dz = max(walls[k, 2] - z[i], 0.0, z[i] - walls[k, 3])
            if dx * dx + dz * dz < reach * reach:
                rho[i] = rho0
                break


def main(argv=None) -> int:
    args = sys.argv[1:] if argv is None else argv
    if len(args) < 2:
        print(__doc__, file=sys.stderr)
        return 2
    from sampled_run import load_case

    from solver import front, simulation

    shipped = simulation.Simulation.step

    def step(self, dt=None):
        reason = shipped(self, dt)
        if not reason:
            floor_near_walls(self.x, self.z, self.rho, self.kind, self.walls, self.n_active,
                             2.0 * self.h, self.rho0)
        return reason

    simulation.Simulation.step = step
    try:
        ds = front.run_front(load_case(args[0], args[2:]), quiet=True)
    finally:
        simulation.Simulation.step = shipped
    print(f"{ds.attrs['status']} at {ds.attrs['simulated_time_s']:.3f} s, {ds.attrs['steps']} steps, "
          f"{ds.attrs['wall_time_s']:.0f} s wall; largest density deviation "
          f"{float(ds.max_density_deviation.max()):.4f}, area drift {float(abs(ds.area_drift).max()):.4f}"
          + (f" ({ds.attrs['reason']})" if ds.attrs["status"] == "diverged" else ""))
    ds.to_netcdf(args[1])
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
