"""Shifting (SPEC section 6): a uniform lattice stays put, a disordered one is ordered."""
import numpy as np
import pytest

from solver.build import build_particles
from solver.run import run_scene
from solver.simulation import Simulation
from tests.conftest import example_scene

U = 0.05  # m/s: the skillen shift scales with |u|, so the lattice moves with both walls


def moving_channel(method, **physics):
    walls = example_scene("channel").to_dict()["walls"]
    for w in walls:
        w["velocity"], w["moving"] = [U, 0.0], True
    return example_scene("channel", walls=walls,
                         physics={"shifting": {"method": method, **physics}})


def disorder(x, z, kind, period, dp):
    """Std of nearest-neighbour distances of fluid particles, in dp (periodic in x)."""
    f = kind == 0
    dx = x[f][:, None] - x[f][None, :]
    dx -= period * np.round(dx / period)
    dz = z[f][:, None] - z[f][None, :]
    d = np.hypot(dx, dz)
    np.fill_diagonal(d, np.inf)
    return d.min(axis=1).std() / dp


@pytest.mark.parametrize("method", ["skillen", "lind"])
def test_uniform_lattice_is_not_shifted(method):
    scene = moving_channel(method)
    parts = build_particles(scene)
    parts.u[parts.kind == 0] = U
    sim = Simulation(scene, parts)
    x0 = sim.snapshot()
    res = run_scene(scene, sim=sim)
    assert res.status == "completed", res.reason
    x1 = sim.snapshot()
    f = x0["kind"] == 0
    period = scene.periodic_x[1]
    moved = np.mod(x1["x"][f] - x0["x"][f] - U * sim.t + period / 2, period) - period / 2
    assert sim.steps > 50
    assert np.abs(moved).max() < 1e-6 * scene.dp
    assert np.abs(x1["z"][f] - x0["z"][f]).max() < 1e-6 * scene.dp


@pytest.mark.parametrize("method", ["skillen", "lind"])
def test_shifting_reduces_disorder(method):
    scene = moving_channel(method)
    parts = build_particles(scene)
    f = parts.kind == 0
    rng = np.random.default_rng(7)
    parts.x[f] += rng.uniform(-0.2, 0.2, f.sum()) * scene.dp
    parts.z[f] += rng.uniform(-0.2, 0.2, f.sum()) * scene.dp
    parts.u[f] = U
    sim = Simulation(scene, parts)
    period = scene.periodic_x[1]
    before = disorder(sim.x, sim.z, sim.kind, period, scene.dp)
    # skillen shifts in proportion to the distance travelled, |u| dt: iterate as if the
    # fluid moved 0.1 h each time (lind ignores dt)
    for _ in range(30):
        sim.shift_only(0.1 * scene.h / U)
    after = disorder(sim.x, sim.z, sim.kind, period, scene.dp)
    assert after < 0.5 * before, (before, after)


def test_shifting_off_leaves_disorder():
    """Control for the test above: without shifting the same calls change nothing."""
    scene = example_scene("channel")
    parts = build_particles(scene)
    f = parts.kind == 0
    parts.x[f] += np.random.default_rng(7).uniform(-0.2, 0.2, f.sum()) * scene.dp
    sim = Simulation(scene, parts)
    before = sim.snapshot()["x"]
    sim.derivatives()
    assert np.array_equal(sim.snapshot()["x"], before)
