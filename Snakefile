# sph-surge convergence campaign: snakemake --cores 2 [--configfile config/paper.yaml]
from snakemake.utils import min_version

min_version("8.0")

configfile: "config/config.yaml"


include: "workflow/rules/common.smk"
include: "workflow/rules/simulate.smk"
include: "workflow/rules/analyse.smk"
include: "workflow/rules/report.smk"


localrules: all, case_file  # writing a case's YAML is no cluster job


rule all:
    input:
        "reports/report.html",
