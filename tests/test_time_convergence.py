"""Order of the time integration (docs/numerics.md).

The step evaluates forces at mid-step positions with the velocities of the step's start, so
the velocity update is first order in dt for the velocity-dependent terms (viscosity,
continuity, the mDBC ghost velocity). Start-up Couette flow at fixed dp, run to the same time
with dt, dt/2, dt/4 and dt/8 (dt: the CFL step): the successive differences of the velocity
field must fall by a factor 2 per halving, i.e. an observed order of 1.
"""
import math

import numpy as np
import pytest

from solver.simulation import Simulation
from tests.conftest import example_scene

pytestmark = pytest.mark.slow  # runs the solver

T_END = 0.0225  # s: 1/10 of the start-up; the profile is still far from linear


def velocity_at_end(n_steps: int) -> np.ndarray:
    sim = Simulation(example_scene("couette"))
    dt = T_END / n_steps
    for _ in range(n_steps):
        reason = sim.step(dt)
        assert not reason, reason
    snap = sim.snapshot()
    return snap["u"][snap["kind"] == 0]


def test_velocity_update_is_first_order_in_dt():
    n0 = math.ceil(T_END / Simulation(example_scene("couette")).info.dt)  # dt0 = T / n0 <= the CFL step
    u = [velocity_at_end(n0 * k) for k in (1, 2, 4, 8)]
    diffs = [np.sqrt(np.mean((a - b) ** 2)) for a, b in zip(u, u[1:])]
    orders = [math.log2(d1 / d2) for d1, d2 in zip(diffs, diffs[1:])]
    # measured: 1.009 and 1.004 (2 threads); a second-order step would give about 2
    for p in orders:
        assert 0.85 <= p <= 1.2, orders
    # the time error at the CFL step is small against the plate speed (measured 0.3 %)
    U0 = example_scene("couette").walls[1].velocity[0]
    assert diffs[0] * 2 < 0.005 * U0  # |u(dt) - u(0)| ~ 2 |u(dt) - u(dt/2)| for order 1


def test_the_step_is_one_c_times_the_smallest_limit():
    """dt = C min(dt1, dt2, dt3) (docs/scheme.md section 6): one C for the force and viscous
    limits; ``cfl_acoustic`` sets the acoustic limit's own C, and an implicit or sub-stepped
    laminar term (``viscous_limit`` false) drops dt3, which is still reported."""
    from solver.integrate import time_step
    h, amax, vmax, c0, nu = 1.8e-3, 9.81, 0.1, 4.29, 5.6 / 1383  # the paper case at dp = 1 mm
    dt1, dt2, dt3 = math.sqrt(h / amax), h / (c0 + vmax), h * h / nu
    assert time_step(0.2, h, amax, vmax, c0, nu) == (0.2 * dt2, 1, (dt1, dt2, dt3))
    assert time_step(0.4, h, amax, vmax, c0, nu)[:2] == (0.4 * dt2, 1)  # one C: the acoustic limit
    # a fluid 5 times as viscous: its dt3 = 1.60e-4 s < dt2 = 4.10e-4 s, the viscous limit binds
    dt3_viscous = h * h / (5 * nu)
    assert time_step(0.4, h, amax, vmax, c0, 5 * nu)[:2] == (0.4 * dt3_viscous, 2)
    assert time_step(0.4, h, amax, vmax, c0, 5 * nu, viscous_limit=False) == (0.4 * dt2, 1, (dt1, dt2, dt3_viscous))
    assert time_step(0.4, h, amax, vmax, c0, nu, cfl_acoustic=0.3)[:2] == (0.3 * dt2, 1)
