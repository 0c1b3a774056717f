"""The acoustic edge of C_CFL (solver/acoustic_edge.py) and ``cfl_rule: damping``: the lattice
symbols are the pair loop's own operators, the edge is where the amplification crosses 1, and
the rule holds the coarse conveyor that the fixed C_CFL 0.6 loses (docs/numerics.md)."""
import math
from pathlib import Path

import numpy as np
import pytest

from solver import acoustic_edge, forces
import study.config as cfgmod
from study.flows import conveyor
from solver.conveyor import build_scene, case_from_dict
from solver.scene import SceneError
from solver.simulation import Simulation
from tests.conftest import coarse_conveyor_case, example_scene, periodic_layer, worst_density_deviation

L_LAYER = 40e-3  # periodic_layer's period and depth
ROOT = Path(__file__).resolve().parent.parent


def interior(sim) -> np.ndarray:
    """Fluid particles with a full kernel support: more than 2h + dp from the bed and the surface."""
    n, m = sim.n, 2 * sim.h + sim.scene.dp
    z = sim.z[:n]
    return (sim.kind[:n] == 0) & (z > m) & (z < L_LAYER - m)


@pytest.mark.parametrize("ch", [1.3, 1.8, 2.2])
@pytest.mark.parametrize("waves", [5, 10])  # k dp = pi / 4 and pi / 2
def test_symbols_are_the_pair_loops_operators(ch, waves):
    """A wave exp(i k x) on the periodic lattice, through one evaluation of the pair loop, at every
    interior particle (to round-off where the sums are linear, to 1e-4 of the amplitude where
    the Tait pressure and 1 / rho are linearised):
    - velocity u = U sin(k x): drho/dt = -rho0 U G cos(k x) and du/dt = -nu L U sin(k x);
    - density rho = rho0 (1 + eps sin(k x)): drho/dt = -delta h c0 L rho0 eps sin(k x) and
      du/dt = -c0^2 eps G cos(k x)."""
    nu, delta = 1.0e-3, 0.1
    sim = periodic_layer(ch, {"boundary": "mdbc", "density_diffusion": delta}, viscosity=nu * 1000.0)
    dp, h, c0, rho0, n = sim.scene.dp, sim.h, sim.c0, sim.rho0, sim.n
    k = 2.0 * math.pi * waves / L_LAYER
    hgx, hgz, h2l = acoustic_edge.symbols(ch, [k * dp], [0.0])
    G, lap = hgx[0] / h, h2l[0] / h ** 2
    assert abs(hgz[0]) < 1e-12 and 0.0 < G < k and lap > 0.0  # the kernel filters: G < k
    fluid = sim.kind[:n] == 0

    U = 0.01
    sim.u[:n] = np.where(fluid, U * np.sin(k * sim.x[:n]), 0.0)
    assert sim._evaluate(0.0) == ""
    inner = interior(sim)
    assert inner.sum() > 300
    xs = sim.x[:n][inner]
    drho, ax = sim.out[forces.DRHO][:n][inner], sim.out[forces.AX][:n][inner]
    expect = -rho0 * U * G * np.cos(k * xs)
    assert np.abs(drho - expect).max() < 1e-9 * rho0 * U * G
    expect = -nu * lap * U * np.sin(k * xs)
    assert np.abs(ax - expect).max() < 1e-9 * nu * lap * U

    eps = 1.0e-7
    sim.u[:n] = 0.0
    sim.rho[:n] = np.where(fluid, rho0 * (1.0 + eps * np.sin(k * sim.x[:n])), rho0)
    assert sim._evaluate(0.0) == ""
    inner = interior(sim)
    xs = sim.x[:n][inner]
    drho, ax = sim.out[forces.DRHO][:n][inner], sim.out[forces.AX][:n][inner]
    expect = -delta * h * c0 * lap * rho0 * eps * np.sin(k * xs)
    assert np.abs(drho - expect).max() < 1e-4 * delta * h * c0 * lap * rho0 * eps
    expect = -c0 ** 2 * eps * G * np.cos(k * xs)
    assert np.abs(ax - expect).max() < 1e-4 * c0 ** 2 * eps * G


def test_symbols_tend_to_the_continuum():
    """G -> k and L -> k^2 as k h -> 0, to the Wendland sums' lattice error (up to 4.2 % at Ch 1.3
    and 2.9 % at Ch 1.8 and 2.2, for k dp = pi / 16)."""
    for ch, tol in ((1.3, 0.045), (1.8, 0.03), (2.2, 0.03)):
        k = math.pi / 16
        hgx, hgz, h2l = acoustic_edge.symbols(ch, [k], [0.0])
        assert abs(hgx[0] / (ch * k) - 1.0) < tol and abs(h2l[0] / (ch * k) ** 2 - 1.0) < tol


def test_edge_is_where_the_amplification_crosses_one():
    """Undamped the explicit update grows at every C; damped, C* separates held from growing C
    and rises with both dampings."""
    assert acoustic_edge.edge(1.8, 0.0, 0.0) == 0.0
    c = acoustic_edge.edge(1.8, 0.233, 0.1)
    assert acoustic_edge.held(0.99 * c, 1.8, 0.233, 0.1)
    assert not acoustic_edge.held(1.01 * c, 1.8, 0.233, 0.1)
    assert acoustic_edge.edge(1.8, 0.35, 0.1) > c and acoustic_edge.edge(1.8, 0.233, 0.2) > c
    # the amplification itself: one mode at a = 0.6 grows by 1.1306 a step undamped
    m = acoustic_edge.amplification(0.6, 0.0, 0.0)
    assert acoustic_edge.spectral_radius(m) == pytest.approx(1.1306, abs=1e-4)


def test_rule_leaves_the_paper_case_and_lowers_the_coarse_one():
    """At dp = 1 mm, Ch = 1.8 (nu / (c0 h) = 0.52) the rule keeps C = 0.6 exactly, so the shipped
    runs are unchanged; at dp = 2.25 mm, Ch = 2.2 (0.19) it gives 0.85 C*; ``fixed`` keeps cfl;
    the time step takes it."""
    damping = {"numerics": {"cfl": 0.6, "cfl_rule": "damping"}}
    fine = build_scene(coarse_conveyor_case(dp=1e-3, ch=1.8, **damping))
    assert fine.acoustic_damping_ratio == pytest.approx(0.524, abs=0.002)
    assert fine.cfl_acoustic == 0.6
    coarse = build_scene(coarse_conveyor_case(**damping))
    assert coarse.acoustic_damping_ratio == pytest.approx(0.191, abs=0.002)
    expect = acoustic_edge.MARGIN * acoustic_edge.edge(2.2, coarse.acoustic_damping_ratio, 0.1)
    assert coarse.cfl_acoustic == pytest.approx(expect) and 0.4 < coarse.cfl_acoustic < 0.5
    assert build_scene(coarse_conveyor_case(numerics={"cfl": 0.6, "cfl_rule": "fixed"})).cfl_acoustic == 0.6
    sim = Simulation(coarse)
    sim.amax, sim.vmax = 0.0, 0.0
    sim._update_dt()
    assert sim.info.dt == pytest.approx(coarse.cfl_acoustic * coarse.h / coarse.c0, rel=1e-12)
    assert sim.info.limit == 1


@pytest.mark.parametrize("config", ["config.yaml", "paper.yaml"])
def test_rule_does_not_bind_on_the_shipped_grids(config):
    """Every case of the default campaign and of the paper grid runs at its own cfl: there the
    rule's bound lies above it (by 1.4 % at the least: the paper grid's dp = 1 mm, Ch = 2.2), so
    their runs are those measured without it."""
    cfg = cfgmod.load(ROOT / "config" / config)
    for case in conveyor.cases(cfg):
        numerics = case_from_dict(conveyor.case_dict(cfg, case)).numerics  # the scheme's, resolved
        assert numerics.cfl_rule == "damping", case.id
        scene = build_scene(case_from_dict(conveyor.case_dict(cfg, case)))
        assert scene.cfl_acoustic == numerics.cfl, case.id
        bound = acoustic_edge.MARGIN * acoustic_edge.edge(scene.ch, scene.acoustic_damping_ratio,
                                                          scene.numerics.density_diffusion)
        assert bound > numerics.cfl, case.id


def test_rule_leaves_a_very_viscous_scene_its_cfl():
    """The Couette example (nu / (c0 h) = 26.7, explicit laminar term): the laminar term damps the
    acoustic modes strongly, and its own stability is the viscous limit's, so C stays cfl."""
    scene = example_scene("couette", numerics={"cfl_rule": "damping"})
    assert scene.numerics.viscous_update == "explicit" and not scene.implicit_viscosity
    assert scene.acoustic_damping_ratio > 10
    assert scene.cfl_acoustic == scene.numerics.cfl


def test_rule_refuses_what_it_cannot_bound():
    with pytest.raises(SceneError, match="numerics.cfl_rule: 'auto' is not one of fixed, damping"):
        coarse_conveyor_case(numerics={"cfl_rule": "auto"})
    with pytest.raises(SceneError, match="numerics.cfl_rule: 'auto' is not one of fixed, damping"):
        example_scene("couette", numerics={"cfl_rule": "auto"})
    with pytest.raises(SceneError, match="numerics.cfl_rule: damping gives an acoustic C of .*barely damp"):
        example_scene("couette", numerics={"cfl_rule": "damping", "density_diffusion": None},  # no damping
                      fluid={"viscosity": 1e-9})
    with pytest.raises(SceneError, match="numerics.cfl_rule: damping needs one viscosity"):
        example_scene("hb_film", numerics={"cfl_rule": "damping"})
    # a small cfl of the user's own is not the rule's doing: kept, not refused
    assert example_scene("couette", numerics={"cfl_rule": "damping", "cfl": 0.01}).cfl_acoustic == 0.01


@pytest.mark.slow
def test_rule_holds_the_coarse_conveyor_that_cfl_06_loses():
    """The coarse conveyor at cfl 0.6: fixed, the density guard stops it at 1.46 s;
    with the rule (C = 0.85 C* = 0.47) the fluid's largest |rho / rho0 - 1| stays at a stable
    run's 1.4-1.5 % through 2.5 s."""
    case = coarse_conveyor_case(numerics={"cfl": 0.6, "cfl_rule": "damping"})
    assert worst_density_deviation(Simulation(build_scene(case)), 2.5) < 0.025
