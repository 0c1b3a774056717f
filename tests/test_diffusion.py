"""Fourtakas density diffusion (docs/scheme.md section 6): diffusive, and silent on a column at rest."""
import math

import numpy as np
import pytest

from solver.build import build_particles
from solver.run import run_scene
from solver.simulation import Simulation
from tests.conftest import example_scene


def sine_channel(delta, eps=1e-3):
    """Channel at rest with rho = rho0 (1 + eps sin(k x)); returns (sim, k)."""
    scene = example_scene("channel", numerics={"density_diffusion": delta})
    parts = build_particles(scene)
    L = scene.periodic_x[1] - scene.periodic_x[0]
    k = 2 * math.pi / L
    fl = parts.kind == 0
    parts.rho[fl] = scene.fluid.density * (1 + eps * np.sin(k * parts.x[fl]))
    parts.mass[fl] = parts.rho[fl] * scene.dp ** 2
    return Simulation(scene, parts), k


@pytest.mark.slow
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


@pytest.mark.slow
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


def diffusion_rate_at_rest(reference, dp, ch):
    """|drho/dt| / rho of the diffusion term alone on the hydrostatic tank at rest, and the
    bulk rate the paper's rho^H leaves, 11 delta h g^2 / c0^3 (see the next test)."""
    phys = {"density_diffusion_reference": reference}
    on = Simulation(example_scene("hydrostatic", dp=dp, ch=ch, numerics=phys))
    off = Simulation(example_scene("hydrostatic", dp=dp, ch=ch, numerics={"density_diffusion": None}))
    d_on, d_off = on.derivatives(), off.derivatives()
    s = on.snapshot()
    fl = s["kind"] == 0
    rate = (d_on["drho"][fl] - d_off["drho"][fl]) / s["rho"][fl]
    sc = on.scene
    return rate, s["z"][fl], 11 * 0.1 * sc.h * sc.gravity[1] ** 2 / sc.c0 ** 3


@pytest.mark.slow
def test_spec_reference_leaves_a_bulk_density_sink_on_a_column_at_rest():
    """the paper's rho^H_ab = rho0 ((1 + x)^(1/7) - 1) is exact only for a pair whose upper
    particle is at zero pressure: its curvature in z_b - z_a has the opposite sign to the
    Tait column's. In the bulk the sum leaves drho/dt / rho = -11 delta h g^2 / c0^3
    (the kernel-sum Laplacian of the (11/98) rho0 k^2 dz^2 mismatch, k = 7 g / c0^2), and
    the one-sided sums at the bed and surface rows leave more. Checked to 5 %."""
    for dp, ch in ((2e-3, 1.5), (1e-3, 1.8)):
        rate, z, bulk = diffusion_rate_at_rest("spec", dp, ch)
        H = z.max()
        mid = (z > 0.3 * H) & (z < 0.7 * H)
        np.testing.assert_allclose(np.median(rate[mid]), -bulk, rtol=0.05)


@pytest.mark.slow
def test_column_reference_vanishes_on_a_column_at_rest():
    """u = 0 and rho the Tait column at rest (rho^6 linear in depth): the "column" rho^H_ab
    cancels rho_a - rho_b for every pair, bed and surface rows included. Bound: a
    thousandth of the bulk sink the paper's form leaves (measured: 4e-5 of it)."""
    for dp, ch in ((2e-3, 1.5), (1e-3, 1.8)):
        rate, _, bulk = diffusion_rate_at_rest("column", dp, ch)
        assert np.abs(rate).max() < 1e-3 * bulk, (dp, np.abs(rate).max(), bulk)


def test_hydrostatic_pair_series_matches_pow():
    """rho^H_ab's (1 +- x)^(1/7) - 1: the series below SERIES_MAX within 1.1e-12 of pow,
    pow beyond it."""
    from solver.forces import SERIES_MAX, hydrostatic_pair
    for x in np.linspace(-0.999 * SERIES_MAX, 0.999 * SERIES_MAX, 401).tolist() + [0.05, -0.3]:
        fa, fb = hydrostatic_pair(x)
        assert abs(fa - ((1 + x) ** (1 / 7) - 1)) < 1.1e-12
        assert abs(fb - ((1 - x) ** (1 / 7) - 1)) < 1.1e-12
