"""What a frame comparison says: over the devices of a production series
each quantity's spread (min, mean, max, coefficient of variation) per
model, and the verdict: the simplest model whose peak drift and damper
force stay within VERDICT_TOLERANCE of the best-fitting model's (the lowest
mean OF where the OFs are computed on the same data: every model fitted to
the same tests, or each evaluated on a common record: one the caller gives,
else a test every calibration was fitted on; models fitted to different
tests without one are not ranked), what the model choice changes in drift
and in damper force, and whether the dampers matter at all."""

from __future__ import annotations

import os

import numpy as np

from ..report.numbers import rounded, share
from .compare import QUANTITIES

#: dampers adding less than this supplemental damping ratio to the first mode are too small to matter
SMALL_DAMPING = 0.02

#: a simpler model is as good as the best-fitting one within this share
VERDICT_TOLERANCE = 0.05


def series_spread(cases) -> dict:
    """{spec: {quantity: (min, mean, max, cov)}} over the devices of each model
    whose analysis reached its end (cov = std / |mean|, NaN for a single
    device); plus 'devices', 'of' (the mean calibration OF) and 'common_of'
    (the mean OF on the common record the models rank on; None: none)."""
    out = {}
    ran = [c for c in nominal(cases) if c.spec is not None and c.result is not None and c.result.solver.completed]
    for spec in dict.fromkeys(c.spec for c in ran):
        group = [c for c in ran if c.spec == spec]
        values = [c.values() for c in group]
        stats = {}
        for key, _, _ in QUANTITIES:
            x = np.array([v[key] for v in values], dtype=float)
            mean = float(np.mean(x))
            cov = float(np.std(x) / abs(mean)) if len(x) > 1 and mean != 0.0 else float("nan")
            stats[key] = (float(np.min(x)), mean, float(np.max(x)), cov)
        stats["devices"] = [c.device for c in group]
        stats["of"] = float(np.mean([c.of for c in group]))
        stats["common_of"] = (float(np.mean([c.ranked_on[1] for c in group]))
                              if all(c.ranked_on for c in group) else None)
        stats["n_params"] = group[0].n_params
        out[spec] = stats
    return out


def nominal(cases) -> list:
    """The cases without bounds or of the nominal damper (``frame --property-bounds`` runs three per calibration)."""
    return [c for c in cases if getattr(c, "bound", None) in (None, "nominal")]


def unfinished(cases) -> list[str]:
    """'law 2 | dev (stopped at 37.4 s of the record's 53.7 s)' for each damper
    case whose analysis did not reach its end (left out of the verdict)."""
    return [f"{c.label} (stopped at {c.result.solver.failed_at or c.result.t[-1]:.1f} s of the record's "
            f"{c.result.record_end:.1f} s)" for c in cases
            if c.spec is not None and c.result is not None and not c.result.solver.completed]


def ranking(spread: dict, cases=()) -> tuple[dict | None, str]:
    """What the verdict ranks the models by: ({spec: mean OF}, where it is
    computed), or (None, why they are not ranked).  The OFs rank only on
    the same data: the common record of ``rank_common`` where every case
    has it, else the calibration OFs where every model's cases were fitted
    to the same tests (a series: the same tests for each device)."""
    ran = [c for c in cases if c.spec in spread and c.result is not None and c.result.solver.completed]
    if ran and all(c.ranked_on for c in ran):
        return {s: spread[s]["common_of"] for s in spread}, f"on {ran[0].ranked_on[0]}"
    data = {s: frozenset(c.fitted_on for c in ran if c.spec == s) for s in spread}
    if len(set(data.values())) <= 1:
        return {s: spread[s]["of"] for s in spread}, ""
    fitted = "; ".join(f"law {s} on {_tests(d)}" for s, d in data.items())
    return None, (f"fitted to different tests: not ranked ({fitted}; give a test record to rank them on, "
                  f"frame --rank-on FILE)")


def _tests(data: frozenset) -> str:
    """'a, b' or '12 tests': the tests of a model's cases (Case.fitted_on)."""
    names = sorted({os.path.splitext(os.path.basename(str(k[0])))[0] for tests in data for k in tests})
    return ", ".join(names) if len(names) <= 3 else f"{len(names)} tests"


def verdict(spread: dict, cases=(), resize: str | None = None) -> str:
    """The verdict's lines (``verdict_lines``) as one text."""
    return "; ".join(verdict_lines(spread, cases, resize))


def verdict_lines(spread: dict, cases=(), resize: str | None = None) -> list[str]:
    """What the frame analysis says, one line each:

    - the best-fitting model, ranked on the same data only (``ranking``;
      models whose OFs are not get none, and the verdict says why), and the
      simplest model (fewest parameters, then lowest law number) whose mean
      peak drift and damper force are within VERDICT_TOLERANCE of its;
    - the response with that model's dampers against the bare frame: peak
      and residual drift, floor acceleration, damper force;
    - how much the choice of model changes peak drift (a decision on the
      frame) and, apart, damper force (the damper and its connections),
      with the series scatter (CoV) as the yardstick;
    - the dampers' supplemental damping of the first mode: achieved against
      the target where they were sized, else the energy method's estimate,
      and below SMALL_DAMPING that they are too small to matter and how to
      size them (``resize``, a command line);
    - an analysis that did not reach its end (in ``cases``) is left out, and said so."""
    gone = unfinished(cases)
    cases = nominal(cases)  # the bounds' own lines: frames.property_bounds.envelope_lines
    left_out = [f"left out, the analysis did not reach its end: {'; '.join(gone)}"] if gone else []
    if not spread:
        return ["no damper model ran to the end"] + left_out
    pick = choice(spread, cases)
    parts = []
    if pick["best"] is None:
        parts.append(pick["why"])
    else:
        where = pick["where"]
        there = f" {where}" if where else ""
        parts.append(f"best-fitting model{there}: law {pick['best']} (mean OF{' there' if where else ''} "
                     f"{rounded(pick['of'])}); simplest within {VERDICT_TOLERANCE:.0%} on peak drift and damper "
                     f"force: law {pick['simplest']}")
    shown = pick["shown"]
    parts.append(_response(spread, shown, cases))
    parts.append(_model_choice(spread))
    damping = _damping(spread, cases, resize)
    if damping:
        parts.append(damping)
    return parts + left_out


def choice(spread: dict, cases=()) -> dict:
    """The verdict's choice of model, as data: {'shown': the model whose
    response it gives (the best-fitting, else the simplest), 'best' (None:
    not ranked), 'simplest' (fewest parameters, then lowest law number,
    within VERDICT_TOLERANCE of the best's mean peak drift and damper force;
    of all models where not ranked), 'of' (the best's mean OF), 'where'
    (what it is computed on, '' for their own OFs), 'why' (not ranked: why)};
    {} without a model that ran."""
    cases = nominal(cases)
    if not spread:
        return {}
    of, where = ranking(spread, cases)

    def simplest(specs):
        return min(specs, key=lambda s: (spread[s]["n_params"], s))

    if of is None:
        shown = simplest(spread)
        return {"shown": shown, "best": None, "simplest": shown, "of": None, "where": "", "why": where}
    best = min(spread, key=lambda s: of[s])
    ref_drift, ref_force = spread[best]["drift"][1], spread[best]["force"][1]

    def close(s):
        return (abs(spread[s]["drift"][1] - ref_drift) <= VERDICT_TOLERANCE * abs(ref_drift)
                and abs(spread[s]["force"][1] - ref_force) <= VERDICT_TOLERANCE * abs(ref_force))

    return {"shown": best, "best": best, "simplest": simplest([s for s in spread if close(s)]), "of": of[best],
            "where": where, "why": ""}


def _mean_text(stats: tuple, unit: str) -> str:
    """'1.215%' (one device) or '1.211-1.220%' (min-max over the series' devices)."""
    low, mean, high, _ = stats
    if not np.isfinite(mean):
        return "n/a"
    body = rounded(mean) if np.isclose(low, high, rtol=1e-12, atol=0.0) else f"{rounded(low)}-{rounded(high)}"
    return f"{body}{unit if unit == '%' else ' ' + unit}"


def _response(spread: dict, spec: str, cases) -> str:
    """'with law 2: peak drift 1.215% (bare frame 1.376%), residual drift ...'."""
    bare = next((c.values() for c in cases if c.spec is None and c.result is not None), None)
    s = spread[spec]

    def against(key, unit):
        was = "" if bare is None or not np.isfinite(bare[key]) else \
            f" (bare frame {rounded(bare[key])}{unit if unit == '%' else ' ' + unit})"
        return _mean_text(s[key], unit) + was

    return (f"with law {spec}: peak interstory drift {against('drift', '%')}, residual drift "
            f"{against('residual', '%')}, peak floor acceleration {against('pfa', 'g')}, peak damper force "
            f"{_mean_text(s['force'], 'kN')} per damper")


def _model_choice(spread: dict) -> str:
    """How far apart the models' mean peak drift and damper force lie, each
    named with the decision it weighs on, beside the series' scatter."""
    scatter = [spread[s][q][3] for s in spread for q in ("drift", "force") if np.isfinite(spread[s][q][3])]
    yard = (f"; the series' own scatter (CoV over devices) reaches {share(max(scatter))}"
            if scatter else "; one device per model, no series scatter to compare with")
    if len(spread) < 2:
        return "one model, no choice of model to weigh" + yard

    def apart(q):
        x = [spread[s][q][1] for s in spread]
        return (max(x) - min(x)) / abs(min(x)) if min(x) != 0.0 else float("nan")

    return (f"the choice of model changes peak drift by up to {share(apart('drift'))} (what the frame is designed "
            f"for) and peak damper force by up to {share(apart('force'))} (what the damper and its connections "
            f"are designed for){yard}")


def _damping(spread: dict, cases, resize: str | None) -> str:
    """The dampers' supplemental damping ratio of the first mode: achieved
    (free-vibration decay) against the target, or the energy method's
    estimate, flagged below SMALL_DAMPING with the command that sizes them."""
    ran = [c for c in cases if c.spec in spread and getattr(c, "design", None) is not None]
    if not ran:
        return ""
    drift = share(ran[0].design.roof_drift)
    target = ran[0].design.target
    if target is not None:
        got = [c.achieved for c in ran if c.achieved is not None and np.isfinite(c.achieved)]
        measured = (f"achieved {_span(got, 3)}" if got else
                    "not measured (the decay did not reach the design amplitude)")
        return (f"dampers sized for {share(target)} of critical damping in the first mode at roof drift {drift}: "
                f"{measured} (free-vibration decay)")
    xi = [c.design.damping for c in ran]
    high = max(xi)
    text = f"the dampers add {_span(xi)} of critical damping to the first mode (energy method at roof drift {drift})"
    if high < SMALL_DAMPING:
        text += (": too small to matter; size them for a target"
                 + (f": {resize}" if resize else " (frame --target-damping 0.20)"))
    return text


def _span(ratios, digits: int = 2) -> str:
    """'3.3%', or '3.3-3.5%' where the ratios differ as shown."""
    low, high = share(min(ratios), digits), share(max(ratios), digits)
    return low if low == high else f"{low[:-1]}-{high}"
