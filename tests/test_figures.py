"""The report's figures from a synthetic campaign: every registered figure draws; dp axes in
mm with plain tick labels; one legend entry per Ch; the GCI band on the finest point."""
import matplotlib.pyplot as plt
import numpy as np
import xarray as xr

from campaign_data import STATIONS, campaign
from study import figures


def metric(name, dp, ch, sh):
    if name == "zeta_u":
        return np.array([0.04, 0.03, 0.01]) + 2 * dp
    return 0.001 + 5 * dp * ch  # first order, monotone: a GCI exists


def test_every_registered_figure_draws(tmp_path):
    ds = campaign(metric, steady=lambda dp, ch, sh: dp > 0.001)
    z = np.linspace(0, 1, 11)
    theory = xr.Dataset({"velocity": (("station", "z_star"), np.tile(1.5 * z, (STATIONS.size, 1)))},
                        coords={"station": STATIONS, "z_star": z})
    paths = figures.write_all(ds, tmp_path, figures.Settings(1.8, theory), dpi=40)
    assert [p.stem for p in paths] == list(figures.FIGURE_NAMES)
    assert all(p.stat().st_size > 1000 for p in paths)


def test_dp_axis_legend_and_gci_band():
    ds = campaign(metric, steady=lambda dp, ch, sh: dp > 0.001)
    with plt.rc_context(figures.STYLE):
        fig = figures._metric_figure(ds, "zeta_f", "zeta_f")
    fig.canvas.draw()
    ax = fig.axes[0]
    ticks = [t.get_text() for t in ax.get_xticklabels() if t.get_text()]
    assert ticks == ["4", "2", "1"]  # the campaign's dp in mm, no 10^x notation
    assert ax.get_xlabel() == "particle spacing dp [mm]"
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert labels == ["Ch = 1.5", "Ch = 1.8", "Ch = 2.2", "steady window", "final window, not steady"]
    bars = [c for c in ax.containers if c.__class__.__name__ == "ErrorbarContainer"]
    assert len(bars) == 3  # one GCI band per Ch, on the finest point
    seg = bars[0].lines[2][0].get_segments()[0]
    assert seg[0][0] == seg[1][0] == 1.0  # at dp = 1 mm
    plt.close(fig)


def test_fig7_colours_by_speed_only_when_the_dataset_has_speeds():
    ds = campaign(metric)
    with_speed = figures.fig_front_particles(ds, 1.8)
    assert [a.get_ylabel() for a in with_speed.axes][-1] == "|u| / u_b (lab frame)"  # the colour bar
    without = figures.fig_front_particles(ds.drop_vars("front_speed"), 1.8)
    assert len(without.axes) == len(with_speed.axes) - 1  # no colour bar, one colour
    plt.close("all")


def test_sampling_error_bars_on_every_point_that_has_one():
    """With zeta_u_se in the dataset, fig. 8 draws one capless +- 2 se bar per shifting method
    and station over the dp that have a finite se (here 2 of 3), besides the GCI bands; the
    upper arm is 2 se long."""
    ds = campaign(metric)
    ds["zeta_u_se"] = xr.full_like(ds["zeta_u"], 0.001)
    ds["zeta_u_se"].loc[dict(dp=0.004)] = np.nan
    with plt.rc_context(figures.STYLE):
        fig = figures.fig_shifting_comparison(ds, "zeta_u", 1.8, station_panels=True)
    for ax in fig.axes:
        bars = [c for c in ax.containers if c.__class__.__name__ == "ErrorbarContainer"]
        se_bars = [b for b in bars if not b.lines[1]]  # no caps
        assert len(se_bars) == 2  # skillen and lind
        segs = se_bars[0].lines[2][0].get_segments()
        assert len(segs) == 2
        top = [max(s[:, 1]) for s in segs]
        mid = sorted(float(v) for v in ds["zeta_u"].sel(ch=1.8, shifting="skillen", dp=[0.002, 0.001]).sel(
            station=float(ax.get_title().split("= ")[1])).values)
        np.testing.assert_allclose(sorted(top), [m + 0.002 for m in mid], rtol=1e-12)
    plt.close(fig)


def test_every_caption_reads_as_plain_restructured_text():
    """Snakemake's report parses the captions as reStructuredText: |u| and u*_f must come out as
    written, with no substitution or emphasis and no docutils error (it printed two)."""
    from docutils.core import publish_doctree
    from docutils.nodes import system_message

    from study.figures import FIGURES, rst_text
    assert rst_text("|u*_f - u*_b| / u*_b") == r"\|u\*\_f - u\*\_b\| / u\*\_b"
    for spec in FIGURES:
        tree = publish_doctree(spec.caption_rst(1.8), settings_overrides={"report_level": 5, "halt_level": 5})
        assert not list(tree.findall(system_message)), spec.name
        assert tree.astext().strip() == f"{spec.title}. {spec.full_caption(1.8)}", spec.name


def _config(name, **changes):
    import yaml
    from pathlib import Path

    from study.config import validate
    cfg = yaml.safe_load((Path(__file__).resolve().parent.parent / "config" / name).read_text())
    return validate({**cfg, **changes})


def test_the_plug_map_is_drawn_only_for_a_campaign_with_a_yield_stress_case():
    """figures_for (the rules' outputs and both reports): a Newtonian campaign has no plug map,
    a Herschel-Bulkley one has it, and so has a Newtonian grid with one Herschel-Bulkley extra
    case; every other figure is drawn for all three."""
    hb = {"rheology": "herschel_bulkley", "density": 1000.0, "yield_stress": 20.0, "consistency": 10.0,
          "index": 0.4, "max_viscosity": 100.0}
    newtonian = _config("config.yaml")
    mixed = _config("config.yaml", extra_cases=[{"dp": 2.25e-3, "ch": 1.8, "shifting": "lind", "tag": "hb",
                                                 "overrides": hb}])
    others = [n for n in figures.FIGURE_NAMES if n not in ("fig13_plug_map", "fig14_sweep")]
    from study.flows.conveyor import FLOW
    assert [name for name, _, _ in FLOW.figures(newtonian)] == others
    for cfg in (_config("viscoplastic.yaml"), mixed):
        assert [name for name, _, _ in FLOW.figures(cfg)] == [n for n in figures.FIGURE_NAMES if n != "fig14_sweep"]


def test_a_newtonian_campaign_neither_draws_nor_reports_the_plug_map(tmp_path):
    """python -m study figures and report, as the rules call them, on a Newtonian campaign
    dataset: no plug-map file, and the HTML report neither shows nor names it."""
    import yaml

    from study.cli import main
    ds = campaign(metric, steady=lambda dp, ch, sh: dp > 0.001)
    ds.to_netcdf(tmp_path / "campaign.nc")
    cfg = _config("config.yaml")
    cfg["figures"]["dpi"] = 50
    (tmp_path / "config.yaml").write_text(yaml.safe_dump(cfg))
    out = tmp_path / "figures"
    assert main(["figures", str(tmp_path / "config.yaml"), str(tmp_path / "campaign.nc"), "-o", str(out)]) == 0
    drawn = sorted(p.stem for p in out.iterdir())
    assert drawn == sorted(n for n in figures.FIGURE_NAMES if n not in ("fig13_plug_map", "fig14_sweep"))
    report = tmp_path / "report.html"
    assert main(["report", str(tmp_path / "config.yaml"), str(tmp_path / "campaign.nc"), "--figures", str(out),
                 "-o", str(report)]) == 0
    text = report.read_text()
    assert text.count("<figure ") == len(drawn)
    assert "fig13_plug_map" not in text and "Where the plug is" not in text
    plt.close("all")


def _tick_labels(axis):
    """Every label of the major and minor ticks in view, and the axis's offset text."""
    lo, hi = sorted(axis.get_view_interval())
    labels = [t.get_text() for minor in (False, True) for t in axis.get_ticklabels(minor=minor)
              if t.get_text() and lo <= t.get_position()[axis.axis_name == "y"] <= hi]
    return labels + [axis.get_offset_text().get_text()]


def test_every_axis_of_every_figure_has_plain_tick_labels():
    """Run times within a factor 2 (30 to 60 s: matplotlib labels a log axis spanning less than
    a decade at its minor ticks, as 3x10^1) and errors within one decade: every tick label of
    every figure is a plain number, errors in per cent; no mathtext, no offset."""
    ds = campaign(metric, steady=lambda dp, ch, sh: dp > 0.001)
    ds["wall_time"][:] = np.linspace(30, 60, ds["wall_time"].size).reshape(ds["wall_time"].shape)
    z = np.linspace(0, 1, 11)
    theory = xr.Dataset({"velocity": (("station", "z_star"), np.tile(1.5 * z, (STATIONS.size, 1)))},
                        coords={"station": STATIONS, "z_star": z})
    settings = figures.Settings(1.8, theory)
    for spec in figures.FIGURES:
        with plt.rc_context(figures.STYLE):
            fig = spec.draw(ds, settings)
            fig.canvas.draw()
        for ax in fig.axes:
            for axis in (ax.xaxis, ax.yaxis):
                if axis.get_label_text() and axis.get_visible():  # a labelled axis is numbered
                    shown = [t.get_text() for t in axis.get_ticklabels() if t.get_visible() and t.get_text()]
                    assert shown, (spec.name, axis.get_label_text())
                for label in _tick_labels(axis):
                    assert not any(m in label for m in ("$", "10^", "times", "×", "e+", "e-")), (spec.name, label)
                if axis.get_scale() == "log" and axis.axis_name == "y":  # the errors
                    assert all(t.endswith(" %") for t in _tick_labels(axis)[:-1]), spec.name
        if spec.name == "fig11_cost_vs_error":
            wall = _tick_labels(fig.axes[0].xaxis)
            assert {"30", "40", "60"} <= set(wall), wall
            assert set(_tick_labels(fig.axes[0].yaxis)) >= {"1 %", "2 %", "3 %"}
        plt.close(fig)


def test_no_gci_band_from_an_observed_order_above_4():
    dp = np.array([0.004, 0.002, 0.001])
    assert np.isnan(figures._gci_band(dp, 0.02 + 0.01 * (dp / 0.001) ** 6))
    assert figures._gci_band(dp, 0.02 + 0.01 * (dp / 0.001) ** 3) > 0
