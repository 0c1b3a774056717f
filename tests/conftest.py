import copy
import shutil
import subprocess
import tempfile
from pathlib import Path

import pytest
import yaml

from solver.scene import scene_from_dict

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


def example_dict(name: str) -> dict:
    with open(EXAMPLES / f"{name}.yaml") as fh:
        return yaml.safe_load(fh)


def merge(base: dict, changes: dict) -> dict:
    """Nested update of a copy of base."""
    out = copy.deepcopy(base)
    for k, v in changes.items():
        if isinstance(v, dict) and isinstance(out.get(k), dict):
            out[k] = merge(out[k], v)
        else:
            out[k] = v
    return out


def example_scene(name: str, **changes):
    return scene_from_dict(merge(example_dict(name), changes))


def load_benchmark(name: str):
    """The module benchmarks/NAME.py (the benchmarks are scripts, not a package)."""
    import importlib.util
    spec = importlib.util.spec_from_file_location(name, EXAMPLES.parent / "benchmarks" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def periodic_layer(ch: float, physics: dict, viscosity: float = 1.0e-3):
    """A periodic fluid layer 40 dp deep and long (dp = 1 mm, rho0 = 1000, c0 = 10, no gravity)
    on a 4 dp bed, at rest, sorted into its cells by one evaluation."""
    from solver.simulation import Simulation
    dp, L, H = 1.0e-3, 40e-3, 40e-3
    sim = Simulation(scene_from_dict({
        "name": "layer", "dp": dp, "ch": ch,
        "fluid": {"density": 1000.0, "viscosity": viscosity, "blocks": [{"x": [0.0, L], "z": [0.0, H]}]},
        "walls": [{"name": "bed", "x": [0.0, L], "z": [-4 * dp, 0.0]}],
        "gravity": [0.0, 0.0], "sound": {"c0": 10.0}, "periodic_x": [0.0, L],
        "physics": physics, "time": {"end": 1.0, "output_interval": 1.0}}))
    assert sim._evaluate(0.0) == ""
    return sim


def coarse_conveyor_case(**changes):
    """dp = 2.25 mm, Ch = 2.2: the default campaign's scheme at its coarsest grid and largest Ch,
    where nu / (c0 h) = 0.19 (docs/numerics.md, "What sets the coarse edge")."""
    from solver.conveyor import case_from_dict
    return case_from_dict({
        "name": "coarse", "dp": 2.25e-3, "ch": 2.2, "shifting": "skillen",
        "shift_min_speed": 0.5, "viscous_correction": True, "volume_relaxation": 0.1,
        "density_diffusion_reference": "column", "start_velocity": "lubrication",
        "viscous_update": "substepped", "normalising_depth": 0.0186, "start_depth": "theory",
        **changes})


def worst_density_deviation(sim, t_end: float, t_from: float = 0.2) -> float:
    """Step ``sim`` to t_end (every step must pass the guards) and return the fluid's largest
    |rho / rho0 - 1| after t_from."""
    worst = 0.0
    while sim.t < t_end:
        reason = sim.step()
        assert reason == "", reason
        if sim.t > t_from:
            worst = max(worst, float(sim.check_health()[1]))
    return worst


@pytest.fixture
def examples_dir():
    return EXAMPLES


# ---- the miniature campaign (tests/test_campaign_e2e.py), run beside the other tests --------
MINI_CAMPAIGN = pytest.StashKey[tuple]()


def pytest_collection_finish(session):
    """Start the miniature campaign's Snakemake run in the background as soon as the tests
    are known, if any of them uses it: it runs in its own process (its numba compile and its
    cases) beside the tests that come before its module, which awaits it (``campaign``). Its
    output goes to files in its directory, so that no pipe fills while nobody reads it."""
    users = [item for item in session.items
             if getattr(item, "module", None) is not None and item.module.__name__.endswith("test_campaign_e2e")
             and "campaign" in getattr(item, "fixturenames", ())]
    if not users:
        return
    e2e = users[0].module
    work = Path(tempfile.mkdtemp(prefix="sph-surge-mini-"))
    with open(work / "snakemake.out", "w") as out, open(work / "snakemake.err", "w") as err:
        proc = subprocess.Popen(e2e.snakemake_command(e2e.MINI), cwd=work, stdout=out, stderr=err)
    session.config.stash[MINI_CAMPAIGN] = (work, proc)


def pytest_sessionfinish(session, exitstatus):
    """Stop the miniature campaign if the session ends before awaiting it (-x, a failure);
    remove its directory after a session that passed."""
    run = session.config.stash.get(MINI_CAMPAIGN, None)
    if run is None:
        return
    if run[1].poll() is None:
        run[1].kill()
        run[1].wait()
    if exitstatus == 0:
        shutil.rmtree(run[0], ignore_errors=True)
