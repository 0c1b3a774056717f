"""Particle-steps per second of the solver: the 40k layer (examples/film.yaml, 100 dp deep,
periodic, on a 2h bed; ``benchmarks.common.layer``) or any case or scene (--case).

particle-steps/s = (fluid and boundary particles) x steps / wall seconds of the steps, after
5 warm-up steps; bytes/particle = the simulation's numpy arrays over its particle count.
--jitter DP first moves the layer's fluid particles by up to DP dp: the layer from rest is a
lattice, whose exact rows make the pair loop's branches predictable, which no flow's are.

    python -m benchmarks.throughput [--ch 1.5 1.8] [--shifting none lind skillen] [--threads 1 2]
        [--particles 40000] [--steps 200] [--rounds 1] [--jitter DP] [--set KEY=VALUE] [--json]
    python -m benchmarks.throughput --case examples/conveyor_fast.yaml --set dp=0.002
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from benchmarks import common

QUICK = {"ch": [1.5], "threads": [2], "steps": 100}


def array_bytes(sim) -> int:
    """Bytes held in the simulation's numpy arrays (sort buffers included)."""
    seen, total = set(), 0
    arrays = [v for v in vars(sim).values() if isinstance(v, np.ndarray)]
    arrays += list(getattr(sim, "_buf", {}).values())
    for a in arrays:
        if id(a) not in seen:
            seen.add(id(a))
            total += a.nbytes
    return total


def jitter(sim, amplitude: float, seed: int = 1) -> None:
    """Move every fluid particle by uniform offsets of up to ``amplitude`` dp in x and z; the
    next step sorts them again."""
    rng = np.random.default_rng(seed)
    fluid = sim.kind == 0
    for arr in (sim.x, sim.z):
        arr[fluid] += rng.uniform(-1.0, 1.0, int(fluid.sum())) * amplitude * sim.scene.dp


def measure(data: dict, threads: int, steps: int, jitter_dp: float = 0.0) -> dict:
    """Time ``steps`` steps of the case or scene ``data`` on ``threads`` threads."""
    threads = common.set_threads(threads)
    sim = common.simulation(data)
    if jitter_dp > 0:
        jitter(sim, jitter_dp)
    for _ in range(5):  # warm-up (compilation is cached after the first configuration)
        sim.step()
    with common.Timer() as t:
        for _ in range(steps):
            reason = sim.step()
            if reason:
                raise RuntimeError(reason)
    return {"particles": sim.n, "threads": threads, "steps": steps, "wall_s": round(t.seconds, 4),
            "particle_steps_per_s": round(sim.n * steps / t.seconds),
            "ns_per_particle_step": round(1e9 * t.seconds / (sim.n * steps), 1),
            "bytes_per_particle": round(array_bytes(sim) / sim.n)}


def configurations(a) -> list[tuple[dict, dict]]:
    """(labels, case or scene dict) of every configuration the options ask for."""
    if a.case is not None:
        return [({"case": a.case.name, "shifting": s},
                 common.set_shifting(common.read_case(a.case, a.sets), None if s == "case" else s))
                for s in a.shifting]
    return [({"case": f"layer {p // 1000}k", "ch": ch, "shifting": s}, common.layer(p, ch, s, a.sets))
            for p in a.particles for ch in a.ch for s in a.shifting]


def main(argv=None) -> int:
    ap = common.parser(__doc__, sets=True, threads=[1, 2], rounds=1)
    ap.add_argument("--case", type=Path, default=None, help="a case or scene YAML instead of the layer")
    ap.add_argument("--ch", type=float, nargs="+", default=[1.5, 1.8], help="the layer's Ch")
    ap.add_argument("--shifting", nargs="+", default=None,
                    help="shifting methods (default: none lind skillen; with --case: the case's own)")
    ap.add_argument("--particles", type=int, nargs="+", default=[40000], help="the layer's particles")
    ap.add_argument("--steps", type=int, default=200)
    ap.add_argument("--jitter", type=float, default=0.0, metavar="DP", help="move the fluid by up to DP dp first")
    ap.add_argument("--json", action="store_true", help="one JSON object a measurement instead of the table")
    a = common.parse(ap, argv, QUICK)
    if not a.shifting:
        a.shifting = ["case"] if a.case is not None else ["none", "skillen"] if a.quick else ["none", "lind", "skillen"]
    rows = []
    for r in range(a.rounds):
        for labels, data in configurations(a):
            for threads in a.threads:
                row = {"round": r, **labels, "jitter_dp": a.jitter, **measure(data, threads, a.steps, a.jitter)}
                rows.append(row)
                if a.json:
                    print(json.dumps(row), flush=True)
    if a.json:
        return 0
    print(common.table(
        ["round", "case", "Ch", "shifting", "threads", "particles", "steps", "wall [s]", "M particle-steps/s",
         "ns / particle-step", "bytes / particle"],
        [[r["round"], r["case"], r.get("ch", "-"), r["shifting"], r["threads"], r["particles"], r["steps"],
          f"{r['wall_s']:.2f}", f"{r['particle_steps_per_s'] / 1e6:.3f}", r["ns_per_particle_step"],
          r["bytes_per_particle"]] for r in rows]))
    best = max(rows, key=lambda r: r["particle_steps_per_s"])
    common.summary(f"{best['case']}, Ch {best.get('ch', '-')}, {best['shifting']}, {best['threads']} threads: "
                   f"{best['particle_steps_per_s'] / 1e6:.2f} M particle-steps/s (the fastest of {len(rows)})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
