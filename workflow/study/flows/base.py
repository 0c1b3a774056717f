"""What every flow gives the campaign (docs/flows.md): one object per flow, found by the
campaign's ``flow`` key in ``study.registry``. The rules and the CLI ask it; nothing outside
the registry asks which flow it is."""
from __future__ import annotations

from pathlib import Path

import xarray as xr

from ..grid import Case


class Flow:
    """A flow's campaign: its schema and cases, the solver command and file of each case, the
    scoring of a run, the reduction of the runs into one dataset, its figures and report."""

    name: str = ""
    title: str = ""  # what the report's lead says the flow is
    schema: Path = Path()
    solver: str = "run"  # the ``python -m solver`` command that runs a case file
    metric_keys: tuple[str, ...] = ()  # the campaign keys whose change rescores every run

    def metric_sources(self) -> list[Path]:
        """The source files whose change rescores every run."""
        raise NotImplementedError

    def file_keys(self, cfg: dict) -> list[tuple]:
        """The key paths of the campaign's file names (read relative to the campaign file)."""
        return []

    def validate(self, cfg: dict) -> dict:
        """The campaign with its defaults; ConfigError naming the key of anything invalid, every
        case's solver file included, before any job starts."""
        raise NotImplementedError

    def cases(self, cfg: dict) -> list[Case]:
        raise NotImplementedError

    def case_dict(self, cfg: dict, case: Case) -> dict:
        """The solver file of one case: a conveyor case file (``solver front``) or a scene."""
        raise NotImplementedError

    def warm_source(self, cfg: dict, case: Case) -> Case | None:
        """The case whose final state starts this one; None for a cold start."""
        return None

    def score(self, cfg: dict, case_id: str, run: xr.Dataset) -> xr.Dataset:
        """One run's metrics against its own reference (metrics.nc)."""
        raise NotImplementedError

    def reduce(self, cfg: dict, results: Path) -> xr.Dataset:
        """Every case's run and metrics under ``results/<case id>/`` into the campaign dataset."""
        raise NotImplementedError

    def figures(self, cfg: dict) -> list[tuple[str, str, str]]:
        """(name, title, caption) of each figure the campaign draws."""
        raise NotImplementedError

    def write_figures(self, cfg: dict, ds: xr.Dataset, outdir) -> list[Path]:
        raise NotImplementedError

    def render(self, cfg: dict, ds: xr.Dataset, figure_dir) -> str:
        """The report's HTML."""
        raise NotImplementedError

    def case_by_id(self, cfg: dict, case_id: str) -> Case:
        for c in self.cases(cfg):
            if c.id == case_id:
                return c
        raise KeyError(f"case {case_id!r} is not in this campaign")
