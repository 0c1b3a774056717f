"""Volume relaxation (solver/packing.py): rho_a *= 1 + clip(beta c0 dt / h (C_a / C_0 - 1))
for interior fluid particles, C_a = sum_b (m_b / rho_b) W_ab."""
import numpy as np
import pytest

from solver import packing
from solver.build import build_particles
from solver.scene import SceneError
from solver.simulation import Simulation
from tests.conftest import example_scene

BETA = 0.1


def channel_sim(volume_scale: float = 1.0, shifting: str = "lind") -> Simulation:
    """The closed channel at rest with ``shifting`` and the relaxation; the fluid particles'
    volumes m / rho scaled by ``volume_scale`` (their spacing unchanged)."""
    scene = example_scene("channel", numerics={"shifting": {"method": shifting},
                                               "volume_relaxation": BETA})
    parts = build_particles(scene)
    parts.mass[parts.kind == 0] *= volume_scale
    return Simulation(scene, parts)


def relaxed_change(sim: Simulation) -> np.ndarray:
    """rho_new / rho - 1 of one relaxation step at the step's dt (the evaluation is current)."""
    rho0 = sim.rho.copy()
    sim._relax_volume(sim.info.dt)
    return sim.rho / rho0 - 1.0


def concentration(sim: Simulation) -> np.ndarray:
    return sim.out[sim.slots.VOLC] + sim.mass / sim.rho * 7.0 / (4.0 * np.pi * sim.h ** 2)


@pytest.mark.parametrize("shifting", ["lind", "none"])
def test_a_lattice_is_at_the_lattice_concentration_and_is_left_alone(shifting):
    """With or without shifting: the relaxation needs only the packing sums, which the pair loop
    computes for it when shifting is off."""
    sim = channel_sim(shifting=shifting)
    f = sim.kind == 0
    np.testing.assert_allclose(concentration(sim)[f], sim.n_lattice, rtol=1e-12)
    assert np.abs(relaxed_change(sim)).max() < 1e-14


def test_without_shifting_the_relaxation_keeps_a_lattice_at_rest():
    """Shifting none with the relaxation: the scene is accepted and runs, and the channel's
    lattice at rest stays at rest, in place and at rho0, step after step."""
    sim = channel_sim(shifting="none")
    assert sim.pair_options.packing == 2 and sim.slots.VOLC >= 0
    x0 = sim.snapshot()
    for _ in range(20):
        assert sim.step() == ""
    x1 = sim.snapshot()
    f = x0["kind"] == 0
    dp = sim.scene.dp
    assert np.abs(x1["x"][f] - x0["x"][f]).max() < 1e-12 * dp
    assert np.abs(x1["z"][f] - x0["z"][f]).max() < 1e-12 * dp
    assert np.abs(x1["rho"][f] / sim.rho0 - 1.0).max() < 1e-12


@pytest.mark.parametrize("scale", [1.0 / 1.001, 1.001])
def test_loose_and_crowded_packing_move_the_density_at_the_stated_rate(scale):
    """Volumes 0.1 % smaller than the space (loose) lower rho; 0.1 % larger (crowded) raise it,
    by lambda (C / C_0 - 1) with lambda = beta c0 dt / h (the walls, at their own volumes,
    make C / C_0 - 1 less than 0.1 % in magnitude next to them)."""
    sim = channel_sim(scale)
    f = sim.kind == 0
    c = concentration(sim)[f] / sim.n_lattice
    lam = BETA * sim.c0 * sim.info.dt / sim.h
    change = relaxed_change(sim)
    np.testing.assert_allclose(change[f], lam * (c - 1.0), rtol=1e-9, atol=1e-15)
    assert np.all(np.sign(change[f]) == np.sign(scale - 1.0))
    assert np.abs(c - scale).max() <= abs(scale - 1.0) + 1e-12  # interior exactly `scale`
    assert np.all(change[~f] == 0.0)


def test_loose_packing_is_limited_per_step():
    """A fifth of the space empty: the change is clipped to LIMIT per step."""
    sim = channel_sim(1.0 / 1.21)
    f = sim.kind == 0
    change = relaxed_change(sim)[f]
    lam = BETA * sim.c0 * sim.info.dt / sim.h
    assert lam * (1.0 / 1.21 - 1.0) < -packing.LIMIT  # the rate alone would exceed it
    np.testing.assert_allclose(change, -packing.LIMIT, rtol=1e-12)


def test_a_free_surface_is_not_taken_for_loose_packing():
    """The tank at rest: the rows whose kernel reaches past the surface (the missing row above
    the top one within 2h) have C down to 0.75 and keep their density; below them the
    lattice is at C_0 but for the particles next to the walls, whose mDBC densities make C
    up to 0.3 % low (measured), so nothing moves by more than lambda 0.4 %."""
    scene = example_scene("hydrostatic", numerics={"shifting": {"method": "lind"},
                                                  "volume_relaxation": BETA})
    sim = Simulation(scene)
    f = sim.kind == 0
    near = f & (sim.z > sim.z[f].max() + scene.dp - 2.0 * sim.h)
    assert concentration(sim)[near].min() < 0.8  # relaxed, these would lose LIMIT
    change = relaxed_change(sim)
    assert np.all(change[near] == 0.0)
    lam = BETA * sim.c0 * sim.info.dt / sim.h
    assert np.abs(change[f]).max() < lam * 0.004


@pytest.mark.parametrize("numerics, message", [
    ({"volume_relaxation": -1.0, "shifting": {"method": "lind"}}, "beta > 0"),
    ({"volume_relaxation": 0.0}, "beta > 0"),
    ({"volume_relaxation": "fast", "shifting": {"method": "lind"}}, "expected a number"),
])
def test_bad_settings_name_the_key(numerics, message):
    with pytest.raises(SceneError, match=f"numerics.volume_relaxation: .*{message}"):
        example_scene("channel", numerics=numerics)
