"""Scene reading and validation: each error class names its key, before any compilation."""
import pytest
import yaml

from solver.scene import SceneError, load_scene, scene_from_dict
from tests.conftest import example_dict, merge


def err(changes=None, base="poiseuille", drop=None):
    d = merge(example_dict(base), changes or {})
    if drop:
        d.pop(drop)
    with pytest.raises(SceneError) as exc:
        scene_from_dict(d)
    return str(exc.value)


@pytest.mark.parametrize("name", ["poiseuille", "couette", "hydrostatic", "film", "channel", "unstable"])
def test_examples_are_valid_and_round_trip(examples_dir, name):
    scene = load_scene(examples_dir / f"{name}.yaml")
    again = scene_from_dict(yaml.safe_load(scene.to_yaml()))
    assert again == scene


def test_unknown_key_named_with_allowed_keys():
    msg = err({"numerics": {"shiftng": {"method": "lind"}}})
    assert "numerics" in msg and "shiftng" in msg and "shifting" in msg


def test_wrong_type_named():
    msg = err({"dp": "fine"})
    assert msg.startswith("scene.dp") and "number" in msg
    assert "scene.walls[0].moving" in err({"walls": [{"name": "b", "x": [0, 1e-3], "z": [-1e-3, 0], "moving": "yes"}]})


def test_yaml_exponent_without_dot_is_read_as_number():
    d = merge(example_dict("poiseuille"), {"dp": "5e-5"})
    assert scene_from_dict(d).dp == 5e-5


def test_impossible_values():
    assert "dp: must be a positive" in err({"dp": 0.0})
    assert "dp: must be a positive" in err({"dp": -1e-3})
    assert "numerics.cfl: must be a positive" in err({"numerics": {"cfl": -0.2}})
    assert "numerics.shifting.method" in err({"numerics": {"shifting": {"method": "magic"}}})
    assert "none, skillen, lind" in err({"numerics": {"shifting": {"method": "magic"}}})
    assert "numerics.boundary" in err({"numerics": {"boundary": "slip"}})
    assert "numerics.viscous_update: 'auto' is not one of explicit, implicit, substepped" in err(
        {"numerics": {"viscous_update": "auto"}})
    assert "numerics.shifting.min_speed: must be a finite number >= 0" in err(
        {"numerics": {"shifting": {"method": "skillen", "min_speed": -0.1}}})
    assert "fluid.blocks[0].x" in err({"fluid": {"blocks": [{"x": [1e-3, 0.0], "z": [0.0, 1e-3]}]}})


def test_ch_must_lie_in_one_to_four():
    """h / dp below 1 leaves a particle's support too few neighbours; the range is [1, 4]."""
    for ch in (0.5, 0.99, 4.5):
        msg = err({"ch": ch})
        assert msg.startswith("ch: ") and "[1, 4]" in msg, msg
    for ch in (1.0, 4.0):  # the tank: no periodic period for a wide support to outgrow
        assert scene_from_dict(merge(example_dict("hydrostatic"), {"ch": ch})).ch == ch


def test_removed_and_moved_keys_are_refused_saying_where_they_went():
    assert "physics: renamed numerics" in err({"physics": {"boundary": "mdbc"}})
    assert "cfl: now numerics.cfl" in err({"cfl": 0.2})
    assert "cfl_rule: now numerics.cfl_rule" in err({"cfl_rule": "fixed"})
    assert "cfl_viscous: removed" in err({"cfl_viscous": 0.2})
    for key in ("density_update", "viscous_normalisation", "cfl_viscous"):
        msg = err({"numerics": {key: False}})
        assert "unknown key(s) " + key in msg, msg
    for key in ("max_shift", "density_correction", "correction_limit", "surface_threshold"):
        msg = err({"numerics": {"shifting": {"method": "lind", key: 0.1}}})
        assert "scene.numerics.shifting: unknown key(s) " + key in msg, msg


def test_each_shifting_method_ignores_the_others_key():
    """min_speed is skillen's and near_surface lind's; one scheme serves both methods, so the
    other method accepts the key and keeps it unused."""
    lind = scene_from_dict(merge(example_dict("poiseuille"),
                                 {"numerics": {"shifting": {"method": "lind", "min_speed": 0.05}}}))
    assert lind.numerics.shifting.min_speed == 0.05
    skillen = scene_from_dict(merge(example_dict("poiseuille"),
                                    {"numerics": {"shifting": {"method": "skillen", "near_surface": "tangential"}}}))
    assert skillen.numerics.shifting.near_surface == "tangential"


def test_missing_required_key():
    assert "scene.dp: required" in err(drop="dp")


def test_wall_overlapping_fluid():
    msg = err({"walls": [{"name": "intruder", "x": [0.0, 5e-4], "z": [-1e-4, 1e-4]}]})
    assert "walls[0] (intruder)" in msg and "overlaps fluid.blocks[0]" in msg


def test_memory_budget():
    msg = err({"dp": 1e-7})
    assert msg.startswith("dp:") and "memory_budget_gb" in msg


def test_sound_speed_needs_one_definition():
    assert "sound" in err({"sound": {"c0": None}})
    assert "sound" in err({"sound": {"c0": 1.0, "coefsound": 10.0, "depth": 1.0}})


def test_periodic_length_must_be_whole_dp():
    assert "periodic_x" in err({"periodic_x": [0.0, 5.01e-4]})


@pytest.mark.slow
def test_validation_happens_before_compilation(tmp_path, capsys):
    """The CLI rejects a bad scene without importing the numba kernels."""
    import subprocess
    import sys
    bad = tmp_path / "bad.yaml"
    bad.write_text(yaml.safe_dump(merge(example_dict("poiseuille"), {"dp": -1.0})))
    code = ("import sys; from solver.cli import main; rc = main(['run', sys.argv[1], '-o', sys.argv[2]]); "
            "assert 'solver.forces' not in sys.modules; sys.exit(rc)")
    p = subprocess.run([sys.executable, "-c", code, str(bad), str(tmp_path / "o.nc")],
                       capture_output=True, text=True)
    assert p.returncode == 2, p.stderr
    assert "dp: must be a positive" in p.stderr and "Traceback" not in p.stderr
    assert not (tmp_path / "o.nc").exists()
