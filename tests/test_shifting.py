"""Shifting (docs/scheme.md section 6): a uniform lattice stays put, a disordered one is ordered."""
import math

import numpy as np
import pytest

from solver import shifting
from solver.build import build_particles

from solver.run import run_scene
from solver.simulation import Simulation
from tests.conftest import example_scene

pytestmark = pytest.mark.slow  # runs the solver or Snakemake

U = 0.05  # m/s: the skillen shift scales with |u|, so the lattice moves with both walls


def moving_channel(method, **shifting):
    walls = example_scene("channel").to_dict()["walls"]
    for w in walls:
        w["velocity"], w["moving"] = [U, 0.0], True
    return example_scene("channel", walls=walls,
                         numerics={"shifting": {"method": method, **shifting}})


def disorder(x, z, kind, period, dp, among=None):
    """Std of nearest-neighbour distances of fluid particles (or of the fluid particles where
    ``among`` is true), in dp (periodic in x)."""
    f = kind == 0
    dx = x[f][:, None] - x[f][None, :]
    dx -= period * np.round(dx / period)
    dz = z[f][:, None] - z[f][None, :]
    d = np.hypot(dx, dz)
    np.fill_diagonal(d, np.inf)
    nearest = d.min(axis=1)
    return (nearest if among is None else nearest[among[f]]).std() / dp


@pytest.mark.parametrize("method, bound", [
    ("skillen", 1e-6),  # measured 5e-13 dp
    ("lind", 1e-5),  # measured 1.6e-6 dp over the 335 steps
])
def test_uniform_lattice_is_not_shifted(method, bound):
    """The shift law: no concentration gradient, no shift; largest displacement in dp against
    the lattice carried by the flow. Lind's per-step density correction amplifies round-off
    (up to its limit: see the rest-channel test below), so the lattice drifts by round-off
    grown over the run; the bound there is 6x the measured drift."""
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
    assert np.abs(moved).max() < bound * scene.dp
    assert np.abs(x1["z"][f] - x0["z"][f]).max() < bound * scene.dp


@pytest.mark.parametrize("method", ["skillen", "lind"])
def test_shifting_reduces_disorder(method):
    # shifting alone (shift_only: no time integration); the shift's concentration counts each
    # particle's lattice cell, not m / rho, so the density correction does not steer it
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


def disordered_channel_at_rest(min_speed):
    scene = example_scene("channel", numerics={"shifting": {"method": "skillen", "min_speed": min_speed}})
    parts = build_particles(scene)
    f = parts.kind == 0
    rng = np.random.default_rng(7)
    parts.x[f] += rng.uniform(-0.2, 0.2, f.sum()) * scene.dp
    parts.z[f] += rng.uniform(-0.2, 0.2, f.sum()) * scene.dp
    parts.u[:] = parts.w[:] = 0.0
    return scene, Simulation(scene, parts)


def test_skillen_speed_floor_orders_the_interior_of_fluid_at_rest():
    """Skillen's shift scales with |u|: fluid at rest (in this frame) is never reordered, whatever
    its disorder. With ``min_speed`` the speed is max(|u|, min_speed) where no wall is within 2h,
    and there the same disordered fluid at rest is ordered as the
    moving one above (30 shifts, each over 0.1 h of travel at min_speed); the rows within reach
    of a wall keep the paper's |u| = 0 and do not move."""
    results = {}
    for floor in (0.0, U):
        scene, sim = disordered_channel_at_rest(floor)
        period, dp, top = scene.periodic_x[1], scene.dp, scene.fluid.blocks[0].z[1]
        pid0 = sim.pid.copy()
        x0 = dict(zip(pid0, sim.x)), dict(zip(pid0, sim.z))
        interior = (sim.z > 4.0 * dp) & (sim.z < top - 4.0 * dp)  # > 2h + 2 dp from both walls
        ids = set(sim.pid[interior])
        before = disorder(sim.x, sim.z, sim.kind, period, dp, among=interior)
        for _ in range(30):
            sim.shift_only(0.1 * scene.h / U)
        interior = np.array([p in ids for p in sim.pid])
        wall_rows = (sim.kind == 0) & ((sim.z < 2.0 * dp) | (sim.z > top - 2.0 * dp))
        moved = max((abs(sim.x[i] - x0[0][sim.pid[i]]) + abs(sim.z[i] - x0[1][sim.pid[i]])
                     for i in np.flatnonzero(wall_rows)), default=np.nan)
        results[floor] = before, disorder(sim.x, sim.z, sim.kind, period, dp, among=interior), moved
    before, after, moved = results[0.0]
    assert after == pytest.approx(before, rel=1e-12)  # |u| = 0: no shift at all
    assert moved == 0.0
    before, after, moved = results[U]
    assert after < 0.5 * before, (before, after)
    assert moved == 0.0  # within reach of a wall: |u| = 0, not the floor


def test_shifting_off_leaves_disorder():
    """Control for the test above: with method none the same shifting calls move nothing."""
    scene = example_scene("channel")
    assert scene.numerics.shifting.method == "none"
    parts = build_particles(scene)
    f = parts.kind == 0
    parts.x[f] += np.random.default_rng(7).uniform(-0.2, 0.2, f.sum()) * scene.dp
    parts.u[f] = U
    sim = Simulation(scene, parts)
    before = sim.snapshot()
    for _ in range(30):
        sim.shift_only(0.1 * scene.h / U)
    after = sim.snapshot()
    assert np.array_equal(after["x"], before["x"]) and np.array_equal(after["z"], before["z"])


def test_density_correction_follows_the_volume_change_of_the_shift():
    """rho *= 1 - div(dr): zero for a uniform shift, -2 eps rho for dr = eps r in 2D.
    div(dr) of the pending shift is summed in the next evaluation's pair loop."""
    scene = example_scene("channel", numerics={"shifting": {"method": "skillen"}})
    H = scene.fluid.blocks[0].z[1]

    def div(fx, fz):
        sim = Simulation(scene)
        n = sim.n_active
        f = sim.kind == 0
        sim.shift_dx[:] = np.where(f, fx(sim.x, sim.z), 0.0)
        sim.shift_dz[:] = np.where(f, fz(sim.x, sim.z), 0.0)
        z = sim.snapshot()["z"]
        d = sim.derivatives()["div_dr"]
        interior = (sim.snapshot()["kind"] == 0) & (z > 2 * sim.h) & (z < H - 2 * sim.h)
        assert not sim.shift_dx[:n].any()  # the shift is consumed
        return d[interior]

    uniform = div(lambda x, z: 0.01 * scene.dp + 0 * x, lambda x, z: 0.01 * scene.dp + 0 * x)
    assert np.abs(uniform).max() < 1e-12
    eps = 1e-3
    zc = 0.5 * H
    d = div(lambda x, z: 0 * x, lambda x, z: eps * (z - zc))
    np.testing.assert_allclose(d, eps, rtol=0.01)  # d(dz)/dz = eps


def film_inflation(method, t_end=0.5, near_surface="none"):
    """Relative growth of the film's free-surface height over t_end (periodic film)."""
    from solver.probes import FieldSampler
    scene = example_scene("film", numerics={"shifting": {"method": method, "near_surface": near_surface}},
                          time={"end": t_end, "output_interval": t_end})
    sim = Simulation(scene)
    xs = np.linspace(0.002, 0.017, 8)
    z0 = FieldSampler(sim).surface(xs, 0.0).mean()
    res = run_scene(scene, sim=sim)
    assert res.status == "completed", res.reason
    return FieldSampler(sim).surface(xs, 0.0).mean() / z0 - 1.0


def test_skillen_with_its_density_correction_does_not_inflate_a_film():
    """The known failure of shifting near a free surface, particles spread at constant density,
    is what the density correction prevents. Measured here: +0.3 % in 0.5 s (+1.8 % without
    the correction, which is no longer an option)."""
    assert abs(film_inflation("skillen")) < 0.005


def rest_density_error(steps=1200):
    """max |rho/rho0 - 1| of a closed channel at rest after ``steps`` steps of lind with its
    density correction (limited per step); '' or the reason."""
    scene = example_scene("channel", numerics={"shifting": {"method": "lind"}},
                          time={"end": 1.0, "output_interval": 1.0})
    sim = Simulation(scene)
    for _ in range(steps):
        reason = sim.step()
        if reason:
            return math.inf, reason
    n = sim.n_active
    f = sim.kind[:n] == 0
    return float(np.abs(sim.rho[:n][f] / scene.fluid.density - 1.0).max()), ""


def test_lind_density_correction_is_limited_per_step():
    """Round-off in a channel at rest: a full per-step correction erases the compression the
    pressure needs and the density error grows to the 10 % guard (measured: step 454); the
    limit of 1e-3 per step (LIND_CORRECTION_LIMIT; skillen's is unlimited) keeps it below
    0.5 % (measured: 0.19 %)."""
    from solver.scene import LIND_CORRECTION_LIMIT
    assert LIND_CORRECTION_LIMIT == 1e-3
    assert example_scene("channel", numerics={"shifting": {"method": "lind"}}).shift_correction_limit == 1e-3
    assert example_scene("channel", numerics={"shifting": {"method": "skillen"}}).shift_correction_limit == math.inf
    err, reason = rest_density_error()
    assert reason == "" and err < 0.005, (err, reason)


def test_lind_with_its_density_correction_does_not_inflate_a_film():
    """The film stays within 0.5 % (skillen's tolerance above) with lind's default correction."""
    assert abs(film_inflation("lind")) < 0.005


def test_lind_with_the_tangential_near_surface_shift_does_not_inflate_a_film():
    """Shifting the particles near the surface along it keeps the film within the same 0.5 %."""
    assert abs(film_inflation("lind", near_surface="tangential")) < 0.005


def shifted_thin_film(depth_dp, near_surface):
    """One lind shift of a disordered film depth_dp particles deep (h = 1.5 dp): the shift and
    the flags, in the simulation's order, of its active particles."""
    dp = example_scene("film").dp
    scene = example_scene("film", fluid={"blocks": [{"x": [0.0, 20 * dp], "z": [0.0, depth_dp * dp]}]},
                          numerics={"shifting": {"method": "lind", "near_surface": near_surface}})
    parts = build_particles(scene)
    f = parts.kind == 0
    rng = np.random.default_rng(3)
    parts.x[f] += rng.uniform(-0.1, 0.1, f.sum()) * dp
    parts.z[f] += rng.uniform(-0.1, 0.1, f.sum()) * dp
    sim = Simulation(scene, parts)
    sim.shift_only(1e-4)
    n = sim.n_active
    fluid = sim.kind[:n] == 0
    return {"sim": sim, "dp": dp, "dx": sim.shift_dx[:n], "dz": sim.shift_dz[:n],
            "near": (sim.near_flag[:n] == 1) & fluid, "surface": (sim.surface_flag[:n] == 1) & fluid,
            "walled": np.hypot(sim.out[sim.slots.WNX, :n], sim.out[sim.slots.WNZ, :n]) > 0}


@pytest.mark.parametrize("near_surface", ["none", "tangential"])
def test_lind_near_the_free_surface(near_surface):
    """Within 2h of the free surface of a disordered film 4 dp deep, the paper's lind does not shift;
    with ``near_surface: tangential`` the particles there move, and only along the surface: the
    shift has no component along the normal n of the nearby surface particles (dr . n = 0 to
    round-off wherever neither the clip nor a wall altered it)."""
    r = shifted_thin_film(4, near_surface)
    near, dx, dz, dp = r["near"], r["dx"], r["dz"], r["dp"]
    moved = np.hypot(dx, dz) > 1e-3 * dp
    assert near.sum() > 30  # the rows within 2h of the surface
    if near_surface == "none":
        assert not (moved & near).any()
        return
    assert (moved & near).sum() > 0.5 * near.sum(), "the near-surface particles do move"
    clip = 0.1 * dp * (1 - 1e-9)
    free = near & ~r["walled"] & (np.abs(dx) < clip) & (np.abs(dz) < clip)
    assert free.sum() > 10
    sim = r["sim"]
    n = sim.n_active
    along_normal = dx * sim.surface_nx[:n] + dz * sim.surface_nz[:n]
    assert np.abs(along_normal[free]).max() < 1e-12 * dp


def test_lind_tangential_leaves_the_surface_at_a_wall_alone():
    """Where the free surface meets a wall (a surface particle with a wall particle within 2h),
    the tangential shift does not move it, as the paper's lind; the particles under it, within 2h of
    the surface and of the wall, still shift along the surface. Film 2 dp deep: every particle
    is within 2h of the bed."""
    r = shifted_thin_film(2, "tangential")
    moved = np.hypot(r["dx"], r["dz"]) > 1e-3 * r["dp"]
    at_wall = r["surface"] & r["walled"]
    under = r["near"] & r["walled"] & ~r["surface"]
    assert at_wall.sum() > 10 and under.sum() > 10
    assert not (moved & at_wall).any()
    assert (moved & under).sum() > 0.5 * under.sum()


def test_surface_normals_are_the_weighted_mean_of_the_nearby_surface_normals():
    """``surface_normals`` against its definition summed over every pair (periodic in x): near[i]
    = a free-surface particle within 2h of fluid particle i, n_i along sum_j (1 - q_ij/2)^4 n_j
    over those j, n_j = -gradC_j / |gradC_j|; on a disordered film 6 dp deep, whose surface
    normals point up."""
    r = shifted_thin_film(6, "tangential")
    sim = r["sim"]
    n, h = sim.n_active, sim.h
    sl = sim.slots
    gcx, gcz = sim.out[sl.GCX], sim.out[sl.GCZ]
    shifting.surface_normals(sim.x, sim.z, sim.kind, sim.surface_flag, gcx, gcz, sim.cells, n, h,
                             sim.near_flag, sim.surface_nx, sim.surface_nz)
    fluid = sim.kind[:n] == 0
    surf = np.flatnonzero((sim.surface_flag[:n] == 1) & fluid)
    dx = sim.x[:n, None] - sim.x[surf][None, :]
    dx -= sim.grid.period * np.round(dx / sim.grid.period)
    q = np.hypot(dx, sim.z[:n, None] - sim.z[surf][None, :]) / h
    w = np.where(q < 2.0, (1.0 - 0.5 * q) ** 4, 0.0)
    g = np.hypot(gcx[surf], gcz[surf])
    sx, sz = w @ (-gcx[surf] / g), w @ (-gcz[surf] / g)
    norm = np.maximum(np.hypot(sx, sz), 1e-300)
    near = (q < 2.0).any(axis=1) & fluid
    assert surf.size > 15 and 0 < near.sum() < fluid.sum()
    np.testing.assert_array_equal(sim.near_flag[:n] == 1, near)
    np.testing.assert_allclose(sim.surface_nx[:n][near], (sx / norm)[near], atol=1e-12)
    np.testing.assert_allclose(sim.surface_nz[:n][near], (sz / norm)[near], atol=1e-12)
    assert (sim.surface_nx[:n][~near] == 0).all() and (sim.surface_nz[:n][~near] == 0).all()
    assert np.median(sim.surface_nz[:n][near]) > 0.95
