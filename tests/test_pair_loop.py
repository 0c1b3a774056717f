"""The pair loop finds every pair within 2h once: its sums against a direct sum over all pairs.

The loop visits each pair from a half stencil of z-sorted columns and lists each particle's
candidates within 2h before summing (solver/forces.py). Here a disordered, periodic fluid with
a moving wall below it, random velocities, densities and last shifts is evaluated once, and
every fluid particle's sums are compared with the same docs/scheme.md section 6 terms summed directly
over all particle pairs (nearest periodic image), which needs no neighbour search.
"""
import numpy as np
import pytest

from solver import forces
from solver.kernel import ETA2, grad_coefficient
from solver.scene import scene_from_dict
from solver.simulation import Simulation

DP = 1.0e-3
LENGTH, DEPTH = 20 * DP, 12 * DP


def disordered_layer(ch: float, seed: int = 3) -> Simulation:
    """A periodic layer LENGTH x DEPTH on a 4 dp bed that moves at 0.1 m/s, its fluid moved by up
    to 0.3 dp, with random velocities (0.05 m/s) and densities (1 %), and a last shift of up to
    0.02 dp (``last_shift``), not yet evaluated."""
    sim = Simulation(scene_from_dict({
        "name": "disordered", "dp": DP, "ch": ch,
        "fluid": {"density": 1000.0, "viscosity": 0.05, "blocks": [{"x": [0.0, LENGTH], "z": [0.0, DEPTH]}]},
        "walls": [{"name": "bed", "x": [0.0, LENGTH], "z": [-4 * DP, 0.0], "velocity": [0.1, 0.0]}],
        "gravity": [0.0, 0.0], "sound": {"c0": 10.0}, "periodic_x": [0.0, LENGTH],
        "numerics": {"density_diffusion": 0.1, "shifting": {"method": "skillen"}},
        "time": {"end": 1.0, "output_interval": 1.0}}))
    rng = np.random.default_rng(seed)
    fl = sim.kind == 0
    nf = int(fl.sum())
    sim.x[fl] += rng.uniform(-0.3, 0.3, nf) * DP
    sim.z[fl] += rng.uniform(-0.3, 0.3, nf) * DP
    sim.u[fl] = rng.normal(0.0, 0.05, nf)
    sim.w[fl] = rng.normal(0.0, 0.05, nf)
    sim.rho[fl] *= 1.0 + rng.uniform(-0.01, 0.01, nf)
    sim.shift_dx[fl], sim.shift_dz[fl] = last_shift(sim.x[fl], sim.z[fl])
    return sim


def last_shift(x, z):
    """A last shift of up to 0.02 dp as a function of position (the evaluation's sort reorders
    the particle arrays, and consumes the shift)."""
    return (0.02 * DP * np.sin(2 * np.pi * x / LENGTH + 3.0 * z / DP),
            0.02 * DP * np.cos(2 * np.pi * x / LENGTH - 2.0 * z / DP))


def direct_sums(sim: Simulation, sdx, sdz) -> dict:
    """docs/scheme.md section 6's pair sums of every particle over all others within 2h, by the nearest
    periodic image, from the arrays the pair loop read (``sdx``, ``sdz``: the last shift)."""
    n = sim.n_active
    x, z, u, w, p, m, kind, cell = (a[:n] for a in (sim.x, sim.z, sim.u, sim.w, sim.p, sim.mass, sim.kind,
                                                    sim.cell_volume))
    wnx, wnz = sim.wnx[:n], sim.wnz[:n]
    rho = 1.0 / sim.irho[:n]  # the density the loop read (the shift's correction came after it)
    h, nu, c0, delta = sim.h, sim.nu, sim.c0, sim.delta
    dx = x[:, None] - x[None, :]
    dx -= LENGTH * np.round(dx / LENGTH)
    dz = z[:, None] - z[None, :]
    r2 = dx * dx + dz * dz
    wall = kind == 1
    pair = (r2 < 4.0 * h * h) & ~(wall[:, None] & wall[None, :])
    np.fill_diagonal(pair, False)
    s = 1.0 - 0.5 * np.sqrt(r2) / h
    F = np.where(pair, grad_coefficient(h) * s ** 3, 0.0)
    V = m / rho
    du, dw = u[:, None] - u[None, :], w[:, None] - w[None, :]
    inv_r2e = 1.0 / (r2 + ETA2 * h * h)
    fluid_pair = ~(wall[:, None] | wall[None, :])
    drho = rho * ((F * (du * dx + dw * dz)) @ V)
    drho += 2.0 * delta * h * c0 * (np.where(fluid_pair, (rho[:, None] - rho[None, :]) * F * r2 * inv_r2e, 0.0) @ V)
    psum = p[:, None] + p[None, :]
    psum = np.where(wall[:, None] ^ wall[None, :], np.maximum(psum, 0.0), psum)
    pt = psum / (rho[:, None] * rho[None, :]) * F
    vt = 4.0 * nu * F * r2 / (rho[:, None] + rho[None, :]) * inv_r2e
    sl = sim.slots
    return {
        forces.AX: (-pt * dx + vt * du) @ m,
        forces.AZ: (-pt * dz + vt * dw) @ m,
        forces.DRHO: drho,
        sl.GCX: (F * dx) @ cell,
        sl.GCZ: (F * dz) @ cell,
        sl.DIVR: -(F * r2) @ cell,
        sl.WNX: -(F @ np.where(wall, wnx, 0.0)),
        sl.WNZ: -(F @ np.where(wall, wnz, 0.0)),
        sl.DIVDR: (F * ((sdx[None, :] - sdx[:, None]) * dx + (sdz[None, :] - sdz[:, None]) * dz)) @ V,
    }


@pytest.mark.parametrize("ch", [1.3, 1.8])
def test_the_pair_loop_sums_every_pair_within_2h_once(ch):
    """Every fluid particle's accelerations, density rate (continuity and Fourtakas diffusion),
    gradC, div r, wall-normal sum and div(dr) equal the direct sums to 1e-9 of each sum's
    largest value (round-off, summed in another order). A pair missed or counted twice changes
    a sum by more than that even at the edge of the support: a loop that drops the pairs with
    r^2 between 0.995 (2h)^2 and (2h)^2, whose weights are at most 1.6e-8 of the kernel
    gradient's scale, fails here."""
    sim = disordered_layer(ch)
    assert sim._evaluate(0.0) == ""
    n = sim.n_active
    fl = sim.kind[:n] == 0
    sdx, sdz = (np.where(fl, d, 0.0) for d in last_shift(sim.x[:n], sim.z[:n]))
    direct = direct_sums(sim, sdx, sdz)
    assert len(direct) == 9 and min(direct) >= 0  # with shifting, every slot is summed, each its own
    assert np.count_nonzero(direct[sim.slots.WNZ][fl]) > 20  # fluid particles within reach of the wall
    for slot, expected in direct.items():
        got = sim.out[slot][:n][fl]
        scale = np.abs(expected[fl]).max()
        assert scale > 0, slot
        np.testing.assert_allclose(got, expected[fl], rtol=0, atol=1e-9 * scale, err_msg=f"slot {slot}")
