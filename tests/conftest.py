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


@pytest.fixture
def examples_dir():
    return EXAMPLES
