"""Smoke tests of the maintained benchmarks (benchmarks/): each runs as its own process from the
repository root, in its smallest mode and on one numba thread, and must exit 0 and print its
Markdown table and its ``summary:`` line. Tests import nothing from benchmarks/."""
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
TABLE = re.compile(r"^\|.*\|\n\|(---\|)+$", re.M)


def run(*args: str, timeout: float = 600) -> str:
    cmd = ["bash", *args] if args[0].endswith(".sh") else [sys.executable, "-m", *args]
    res = subprocess.run(cmd, cwd=ROOT, capture_output=True, text=True, timeout=timeout,
                         env=dict(os.environ, NUMBA_NUM_THREADS="1"))  # a busy host slows 2 threads most
    assert res.returncode == 0, res.stderr[-4000:]
    return res.stdout


def assert_table(out: str, *headers: str) -> None:
    assert TABLE.search(out), out
    for h in headers:
        assert h in out, (h, out)
    assert re.search(r"^summary: \S", out, re.M), out


def test_common_describes_the_host():
    out = run("benchmarks.common")
    assert "cores" in out and "commit" in out


def test_slurm_local_lists_what_it_needs():
    assert_table(run("benchmarks/slurm_local.sh", "--check"), "| needs | found |", "| sinfo |")


def test_report_writes_one_table(tmp_path):
    out = tmp_path / "RESULTS.md"
    run("benchmarks.report", "--quick", "--only", "slurm_local.sh", "throughput", "--output", str(out),
        "--out", str(tmp_path))
    text = out.read_text()
    assert text.startswith("# Benchmark results")
    assert "| benchmark | command | date | host | wall [s] | figures |" in text
    assert "| throughput | `python -m benchmarks.throughput --quick` |" in text
    assert "FAILED" not in text


def test_throughput():
    assert_table(run("benchmarks.throughput", "--quick", "--particles", "2000", "--steps", "5"),
                 "M particle-steps/s", "| layer 2k | 1.5 | none | 1 |")


def test_kernel_times():
    assert_table(run("benchmarks.kernel_times", "--quick", "--particles", "2000", "--steps", "5"),
                 "| kernel | ms a step | share |", "| pair_loop |")


def test_viscous_limit():
    assert_table(run("benchmarks.viscous_limit", "--quick", "--dp", "0.002", "--end", "0.005"),
                 "u RMS error", "| 0.2 |")


def test_viscous_forms_step_cost():
    assert_table(run("benchmarks.viscous_limit", "--forms", "--quick", "--exact", "--steps", "5", "--threads", "1"),
                 "| form | ms per step (median) | per round |", "| stress |")


def test_acoustic_edge_predicts():
    assert_table(run("benchmarks.acoustic_edge", "--predict", "--only", "dp2.25-ch1.8-c0.60"),
                 "C / C*", "| dp2.25-ch1.8-c0.60 | 2.25 | 1.8 |")


@pytest.mark.slow
def test_acoustic_edge_runs(tmp_path):
    out = run("benchmarks.acoustic_edge", "--quick", "--only", "dp2.25-ch1.8-c0.60", "--to", "0.05",
              "--out", str(tmp_path))
    assert_table(out, "held to 0.05 s")


@pytest.mark.slow
def test_paired():
    out = run("benchmarks.paired", "--old", ".", "--new", ".", "--quick", "--particles", "2000", "--steps", "5",
              "--shifting", "none")
    assert_table(out, "new / old", "| layer 2k | 1.5 | none | 1 | 2 |")


@pytest.mark.slow
def test_time_to_solution(tmp_path):
    out = run("benchmarks.time_to_solution", "--quick", "--out", str(tmp_path),
              "--variant", "same", "coefsound=10.0", "--variant", "c9", "coefsound=9.0")
    assert_table(out, "| skillen | case | not_steady |", "zeta_u_9.7", "largest shift / se")
    # a variant that repeats the case's run has not moved; another sound speed has, by a finite amount
    assert re.search(r"^\| skillen \| same \| .*\| 0\.0 \(zeta_\w+(\.\d+)?\) \| - \|$", out, re.M), out
    assert re.search(r"^\| skillen \| c9 \| .*\| \d+\.\d \(zeta_\w+(\.\d+)?\) \| - \|$", out, re.M), out


@pytest.mark.slow
def test_window_metrics(tmp_path):
    out = run("benchmarks.window_metrics", "--quick", "--set", "steady.max_time=1.6", "--out", str(tmp_path))
    assert_table(out, "| 1.0-1.5 |", "targets from 1.00 s")
    out = run("benchmarks.window_metrics", str(tmp_path / "quick.nc"), "--length", "0.4", "--stride", "0.6",
              "--from", "0.5")
    assert_table(out, "| 0.5-0.9 |", "| 1.1-1.5 |", "steady detection replayed")


@pytest.mark.slow
def test_paper_grid(tmp_path):
    out = run("benchmarks.paper_grid", "--quick", "--config", "tests/data/mini.yaml", "--time", "0.005",
              "--out", str(tmp_path))
    assert_table(out, "| 4 | 1.5 | skillen |", "| total |")
