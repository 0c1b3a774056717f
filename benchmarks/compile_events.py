"""pytest plugin: the numba compile seconds of a test session, by function.

Times every numba compilation of the pytest process by numba's compile events; a compilation
started inside another (a callee typed while its caller compiles) counts in its caller's
seconds. Compilations in subprocesses (the Snakemake and CLI tests) are not seen. At the end
it writes the sum and one line a function (seconds, compilations) to $COMPILE_EVENTS_OUT
(default compile_events.txt). Run with an empty cache to see the cold suite's compile time:

    SPH_SURGE_CACHE_DIR=$(mktemp -d) PYTHONPATH=benchmarks python -m pytest -q -p compile_events

Imported elsewhere (``benchmarks/compile_time.py``), it records from the import on; ``totals``
reads what it has recorded. Under pytest it also lists, per test, the seconds it compiled and,
for each pair-loop variant (``forces.make_pair_loop``), its switches (in that function's
order) and the test that compiled it: the tests that alone need a variant are where a cold suite's time goes.
"""
from __future__ import annotations

import collections
import os
import time

from numba.core import event

_records: list[tuple[str, float]] = []
_by_test: list[tuple[str, str, float, str]] = []  # (test, function, seconds, switches)
_current = {"test": "(collection)"}


def _switches(py_func) -> str:
    """The compile-time switches of a pair-loop variant (its closure's ``switches``), or ''."""
    names = py_func.__code__.co_freevars
    cells = py_func.__closure__ or ()
    values = dict(zip(names, (c.cell_contents for c in cells)))
    return " ".join(map(str, values.get("switches", ())))


class _Timer(event.Listener):
    def __init__(self):
        self.open: list[float] = []

    def on_start(self, ev):
        self.open.append(time.perf_counter())

    def on_end(self, ev):
        t0 = self.open.pop()
        if not self.open:
            d = ev.data["dispatcher"]
            name, seconds = d.py_func.__module__ + "." + d.py_func.__qualname__, time.perf_counter() - t0
            _records.append((name, seconds))
            _by_test.append((_current["test"], name, seconds, _switches(d.py_func)))


event.register("numba:compile", _Timer())


def totals() -> dict[str, list]:
    """{function: [compile seconds, compilations]} of every compilation recorded so far."""
    out: dict[str, list] = collections.defaultdict(lambda: [0.0, 0])
    for name, seconds in _records:
        out[name][0] += seconds
        out[name][1] += 1
    return dict(out)


def pytest_runtest_setup(item):
    _current["test"] = item.nodeid


def pytest_sessionfinish(session, exitstatus):
    totals_ = totals()
    with open(os.environ.get("COMPILE_EVENTS_OUT", "compile_events.txt"), "w") as f:
        f.write(f"compile seconds in all: {sum(v[0] for v in totals_.values()):.1f}\n")
        for name, (seconds, count) in sorted(totals_.items(), key=lambda kv: -kv[1][0]):
            f.write(f"{seconds:8.2f} s {count:4d}x {name}\n")
        per_test: dict[str, float] = collections.defaultdict(float)
        for test, _, seconds, _ in _by_test:
            per_test[test] += seconds
        f.write("\nby test (compile seconds):\n")
        for test, seconds in sorted(per_test.items(), key=lambda kv: -kv[1]):
            f.write(f"{seconds:8.2f} s {test}\n")
        f.write("\npair-loop variants (first compiled by):\n")
        for test, _, seconds, switches in _by_test:
            if switches:
                f.write(f"{seconds:8.2f} s {test}: {switches}\n")
