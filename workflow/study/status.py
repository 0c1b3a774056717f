"""``python -m study status``: each running case's simulated time, drift ratios and when it can
end, from the progress files the runs write (solver/progress.py) under results/<campaign>/progress/."""
from __future__ import annotations

import json
import time
from pathlib import Path


def _minutes(s) -> str:
    return "?" if s is None else f"{s / 60:.1f}"


def line(p: dict, now: float) -> str:
    """One case: status, t / max_time, the worst drift ratio and which quantity, the wall time
    left (from the first moment a window pair may end to max_time) at the run's rate."""
    ratios = {q: r for q, r in p.get("drift_ratios", {}).items()}
    finite = {q: r for q, r in ratios.items() if r is not None}
    worst = max(finite, key=finite.get) if finite else None
    drift = (f"{finite[worst]:5.2f} ({worst})" if worst else "not judged yet")
    if not p.get("detector", True):  # a scene run: it ends at its end time
        drift = "- (runs to its end)"
    if len(finite) < len(ratios):
        drift += f", {len(ratios) - len(finite)} not measurable"
    status = "steady" if p.get("steady") and p["status"] == "running" else p["status"]
    if p["status"] == "running":
        left = f"ends in {_minutes(p.get('wall_left_min_s'))}-{_minutes(p.get('wall_left_max_s'))} min"
        age = now - p.get("written", now)
        if age > 120:
            left += f" (no update for {age / 60:.0f} min)"
    else:
        left = ""
    name = f"{p['campaign']}/{p['case']}" if p.get("campaign") else p["case"]
    return (f"{name:<44} {status:<10} t = {p['t']:6.2f}/{p['max_time']:g} s  "
            f"worst drift/allowance {drift:<28} {left}")


def show(folder=None, all_cases: bool = False, results="results") -> str:
    """The table of the progress files in ``folder`` (default: every campaign's under
    ``results``), running cases first (``all_cases``: also the ended ones)."""
    rows = []
    files = Path(folder).glob("*.json") if folder else Path(results).glob("*/progress/*.json")
    for f in sorted(files):
        try:
            row = json.loads(f.read_text())
        except (OSError, ValueError):
            continue
        rows.append(row | ({} if folder else {"campaign": f.parent.parent.name}))
    now = time.time()
    running = [r for r in rows if r.get("status") == "running"]
    ended = [r for r in rows if r.get("status") != "running"]
    out = [line(r, now) for r in running]
    if all_cases:
        out += [line(r, now) for r in ended]
    head = f"{len(running)} running, {len(ended)} ended (drift/allowance <= 1 on every quantity: steady)"
    return "\n".join([head] + out)
