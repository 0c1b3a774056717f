"""A miniature campaign end to end: Snakemake -> per-case NetCDF -> campaign.nc -> report.

Two very coarse, short grid cases, the finer in two realisations, and one extra case forced to
diverge (cfl = 5), which must be shown as such while the campaign completes. Then: changing a
figure setting reruns no simulation.
"""
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
import yaml

pytestmark = pytest.mark.slow  # runs the solver or Snakemake

ROOT = Path(__file__).resolve().parent.parent
MINI = ROOT / "tests" / "data" / "mini.yaml"


def snakemake(cwd, configfile, *args):
    return subprocess.run([sys.executable, "-m", "snakemake", "-s", str(ROOT / "Snakefile"),
                           "--configfile", str(configfile), "--cores", "2", *args],
                          cwd=cwd, capture_output=True, text=True)


@pytest.fixture(scope="module")
def campaign(tmp_path_factory):
    """The miniature campaign run in its own folder from a copy of tests/data/mini.yaml there."""
    work = tmp_path_factory.mktemp("campaign")
    (work / "mini.yaml").write_text(MINI.read_text())
    p = snakemake(work, work / "mini.yaml")
    assert p.returncode == 0, p.stderr[-4000:]
    return work


def test_campaign_dataset(campaign):
    ds = xr.open_dataset(campaign / "results" / "mini" / "campaign.nc")
    assert set(ds.dims) >= {"dp", "ch", "shifting", "station", "case"}
    for v in ("zeta_f", "zeta_h", "zeta_h_paper", "zeta_fs", "zeta_u", "wall_time", "steps",
              "n_particles", "status"):
        assert v in ds
    assert ds["zeta_u"].dims == ("dp", "ch", "shifting", "station")
    status = dict(zip(ds["case"].values, ds["case_status"].values))
    assert status["dp4mm_ch1.5_skillen_unstable"] == "diverged"
    i = list(ds["case"].values).index("dp4mm_ch1.5_skillen_unstable")
    assert "density" in str(ds["case_reason"].values[i])
    assert np.isnan(ds["case_zeta_f"].values[i])  # no metrics from a diverged run
    on_grid = ds.sel(ch=1.5, shifting="skillen")
    assert np.all(on_grid["status"].values == "completed")
    assert np.all(np.isfinite(on_grid["zeta_h"].values))
    # dp = 3.5 mm in two realisations: the perturbed start gives another run, and the grid
    # point holds their mean; dp = 4 mm ran once (ensemble.overrides) and holds its run's value
    assert ds["realisations"].values.ravel().tolist() == [1, 2] and ds.attrs["realisations"] == 2
    cases = list(ds["case"].values)
    assert "dp4mm_ch1.5_skillen_r1" not in cases
    a, b = (cases.index(f"dp3.5mm_ch1.5_skillen{r}") for r in ("", "_r1"))
    pair = ds["case_zeta_fs"].values[[a, b]]
    assert pair[0] != pair[1]
    assert float(on_grid["zeta_fs"].sel(dp=0.0035)) == pytest.approx(pair.mean(), rel=1e-12)
    single = cases.index("dp4mm_ch1.5_skillen")
    assert float(on_grid["zeta_fs"].sel(dp=0.004)) == float(ds["case_zeta_fs"].values[single])
    assert float(on_grid["zeta_fs_se"].sel(dp=0.004)) == float(ds["case_zeta_fs_se"].values[single])


def test_report_has_every_section(campaign):
    html = (campaign / "reports" / "mini" / "report.html").read_text()
    sections = ("Verdict", "Accuracy and cost", "Summary", "Figures", "Cases", "Convergence",
                "Stability", "Configuration", "Provenance")
    assert [html.index(f"<h2>{s}</h2>") for s in sections] == sorted(html.index(f"<h2>{s}</h2>") for s in sections)
    assert "dp4mm_ch1.5_skillen_unstable" in html and "diverged" in html
    from study.config import load
    from study.flows.conveyor import FLOW
    assert html.count("data:image/png;base64,") == len(FLOW.figures(load(MINI))) == 11  # Figs. 2-12
    assert "Where the plug is" not in html  # a Newtonian campaign: no plug map
    # the forced divergence is counted and named in the stability section and map
    assert "1 diverged, 1 of them stopped by a named detector (1 density deviation)" in html
    assert "http://" not in html and "https://" not in html  # opens offline
    assert ("grid points ran in 2 realisations: dp3.5mm_ch1.5_skillen; in 1 realisation: "
            "dp4mm_ch1.5_skillen") in html


def test_report_in_a_real_browser(campaign):
    from study.browser import check_report, find_browser
    if find_browser() is None:
        pytest.skip("no Chromium (Debian: apt-get install chromium); .ci/run installs it")
    r = check_report(campaign / "reports" / "mini" / "report.html", screenshot=campaign / "first_screen.png")
    assert r.ok, (r.broken, r.external)
    assert len(r.images) == 11 and r.title == "sph-surge campaign report"


def test_figure_settings_do_not_rerun_simulations(campaign):
    cfg = yaml.safe_load(MINI.read_text())
    cfg["figures"]["dpi"] = 61
    path = campaign / "mini.yaml"
    path.write_text(yaml.safe_dump(cfg))  # the campaign file edited in place
    try:
        p = snakemake(campaign, path, "-n", "--quiet", "rules")
    finally:
        path.write_text(MINI.read_text())
    assert p.returncode == 0, p.stderr
    assert "figures" in p.stdout and "report_html" in p.stdout
    assert "run_case" not in p.stdout and "metrics" not in p.stdout


def test_finished_cases_are_not_recomputed(campaign):
    (campaign / "reports" / "mini" / "report.html").unlink()
    p = snakemake(campaign, campaign / "mini.yaml", "-n", "--quiet", "rules")
    assert p.returncode == 0, p.stderr
    assert "report_html" in p.stdout and "run_case" not in p.stdout


def test_snakemake_report_takes_the_registered_captions(campaign):
    """``snakemake --report`` packages every figure the campaign draws with its caption, and
    not the plug map of a Newtonian campaign."""
    import zipfile
    from study.config import load
    from study.figures import FIGURES
    from study.flows.conveyor import FLOW
    p = snakemake(campaign, campaign / "mini.yaml", "--report", "report.zip")
    assert p.returncode == 0, p.stderr[-4000:]
    with zipfile.ZipFile(campaign / "report.zip") as z:
        names = z.namelist()
        text = "".join(z.read(n).decode("utf-8", "replace") for n in names if n.endswith((".html", ".js")))
    drawn = [name for name, _, _ in FLOW.figures(load(MINI))]
    for spec in FIGURES:
        assert any(n.endswith(f"{spec.name}.png") for n in names) == (spec.name in drawn), spec.name
    assert "Pareto front (no case is both cheaper and more accurate)" in text


def test_a_physical_sweep_reports_each_value_against_its_own_theory(tmp_path):
    """A two-slope miniature campaign: each run records its own slope and is scored against it,
    the dataset holds the slope of every case, and the report draws the sweep figure."""
    cfg = yaml.safe_load(MINI.read_text())
    cfg.pop("extra_cases")
    cfg["ensemble"] = {"realisations": 1}
    cfg["grid"]["case.slope_deg"] = [15.3, 20.0]
    cfg["start_check"] = False
    path = tmp_path / "sweep.yaml"
    path.write_text(yaml.safe_dump(cfg))
    p = snakemake(tmp_path, path)
    assert p.returncode == 0, p.stderr[-4000:]
    ds = xr.load_dataset(tmp_path / "results" / "sweep" / "campaign.nc")
    assert list(ds["case_axis_slope_deg"].values) == [15.3, 15.3, 20.0, 20.0]
    from study.reference import recorded_case
    for cid, slope in zip(ds["case"].values, ds["case_axis_slope_deg"].values):
        run = xr.load_dataset(tmp_path / "results" / "sweep" / "cases" / str(cid) / "run.nc")
        assert recorded_case(run).slope_deg == slope
    assert np.all(np.isfinite(ds["case_zeta_h"].values))
    html = (tmp_path / "reports" / "sweep" / "report.html").read_text()
    assert "Errors against dp for each value of the physical axes" in html
    assert "<b>Physical axes</b>: slope_deg = 15.3, 20.0" in html
