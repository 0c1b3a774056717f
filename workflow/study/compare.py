"""Two conveyor campaign datasets (``results/<name>/campaign.nc``), case by case: each metric's change in units of
their combined standard error, z = (new - old) / sqrt(se_new^2 + se_old^2), with status, steps and
steady time. Pure functions over xarray.

A solver change that should leave the physics alone (round-off, speed) should leave its
campaign's metrics within their run-to-run spread: |z| mostly within 2 (if the se describe that
spread, noise alone puts about 1 value in 20 beyond it), and no case far beyond.

    python -m study.compare NEW/results/config/campaign.nc OLD/results/config/campaign.nc
"""
from __future__ import annotations

import argparse

import numpy as np
import xarray as xr

METRICS = ("zeta_f", "zeta_h", "zeta_fs", "zeta_u")


def changes(new: xr.Dataset, old: xr.Dataset) -> dict:
    """case -> {z: {metric: z values (one per station for zeta_u)}, status, steps, steady_at:
    (new, old) pairs} for the cases both datasets hold (their ``case`` dimension)."""
    old_cases = [str(c) for c in old.case.values]
    out = {}
    for cid in (str(c) for c in new.case.values):
        if cid not in old_cases:
            continue
        a, b = new.sel(case=cid), old.sel(case=cid)
        z = {}
        for m in METRICS:
            x, y = np.ravel(a[f"case_{m}"].values), np.ravel(b[f"case_{m}"].values)
            sx, sy = np.ravel(a[f"case_{m}_se"].values), np.ravel(b[f"case_{m}_se"].values)
            z[m] = (x - y) / np.sqrt(sx ** 2 + sy ** 2)
        out[cid] = dict(z=z, status=(str(a.case_status.values), str(b.case_status.values)),
                        steps=(int(a.case_steps.values), int(b.case_steps.values)),
                        steady_at=(float(a.case_steady_state_time.values),
                                   float(b.case_steady_state_time.values)))
    return out


def largest(rows: dict) -> np.ndarray:
    """Every finite |z| of ``changes``."""
    w = np.array([v for r in rows.values() for m in METRICS for v in np.abs(r["z"][m])])
    return w[np.isfinite(w)]


def markdown(rows: dict) -> str:
    """``changes`` as a Markdown table, and a line on the |z| beyond 2."""
    lines = ["| case | status new / old | steps new / old | steady at new / old [s] | "
             + " | ".join(f"z {m}" for m in METRICS) + " |",
             "|---|---|---|---|" + "---|" * len(METRICS)]
    for cid, r in rows.items():
        zs = " | ".join("/".join(f"{v:+.1f}" for v in r["z"][m]) for m in METRICS)
        lines.append(f"| {cid} | {r['status'][0]} / {r['status'][1]} | {r['steps'][0]} / {r['steps'][1]} | "
                     f"{r['steady_at'][0]:.2f} / {r['steady_at'][1]:.2f} | {zs} |")
    w = largest(rows)
    if w.size:
        lines.append(f"\n{w.size} metric values in {len(rows)} cases; |z| > 2: {int((w > 2).sum())}; "
                     f"largest |z| {w.max():.2f}")
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("new")
    ap.add_argument("old")
    a = ap.parse_args(argv)
    with xr.open_dataset(a.new) as new, xr.open_dataset(a.old) as old:
        print(markdown(changes(new, old)))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
