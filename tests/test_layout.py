"""Scenes valid at any dp (docs/scene.md, "Particle layout"): every shipped scene without a period,
built at spacings that do not divide its sizes, has its wall layers dp from the fluid, walls
holding every layer within 2h of fluid a tenth of dp off their faces, and its fluid area; where
the sizes divide dp the positions are the plain lattice."""
from pathlib import Path

import numpy as np
import pytest
import yaml

from solver.build import BOUNDARY, FLUID, build_particles
from solver.conveyor import build_scene, case_from_dict
from solver.layout import stretched_points
from solver.scene import SceneError, scene_from_dict
from workflow.study import config as campaign_config
from workflow.study.registry import flow_of
from tests.conftest import example_dict, merge

ROOT = Path(__file__).resolve().parents[1]


def _example(name):
    return lambda dp: load_scene_at(ROOT / "examples" / f"{name}.yaml", dp)


def load_scene_at(path, dp):
    data = yaml.safe_load(path.read_text())
    data["dp"] = dp
    return scene_from_dict(data)


def _conveyor(name):
    def make(dp):
        data = yaml.safe_load((ROOT / "examples" / f"{name}.yaml").read_text())
        data["dp"] = dp
        return build_scene(case_from_dict(data))
    return make


def _slump(dp):
    cfg = campaign_config.load(ROOT / "config" / "slump.yaml")
    flow = flow_of(cfg)
    case = next(c for c in flow.cases(cfg) if c.fluid == "bingham" and c.scheme == "surge")
    case = type(case)(dp, case.ch, case.shifting, scheme=case.scheme, fluid=case.fluid, axes=case.axes)
    return scene_from_dict(flow.case_dict(cfg, case))


# every shipped scene without a period, and three spacings that divide none of its sizes (the
# conveyor's scene is sized from its dp, so only its layout is checked there)
SCENES = {
    "dambreak": (_example("dambreak"), [1.25e-3, 1.75e-3, 2.2e-3]),
    "hydrostatic": (_example("hydrostatic"), [1.7e-3, 2.3e-3, 2.6e-3]),
    "unstable": (_example("unstable"), [1.7e-3, 2.3e-3, 2.6e-3]),
    "conveyor": (_conveyor("conveyor"), [1.3e-3, 1.7e-3, 2.3e-3]),
    "conveyor_fast": (_conveyor("conveyor_fast"), [1.3e-3, 1.7e-3, 2.3e-3]),
    "slump": (_slump, [2.2e-3, 2.7e-3, 3.3e-3]),
}


def _fluid_area(scene):
    return sum(r.area for r in scene.fluid.blocks) + sum(p.area for p in scene.fluid.profiles)


def _wall_depth_along(bx, bz, x0, z0, nx, nz, dp):
    """Contiguous wall layers met from (x0, z0) along the axis direction (nx, nz): wall particles
    within dp / 2 of the ray, sorted along it, the first within 1.5 dp and each next one within
    1.5 dp of the last."""
    along = (bx - x0) * nx + (bz - z0) * nz
    across = np.abs((bx - x0) * nz - (bz - z0) * nx)
    s = np.sort(along[(across <= 0.5 * dp * (1 + 1e-9)) & (along > 0)])
    depth, last = 0, 0.0
    for a in s:
        if a - last > 1.5 * dp:
            break
        if a - last > 0.5 * dp or depth == 0:
            depth += 1
        last = a
    return depth


@pytest.mark.parametrize("name", SCENES)
def test_every_scene_is_valid_at_spacings_that_divide_none_of_its_sizes(name):
    make, spacings = SCENES[name]
    for dp in spacings:
        scene = make(dp)
        if not name.startswith("conveyor"):
            assert any(abs(s / dp - round(s / dp)) > 0.05 for s in _sizes(scene)), (name, dp)
        p = build_particles(scene)
        fluid, wall = p.kind == FLUID, p.kind == BOUNDARY
        fx, fz, bx, bz = p.x[fluid], p.z[fluid], p.x[wall], p.z[wall]
        # least fluid-to-wall distance: dp, within 10 %
        d = np.array([np.min(np.hypot(bx - x, bz - z)) for x, z in zip(fx, fz)])
        assert 0.9 * dp <= d.min() <= 1.1 * dp, (name, dp, d.min() / dp)
        # every wall layer within 2h of a fluid particle a tenth of dp off the face (its layers
        # sit (l - 1/2) dp inside it): from each fluid particle next to a wall, towards its
        # nearest wall particle along the nearer axis, count contiguous layers
        need = sum(1 for layer in range(1, 20) if (layer - 0.5 + 0.1) * dp < 2 * scene.h - 1e-12 * dp)
        touching = np.where(d < 1.1 * dp)[0]
        for k in touching[:: max(1, touching.size // 200)]:
            j = np.argmin(np.hypot(bx - fx[k], bz - fz[k]))
            ox, oz = bx[j] - fx[k], bz[j] - fz[k]
            nx, nz = (np.sign(ox), 0.0) if abs(ox) > abs(oz) else (0.0, np.sign(oz))
            depth = _wall_depth_along(bx, bz, fx[k], fz[k], nx, nz, dp)
            assert depth >= need, (name, dp, fx[k], fz[k], depth, need)
        # fluid area kept: sum of the particles' cells against the scene's
        area = float(np.sum(p.cell_volume[fluid]))
        assert abs(area - _fluid_area(scene)) <= 0.01 * _fluid_area(scene), (name, dp)


def _sizes(scene):
    """Every side of the scene's fluid regions and walls."""
    rects = scene.fluid.extents() + list(scene.walls)
    return [r.x[1] - r.x[0] for r in rects] + [r.z[1] - r.z[0] for r in rects]


def test_blocks_keep_their_area_exactly():
    scene = load_scene_at(ROOT / "examples" / "dambreak.yaml", 1.75e-3)
    p = build_particles(scene)
    area = np.sum(p.cell_volume[p.kind == FLUID])
    assert area == pytest.approx(0.057 * 0.114, rel=1e-12)


@pytest.mark.parametrize("name", ["dambreak", "hydrostatic", "slump"])
def test_divisible_sizes_give_the_plain_lattice(name):
    """Where every size is a whole number of dp, each position is lo + (i + 1/2) dp."""
    make, _ = SCENES[name]
    dp = {"dambreak": 1e-3, "hydrostatic": 2e-3, "slump": 2.5e-3}[name]
    scene = make(dp)
    p = build_particles(scene)
    for rect in scene.fluid.blocks:
        inside = (p.kind == FLUID) & (p.x > rect.x[0]) & (p.x < rect.x[1])
        assert np.allclose((p.x[inside] - rect.x[0]) / dp % 1.0, 0.5, atol=1e-9)
        assert np.allclose((p.z[inside] - rect.z[0]) / dp % 1.0, 0.5, atol=1e-9)
    for i, w in enumerate(scene.walls):
        mine = p.wall == i
        x = np.unique(np.round(p.x[mine], 12))
        expect = w.x[0] + (np.arange(int(round((w.x[1] - w.x[0]) / dp))) + 0.5) * dp
        if expect.size == x.size:  # walls thinner than 2h grow (tested above)
            np.testing.assert_allclose(x, expect, rtol=0, atol=1e-12)
    assert np.all(p.cell_volume == dp * dp)


def test_stretched_points_fill_the_interval():
    xs, step = stretched_points(0.0, 0.057, 1.75e-3)
    assert xs.size == 33 and step == pytest.approx(0.057 / 33)
    assert xs[0] == pytest.approx(step / 2) and xs[-1] == pytest.approx(0.057 - step / 2)
    xs, step = stretched_points(0.0, 0.057, 1e-3)
    assert step == 1e-3


def test_a_period_no_whole_number_of_particles_fills_is_refused_before_the_run():
    d = merge(example_dict("channel"), {"dp": 3e-4})
    with pytest.raises(SceneError) as exc:
        scene_from_dict(d)
    msg = str(exc.value)
    assert "periodic_x" in msg and "0.3 mm" in msg and "whole number" in msg


def test_a_block_thinner_than_half_dp_is_refused_naming_it():
    d = example_dict("dambreak")
    d["fluid"]["blocks"].append({"x": [0.1, 0.1004], "z": [0.0, 0.01]})
    with pytest.raises(SceneError) as exc:
        scene_from_dict(d)
    msg = str(exc.value)
    assert "fluid.blocks[1]" in msg and "x extent" in msg and "dp = 1 mm" in msg
