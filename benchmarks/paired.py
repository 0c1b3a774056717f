"""Compare solver throughput of two source trees, alternately, in one run (the machine is noisy).

Each round runs ``benchmarks/throughput.py`` of the current tree with PYTHONPATH set to the
old tree and to the new one (the benchmark script is the same for both, so the scene is the
same), and prints one JSON line per measurement with "round", "tree" and "order" (0: run
first in its round) keys. The order alternates from round to round: on this host the tree
run second read 8-16 % lower even for identical code, so compare the trees over an even
number of rounds, or within the same order.

Usage: python benchmarks/paired.py OLD_TREE [NEW_TREE=.] [--rounds 2] [throughput.py args...]
Example: git worktree add /tmp/base <commit>; python benchmarks/paired.py /tmp/base --ch 1.5 --threads 2
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))


def run_tree(tree: str, args: list[str]) -> list[dict]:
    env = dict(os.environ, PYTHONPATH=os.path.abspath(tree))
    out = subprocess.run([sys.executable, os.path.join(HERE, "throughput.py"), *args], env=env,
                         check=True, capture_output=True, text=True, cwd=os.path.abspath(tree)).stdout
    return [json.loads(line) for line in out.splitlines() if line.startswith("{")]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("old")
    ap.add_argument("new", nargs="?", default=".")
    ap.add_argument("--rounds", type=int, default=2)
    a, rest = ap.parse_known_args(argv)
    for tree in (a.old, a.new):  # compile both before timing
        run_tree(tree, rest + ["--steps", "1"])
    pair = [("old", a.old), ("new", a.new)]
    for r in range(a.rounds):
        for order, (label, tree) in enumerate(pair if r % 2 == 0 else pair[::-1]):
            for row in run_tree(tree, rest):
                print(json.dumps({"round": r, "tree": label, "order": order, **row}), flush=True)


if __name__ == "__main__":
    main()
