"""Solver against the exact solutions of SPEC section 7."""
import math

import numpy as np
import pytest

from solver import exact
from solver.run import run_scene
from tests.conftest import example_scene

pytestmark = pytest.mark.slow  # runs the solver or Snakemake


def fluid(snap):
    f = snap["kind"] == 0
    return {k: v[f] for k, v in snap.items()}


def test_hydrostatic_layer_pressure_and_no_penetration():
    scene = example_scene("hydrostatic")
    res = run_scene(scene)
    assert res.status == "completed", res.reason
    H = scene.fluid.blocks[0].z[1]
    rho0, g = scene.fluid.density, -scene.gravity[1]
    scale = rho0 * g * H
    snap = fluid(res.snaps[-1])  # after 0.3 s, > 10 acoustic periods
    err = (snap["p"] - exact.hydrostatic_pressure(snap["z"], H, rho0, g)) / scale
    assert np.abs(err).max() <= 0.02
    # settled: velocities small against the free-fall speed over one dp
    assert np.hypot(snap["u"], snap["w"]).max() < 0.05 * math.sqrt(g * scene.dp)
    # no fluid particle ever inside a wall
    assert max(res.diag["max_penetration"]) == 0.0
    assert snap["z"].min() > 0.0 and snap["x"].min() > 0.0 and snap["x"].max() < 0.1


def startup_channel_errors(name, velocity, exact_u):
    """L2 error at t = 0.0225, 0.1125, 0.225 s of a start-up channel flow (20 particles across)."""
    scene = example_scene(name, physics={"mdbc_velocity": velocity})
    res = run_scene(scene)
    assert res.status == "completed", res.reason
    assert scene.fluid.blocks[0].z[1] / scene.dp >= 20
    errors = {}
    for t, snap in zip(res.snap_time, res.snaps):
        if min(abs(t - tc) for tc in (0.0225, 0.1125, 0.225)) > 1e-9:
            continue
        s = fluid(snap)
        errors[t] = np.sqrt(np.mean((s["u"] - exact_u(scene, s["z"], t)) ** 2))
    assert len(errors) == 3
    return scene, errors


@pytest.mark.parametrize("velocity", ["shepard", "corrected"])
def test_startup_poiseuille(velocity):
    L = 1.0e-3
    scene, errors = startup_channel_errors(
        "poiseuille", velocity, lambda sc, z, t: exact.poiseuille(z, t, L, sc.gravity[0], sc.nu))
    u_max = scene.gravity[0] * L ** 2 / (8 * scene.nu)
    for t, l2 in errors.items():
        assert l2 <= 0.02 * u_max, f"t = {t}: L2 = {l2 / u_max:.4f} u_max"


@pytest.mark.parametrize("velocity", ["shepard", "corrected"])
def test_startup_couette(velocity):
    L = 1.0e-3
    scene, errors = startup_channel_errors(
        "couette", velocity, lambda sc, z, t: exact.couette(z, t, L, sc.walls[1].velocity[0], sc.nu))
    U0 = scene.walls[1].velocity[0]
    for t, l2 in errors.items():
        assert l2 <= 0.02 * U0, f"t = {t}: L2 = {l2 / U0:.4f} U0"


def test_film_on_incline_reaches_semi_parabolic_profile():
    scene = example_scene("film")
    res = run_scene(scene)
    assert res.status == "completed", res.reason
    H = scene.fluid.blocks[0].z[1]
    s = fluid(res.snaps[-1])
    ue = exact.film(s["z"], H, scene.gravity[0], scene.nu)
    u_surface = exact.film(H, H, scene.gravity[0], scene.nu)
    l2 = np.sqrt(np.mean((s["u"] - ue) ** 2))
    assert l2 <= 0.02 * u_surface
    # the layer is uniform along x: no wall-normal drift
    assert np.abs(s["w"]).max() < 1e-3 * u_surface
