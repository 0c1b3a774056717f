"""``python -m study COMMAND``: the small CLIs the Snakemake rules call."""
from __future__ import annotations

import argparse
import sys
from pathlib import Path


def _cfg(path):
    from .config import load
    return load(path)


def _flow(cfg) -> bool:
    """Whether the campaign is a flow other than the conveyor (study.flowconfig)."""
    return cfg.get("flow", "conveyor") != "conveyor"


def cmd_validate(a):
    from .config import cases
    cfg = _cfg(a.config)
    if _flow(cfg):
        from .flowconfig import cases
    cs = cases(cfg)
    print(f"{a.config}: valid, {len(cs)} cases")
    for c in cs:
        print("  " + c.id)


def cmd_case_file(a):
    import yaml
    from .config import case_dict, cases
    cfg = _cfg(a.config)
    if _flow(cfg):
        from .flowconfig import cases, scene_dict as case_dict
    match = [c for c in cases(cfg) if c.id == a.case]
    if not match:
        raise SystemExit(f"error: case {a.case!r} is not in {a.config}")
    _write_text(a.output, yaml.safe_dump(case_dict(cfg, match[0]), sort_keys=False))


def _reference(cfg, case):
    """The reference of one run: the theory of ``case`` (the physical case the run recorded) and
    the campaign's measured profiles, if any."""
    import numpy as np
    from .reference import read_surface_csv, read_velocity_csv, theory_for_case
    lo, hi = cfg["metrics"]["free_surface_x_star"]
    x = np.round(np.arange(lo, hi + 1e-9, 0.1), 10)
    z = np.round(np.arange(0.0, 1.3 + 1e-9, 0.025), 10)
    ref = theory_for_case(case, x, cfg["metrics"]["stations"], z)
    m = cfg["reference"]["measured"]
    measured = {"surface": read_surface_csv(m["free_surface"]) if m.get("free_surface") else None,
                "velocity": {float(k): read_velocity_csv(v) for k, v in (m.get("velocity") or {}).items()}}
    return ref, measured


def cmd_metrics(a):
    import xarray as xr
    from solver.output import write_atomic
    from .metrics import case_metrics
    from .config import solver_case
    from .reference import recorded_case
    cfg = _cfg(a.config)
    with xr.open_dataset(a.run) as run:
        run = run.load()
    if _flow(cfg):
        from .flowcampaign import case_by_id, score
        m = score(cfg, case_by_id(cfg, Path(a.run).parent.name), run)
        write_atomic(m, a.output)
        return
    case = recorded_case(run) or solver_case(cfg)  # each run against its own physics
    ref, measured = _reference(cfg, case)
    m = case_metrics(run, ref, tuple(cfg["metrics"]["free_surface_x_star"]), measured)
    m.attrs["case"] = Path(a.run).parent.name
    write_atomic(m, a.output)


def cmd_reduce(a):
    import xarray as xr
    from solver.output import write_atomic
    from .campaign import build
    from .config import cases, solver_case
    cfg = _cfg(a.config)
    if _flow(cfg):
        import yaml
        from .flowcampaign import reduce
        ds = reduce(cfg, Path(a.results))
        ds.attrs["config_yaml"] = yaml.safe_dump(cfg, sort_keys=False)
        write_atomic(ds, a.output)
        return
    cs = cases(cfg)
    runs, metrics = [], []
    for c in cs:
        with xr.open_dataset(Path(a.results) / c.id / "run.nc") as r:
            runs.append(r.load())
        with xr.open_dataset(Path(a.results) / c.id / "metrics.nc") as m:
            metrics.append(m.load())
    ds = build(cs, runs, metrics)
    import yaml
    from .reference import physics_of, recorded_case, start_description
    recorded = [recorded_case(r) or solver_case(cfg, c) for r, c in zip(runs, cs)]
    physics = [physics_of(case) for case in recorded]
    ds.attrs["schemes"] = ", ".join(sorted({case.scheme for case in recorded}))
    from .config import START_CHECK_TAG
    ds.attrs["starts"] = "; ".join(sorted({start_description(case) for case, c in zip(recorded, cs)
                                           if c.tag != START_CHECK_TAG}))
    mixed = [c.id for c, p in zip(cs, physics) if p != physics[0]]
    if mixed:  # each run was scored against its own theory; one h_n or slope would misstate them
        ds.attrs["physics_differ"] = (f"{', '.join(mixed)} differ in physics from {cs[0].id}: each run's "
                                      "metrics are against its own theory, but the figures' theory "
                                      "curves and the campaign's h_n and slope are the first case's")
    ds.attrs.update(h_n_m=float(runs[0].attrs.get("h_n_m", float("nan"))),
                    normalising_depth_m=float(cfg["reference"]["normalising_depth"]),
                    slope_deg=float(solver_case(cfg).slope_deg),
                    config_yaml=yaml.safe_dump(cfg, sort_keys=False),
                    realisations=int(ds["realisations"].max()),
                    start_perturbation=float(cfg["ensemble"]["perturbation"]),
                    window_stagger=float(cfg["ensemble"]["window_stagger"]),
                    version_numba=str(runs[0].attrs.get("version_numba", "")))
    write_atomic(ds, a.output)


def _figure_settings(cfg, ds):
    import numpy as np
    from .figures import Settings
    from .config import solver_case
    from .reference import theory_for_case
    profiles = theory_for_case(solver_case(cfg), np.array([0.0]), ds["station"].values, ds["z_star"].values)
    return Settings(profile_ch=float(cfg["figures"]["profile_ch"]), theory=profiles)


def cmd_figures(a):
    import xarray as xr
    from .figures import figures_for, write_all
    cfg = _cfg(a.config)
    f = cfg["figures"]
    with xr.open_dataset(a.campaign) as ds:
        ds = ds.load()
    if _flow(cfg):
        from .flowreport import write_figures
        for p in write_figures(cfg, ds, a.outdir, fmt=f["format"], dpi=f["dpi"]):
            print(p)
        return
    for p in write_all(ds, a.outdir, _figure_settings(cfg, ds), fmt=f["format"], dpi=f["dpi"],
                       specs=figures_for(cfg)):
        print(p)


def cmd_report(a):
    import xarray as xr
    import yaml
    from .figures import figures_for
    from .report import render, write
    cfg = _cfg(a.config)
    f = cfg["figures"]
    with xr.open_dataset(a.campaign) as ds:
        ds = ds.load()
    if _flow(cfg):
        from .flowreport import render as render_flow
        write(render_flow(cfg, ds, a.figures, yaml.safe_dump(cfg, sort_keys=False)), a.output)
        print(a.output)
        return
    settings = _figure_settings(cfg, ds)
    figs = []
    for spec in figures_for(cfg):
        p = Path(a.figures) / f"{spec.name}.{f['format']}"
        if not p.exists():
            raise SystemExit(f"error: missing figure {p}; run the figures step first")
        figs.append((p, spec.title, spec.full_caption(settings.profile_ch)))
    write(render(ds, figs, yaml.safe_dump(cfg, sort_keys=False)), a.output)
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
    p.set_defaults(fn=cmd_metrics)
    p = sub.add_parser("reduce", help="campaign dataset from every case")
    p.add_argument("config"); p.add_argument("--results", default="results/cases")  # noqa: E702
    p.add_argument("-o", "--output", required=True)
    p.set_defaults(fn=cmd_reduce)
    p = sub.add_parser("figures", help="the paper's figures from the campaign dataset")
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
    p.add_argument("--folder", default="results/progress", help="the progress files (default: results/progress)")
    p.add_argument("--all", action="store_true", help="also the cases that have ended")
    p.set_defaults(fn=cmd_status)
    a = ap.parse_args(argv)
    from .config import ConfigError
    try:
        a.fn(a)
    except ConfigError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    return 0
