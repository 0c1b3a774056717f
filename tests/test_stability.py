"""Stability margins, detector names and the safe-settings summary on synthetic runs."""
import numpy as np
import pytest
import xarray as xr
import yaml
from study import stability


def run(status="completed", reason="", dev=0.02, pen=0.0, drift=0.01, ke=1e-3, cfl=0.2, dp=0.004, **numerics):
    """A run whose case file (as the solver records it) has these numerics keys."""
    t = np.linspace(0.0, 1.0, 11)
    case = {"ch": 1.5, "shifting": "skillen", "max_area_drift": 0.05, "coefsound": 10.0,
            "numerics": {"cfl": cfl, "cfl_rule": "fixed", "density_diffusion": 0.1, "boundary": "mdbc",
                         "shifting": {"method": "skillen", "coefficient": None}, **numerics}}
    return xr.Dataset(
        {"max_density_deviation": ("diag_time", np.linspace(0.0, dev, 11)),
         "max_penetration": ("diag_time", np.linspace(0.0, pen, 11)),
         "kinetic_energy": ("diag_time", np.linspace(0.0, ke, 11)),
         "area_drift": ("time", np.linspace(0.0, -drift, 11)),
         "mass_area": ("time", np.full(11, 0.01))},
        coords={"time": t, "diag_time": t},
        attrs={"status": status, "reason": reason, "dp": dp, "rho0": 1000.0, "belt_speed_m_s": 0.1,
               "simulated_time_s": 1.0, "scene_yaml": "guards: {max_density_deviation: 0.2}",
               "case_yaml": yaml.safe_dump(case)})


@pytest.mark.parametrize("reason, name", [
    ("t = 1 s, step 3: non-finite values in 2 fluid particles", "non-finite values"),
    ("t = 1 s: density deviation max|rho/rho0 - 1| = 0.2 exceeds", "density deviation"),
    ("t = 1 s: a fluid particle crossed a wall: 0.6 dp inside", "wall crossing"),
    ("t = 1 s: a fluid particle left the domain x in [0, 1]", "left domain"),
    ("t = 1 s: time step collapsed: dt = 1e-9 s", "time-step collapse"),
    ("t = 1 s: enclosed area differs from the mass-implied area by +5.1 %", "area drift"),
    ("something new", "other"),
])
def test_detector_names(reason, name):
    assert stability.detector("diverged", reason) == name
    assert stability.detector("completed", "") == ""


def test_margins_are_fractions_of_the_guards():
    m = stability.margins(run(dev=0.05, pen=0.0008, drift=0.02, ke=2e-3))
    assert m["density_margin"] == pytest.approx(0.25)  # the scene's guard 0.2, not the default
    assert m["penetration_margin"] == pytest.approx(0.4)  # 0.0008 m / (0.5 dp)
    assert m["area_drift_margin"] == pytest.approx(0.4)  # |-0.02| / 0.05
    assert m["energy_ratio"] == pytest.approx(2e-3 / (0.5 * 10.0 * 0.01))  # M = 0.01 m2 * 1000
    assert stability.is_safe("completed", m)
    assert not stability.is_safe("diverged", m)
    assert not stability.is_safe("completed", stability.margins(run(drift=0.03)))  # 0.6 of its guard


def summary_dataset(runs) -> xr.Dataset:
    marg = [stability.margins(r) for r in runs]
    return xr.Dataset({
        "case_status": ("case", [r.attrs["status"] for r in runs]),
        "case_detector": ("case", [stability.detector(r.attrs["status"], r.attrs["reason"]) for r in runs]),
        "case_safe": ("case", [int(stability.is_safe(r.attrs["status"], m)) for r, m in zip(runs, marg)]),
        "case_settings": ("case", [yaml.safe_dump(stability.case_settings(r)) for r in runs]),
        **{f"case_{k}": ("case", [m[k] for m in marg]) for k in stability.MARGINS}},
        coords={"case": [f"c{i}" for i in range(len(runs))]})


def test_settings_summary_and_recommendation():
    runs = [run(cfl=0.2), run(cfl=0.4, dev=0.15), run("diverged", "t = 0.1 s: density deviation x", cfl=0.8, dev=0.21)]
    ds = summary_dataset(runs)
    rows = stability.settings_summary(ds)
    assert [(r["setting"], r["value"], r["survived"], r["safe"]) for r in rows] == [
        ("cfl", "0.2", 1, 1), ("cfl", "0.4", 1, 0), ("cfl", "0.8", 0, 0)]
    assert rows[2]["detectors"] == ["density deviation"]
    assert rows[1]["alone"] == ("completed", pytest.approx(0.75))  # density 0.15 / 0.2
    rec = stability.recommended(ds)
    assert rec["settings"] == {"cfl": {"survived": ["0.2", "0.4"], "diverged": ["0.8"], "best": "0.2"}}
    assert rec["safest_case"] == "c0" and rec["base"]["cfl"] == "0.2"


def test_no_recommendation_from_a_value_never_tried_alone():
    """cfl_rule: damping is tried only with cfl 0.8, so no case varies it alone: the summary lists
    it, the recommendation has nothing to compare it with and names no cfl_rule."""
    runs = [run(cfl=0.2), run(cfl=0.2), run("diverged", "t = 0.1 s: density deviation x", cfl=0.8, dev=0.21),
            run(cfl=0.8, cfl_rule="damping")]
    ds = summary_dataset(runs)
    rows = {(r["setting"], r["value"]): r for r in stability.settings_summary(ds)}
    assert rows[("cfl_rule", "damping")]["survived"] == 1 and rows[("cfl_rule", "damping")]["alone"] is None
    rec = stability.recommended(ds)
    assert "cfl_rule" not in rec["settings"]
    assert rec["settings"]["cfl"] == {"survived": ["0.2"], "diverged": ["0.8"], "best": "0.2"}


def test_the_guard_that_fired_has_margin_at_least_one():
    """Diagnostics are sampled: the tripping value may be missing from them."""
    m = stability.margins(run("diverged", "t = 1 s: density deviation max|rho/rho0 - 1| = 0.21 exceeds", dev=0.1))
    assert m["density_margin"] == 1.0 and m["area_drift_margin"] == pytest.approx(0.2)
