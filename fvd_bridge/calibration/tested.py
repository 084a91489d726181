"""Where a calibration holds: the range its tests covered (stroke,
velocity, force, frequencies), what of a motion lies beyond it, and which
calibrations' OFs rank (computed on the same tests)."""

from __future__ import annotations

from ..records.device import tested_range

#: a motion counts as beyond the tested range from this share above its peaks
TESTED_MARGIN = 0.05


def tested(cal) -> dict:
    """The tested range: peak stroke d [mm], velocity v [mm/s], force F [kN]
    over every test, and the tests' frequencies f = (lowest, highest) in Hz (None: unknown)."""
    ranges = [t.range for t in cal.tests]
    peaks = cal.record.peaks
    out = {k: max([r[k] for r in ranges if r.get(k)] + [getattr(peaks, k) or 0.0]) or None for k in ("d", "v")}
    out["F"] = max([t.record.peaks.F or 0.0 for t in cal.tests] + [peaks.F or 0.0]) or None
    f = [r["f"] for r in ranges if r.get("f")]
    out["f"] = [min(f), max(f)] if f else None
    return out


def beyond(cal, motion, margin: float = TESTED_MARGIN) -> list[dict]:
    """What of a motion (a Record, or {d, v[, f]}) goes beyond the tested
    range, as data: one {'quantity': 'stroke' | 'velocity' | 'frequency',
    'value', 'tested' (the tests' peak, or [lowest, highest] Hz), 'unit',
    'where' (the device or record)} per quantity beyond it (a peak more
    than ``margin`` above the tests', a frequency outside their band by it)."""
    mine = motion if isinstance(motion, dict) else tested_range(motion)
    ref, where = tested(cal), cal.device or cal.record.name or "its record"
    out = []
    for key, what, unit in (("d", "stroke", "mm"), ("v", "velocity", "mm/s")):
        if ref.get(key) and mine.get(key) and mine[key] > (1.0 + margin) * ref[key]:
            out.append({"quantity": what, "value": float(mine[key]), "tested": float(ref[key]), "unit": unit,
                        "where": where})
    f, (lo, hi) = mine.get("f"), ref.get("f") or (None, None)
    if f and lo and not (1.0 - margin) * lo <= f <= (1.0 + margin) * hi:
        out.append({"quantity": "frequency", "value": float(f), "tested": [float(lo), float(hi)], "unit": "Hz",
                    "where": where})
    return out


def beyond_text(item: dict, name: str = "the motion") -> str:
    """One ``beyond`` item as the line ``beyond_tested`` gives."""
    if item["quantity"] == "frequency":
        return (f"{name}: dominant frequency {item['value']:.3g} Hz is outside the {band(*item['tested'])} the model "
                f"was calibrated on ({item['where']}): an extrapolation")
    unit = item["unit"]
    return (f"{name}: peak {item['quantity']} {item['value']:.4g} {unit} is beyond the {item['tested']:.4g} {unit} "
            f"the model was calibrated on ({item['where']}): an extrapolation")


def beyond_tested(cal, motion, margin: float = TESTED_MARGIN, what_of: str | None = None) -> list[str]:
    """What of a motion (a Record, or {d, v[, f]}) goes beyond the tested
    range: one line each (``Calibration.beyond_tested``; ``beyond``, as text)."""
    name = (what_of or "the motion") if isinstance(motion, dict) else motion.name
    return [beyond_text(item, name) for item in beyond(cal, motion, margin)]


def tested_text(cal) -> str:
    """'tested up to 30 mm and 450 mm/s at 0.8-2.4 Hz (device sn101, 3 tests)': where the model holds."""
    r = tested(cal)
    parts = [f"{r[k]:.4g} {u}" for k, u in (("d", "mm"), ("v", "mm/s")) if r.get(k)]
    freq = f" at {band(*r['f'])}" if r.get("f") else ""
    n = len(cal.tests) or 1
    where = f"device {cal.device or cal.record.name or '?'}, {n} test{'s' if n > 1 else ''}"
    return f"tested up to {' and '.join(parts)}{freq} ({where}); beyond it the model extrapolates"


def provenance_lines(cal) -> list[str]:
    """What an export's header says of the calibration: what it was fitted on and its tested range."""
    source = fitted_on_text(cal)
    return [*([f"calibrated on {source}"] if source else []), tested_text(cal)]


def fitted_on_text(cal) -> str:
    """What a calibration was fitted on: 'record A', 'device D, tests A, B',
    or one test of a device ('device D, test B'; with what it took of that
    test: 'device D, test B (beta fitted per test: test B's value)'); '': unknown."""
    names = [t.name for t in cal.tests]
    if len(names) <= 1 and (not cal.device or cal.device == (names or [cal.record.name])[0]):
        return f"record {cal.record.name}" if cal.record.name else ""
    own = list(cal.tests[0].parameters) if len(names) == 1 else []
    taken = f" ({', '.join(own)} fitted per test: test {names[0]}'s value)" if own else ""
    return f"device {cal.device}, test{'s' if len(names) > 1 else ''} {', '.join(names)}{taken}"


def data_key(test) -> tuple:
    """What a test (TestFit) of a calibration holds: (its record file, else its name; its samples)."""
    return (test.record.file or test.name, test.record.samples)


def same_data(calibrations) -> bool:
    """Whether every calibration's OF was computed on the same tests (files
    or names, samples, weights): only then do their OFs rank."""
    return len({c.fitted_on for c in calibrations}) <= 1


def common_tests(calibrations) -> list:
    """The tests (TestFits, as the first calibration holds them) every calibration was fitted on."""
    calibrations = list(calibrations)
    if not calibrations:
        return []
    shared = set.intersection(*({data_key(t) for t in c.tests} for c in calibrations))
    return [t for t in calibrations[0].tests if data_key(t) in shared]


def band(lo: float, hi: float) -> str:
    """'0.8-2.4 Hz', or '2 Hz' when both ends read alike."""
    a, b = f"{lo:.3g}", f"{hi:.3g}"
    return f"{a} Hz" if a == b else f"{a}-{b} Hz"
