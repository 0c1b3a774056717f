"""Run a conveyor case with extra series sampled at every probe sample (a benchmarks helper).

``run_sampled(case, sample)`` runs ``case`` through ``solver.front.run_front`` with the front
monitor's ``sample`` extended: after the monitor's own sample ``d`` (with ``d["toe"]``) it
calls ``sample(sim, d, case)`` and appends each value of the dict returned to that key's
series. The module's FrontMonitor is replaced for the run only and restored after it.
"""
from __future__ import annotations

import sys
from typing import Callable

import numpy as np


def load_case(path: str, sets):
    """The conveyor case in file ``path`` with ``--set KEY=VALUE`` overrides applied."""
    from solver.cli import apply_overrides
    from solver.conveyor import case_from_dict
    from solver.scene import read_yaml

    return case_from_dict(apply_overrides(read_yaml(path) or {}, sets))


def run_sampled(case, sample: Callable) -> tuple:
    """(the run's dataset, {key: array of the values ``sample`` returned, one per probe sample})."""
    from solver import front

    series: dict[str, list] = {}

    class SampledMonitor(front.FrontMonitor):
        def sample(self, sim):
            d = super().sample(sim)
            for k, v in sample(sim, d, self.case).items():
                series.setdefault(k, []).append(v)
            return d

    shipped = front.FrontMonitor
    front.FrontMonitor = SampledMonitor
    try:
        ds = front.run_front(case, quiet=True)
    finally:
        front.FrontMonitor = shipped
    return ds, {k: np.asarray(v) for k, v in series.items()}


def report(case, ds, out: str) -> None:
    """One line on stderr: the run's status, simulated time, wall time and output file, and the
    reason of a run that diverged."""
    why = f" ({ds.attrs.get('reason', '')})" if ds.attrs["status"] == "diverged" else ""
    print(f"{case.name}: {ds.attrs['status']} at {ds.attrs['simulated_time_s']:.2f} s, "
          f"{ds.attrs['wall_time_s']:.0f} s wall -> {out}{why}", file=sys.stderr)
