"""Model = law + effects: the spec string '2+friction+series_stiffness', the
parameter vector layout (law parameters, then 'effect.param'), derived
quantities, and the operations that add or remove an effect.

A Model is the interface: no module builds or splits a spec string itself.
Models come from ``fvd_bridge.catalog`` (``parse_model(spec)`` or
``catalog(plugins).model(spec)``).  What a model can be exported to is read
from its law's and effects' declarations (``exports``, ``opensees_refusal``),
never by trying an exporter.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .effects.catalog import EFFECTS
from .effects.compose import composed_force, inside_connection
from .errors import InputError, option
from .laws import Law
from .laws.opensees_forms import NEWTON_ALPHA

#: where a model can go: {target: its name in messages}
EXPORT_TARGETS = {"opensees": "OpenSees", "fmu": "FMU", "sap2000": "SAP2000", "etabs": "ETABS"}
#: the file ``fvd-bridge export TARGET`` writes in the commands printed next
EXPORT_FILES = {"opensees": "damper.py", "fmu": "damper.fmu", "sap2000": "damper.s2k", "etabs": "damper.e2k"}


def export_target(target: str | None) -> str | None:
    """``target`` checked against EXPORT_TARGETS (None: anywhere); InputError in the caller's words."""
    if target is not None and target not in EXPORT_TARGETS:
        raise InputError(f"{option('--target', target)}: expected one of {', '.join(EXPORT_TARGETS)}")
    return target


def export_step(exports: dict, path: str, target: str | None = None) -> str:
    """The export to run next of a calibration file ``path`` whose model
    exports as ``exports`` says (``Model.exports``): to ``target``, else
    to OpenSees where it reaches it, else to an FMU ('' when it cannot go
    there)."""
    target = target or ("opensees" if not exports["opensees"] else "fmu")
    return "" if exports[target] else f"fvd-bridge export {target} {path} -o {EXPORT_FILES[target]}"


def _placement_conflict(effects) -> str:
    """Why one connection kernel cannot hold ``effects`` ('' when it can): an
    effect solved behind one of the connection effects (``inside_with``) but
    beside another (friction with a gap and an oil_column: behind the
    clearance, beside the oil column)."""
    connections = [e.name for e in effects if e.stage == "series"]
    for e in effects:
        inside = [c for c in connections if c in e.inside_with]
        if e.stage != "series" and inside and len(inside) < len(connections):
            beside = next(c for c in connections if c not in inside)
            return f"{e.name} would sit behind {inside[0]} but beside {beside}: one connection cannot hold both"
    return ""


@dataclass(frozen=True)
class Model:
    """A law with optional physical effects; ``force(record, P)`` -> (pop, n_t) [kN]."""

    law: Law
    effects: tuple = field(default_factory=tuple)

    @property
    def spec(self) -> str:
        """'2+friction': the law's number, then the effects in the order added."""
        return "+".join([self.law.key] + [e.name for e in self.effects])

    @property
    def effect_names(self) -> list[str]:
        """The effects' names, in the model's order."""
        return [e.name for e in self.effects]

    @property
    def parameters(self) -> list:
        """All parameters in vector order (law first, then each effect's)."""
        out = list(self.law.parameters)
        for e in self.effects:
            out.extend(e.parameters)
        return out

    @property
    def names(self) -> list[str]:
        """Parameter names in vector order: the law's, then 'effect.param'."""
        return self.law.names + [n for e in self.effects for n in e.names]

    def known_parameter(self, name: str, given: str) -> str:
        """``name``, a parameter of the model; else an InputError in one
        line: "{given}: model 2 has no parameter 'K' (has: C, alpha)".

        Parameters
        ----------
        name : str
            A parameter's name, e.g. 'alpha' or 'friction.Ff'.
        given : str
            The option or argument that named it, in the caller's words
            (``errors.parameter_option``).
        """
        if name not in self.names:
            raise InputError(f"{given}: model {self.spec} has no parameter '{name}' (has: {', '.join(self.names)})")
        return name

    @property
    def units(self) -> list[str]:
        """Each parameter's unit (kN, mm, s), in the model's order."""
        return [p.unit for p in self.parameters]

    def has(self, effect_name: str) -> bool:
        """Whether the model carries the named effect.

        Parameters
        ----------
        effect_name : str
            An effect's registry name, e.g. 'friction'.
        """
        return effect_name in self.effect_names

    def refusal(self, effect) -> str:
        """Why an effect cannot be added to this model ('' when it can).

        From the declarations: a law without a connection takes no series
        effect, an effect appears once, two effects cannot set the same
        connection argument, parameter names must not clash, an effect cannot
        sit behind one connection effect and beside another.

        Parameters
        ----------
        effect : Effect
            The effect to add (``catalog``'s registry entry).
        """
        if effect.stage == "series" and not self.law.connection:
            return (f"law {self.law.key} ({self.law.name}) cannot sit behind '{effect.name}' "
                    f"(its step form has no connection)")
        if self.has(effect.name):
            return f"effect '{effect.name}' appears twice"
        taken = {s for e in self.effects for s in e.slots} & set(effect.slots)
        if taken:
            return f"effect '{effect.name}' sets the connection's {sorted(taken)[0]}, which another effect sets"
        names = self.names + effect.names
        clash = sorted({n for n in names if names.count(n) > 1})
        if clash:
            return f"parameter name '{clash[0]}' clashes"
        return _placement_conflict(self.effects + (effect,))

    def with_effect(self, effect, spec_text: str | None = None) -> "Model":
        """This model plus an effect.

        Parameters
        ----------
        effect : Effect
            The effect to add; what ``refusal`` refuses raises InputError.
        spec_text : str, optional
            The spec the user wrote, quoted in that message.
        """
        why = self.refusal(effect)
        if why:
            raise InputError(f"model '{spec_text or f'{self.spec}+{effect.name}'}': {why}")
        return Model(self.law, self.effects + (effect,))

    @property
    def global_search(self) -> bool:
        """Its law or an effect declares basins that a local solve does not
        leave: the default optimizer searches it with DE."""
        return self.law.global_search or any(e.global_search for e in self.effects)

    @property
    def stepped(self) -> list[str]:
        """Names of the parameters on which the OF moves in steps (``Effect.stepped``)."""
        return [f"{e.name}.{p}" for e in self.effects for p in e.stepped]

    def without_effect(self, effect_name: str) -> "Model":
        """This model without the named effect (the nested model).

        Parameters
        ----------
        effect_name : str
            An effect the model carries (InputError otherwise).
        """
        if not self.has(effect_name):
            raise InputError(f"model '{self.spec}' has no effect '{effect_name}'")
        return Model(self.law, tuple(e for e in self.effects if e.name != effect_name))

    def columns_without(self, effect_name: str) -> list[int]:
        """Indices of the parameter vector that remain without the named effect.

        Parameters
        ----------
        effect_name : str
            An effect the model carries.
        """
        drop = set(next(e for e in self.effects if e.name == effect_name).names)
        return [k for k, n in enumerate(self.names) if n not in drop]

    def split(self, P: np.ndarray) -> tuple[np.ndarray, dict]:
        """The law's columns and each effect's of a parameter population.

        Parameters
        ----------
        P : numpy.ndarray
            (pop, n_par) parameter rows in the model's order.

        Returns
        -------
        tuple
            The law's parameters (pop, n_law) and {effect name: (pop, n_e)}.
        """
        j = len(self.law.parameters)
        out = {}
        for e in self.effects:
            k = len(e.parameters)
            out[e.name] = P[:, j:j + k]
            j += k
        return P[:, :len(self.law.parameters)], out

    def derived(self, params) -> dict:
        """Derived quantities of one parameter vector (law 8: mu*N [kN]).

        Parameters
        ----------
        params : array_like
            The model's parameter vector.

        Returns
        -------
        dict
            {name: (value, unit)}.
        """
        p = np.asarray(params, dtype=float)[:len(self.law.parameters)]
        return {d.name: (float(d.value(p)), d.unit) for d in self.law.derived}

    def bounds(self, mode: str, scales: dict) -> np.ndarray:
        """The search bounds, (n_par, 2).

        Parameters
        ----------
        mode : str
            'auto' (bounds scaled to the record) or 'paper' (Table 2's);
            effects use their own bounds in both modes.
        scales : dict
            The record's scales (``Record.scales``: peak d, v, F).
        """
        rows = [self.law.bounds(mode, scales)]
        rows += [e.bounds(scales) for e in self.effects]
        return np.vstack(rows)

    def off_values(self) -> list:
        """Per parameter: the value that switches its effect off (None for law parameters)."""
        return [None] * len(self.law.parameters) + [v for e in self.effects for v in e.none]

    def log_scale(self, mode: str) -> np.ndarray:
        """Which parameters the default optimizer searches on a log scale.

        Parameters
        ----------
        mode : str
            'auto' (log where declared) or 'paper' (none).
        """
        return np.array([p.log and mode == "auto" for p in self.parameters])

    def force(self, record, P: np.ndarray, substeps: int = 1) -> np.ndarray:
        """Model force [kN] for each parameter row.

        Parameters
        ----------
        record : Record
            The motion: d [mm], v [mm/s], dt [s].
        P : array_like
            (pop, n_par) parameter rows in the model's order (one row: (n_par,)).
        substeps : int
            Integration sub-steps per sample (differential laws).

        Returns
        -------
        numpy.ndarray
            (pop, n_t) forces [kN].
        """
        P = np.atleast_2d(np.asarray(P, dtype=float))
        if P.shape[1] != len(self.names):
            raise InputError(f"model {self.spec}: expected {len(self.names)} parameters "
                             f"({', '.join(self.names)}), got {P.shape[1]}")
        if not self.effects:
            return self.law.force(record.d, record.v, record.dt, P, substeps)
        return composed_force(self, record, P, substeps)

    def active_effects(self, params: dict | None = None) -> list:
        """The effects not switched off by a parameter set.

        Parameters
        ----------
        params : dict, optional
            {name: value}; None: every effect.
        """
        if params is None:
            return list(self.effects)
        return [e for e in self.effects
                if not e.off(np.array([[float(params[n]) for n in e.names]]))[0]]

    def opensees_refusal(self, params: dict | None = None) -> str:
        """Why OpenSees cannot express this model ('' when it can).

        From the law's and effects' OpenSees forms.

        Parameters
        ----------
        params : dict, optional
            {name: value}: effects at their 'off' values are left out and the
            law's form may refuse parameter values (law 7 with beta != 1).
        """
        law, form = self.law, self.law.opensees
        if form is None:
            return f"law {law.key} ({law.name})"
        if refused := self._values_refused(params):
            return refused
        active = self.active_effects(params)
        inside = inside_connection(Model(law, tuple(active)))
        series = [e for e in active if e.stage == "series"]
        two = bool(series) and form.series is None  # the connection and the law as two materials in series
        if two and form.exponent and params is not None and float(params[form.exponent]) < NEWTON_ALPHA:
            return (f"law {law.key} with {form.exponent} = {float(params[form.exponent]):.3g} behind {series[0].name} "
                    f"(the law goes behind it as a second material, and its Viscous dashpot with an exponent below "
                    f"{NEWTON_ALPHA:g} defeats Newton at the node between them)")
        for e in active:
            if e.opensees is None:
                return e.no_opensees or f"effect '{e.name}' ({e.source})"
            if two and e.stage != "series" and e.name not in inside:
                return (f"{e.name} beside the connection (law {law.key} goes behind it as a second material, "
                        f"which holds the effects inside the connection only)")
            if series and not two and e.stage != "series" and e.name in inside:
                beside = [x.name for x in EFFECTS.values() if x.arrangement_of in {c.name for c in series}]
                where = "the pin gap" if "gap" in {c.name for c in series} else "the series spring"
                return f"{e.name} inside {where}" + (f" (beside it: {beside[0]})" if beside else "")
            if e.opensees.needs_stateless and not form.stateless:
                return f"{e.name} of law {law.key} (TensionOnly loses its state in compression)"
        return ""

    def _values_refused(self, params: dict | None) -> str:
        """Why the law's parameter values cannot be exported ('' when they can;
        its OpenSees form's ``refuse``, which the CSI links share: law 7 with beta != 1)."""
        form = self.law.opensees
        if params is None or form is None or form.refuse is None:
            return ""
        return form.refuse({n: float(params[n]) for n in self.law.names})

    def fmu_refusal(self) -> str:
        """Why the FMU cannot carry this model ('' when it can)."""
        if not self.law.fmu:
            return f"law {self.law.key} ({self.law.name}) cannot go into the FMU (no C step form)"
        missing = [e for e in self.effects if not e.fmu]
        return (f"effect '{missing[0].name}' ({missing[0].source}) cannot go into the FMU (no C step form)"
                if missing else "")

    def csi_refusal(self, params: dict | None = None) -> str:
        """Why no CSI (SAP2000, ETABS) damper link expresses this model ('' when one does).

        A link is the law's ``csi`` type (a spring in series with the
        dashpot), so a series spring is the only effect it takes.

        Parameters
        ----------
        params : dict, optional
            {name: value}, as for ``opensees_refusal``.
        """
        law = self.law
        if not law.csi:
            return f"law {law.key} ({law.name})"
        if refused := self._values_refused(params):
            return refused
        other = [e.name for e in self.active_effects(params) if not (e.stage == "series" and e.slots == ("Ks",))]
        return (f"effect '{other[0]}' (a CSI {law.csi} link is a spring in series with the dashpot, nothing else)"
                if other else "")

    def exports(self, params: dict | None = None) -> dict:
        """Where the model exports.

        Parameters
        ----------
        params : dict, optional
            {name: value}, as for ``opensees_refusal``.

        Returns
        -------
        dict
            {target: why not ('' when it exports)} for each of EXPORT_TARGETS.
        """
        csi = self.csi_refusal(params)
        return {"opensees": self.opensees_refusal(params), "fmu": self.fmu_refusal(), "sap2000": csi, "etabs": csi}
