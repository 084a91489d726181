"""Explain the misfit on a real friction damper with play: diagnose, ladder, compare.

The records are a banded rotary friction damper (about 15 kN) driven with
sinusoidal displacement at 0.5 Hz and 1 Hz, 1024 Hz sampling, from
../shared/devices (ARTS Lab, CC BY-SA 4.0; units in the YAML sidecars:
in, kip), kept at 256 Hz.  The velocity is derived by the tool from the
displacement.

1. ``diagnose`` the 0.5 Hz test with law 9 (LuGre + viscous) and law 8
   (friction + viscous) as the base: where each fails, every effect refitted,
   judged against the record's noise floor, on held-out cycles and by its
   physical size;
2. the ladder from law 9: add the effect that helps most, refit, repeat;
3. ``compare``: the models calibrated on the 0.5 Hz test, checked on the
   1 Hz test they were not fitted to.

    python examples/diagnose_friction_damper.py [--out DIR] [--quick]

Prints the reports and a summary of what was found and what is left; writes
the figures (where each model fails, the ladder, the overlaid loops) to DIR.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

import numpy as np

from fvd_bridge.diagnose import climb, diagnose, diagnose_settings
from fvd_bridge.text.diagnosis import format_diagnosis, format_ladder
from fvd_bridge.fit import objective
from fvd_bridge.records import ReadOptions, Record, read_record
from fvd_bridge.records.velocity import derive

DEVICES = Path(__file__).resolve().parents[1] / ".." / "shared" / "devices"
FIT_ON, CHECK_ON = "arts_brfd_0.5Hz_25lb.csv", "arts_brfd_1Hz_35lb.csv"
#: t, d, F only: the velocity is derived by the tool (the lab's v column is not read)
COLUMNS = ReadOptions(columns={"t": "t", "d": "d", "F": "F"})
#: keep every DECIMATE-th sample (1024 Hz -> 256 Hz: 512 samples per cycle at 0.5 Hz)
DECIMATE = 4


def read(name: str) -> Record:
    """The record at 1024 / DECIMATE Hz, its velocity derived again at that step."""
    full = read_record(str((DEVICES / name).resolve()), COLUMNS, name=name.rsplit(".", 1)[0])
    t, d, F = full.t[::DECIMATE], full.d[::DECIMATE], full.F[::DECIMATE]
    der = derive(d, float(t[1] - t[0]))
    return Record(t, d, F, der.v, der.a, name=full.name,
                  provenance=dict(full.provenance, velocity=der.settings, decimated=DECIMATE),
                  d_noise=der.d_noise, v_noise=der.v_noise, a_noise=der.a_noise)


def summary(diags: dict, lad, table: list) -> list[str]:
    lines = []
    for law, diag in diags.items():
        best = diag.best
        lines.append(f"law {law}: OF {diag.of:.4g}, {diag.of / diag.floor:.0f}x the noise floor; "
                     + (f"best supported effect: {best.effect} ({best.size.text}, OF -{best.improvement:.0%})"
                        if best else "no effect passes every test"))
        rejected = [c for c in diag.candidates if not c.significant and c.improvement > 0.05]
        for c in rejected:
            lines.append(f"  {c.effect} lowers the OF {c.improvement:.0%} but is not credited: {c.reason}")
    lines.append(f"ladder from law 9: {' -> '.join(r.spec for r in lad.rungs)} (OF {lad.rungs[-1].of:.4g}; "
                 f"{lad.stop})")
    lines.append("on the 1 Hz test: " + ", ".join(f"{spec} OF {of:.4g}" for spec, of in table))
    final = lad.final
    rv = final.where.reversal
    lines.append(f"left unexplained: OF {final.of:.4g} is {final.of / final.floor:.0f}x the floor; "
                 f"{rv.error_share:.0%} of the residual lies near the reversals ({rv.time_share:.0%} "
                 f"of the time)")
    return lines


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="diagnose_friction_out", help="directory for the figures")
    ap.add_argument("--quick", action="store_true", help="small optimizer settings (for tests)")
    args = ap.parse_args(argv)
    if not all((DEVICES / f).is_file() for f in (FIT_ON, CHECK_ON)):
        print(f"{DEVICES.resolve()} lacks the friction-damper records: this example needs ../shared",
              file=sys.stderr)
        return 0
    from fvd_bridge.plots import diagnose as figs

    settings = diagnose_settings(6, 50) if args.quick else diagnose_settings()
    os.makedirs(args.out, exist_ok=True)
    rec, other = read(FIT_ON), read(CHECK_ON)
    say = lambda m: print(m, file=sys.stderr, flush=True)  # noqa: E731
    diags = {}
    for law in ("9", "8"):
        diag = diagnose(rec, law, seed=0, settings=settings, progress=say)
        diags[law] = diag
        print(format_diagnosis(diag), "\n")
        figs.where(rec, diag, os.path.join(args.out, f"where_law{law}.png"))
    lad = climb(rec, "9", seed=0, settings=settings, max_rungs=2, progress=say)
    print(format_ladder(lad), "\n")
    figs.ladder(lad, os.path.join(args.out, "ladder_law9.png"))
    models = {d.spec: (d.model, d.fit.values) for d in list(diags.values()) + [lad.final]}
    table = []
    for spec, (model, params) in models.items():
        F = model.force(other, np.asarray(params)[None, :])[0]
        table.append((spec, float(objective(other.F, F, other.t))))
    table.sort(key=lambda row: row[1])
    print(f"calibrated on {rec.name}, checked on {other.name} (best first):")
    for spec, of in table:
        print(f"  {spec:<36} OF {of:.4g}")
    print("\nwhat was found:")
    for line in summary(diags, lad, table):
        print(f"  {line}")
    print(f"figures in {args.out}/")
    return 0


if __name__ == "__main__":
    sys.exit(main())
