"""A user's reference data from CSV files, and a run's error against it (docs/flow-user.md).

Three formats, one kind of data a file, comma-separated, SI units:

  front     columns t, x_front   front position x_front (m) at time t (s): t strictly
                                 ascending, x_front > 0 (distance from the end wall)
  depth     columns t, x, h      depth profiles h(x) (m) at times t: the rows of one time
                                 together, times ascending, x strictly ascending within each
                                 profile, h >= 0
  velocity  columns x, z, u      velocity profiles u(z) (m/s) at stations x: the rows of one
                                 station together, stations ascending, z strictly ascending
                                 within each profile

Everything from a '#' to the end of its line is a comment; blank lines are skipped. The first
other line is the header row, naming the columns (in any order; further columns are allowed
and ignored, names are case-sensitive). Every later line holds one value per header column;
the named columns must hold finite numbers. A file has at least 2 data rows, and each profile
at least 2 points.

A file that breaks a rule is refused with a ValueError that names the file, the line (1-based,
counting every line, comments and header included, as a text editor does) and the fault, e.g.
``ref.csv line 7: 'abc' in column x_front is not a number``.
"""
from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np
import xarray as xr

FRONT_COLUMNS = ("t", "x_front")
DEPTH_COLUMNS = ("t", "x", "h")
VELOCITY_COLUMNS = ("x", "z", "u")
UNITS = {"t": "s", "x_front": "m", "x": "m", "z": "m", "h": "m", "u": "m/s"}


def read_rows(path, columns) -> tuple[np.ndarray, np.ndarray]:
    """(values, lines): the named ``columns`` of each data row of a CSV file as floats, shape
    (rows, len(columns)), and each row's 1-based line number. Checks the rules of the module
    docstring that do not depend on the kind of data (header, row length, finite numbers, at
    least 2 rows)."""
    path = Path(path)
    header, where, rows, lines, last = None, None, [], [], 0
    with open(path, newline="", encoding="utf-8-sig") as fh:
        for last, raw in enumerate(fh, start=1):
            text = raw.split("#", 1)[0]
            if not text.strip():
                continue
            fields = [f.strip() for f in next(csv.reader([text]))]
            if header is None:
                header = _header(path, last, fields, columns)
                where = [header.index(c) for c in columns]
                continue
            if len(fields) != len(header):
                raise ValueError(f"{path} line {last}: {len(fields)} value{'' if len(fields) == 1 else 's'}, "
                                 f"expected {len(header)} ({', '.join(header)})")
            rows.append([_number(path, last, fields[i], header[i]) for i in where])
            lines.append(last)
    if header is None:
        raise ValueError(f"{path} line {max(last, 1)}: no header row; the first line that is not a "
                         f"comment must name the columns {', '.join(columns)}")
    if len(rows) < 2:
        raise ValueError(f"{path} line {last}: the file ends after {len(rows)} data row(s); at least 2 needed")
    return np.array(rows, dtype=float), np.array(lines)


def _header(path: Path, line: int, fields: list[str], columns) -> list[str]:
    """The header row's names, checked: none empty or repeated, every one of ``columns`` present."""
    if all(_is_number(f) for f in fields):
        raise ValueError(f"{path} line {line}: no header row; this line holds numbers, the first line "
                         f"that is not a comment must name the columns {', '.join(columns)}")
    if "" in fields:
        raise ValueError(f"{path} line {line}: an empty column name in the header")
    repeated = sorted({f for f in fields if fields.count(f) > 1})
    if repeated:
        raise ValueError(f"{path} line {line}: column(s) {', '.join(repeated)} named twice in the header")
    missing = [c for c in columns if c not in fields]
    if missing:
        raise ValueError(f"{path} line {line}: missing column(s) {', '.join(missing)} in the header "
                         f"({', '.join(fields)}); expected {', '.join(columns)}")
    return fields


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _number(path: Path, line: int, text: str, column: str) -> float:
    """float(text), refused unless it is a finite number."""
    try:
        value = float(text)
    except ValueError:
        raise ValueError(f"{path} line {line}: '{text}' in column {column} is not a number") from None
    if not math.isfinite(value):
        raise ValueError(f"{path} line {line}: '{text}' in column {column} is not a finite number")
    return value


def read_front(path) -> xr.DataArray:
    """Front positions: CSV with columns t, x_front (module docstring). Returns x_front along
    the coordinate t."""
    path = Path(path)
    v, lines = read_rows(path, FRONT_COLUMNS)
    t, x = v[:, 0], v[:, 1]
    for i in range(1, t.size):
        if t[i] <= t[i - 1]:
            raise ValueError(f"{path} line {lines[i]}: t = {t[i]:g} is not after t = {t[i - 1]:g} "
                             f"(line {lines[i - 1]}); times must ascend")
    for i in np.nonzero(x <= 0)[0]:
        raise ValueError(f"{path} line {lines[i]}: x_front = {x[i]:g} is not positive "
                         f"(the front's distance from the end wall)")
    return xr.DataArray(x, coords={"t": ("t", t, {"units": "s"})}, dims="t", name="x_front",
                        attrs={"units": "m", "source": str(path)})


def read_depth_profiles(path) -> xr.DataArray:
    """Depth profiles: CSV with columns t, x, h (module docstring). Returns h over the
    coordinates (t, x), x the union of all profiles' abscissas, NaN where a profile has no
    point: ``ref.sel(t=t_k).dropna("x")`` is the profile at t_k."""
    path = Path(path)
    v, lines = read_rows(path, DEPTH_COLUMNS)
    _check_profiles(path, v[:, 0], v[:, 1], lines, DEPTH_COLUMNS)
    for i in np.nonzero(v[:, 2] < 0)[0]:
        raise ValueError(f"{path} line {lines[i]}: h = {v[i, 2]:g} is negative")
    return _grid(path, v, DEPTH_COLUMNS)


def read_velocity_profiles(path) -> xr.DataArray:
    """Velocity profiles: CSV with columns x, z, u (module docstring). Returns u over the
    coordinates (x, z), z the union of all stations' heights, NaN where a station has no
    point: ``ref.sel(x=x_k).dropna("z")`` is the profile at station x_k."""
    path = Path(path)
    v, lines = read_rows(path, VELOCITY_COLUMNS)
    _check_profiles(path, v[:, 0], v[:, 1], lines, VELOCITY_COLUMNS)
    return _grid(path, v, VELOCITY_COLUMNS)


def _check_profiles(path: Path, key, s, lines, columns) -> None:
    """Profiles in a file: key (a time or a station) ascending from one profile to the next,
    abscissa s strictly ascending within one, at least 2 points each."""
    k, a = columns[0], columns[1]
    start = 0
    for i in range(1, key.size + 1):
        if i < key.size and key[i] == key[i - 1]:
            if s[i] <= s[i - 1]:
                raise ValueError(f"{path} line {lines[i]}: {a} = {s[i]:g} is not after {a} = {s[i - 1]:g} "
                                 f"(line {lines[i - 1]}) within the profile at {k} = {key[i]:g}")
            continue
        if i - start < 2:
            raise ValueError(f"{path} line {lines[start]}: the profile at {k} = {key[start]:g} has 1 point; "
                             f"at least 2 needed")
        if i < key.size and key[i] < key[i - 1]:
            raise ValueError(f"{path} line {lines[i]}: {k} = {key[i]:g} comes after the profile at "
                             f"{k} = {key[i - 1]:g} (line {lines[i - 1]}); profiles must come in ascending {k}")
        start = i


def _grid(path: Path, v: np.ndarray, columns) -> xr.DataArray:
    """The rows (key, abscissa, value) on the grid of the distinct keys and abscissas, NaN where
    a key has no value."""
    k, a, name = columns
    keys, absc = np.unique(v[:, 0]), np.unique(v[:, 1])
    out = np.full((keys.size, absc.size), np.nan)
    out[np.searchsorted(keys, v[:, 0]), np.searchsorted(absc, v[:, 1])] = v[:, 2]
    return xr.DataArray(out, dims=(k, a), name=name, attrs={"units": UNITS[name], "source": str(path)},
                        coords={k: (k, keys, {"units": UNITS[k]}), a: (a, absc, {"units": UNITS[a]})})


def on_reference(x_ref, x_run, y_run) -> np.ndarray:
    """A run's curve interpolated onto the reference's abscissas, as every metric does
    (study.metrics.on_abscissas: never extrapolated, never bridged over a gap)."""
    from ..metrics import on_abscissas
    return on_abscissas(x_ref, x_run, y_run)


def _rms(values) -> float:
    v = np.asarray(values, dtype=float)
    v = v[np.isfinite(v)]
    return float(np.sqrt(np.mean(v * v))) if v.size else float("nan")


def front_error(t_ref, x_ref, t_run, x_run, interval=None) -> float:
    """sqrt(mean ((x_run(t_i) - x_ref,i) / x_ref,i)^2) over the reference times t_i in the
    closed ``interval`` (t0, t1) (None: all), x_run interpolated linearly onto them
    (``on_reference``); reference times outside the run's record do not count. NaN when no
    reference time counts. A run at 1.05 times the reference gives 0.05."""
    t_ref = np.asarray(t_ref, dtype=float)
    x_ref = np.asarray(x_ref, dtype=float)
    if interval is not None:
        keep = (t_ref >= interval[0]) & (t_ref <= interval[1])
        t_ref, x_ref = t_ref[keep], x_ref[keep]
    return _rms((on_reference(t_ref, t_run, x_run) - x_ref) / x_ref)


def profile_error(s_ref, y_ref, s_run, y_run, scale: float | None = None) -> float:
    """sqrt(mean (y_run(s_i) - y_ref,i)^2) / scale over the reference abscissas s_i (x of a depth
    profile, z of a velocity profile) where the run is defined, y_run interpolated linearly onto
    them (``on_reference``). scale: by default the reference's largest |y| in this profile (its
    largest depth; its largest speed at the station). NaN when no abscissa counts."""
    y_ref = np.asarray(y_ref, dtype=float)
    if scale is None:
        scale = float(np.nanmax(np.abs(y_ref)))
    return _rms(on_reference(s_ref, s_run, y_run) - y_ref) / scale
