"""Throughput of two source trees, alternately, in one run: the host is noisy, so a performance
claim compares the old and the new code this way and never against a figure measured earlier.

Each round runs this tree's ``benchmarks.throughput`` once with the old tree's ``solver`` and
once with the new one's (the layer read from each tree's examples/film.yaml); the order
alternates from round to round (the tree run second can read lower even for identical code),
so use an even --rounds. OLD and
NEW are folders or git revisions of this repository (exported with ``git archive`` to
results/benchmarks/trees/); the other options go to ``benchmarks.throughput``.

    python -m benchmarks.paired [--old HEAD] [--new .] [--rounds 2] [throughput options: --ch 1.5 --threads 2 ...]
"""
from __future__ import annotations

import io
import json
import os
import statistics
import subprocess
import sys
import tarfile
import tempfile
from pathlib import Path

from benchmarks import common


def tree(spec: str) -> Path:
    """The folder ``spec``, or the git revision ``spec`` exported to results/benchmarks/trees/
    (kept: numba's cache is keyed on the source path, so a second run does not compile again)."""
    if Path(spec).is_dir():
        return Path(spec).resolve()
    sha = subprocess.run(["git", "rev-parse", "--verify", f"{spec}^{{commit}}"], cwd=common.ROOT, capture_output=True,
                         text=True, check=True).stdout.strip()
    dest = common.RESULTS / "trees" / sha
    if not dest.is_dir():
        data = subprocess.run(["git", "archive", sha], cwd=common.ROOT, capture_output=True, check=True).stdout
        with tarfile.open(fileobj=io.BytesIO(data)) as tar:
            tar.extractall(dest.with_suffix(".part"), filter="tar")  # this repository's own tree
        dest.with_suffix(".part").rename(dest)
    return dest


def launcher(tmp: Path) -> Path:
    """A folder holding only a link to this benchmarks package: run from it with a tree on
    PYTHONPATH, ``benchmarks`` is this one and ``solver`` the tree's."""
    path = tmp / "launch"
    path.mkdir()
    (path / "benchmarks").symlink_to(Path(__file__).resolve().parent)
    return path


def run_tree(launch: Path, source: Path, args: list[str]) -> list[dict]:
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(launch), str(source)]))
    out = subprocess.run([sys.executable, "-m", "benchmarks.throughput", "--json", *args], env=env, cwd=launch,
                         check=True, capture_output=True, text=True).stdout
    return [json.loads(line) for line in out.splitlines() if line.startswith("{")]


def main(argv=None) -> int:
    ap = common.parser(__doc__, threads=None, rounds=2)
    ap.add_argument("--old", default="HEAD", help="folder or git revision (default: HEAD)")
    ap.add_argument("--new", default=".", help="folder or git revision (default: the working tree)")
    a, rest = ap.parse_known_args(argv)
    if a.quick:
        rest = ["--quick", *rest]
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        launch = launcher(tmp)
        pair = [("old", tree(a.old)), ("new", tree(a.new))]
        for _, source in pair:  # compile both before timing
            run_tree(launch, source, rest + ["--steps", "1"])
        for r in range(a.rounds):
            for order, (label, source) in enumerate(pair if r % 2 == 0 else pair[::-1]):
                for row in run_tree(launch, source, rest):
                    rows.append({**row, "round": r, "tree": label, "order": order})
                    print(json.dumps(rows[-1]), file=sys.stderr, flush=True)
    keys = sorted({(r["case"], r.get("ch", "-"), r["shifting"], r["threads"]) for r in rows}, key=str)
    out, ratios = [], []
    for key in keys:
        rate = {t: [r["particle_steps_per_s"] for r in rows
                    if (r["case"], r.get("ch", "-"), r["shifting"], r["threads"]) == key and r["tree"] == t]
                for t in ("old", "new")}
        old, new = statistics.mean(rate["old"]), statistics.mean(rate["new"])
        ratios.append(new / old)
        out.append([*key, len(rate["old"]), f"{old / 1e6:.3f}", f"{new / 1e6:.3f}", f"{new / old:.3f}"])
    print(f"old: {a.old}, new: {a.new}, {a.rounds} rounds alternated")
    print(common.table(["case", "Ch", "shifting", "threads", "rounds", "old M particle-steps/s",
                        "new M particle-steps/s", "new / old"], out))
    common.summary(f"new ({a.new}) / old ({a.old}) particle-steps/s: "
                   + ", ".join(f"{x:.3f}" for x in ratios) + f" ({a.rounds} rounds alternated)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
