"""``fvd-bridge laws``: the nine laws with equation, parameters, units and bounds."""

from __future__ import annotations

from ..laws import LAWS


def add_parser(sub):
    p = sub.add_parser("laws", help="list the nine FVD laws: equation, parameters, units, paper bounds",
                       description="The nine FVD laws of the paper: equation, source, parameters with units, "
                                   "the paper's Table 4 bounds and the 'auto' bounds derived from a record.")
    p.set_defaults(func=run)


def run(args) -> int:
    example = {"F": 300.0, "v": 500.0, "d": 40.0}
    print("auto bounds shown for a record with peak F 300 kN, v 500 mm/s, d 40 mm\n")
    for law in LAWS.values():
        print(f"law {law.number}: {law.name} ({law.kind})")
        print(f"  {law.equation}")
        print(f"  source: {law.source}")
        if law.note:
            print(f"  note: {law.note}")
        auto = law.bounds("auto", example)
        for par, (lo, hi) in zip(law.parameters, auto):
            print(f"  {par.name:<6} [{par.unit}]  paper [{par.paper[0]:g}, {par.paper[1]:g}]  "
                  f"auto [{lo:.4g}, {hi:.4g}]  {par.description}")
        print()
    return 0
