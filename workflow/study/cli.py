"""``python -m study COMMAND``: the small CLIs the Snakemake rules call."""
from __future__ import annotations

import argparse
import sys
from pathlib import Path


def _cfg(path):
    from .config import load
    return load(path)


def _flow(cfg):
    from .registry import flow_of
    return flow_of(cfg)


def cmd_validate(a):
    cfg = _cfg(a.config)
    cs = _flow(cfg).cases(cfg)
    print(f"{a.config}: valid, campaign {cfg['name']}, {len(cs)} cases")
    for c in cs:
        print("  " + c.id)


def cmd_case_file(a):
    import yaml
    cfg = _cfg(a.config)
    flow = _flow(cfg)
    try:
        case = flow.case_by_id(cfg, a.case)
    except KeyError:
        raise SystemExit(f"error: case {a.case!r} is not in {a.config}") from None
    _write_text(a.output, yaml.safe_dump(flow.case_dict(cfg, case), sort_keys=False))


def cmd_metrics(a):
    import xarray as xr
    from solver.output import write_atomic
    cfg = _cfg(a.config)
    flow = _flow(cfg)
    with xr.open_dataset(a.run) as run:
        run = run.load()
    write_atomic(flow.score(cfg, a.case or Path(a.run).parent.name, run), a.output)


def cmd_reduce(a):
    from solver.output import write_atomic
    cfg = _cfg(a.config)
    write_atomic(_flow(cfg).reduce(cfg, Path(a.results)), a.output)


def cmd_figures(a):
    import xarray as xr
    cfg = _cfg(a.config)
    with xr.open_dataset(a.campaign) as ds:
        ds = ds.load()
    for p in _flow(cfg).write_figures(cfg, ds, a.outdir):
        print(p)


def cmd_report(a):
    import xarray as xr
    from .page import write
    cfg = _cfg(a.config)
    with xr.open_dataset(a.campaign) as ds:
        ds = ds.load()
    write(_flow(cfg).render(cfg, ds, a.figures), a.output)
    print(a.output)


def cmd_check_report(a):
    """Headless Chromium: every image decoded, no request outside the file, a screenshot."""
    from .browser import check_report
    r = check_report(a.report, screenshot=a.screenshot, width=a.width, height=a.height)
    print(f"{a.report}: {len(r.images)} images, {len(r.broken)} not decoded, "
          f"{len(r.external)} external requests" + (f"; screenshot {a.screenshot}" if a.screenshot else ""))
    for alt in r.broken:
        print(f"  not decoded: {alt}")
    for url in r.external:
        print(f"  external request: {url}")
    if not r.ok:
        raise SystemExit(1)


def cmd_status(a):
    from .status import show
    print(show(a.folder, all_cases=a.all))


def _write_text(path, text):
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(path.suffix + ".tmp")
    tmp.write_text(text)
    tmp.replace(path)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m study", description=__doc__)
    sub = ap.add_subparsers(dest="cmd", required=True)
    p = sub.add_parser("validate", help="validate a campaign config and list its cases")
    p.add_argument("config")
    p.set_defaults(fn=cmd_validate)
    p = sub.add_parser("case-file", help="write the solver case file of one case")
    p.add_argument("config"); p.add_argument("case"); p.add_argument("-o", "--output", required=True)  # noqa: E702
    p.set_defaults(fn=cmd_case_file)
    p = sub.add_parser("metrics", help="metrics of one run against the reference")
    p.add_argument("config"); p.add_argument("run"); p.add_argument("-o", "--output", required=True)  # noqa: E702
    p.add_argument("--case", help="the run's case id (default: the name of the run's folder)")
    p.set_defaults(fn=cmd_metrics)
    p = sub.add_parser("reduce", help="campaign dataset from every case")
    p.add_argument("config"); p.add_argument("--results", required=True, help="the folder of the cases")  # noqa: E702
    p.add_argument("-o", "--output", required=True)
    p.set_defaults(fn=cmd_reduce)
    p = sub.add_parser("figures", help="the campaign's figures (its flow's) from the campaign dataset")
    p.add_argument("config"); p.add_argument("campaign"); p.add_argument("-o", "--outdir", required=True)  # noqa: E702
    p.set_defaults(fn=cmd_figures)
    p = sub.add_parser("report", help="self-contained HTML report")
    p.add_argument("config"); p.add_argument("campaign"); p.add_argument("--figures", required=True)  # noqa: E702
    p.add_argument("-o", "--output", required=True)
    p.set_defaults(fn=cmd_report)
    p = sub.add_parser("check-report", help="open the report in headless Chromium: images, requests, screenshot")
    p.add_argument("report"); p.add_argument("--screenshot")  # noqa: E702
    p.add_argument("--width", type=int, default=1280); p.add_argument("--height", type=int, default=900)  # noqa: E702
    p.set_defaults(fn=cmd_check_report)
    p = sub.add_parser("status", help="each running case's simulated time, drift ratios and time left")
    p.add_argument("--folder", default=None,
                   help="a folder of progress files (default: every campaign's, results/*/progress)")
    p.add_argument("--all", action="store_true", help="also the cases that have ended")
    p.set_defaults(fn=cmd_status)
    a = ap.parse_args(argv)
    from .schema import ConfigError
    try:
        a.fn(a)
    except ConfigError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    return 0
