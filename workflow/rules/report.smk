# The figures and captions come from the flow (FLOW.figures: for the conveyor, the registry
# study.figures.FIGURES; the plug map only with a Herschel-Bulkley case, the sweep figure
# only with a physical axis).
from study.figures import rst_text

FMT = config["figures"]["format"]
CAPTIONS = os.path.abspath(f"{R}/report_captions")  # absolute: Snakemake resolves captions from this file's folder
FIGURES = [name for name, _, _ in FLOW.figures(config)]
for _name, _title, _caption in FLOW.figures(config):  # Snakemake's report reads each caption from a file
    _write_if_changed(f"{CAPTIONS}/{_name}.rst", f"**{rst_text(_title)}.** {rst_text(_caption)}\n")


rule figures:
    input:
        f"{R}/campaign.nc",
    output:
        [report(f"{R}/figures/{f}.{FMT}", caption=f"{CAPTIONS}/{f}.rst", category="Figures")
         for f in FIGURES],
    params:
        settings=lambda wc: yaml.safe_dump(config["figures"]),
        config=CONFIG_FILE,
    log:
        f"{R}/logs/figures.log",
    shell:
        f"{PY} -m study figures {{params.config}} {{input}} -o {R}/figures > {{log}} 2>&1"


rule report_html:
    input:
        campaign=f"{R}/campaign.nc",
        figures=expand(f"{R}/figures/{{f}}.{{fmt}}", f=FIGURES, fmt=FMT),
    output:
        REPORT,
    params:
        config=CONFIG_FILE,
    log:
        f"{R}/logs/report_html.log",
    shell:
        f"{PY} -m study report {{params.config}} {{input.campaign}} --figures {R}/figures -o {{output}} > {{log}} 2>&1"
