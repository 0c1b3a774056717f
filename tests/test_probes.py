"""Probes on synthetic particle fields with known answers (no time stepping)."""

import numpy as np
import pytest

from solver.build import build_particles
from solver.probes import FieldSampler, toe_position
from solver.scene import scene_from_dict
from solver.simulation import Simulation

pytestmark = pytest.mark.slow  # runs the solver or Snakemake

DP = 1.0e-3
H = 0.02


def layer_sim(u_of_z=None, ch=1.8, length=0.1):
    """A fluid block of depth H on a bed (no periodicity), with u = u_of_z(z)."""
    scene = scene_from_dict({
        "dp": DP, "ch": ch,
        "fluid": {"density": 1000.0, "viscosity": 1.0, "blocks": [{"x": [0.0, length], "z": [0.0, H]}]},
        "walls": [{"name": "bed", "x": [-0.005, length + 0.02], "z": [-0.004, 0.0]}],
        "sound": {"c0": 5.0}, "time": {"end": 1.0, "output_interval": 1.0}})
    parts = build_particles(scene)
    if u_of_z is not None:
        f = parts.kind == 0
        parts.u[f] = u_of_z(parts.z[f])
    return Simulation(scene, parts)


@pytest.mark.parametrize("ch", [1.3, 1.8, 2.2])
def test_planar_free_surface_is_found_at_the_continuum_surface(ch):
    sim = layer_sim(ch=ch)
    xs = np.linspace(0.03, 0.07, 9)
    zs = FieldSampler(sim).surface(xs, 0.0)
    # the C = 0.5 level of a lattice half space sits on its edge, dp/2 above the top row
    np.testing.assert_allclose(zs, H, atol=0.1 * DP)


def test_surface_over_dry_bed_is_the_bed():
    sim = layer_sim()
    zs = FieldSampler(sim).surface(np.array([0.105, 0.11]), 0.0)
    np.testing.assert_allclose(zs, 0.0, atol=0.1 * DP)


@pytest.mark.parametrize("profile", ["linear", "semi-parabolic"])
def test_velocity_line_profile(profile):
    U = 0.1
    if profile == "linear":
        f = lambda z: U * z / H  # noqa: E731
    else:
        f = lambda z: U * (2 * z / H - (z / H) ** 2)  # noqa: E731
    sim = layer_sim(f)
    z = np.linspace(0.0, H, 41)
    out = FieldSampler(sim).points(np.full(z.size, 0.05), z)
    inside = out[0] >= 0.5
    assert inside[:-1].all()  # every point below the surface counts as fluid
    u = out[2][inside]
    err = np.abs(u - f(z[inside]))
    # the linear moving-least-squares fit reproduces a linear field exactly, one-sided stencil
    # at the bed and the surface included; for the parabola (curvature 2U/H^2) its error is the
    # second-moment term, below U (h/H)^2 everywhere (measured: 0.15 of that, at the bed)
    h = sim.h
    tol = 1e-9 * U if profile == "linear" else U * (h / H) ** 2
    assert err.max() <= tol


def test_velocity_falls_back_to_shepard_on_a_single_row():
    """A line of particles cannot fix a linear fit across it: the probe then returns the
    Shepard mean, which for a uniform row is the row's velocity."""
    scene = scene_from_dict({
        "dp": DP, "ch": 1.8,
        "fluid": {"density": 1000.0, "viscosity": 1.0, "blocks": [{"x": [0.0, 0.05], "z": [0.0, DP]}]},
        "walls": [{"name": "bed", "x": [-0.005, 0.07], "z": [-0.004, 0.0]}],
        "sound": {"c0": 5.0}, "time": {"end": 1.0, "output_interval": 1.0}})
    parts = build_particles(scene)
    parts.u[parts.kind == 0] = 0.3
    out = FieldSampler(Simulation(scene, parts)).points(np.full(3, 0.025), np.array([0.0, 0.5 * DP, DP]))
    np.testing.assert_allclose(out[2], 0.3, rtol=1e-12)


def test_toe_of_a_block_and_stray_particle():
    rng = np.random.default_rng(0)
    xs = np.concatenate([rng.uniform(0.0, 0.3, 5000), [0.3 + 5 * DP]])  # one stray 5 dp ahead
    toe = toe_position(xs, DP)
    assert toe == pytest.approx(xs[:-1].max() + 0.5 * DP)
    sim = layer_sim()
    n = sim.n_active
    assert toe_position(sim.x[:n][sim.kind[:n] == 0], DP) == pytest.approx(0.1, abs=1e-12)


def test_number_density_on_a_lattice_is_one():
    sim = layer_sim(ch=1.8)
    out = FieldSampler(sim).points(np.full(5, 0.05), np.linspace(0.006, 0.014, 5))
    np.testing.assert_allclose(out[4] * DP * DP, 1.0, atol=0.005)
