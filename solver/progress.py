"""A running case's progress as a small JSON file, rewritten atomically every few wall seconds:
simulated time, for a front run the latest window pair's drift ratios, and when the run can end
(``python -m study status`` reads these files)."""
from __future__ import annotations

import json
import math
import os
import tempfile
import time as _time


class ProgressFile:
    """Called after every step (``Runner.run``'s ``on_step``); writes ``path`` at most every
    ``every`` s of wall time; ``write`` with the run's status once it has ended."""

    def __init__(self, path, case_name: str, monitor, max_time: float, every: float = 5.0):
        self.path, self.name, self.monitor, self.max_time, self.every = os.fspath(path), case_name, monitor, \
            max_time, every
        self.last = -math.inf
        self.t_sim0 = None
        self.wall0 = None

    def __call__(self, runner):
        now = _time.perf_counter()
        if self.t_sim0 is None:
            self.t_sim0, self.wall0 = runner.sim.t, now
        if now - self.last >= self.every:
            self.write(runner, "running")
            self.last = now

    def state(self, runner, status: str) -> dict:
        """The record written: the run's rate is simulated seconds per wall second since this
        process started; a front run's end lies between the first time a pair may end (or now)
        and max_time, a scene run's (``monitor`` None) at its end time; the wall estimates at
        that rate."""
        t = float(runner.sim.t)
        rate = (t - self.t_sim0) / max(_time.perf_counter() - self.wall0, 1e-9) if self.t_sim0 is not None else 0.0
        det = self.monitor.detector if self.monitor is not None else None
        if det is None:
            earliest, last, found = self.max_time, None, False
        else:
            earliest = max(det.earliest_end if math.isfinite(det.t_first) else det.crit.min_time + 2 * det.crit.window,
                           t)
            last, found = det.found or det.last, det.found is not None
        ratios = {q: (r if math.isfinite(r) else None) for q, r in last.ratios.items()} if last else {}

        def wall_to(t_end):
            return (t_end - t) / rate if rate > 0 else None

        return {"case": self.name, "status": status, "t": t, "max_time": self.max_time,
                "wall_s": float(runner.elapsed()), "sim_s_per_wall_s": rate,
                "steady": found, "detector": det is not None, "t_end_earliest": min(earliest, self.max_time),
                "wall_left_min_s": wall_to(min(earliest, self.max_time)), "wall_left_max_s": wall_to(self.max_time),
                "drift_ratios": ratios, "written": _time.time()}

    def write(self, runner, status: str):
        folder = os.path.dirname(os.path.abspath(self.path))
        os.makedirs(folder, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=os.path.basename(self.path) + ".", suffix=".tmp", dir=folder)
        with os.fdopen(fd, "w") as fh:
            json.dump(self.state(runner, status), fh)
        os.replace(tmp, self.path)


def chain(*hooks):
    """One on_step hook that calls each of ``hooks`` that is not None."""
    hooks = [h for h in hooks if h is not None]
    if not hooks:
        return None

    def call(runner):
        for h in hooks:
            h(runner)
    return call
