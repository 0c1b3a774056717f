"""Command line: ``python -m solver run SCENE.yaml -o OUT.nc`` (a scene to its end time),
``python -m solver front CASE.yaml -o OUT.nc`` (the conveyor front to steady state), ``check``
and ``warm``."""
from __future__ import annotations

import argparse
import os
import sys


def _parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="python -m solver", description=__doc__)
    sub = ap.add_subparsers(dest="command", required=True)
    c = sub.add_parser("check", help="validate a scene or a conveyor case file and print its particle count")
    c.add_argument("scene", help="scene YAML file, or a conveyor case file (as for front)")
    r = sub.add_parser("run", help="run a scene to its end time and write a NetCDF result")
    r.add_argument("scene", help="scene YAML file (see docs/scene.md)")
    f = sub.add_parser("front", help="run the conveyor-belt flow-front case to steady state")
    f.add_argument("case", help="case YAML file (see docs/conveyor.md)")
    for p, what in ((r, "scene"), (f, "case")):
        p.add_argument("-o", "--output", required=True, help="NetCDF file to write")
        p.add_argument("--threads", type=int, default=None, help="numba threads (default: all cores)")
        p.add_argument("--quiet", action="store_true", help="no progress on stderr")
        p.add_argument("--checkpoint", default=None,
                       help="checkpoint file (default: OUTPUT.ckpt); resumed from when it matches")
        p.add_argument("--no-checkpoint", action="store_true", help="never write or read a checkpoint")
        p.add_argument("--progress", default=None, metavar="JSON",
                       help="write the run's progress there every few seconds (python -m study status reads it)")
        p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                       help=f"override a {what} key (dotted for nested keys, VALUE read as YAML), "
                            "e.g. --set dp=0.002")
        p.add_argument("--allow-diverged", action="store_true",
                       help="exit 0 when a diverged (or, for front, unsteady) run was written (campaigns record it)")
    w = sub.add_parser("warm", help="compile and cache every numba kernel (before parallel jobs)")
    w.add_argument("cases", nargs="*", default=[],
                   help="front case files or scenes (or files holding a list of them) whose kernels to compile "
                        "(a case at a coarse dp, a scene as it is); none: a generic set")
    w.add_argument("--touch", default=None, help="file to create when done")
    return ap


def main(argv=None) -> int:
    args = _parser().parse_args(argv)
    if args.command == "front":
        return _front(args)
    if args.command == "warm":
        return _warm(args)
    from .overrides import apply_overrides
    from .scene import SceneError, read_yaml, scene_from_dict
    try:
        scene = scene_from_dict(apply_overrides(read_yaml(args.scene), getattr(args, "set", [])))
    except (SceneError, OSError, ValueError) as exc:
        case, case_error = _conveyor_case(args.scene)
        if case is None:
            print(f"error: {case_error or exc}", file=sys.stderr)
            return 2
        if args.command == "run":
            print(f"error: {args.scene} is a conveyor case file, not a scene: run it with "
                  f"python -m solver front {args.scene} -o OUT.nc", file=sys.stderr)
            return 2
        from .conveyor import build_scene
        scene = build_scene(case)
        print(f"{case.name}: conveyor case (python -m solver front), h_n = {case.h_n * 1e3:.4g} mm, "
              f"h_n / dp = {case.h_n / case.dp:.3g}, about {scene.estimated_particles()} particles, "
              f"h = {scene.h:g} m, c0 = {scene.c0:g} m/s")
        return 0
    if args.command == "check":
        print(f"{scene.name}: about {scene.estimated_particles()} particles, h = {scene.h:g} m, "
              f"c0 = {scene.c0:g} m/s")
        return 0
    if not _set_threads(args.threads):
        return 2
    from .output import to_dataset, write_atomic
    from .run import run_scene
    ckpt = None if args.no_checkpoint else (args.checkpoint or args.output + ".ckpt")
    res = run_scene(scene, quiet=args.quiet, checkpoint=ckpt, progress=args.progress)
    write_atomic(to_dataset(res), args.output)
    if ckpt is not None and os.path.exists(ckpt):  # only once the result is on disk
        os.remove(ckpt)
    msg = f"{scene.name}: {res.status} after {res.steps} steps, {res.wall_time:.1f} s"
    if res.reason:
        msg += f" ({res.reason})"
    print(msg, file=sys.stderr)
    return 0 if res.status == "completed" or args.allow_diverged else 3


def _conveyor_case(path):
    """(the conveyor case the file holds, None) or (None, its error as a case file when it has
    keys only a case file has, else None: then it is a scene and the scene's error stands)."""
    import dataclasses

    from .conveyor import ConveyorCase, case_from_dict
    from .scene import Scene, SceneError, read_yaml
    try:
        data = read_yaml(path) or {}
    except (SceneError, OSError, ValueError):
        return None, None
    try:
        return case_from_dict(data), None
    except (SceneError, ValueError, TypeError) as exc:
        case_only = ({f.name for f in dataclasses.fields(ConveyorCase)}
                     - {f.name for f in dataclasses.fields(Scene)})
        is_case = isinstance(data, dict) and bool(case_only & set(data))
        return None, (f"{exc} (read as a conveyor case file)" if is_case else None)


def _set_threads(threads) -> bool:
    import numba
    if threads is None:
        return True
    if not 1 <= threads <= numba.config.NUMBA_NUM_THREADS:
        print(f"error: --threads must lie in [1, {numba.config.NUMBA_NUM_THREADS}]", file=sys.stderr)
        return False
    numba.set_num_threads(threads)
    return True


def _front(args) -> int:
    from .conveyor import case_from_dict
    from .overrides import apply_overrides
    from .scene import SceneError, read_yaml
    try:
        case = case_from_dict(apply_overrides(read_yaml(args.case) or {}, args.set))
    except (SceneError, OSError, ValueError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    if args.set and not args.quiet:
        print(f"case: {case.name}", file=sys.stderr)
    if not _set_threads(args.threads):
        return 2
    from .front import run_front
    from .output import write_atomic
    ckpt = None if args.no_checkpoint else (args.checkpoint or args.output + ".ckpt")
    ds = run_front(case, quiet=args.quiet, checkpoint=ckpt, progress=args.progress)
    write_atomic(ds, args.output)
    if ckpt is not None and os.path.exists(ckpt):  # only once the result is on disk
        os.remove(ckpt)
    msg = (f"{case.name}: {ds.attrs['status']} at t = {ds.attrs['simulated_time_s']:.3f} s, "
           f"{ds.attrs['steps']} steps, {ds.attrs['wall_time_s']:.1f} s wall")
    if ds.attrs["reason"]:
        msg += f" ({ds.attrs['reason']})"
    print(msg, file=sys.stderr)
    return 0 if ds.attrs["status"] == "completed" or args.allow_diverged else 3


def _warm(args) -> int:
    """Compile the kernels of the given case and scene files (a file may hold a list of them),
    or without files a generic set (``solver.precompile``)."""
    from .precompile import compile_kernels
    from .scene import read_yaml
    entries = []
    for path in args.cases:
        data = read_yaml(path)
        entries += data if isinstance(data, list) else [data]
    seconds = compile_kernels(entries)
    print(f"numba kernels compiled and cached in {seconds:.1f} s", file=sys.stderr)
    if args.touch:
        from pathlib import Path
        Path(args.touch).parent.mkdir(parents=True, exist_ok=True)
        Path(args.touch).touch()
    return 0
