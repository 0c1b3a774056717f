"""Fourtakas density diffusion (SPEC section 6): diffusive, and silent on a column at rest."""
import math

import numpy as np

from solver.build import build_particles
from solver.run import run_scene
from solver.simulation import Simulation
from tests.conftest import example_scene


def sine_channel(delta, eps=1e-3):
    """Channel at rest with rho = rho0 (1 + eps sin(k x)); returns (sim, k)."""
    scene = example_scene("channel", physics={"density_diffusion": delta})
    parts = build_particles(scene)
    L = scene.periodic_x[1] - scene.periodic_x[0]
    k = 2 * math.pi / L
    fl = parts.kind == 0
    parts.rho[fl] = scene.fluid.density * (1 + eps * np.sin(k * parts.x[fl]))
    parts.mass[fl] = parts.rho[fl] * scene.dp ** 2
    return Simulation(scene, parts), k


def test_diffusion_term_is_a_laplacian_with_coefficient_delta_h_c0():
    """At rest, drho/dt = h c0 D = delta h c0 lap(rho) = -delta h c0 k^2 (rho - rho0)."""
    eps, delta = 1e-3, 0.1
    sim, k = sine_channel(delta, eps)
    d = sim.derivatives()
    scene = sim.scene
    x, z = sim.snapshot()["x"], sim.snapshot()["z"]
    H = scene.fluid.blocks[0].z[1]
    interior = (sim.snapshot()["kind"] == 0) & (z > 2 * scene.h) & (z < H - 2 * scene.h)
    rho0 = scene.fluid.density
    expected = -delta * scene.h * scene.c0 * k ** 2 * rho0 * eps * np.sin(k * x[interior])
    amp = delta * scene.h * scene.c0 * k ** 2 * rho0 * eps
    # the kernel-sum Laplacian on a lattice at Ch = 1.5 is exact to 1.5 % (eta^2 = 0.01 h^2)
    np.testing.assert_allclose(d["drho"][interior], expected, atol=0.03 * amp)
    # and strictly opposite in sign to the bump wherever the bump is clear
    clear = np.abs(np.sin(k * x[interior])) > 0.3
    assert np.all(d["drho"][interior][clear] * expected[clear] > 0)


def test_density_bump_decays_faster_with_diffusion():
    def amplitude_after(delta):
        sim, _ = sine_channel(delta, 1e-3)
        res = run_scene(sim.scene, sim=sim)
        assert res.status == "completed", res.reason
        s = res.snaps[-1]
        fl = s["kind"] == 0
        return np.abs(s["rho"][fl] / sim.scene.fluid.density - 1).max()

    with_d, without_d = amplitude_after(0.1), amplitude_after(None)
    assert with_d < 0.8 * without_d


def test_diffusion_nearly_vanishes_on_hydrostatic_column():
    """u = 0 and rho hydrostatic: rho^H cancels the one-sided diffusion of the hydrostatic
    gradient at the bed and the free surface, up to the Tait curvature: rho^H_ab is
    linear in the pressure difference, the column's density is not, which leaves a relative
    residual of (6/7) P/B at depth P (SPEC's rho^H_ab, exactly as specified)."""
    on = Simulation(example_scene("hydrostatic"))
    off = Simulation(example_scene("hydrostatic", physics={"density_diffusion": None}))
    d_on, d_off = on.derivatives(), off.derivatives()
    fl = on.snapshot()["kind"] == 0
    diff = np.abs(d_on["drho"][fl] - d_off["drho"][fl]).max()
    sc = on.scene
    # scale of the one-sided diffusion of the hydrostatic gradient without rho^H:
    # delta c0 |d rho / dz| = delta c0 rho0 g / c0^2
    g, H = 9.81, sc.fluid.blocks[0].z[1]
    scale = 0.1 * sc.c0 * sc.fluid.density * g / sc.c0 ** 2
    curvature = 6.0 / 7.0 * (sc.fluid.density * g * H) / (sc.c0 ** 2 * sc.fluid.density / 7)
    assert diff < 1.5 * curvature * scale
    assert curvature < 0.1  # i.e. at least a tenfold cancellation here


def test_hydrostatic_pair_series_matches_pow():
    """rho^H_ab's (1 +- x)^(1/7) - 1: the series below SERIES_MAX within 1.1e-12 of pow,
    pow beyond it."""
    from solver.forces import SERIES_MAX, hydrostatic_pair
    for x in np.linspace(-0.999 * SERIES_MAX, 0.999 * SERIES_MAX, 401).tolist() + [0.05, -0.3]:
        fa, fb = hydrostatic_pair(x)
        assert abs(fa - ((1 + x) ** (1 / 7) - 1)) < 1.1e-12
        assert abs(fb - ((1 - x) ** (1 / 7) - 1)) < 1.1e-12
