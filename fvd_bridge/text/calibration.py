"""A calibration as text: the fit report (sections as lmfit's fit_report)
and the parameters' interval lines, every number rounded to its
uncertainty (``report.numbers``)."""

from __future__ import annotations

from ..fit.layout import SEP
from ..fit.objective import EXPLAINS_LITTLE, NEAR_FLOOR
from ..report.numbers import interval, rounded

#: the report lists correlations of at least this magnitude (lmfit's default)
REPORTED_CORRELATION = 0.1


def report(cal, min_correlation: float = REPORTED_CORRELATION) -> str:
    """The fit report as text (``Calibration.report``): model, fit
    statistics, variables with stderr and 95% intervals, derived quantities,
    correlations of at least ``min_correlation`` and warnings."""
    law = cal.model.law
    n = sum(t.record.samples or 0 for t in cal.tests) or cal.record.samples
    lines = ["[[Model]]", f"    {cal.spec}: law {law.key} ({law.name}), {law.equation}"]
    lines += [f"    + {e.name}: {e.equation}" for e in cal.model.effects]
    lines += ["[[Fit Statistics]]",
              f"    device:        {cal.device or cal.record.name} ({len(cal.tests) or 1} test(s), "
              f"{n} samples)",
              f"    OF (eq. 18):   {cal.of:.6g}{of_against_floor(cal)}"]
    lines += [f"    OF {t.name}: {t.of:.6g}" for t in cal.tests if len(cal.tests) > 1]
    asked = cal.settings.get("runs", 1)
    made = cal.settings.get("runs_made", asked)
    if cal.runs is not None and asked > 1:
        why = f" (they ended on one optimum: the other {asked - made} were not made)" if made < asked else ""
        lines.append(f"    runs:          {made} of {asked}, OF mean {cal.runs.of_mean:.6g}, "
                     f"sigma {cal.runs.of_sigma:.2g}{why}")
    if cal.settings.get("optimizer"):
        lines.append(f"    optimizer:     {cal.settings['optimizer']}, seed {cal.settings.get('seed')}")
    wider = cal.settings.get("wider_runs", 0)
    if wider:
        lines.append(f"    wider search:  {wider} round(s) beside the runs (their OF far above the noise floor)")
    if cal.solver is not None:
        lines.append(f"    search:        {cal.solver.evaluations} evaluations; {cal.solver.stop}")
    lines += [f"    {cal.tested_text()}", "[[Variables]]"]
    for p in cal.params.values():
        bounds = "" if None in p.bounds or p.fixed else f"  (bounds [{p.bounds[0]:.4g}, {p.bounds[1]:.4g}])"
        lines.append(f"    {p.text()}{bounds}")
        lines += [f"        {test}: {v:.6g}" for test, v in p.per_test.items()]
    if cal.derived():
        lines.append("[[Derived]]")
        lines += [f"    {name} = {value:.6g} {unit}" for name, (value, unit) in cal.derived().items()]
    if not cal.intervals:
        lines.append("    (no intervals: calibrate with intervals > 0)")
    else:
        lines += [f"    not identified: {line}" for line in cal.intervals.not_identified]
    if cal.force_zero is not None:
        head, *per_test = cal.force_zero.lines()
        lines += ["[[Force zero]] " + head.removeprefix("the tests' force zero ")]
        lines += [f"    {line}" for line in per_test]
    corr = cal.correlation
    if corr:
        names = list(corr)
        pairs = sorted(((corr[a][b], a, b) for i, a in enumerate(names) for b in names[i + 1:]
                        if abs(corr[a][b]) >= min_correlation), key=lambda x: -abs(x[0]))
        lines.append(f"[[Correlations]] (unreported correlations are < {min_correlation:.3f})")
        lines += [f"    C({a}, {b}) = {r:+.4f}" for r, a, b in pairs]
    if cal.warnings:
        lines.append("[[Warnings]]")
        lines += [f"    {w}" for w in cal.warnings]
    return "\n".join(lines)


def of_against_floor(cal) -> str:
    """', 12x the records' noise floor 0.0078: FAR ABOVE IT' (empty without a floor):
    what the OF means, beside it."""
    ratio = cal.solver.times_floor(cal.of) if cal.solver is not None else None
    if ratio is None:
        return ""
    said = f", {rounded(ratio, digits=2)}x the records' noise floor {rounded(cal.solver.floor, digits=2)}"
    if cal.of > EXPLAINS_LITTLE:
        return said + ": THE MODEL EXPLAINS LITTLE OF THE FORCE"
    return said + (": FAR ABOVE IT (the intervals count the noise only)" if ratio > NEAR_FLOOR else "")


def interval_lines(cal) -> list[str]:
    """'C = 39.87 kN/(mm/s)^alpha, 95% [39.9, 40.1] (stderr 0.05)' per
    parameter and derived quantity, then what is not identified; [] without intervals."""
    if not cal.intervals:
        return []
    given, derived = cal.intervals.parameters, cal.derived()
    values = {**cal.named(), **{f"{n}{SEP}{t.name}": v for t in cal.tests for n, v in t.parameters.items()}}
    units = dict(zip(cal.model.names, cal.model.units))

    def unit(name):
        return "" if units.get(name.split(SEP)[0], "-") == "-" else f" {units[name.split(SEP)[0]]}"

    first = {n: f"{n}{SEP}{cal.tests[0].name}" for n in cal.per_test}  # the model's vector holds the first test's
    out = [f"{first.get(n, n)} = {rounded(values[n])}{unit(n)} (fixed by the caller)"
           if e.ci95[0] == e.ci95[1] else
           f"{first.get(n, n)} = {rounded(values[n], e.stderr)}{unit(n)}, 95% {interval(*e.ci95, e.stderr)}"
           + (f" (stderr {rounded(e.stderr, digits=2)})" if e.stderr is not None else "")
           for n, e in given.items() if n in values]
    out += [f"{n} = {rounded(derived[n][0], d.stderr)} {derived[n][1]}, 95% {interval(*d.ci95, d.stderr)} "
            f"(stderr {rounded(d.stderr, digits=2)})" for n, d in cal.intervals.derived.items() if n in derived]
    out += [f"not identified: {line}" for line in cal.intervals.not_identified]
    if cal.force_zero is not None:
        out += cal.force_zero.lines()
    return out + ([f"note: {cal.intervals.note}"] if cal.intervals.note else [])


def per_test_text(cal) -> str:
    """'beta was fitted per test (A: 2.1, B: 3.35 kN/mm)': the parameters
    fitted per test (``Calibration.per_test``) with each test's value."""
    fitted, units = cal.per_test, dict(zip(cal.model.names, cal.model.units))

    def values(name: str, sep: str) -> str:
        unit = "" if units[name] == "-" else f" {units[name]}"
        return ", ".join(f"{test}{sep} {rounded(v)}" for test, v in fitted[name].items()) + unit

    if len(fitted) == 1:
        (name,) = fitted
        return f"{name} was fitted per test ({values(name, ':')})"
    return f"{', '.join(fitted)} were fitted per test ({'; '.join(f'{n}: {values(n, str())}' for n in fitted)})"
