# The figures and captions come from one registry, study.figures.FIGURES: those this campaign
# draws (figures_for: the plug map only with a Herschel-Bulkley case).
import os

from study.figures import figures_for

FMT = config["figures"]["format"]
CAPTIONS = os.path.abspath("results/report_captions")  # absolute: Snakemake resolves captions from this file's folder
if FLOW == "conveyor":
    FIGURE_SPECS = figures_for(config)
    FIGURES = [spec.name for spec in FIGURE_SPECS]
    for spec in FIGURE_SPECS:  # Snakemake's report reads each caption from a file
        _write_if_changed(f"{CAPTIONS}/{spec.name}.rst", spec.caption_rst(config["figures"]["profile_ch"]))
else:
    from study.flowreport import figures_for as flow_figures
    from study.figures import rst_text

    FIGURES = [name for name, _, _ in flow_figures(config)]
    for name, title, caption in flow_figures(config):
        _write_if_changed(f"{CAPTIONS}/{name}.rst", rst_text(f"{title}. {caption}"))


rule figures:
    input:
        "results/campaign.nc",
    output:
        [report(f"results/figures/{f}.{FMT}", caption=f"{CAPTIONS}/{f}.rst", category="Figures")
         for f in FIGURES],
    params:
        settings=lambda wc: yaml.safe_dump(config["figures"]),
        config=CONFIG_FILE,
    log:
        "results/logs/figures.log",
    shell:
        "python -m study figures {params.config} {input} -o results/figures > {log} 2>&1"


rule report_html:
    input:
        campaign="results/campaign.nc",
        figures=expand("results/figures/{f}.{fmt}", f=FIGURES, fmt=FMT),
    output:
        "reports/report.html",
    params:
        config=CONFIG_FILE,
    log:
        "results/logs/report_html.log",
    shell:
        "python -m study report {params.config} {input.campaign} --figures results/figures -o {output} > {log} 2>&1"
