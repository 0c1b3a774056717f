"""pytest plugin: the numba compile seconds of a test session, by function.

Times every numba compilation of the pytest process by numba's compile events; a compilation
started inside another (a callee typed while its caller compiles) counts in its caller's
seconds. Compilations in subprocesses (the Snakemake and CLI tests) are not seen. At the end
it writes the sum and one line a function (seconds, compilations) to $COMPILE_EVENTS_OUT
(default compile_events.txt). Run with an empty cache to see the cold suite's compile time:

    SPH_SURGE_CACHE_DIR=$(mktemp -d) PYTHONPATH=benchmarks python -m pytest -q -p compile_events

Imported elsewhere (``benchmarks/compile_time.py``), it records from the import on; ``totals``
reads what it has recorded.
"""
from __future__ import annotations

import collections
import os
import time

from numba.core import event

_records: list[tuple[str, float]] = []


class _Timer(event.Listener):
    def __init__(self):
        self.open: list[float] = []

    def on_start(self, ev):
        self.open.append(time.perf_counter())

    def on_end(self, ev):
        t0 = self.open.pop()
        if not self.open:
            d = ev.data["dispatcher"]
            _records.append((d.py_func.__module__ + "." + d.py_func.__qualname__, time.perf_counter() - t0))


event.register("numba:compile", _Timer())


def totals() -> dict[str, list]:
    """{function: [compile seconds, compilations]} of every compilation recorded so far."""
    out: dict[str, list] = collections.defaultdict(lambda: [0.0, 0])
    for name, seconds in _records:
        out[name][0] += seconds
        out[name][1] += 1
    return dict(out)


def pytest_sessionfinish(session, exitstatus):
    totals_ = totals()
    with open(os.environ.get("COMPILE_EVENTS_OUT", "compile_events.txt"), "w") as f:
        f.write(f"compile seconds in all: {sum(v[0] for v in totals_.values()):.1f}\n")
        for name, (seconds, count) in sorted(totals_.items(), key=lambda kv: -kv[1][0]):
            f.write(f"{seconds:8.2f} s {count:4d}x {name}\n")
