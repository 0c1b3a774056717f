"""How long the start's transient lasts in a front run's detection signals.

For each run (best with steady.stop: false and a few seconds past the transient), every
signal's mean over successive bins of --bin seconds is compared with its mean over the run's
last --tail seconds, in dp: the toe, the equivalent front and each station front. A signal
has settled at the end of the last bin whose mean is off by more than --band dp; the table
gives that time per signal, and the heading the time a depth change takes to cross the body
from the upstream wall, fluid_length h_n / (2 u_b) (the kinematic wave of a Newtonian film,
c = dq/dh = 3 u_b relative to the belt, 2 u_b in the lab frame).

    python benchmarks/transient.py RUN.nc [...] [--bin 0.25 --tail 2 --band 0.1] [--rows]
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
import xarray as xr
import yaml

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from solver.conveyor import case_from_dict  # noqa: E402


def signals(run: xr.Dataset) -> dict[str, np.ndarray]:
    """The detection's position signals [m] (and the toe), by name."""
    out = {"toe": run.toe_position.values, "equivalent front": run.front_equivalent.values}
    for k, s in enumerate(run.station.values):
        out[f"station {s:g}"] = run.station_front.values[:, k]
    return out


def binned_offsets(t, y, dp, bin_s, tail_s):
    """(bin ends, offset of each bin's mean from the last tail_s seconds' mean, in dp)."""
    ref = np.nanmean(y[t >= t[-1] - tail_s])
    edges = np.arange(0.0, t[-1] - tail_s + 1e-9, bin_s)
    ends, off = [], []
    for lo in edges:
        sel = (t >= lo) & (t < lo + bin_s)
        if sel.any():
            ends.append(lo + bin_s)
            off.append((np.nanmean(y[sel]) - ref) / dp)
    return np.array(ends), np.array(off)


def settled_at(ends, off, band):
    """End of the last bin whose offset exceeds band (0 if none does)."""
    out = ends[np.abs(off) > band]
    return float(out[-1]) if out.size else 0.0


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("runs", nargs="+")
    ap.add_argument("--bin", type=float, default=0.25)
    ap.add_argument("--tail", type=float, default=2.0)
    ap.add_argument("--band", type=float, default=0.1)
    ap.add_argument("--rows", action="store_true", help="also print every bin's offsets")
    a = ap.parse_args(argv)
    for path in a.runs:
        with xr.open_dataset(path) as ds:
            run = ds.load()
        case = case_from_dict(yaml.safe_load(run.attrs["case_yaml"]))
        dp = float(run.attrs["dp"])
        t = run.time.values
        sig = signals(run)
        crossing = case.fluid_length * case.h_n / (2.0 * case.belt.speed)
        print(f"\n{path}: dp {dp * 1e3:g} mm, {t[-1]:.2f} s, crossing time "
              f"{crossing:.2f} s; settled (within {a.band:g} dp of the last "
              f"{a.tail:g} s, {a.bin:g} s bins) at:")
        table = {name: binned_offsets(t, y, dp, a.bin, a.tail) for name, y in sig.items()}
        print("| " + " | ".join(table) + " |")
        print("|" + "---|" * len(table))
        print("| " + " | ".join(f"{settled_at(e, o, a.band):.2f} s" for e, o in table.values()) + " |")
        if a.rows:
            ends = next(iter(table.values()))[0]
            print("\n| bin end [s] | " + " | ".join(table) + " |")
            print("|" + "---|" * (len(table) + 1))
            for i, e in enumerate(ends):
                print(f"| {e:.2f} | " + " | ".join(f"{o[i]:+.2f}" for _, o in table.values()) + " |")


if __name__ == "__main__":
    main()
