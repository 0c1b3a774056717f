"""How the report writes an error: the zeta metrics are fractions, shown in per cent."""
from __future__ import annotations

import numpy as np


def percent(fraction, missing: str = "-") -> str:
    """``fraction`` in per cent to two significant digits, in plain decimals: 4.537e-4 ->
    '0.045 %', 0.0816 -> '8.2 %', 1.23 -> '120 %', 0.01 -> '1 %'; ``missing`` where it is not
    a finite number."""
    try:
        v = 100.0 * float(fraction)
    except (TypeError, ValueError):
        return missing
    if not np.isfinite(v):
        return missing
    if v == 0.0:
        return "0 %"
    return np.format_float_positional(v, precision=2, unique=False, fractional=False, trim="-") + " %"


def with_error(value, se) -> str:
    """An error (a fraction) in per cent +- 2 se (its sampling error), both to two significant
    digits, or the value alone where se is unknown."""
    if se is None or not np.isfinite(se) or not np.isfinite(value):
        return percent(value, "&ndash;")
    return f"{percent(value)} &plusmn; {percent(2.0 * se)}"
