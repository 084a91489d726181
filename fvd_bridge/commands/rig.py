"""``fvd-bridge rig``: simulate virtual dampers and write lab-like records plus truth.yaml."""

from __future__ import annotations

import math

from ..errors import InputError
from ..io.staging import check_output
from ..rig import (DEMO_NOISE, DEMO_SCATTER, PARAMETERS, VirtualDamper, Noise, demo_series, from_spec, production_series,
                   write_series)
from ..rig.device import ARRANGEMENTS
from ..rig.simulate import DISPLACEMENT_NOISE

#: CLI flag -> VirtualDamper field
FLAGS = {"C": "C", "alpha": "alpha", "Ks": "Ks", "friction": "friction", "v_friction": "v_friction",
         "heating": "heating", "gap": "gap", "asymmetry": "asymmetry", "Kp": "Kp",
         "preload": "preload", "mass": "mass"}


def add_parser(sub):
    p = sub.add_parser(
        "rig", help="simulate virtual dampers: lab-like CSV records plus truth.yaml",
        description="Simulate virtual fluid-viscous dampers with known physics (orifice C sign(v)|v|^alpha, "
                    "series stiffness, seal friction, heating, pin gap, asymmetry, accumulator, mass) "
                    "under a test protocol; write one CSV (t,d,F in s, mm, kN) with its unit sidecar per "
                    "device and truth.yaml.")
    p.add_argument("--out", required=True, metavar="DIR", help="output directory")
    p.add_argument("--devices", metavar="N", help="number of devices (default 1; 5 with --demo)")
    p.add_argument("--protocol", default="paper", metavar="SPEC",
                   help="paper (10 cycles of 40 mm at 500 mm/s, dt 0.002 s), acceptance (3 cycles at "
                        "1, 25, 50, 75, 100%% of 500 mm/s at 20 mm) or history:FILE.csv (columns t,d)")
    p.add_argument("--seed", default="0", metavar="N", help="seed of scatter and noise (default 0)")
    p.add_argument("--noise", metavar="KN", help="force noise standard deviation [kN] (default 0; 1 with --demo)")
    p.add_argument("--disp-noise", metavar="MM",
                   help=f"displacement noise standard deviation [mm] (default {DISPLACEMENT_NOISE:g}, as a lab "
                        f"record has; 0 for an exact displacement)")
    p.add_argument("--demo", action="store_true",
                   help="five devices like the paper's (300 kN class, loads +-260..330 kN) with realistic "
                        "effects and noise")
    g = p.add_argument_group("device parameters (nominal; kN, mm, s, kg)")
    g.add_argument("--C", metavar="X", help="orifice coefficient [kN/(mm/s)^alpha] (default 45.4)")
    g.add_argument("--alpha", metavar="X", help="orifice exponent, 0 < alpha <= 2 (default 0.3)")
    g.add_argument("--Ks", metavar="X", help="series stiffness [kN/mm]; none or inf = rigid (default)")
    g.add_argument("--friction", metavar="X", help="seal friction [kN] (default 0)")
    g.add_argument("--v-friction", dest="v_friction", metavar="X",
                   help="friction smoothing velocity [mm/s] (default 1)")
    g.add_argument("--heating", metavar="X", help="heating coefficient theta [1/MJ]: force x exp(-theta E) "
                                                  "(default 0)")
    g.add_argument("--gap", metavar="X", help="total pin clearance [mm] (default 0)")
    g.add_argument("--asymmetry", metavar="X", help="tension/compression asymmetry r, |r| < 1 (default 0)")
    g.add_argument("--Kp", metavar="X", help="accumulator stiffness [kN/mm] (default 0)")
    g.add_argument("--preload", metavar="X", help="accumulator preload [kN] (default 0)")
    g.add_argument("--mass", metavar="X", help="moving mass [kg] (default 0)")
    g.add_argument("--arrangement", choices=ARRANGEMENTS,
                   help="where Ks sits: 'connection' (a flexible connection outside the damper, the seal and "
                        "accumulator behind it; default) or 'oil_column' (the compressible oil inside it, the "
                        "seal and accumulator on the rod beside it)")
    g.add_argument("--scatter", metavar="S",
                   help="manufacturing scatter: one relative std for every parameter (e.g. 0.05) "
                        "or per parameter (e.g. C=0.05,Ks=0.2)")
    q = p.add_argument_group("protocol and output")
    q.add_argument("--dt", metavar="S", help="sampling step [s] (default 0.002)")
    q.add_argument("--amplitude", metavar="MM", help="amplitude [mm] (paper 40, acceptance 20)")
    q.add_argument("--velocity", metavar="MM_S", help="peak velocity [mm/s] (paper; acceptance: Vmax) (default 500)")
    q.add_argument("--cycles", metavar="N", help="full-amplitude cycles (paper 10; acceptance 3 per level)")
    q.add_argument("--with-velocity", action="store_true", help="add the exact velocity column v [mm/s]")
    p.set_defaults(func=run)


def _float(flag: str, text) -> float:
    try:
        x = float(text)
    except (TypeError, ValueError):
        raise InputError(f"--{flag} '{text}': not a number") from None
    if math.isnan(x):
        raise InputError(f"--{flag} '{text}': not a number")
    return x


def _int(flag: str, text, low: int) -> int:
    try:
        x = int(str(text))
    except ValueError:
        raise InputError(f"--{flag} '{text}': not a whole number") from None
    if x < low:
        raise InputError(f"--{flag} {x}: must be >= {low}")
    return x


def _scatter(text) -> dict:
    if not text:
        return {}
    text = str(text).strip()
    if "=" not in text:
        s = _float("scatter", text)
        return {k: s for k in PARAMETERS if k != "v_friction"}
    out = {}
    for item in text.split(","):
        key, _, val = item.partition("=")
        out[key.strip()] = _float(f"scatter {key.strip()}", val)
    return out


def _device_args(args) -> dict:
    out = {}
    for flag, field in FLAGS.items():
        text = getattr(args, flag)
        if text is None:
            continue
        if field == "Ks" and str(text).strip().lower() in ("none", "inf", "rigid"):
            out[field] = None
        else:
            out[field] = _float(flag.replace("_", "-"), text)
    return out


def run(args) -> int:
    check_output(args.out, "dir", "--out")  # before any work: a bad path is one line, exit 2
    seed = _int("seed", args.seed, 0)
    proto_opts = {}
    for key in ("dt", "amplitude", "velocity"):
        if getattr(args, key) is not None:
            proto_opts[key] = _float(key, getattr(args, key))
    if args.cycles is not None:
        proto_opts["cycles"] = _float("cycles", args.cycles)
    protocol = from_spec(args.protocol, **proto_opts)
    params = _device_args(args)
    scatter = _scatter(args.scatter)
    if args.demo:
        if params or scatter or args.arrangement:
            given = ", ".join(f"--{k}" for k in list(params) + (["scatter"] if scatter else [])
                              + (["arrangement"] if args.arrangement else []))
            raise InputError(f"--demo sets the device parameters itself; drop {given}")
        n = _int("devices", args.devices, 1) if args.devices is not None else 5
        devices = demo_series(seed, n)
        scatter = dict(DEMO_SCATTER)
        force = DEMO_NOISE["force"] if args.noise is None else _float("noise", args.noise)
        disp = DEMO_NOISE["displacement"] if args.disp_noise is None else _float("disp-noise", args.disp_noise)
    else:
        n = _int("devices", args.devices, 1) if args.devices is not None else 1
        nominal = VirtualDamper(**params, **({"arrangement": args.arrangement} if args.arrangement else {}))
        devices = production_series(n, nominal, scatter, seed)
        force = 0.0 if args.noise is None else _float("noise", args.noise)
        disp = DISPLACEMENT_NOISE if args.disp_noise is None else _float("disp-noise", args.disp_noise)
    noise = Noise(force, disp)
    try:
        paths = write_series(args.out, devices, protocol, noise, seed=seed, with_velocity=args.with_velocity,
                             scatter=scatter, extra={"demo": bool(args.demo)})
    except OSError as exc:
        raise InputError(f"--out {args.out}: cannot write ({exc.strerror or exc})") from None
    print(f"rig: {len(devices)} device(s), protocol {protocol.name} ({protocol.n} samples, dt {protocol.dt:g} s), "
          f"noise {noise.force:g} kN / {noise.displacement:g} mm, seed {seed}")
    for path in paths:
        print(f"  wrote {path}")
    return 0
