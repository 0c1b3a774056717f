"""A run's whole state (the simulation's arrays, the results so far, the next sampling times and
monitors), pickled atomically now and then, so that a killed run resumes to the same result bit
for bit. A checkpoint carries a key: it resumes only the run it was written for."""
from __future__ import annotations

import hashlib
import os
import pickle
import sys
import tempfile

from .sources import source_hash


def run_key(text: str, threads: int) -> str:
    """The key of a run of the case or scene ``text`` (its YAML) on these solver sources and this
    thread count (another thread count sums in another order: the result would differ)."""
    return hashlib.sha256(f"{text}\nsolver {source_hash()}\nthreads {threads}".encode()).hexdigest()[:16]


class Checkpointer:
    """Pickles the runner state every ``interval`` of simulated time (an ``on_step`` hook of
    ``Runner.run``), atomically; with ``wall_interval``, also once that many wall seconds have
    passed since the last."""

    def __init__(self, path, interval: float, key: str, wall_interval: float | None = None):
        self.path, self.interval, self.key = os.fspath(path), interval, key
        self.wall_interval = wall_interval
        self.next = None
        self.wall_next = None
        self.start = None  # (flux ratio, how the start's depth was chosen), saved with the state

    def __call__(self, runner):
        if self.next is None:
            self.next = runner.sim.t + self.interval
        wall = runner.elapsed()
        if self.wall_next is None and self.wall_interval is not None:
            self.wall_next = wall + self.wall_interval
        due_wall = self.wall_next is not None and wall >= self.wall_next
        due_sim = runner.sim.t >= self.next - 1e-12
        if due_sim or due_wall:
            if due_sim:
                self.next += self.interval
            if self.wall_next is not None:
                self.wall_next = wall + self.wall_interval
            self.save(runner)

    def save(self, runner):
        state = {"key": self.key, "sim": runner.sim.state(), "res": runner.res,
                 "next_out": runner.next_out, "next_diag": runner.next_diag,
                 "next_monitor": runner.next_monitor, "monitors": runner.monitors,
                 "next_checkpoint": self.next, "wall_time": runner.elapsed(),
                 "start": self.start}
        folder = os.path.dirname(os.path.abspath(self.path))
        os.makedirs(folder, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=os.path.basename(self.path) + ".", suffix=".tmp", dir=folder)
        with os.fdopen(fd, "wb") as fh:
            pickle.dump(state, fh, protocol=pickle.HIGHEST_PROTOCOL)
        os.replace(tmp, self.path)

    def load(self) -> dict | None:
        """The checkpoint's state when it matches this case, solver and thread count; None
        when there is none, it cannot be read, or it is another's (with a note)."""
        if not os.path.exists(self.path):
            return None
        try:
            with open(self.path, "rb") as fh:
                state = pickle.load(fh)
        except Exception:
            return None
        if state.get("key") != self.key:
            print(f"note: ignoring the checkpoint {self.path}: written for another case, solver "
                  "version or thread count; starting from t = 0", file=sys.stderr)
            return None
        return state

    def restore(self, runner, state: dict) -> None:
        """Put a checkpoint's state (from ``load``) into the runner."""
        runner.sim.restore(state["sim"])
        runner.res = state["res"]
        runner.res.wall_time = state["wall_time"]
        runner.next_out, runner.next_diag = state["next_out"], state["next_diag"]
        runner.next_monitor, runner.monitors = state["next_monitor"], state["monitors"]
        self.next = state["next_checkpoint"]
