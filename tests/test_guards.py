"""Every divergence detector fires on a scene crafted for it, with its reason."""
import re

import numpy as np

from solver.build import build_particles
from solver.run import run_scene
from solver.simulation import Simulation
from tests.conftest import example_scene
import pytest

pytestmark = pytest.mark.slow  # runs the solver or Snakemake


def run(scene, parts=None):
    sim = Simulation(scene, parts) if parts is not None else None
    return run_scene(scene, sim=sim)


def assert_clean_divergence(res, phrase):
    assert res.status == "diverged"
    assert phrase in res.reason, res.reason
    for snap in res.snaps:  # nothing recorded after the blow-up
        assert all(np.isfinite(v).all() for v in snap.values())


def test_cfl_5_diverges_with_a_reason():
    res = run(example_scene("unstable"))
    assert res.status == "diverged"
    assert res.reason.startswith("t = ") and len(res.reason) > 30


def test_non_finite_values():
    scene = example_scene("channel")
    parts = build_particles(scene)
    parts.rho[5] = np.nan
    assert_clean_divergence(run(scene, parts), "non-finite")


def test_density_deviation():
    """Fluid slammed at 2 c0 against the top wall (z = 16 mm): the reason says where the
    largest deviation lies, a compression at that wall."""
    scene = example_scene("channel", fluid={"blocks": [{"x": [0.0, 0.04], "z": [0.0, 0.016],
                                                        "velocity": [0.0, 20.0]}]})
    res = run(scene)
    assert_clean_divergence(res, "density deviation")
    where = re.search(r"rho/rho0 - 1 = ([-+.\de]+) at x = ([-.\de]+) m, z = ([-.\de]+) m\)$", res.reason)
    assert where, res.reason
    dev, x, z = (float(v) for v in where.groups())
    assert dev > scene.guards.max_density_deviation and 0.0 <= x <= 0.04
    assert z > 0.016 - 4 * scene.h, res.reason  # within the kernel's reach of the top wall


def test_particle_leaves_domain():
    scene = example_scene("hydrostatic", gravity=[0.0, 0.0], sound={"c0": 20.0, "coefsound": None, "depth": None},
                          fluid={"blocks": [{"x": [0.0, 0.1], "z": [0.0, 0.05], "velocity": [0.0, 1.0]}]},
                          walls=[])
    assert_clean_divergence(run(scene), "left the domain")


def test_particle_crosses_wall():
    # plain DBC, soft fluid, fast impact: particles are pushed through the thin bed
    scene = example_scene("hydrostatic", sound={"coefsound": 2.0, "depth": 0.05},
                          numerics={"boundary": "dbc"},
                          guards={"max_density_deviation": 10.0},
                          fluid={"blocks": [{"x": [0.0, 0.1], "z": [0.0, 0.05], "velocity": [0.0, -3.0]}]})
    assert_clean_divergence(run(scene), "crossed a wall")


def test_time_step_collapse():
    # fluid falling onto the bed speeds up, so dt2 = h / (c0 + v) shrinks; a 0.99 floor trips
    scene = example_scene("hydrostatic", guards={"min_dt_fraction": 0.99},
                          fluid={"blocks": [{"x": [0.0, 0.1], "z": [0.02, 0.05]}]})
    assert_clean_divergence(run(scene), "time step collapsed")


def test_area_drift():
    """The conveyor run's volume guard: fluid spread to 1.05 dp at unchanged density encloses
    about 8 % more area than its mass implies (10 % for the particle rows, less the half
    spacing at the surface and toe, which does not grow); the unspread lattice stays within
    0.5 %."""
    import yaml

    from solver.conveyor import build_scene, case_from_dict
    from solver.front import FrontMonitor
    from solver.run import Runner
    from tests.conftest import EXAMPLES
    with open(EXAMPLES / "conveyor.yaml") as fh:
        d = yaml.safe_load(fh)
    d.update(dp=0.004, ch=1.5, start="block")
    d["steady"].update(max_time=0.1)
    case = case_from_dict(d)
    scene = build_scene(case)
    monitor = FrontMonitor(case)
    assert monitor(Simulation(scene)) is None
    assert abs(monitor.series["enclosed_area"][0] / monitor.series["mass_area"][0] - 1.0) < 0.005
    parts = build_particles(scene)
    f = parts.kind == 0
    parts.x[f] *= 1.05
    parts.z[f] *= 1.05
    res = Runner(scene, Simulation(scene, parts), monitors=[FrontMonitor(case)]).run()
    assert_clean_divergence(res, "enclosed area differs from the mass-implied area by +")
    drift = float(res.reason.split("by +")[1].split(" %")[0])
    assert 7.0 < drift < 10.0, res.reason
