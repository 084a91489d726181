"""The contact gap (effect ``gap``): no force passes the clearance, for every
law.  Checked against independent time-stepping of the same physics (the
body frozen in the clearance for a viscous law; the connection's two modes,
contact and free, for the hysteretic laws 8 and 9), the dead band of zero
force after each force reversal, and nesting (g = 0 is the model without
the gap, bit for bit)."""

from __future__ import annotations

import numpy as np
import pytest

from fvd_bridge.laws import LAWS
from fvd_bridge.catalog import parse_model
from fvd_bridge.records import Record

C2, ALPHA2 = 45.4, 0.3
LAW8 = (0.25, 30.0, 0.5, 330.0)  # C, K, mu, N (the golden set): slip force 165 kN
LAW9 = (0.2, 0.15, 27.0)         # C, alpha, beta (the golden set)
G = 2.0                          # total clearance [mm]


def sine(amp=40.0, freq=0.5, n_cycles=2.0, dt=0.002) -> Record:
    """d = amp sin(w t) [mm] with exact v, a; the pin starts centred, moving."""
    t = np.arange(int(round(n_cycles / freq / dt)) + 1) * dt
    w = 2 * np.pi * freq
    d, v, a = amp * np.sin(w * t), amp * w * np.cos(w * t), -amp * w * w * np.sin(w * t)
    return Record(t, d, np.sign(v), v, a, name="sine")


def force(spec, rec, **named):
    m = parse_model(spec)
    law = {"2": (C2, ALPHA2), "8": LAW8, "9": LAW9}[spec.split("+")[0]]
    p = list(law) + [named[n] for n in m.names[len(law):]]
    return m.force(rec, np.array([p]))[0]


# ------------------------------------------------ independent time-stepping
def viscous_by_hand(rec, g, fine=50):
    """Law 2 with a contact gap on a `fine`x finer analytic path: the body is
    frozen in the clearance (the play of the pin's path, half-width g/2) and
    carries C sign(v)|v|^alpha in contact, while the pin pushes it."""
    tf = np.linspace(0, rec.t[-1], (rec.n - 1) * fine + 1)
    w = 2 * np.pi * 0.5
    df = 40.0 * np.sin(w * tf)
    y = np.empty_like(df)
    y[0] = df[0]
    for k in range(1, df.size):
        y[k] = min(max(y[k - 1], df[k] - g / 2), df[k] + g / 2)
    y = y[::fine]
    pushing = (np.abs(rec.d - y) >= g / 2 - 1e-9) & (np.sign(rec.v) == np.sign(rec.d - y))
    u = np.where(pushing, rec.v, 0.0)
    return C2 * np.sign(u) * np.abs(u) ** ALPHA2


def hysteretic_by_hand(law, rec, g, Kp=0.0, F0=0.0, Ks=None, fine=20):
    """Laws 8 and 9 (F_el = b z + C u + Kp x + F0) behind a contact gap of
    clearance g, by classical RK4 on a `fine`x finer grid of the analytic
    motion d = 40 sin(pi t) [mm].

    Rigid contact (Ks None): two modes.  In contact on side s the body
    follows the pin, x = d - s g/2, u = v, until s F_el <= 0 (the force would
    reverse); free, F_el(x, z, u) = 0 gives u = -(b z + Kp x + F0) / C, until
    |d - x| reaches g/2.  With a series spring Ks the dead-zone spring is an
    ordinary ODE: C u = Ks dz(d - x, g/2) - (b z + Kp x + F0).  Law 9:
    z' = u - alpha |u| z (b = beta); law 8: z' = K/(mu N) u with z held in
    [-1, 1] (b = mu N)."""
    if law == 9:
        C, alpha, b = LAW9
        rate = lambda z, u: u - alpha * abs(u) * z  # noqa: E731
    else:
        C, K, mu, N = LAW8
        b, kz = mu * N, K / (mu * N)
        rate = lambda z, u: 0.0 if (z >= 1.0 and u > 0) or (z <= -1.0 and u < 0) else kz * u  # noqa: E731
    h = 0.5 * g
    w = np.pi * 0.5 * 2  # 0.5 Hz
    pin = lambda t: (40.0 * np.sin(w * t), 40.0 * w * np.cos(w * t))  # noqa: E731

    def dz(s):
        return s - h if s > h else (s + h if s < -h else 0.0)

    def rhs(t, x, z, side):
        d, v = pin(t)
        if Ks is not None:
            u = (Ks * dz(d - x) - b * z - Kp * x - F0) / C
        elif side != 0:
            u = v
        else:
            u = -(b * z + Kp * x + F0) / C
        return u, rate(z, u)

    dt = rec.dt / fine
    x, z, side = 0.0, 0.0, 0
    F = np.zeros(rec.n)
    for k in range(1, rec.n):
        for j in range(fine):
            t = rec.t[k - 1] + j * dt
            k1 = rhs(t, x, z, side)
            k2 = rhs(t + dt / 2, x + dt / 2 * k1[0], z + dt / 2 * k1[1], side)
            k3 = rhs(t + dt / 2, x + dt / 2 * k2[0], z + dt / 2 * k2[1], side)
            k4 = rhs(t + dt, x + dt * k3[0], z + dt * k3[1], side)
            x += dt / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
            z += dt / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])
            if law == 8:
                z = min(max(z, -1.0), 1.0)
            d, v = pin(t + dt)
            if Ks is None:
                if side != 0:
                    x = d - side * h  # exact kinematics in contact
                    if side * (b * z + C * v + Kp * x + F0) <= 0.0:
                        side = 0
                elif abs(d - x) >= h:
                    side = 1 if d - x > 0 else -1
                    x = d - side * h
        d, v = pin(rec.t[k])
        if Ks is not None:
            F[k] = Ks * dz(d - x)
        elif side != 0:
            F[k] = b * z + C * v + Kp * x + F0
    return F


def dead_bands(F, d, tol):
    """Pin travel [mm] over each run of |F| <= tol after a force reversal
    (from the last sample of one sign to the first of the other)."""
    zero = np.abs(F) <= tol
    out = []
    k = int(np.argmax(~zero))  # past the start (the pin starts centred)
    while k < F.size:
        if not zero[k]:
            k += 1
            continue
        start = k - 1
        while k < F.size and zero[k]:
            k += 1
        if k < F.size and np.sign(F[start]) != np.sign(F[k]):
            out.append(abs(d[k] - d[start]))
    return np.array(out)


# ------------------------------------------------------------------ law 2
def test_viscous_law_holds_still_in_the_clearance():
    """Law 2: zero force in the clearance after each reversal, the law of the
    pin's velocity in contact (the body follows the pin)."""
    rec = sine(dt=0.002)
    F = force("2+gap", rec, **{"gap.g": G})
    Fref = viscous_by_hand(rec, G)
    peak = np.abs(Fref).max()
    assert 0.05 < np.mean(F == 0.0) < 0.2  # the dead bands
    differ = (F == 0.0) != (Fref == 0.0)
    assert np.all(np.abs(rec.v[differ]) < 1e-9)  # the same samples, but for the reversals themselves
    assert np.max(np.abs(F - Fref)) < 1e-4 * peak
    assert np.mean(np.abs(F - Fref)) < 1e-6 * peak


# ------------------------------------------------------------------ laws 8, 9
CASES = {
    "gap": {},
    "series_stiffness": {"series_stiffness.Ks": 50.0},
    "parallel_stiffness": {"parallel_stiffness.Kp": 1.0, "parallel_stiffness.F0": 3.0},
}


@pytest.mark.parametrize("law", [8, 9])
@pytest.mark.parametrize("extra", list(CASES))
def test_hysteretic_laws_carry_no_force_in_the_clearance(law, extra):
    """A 2 mm gap under 40 mm at 0.5 Hz: |F| < 1e-6 of the peak over a dead
    band of pin travel about g after each force reversal; elsewhere the
    force of the same physics stepped independently (hysteretic_by_hand)."""
    rec = sine()
    spec = f"{law}+gap" + ("" if extra == "gap" else f"+{extra}")
    named = {"gap.g": G, **CASES[extra]}
    F = force(spec, rec, **named)
    Fref = hysteretic_by_hand(law, rec, G, Kp=named.get("parallel_stiffness.Kp", 0.0),
                              F0=named.get("parallel_stiffness.F0", 0.0), Ks=named.get("series_stiffness.Ks"))
    peak = np.abs(F).max()
    bands = dead_bands(F, rec.d, 1e-6 * peak)
    ref = dead_bands(Fref, rec.d, 1e-6 * peak)
    assert bands.size == ref.size >= 3  # every reversal of the force, after the first
    assert np.max(np.abs(bands - ref)) < 0.15  # mm: about a sample's travel
    if extra == "gap":  # the clearance, and the law's own travel while it unloads
        assert np.all((bands > G) & (bands < 1.4 * G)), bands
    assert np.mean(np.abs(F - Fref)) < 2e-4 * peak
    assert np.median(np.abs(F - Fref)) < 1e-5 * peak


@pytest.mark.parametrize("law", [8, 9])
def test_outside_the_clearance_the_loop_is_the_laws(law):
    """Far from the dead bands (past the mid-stroke, the law's state has
    saturated again) the force is the law's at the same pin velocity."""
    rec = sine()
    F = force(f"{law}+gap", rec, **{"gap.g": G})
    F0 = LAWS[law].force(rec.d, rec.v, rec.dt, np.array([LAW8 if law == 8 else LAW9]))[0]
    late = (rec.t > 1.0) & (np.abs(rec.d) > 30.0) & (np.sign(rec.d) == np.sign(rec.v))
    assert np.max(np.abs(F - F0)[late]) < 1e-3 * np.abs(F0).max()


@pytest.mark.parametrize("spec, base, extra", [
    ("2+gap", "2", []), ("8+gap", "8", []), ("9+gap", "9", []),
    ("9+gap+series_stiffness", "9+series_stiffness", [50.0]),
    ("8+parallel_stiffness+gap", "8+parallel_stiffness", [1.0, 3.0]),
    ("9+gap+friction+parallel_stiffness+inertia", "9+friction+parallel_stiffness+inertia", [5.0, 1.0, 3.0, 500.0]),
])
def test_a_closed_gap_is_the_model_without_it_bit_for_bit(spec, base, extra):
    rec = sine(n_cycles=1.0)
    m, mb = parse_model(spec), parse_model(base)
    law = list(LAW8 if spec[0] == "8" else (LAW9 if spec[0] == "9" else (C2, ALPHA2)))
    pb = np.array([law + extra])
    p = np.insert(pb, m.names.index("gap.g"), 0.0, axis=1)
    assert np.array_equal(m.force(rec, p), mb.force(rec, pb))
    # in a population too, next to rows with a gap
    p2 = np.vstack([p, p])
    p2[1, m.names.index("gap.g")] = G
    F2 = m.force(rec, p2)
    assert np.array_equal(F2[0], mb.force(rec, pb)[0]) and not np.array_equal(F2[1], F2[0])


def test_contributions_behind_a_gap_sum_to_the_force():
    """The accumulator is behind the clearance: in it, its force and the
    law's cancel (no force passes), and the parts still sum to F."""
    from fvd_bridge.effects.compose import contributions

    rec = sine(n_cycles=1.0)
    m = parse_model("9+gap+friction+parallel_stiffness+inertia")
    p = np.array(list(LAW9) + [G, 5.0, 1.0, 3.0, 500.0])
    parts = contributions(m, rec, p)
    assert set(parts) == {"law", "friction", "parallel_stiffness", "inertia"}
    F = m.force(rec, p[None, :])[0]
    np.testing.assert_allclose(sum(parts.values()), F, atol=1e-8)
    inside = (F - parts["inertia"]) == 0.0
    assert inside.sum() > 10 and np.abs(parts["parallel_stiffness"][inside]).max() > 1.0
    np.testing.assert_array_equal(parts["inertia"], 500.0 * 1e-6 * rec.a)  # the mass moves with the pin


def test_gap_figure(tmp_path, capsys):
    from fvd_bridge import cli

    out = tmp_path / "gap.png"
    assert cli.main(["effects", "--gap-figure", str(out)]) == 0
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and "wrote" in capsys.readouterr().out
    assert cli.main(["effects", "--gap-figure", str(tmp_path / "none" / "gap.png")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "does not exist" in err
