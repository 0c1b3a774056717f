"""The HTML report from a synthetic campaign: the verdict on the first screen, and the page
as headless Chromium renders it (images decoded, nothing fetched from outside)."""
import html

import numpy as np
import pytest
import xarray as xr

from campaign_data import STATIONS, campaign
from study import figures
from study.browser import check_report, find_browser
from study.report import render, write
from study.verdict import verdicts
from test_verdict import paper_like


def test_the_report_opens_with_the_verdict():
    ds = campaign(paper_like, steady=lambda dp, ch, sh: dp > 0.001)
    text = render(ds, [], "grid: {}")
    assert text.index("<h2>Verdict</h2>") < text.index("<h2>Accuracy and cost</h2>") < text.index(
        "<h2>Configuration</h2>")
    for v in verdicts(ds):
        assert v.claim in text.replace("&#x27;", "'")
    assert text.count("runs that are not steady</b>") == 6  # every verdict here rests on them
    assert "dp for 1 %" in text and "mm</td>" in text  # the dp needed, in mm


def test_the_case_table_gives_the_metrics_with_their_sampling_error():
    """zeta_f is shown as value +- 2 se where the run carries its standard error, alone where
    it does not (metrics written before the error was kept); both in per cent to two
    significant digits."""
    from study.report import case_table
    ds = campaign(paper_like)
    ds["case_zeta_f"][:] = 0.0077
    ds["case_zeta_f_se"] = xr.full_like(ds["case_zeta_f"], 0.0105)
    ds["case_zeta_f_se"][0] = np.nan
    table = case_table(ds)
    assert table.count("0.77 % &plusmn; 2.1 %") == ds.sizes["case"] - 1
    assert table.count("<td>0.77 %</td>") == 1
    assert "zeta_f [%] (± 2 se)" in table
    # the front body's error beside it; a dash where the metrics predate it
    dashes = table.count("<td>&ndash;</td>")
    ds["case_zeta_f_body"] = xr.full_like(ds["case_zeta_f"], 0.00357)
    ds["case_zeta_f_body_se"] = xr.full_like(ds["case_zeta_f"], 0.000105)
    table = case_table(ds)
    assert table.count("0.36 % &plusmn; 0.021 %") == ds.sizes["case"]
    assert dashes - table.count("<td>&ndash;</td>") == ds.sizes["case"]
    # zeta_u's jackknife error
    ds["case_zeta_u"][:] = 0.0159
    ds["case_zeta_u_se"] = xr.full_like(ds["case_zeta_u"], 0.00029)
    table = case_table(ds)
    assert table.count("1.6 % &plusmn; 0.058 %") == ds.sizes["case"] * ds.sizes["station"]
    assert "zeta_u x*=0.76 [%] (± 2 se)" in table
    # the two the case table mixed as 4.537e-04 ± 0.0016 and 0.0816 ± 0.015
    ds["case_zeta_fs"][:2] = [4.537e-4, 0.0816]
    ds["case_zeta_fs_se"] = ("case", [0.0008, 0.0075] + [np.nan] * (ds.sizes["case"] - 2))
    table = case_table(ds)
    assert "<td>0.045 % &plusmn; 0.16 %</td>" in table and "<td>8.2 % &plusmn; 1.5 %</td>" in table


def test_an_error_reads_in_per_cent_to_two_significant_digits():
    from study.numbers import percent
    assert [percent(v) for v in (4.537e-4, 0.0016, 0.0816, 0.015, 0.01, 1.234, 0.0)] == [
        "0.045 %", "0.16 %", "8.2 %", "1.5 %", "1 %", "120 %", "0 %"]
    assert percent(np.nan) == "-" and percent(np.inf, "&ndash;") == "&ndash;"


def test_the_case_table_gives_the_acoustic_cfl_each_run_used():
    """cfl_rule: damping may lower a case's C_CFL: the table shows what each run took, and a dash
    for a run written before the runs recorded it."""
    from study.report import case_table
    ds = campaign(paper_like)
    dashes = case_table(ds).count("<td>&ndash;</td>")  # case_cfl_acoustic NaN: not recorded
    ds["case_cfl_acoustic"] = ("case", [0.4] * (ds.sizes["case"] - 1) + [0.468])
    table = case_table(ds)
    assert dashes - table.count("<td>&ndash;</td>") == ds.sizes["case"]
    assert "C_CFL used" in table and table.count("<td>0.4</td>") == ds.sizes["case"] - 1
    assert table.count("<td>0.468</td>") == 1


def test_a_yield_stress_campaign_is_not_judged_against_the_newtonian_paper():
    """The paper's conclusions concern a Newtonian fluid: a Herschel-Bulkley campaign's report
    says so instead of giving verdicts on them."""
    ds = campaign(paper_like, steady=lambda dp, ch, sh: dp > 0.001)
    ds.attrs["rheology"] = "herschel_bulkley"
    text = render(ds, [], "grid: {}")
    assert "Does this campaign reproduce" not in text
    assert "not judged here" in text and "herschel_bulkley" in text
    for v in verdicts(ds):
        assert v.claim not in text.replace("&#x27;", "'")
    assert "<h2>Accuracy and cost</h2>" in text


browser = pytest.mark.skipif(find_browser() is None,
                             reason="no Chromium (Debian: apt-get install chromium); .ci/run installs it")


@browser
def test_the_report_in_a_real_browser(tmp_path):
    """Headless Chromium: every figure decodes, nothing is fetched from outside the file, and
    the first screen shows the verdict (screenshot saved)."""
    ds = campaign(paper_like, steady=lambda dp, ch, sh: dp > 0.001)
    z = np.linspace(0, 1, 11)
    theory = xr.Dataset({"velocity": (("station", "z_star"), np.tile(1.5 * z, (STATIONS.size, 1)))},
                        coords={"station": STATIONS, "z_star": z})
    paths = figures.write_all(ds, tmp_path / "figs", figures.Settings(1.8, theory), dpi=40)
    figs = [(p, s.title, s.full_caption(1.8)) for p, s in zip(paths, figures.FIGURES)]
    write(render(ds, figs, "grid: {}"), tmp_path / "report.html")
    r = check_report(tmp_path / "report.html", screenshot=tmp_path / "first_screen.png")
    assert r.ok and len(r.images) == len(figures.FIGURES), (r.broken, r.external)
    assert (tmp_path / "first_screen.png").stat().st_size > 10_000
    # a page with a broken image and an outside request fails the same check
    bad = tmp_path / "bad.html"
    bad.write_text('<html><body><img alt="broken" src="data:image/png;base64,AAAA">'
                   '<img alt="outside" src="http://example.invalid/x.png"></body></html>')
    r = check_report(bad)
    assert r.broken == ["broken", "outside"] and r.external == ["http://example.invalid/x.png"]


def test_an_ensemble_campaign_says_what_its_grid_values_and_errors_are():
    ds = campaign(paper_like)
    assert "Ensemble:" not in render(ds, [], "grid: {}")  # one realisation: nothing to say
    ds["realisations"] = xr.full_like(ds["wall_time"], 3, dtype=int)
    ds.attrs.update(realisations=3, start_perturbation=1e-6)
    text = render(ds, [], "grid: {}")
    assert "every grid case ran in 3 realisations" in text and "start by up to 1e-06 dp" in text
    assert "min_time is raised" not in text  # no stagger: nothing said
    ds.attrs.update(window_stagger=0.25)
    assert "realisation k's steady.min_time is raised by k &times; 0.25 s" in render(ds, [], "grid: {}")
    n_points = ds["wall_time"].size
    assert f"{ds.sizes['case']} cases ({n_points} grid points; every grid case ran in 3 realisations)" in text
    assert "cheapest steady grid point &le; 1 %" in text


def test_an_ensemble_of_different_sizes_names_its_grid_points_by_count():
    """With ensemble.overrides, grid points ran in different numbers of realisations: the report
    lists them by count, most first; an ensemble of one realisation a point says nothing."""
    ds = campaign(paper_like)
    ds["realisations"] = xr.full_like(ds["wall_time"], 1, dtype=int)
    finest = ds["dp"].values.min()
    ds["realisations"].loc[dict(dp=finest)] = 4
    ds.attrs.update(start_perturbation=1e-3)
    text = render(ds, [], "grid: {}")
    four = [str(c) for c in ds["case_id"].sel(dp=finest).values.ravel()]
    rest = [str(c) for c in ds["case_id"].values.ravel() if str(c) not in four]
    assert "grid points ran in 4 realisations: " + ", ".join(four) + "; in 1 realisation: " + ", ".join(rest) in text
    ds["realisations"][:] = 1
    assert "Ensemble:" not in render(ds, [], "grid: {}")


def test_the_verdict_section_says_what_the_runs_start_from_and_which_scheme_they_run():
    from solver.conveyor import case_from_dict
    from study.reference import start_description
    from study.report import verdict_table
    ds = campaign(paper_like)
    case = case_from_dict({"dp": 1e-3, "ch": 1.8, "shifting": "lind"})
    ds.attrs.update(schemes=case.scheme, starts=start_description(case))
    text = html.unescape(verdict_table(ds))
    assert ("The runs start from a block at rest at the normal depth, the belt ramped up from rest; "
            "their scheme, surge, departs") in text
    assert 'href="../docs/numerics.md"' in text
    spec = case_from_dict({"dp": 1e-3, "scheme": "spec"})
    ds.attrs.update(schemes="spec", starts=start_description(spec))
    assert ("the steady lubrication front at the scheme's own film depth, the belt ramped up from rest; their "
            "scheme, spec, is the paper's") in html.unescape(verdict_table(ds))
    film = case_from_dict({"dp": 1e-3, "start": "lubrication", "start_velocity": "lubrication"})
    assert start_description(film) == ("the steady lubrication front at the scheme's own film depth, moving "
                                       "with the film's velocity profile, the belt at full speed")


def test_the_convergence_table_lists_only_the_sequences_that_have_data():
    """The default campaign runs Lind at Ch 1.8 only: its excluded (Ch, shifting) sequences,
    with no value at any dp, get no rows; a sequence with data gets one row per quantity."""
    from study.report import convergence_table
    ds = campaign(paper_like)
    for ch in (1.5, 2.2):  # as the campaign dataset holds the grid's excluded points
        sel = dict(ch=ch, shifting="lind")
        ds["uniform_depth"].loc[sel] = np.nan
        ds["mean_velocity"].loc[sel] = np.nan
        ds["status"].loc[sel] = "missing"
    table = convergence_table(ds)
    rows = table.count("<tr><td")
    assert rows == 4 * (1 + STATIONS.size)  # skillen at three Ch, lind at 1.8; h_u and u* per station
    assert '<td class="l">lind</td><td>1.8</td>' in table
    for ch in ("1.5", "2.2"):
        assert f'<td class="l">lind</td><td>{ch}</td>' not in table
        assert f'<td class="l">skillen</td><td>{ch}</td>' in table
    ds["uniform_depth"][:] = np.nan
    ds["mean_velocity"][:] = np.nan
    assert "<table>" not in convergence_table(ds)


def test_an_observed_order_above_4_is_flagged_and_not_extrapolated():
    """zeta_f and the uniform depth of order 6 over dp (4, 2, 1 mm): the accuracy table and the
    convergence table show the order, flagged unreliable, and no limit, band, GCI or dp from it;
    first-order metrics keep theirs."""
    from study.report import accuracy_table, convergence_table

    def steep(name, dp, ch, sh):
        if name in ("zeta_f", "zeta_h"):
            return 0.02 + 0.01 * (dp / 0.001) ** 6
        return paper_like(name, dp, ch, sh)
    ds = campaign(steep)
    table = accuracy_table(ds)
    zeta_f = table[table.index(">zeta_f<"):table.index(">zeta_h<")]
    assert zeta_f.count("not extrapolated: observed order p = 6, above 4 (unreliable)") == 2  # both methods
    assert zeta_f.count("&ndash; (order above 4: unreliable)") == 2
    assert "(p = 6)" not in table and "(p = 1)" in table  # zeta_fs, first order, is extrapolated
    assert "an order above 4 is unreliable" in table
    conv = convergence_table(ds)
    depth = [row for row in conv.split("<tr>") if "h_u / h_n" in row]
    assert len(depth) == ds.sizes["ch"] * ds.sizes["shifting"]
    for row in depth:
        cells = row.split("</td>")
        assert cells[3].endswith("unreliable") and cells[4].endswith("6 (above 4: unreliable)")
        assert all(c.endswith("&ndash;") for c in cells[5:8]), row


def start_check_campaign(shift: float, tag: str = "paper-start") -> xr.Dataset:
    """A case table of a grid run at dp = 1 mm and its start check (``tag``), whose zeta_h is
    ``shift`` above the grid run's (every se 0.0005)."""
    st = np.array([0.76, 1.5, 9.7])
    ids = ["dp1mm_ch1.8_skillen", f"dp1mm_ch1.8_skillen_{tag}"]
    ds = xr.Dataset({"case_tag": ("case", ["", tag]), "case_steady": ("case", [1, 1]),
                     "case_zeta_u": (("case", "station"), np.full((2, 3), 0.01)),
                     "case_zeta_u_se": (("case", "station"), np.full((2, 3), 0.0005))},
                    coords={"case": ids, "station": st})
    for k, v in (("zeta_f", 0.01), ("zeta_h", 0.002), ("zeta_fs", 0.02)):
        ds[f"case_{k}"] = ("case", [v, v + (shift if k == "zeta_h" else 0.0)])
        ds[f"case_{k}_se"] = ("case", [0.0005, 0.0005])
    return ds


def test_the_start_check_sets_both_starts_side_by_side_and_says_whether_they_agree():
    """zeta_h 0.1 % apart with se 0.05 % each (2 se of the difference 0.14 %): agree; 0.2 %
    apart: zeta_h differs by more than 2 se, the rest agree. Without a start check, no section."""
    from study import startcheck
    from study.report import start_check_section
    tab = startcheck.table(start_check_campaign(0.001))
    assert list(tab["check"].values) == ["dp1mm_ch1.8_skillen_paper-start"]
    assert bool(tab["agree"].all()) and "the two starts agree within 2 se on every metric" in start_check_section(
        start_check_campaign(0.001))
    tab = startcheck.table(start_check_campaign(0.002))
    moved = [str(m) for m, a in zip(tab["metric"].values, tab["agree"].values[0]) if not a]
    assert moved == ["zeta_h"]
    text = start_check_section(start_check_campaign(0.002))
    assert "<b>differ</b> on 1 of 6 metrics by more than 2 se (zeta_h): a real difference" in text
    assert "0.2 %" in text
    assert start_check_section(start_check_campaign(0.0).isel(case=[0])) == ""


@pytest.mark.parametrize("tag, words", [
    ("film-start", "(from the film start: the steady lubrication front moving with the film's velocity profile"),
    ("warm-start", "(from a warm start: the final state of the run at the next coarser dp)")])
def test_a_check_from_another_start_is_paired_and_named_by_its_start(tag, words):
    """A campaign that starts as the paper does is checked from a warm start or the moving film:
    the check pairs with its grid run by its own tag, and the report says which start it ran from."""
    from study import startcheck
    from study.report import start_check_section
    tab = startcheck.table(start_check_campaign(0.001, tag))
    assert list(tab["check"].values) == [f"dp1mm_ch1.8_skillen_{tag}"]
    assert list(tab["start"].values) == [tag] and bool(tab["agree"].all())
    text = html.unescape(start_check_section(start_check_campaign(0.001, tag)))
    assert words in text
    assert "the paper's start: a block" not in text
    assert startcheck.table(start_check_campaign(0.001, "other-start")).sizes["check"] == 0
