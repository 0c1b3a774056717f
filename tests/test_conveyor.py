"""The conveyor-belt case: preset geometry, and a killed run resumed from its checkpoint."""
import math
import subprocess
import sys
from dataclasses import replace

import numpy as np
import pytest
import xarray as xr
import yaml

from solver import lubrication
from solver.build import build_particles
from solver.conveyor import build_scene, case_from_dict, initial_toe, scheme_fluid, wall_thickness
from solver.scene import SceneError
from tests.conftest import EXAMPLES, coarse_conveyor_case, kill_after_first_checkpoint, worst_density_deviation


def paper(**changes):
    with open(EXAMPLES / "conveyor.yaml") as fh:
        d = yaml.safe_load(fh)
    d.update(changes)
    return case_from_dict(d)


def test_normal_depth_and_reference_stations():
    c = paper()
    assert c.h_n == pytest.approx(18.76e-3, abs=0.005e-3)
    assert c.normalising_depth == 0.0186
    eta = lubrication.front_eta(np.array([0.76, 1.5, 9.7]), c.theta)
    np.testing.assert_allclose(eta, [0.7379, 0.8516, 0.99866], atol=5e-5)


@pytest.mark.parametrize("start", ["block", "lubrication"])
def test_preset_geometry(start):
    c = paper(start=start, dp=2.0e-3, ch=1.5)
    scene = build_scene(c)
    g = scene.gravity
    assert math.degrees(math.atan2(g[0], -g[1])) == pytest.approx(15.3)
    assert math.hypot(*g) == pytest.approx(9.81)
    belt, upstream, *taper = scene.walls
    # the belt speed rises from the wall over taper_length h_n
    speeds = [-w.velocity[0] for w in taper] + [-belt.velocity[0]]
    assert speeds == sorted(speeds) and speeds[0] < 0.2 * c.belt.speed
    assert taper[0].x[0] == 0.0 and belt.x[0] == pytest.approx(c.belt.taper_length * c.h_n, abs=c.dp)
    assert belt.velocity == (-0.075, 0.0) and not belt.moving
    assert belt.ramp_delay == c.belt.rest and belt.ramp_time == c.belt.ramp
    assert upstream.velocity == (0.0, 0.0) and upstream.x[1] == 0.0
    # the belt holds every layer within 2h of fluid a tenth of dp above it, and no deeper one
    layers = round(wall_thickness(c) / c.dp)
    assert belt.z[1] == 0.0 and (layers - 0.4) * c.dp < 2 * scene.h <= (layers + 0.6) * c.dp
    assert belt.x[1] >= initial_toe(c) + c.belt.margin * c.h_n - 1e-12
    p = build_particles(scene)
    f = p.kind == 0
    area = (p.mass[f] / p.rho[f]).sum()
    # same fluid area for both starts: fluid_length h_n^2, to lattice rounding (half a dp per column)
    assert area == pytest.approx(c.fluid_length * c.h_n ** 2, abs=0.5 * c.dp * initial_toe(c))
    assert p.x[f].min() > 0 and p.z[f].min() > 0
    assert p.x[f].max() < initial_toe(c)
    if start == "block":  # round(h_n / dp) rows filling h_n exactly (docs/scene.md, "Particle layout")
        rows = round(c.h_n / c.dp)
        assert p.z[f].max() == pytest.approx(c.h_n * (1 - 0.5 / rows), abs=1e-12)
        assert area == pytest.approx(c.fluid_length * c.h_n ** 2, rel=1e-9)


@pytest.mark.parametrize("r", [1.0, 0.9831])
def test_lubrication_start_fills_its_body_depth_exactly(r):
    """The start is the steady front of the fluid the scheme behaves as (mu / r), whose
    normal depth is h_s = h_n / sqrt(r); its rows are dz = h_s / round(h_s / dp) apart, so the
    body's top edge is h_s (a dp lattice would put it at 19 dp = 1.0128 h_n at dp = 1 mm),
    each particle's m / rho is its cell dp dz, and the fluid holds fluid_length h_n h_s."""
    c = paper(dp=1.0e-3)
    start = scheme_fluid(c, r)
    h_s = c.h_n / math.sqrt(r)
    assert start.h_n == pytest.approx(h_s, rel=1e-12)
    p = build_particles(build_scene(c, flux_ratio=r))
    f = p.kind == 0
    volume = p.mass[f] / p.rho[f]
    column = f & (np.abs(p.x - 10.0 * c.h_n) < 0.5 * c.dp)  # x* about 10 from the toe
    zs = np.sort(p.z[column])
    dz = h_s / round(h_s / c.dp)
    np.testing.assert_allclose(np.diff(zs), dz, rtol=1e-9)
    assert zs[-1] + 0.5 * dz == pytest.approx(h_s, rel=1e-9)
    np.testing.assert_allclose(p.mass[column] / p.rho[column], c.dp * dz, rtol=1e-12)
    # each column rounds to whole rows: at most half a row
    assert volume.sum() == pytest.approx(c.fluid_length * c.h_n * h_s, abs=0.5 * dz * initial_toe(start))


def test_start_depth_is_validated():
    with pytest.raises(SceneError, match="start_depth.*film, theory"):
        paper(start_depth="exact")


def test_film_of_the_scheme_carries_the_exact_flux_to_two_percent():
    """The periodic film that sets the start's body depth (solver/film_depth.py): the paper's
    scheme at dp = 1 mm carries the exact film flux g sin(theta) h^3 / (3 nu) within 2 %
    (measured 1.9 % low), and the body depth is where that flux is u_b h, h_n / sqrt(r)."""
    from solver import film_depth

    film = film_depth.scheme_normal_depth(paper(dp=1.0e-3))
    assert abs(film.flux_ratio - 1.0) < 0.02
    assert film.depth == pytest.approx(film.flux_ratio ** -0.5, rel=1e-12)


def test_start_falls_back_to_h_n_when_the_film_stops():
    """A scheme whose film diverges (C_CFL 5) starts at h_n and says why; the block start
    does not run the film at all."""
    from solver.front import start_flux_ratio

    r, note = start_flux_ratio(paper(dp=4.0e-3, ch=1.5, numerics={"cfl": 5.0}), None)
    assert r == 1.0 and note.startswith("theory: h_n, because the film stopped")
    r, note = start_flux_ratio(paper(start="block"), None)
    assert math.isnan(r) and "not used" in note


def test_fast_example_is_the_paper_case_with_the_shipped_scheme():
    """examples/conveyor_fast.yaml differs from conveyor.yaml (scheme: spec) only in its name,
    shifting method, scheme (the default, surge) and steady.max_time, and builds a valid scene
    with the surge preset's numerics."""
    with open(EXAMPLES / "conveyor.yaml") as fh:
        paper_d = yaml.safe_load(fh)
    with open(EXAMPLES / "conveyor_fast.yaml") as fh:
        fast_d = yaml.safe_load(fh)
    changed = {k for k in paper_d.keys() | fast_d.keys() if paper_d.get(k) != fast_d.get(k)}
    assert changed == {"name", "shifting", "scheme", "steady", "start"}
    assert {k: v for k, v in fast_d["steady"].items() if k != "max_time"} == \
        {k: v for k, v in paper_d["steady"].items() if k != "max_time"}
    assert fast_d["dp"] <= 1.0e-3
    fast = case_from_dict(fast_d)
    n = fast.numerics
    assert (fast.scheme, fast.shifting, n.viscous_correction, fast.start, fast.start_velocity) == \
        ("surge", "skillen", True, "block", "rest")
    assert (n.cfl, n.viscous_update) == (0.6, "substepped")
    assert n.cfl_rule == "damping" and build_scene(fast).cfl_acoustic == 0.6  # the rule does not bind
    assert n.shifting.min_speed == pytest.approx(0.5 * fast.belt.speed)
    assert n.shifting.near_surface == "tangential"  # lind's, when the example runs with shifting=lind
    assert (n.volume_relaxation, n.density_diffusion_reference) == (0.1, "column")
    assert n.mdbc_velocity == "corrected"
    assert fast.h_n == paper().h_n
    build_scene(replace(fast, dp=4.0e-3, ch=1.5))


def test_a_case_of_only_dp_ch_and_shifting_runs_the_shipped_scheme():
    """The surge preset is every case's default: a case file with only dp, ch and shifting
    builds the scene of examples/conveyor_fast.yaml at that dp (but for its name and the run's
    length), and scheme: spec with no other key the scene of examples/conveyor.yaml."""
    with open(EXAMPLES / "conveyor_fast.yaml") as fh:
        fast_d = yaml.safe_load(fh)
    bare = build_scene(case_from_dict({"dp": 1.0e-3, "ch": 1.8, "shifting": "skillen"})).to_dict()
    fast = build_scene(case_from_dict(fast_d)).to_dict()
    for d in (bare, fast):
        d.pop("name"), d.pop("time")
    assert bare == fast
    with open(EXAMPLES / "conveyor.yaml") as fh:
        spec_d = yaml.safe_load(fh)
    spec = build_scene(case_from_dict(spec_d)).to_dict()
    bare_spec = build_scene(case_from_dict({"dp": 1.0e-3, "ch": 1.8, "shifting": "lind", "scheme": "spec"})).to_dict()
    for d in (spec, bare_spec):
        d.pop("name"), d.pop("time")
    assert spec == bare_spec


def test_surge_starts_as_the_paper_where_h_n_holds_15_particles_and_from_the_moving_film_below():
    """h_n = 18.8 mm: 18.8 particles across at dp = 1 mm (a block at rest, the belt ramped), 8.3 at
    2.25 mm (the moving film, the belt at full speed); spec keeps its film shape at rest, and a
    Herschel-Bulkley fluid starts from its moving film at any dp."""
    def start(**d):
        c = case_from_dict({"ch": 1.8, "shifting": "skillen", **d})
        return c.start, c.start_velocity, c.ramp_end
    assert start(dp=1.0e-3) == ("block", "rest", pytest.approx(0.3))
    assert start(dp=1.2e-3)[0] == "block" and start(dp=1.3e-3)[0] == "lubrication"  # h_n / 15 = 1.25 mm
    assert start(dp=2.25e-3) == ("lubrication", "lubrication", 0.0)
    assert start(dp=1.0e-3, scheme="spec") == ("lubrication", "rest", pytest.approx(0.3))
    hb = {"density": 1000.0, "rheology": "herschel_bulkley", "yield_stress": 20.0, "consistency": 10.0,
          "index": 0.4, "max_viscosity": 100.0}
    assert start(dp=1.0e-3, **hb) == ("lubrication", "lubrication", 0.0)


def test_a_preset_key_is_overridden_by_the_case_and_old_flat_keys_say_where_they_live():
    c = paper(numerics={"cfl": 0.3})
    assert c.numerics.cfl == 0.3 and c.numerics.cfl_rule == "fixed"  # the rest stays spec's
    s = case_from_dict({"dp": 4.0e-3, "ch": 1.5, "shifting": "skillen", "numerics": {"cfl": 0.4}})
    assert s.numerics.cfl == 0.4 and s.numerics.viscous_correction  # the rest stays surge's
    with pytest.raises(SceneError, match="case.cfl: now numerics.cfl"):
        paper(cfl=0.4)
    with pytest.raises(SceneError, match="case.scheme: 'fast' is not one of spec, surge"):
        paper(scheme="fast")
    with pytest.raises(SceneError, match="case.numerics.shifting.method"):
        paper(numerics={"shifting": {"method": "skillen"}})


def test_case_errors_name_the_key():
    with pytest.raises(SceneError, match="case.start"):
        paper(start="pyramid")
    with pytest.raises(SceneError, match="case.probes.stations"):
        paper(probes={"stations": []})
    with pytest.raises(SceneError, match="case.fluid_length"):
        paper(fluid_length=10.0)
    with pytest.raises(SceneError, match="case: unknown key.*shiftng"):
        paper(shiftng="lind")
    with pytest.raises(SceneError, match="case.shifting: 'magic' is not one of none, skillen, lind"):
        paper(shifting="magic")
    with pytest.raises(SceneError, match="numerics.shifting.min_speed"):
        paper(numerics={"shifting": {"min_speed": -0.5}})
    for gone in ("velocity", "window", "front_velocity", "depth"):
        with pytest.raises(SceneError, match=f"case.steady.{gone}: no longer a key.*steady.average"):
            paper(steady={gone: 0.02})
    with pytest.raises(SceneError, match=r"case.steady.fraction: 0.5 is not in \[0, 0.1\)"):
        paper(steady={"fraction": 0.5})


def test_the_surge_speed_floor_is_half_the_belt_speed_and_each_method_reads_its_own_key():
    """One campaign grid holds both methods: the preset's Skillen speed floor is 0.5 u_b [m/s]
    of the case's own belt, and a wrong near-surface value is refused naming the key."""
    fast = case_from_dict({"dp": 4.0e-3, "ch": 1.5, "shifting": "skillen", "belt": {"speed": 0.05}})
    assert fast.numerics.shifting.min_speed == pytest.approx(0.5 * 0.05)
    lind = build_scene(case_from_dict({"dp": 4.0e-3, "ch": 1.5, "shifting": "lind"}))
    assert lind.numerics.shifting.near_surface == "tangential"
    assert build_scene(paper(shifting="lind", dp=4.0e-3)).numerics.shifting.near_surface == "none"
    with pytest.raises(SceneError, match="numerics.shifting.near_surface: 'normal' is not one of none, tangential"):
        build_scene(paper(shifting="skillen", numerics={"shifting": {"near_surface": "normal"}}, dp=4.0e-3))


@pytest.mark.slow
def test_killed_run_resumes_to_the_same_result(tmp_path):
    case = tmp_path / "case.yaml"
    with open(EXAMPLES / "conveyor.yaml") as fh:
        d = yaml.safe_load(fh)
    d.update(dp=2.5e-3, ch=1.5, checkpoint_interval=0.1)
    d["steady"].update(max_time=0.5, average=0.2)
    d["probes"].update(interval=0.02)
    case.write_text(yaml.safe_dump(d))
    cmd = [sys.executable, "-m", "solver", "front", str(case), "--quiet"]
    ref = tmp_path / "ref.nc"
    assert subprocess.run(cmd + ["-o", str(ref), "--no-checkpoint"]).returncode == 3  # not steady
    out = tmp_path / "out.nc"
    ckpt = tmp_path / "out.nc.ckpt"
    kill_after_first_checkpoint(cmd + ["-o", str(out)], ckpt)
    assert ckpt.exists() and not out.exists()  # nothing that looks finished
    assert subprocess.run(cmd + ["-o", str(out)]).returncode == 3
    assert not ckpt.exists()
    a, b = xr.open_dataset(ref), xr.open_dataset(out)
    assert b.attrs["resumed_from_checkpoint"] == 1 and a.attrs["resumed_from_checkpoint"] == 0
    assert a.attrs["steps"] == b.attrs["steps"]
    for v in a.data_vars:
        np.testing.assert_array_equal(a[v].values, b[v].values, err_msg=v)


def coarse_state(path, dp=4.0e-3, length=0.3, depth=0.04, status="not_steady"):
    """A synthetic front run: a block of fluid particles with u = -0.075 + 5 z, w = 0.01."""
    xs, zs = np.meshgrid(np.arange(0.5, round(length / dp)) * dp, np.arange(0.5, round(depth / dp)) * dp)
    x, z = xs.ravel(), zs.ravel()
    ds = xr.Dataset({"x": (("snapshot", "particle"), x[None]), "z": (("snapshot", "particle"), z[None]),
                     "u": (("snapshot", "particle"), (-0.075 + 5.0 * z)[None]),
                     "w": (("snapshot", "particle"), np.full((1, x.size), 0.01)),
                     "kind": (("snapshot", "particle"), np.zeros((1, x.size), dtype=np.int8)),
                     "toe_position": ("time", [length])},
                    attrs={"dp": dp, "h": 1.5 * dp, "status": status, "reason": ""})
    ds.to_netcdf(path)
    return x.size * dp * dp


def test_warm_start_fills_the_coarse_state(tmp_path):
    area = coarse_state(tmp_path / "coarse.nc")
    c = paper(start="warm", warm_from=str(tmp_path / "coarse.nc"), dp=2.0e-3, ch=1.5)
    assert c.ramp_end == 0.0
    from solver import warm
    state = warm.load(c.warm_from)
    scene = build_scene(c, state)
    assert all(w.ramp_time == 0.0 and w.ramp_delay == 0.0 for w in scene.walls)
    p = build_particles(scene)
    f = p.kind == 0
    # the fine lattice fills the coarse fluid's area, to half a fine dp per column
    assert f.sum() * c.dp ** 2 == pytest.approx(area, abs=0.5 * c.dp * 0.3)
    u, w = state.velocity_at(p.x[f], p.z[f])
    h2 = 2 * state.h
    inside = (p.z[f] > h2) & (p.z[f] < 0.04 - h2) & (p.x[f] > h2) & (p.x[f] < 0.3 - h2)
    assert inside.sum() > 100
    # Shepard interpolation of a linear field where the coarse kernel is full: exact up to
    # the kernel's first moment off the lattice, held here to 0.5 % of a coarse dp
    np.testing.assert_allclose(u[inside], -0.075 + 5.0 * p.z[f][inside], atol=5.0 * 0.005 * state.dp)
    np.testing.assert_allclose(w, 0.01, atol=1e-12)


def test_warm_start_fills_the_source_surface_and_holds_its_depth(tmp_path):
    """A source run that records its C = 0.5 surface (``final_surface``) and uniform depth: the
    fine lattice fills under that surface, not under its particles' column tops, and its rows
    hold the depth exactly where the surface is flat, whatever the depth's ratio to the fine dp."""
    depth, length, dp = 0.0413, 0.3, 2.0e-3  # 20.65 fine dp: rows of dp would round to 21
    coarse_state(tmp_path / "coarse.nc", depth=0.04)
    with xr.open_dataset(tmp_path / "coarse.nc") as ds:
        src = ds.load()
    sx = np.arange(0.5e-3, length, 1.0e-3)
    src["final_surface"] = ("surface_x", np.full(sx.size, depth))
    src = src.assign_coords(surface_x=sx)
    src["uniform_depth"] = ("time", [depth])
    src.to_netcdf(tmp_path / "surface.nc")
    c = paper(start="warm", warm_from=str(tmp_path / "surface.nc"), dp=dp, ch=1.5)
    from solver import warm
    state = warm.load(c.warm_from)
    assert state.depth == depth
    p = build_particles(build_scene(c, state))
    f = p.kind == 0
    xf, zf = p.x[f], p.z[f]
    rows = round(depth / dp)
    dz = depth / rows
    interior = xf < length - 4 * dp
    cols = np.unique(np.round(xf[interior], 9))
    assert cols.size > 100
    # every interior column: `rows` rows dz apart, its top at the source depth to rounding
    for x in cols[::10]:
        z = np.sort(zf[np.isclose(xf, x)])
        assert z.size == rows
        assert z[-1] + 0.5 * dz == pytest.approx(depth, abs=1e-12)
    # the fluid's volume is the area under the surface, to half a cell per column at the toe
    volume = (p.mass[f] / p.rho[f]).sum()
    assert volume == pytest.approx(depth * length, abs=2 * dp * dz)


def nearest_neighbour(x, z):
    d = np.hypot(x[:, None] - x[None], z[:, None] - z[None])
    np.fill_diagonal(d, np.inf)
    return d.min(axis=1)


def test_a_warm_start_carries_the_source_arrangement_at_the_finer_dp(tmp_path):
    """The finer run's fluid is the source's body arrangement scaled to 1 / dp^2 and tiled:
    the same nearest-neighbour statistics in units of dp, no pair closer than MIN_GAP dp, under
    the surface and off the walls, holding the area under the surface; the walls unchanged."""
    from solver import warm
    dpc, length, depth = 4.0e-3, 0.3, 0.04
    coarse_state(tmp_path / "coarse.nc", dp=dpc, length=length, depth=depth)
    with xr.open_dataset(tmp_path / "coarse.nc") as ds:
        src = ds.load()
    jitter = np.random.default_rng(3).uniform(-0.2, 0.2, (2, src.sizes["particle"])) * dpc
    src["x"] = src["x"] + jitter[0]
    src["z"] = src["z"] + jitter[1]
    sx = np.arange(1.0e-3, length, 2.0e-3)
    src["final_surface"] = ("surface_x", np.full(sx.size, depth))
    src = src.assign_coords(surface_x=sx)
    src["uniform_depth"] = ("time", [depth])
    src.to_netcdf(tmp_path / "disordered.nc")
    c = paper(start="warm", warm_from=str(tmp_path / "disordered.nc"), dp=2.0e-3, ch=1.5)
    state = warm.load(c.warm_from)
    scene = build_scene(c, state)
    lattice = build_particles(scene)
    p = warm.carry_arrangement(lattice, scene, state)
    f, lf = p.kind == 0, lattice.kind == 0
    np.testing.assert_array_equal(p.x[~f], lattice.x[~lf])
    np.testing.assert_array_equal(p.wall[~f], lattice.wall[~lf])
    xf, zf = p.x[f], p.z[f]
    assert (zf < depth).all() and (zf >= warm.MIN_GAP * c.dp).all() and (xf >= warm.MIN_GAP * c.dp).all()
    nn = nearest_neighbour(xf, zf) / c.dp
    assert nn.min() >= warm.MIN_GAP
    block = (state.x >= 0.25 * length) & (state.x < 0.75 * length) & (state.z < depth - 1.5 * dpc)
    nn_src = nearest_neighbour(state.x[block], state.z[block]) / dpc
    # one particle per dp^2 to the seams' thinning, and the source's spacings, not a lattice's
    assert p.cell_volume[0] == pytest.approx(c.dp ** 2, rel=0.03)
    assert np.median(nn) == pytest.approx(np.median(nn_src), rel=0.03)
    nn_lattice = nearest_neighbour(lattice.x[lf], lattice.z[lf]) / c.dp
    assert np.median(nn) < 0.97 and np.median(nn_lattice) == pytest.approx(1.0)
    assert (p.mass[f] / p.rho[f]).sum() == pytest.approx(scene.fluid.profiles[0].area, rel=1e-12)


def test_warm_start_errors(tmp_path):
    with pytest.raises(SceneError, match="case.warm_from"):
        paper(start="warm")
    coarse_state(tmp_path / "bad.nc", status="diverged")
    from solver import warm
    with pytest.raises(ValueError, match="diverged"):
        warm.load(tmp_path / "bad.nc")


@pytest.mark.slow
def test_warm_start_from_a_diverged_run_falls_back_to_a_cold_start(tmp_path):
    from solver.front import run_front
    coarse_state(tmp_path / "bad.nc", status="diverged")
    c = paper(start="warm", warm_from=str(tmp_path / "bad.nc"), dp=4.0e-3, ch=1.5,
              steady={"max_time": 0.05, "average": 0.04}, probes={"interval": 0.004})
    ds = run_front(c)
    assert ds.attrs["status"] == "not_steady"
    assert ds.attrs["warm_start"].startswith("fallback to the scheme's start (lubrication)")  # spec's
    assert "diverged" in ds.attrs["warm_start"]
    assert "start: lubrication" in ds.attrs["case_yaml"]
    # the run records the surface a warm start from it fills: its last sample's C = 0.5 level
    # from wall to toe, which over the uniform zone is the last uniform depth (same probe)
    x_star = (ds.toe_position.values[-1] - ds.surface_x.values) / c.h_n
    assert ds.surface_x.values[0] < c.dp and x_star[-1] < 0.1
    zone = (x_star >= c.probes.uniform_zone[0]) & (x_star <= c.probes.uniform_zone[1])
    assert ds.final_surface.values[zone].mean() == pytest.approx(ds.uniform_depth.values[-1], rel=2e-3)


def test_checkpoint_key_covers_case_solver_and_threads(monkeypatch):
    """A checkpoint written by another solver version or thread count is never resumed."""
    from solver import checkpoint, front
    with open(EXAMPLES / "conveyor.yaml") as fh:
        d = yaml.safe_load(fh)
    case = case_from_dict(d)
    key = front.checkpoint_key(case, 2)
    assert key == front.checkpoint_key(case_from_dict(d), 2)
    assert key != front.checkpoint_key(case, 1)
    assert key != front.checkpoint_key(case_from_dict({**d, "numerics": {"cfl": 0.25}}), 2)
    monkeypatch.setattr(checkpoint, "source_hash", lambda: "another solver")
    assert key != front.checkpoint_key(case, 2)


@pytest.mark.parametrize("start", ["block", "lubrication"])
def test_lubrication_start_velocity_is_the_film_profile_with_zero_flux(start):
    """u = U (3 (s - s^2/2) - 1) at the local depth: U at the bed (no slip on the belt),
    U/2 downslope at the surface, and a depth-mean lab velocity of zero in every column."""
    from solver.conveyor import lubrication_velocity
    c = paper(start=start, start_velocity="lubrication", dp=1.0e-3)
    scene = build_scene(c)
    assert c.running_start and c.ramp_end == 0.0
    assert all(w.ramp_time == 0.0 and w.ramp_delay == 0.0 for w in scene.walls)
    z = np.linspace(0.0, 1.0, 2001)
    for x in (0.5 * c.h_n, 5 * c.h_n, 15 * c.h_n):  # in the taper, and beyond it
        top = scene.fluid.profiles[0].top(x) if scene.fluid.profiles else c.h_n
        u, w = lubrication_velocity(c, scene, np.full(z.size, x), z * top)
        U = -u[0]
        assert U > 0 and not w.any()
        assert u[-1] == pytest.approx(0.5 * U)
        assert abs(np.trapezoid(u, z)) < 1e-6 * U  # trapezoid error of this parabola: 6e-8 U
    far = lubrication_velocity(c, scene, np.array([15 * c.h_n]), np.array([0.0]))[0]
    assert far[0] == pytest.approx(-c.belt.speed)


def test_start_velocity_is_validated():
    with pytest.raises(SceneError, match="case.start_velocity.*rest, lubrication"):
        paper(start_velocity="moving")


@pytest.mark.slow
def test_a_resumed_run_takes_its_start_from_the_checkpoint(tmp_path, monkeypatch):
    """The start's periodic film (seconds at dp = 1 mm, a minute at 0.25 mm) is not run again
    when a run resumes: its flux ratio and note come from the checkpoint."""
    from solver import film_depth
    from solver.front import run_front
    with open(EXAMPLES / "conveyor.yaml") as fh:
        steady = {**yaml.safe_load(fh)["steady"], "max_time": 0.05}
    c = paper(dp=4.0e-3, checkpoint_interval=0.02, steady=steady)
    assert c.start_depth == "film"
    ckpt = tmp_path / "run.ckpt"
    first = run_front(c, checkpoint=ckpt)
    assert ckpt.exists() and np.isfinite(first.attrs["start_flux_ratio"])

    def no_film(case):
        raise AssertionError("the film ran again")

    monkeypatch.setattr(film_depth, "scheme_normal_depth", no_film)
    again = run_front(c, checkpoint=ckpt)
    assert again.attrs["resumed_from_checkpoint"] == 1
    assert again.attrs["start_flux_ratio"] == first.attrs["start_flux_ratio"]
    assert again.attrs["start_depth"] == first.attrs["start_depth"]


def test_no_tension_is_passed_to_the_scene():
    assert build_scene(coarse_conveyor_case()).numerics.no_tension is False
    assert build_scene(coarse_conveyor_case(numerics={"no_tension": True})).numerics.no_tension is True
    with pytest.raises(SceneError, match="case.numerics.no_tension"):
        coarse_conveyor_case(numerics={"no_tension": "yes"})


@pytest.mark.slow
def test_no_tension_holds_the_upstream_contact_line_that_weak_diffusion_loses():
    """dp = 2.25 mm, Ch = 1.8, delta = 0.05: the free-surface particle at the upstream wall is
    drawn into tension (rho/rho0 - 1 = -0.10 at x = 2.3 mm, z = 17 mm) and the density guard
    stops the run at 2.38 s (measured; 1.89-1.94 s from the film-depth start, for C 0.33-0.54).
    With the fluid density floored at rho0 the largest deviation stays below 2.5 % through 2.6 s
    (1.85 % measured to 2.4 s)."""
    from solver.simulation import Simulation
    case = coarse_conveyor_case(ch=1.8, numerics={"density_diffusion": 0.05, "cfl": 0.54, "cfl_rule": "fixed",
                                                  "no_tension": True})
    assert worst_density_deviation(Simulation(build_scene(case)), 2.6) < 0.025


def test_a_start_perturbation_moves_each_point_by_at_most_its_amplitude_and_is_seeded():
    from solver.conveyor import case_from_dict, start_offsets
    from solver.scene import SceneError
    (dx, dz), again, other = (start_offsets(5000, 1e-6, seed) for seed in (1, 1, 2))
    assert np.abs(dx).max() <= 1e-6 and np.abs(dz).max() <= 1e-6
    assert np.abs(dx).max() > 0.99e-6 and abs(np.mean(dx)) < 0.05e-6  # uniform on [-a, a]
    assert not np.array_equal(dx, dz)  # x and z drawn independently
    assert np.array_equal(dx, again[0]) and not np.array_equal(dx, other[0])
    with pytest.raises(SceneError, match="case.start_perturbation"):
        case_from_dict({"dp": 2.5e-3, "start_perturbation": 0.02})
    with pytest.raises(SceneError, match="case.perturbation_seed"):
        case_from_dict({"dp": 2.5e-3, "perturbation_seed": -1})


def test_toe_profile_theory_keeps_the_stations_and_the_flux():
    """study/toe_profile.py: the lubrication front's second-order long-wave correction of
    the profile (the stations' depths are solver.lubrication's): zero on the belt, zero net flux
    (the depth-mean of u* stays 1), independent of the difference step, and nil in the
    uniform zone."""
    import study.toe_profile as tp
    s, d = tp.second_order_profile(0.76)
    assert d[0] == 0.0
    assert abs(np.trapezoid(d, s)) < 1e-6 and np.abs(d).max() > 1e-3
    _, d_fine = tp.second_order_profile(0.76, dx=5e-4)
    assert np.abs(d_fine - d).max() < 1e-4
    assert np.abs(tp.second_order_profile(9.7)[1]).max() < 1e-4
    s, d = tp.inertial_profile(0.76, 0.35)
    assert d[0] == 0.0 and abs(np.trapezoid(d, s)) < 1e-9


@pytest.mark.parametrize("dp, cfl", [(2.25e-3, 0.4), (1.5e-3, 0.4), (1.25e-3, 0.6), (1.0e-3, 0.6), (2.5e-4, 0.6)])
def test_surge_takes_c_cfl_0_6_where_the_depth_holds_15_particles_and_0_4_below(dp, cfl):
    """h_n = 18.76 mm: 8.3, 12.5, 15.0, 18.8 and 75 particles across it. A case's own cfl wins."""
    case = case_from_dict({"dp": dp, "ch": 1.8, "shifting": "lind"})
    assert (case.numerics.cfl, case.numerics.cfl_rule) == (cfl, "damping")
    assert case_from_dict({"dp": dp, "ch": 1.8, "numerics": {"cfl": 0.5}}).numerics.cfl == 0.5


@pytest.mark.parametrize("start", ["block", "lubrication"])
def test_the_belt_omits_no_layer_that_the_fluid_reaches(start):
    """The walls hold only the layers within 2h of fluid FLUID_STANDOFF dp off their faces
    (solver.layout.support_layers). Through the start-up (the block's collapse, or the film's
    front forming; dp = 2.25 mm, Ch 1.8, to 1.5 s) the fluid's closest approach to the belt
    (z = 0) and to the upstream wall (x = 0) stays beyond it (measured 0.19 and 0.13 dp to the
    belt, 0.33 dp to the wall), so the first layer not laid is outside every fluid particle's
    support: the kernel sum it would add to the closest particle, a row of particles dp apart
    (L + 1/2) dp below the face, is 0."""
    from solver.kernel import kernel
    from solver.layout import FLUID_STANDOFF, support_layers
    from solver.simulation import Simulation
    case = coarse_conveyor_case(ch=1.8, start=start, start_velocity="rest" if start == "block" else "lubrication")
    sim = Simulation(build_scene(case))
    closest = math.inf
    while sim.t < 1.5:
        assert sim.step() == ""
        f = sim.kind[: sim.n_active] == 0
        closest = min(closest, float(sim.z[: sim.n_active][f].min()), float(sim.x[: sim.n_active][f].min()))
    dp, h = case.dp, sim.h
    assert closest >= FLUID_STANDOFF * dp, closest / dp
    depth = (support_layers(h, dp) + 0.5) * dp + closest
    row = np.arange(-10, 11) * dp
    assert float(np.sum(kernel(np.hypot(row, depth), h))) * dp * dp == 0.0
