"""Command line: ``python -m solver run SCENE.yaml -o OUT.nc [--threads N] [--quiet]``."""
from __future__ import annotations

import argparse
import sys


def _parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="python -m solver", description=__doc__)
    sub = ap.add_subparsers(dest="command", required=True)
    r = sub.add_parser("run", help="run a scene and write a NetCDF result")
    r.add_argument("scene", help="scene YAML file")
    r.add_argument("-o", "--output", required=True, help="NetCDF file to write")
    r.add_argument("--threads", type=int, default=None, help="numba threads (default: all cores)")
    r.add_argument("--quiet", action="store_true", help="no progress on stderr")
    c = sub.add_parser("check", help="validate a scene and print its particle count")
    c.add_argument("scene")
    return ap


def main(argv=None) -> int:
    args = _parser().parse_args(argv)
    from .scene import SceneError, load_scene
    try:
        scene = load_scene(args.scene)
    except (SceneError, OSError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    if args.command == "check":
        print(f"{scene.name}: about {scene.estimated_particles()} particles, h = {scene.h:g} m, "
              f"c0 = {scene.c0:g} m/s")
        return 0
    import numba
    if args.threads is not None:
        if not 1 <= args.threads <= numba.config.NUMBA_NUM_THREADS:
            print(f"error: --threads must lie in [1, {numba.config.NUMBA_NUM_THREADS}]", file=sys.stderr)
            return 2
        numba.set_num_threads(args.threads)
    from .output import to_dataset, write_atomic
    from .run import run_scene
    res = run_scene(scene, quiet=args.quiet)
    write_atomic(to_dataset(res), args.output)
    msg = f"{scene.name}: {res.status} after {res.steps} steps, {res.wall_time:.1f} s"
    if res.reason:
        msg += f" ({res.reason})"
    print(msg, file=sys.stderr)
    return 0 if res.status == "completed" else 3
