"""Campaigns of the flows beyond the conveyor: config validation, the scenes they build, the
scores against exact fields, and a miniature film campaign end to end."""
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
import yaml

from study.config import ConfigError, validate
from study.flows import scores
from study.references import film, slump
from study.registry import flow_of

ROOT = Path(__file__).resolve().parent.parent
G = 9.81


def cases(cfg):
    return flow_of(cfg).cases(cfg)


def scene_dict(cfg, case):
    return flow_of(cfg).case_dict(cfg, case)


def config(name):
    with open(ROOT / "config" / f"{name}.yaml") as fh:
        return yaml.safe_load(fh)


# ---- configuration -----------------------------------------------------------

def test_an_unknown_flow_is_refused_with_the_allowed_ones():
    with pytest.raises(ConfigError, match="config key flow: 'dambreak' is not one of conveyor, slump, film, user"):
        validate({"flow": "dambreak"})


@pytest.mark.parametrize("change, match", [
    (lambda c: c["scene"].pop("height"), r"scene.height: required for flow slump \(release height H0, m\)"),
    (lambda c: c["scene"].update(width=0.1), r"scene.width: not a key of flow slump; its keys are height"),
    (lambda c: c["scene"].update(end_time="soon"), r"scene.end_time: 'soon' is not valid"),
    (lambda c: c.pop("fluids"), r"config key fluids: flow slump needs at least one fluid"),
    (lambda c: c["grid"].update(scheme=["dualsphysics"]), r"grid.scheme.0: 'dualsphysics' is not one of"),
    (lambda c: c["fluids"]["newtonian"].update(viscosity=-1.0), r"config key fluids.newtonian: .*viscosity"),
    (lambda c: c["fluids"]["bingham"].pop("yield_stress"), r"fluids.bingham.yield_stress: a yield-stress slump needs"),
])
def test_a_bad_slump_config_names_its_key(change, match):
    cfg = config("slump")
    change(cfg)
    with pytest.raises(ConfigError, match=match):
        validate(cfg)


def test_a_film_of_a_yield_stress_fluid_is_refused():
    cfg = config("film")
    cfg["fluids"]["newtonian"] = {"density": 1000.0, "rheology": "herschel_bulkley", "yield_stress": 1.0,
                                  "consistency": 1.0, "index": 1.0, "max_viscosity": 100.0}
    with pytest.raises(ConfigError, match="fluids.newtonian: flow film compares with the Newtonian start-up series"):
        validate(cfg)


def test_the_arrested_shape_of_a_release_keeps_its_plateau_where_it_does_not_yield():
    """Where H0^3 < 3 A tau_y / (rho g) the shape is H0 up to x_1 = L0 - rho g H0^2 / (3 tau_y)
    and the lubrication shape beyond; where the whole release yields it is ``final_shape``."""
    rho, g, H0, L0 = 1000.0, 9.81, 0.05, 0.2
    tau_y = 100.0  # H0^3 = 1.25e-4 < 3 A tau_y / (rho g) = 3.06e-4: a plateau
    x1 = L0 - rho * g * H0 ** 2 / (3 * tau_y)
    xs = np.linspace(0.0, 0.3, 301)
    h = slump.release_shape(xs, H0, L0, tau_y, rho, g)
    assert np.all(h[xs <= x1 - 1e-9] == H0)
    assert h[np.argmin(abs(xs - (x1 + 0.01)))] < H0
    assert slump.release_shape(xs, H0, L0, 5.0, rho, g) == pytest.approx(
        slump.final_shape(xs, slump.release_runout(H0, L0, 5.0, rho, g), 5.0, rho, g))


def test_a_number_written_1e_3_is_read_as_a_number():
    cfg = config("film")
    cfg["grid"]["dp"] = ["2e-3"]
    cfg["scene"]["depth"] = "2e-2"
    v = validate(cfg)
    assert v["grid"]["dp"] == [0.002] and v["scene"]["depth"] == 0.02


def test_a_malformed_user_reference_is_refused_with_its_line(tmp_path, monkeypatch):
    monkeypatch.chdir(ROOT)
    bad = tmp_path / "u.csv"
    bad.write_text("x, z, u\n2.5e-4, 0.0001, 1e-6\n2.5e-4, abc, 2e-6\n")
    cfg = config("user")
    cfg["scene"]["reference"] = {"velocity": str(bad)}
    line3 = r"scene.reference.velocity: .*u.csv line 3: 'abc' in column z is not a number"
    with pytest.raises(ConfigError, match=line3):
        validate(cfg)
    cfg["scene"]["reference"] = {"speed": str(bad)}
    kinds = "scene.reference.speed: not a kind of reference; allowed: front, depth, velocity"
    with pytest.raises(ConfigError, match=kinds):
        validate(cfg)


def test_the_slump_scene_is_the_two_sided_release_on_a_bed_past_the_reference_front():
    cfg = validate(config("slump"))
    by_id = {c.id: c for c in cases(cfg)}
    assert len(by_id) == 12  # 3 dp x 2 schemes x 2 fluids
    sc = scene_dict(cfg, by_id["dp2mm_ch1.5_skillen_surge_newtonian"])
    assert sc["fluid"]["blocks"] == [{"x": [-0.1, 0.1], "z": [0.0, 0.05]}]
    x_ref = slump.front_position(5.0, 0.05 * 0.1, 5.6 / 1383.0, G)
    assert sc["walls"][0]["x"][1] >= 1.3 * x_ref
    # spec with a yield-stress fluid: the paper's scheme with the implicit laminar term
    spec = scene_dict(cfg, by_id["dp2mm_ch1.5_skillen_spec_bingham"])["numerics"]
    assert spec["viscous_update"] == "implicit" and "volume_relaxation" not in spec
    surge = scene_dict(cfg, by_id["dp2mm_ch1.5_skillen_surge_newtonian"])["numerics"]
    assert surge["viscous_update"] == "substepped" and surge["shifting"]["method"] == "skillen"


# ---- scores against exact fields ----------------------------------------------

def fake_run(times, frames, dp):
    """A run dataset as solver.output writes it, from frames of (x, z, u) fluid arrays."""
    n = max(len(f[0]) for f in frames)
    arr = {k: np.full((len(frames), n), np.nan) for k in ("x", "z", "u")}
    kind = np.ones((len(frames), n), dtype=np.int8)
    for k, (x, z, u) in enumerate(frames):
        arr["x"][k, :len(x)], arr["z"][k, :len(x)], arr["u"][k, :len(x)] = x, z, u
        kind[k, :len(x)] = 0
    data = {k: (("snapshot", "particle"), v) for k, v in arr.items()}
    data["kind"] = (("snapshot", "particle"), kind)
    return xr.Dataset(data, coords={"snapshot_time": ("snapshot", np.asarray(times))},
                      attrs={"dp": dp, "status": "completed", "scene_yaml": "periodic_x: null\n"})


def similarity_particles(t, A, nu, dp, scale=1.0):
    """Particle centres filling the similarity profile (both sides), the front stretched by ``scale``."""
    xn = scale * float(slump.front_position(t, A, nu, G))
    xs = np.arange(-xn + dp / 2, xn, dp)
    px, pz = [], []
    for x in xs:
        h = float(slump.depth_profile(x / scale, t, A, nu, G))
        for z in np.arange(dp / 2, h, dp):
            px.append(x)
            pz.append(z)
    return np.array(px), np.array(pz), np.zeros(len(px))


@pytest.mark.parametrize("scale, expected", [(1.0, 0.0), (1.05, 0.05)])
def test_the_slump_front_error_and_exponent_of_a_similarity_current(scale, expected):
    """Particles filling the similarity current (front = outermost centre + dp / 2 within dp / 2
    of x_N): front error below 0.4 % and exponent within 1 % of 1/5; stretched by 5 %: 5 %."""
    H0, L0, nu, dp = 0.05, 0.1, 4e-3, 5e-4
    times = np.arange(0.0, 5.01, 0.25)
    frames = [similarity_particles(max(t, 0.05), H0 * L0, nu, dp, scale) for t in times]
    s = scores.slump_newtonian(fake_run(times, frames, dp), H0, L0, nu, 0.02)
    assert s["front_error"] == pytest.approx(expected, abs=4e-3)
    assert abs(s["exponent"] / 0.2 - 1) < 0.01
    if scale == 1.0:
        assert s["depth_error"] < 0.03  # the depth resolved to dp = 1 % of the depth at the plane


def test_a_front_that_stops_is_found_stopped_and_one_that_creeps_is_not():
    t = np.arange(0.0, 5.0, 0.05)
    # speed 0.2 exp(-t / 0.5) m/s: below 1 mm/s from t = 2.65 s; a line over the 0.5 s before t
    # measures about the speed at t - 0.25 s, so the stop is found at about 2.9 s
    stopping = 0.3 - 0.1 * np.exp(-t / 0.5)
    t_s = scores.stop_time(t, stopping, 1e-3, 0.5)
    assert 2.85 <= t_s <= 3.0
    creeping = 0.3 + 2e-3 * t
    assert math.isnan(scores.stop_time(t, creeping, 1e-3, 0.5))


@pytest.mark.parametrize("shift", [1.0, 1.05])
def test_a_user_front_reference_scores_a_symmetric_release(tmp_path, shift):
    """The similarity current as a run, its front written as a user's CSV (raised by ``shift``):
    the user flow's front error is the shift (to 0.4 %, the front's dp / 2 granularity)."""
    from study.references.user import read_front
    H0, L0, nu, dp = 0.05, 0.1, 4e-3, 5e-4
    times = np.arange(0.25, 5.01, 0.25)
    run = fake_run(times, [similarity_particles(t, H0 * L0, nu, dp) for t in times], dp)
    path = tmp_path / "front.csv"
    x_ref = shift * slump.front_position(times, H0 * L0, nu, G)
    path.write_text("t, x_front\n" + "".join(f"{t:g}, {x:.6g}\n" for t, x in zip(times, x_ref)))
    s = scores.user_scores(run, {"front": read_front(path)}, 1.0, True)
    assert s["front_error"] == pytest.approx(1 - 1 / shift, abs=4e-3)


@pytest.mark.parametrize("offset, expected", [(0.0, 0.0), (0.01, 0.01)])
def test_the_film_profile_error_of_the_exact_series(offset, expected):
    h, nu, theta, dp = 0.02, 4e-3, math.radians(15.3), 1e-3
    z = np.repeat(np.arange(dp / 2, h, dp), 4)
    x = np.tile(np.arange(4) * dp, z.size // 4)
    um = film.u_max(h, nu, G, theta)
    times = [0.0, 0.05, 0.1]
    frames = [(x, z, film.velocity(z, t, h, nu, G, theta) + offset * um) for t in times]
    s = scores.film_startup(fake_run(times, frames, dp), h, nu, theta)
    assert s["profile_error"] == pytest.approx(expected, abs=1e-9)


def test_rms_with_se_of_noise_about_a_constant():
    rng = np.random.default_rng(1)
    d = 0.05 + 0.002 * rng.standard_normal(400)
    rms, se = scores.rms_with_se(np.arange(400.0), d)
    assert rms == pytest.approx(0.05, rel=0.01)
    assert 0.5 * 0.002 / 20 < se < 2 * 0.002 / 20  # sd / sqrt(n)


# ---- a miniature film campaign end to end -------------------------------------

@pytest.mark.slow
def test_a_film_campaign_runs_end_to_end_and_reports_its_answer(tmp_path):
    cfg = config("film")
    cfg["scene"].update(end_time=0.05, output_interval=0.025)
    cfg["grid"]["dp"] = [4e-3, 2.5e-3]
    path = tmp_path / "film.yaml"
    path.write_text(yaml.safe_dump(cfg))
    p = subprocess.run([sys.executable, "-m", "snakemake", "-s", str(ROOT / "Snakefile"), "--configfile",
                        str(path), "--cores", "2"], cwd=tmp_path, capture_output=True, text=True)
    assert p.returncode == 0, p.stderr[-4000:]
    ds = xr.load_dataset(tmp_path / "results" / "film" / "campaign.nc")
    assert list(ds["case"].values) == ["dp4mm_ch1.5_skillen_surge_newtonian", "dp2.5mm_ch1.5_skillen_surge_newtonian",
                                       "dp4mm_ch1.5_skillen_spec_newtonian", "dp2.5mm_ch1.5_skillen_spec_newtonian"]
    assert np.all(ds["status"].values == "completed")
    assert np.all(np.isfinite(ds["profile_error"].values)) and np.all(ds["profile_error"].values < 0.1)
    html = (tmp_path / "reports" / "film" / "report.html").read_text()
    for section in ("Answer", "Accuracy and cost", "Convergence", "Stability", "Run time against error"):
        assert section in html
    assert "Verdict" not in html and "Where the plug is" not in html
    assert "newtonian</b>: surge's velocity profile error at dp = 2.5 mm is" in html


def test_a_diverged_run_is_recorded_with_its_reason_and_no_errors(tmp_path):
    """A flow run that diverged is scored with no errors; the campaign dataset, the figures and the
    report still come out, the report's stability map naming its reason."""
    from solver.output import write_atomic
    cfg = config("film")
    cfg["grid"].update(dp=[2e-3, 1e-3], scheme=["surge"])
    cfg = validate(cfg)
    h, nu, theta = 0.02, 5.6 / 1383.0, math.radians(15.3)
    z = np.arange(0.5e-3, h, 1e-3)
    good = fake_run([0.0, 0.1], [(z * 0, z, film.velocity(z, t, h, nu, G, theta)) for t in (0.0, 0.1)], 1e-3)
    bad = fake_run([0.0], [(z * 0, z, z * 0)], 2e-3)
    bad.attrs.update(status="diverged", reason="density deviation 0.2 exceeds 0.1")
    for c, run in zip(cases(cfg), (bad, good)):
        run.attrs.update(wall_time_s=1.0, steps=10, n_particles=z.size)
        write_atomic(flow_of(cfg).score(cfg, c.id, run), tmp_path / c.id / "metrics.nc")
    ds = flow_of(cfg).reduce(cfg, tmp_path)
    assert list(ds["status"].values) == ["diverged", "completed"]
    assert np.isnan(ds["profile_error"].values[0]) and ds["profile_error"].values[1] < 1e-9
    flow_of(cfg).write_figures(cfg, ds, tmp_path / "figures")
    html = flow_of(cfg).render(cfg, ds, tmp_path / "figures")
    assert "1 of 2 runs did not complete" in html and "diverged: density deviation 0.2 exceeds 0.1" in html


# ---- a physical axis ----------------------------------------------------------------------

def test_a_physical_axis_scores_each_run_against_its_own_theory(tmp_path):
    """config/film_angle.yaml sweeps the incline: each case's scene has its own gravity, and a
    run holding the exact start-up profile of its own angle scores ~0 while the same profile
    scored as another angle's run is off by the ratio of the two u_max; the reduced dataset
    holds the angle as a coordinate and one convergence sequence for each angle."""
    from solver.output import write_atomic
    from study.config import load
    cfg = load(ROOT / "config" / "film_angle.yaml")
    flow = flow_of(cfg)
    cs = cases(cfg)
    assert [dict(c.axes)["scene.angle"] for c in cs] == [5.0] * 3 + [15.3] * 3 + [30.0] * 3
    for c in cs:
        g = scene_dict(cfg, c)["gravity"]
        assert math.degrees(math.atan2(g[0], -g[1])) == pytest.approx(dict(c.axes)["scene.angle"], rel=1e-12)
    h, nu = 0.02, 5.6 / 1383.0
    z = np.arange(0.5e-3, h, 1e-3)

    def run_at(angle):
        theta = math.radians(angle)
        run = fake_run([0.0, 0.1], [(z * 0, z, film.velocity(z, t, h, nu, G, theta)) for t in (0.0, 0.1)], 1e-3)
        run.attrs.update(wall_time_s=1.0, steps=10, n_particles=z.size)
        return run

    for c in cs:
        write_atomic(flow.score(cfg, c.id, run_at(dict(c.axes)["scene.angle"])), tmp_path / c.id / "metrics.nc")
    ds = flow.reduce(cfg, tmp_path)
    assert np.all(ds["profile_error"].values < 1e-9)  # every run against its own angle's series
    wrong = flow.score(cfg, cs[-1].id, run_at(5.0))  # a 5 deg profile scored as a 30 deg run
    ratio = math.sin(math.radians(5.0)) / math.sin(math.radians(30.0))
    assert float(wrong["profile_error"]) > 0.5 * (1 - ratio)
    assert list(ds["angle"].values) == [5.0] * 3 + [15.3] * 3 + [30.0] * 3
    from study.flows.runs import sequences
    assert [s["axes"] for s in sequences(ds)] == [(("angle", 5.0),), (("angle", 15.3),), (("angle", 30.0),)]
    flow.write_figures(cfg, ds, tmp_path / "figures")
    html = flow.render(cfg, ds, tmp_path / "figures")
    assert "newtonian angle 30</b>: surge's velocity profile error" in html
    assert "<th>angle</th>" in html  # the accuracy table names each run's angle


def test_an_axis_must_name_a_key_of_the_flow():
    cfg = config("film")
    cfg["grid"]["scene.slope"] = [5.0, 10.0]
    with pytest.raises(ConfigError, match="config key grid.scene.slope: a scene axis is scene.KEY with KEY one of"):
        validate(cfg)
    cfg = config("film")
    cfg["grid"]["fluids.water.viscosity"] = [1.0]
    with pytest.raises(ConfigError, match="config key grid.fluids.water.viscosity: a fluid axis"):
        validate(cfg)
