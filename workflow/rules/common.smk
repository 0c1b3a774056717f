# Config validation (schema, then what a schema cannot check) before any job starts,
# and the case grid.
import yaml
from study.config import validate as validate_campaign, cases as campaign_cases, case_dict, run_path, warm_source
from study.grid import CASE_ID

config = validate_campaign(config)  # the schema (with its defaults), then what it cannot check
FLOW = config.get("flow", "conveyor")  # conveyor, or a flow of study.flowconfig
if FLOW != "conveyor":
    from study import flowconfig
    from study.flowconfig import CASE_ID

    campaign_cases = flowconfig.cases
    case_dict = flowconfig.scene_dict
CASES = campaign_cases(config)
CASE_IDS = [c.id for c in CASES]
CASE_BY_ID = {c.id: c for c in CASES}
RES = config["resources"]


def _write_if_changed(path, text):
    """The merged, validated config for our CLIs; rewritten only when it changes. Rules take
    it as a param, not an input, and list the settings they use as params, so a change to
    figure settings does not rerun simulations."""
    import os
    old = open(path).read() if os.path.exists(path) else None
    if old != text:
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with open(f"{path}.tmp", "w") as fh:
            fh.write(text)
        os.replace(f"{path}.tmp", path)


CONFIG_FILE = "results/campaign_config.yaml"
_write_if_changed(CONFIG_FILE, yaml.safe_dump(config, sort_keys=False))

from solver.sources import files_hash, source_hash

SOLVER_HASH = source_hash()  # a param of every run: a changed solver reruns them

import study.metrics, study.reference

# a param of the metrics: new metric code rescores
if FLOW == "conveyor":
    METRICS_HASH = files_hash([study.metrics.__file__, study.reference.__file__], names=False)
    METRIC_KEYS = ("reference", "metrics")
else:
    import pathlib

    import study.flowcampaign, study.flowconfig, study.flows

    METRICS_HASH = files_hash([study.flowcampaign.__file__, study.flowconfig.__file__]
                              + sorted(pathlib.Path(study.flows.__file__).parent.glob("*.py")), names=False)
    METRIC_KEYS = ("scene", "fluids", "metrics")

wildcard_constraints:
    case=CASE_ID,


def case_yaml(wildcards):
    """The solver case of one campaign case: a param, so only its own settings rerun it."""
    return yaml.safe_dump(case_dict(config, CASE_BY_ID[wildcards.case]), sort_keys=True)


def warm_input(wildcards):
    """The coarser case's run a warm-started case starts from (none without warm_start)."""
    if FLOW != "conveyor":
        return []
    src = warm_source(config, CASE_BY_ID[wildcards.case])
    return [run_path(src)] if src is not None else []


def run_priority(wildcards):
    """Finer cases first (cost ~ dp^-3): the longest runs start at once, so that the cores
    finish together instead of one long run starting last."""
    return round(1e-9 / CASE_BY_ID[wildcards.case].dp ** 3, 3)


# the solver command of a run: the conveyor front to steady state, or a flow's scene to its end
if FLOW == "conveyor":
    RUN_COMMAND = ("NUMBA_NUM_THREADS={threads} python -m solver front {input.case} -o {output} "
                   "--threads {threads} --quiet --allow-diverged "
                   "--checkpoint results/checkpoints/{wildcards.case}.ckpt "
                   "--progress results/progress/{wildcards.case}.json 2> {log}")
else:
    RUN_COMMAND = ("NUMBA_NUM_THREADS={threads} python -m solver run {input.case} -o {output} "
                   "--threads {threads} --quiet --allow-diverged 2> {log}")
