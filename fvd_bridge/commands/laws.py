"""``fvd-bridge laws``: every law with equation, parameters, units, bounds and
what it can do (state, device kind, export targets), read from the registry."""

from __future__ import annotations

from ..laws import LAWS, PAPER_SPEC

EXAMPLE = {"F": 300.0, "v": 500.0, "d": 40.0}


def add_parser(sub):
    p = sub.add_parser("laws", help="list the FVD laws: equation, parameters, units, bounds, export targets",
                       description=f"The FVD laws: the paper's nine ({PAPER_SPEC}) and the others declared "
                                   "in the registry, each with its equation, source, parameters with units, "
                                   "the paper's Table 4 bounds (a literature default for the others), the 'auto' "
                                   "bounds derived from a record, and its OpenSees and FMU targets.")
    p.add_argument("--markdown", action="store_true",
                   help="print the table of laws as Markdown (the README's, generated from the registry)")
    p.set_defaults(func=run)


def targets(law) -> str:
    """'OpenSees: Viscous C alpha (exact); FMU' from the law's declarations."""
    form = law.opensees
    ops = f"OpenSees: {form.materials} ({form.accuracy})" if form else "OpenSees: none"
    return f"{ops}; FMU: {'yes' if law.fmu else 'no'}"


def markdown_table() -> str:
    """The laws as a Markdown table: number and name, equation, state,
    OpenSees materials and kind, FMU (the README's table of laws)."""
    def cell(text):
        return str(text).replace("|", "\\|")

    rows = ["| law | equation | state | OpenSees | FMU |", "|---|---|---|---|---|"]
    for law in LAWS.values():
        form = law.opensees
        ops = f"`{form.materials}` ({form.accuracy})" if form else "none"
        rows.append(f"| {law.number} {cell(law.name)} | {cell(law.equation)} | {', '.join(law.state) or '-'} "
                    f"| {cell(ops)} | {'yes' if law.fmu else 'no'} |")
    return "\n".join(rows)


def run(args) -> int:
    if args.markdown:
        print(markdown_table())
        return 0
    print("auto bounds shown for a record with peak F 300 kN, v 500 mm/s, d 40 mm\n")
    for law in LAWS.values():
        state = f", state {', '.join(law.state)}" if law.state else ""
        paper = "" if law.paper else ", not in the paper"
        print(f"law {law.number}: {law.name} ({law.kind}{state}; {law.device} device{paper})")
        print(f"  {law.equation}")
        print(f"  source: {law.source}")
        if law.note:
            print(f"  note: {law.note}")
        print(f"  exports: {targets(law)}")
        auto = law.bounds("auto", EXAMPLE)
        for par, (lo, hi) in zip(law.parameters, auto):
            print(f"  {par.name:<6} [{par.unit}]  paper [{par.paper[0]:g}, {par.paper[1]:g}]  "
                  f"auto [{lo:.4g}, {hi:.4g}]  {par.description}")
        print()
    return 0
