"""Unit conversion to the package's units: kN, mm, s (velocity mm/s)."""

from .errors import InputError

#: factor that converts a value in the named unit to the canonical unit
FACTORS = {
    "t": {"s": 1.0, "ms": 1e-3, "min": 60.0},
    "d": {"mm": 1.0, "m": 1e3, "cm": 10.0, "in": 25.4, "um": 1e-3},
    "F": {"kN": 1.0, "N": 1e-3, "MN": 1e3, "kip": 4.4482216, "lbf": 4.4482216e-3, "tf": 9.80665},
    "v": {"mm/s": 1.0, "m/s": 1e3, "cm/s": 10.0, "in/s": 25.4},
}
CANONICAL = {"t": "s", "d": "mm", "F": "kN", "v": "mm/s"}


def factor(quantity: str, unit: str, where: str = "") -> float:
    """Factor converting ``unit`` of ``quantity`` (t, d, F or v) to kN, mm, s."""
    table = FACTORS.get(quantity)
    if table is None:
        raise InputError(f"{where}unknown quantity '{quantity}' (expected one of t, d, F, v)")
    if unit not in table:
        raise InputError(f"{where}unknown unit '{unit}' for {quantity} (known: {', '.join(table)})")
    return table[unit]
