"""Herschel-Bulkley rheology against exact steady solutions (solver/exact.py).

Each case runs to steady state at 20 particles across; bounds are the values measured on
2026-11-23 plus a stated margin. The Newtonian tests are untouched: a Newtonian fluid
compiles the constant-viscosity loop as before.
"""
import math

import numpy as np
import pytest

from solver import exact, rheology
from solver.scene import SceneError
from solver.simulation import Simulation
from tests.conftest import example_dict, example_scene

L_CHANNEL = 1.0e-3
# (measured, bound) at t = 0.6 s: the L2 error falls to 2.10 % at 1.2 s and stays at 2.0-2.2 %
# to 3 s, so the 2 % is not met at this resolution (hb_film_fine.yaml meets it); the
# bound is the measurement plus 20 %.
# Measured with the explicit update (0.0251) and with the example's implicit one (0.02505 at
# cfl 0.2, 0.02500 at the example's cfl 0.4).
HB_FILM_L2 = (0.0251, 0.030)
# the computed plug is 6 % thinner than the exact 7.73 mm (5.6 % at 1.2 s): measured value
# and the allowed deviation from it
HB_FILM_YIELD = (-0.060, 0.025)


def steady_state(name: str, **changes):
    """(scene, fluid z, u, strain rate, nu_p) after the scene's end time."""
    scene = example_scene(name, **changes)
    sim = Simulation(scene)
    while sim.t < scene.time.end - 1e-12:
        reason = sim.step()
        assert not reason, reason
    sim._evaluate(sim.t)  # the gradient sums of the final state
    n = sim.n_active
    idx = np.flatnonzero(sim.kind[:n] == 0)
    gamma = np.array([rheology.strain_rate(sim.out, i, sim.slots) for i in idx])
    return scene, sim.z[idx], sim.u[idx], gamma, sim.nu_p[idx]


def l2(u, ue, scale):
    return float(np.sqrt(np.mean((u - ue) ** 2)) / scale)


def periodic_strip(name: str, width: float) -> dict:
    """Changes that run a film example on a periodic strip ``width`` wide: the film is
    uniform along x, so the strip only sets how many columns the row means average."""
    d = example_dict(name)
    return {"fluid": {"blocks": [{**d["fluid"]["blocks"][0], "x": [0.0, width]}]},
            "walls": [{**w, "x": [0.0, width]} for w in d["walls"]], "periodic_x": [0.0, width]}


def film_errors(name: str, width: float | None = None, **changes):
    """(L2 error of u over the plug velocity, largest deviation of a particle above the exact
    yield surface from the plug velocity, relative error of the computed plug thickness) of a
    Herschel-Bulkley film example at its end time (on a periodic strip ``width`` wide if
    given, else the example's; ``changes`` merged into the scene)."""
    scene, z, u, gamma, nu = steady_state(name, **(periodic_strip(name, width) if width else {}), **changes)
    f = scene.fluid
    H = f.blocks[0].z[1]
    g_s = scene.gravity[0]
    ue = exact.herschel_bulkley_film(z, H, g_s, f.density, f.yield_stress, f.consistency, f.index)
    u_plug = exact.herschel_bulkley_film(H, H, g_s, f.density, f.yield_stress, f.consistency, f.index)
    h0 = H - f.yield_stress / (f.density * g_s)
    rows = np.round(z / scene.dp - 0.5).astype(int)
    zr = np.array([z[rows == r].mean() for r in np.unique(rows)])
    tau = np.array([(nu * f.density * gamma)[rows == r].mean() for r in np.unique(rows)])
    k = np.flatnonzero(tau < f.yield_stress)[0]
    z_yield = zr[k - 1] + (tau[k - 1] - f.yield_stress) / (tau[k - 1] - tau[k]) * (zr[k] - zr[k - 1])
    return (l2(u, ue, u_plug), float(np.abs(u[z > h0] / u_plug - 1).max()),
            ((H - z_yield) - (H - h0)) / (H - h0))


@pytest.mark.slow
def test_bingham_channel():
    """Bingham plane Poiseuille flow: the sheared layers and the plug. Measured: L2 error
    0.88 % of the plug velocity; the fluid inside the exact plug (|z - L/2| < 0.2 mm) moves
    within 0.9 % of the exact plug velocity."""
    scene, z, u, _, _ = steady_state("bingham")
    f = scene.fluid
    ue = exact.herschel_bulkley_channel(z, L_CHANNEL, scene.gravity[0], f.density, f.yield_stress,
                                        f.consistency, f.index)
    u_plug = ue.max()
    assert l2(u, ue, u_plug) < 0.012  # measured 0.0088
    s0 = f.yield_stress / (f.density * scene.gravity[0])
    plug = np.abs(z - L_CHANNEL / 2) < s0
    assert np.abs(u[plug] / u_plug - 1).max() < 0.012  # measured 0.009 (row means)


@pytest.mark.slow
def test_power_law_channel():
    """Shear-thinning (n = 0.5) plane Poiseuille flow. Measured: L2 error 0.33 % of the
    centre-line velocity."""
    scene, z, u, _, _ = steady_state("powerlaw")
    f = scene.fluid
    ue = exact.herschel_bulkley_channel(z, L_CHANNEL, scene.gravity[0], f.density, 0.0,
                                        f.consistency, f.index)
    assert l2(u, ue, ue.max()) < 0.005  # measured 0.0033


@pytest.mark.slow
@pytest.mark.parametrize("form", ["laminar", "stress"])
def test_herschel_bulkley_film(form):
    """Carbopol-like film (tau_y = 20 Pa, K = 10 Pa s^n, n = 0.4) on the 15.3 deg incline.
    Velocity: see HB_FILM_L2. Plug: every particle above the exact yield surface h0 moves
    within 1 % of the exact plug velocity (measured 0.77 % with the example's implicit
    viscosity at cfl 0.4, 0.75 % at cfl 0.2, 0.73 % explicit); the computed yield surface (where the particle stress
    mu(gamma) gamma falls to tau_y) lies HB_FILM_YIELD above h0. The same bounds hold with the
    stress form, whose extra term vanishes in the exact film but not in its particle noise
    (measured L2 2.53 %, plug 0.82 %)."""
    err, plug_speed, plug_error = film_errors("hb_film", numerics={"viscous_form": form})
    assert err < HB_FILM_L2[1], (err, HB_FILM_L2)
    assert plug_speed < 0.01  # measured 0.0075
    assert abs(plug_error - HB_FILM_YIELD[0]) < HB_FILM_YIELD[1], plug_error


def test_rheology_keys_are_validated():
    from solver.scene import scene_from_dict
    base = example_scene("bingham").to_dict()
    for change, key in (({"rheology": "bingham"}, "fluid.rheology"),
                        ({"max_viscosity": None}, "fluid.max_viscosity"),
                        ({"consistency": -1.0}, "fluid.consistency"),
                        ({"viscosity": 1.0}, "fluid.viscosity")):
        d = {**base, "fluid": {**base["fluid"], **change}}
        with pytest.raises(SceneError, match=key.replace(".", r"\.")):
            scene_from_dict(d)


def test_effective_viscosity_law():
    """mu = min(mu_max, tau_y / gamma + K gamma^(n-1)); Papanastasiou: tau_y (1 - e^(-m gamma)) / gamma."""
    tau_y, K, n, mu_max = 20.0, 10.0, 0.4, 100.0
    for g in (0.01, 0.3, 5.0, 50.0):
        bi = rheology.effective_viscosity(g, tau_y, K, n, mu_max, 0.0)
        assert bi == pytest.approx(min(mu_max, tau_y / g + K * g ** (n - 1)))
        pap = rheology.effective_viscosity(g, tau_y, K, n, mu_max, 100.0)
        assert pap == pytest.approx(min(mu_max, tau_y * (1 - math.exp(-100 * g)) / g + K * g ** (n - 1)))
    assert rheology.effective_viscosity(0.0, tau_y, K, n, mu_max, 0.0) == mu_max


@pytest.mark.slow
def test_herschel_bulkley_film_at_forty_particles_meets_the_targets():
    """hb_film_fine.yaml: 40 particles across, mu_max 105 times the bed viscosity, the
    corrected strain rate, implicit viscosity at cfl 0.4, to 1.2 s, here on a strip of 10
    columns (the example's 40 give the same three figures to the printed digit, in 116 s
    against 32 s). Targets: L2 error below
    2 % of the plug velocity (measured 1.47 %; 1.48 % at cfl 0.2, and 1.50-1.66 % from 1.5 s
    to 3 s) and the computed plug within 5 % of the exact 7.73 mm (measured -1.5 %; -1.2 to
    -1.7 % to 3 s at cfl 0.2). Every particle
    above the exact yield surface moves within 2.5 % of the plug velocity (measured 1.92 %:
    the capped plug creeps by rho g sin(theta) (H - h0)^2 / (2 mu_max) = 0.4 %, and the
    yielded layer still over-shears by about 1 %)."""
    err, plug_speed, plug = film_errors("hb_film_fine", width=0.005)
    assert err < 0.02, err
    assert abs(plug) < 0.05, plug
    assert plug_speed < 0.025, plug_speed


def viscosity_error_on_the_exact_film(correction: bool, dp: float = 1.0e-3):
    """mu_solver / mu(gamma_exact) - 1 of the particles in three bands of the yielded layer
    (z/H 0.1-0.3, 0.3-0.45, 0.45-0.52; the yield surface is at 0.61 H), with the particles
    given the exact Herschel-Bulkley film profile and the solver's viscosity evaluated twice
    (the corrected strain rate uses the previous evaluation's Laplacian)."""
    from solver.build import build_particles
    sc = example_scene("hb_film", dp=dp, fluid={"strain_rate_correction": correction})
    p = build_particles(sc)
    f = sc.fluid
    H, g = f.blocks[0].z[1], sc.gravity[0]
    fl = p.kind == 0
    p.u[fl] = exact.herschel_bulkley_film(p.z[fl], H, g, f.density, f.yield_stress, f.consistency, f.index)
    p.rho[:] = f.density
    sim = Simulation(sc, p)
    sim._evaluate(0.0)
    idx = np.flatnonzero(sim.kind[:sim.n_active] == 0)
    z, mu = sim.z[idx], sim.nu_p[idx] * f.density
    gamma = (np.maximum(f.density * g * (H - z) - f.yield_stress, 0.0) / f.consistency) ** (1 / f.index)
    mu_exact = np.array([rheology.effective_viscosity(gm, f.yield_stress, f.consistency, f.index,
                                                      f.max_viscosity, 0.0) for gm in gamma])
    return [mu[(z > lo * H) & (z < hi * H)] / mu_exact[(z > lo * H) & (z < hi * H)] - 1
            for lo, hi in ((0.1, 0.3), (0.3, 0.45), (0.45, 0.52))]


@pytest.mark.slow
def test_the_strain_rate_correction_removes_the_smoothing_bias_of_the_viscosity():
    """The exact film's strain rate, proportional to (h0 - z)^(1/n) = (h0 - z)^2.5, is convex,
    so its kernel average is too high and the viscosity too low: at dp = 1 mm the band means are -1.9, -4.9 and -12.4 %
    (measured). With fluid.strain_rate_correction (gamma - 5/36 h^2 lap gamma) they are -0.5,
    -0.5 and -0.9 %, every particle within 0.75 %, 0.57 % and 0.93 %."""
    plain = viscosity_error_on_the_exact_film(False)
    corrected = viscosity_error_on_the_exact_film(True)
    assert np.mean(plain[1]) < -0.03 and np.mean(plain[2]) < -0.08
    for band in corrected:
        assert np.abs(band).max() < 0.012, np.abs(band).max()
