"""The case of every campaign, and the conveyor's grid dp x Ch x shifting, with canonical,
float-safe case ids."""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

# every flow's case ids: dp, Ch and shifting, then the scheme, fluid, physical axes or tag
CASE_ID = r"dp[0-9]+(?:\.[0-9]+)?mm_ch[0-9]+(?:\.[0-9]+)?_(?:none|skillen|lind)(?:_[A-Za-z0-9.-]+)*"


def fmt(x: float, digits: int = 6) -> str:
    """Shortest decimal form of x with at most ``digits`` decimals, never exponent notation:
    0.30000000000000004 -> '0.3', 1.0 -> '1', 0.25 -> '0.25'."""
    s = f"{round(float(x), digits):.{digits}f}".rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s


def axis_label(key: str) -> str:
    """A physical axis's name in a case id: the last part of its dotted key."""
    return key.rsplit(".", 1)[-1]


def case_id(dp: float, ch: float, shifting: str, tag: str | None = None, realisation: int = 0,
            scheme: str | None = None, fluid: str | None = None, axes: tuple = ()) -> str:
    """E.g. dp1mm_ch1.8_lind, dp2mm_ch1.5_skillen_surge_newtonian, dp1mm_ch1.8_skillen_slope_deg10;
    dp in mm; then the scheme, the fluid, each physical axis's value and the tag, where set;
    realisation k > 0 of a grid case ends in _rk."""
    parts = [f"dp{fmt(dp * 1000.0)}mm_ch{fmt(ch)}_{shifting}"]
    parts += [p for p in (scheme, fluid) if p]
    parts += [f"{axis_label(k)}{fmt(v) if isinstance(v, (int, float)) and not isinstance(v, bool) else v}"
              for k, v in axes]
    if realisation:
        tag = f"r{realisation}"
    return "_".join(parts + ([tag] if tag else []))


@dataclass(frozen=True)
class Case:
    """One run of a campaign: its spacing, Ch and shifting method; the conveyor's tag, extra-case
    overrides and realisation; a scene flow's scheme and fluid; and the values of the campaign's
    physical grid axes, as (dotted case key, value) pairs."""
    dp: float
    ch: float
    shifting: str
    tag: str | None = None
    overrides: dict = field(default_factory=dict, compare=False, hash=False)
    realisation: int = 0  # grid cases only: 0 runs the case as configured, k > 0 a perturbed start
    scheme: str | None = None
    fluid: str | None = None
    axes: tuple = ()

    @property
    def id(self) -> str:
        return case_id(self.dp, self.ch, self.shifting, self.tag, self.realisation, self.scheme, self.fluid,
                       self.axes)

    @property
    def on_grid(self) -> bool:
        return self.tag is None


def matches(selector: dict, dp: float, ch: float, shifting: str) -> bool:
    """Whether a case has every value the selector names (any of dp, ch, shifting; numbers
    compared as floats, so 1e-3, 1.0e-3 and 0.001 are one dp)."""
    values = {"dp": dp, "ch": ch, "shifting": shifting}
    return all(values[k] == (v if k == "shifting" else float(v)) for k, v in selector.items())


def physical_axes(grid: dict) -> list[tuple[str, list]]:
    """The grid's physical axes: (dotted campaign key, values) for each key with a dot."""
    return [(k, v) for k, v in grid.items() if "." in k]


def expand(grid: dict, extra: list[dict] | None = None,
           realisations: int | Callable[[float, float, str], int] = 1) -> list[Case]:
    """Cases of the grid (``combine``: product, or paper = every Ch with the first shifting
    method plus every method at ``paper_ch``), less those matching an ``exclude`` entry, for
    every combination of the physical axes' values (``physical_axes``), each in
    ``realisations`` realisations (0, 1, ...; a number, or a function of dp, ch and shifting),
    followed by the extra cases; ids unique."""
    import itertools
    axes_keys = [k for k, _ in physical_axes(grid)]
    points = [tuple(zip(axes_keys, values)) for values in itertools.product(*(v for _, v in physical_axes(grid)))]
    count = realisations if callable(realisations) else (lambda dp, ch, sh: int(realisations))
    dps, chs, shifts = grid["dp"], grid["ch"], grid["shifting"]
    combine = grid.get("combine", "product")
    excluded = grid.get("exclude") or []

    def left_out(dp, ch, sh):
        return any(matches(e, dp, ch, sh) for e in excluded)

    cases = []
    for axes in points:
        for dp in dps:
            for ch in chs:
                for sh in shifts:
                    if combine == "paper" and sh != shifts[0] and ch != grid.get("paper_ch", 1.8):
                        continue
                    if left_out(float(dp), float(ch), sh):
                        continue
                    n = count(float(dp), float(ch), sh)
                    cases.extend(Case(float(dp), float(ch), sh, realisation=k, axes=axes) for k in range(n))
    for e in extra or []:
        cases.append(Case(float(e["dp"]), float(e["ch"]), e["shifting"], e.get("tag"),
                          dict(e.get("overrides") or {})))
    return unique(cases, "give each extra case a distinct 'tag', and each physical axis a key whose "
                         "last part differs")


def set_key(tree: dict, dotted: str, value) -> None:
    """tree[a][b][c] = value for the key "a.b.c" (a missing mapping on the way is made)."""
    *path, last = dotted.split(".")
    for p in path:
        tree = tree.setdefault(p, {})
    tree[last] = value


def unique(cases: list[Case], how: str) -> list[Case]:
    """``cases``; ValueError naming the ids that repeat and ``how`` to tell them apart."""
    ids = [c.id for c in cases]
    dup = sorted({i for i in ids if ids.count(i) > 1})
    if dup:
        raise ValueError(f"duplicate case id(s) {', '.join(dup)}: {how}")
    return cases


def axis_values(cases: list[Case], key: str) -> list:
    """Each case's value of the physical axis ``key``: floats (NaN for a case without it) where
    every value is a number, else strings ("" for a case without it)."""
    values = [dict(c.axes).get(key) for c in cases]
    if all(v is None or (isinstance(v, (int, float)) and not isinstance(v, bool)) for v in values):
        return [float("nan") if v is None else float(v) for v in values]
    return ["" if v is None else str(v) for v in values]


def critical_paths(cases: list[Case], cost: Callable[[Case], float],
                   source: Callable[[Case], Case | None]) -> dict[str, float]:
    """Each case's critical path: its own ``cost`` plus the longest path among the cases that
    start from it (``source(c)`` is the case c waits for, None for none). Scheduling the
    longest path first lets a chain of warm starts run beside the runs that wait on nothing."""
    waiting: dict[str, list[Case]] = {}
    for c in cases:
        s = source(c)
        if s is not None:
            waiting.setdefault(s.id, []).append(c)
    paths: dict[str, float] = {}

    def path(c: Case) -> float:
        if c.id not in paths:
            paths[c.id] = cost(c) + max((path(d) for d in waiting.get(c.id, [])), default=0.0)
        return paths[c.id]
    return {c.id: path(c) for c in cases}
