"""Text reports of a diagnosis and of the ladder."""

from __future__ import annotations

from ..diagnose.agree import MOST
from ..diagnose.where import summary_lines
from ..errors import command, repeated, words
from ..fit import mean_abs_noise
from ..model import EXPORT_TARGETS

#: how many helpful candidates get their one-line physical explanation
EXPLAIN_TOP = 3


def _params(fit) -> str:
    """'C = 45.06 kN/(mm/s)^alpha, alpha = 0.3 -': a fit's estimates with their units."""
    return ", ".join(f"{p.name} = {p.value:.4g} {p.unit}" for p in fit.params.values())


def _targets(exports: dict) -> str:
    """'OpenSees, FMU, SAP2000, ETABS' or 'OpenSees, FMU (SAP2000, ETABS: effect ...)'."""
    ok = [EXPORT_TARGETS[t] for t, why in exports.items() if not why]
    why_not = {}  # one reason may keep several targets out
    for t, why in exports.items():
        if why:
            why_not.setdefault(why, []).append(EXPORT_TARGETS[t])
    no = [f"{', '.join(names)}: {why}" for why, names in why_not.items()]
    return ", ".join(ok) + (f" (not {'; '.join(no)})" if no else "") if ok else "none (" + "; ".join(no) + ")"


def format_diagnosis(diag, record_label: str | None = None, next_lines: list | None = None) -> str:
    """The short text summary: fit, where it fails, candidates, verdict;
    ``next_lines``: the commands to run next (default: diagnose the best
    candidate on ``record_label``)."""
    n = diag.noise
    lines = [f"diagnose {record_label or diag.record} with model {diag.spec}: OF {diag.of:.4g} "
             f"({diag.of / diag.floor:.1f}x the noise floor {diag.floor:.4g})" if diag.floor > 0 else
             f"diagnose {record_label or diag.record} with model {diag.spec}: OF {diag.of:.4g}",
             f"noise floor: force noise {diag.noise_std:.3g} kN alone gives {n.force_floor:.4g}; "
             f"with displacement noise {n.sigma_d:.3g} mm (velocity noise "
             f"{n.sigma_v:.3g} mm/s) through the model: {diag.floor:.4g}",
             f"parameters: {_params(diag.fit)}"]
    if diag.tests:
        lines.append(f"tests of device {diag.record} (fitted together"
                     + (f", {', '.join(diag.per_test)} per test" if diag.per_test else "")
                     + f"; the residual below is of {diag.focus.name}, where the model fails most): "
                     + ", ".join(f"{name} OF {of:.4g}" for name, of in diag.tests))
    if len(diag.base_history) > 1:
        lines.append("base fit: " + "; ".join(f"{how} OF {of:.5g}" for how, of in diag.base_history))
    if diag.parent is not None:
        pspec, pof = diag.parent.spec, diag.parent.of
        lines.append(f"error fell from OF {pof:.4g} ({pspec}) to {diag.of:.4g}: "
                     f"{(pof - diag.of) / pof:.0%} lower" if pof > diag.of else
                     f"no gain over {pspec} (OF {pof:.4g})")
    for name, side in diag.on_bound():
        rigid = name.endswith(".Ks") and side == "upper"
        lines.append(f"  note: {name} ended on its {side} bound" + (" (a rigid connection)" if rigid else ""))
    floor_kN = mean_abs_noise(diag.noise_std)
    lines.append("")
    lines.append("where the model fails (residual r = measured - model):")
    lines += [f"  {s}" for s in summary_lines(diag.where, floor_kN)]
    lines += _agreement_lines(diag)
    if diag.candidates:
        held = ("hold on each test left out, predicting none worse than the base" if len(diag.tests) > 1
                else "hold on held-out cycles")
        lines.append("")
        lines.append(f"candidate effects (each added to {diag.spec} and refitted; "
                     f"a gain must exceed {diag.judge.margin:.2g} in OF, lower the BIC, be of a size the record "
                     f"resolves and a device could have, and {held}):")
        lines.append(f"  {'rank':<5}{'effect':<21}{'OF':>9}{'gain':>8}  verdict")
        for k, c in enumerate(diag.candidates, 1):
            lines.append(f"  {k:<5}{c.effect:<21}{c.of:>9.4g}{max(c.improvement, 0.0):>8.1%}  {c.reason}")
            if c.replaces:
                lines.append(f"  {'':<26}{'':>8}{'':>8}  in place of {c.replaces} (the same spring, arranged "
                             f"otherwise)")
            if c.size is not None:
                lines.append(f"  {'':<26}{'':>8}{'':>8}  fitted: {c.size.text}")
            for note in c.on_cap:
                lines.append(f"  {'':<26}{'':>8}{'':>8}  note: {note}")
    if diag.zero is not None:
        lines.append("")
        lines += diag.zero.lines()
    lines.append("")
    if diag.target_refusal():
        lines.append(f"note: {diag.spec} itself does not reach {EXPORT_TARGETS[diag.target]}: "
                     f"{diag.target_refusal()}")
    if diag.advice is not None:
        lines.append(f"suggestion: {diag.verdict()}")
        again = _again(record_label, diag.spec, diag.record, (*diag.per_test, diag.advice.name))
        for line in next_lines or [again]:
            lines.append(f"next: {line}")
    elif diag.best is None:
        lines.append(diag.verdict())
    else:
        for k, c in enumerate(diag.suggestions[:EXPLAIN_TOP]):
            lead = "suggestion:" if k == 0 else "       also:"
            lines.append(f"{lead} {c.explanation} (OF {diag.of:.4g} -> {c.of:.4g}, {c.improvement:.0%} lower"
                         f"{diag.held_out_scope})")
            lines.append(f"{'':<12} exports to: {_targets(c.exports)}")
        lines += _left_out(diag)
        for line in next_lines or [_again(record_label, diag.best.spec)]:
            lines.append(f"next: {line}")
    return "\n".join(lines)


def _left_out(diag) -> list[str]:
    """What the target leaves out: the best credited candidate, when it
    does not reach the target, with what it would add."""
    c = diag.left_out
    if c is None:
        return []
    return [f"{'':<12} left out: {c.spec} (OF {c.of:.4g}, {c.improvement:.0%} below the base) would add "
            f"{c.effect} but does not reach {EXPORT_TARGETS[diag.target]}: {c.exports[diag.target]}"]


def _again(label: str | None, spec: str, device: str | None = None, per_test=()) -> str:
    """The diagnosis to run next, as the caller runs it: a command line, or the Python call."""
    if words() == "api":
        args = ["records", repr(spec)] + ([f"device={device!r}"] if device else []) + (
            [repeated("--per-test", per_test)] if per_test else [])
        return f"{command('diagnose')[:-1]}{', '.join(args)})"
    device = [f"--device {device}"] if device else []
    return " ".join([command("diagnose"), label or "RECORD", *device, f"--law {spec}",
                     *([repeated("--per-test", per_test)] if per_test else [])])


def _agreement_lines(diag) -> list[str]:
    """The per-test check (``agree.py``): each law parameter freed per test."""
    a = diag.agreement
    if a is None or not a.params:
        return []
    lines = ["", f"do the tests agree? (each law parameter freed per test, refitted from {diag.spec}; fitting "
                 f"each test on its own reaches OF {a.own_of:.4g}; a parameter must help beyond noise, explain "
                 f"at least {MOST:.0%} of that and more than any credited effect):",
             f"  {'parameter':<26}{'OF':>9}{'gain':>8}  verdict"]
    for p in a.params:
        lines.append(f"  {p.name + ' per test':<26}{p.of:>9.4g}{max(p.improvement, 0.0):>8.1%}  {p.reason}")
        lines.append(f"  {'':<26}{'':>9}{'':>8}  fitted: {p.name} {p.text()}")
    return lines


def format_ladder(lad) -> str:
    """The ladder as a table: model, OF, improvement, parameters."""
    lines = ["ladder (each rung adds the effect that helps most beyond noise):",
             f"  {'model':<50}{'OF':>9}{'gain':>8}  parameters"]
    for r in lad.rungs:
        gain = "" if r.improvement is None else f"{r.improvement:.1%}"
        params = ", ".join(f"{n} = {v:.4g}" for n, v in r.params.items())
        lines.append(f"  {r.spec:<50}{r.of:>9.4g}{gain:>8}  {params}")
    lines.append(f"noise floor OF {lad.final.floor:.4g}; stopped: {lad.stop}")
    for r in lad.rungs[1:]:
        lines.append(f"  {r.added}: {r.explanation}")
    return "\n".join(lines)
