"""Solver against the exact solutions of docs/scheme.md section 7."""
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
    scene = example_scene(name, numerics={"mdbc_velocity": velocity})
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


L_CHANNEL = 1.0e-3

# L2 error bounds, % of the velocity scale (u_max of Poiseuille, U0 of Couette) at
# t = 0.0225, 0.1125, 0.225 s. Each is the value measured on 2026-11-23 (2 threads) plus a
# 25 % margin, rounded up: measured Poiseuille Shepard 0.093, 0.737, 1.214, corrected 0.229,
# 0.653, 1.089; Couette Shepard 1.083, 0.687, 0.550, corrected 0.177, 0.239, 0.154.
BOUNDS = {
    ("poiseuille", "shepard"): (0.12, 0.93, 1.52),
    ("poiseuille", "corrected"): (0.29, 0.82, 1.37),
    ("couette", "shepard"): (1.36, 0.86, 0.69),
    ("couette", "corrected"): (0.23, 0.30, 0.20),
}
_ERRORS = {}


def channel_errors(case: str, velocity: str) -> dict[float, float]:
    """{t: L2 error / velocity scale} of a start-up channel case (computed once per session)."""
    if (case, velocity) not in _ERRORS:
        L = L_CHANNEL
        if case == "poiseuille":
            scene, errors = startup_channel_errors(
                case, velocity, lambda sc, z, t: exact.poiseuille(z, t, L, sc.gravity[0], sc.nu))
            scale = scene.gravity[0] * L ** 2 / (8 * scene.nu)
        else:
            scene, errors = startup_channel_errors(
                case, velocity, lambda sc, z, t: exact.couette(z, t, L, sc.walls[1].velocity[0], sc.nu))
            scale = scene.walls[1].velocity[0]
        _ERRORS[case, velocity] = {t: e / scale for t, e in sorted(errors.items())}
    return _ERRORS[case, velocity]


@pytest.mark.parametrize("case, velocity", list(BOUNDS))
def test_startup_channel_flow(case, velocity):
    errors = channel_errors(case, velocity)
    for (t, err), bound in zip(errors.items(), BOUNDS[case, velocity]):
        assert 100 * err <= bound, f"t = {t}: L2 = {100 * err:.3f} % of the velocity scale"


def test_corrected_ghost_velocity_gains_on_couette():
    """The first-order corrected ghost velocity removes most of the wall-slip error of the
    Shepard ghost velocity where the wall moves (Couette: 3.7x to 6.1x measured); on
    Poiseuille, driven by a body force with walls at rest, it gains nothing at the start."""
    shepard, corrected = channel_errors("couette", "shepard"), channel_errors("couette", "corrected")
    for t in shepard:
        assert corrected[t] <= shepard[t] / 2.5, f"t = {t}: {corrected[t]:.5f} vs {shepard[t]:.5f}"


def test_film_error_of_a_layer_at_rest_is_the_profiles_own_rms():
    """u = 0 on evenly spaced depths: sqrt(mean (2 zeta - zeta^2)^2) = sqrt(8 / 15) of the
    surface velocity (midpoint rule on 4000 depths: within 1e-6); the exact film scores 0."""
    H, g, nu = 0.02, 2.5, 4e-3
    z = (np.arange(4000) + 0.5) / 4000 * H
    assert exact.film_rms_error(z, np.zeros_like(z), H, g, nu) == pytest.approx(math.sqrt(8 / 15), abs=1e-6)
    assert exact.film_rms_error(z, exact.film(z, H, g, nu), H, g, nu) == 0.0


def test_film_on_incline_reaches_semi_parabolic_profile():
    scene = example_scene("film")
    res = run_scene(scene)
    assert res.status == "completed", res.reason
    H = scene.fluid.blocks[0].z[1]
    s = fluid(res.snaps[-1])
    u_surface = exact.film(H, H, scene.gravity[0], scene.nu)
    assert exact.film_rms_error(s["z"], s["u"], H, scene.gravity[0], scene.nu) <= 0.02
    # the layer is uniform along x: no wall-normal drift
    assert np.abs(s["w"]).max() < 1e-3 * u_surface


def test_a_users_csv_reference_scores_a_run_and_refuses_a_shifted_one(tmp_path):
    """The start-up Poiseuille channel at t = 0.225 s against its exact profile written as a user's
    CSV reference, scored as a user campaign scores it (study.flows.scores.user_scores on the
    run's dataset): within 2 % of the reference's largest speed (measured 1.5 %); against the
    reference raised by 5 % it is not (measured 4.8 %)."""
    from solver.output import to_dataset
    from study.flows.scores import user_scores
    from study.references.user import read_velocity_profiles
    scene = example_scene("poiseuille")
    res = run_scene(scene)
    assert res.status == "completed", res.reason
    run = to_dataset(res)
    L, F, nu = L_CHANNEL, scene.gravity[0], scene.nu
    t_end = res.snap_time[-1]
    z_ref = np.linspace(0.05, 0.95, 19) * L
    errors = {}
    for shift in (1.0, 1.05):
        path = tmp_path / f"ref_{shift:g}.csv"
        lines = ["# exact start-up Poiseuille profile", "x,z,u"]
        lines += [f"2.5e-4,{z:.9g},{shift * u:.9g}" for z, u in zip(z_ref, exact.poiseuille(z_ref, t_end, L, F, nu))]
        path.write_text("\n".join(lines) + "\n")
        scored = user_scores(run, {"velocity": read_velocity_profiles(path)}, 0.0, False)
        errors[shift] = scored["velocity_error"]
    assert errors[1.0] <= 0.02, errors
    assert errors[1.05] > 0.02, errors


def test_film_start_up_follows_the_exact_series():
    """examples/film.yaml starts from rest: at every output time to 0.3 s (3.4 viscous times
    H^2 / nu) its velocity is within 1 % of u_max of the start-up series of study.references.film,
    rms over the fluid particles (measured 0.51-0.79 %)."""
    from study.references import film
    scene = example_scene("film")
    res = run_scene(scene)
    assert res.status == "completed", res.reason
    H = scene.fluid.blocks[0].z[1]
    g = math.hypot(*scene.gravity)
    theta = math.atan2(scene.gravity[0], -scene.gravity[1])
    u_max = film.u_max(H, scene.nu, g, theta)
    assert len(res.snaps) == 7
    for t, snap in zip(res.snap_time[1:], res.snaps[1:]):
        s = fluid(snap)
        err = np.sqrt(np.mean((s["u"] - film.velocity(s["z"], t, H, scene.nu, g, theta)) ** 2)) / u_max
        assert err <= 0.01, f"t = {t:.3f} s: {100 * err:.2f} % of u_max"
