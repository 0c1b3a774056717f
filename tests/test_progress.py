"""A front run's progress file (solver/progress.py) and the status table that reads it
(python -m study status)."""
import json
import time
from types import SimpleNamespace

from solver.progress import ProgressFile, chain
from solver.steady import Judgement, SteadyCriteria, SteadyDetector
from study.status import show


def _runner(t, elapsed):
    return SimpleNamespace(sim=SimpleNamespace(t=t), elapsed=lambda: elapsed)


def test_progress_file_and_status_table(tmp_path):
    """The file holds the simulated time, the latest pair's drift ratios and the wall time left
    between the first moment a pair may end and max_time; the table shows the worst ratio."""
    det = SteadyDetector(SteadyCriteria(window=3.0, min_time=0.3))
    det.t_first = 0.0
    det.last = Judgement(7.5, 3.0, {"toe": (0.4, 0.2), "depth": (1.7, 0.3), "surface": (float("nan"), 0.1)})
    monitor = SimpleNamespace(detector=det)
    path = tmp_path / "progress" / "dp1mm_ch1.8_skillen.json"
    p = ProgressFile(path, "dp1mm_ch1.8_skillen", monitor, max_time=20.0, every=0.0)
    p(_runner(7.0, 100.0))
    p.t_sim0, p.wall0 = 5.0, time.perf_counter() - 20.0  # 2 s simulated in 20 s of wall: 0.1 s/s
    p.write(_runner(7.0, 100.0), "running")
    rec = json.loads(path.read_text())
    assert rec["t"] == 7.0 and rec["max_time"] == 20.0 and not rec["steady"]
    assert rec["drift_ratios"] == {"toe": 0.4, "depth": 1.7, "surface": None}
    assert abs(rec["t_end_earliest"] - 7.0) < 1e-9  # min_time + 2W = 6.3 s has passed
    assert abs(rec["wall_left_max_s"] - 130.0) < 2.0  # 13 s simulated at 0.1 s/s
    table = show(path.parent)
    assert "1 running" in table and "1.70 (depth)" in table and "1 not measurable" in table
    p.write(_runner(7.0, 100.0), "completed")
    assert "0 running, 1 ended" in show(path.parent)
    assert "completed" in show(path.parent, all_cases=True)


def test_chain_calls_every_hook():
    calls = []
    hook = chain(None, lambda r: calls.append(1), lambda r: calls.append(2))
    hook(None)
    assert calls == [1, 2] and chain(None, None) is None
