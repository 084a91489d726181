"""``fvd-bridge effects``: the physical effects that compose with any law."""

from __future__ import annotations

from ..catalog import catalog
from ..effects.compose import ordered
from ..io.staging import check_output

EXAMPLE = {"F": 300.0, "v": 500.0, "d": 40.0}


def add_parser(sub):
    p = sub.add_parser(
        "effects", help="list the physical effects that combine with any law (spec LAW+EFFECT+...)",
        description="Physical effects that compose with the laws: write a model as "
                    "LAW+EFFECT+EFFECT, e.g. 2+friction+series_stiffness (parameters 'effect.param'). "
                    "Composition order: series connection (gap, series spring) -> law -> asymmetry, "
                    "heating -> + friction, parallel stiffness (behind a gap), inertia.")
    p.add_argument("--plugin", action="append", default=[], metavar="FILE.py",
                   help="Python file defining extra effects (EFFECTS list; see examples/custom_effect.py)")
    p.add_argument("--gap-figure", metavar="FILE.png",
                   help="also write the force-displacement loop of law 9 with and without a 2 mm contact gap "
                        "(the dead band of zero force after each force reversal) to FILE.png")
    p.set_defaults(func=run)


def run(args) -> int:
    if args.gap_figure:  # before any output: a bad path is one line, exit 2
        check_output(args.gap_figure, "file", "--gap-figure")
    effects = ordered(catalog(args.plugin).effects.values())
    print("effects in composition order; use as LAW+EFFECT, e.g. 2+friction+series_stiffness")
    print("bounds shown for a record with peak F 300 kN, v 500 mm/s, d 40 mm; "
          "'off' = the value that switches the effect off\n")
    for e in effects:
        src = "" if e.source == "built-in" else f"  [plugin {e.source}]"
        print(f"{e.name} ({e.stage}){src}")
        print(f"  {e.summary}")
        print(f"  {e.equation}")
        for name, p, none, (lo, hi) in zip(e.names, e.parameters, e.none, e.bounds(EXAMPLE)):
            off = f"{min(max(none, lo), hi):.4g}" + (" (rigid)" if none == float("inf") else "")
            print(f"  {name:<24} [{p.unit}]  bounds [{lo:.4g}, {hi:.4g}]{' log' if p.log else ''}"
                  f"  off {off}  {p.description}")
        print(f"  looks like: {e.symptom}")
        ops = f"{e.opensees.materials} ({e.opensees.accuracy})" if e.opensees else f"none: {e.no_opensees or 'no form'}"
        print(f"  exports: OpenSees: {ops}; FMU: {'yes' if e.fmu else 'no'}")
        print()
    if args.gap_figure:
        from ..plots.effects import gap_figure

        print(f"wrote {gap_figure(args.gap_figure)}")
    return 0
