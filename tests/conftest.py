import copy
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


def periodic_layer(ch: float, numerics: dict, viscosity: float = 1.0e-3):
    """A periodic fluid layer 40 dp deep and long (dp = 1 mm, rho0 = 1000, c0 = 10, no gravity)
    on a 4 dp bed, at rest, sorted into its cells by one evaluation."""
    from solver.simulation import Simulation
    dp, L, H = 1.0e-3, 40e-3, 40e-3
    sim = Simulation(scene_from_dict({
        "name": "layer", "dp": dp, "ch": ch,
        "fluid": {"density": 1000.0, "viscosity": viscosity, "blocks": [{"x": [0.0, L], "z": [0.0, H]}]},
        "walls": [{"name": "bed", "x": [0.0, L], "z": [-4 * dp, 0.0]}],
        "gravity": [0.0, 0.0], "sound": {"c0": 10.0}, "periodic_x": [0.0, L],
        "numerics": numerics, "time": {"end": 1.0, "output_interval": 1.0}}))
    assert sim._evaluate(0.0) == ""
    return sim


def coarse_conveyor_case(**changes):
    """dp = 2.25 mm, Ch = 2.2: the shipped scheme (surge) at the default campaign's coarsest grid
    and largest Ch, where nu / (c0 h) = 0.19."""
    from solver.conveyor import case_from_dict
    return case_from_dict({
        "name": "coarse", "dp": 2.25e-3, "ch": 2.2, "shifting": "skillen",
        "normalising_depth": 0.0186, "start_depth": "theory", **changes})


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


def kill_after_first_checkpoint(cmd: list, ckpt) -> None:
    """Start ``cmd`` (a solver run), SIGKILL it as soon as its checkpoint ``ckpt`` exists (a
    cold numba cache compiles first: up to 10 min), and assert it was still running then."""
    import signal
    import subprocess
    import time
    p = subprocess.Popen(cmd)
    t0 = time.time()
    while not ckpt.exists() and p.poll() is None and time.time() - t0 < 600:
        time.sleep(0.005)
    killed = p.poll() is None
    p.send_signal(signal.SIGKILL)
    p.wait()
    assert killed, "the run ended before it could be killed"
