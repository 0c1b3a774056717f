"""Lubrication theory of a Herschel-Bulkley front (solver/viscoplastic.py)."""
import math

import numpy as np
import pytest

from solver import lubrication
from solver.viscoplastic import HBFluid, driving_slope, front_profile, normal_depth

G, THETA, U_B = 9.81, math.radians(15.3), 0.075


def test_newtonian_limit_is_spec_section_5():
    newt = HBFluid(rho=1383.0, tau_y=0.0, K=5.6, n=1.0)
    h_n = normal_depth(newt, U_B, G, THETA)
    assert h_n == pytest.approx(lubrication.normal_depth(5.6, U_B, 1383.0, G, THETA), rel=1e-10)
    xi, eta = front_profile(newt, U_B, G, THETA, eta_max=0.99)
    assert np.interp(0.9, eta, xi) == pytest.approx(float(lubrication.xi_star(0.9, THETA)), rel=1e-4)
    z = np.linspace(0, 0.8 * h_n, 7)
    S = driving_slope(newt, 0.8 * h_n, U_B, G)
    assert newt.film(z, 0.8 * h_n, S, G) / U_B == pytest.approx(
        lubrication.belt_velocity(z / (0.8 * h_n)), rel=1e-9)


def test_carbopol_like_fluid():
    """rho 1000, tau_y 20 Pa, K 10 Pa s^n, n 0.4 on the paper's slope and belt: h_n about 2 cm;
    the flux relative to the belt is u_b h at every depth; the plug takes the top of the film."""
    fluid = HBFluid(rho=1000.0, tau_y=20.0, K=10.0, n=0.4)
    h_n = normal_depth(fluid, U_B, G, THETA)
    assert 0.015 < h_n < 0.03, h_n
    S = math.sin(THETA)
    assert fluid.flux(h_n, S, G) == pytest.approx(U_B * h_n, rel=1e-10)
    plug = fluid.tau_y / (fluid.rho * G * S)
    assert 0 < plug < h_n
    for eta in (0.2, 0.6, 0.95):
        h = eta * h_n
        Sh = driving_slope(fluid, h, U_B, G)
        assert Sh > S  # shallower than h_n: steeper driving slope
        assert fluid.flux(h, Sh, G) == pytest.approx(U_B * h, rel=1e-10)
    xi, eta = front_profile(fluid, U_B, G, THETA)
    assert np.all(np.diff(xi) > 0) and eta[-1] == pytest.approx(0.999)


HB_CASE = {"dp": 0.003, "rheology": "herschel_bulkley", "density": 1000.0, "yield_stress": 20.0,
           "consistency": 10.0, "index": 0.4, "max_viscosity": 100.0, "shifting": "skillen"}


def test_conveyor_case_for_a_yield_stress_fluid():
    from solver.conveyor import build_scene, case_from_dict, front_surface, initial_toe
    from solver.scene import SceneError
    c = case_from_dict(HB_CASE)
    fluid = HBFluid(rho=1000.0, tau_y=20.0, K=10.0, n=0.4)
    assert c.h_n == pytest.approx(normal_depth(fluid, U_B, G, THETA))
    scene = build_scene(c)
    assert scene.fluid.rheology == "herschel_bulkley" and scene.fluid.viscosity is None
    # the lubrication start keeps the area of a block of fluid_length h_n at depth h_n
    pts = np.array(front_surface(c))
    area = float(np.sum(np.diff(pts[:, 0]) * 0.5 * (pts[1:, 1] + pts[:-1, 1])))
    assert area == pytest.approx(c.fluid_length * c.h_n ** 2, rel=2e-3)
    assert initial_toe(c) > c.fluid_length * c.h_n
    with pytest.raises(SceneError, match="start_velocity"):
        case_from_dict({**HB_CASE, "start_velocity": "moving"})


def test_scheme_fluid_of_a_yield_stress_fluid_carries_r_times_the_flux():
    """The start's fluid for a film flux ratio r (solver/conveyor.py, scheme_fluid) has
    consistency K r^-n: its film carries r times the real film's flux at every depth and
    slope (the yield depth does not depend on K), so its zero-flux depth is the scheme's
    normal depth; the start keeps the area fluid_length h_n h_s."""
    from solver.conveyor import build_scene, case_from_dict, initial_toe, scheme_fluid
    from solver.build import build_particles
    c = case_from_dict({**HB_CASE, "dp": 2.0e-3})
    r = 0.73
    s = scheme_fluid(c, r)
    for h in (0.01, c.h_n, 0.03):
        for S in (0.2, math.sin(THETA), 0.4):
            assert s.hb_fluid.flux(h, S, G) == pytest.approx(r * c.hb_fluid.flux(h, S, G), rel=1e-12)
    assert r * c.hb_fluid.flux(s.h_n, math.sin(THETA), G) == pytest.approx(U_B * s.h_n, rel=1e-9)
    assert s.h_n > c.h_n
    p = build_particles(build_scene(c, flux_ratio=r))
    f = p.kind == 0
    area = (p.mass[f] / p.rho[f]).sum()
    # each column rounds to whole rows: at most half a row
    dz = s.h_n / round(s.h_n / c.dp)
    assert area == pytest.approx(c.fluid_length * c.h_n * s.h_n, abs=0.5 * dz * initial_toe(s))


def test_lubrication_start_velocity_of_a_yield_stress_fluid():
    """The Herschel-Bulkley film at the local depth: u = -U on the belt (no slip), a plug of
    uniform velocity above h0 = h - tau_y / (rho g S), and zero lab-frame flux in every column
    (the film's flux relative to the belt is U h)."""
    from solver.conveyor import build_scene, case_from_dict, lubrication_velocity
    c = case_from_dict({**HB_CASE, "start_velocity": "lubrication", "dp": 1.0e-3})
    scene = build_scene(c)
    assert c.running_start
    fluid = HBFluid(rho=1000.0, tau_y=20.0, K=10.0, n=0.4)
    s = np.linspace(0.0, 1.0, 4001)
    for x in (0.5 * c.h_n, 5 * c.h_n, 15 * c.h_n, 20.5 * c.h_n):  # taper, body, near the toe
        top = scene.fluid.profiles[0].top(x)
        u, w = lubrication_velocity(c, scene, np.full(s.size, x), s * top)
        U = -u[0]
        assert U > 0 and not w.any()
        assert abs(np.trapezoid(u, s)) < 1e-4 * U  # trapezoid error at the yield surface's kink
        S = driving_slope(fluid, top, U, G)
        h0 = top - 20.0 / (1000.0 * G * S)
        plug = s * top >= h0
        assert plug.any() and np.ptp(u[plug]) < 1e-12 * U


def test_reference_for_a_yield_stress_fluid():
    """The study's reference: Newtonian cases get docs/scheme.md section 5 unchanged; a HB case the
    film at each station's depth, with zero lab-frame flux (depth-mean belt-frame u* = 1)."""
    from solver.conveyor import case_from_dict
    from study.reference import theory, theory_for_case
    x, st, z = np.array([0.0, 1.0, 5.0]), [0.76, 1.5, 9.7], np.linspace(0, 1.3, 261)
    newt = case_from_dict({"dp": 0.003})
    a, b = theory_for_case(newt, x, st, z), theory(x, st, z, newt.slope_deg)
    assert np.allclose(a["velocity"].values, b["velocity"].values, equal_nan=True)
    ref = theory_for_case(case_from_dict(HB_CASE), x, st, z)
    for k, s in enumerate(st):
        eta = float(ref["station_depth"][k])
        u = ref["velocity"].values[k]
        inside = np.isfinite(u)
        mean = np.trapezoid(u[inside], z[inside]) / eta
        assert mean == pytest.approx(1.0, rel=0.02), s  # the z grid resolves the plug to 0.005 h_n


def test_the_slopes_at_many_depths_solve_the_flux_balance():
    """``driving_slopes`` (the front's thousands of depths at once): for a Newtonian fluid the
    exact S = 3 mu u_b / (rho g h^2); for a Herschel-Bulkley fluid q(h, S) = u_b h, each to
    round-off, and the one-depth ``driving_slope`` is the same."""
    from solver.viscoplastic import driving_slopes
    newt = HBFluid(1383.0, 0.0, 5.6, 1.0)
    h = np.linspace(0.05, 0.999, 40) * normal_depth(newt, U_B, G, THETA)
    np.testing.assert_allclose(driving_slopes(newt, h, U_B, G), 3 * 5.6 * U_B / (1383.0 * G * h * h), rtol=1e-11)
    hb = HBFluid(1383.0, 10.0, 5.6, 0.6)
    h = np.linspace(0.05, 0.999, 40) * normal_depth(hb, U_B, G, THETA)
    S = driving_slopes(hb, h, U_B, G)
    np.testing.assert_allclose(hb.fluxes(h, S, G), U_B * h, rtol=1e-11)
    assert driving_slope(hb, h[7], U_B, G) == S[7]
