"""Unit conversion to the package's units: kN, mm, s (velocity mm/s)."""

from .errors import InputError, option

#: factor that converts a value in the named unit to the canonical unit
FACTORS = {
    "t": {"s": 1.0, "ms": 1e-3, "min": 60.0},
    "d": {"mm": 1.0, "m": 1e3, "cm": 10.0, "in": 25.4, "um": 1e-3},
    "F": {"kN": 1.0, "N": 1e-3, "MN": 1e3, "kip": 4.4482216, "lbf": 4.4482216e-3, "tf": 9.80665},
    "v": {"mm/s": 1.0, "m/s": 1e3, "cm/s": 10.0, "in/s": 25.4},
}
CANONICAL = {"t": "s", "d": "mm", "F": "kN", "v": "mm/s"}
#: other spellings of the units above, as headers write them (``unit_name``)
ALIASES = {"sec": "s", "msec": "ms", "\u00b5m": "um", "\u03bcm": "um", "inch": "in", "lb": "lbf", "lbs": "lbf",
           "kips": "kip", "mm/sec": "mm/s", "m/sec": "m/s", "in/sec": "in/s", "ips": "in/s"}


def factor(quantity: str, unit: str, where: str = "") -> float:
    """Factor converting ``unit`` of ``quantity`` (t, d, F or v) to kN, mm, s."""
    table = FACTORS.get(quantity)
    if table is None:
        raise InputError(f"{where}unknown quantity '{quantity}' (expected one of t, d, F, v)")
    if unit not in table:
        raise InputError(f"{where}unknown unit '{unit}' for {quantity} (known: {', '.join(table)})")
    return table[unit]


def unit_name(quantity: str, text: str) -> str | None:
    """The table's name of the unit ``text`` of ``quantity`` (t, d, F or v)
    as a header writes it ('KN', 'sec', 'lbs'), None when it is not a unit
    of that quantity: an exact name, an alias (ALIASES), or the one name
    equal to it ignoring case."""
    table = FACTORS.get(quantity, {})
    text = text.strip()
    if text in table:
        return text
    alias = ALIASES.get(text) or ALIASES.get(text.lower())
    if alias in table:
        return alias
    same = [u for u in table if u.lower() == text.lower()]
    return same[0] if len(same) == 1 else None


#: the package's own unit system {F, d, t}
SYSTEM = {"F": "kN", "d": "mm", "t": "s"}


def unit_system(text, where: str | None = None) -> dict:
    """'kN,m,s' (FORCE,LENGTH,TIME) -> {'F': 'kN', 'd': 'm', 't': 's'}; a
    tuple ('kN', 'm', 's') and a dict {F, d, t} are checked as they are;
    None is the package's kN, mm, s.  A bad one: an InputError naming
    ``where`` (default: the units option in the caller's words)."""
    if text is None:
        return dict(SYSTEM)
    given = f"{where} '{text}'" if where else option("--units", text)
    if isinstance(text, dict):
        missing = [k for k in "Fdt" if k not in text]
        if missing:
            raise InputError(f"{given}: no unit for '{missing[0]}' (give F, d and t)")
        parts = [text[k] for k in "Fdt"]
    elif isinstance(text, (tuple, list)):
        parts = [str(p) for p in text]
    elif "=" in str(text):  # F=kN,d=m[,t=s]: the package's unit where one is not given
        given = dict(item.split("=", 1) for item in str(text).replace(" ", "").split(",") if "=" in item)
        unknown = sorted(set(given) - set("Fdt"))
        if unknown:
            raise InputError(f"{given}: unknown quantity '{unknown[0]}' (F, d or t)")
        parts = [given.get(k, SYSTEM[k]) for k in "Fdt"]
    else:
        parts = [p.strip() for p in str(text).split(",")]
    if len(parts) != 3:
        raise InputError(f"{given}: expected FORCE,LENGTH,TIME, e.g. kN,m,s or N,mm,s or kip,in,s")
    for quantity, unit in zip("Fdt", parts):
        factor(quantity, unit, f"{given}: ")
    return dict(zip("Fdt", parts))


def system_text(system: dict = SYSTEM) -> str:
    """{F, d, t} -> 'kN,mm,s' (FORCE,LENGTH,TIME, as ``unit_system`` reads it)."""
    return ",".join(system[k] for k in "Fdt")


def in_system(value: float, unit: str, system: dict, exponents: dict | None = None) -> float:
    """``value`` in the registry's ``unit`` string (kN, mm, s; e.g.
    'kN/(mm/s)^alpha', an exponent named by a parameter in ``exponents``)
    expressed in ``system`` ({F, d, t}, ``unit_system``): a dashpot's C with
    exponent alpha scales with LENGTH^alpha, not LENGTH."""
    if unit in ("-", "") or system == SYSTEM:
        return float(value)
    scale = {"kN": 1.0 / factor("F", system["F"]), "mm": 1.0 / factor("d", system["d"]),
             "s": 1.0 / factor("t", system["t"])}
    try:
        k = eval(unit.replace("^", "**"), {"__builtins__": {}}, {**scale, **(exponents or {})})  # registry text
    except Exception:
        raise InputError(f"unit '{unit}': cannot be written in {system['F']}, {system['d']}, {system['t']}") from None
    return float(value) * float(k)
