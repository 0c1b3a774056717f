# The campaign, read and checked before any job starts (its flow's schema, then what a schema
# cannot check), its flow (study.registry: every flow-specific choice below is the flow's), and
# where it writes (study.layout).
import shlex
import sys

import yaml
from study.config import validate as validate_campaign
from study.grid import CASE_ID, critical_paths
from study.layout import report_path, results_dir, run_path
from study.registry import flow_of
from study.schema import ConfigError

CAMPAIGN_FILE = os.path.abspath(workflow.overwrite_configfiles[-1] if workflow.overwrite_configfiles
                                else DEFAULT_CAMPAIGN)
config = validate_campaign(config, source=CAMPAIGN_FILE)
FLOW = flow_of(config)
CASES = FLOW.cases(config)
CASE_IDS = [c.id for c in CASES]
CASE_BY_ID = {c.id: c for c in CASES}
RES = config["resources"]
R = results_dir(config)  # results/<name>
REPORT = report_path(config)
PY = shlex.quote(sys.executable)  # the interpreter that runs Snakemake runs the rules


def _write_if_changed(path, text):
    """Write ``text`` to ``path`` (atomically) only when it changes."""
    old = open(path).read() if os.path.exists(path) else None
    if old != text:
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with open(f"{path}.tmp", "w") as fh:
            fh.write(text)
        os.replace(f"{path}.tmp", path)


# One campaign file a name: a second file with the same name would share its runs and report.
# The file is recorded relative to the working directory where it lies inside it (a moved
# checkout keeps its campaigns).
_SOURCE = f"{R}/campaign_source.txt"
_FILE = os.path.relpath(CAMPAIGN_FILE) if not os.path.relpath(CAMPAIGN_FILE).startswith("..") else CAMPAIGN_FILE
if os.path.exists(_SOURCE) and os.path.abspath(open(_SOURCE).read().strip()) != CAMPAIGN_FILE:
    raise ConfigError(f"config key name: {config['name']!r} is the name of the campaign "
                      f"{open(_SOURCE).read().strip()}, whose results are in {R}/; give {_FILE} "
                      "another name (name: ...), or delete that folder")
_write_if_changed(_SOURCE, f"{_FILE}\n")

# The merged, validated config for our CLIs; rewritten only when it changes. Rules take it as
# a param, not an input, and list the settings they use as params, so a change to figure
# settings does not rerun simulations.
CONFIG_FILE = f"{R}/campaign_config.yaml"
_write_if_changed(CONFIG_FILE, yaml.safe_dump(config, sort_keys=False))

from solver.sources import files_hash, source_hash

SOLVER_HASH = source_hash()  # a param of every run: a changed solver reruns them
METRICS_HASH = files_hash(FLOW.metric_sources(), names=False)  # a param of the metrics: new code rescores
METRIC_KEYS = FLOW.metric_keys

wildcard_constraints:
    case=CASE_ID,


# Every case's solver settings in one file, for the kernels' compilation, which then starts with
# the first job instead of after every case file.
KERNEL_CASES = f"{R}/kernel_cases.yaml"
_write_if_changed(KERNEL_CASES, yaml.safe_dump([FLOW.case_dict(config, c) for c in CASES], sort_keys=True))


def case_yaml(wildcards):
    """The solver file of one case: a param, so only its own settings rerun it."""
    return yaml.safe_dump(FLOW.case_dict(config, CASE_BY_ID[wildcards.case]), sort_keys=True)


def warm_input(wildcards):
    """The run a warm-started case starts from (none for a cold start)."""
    src = FLOW.warm_source(config, CASE_BY_ID[wildcards.case])
    return [run_path(config, src.id)] if src is not None else []


# Each run's priority: its critical path, the cost ~ dp^-3 of the run and of the longest chain of
# warm starts that waits on it, so that the longest chain starts first and the runs that wait on
# nothing fill the other cores (without warm starts: finer runs first).
RUN_PRIORITY = {k: round(v, 3) for k, v in critical_paths(
    CASES, lambda c: 1e-9 / c.dp ** 3, lambda c: FLOW.warm_source(config, c)).items()}


def run_priority(wildcards):
    return RUN_PRIORITY[wildcards.case]
