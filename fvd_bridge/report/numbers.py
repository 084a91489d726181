"""Numbers for people: significant digits from the uncertainty, never a raw float.

Every page and printed table formats its numbers here:

- ``rounded(value, uncertainty)``: the value to the decimal place of the
  uncertainty's second significant digit (the convention of the GUM,
  JCGM 100:2008 7.2.6: an uncertainty is given to at most two significant
  digits and the value to the same place), at most ``MAX_DIGITS``
  significant digits; without an uncertainty, ``DEFAULT_DIGITS``.
- ``share(x)``: a ratio as a percentage, two significant digits beyond 1%.
- ``with_unit(name, unit)``: a table header, ``name [unit]``.
"""

from __future__ import annotations

import math

#: significant digits of a number without an uncertainty
DEFAULT_DIGITS = 4
#: at most this many significant digits, whatever the uncertainty
MAX_DIGITS = 6


def _digits_of(value: float, uncertainty: float | None) -> int:
    """Significant digits of ``value`` that reach its uncertainty's second digit."""
    if uncertainty is None or not math.isfinite(uncertainty) or uncertainty <= 0.0 or value == 0.0:
        return DEFAULT_DIGITS
    places = math.floor(math.log10(abs(value))) - math.floor(math.log10(uncertainty)) + 2
    return max(1, min(MAX_DIGITS, places))


def rounded(value, uncertainty: float | None = None, digits: int | None = None) -> str:
    """``value`` as text with the significant digits its ``uncertainty``
    supports (module docstring), or ``digits`` of them; '-' for None, 'n/a'
    for NaN, '∞' for infinities.  Plain notation from 1e-4 to 1e6, else
    scientific."""
    if value is None:
        return "-"
    try:
        x = float(value)
    except (TypeError, ValueError):
        return str(value)
    if math.isnan(x):
        return "n/a"
    if math.isinf(x):
        return "∞" if x > 0 else "-∞"
    if x == 0.0:
        return "0"
    n = digits if digits is not None else _digits_of(x, uncertainty)
    n = max(1, min(MAX_DIGITS, int(n)))
    magnitude = math.floor(math.log10(abs(x)))
    if -4 <= magnitude < 6:
        decimals = max(0, n - 1 - magnitude)
        text = f"{round(x, decimals):.{decimals}f}"
        if decimals == 0 and magnitude >= n:  # 123456 to 4 digits: 123500
            text = f"{round(x, n - 1 - magnitude):.0f}"
        return text
    return f"{x:.{n - 1}e}"


def interval(low, high, uncertainty: float | None = None) -> str:
    """'[low, high]', each end rounded to ``uncertainty`` (``rounded``)."""
    return f"[{rounded(low, uncertainty)}, {rounded(high, uncertainty)}]"


def share(x, digits: int = 2) -> str:
    """A ratio (0.0123) as a percentage ('1.2%'): ``digits`` significant
    digits, at least one decimal below 10%."""
    if x is None or not math.isfinite(float(x)):
        return rounded(x)
    p = 100.0 * float(x)
    if p == 0.0:
        return "0%"
    magnitude = math.floor(math.log10(abs(p)))
    decimals = max(0, digits - 1 - magnitude, 1 if abs(p) < 10 else 0)
    return f"{p:.{decimals}f}%"


def with_unit(name: str, unit: str | None) -> str:
    """A header with its unit: 'C [kN·(s/mm)^alpha]'; the bare name without one."""
    return f"{name} [{unit}]" if unit else name


def cell(value) -> str:
    """Any table cell for people: a whole number (a count) as it is, any other
    number ``rounded`` to ``DEFAULT_DIGITS``, text that reads as a number (a
    CSV cell) the same, other text as it is; '' for None or ''."""
    if value is None or isinstance(value, bool):
        return "" if value is None else ("yes" if value else "no")
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        return rounded(value)
    text = str(value)
    try:
        return str(int(text))
    except ValueError:
        pass
    try:
        x = float(text)
    except ValueError:
        return text
    return rounded(x)


def has_spread(value, spread) -> bool:
    """Whether ``with_spread`` shows ``spread`` beside ``value``: a finite
    spread above a millionth of the value."""
    return (value is not None and spread is not None and math.isfinite(float(spread))
            and abs(float(spread)) > 1e-6 * abs(float(value)))


def with_spread(value, spread) -> str:
    """'45.41 (0.05)': a mean rounded to its spread (a sigma over runs,
    ``rounded``) and the spread to two significant digits; the mean alone,
    to ``DEFAULT_DIGITS``, when the spread is nil (``has_spread``)."""
    if value is None:
        return ""
    if not has_spread(value, spread):
        return rounded(value)
    return f"{rounded(value, spread)} ({rounded(spread, digits=2)})"


def small_share(x, smallest: float = 1e-4) -> str:
    """``share``, but a ratio below ``smallest`` in magnitude as '<0.01%' (a
    gain of 5e-9 is nothing a reader weighs, not '0.00000050%')."""
    if x is not None and math.isfinite(float(x)) and 0.0 < abs(float(x)) < smallest:
        return f"<{share(smallest, digits=1)}" if x > 0 else f"-<{share(smallest, digits=1)}"
    return share(x)
