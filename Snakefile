# sph-surge convergence campaign: snakemake --cores 2 [--configfile config/paper.yaml]
# Each campaign writes under results/<name>/ and its report to reports/<name>/report.html
# (name: the campaign's name key, default its file's stem; the default campaign's is config).
import os

from snakemake.utils import min_version

min_version("8.0")

# The default campaign, unless --configfile names another: a campaign file is complete in
# itself, so that the default's grid exclusions, case_overrides and case keys never merge into
# it (--config KEY=VALUE still edits whichever campaign runs).
DEFAULT_CAMPAIGN = os.path.join(workflow.basedir, "config", "config.yaml")
if not workflow.overwrite_configfiles:

    configfile: DEFAULT_CAMPAIGN


include: "workflow/rules/common.smk"
include: "workflow/rules/simulate.smk"
include: "workflow/rules/analyse.smk"
include: "workflow/rules/report.smk"


localrules: all, case_file  # writing a case's YAML is no cluster job


rule all:
    input:
        REPORT,
