"""Where a campaign writes: everything under ``results/<name>/`` and its report at
``reports/<name>/report.html``, relative to the directory Snakemake runs in; ``name`` is the
campaign's ``name`` key (default: its file's stem)."""
from __future__ import annotations


def results_dir(cfg: dict) -> str:
    return f"results/{cfg['name']}"


def case_dir(cfg: dict, case_id: str) -> str:
    return f"{results_dir(cfg)}/cases/{case_id}"


def run_path(cfg: dict, case_id: str) -> str:
    """A case's run (the solver's NetCDF)."""
    return f"{case_dir(cfg, case_id)}/run.nc"


def report_path(cfg: dict) -> str:
    return f"reports/{cfg['name']}/report.html"
