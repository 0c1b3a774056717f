# sph-surge convergence campaign: snakemake --cores 2 [--configfile config/paper.yaml]
from snakemake.utils import min_version

min_version("8.0")

# The default campaign, unless --configfile names another: a campaign file is complete in
# itself, so that the default's grid exclusions, case_overrides and case keys never merge into
# it (--config KEY=VALUE still edits whichever campaign runs).
if not workflow.overwrite_configfiles:

    configfile: "config/config.yaml"


include: "workflow/rules/common.smk"
include: "workflow/rules/simulate.smk"
include: "workflow/rules/analyse.smk"
include: "workflow/rules/report.smk"


localrules: all, case_file  # writing a case's YAML is no cluster job


rule all:
    input:
        "reports/report.html",
