"""What hands a Calibration to the modules above it: its OpenSees
commands and FMU (``export``), its figure (``plots``) and a notebook's HTML
table (``report``).  Those modules import the calibration, so these
methods import them when called, here and nowhere else in ``calibration``:
the class keeps the API's one-call conveniences, the layers stay one-way."""

from __future__ import annotations

from ..errors import InputError


class Reach:
    """The Calibration's methods that reach the exporters, plots and report."""

    def _repr_html_(self) -> str:
        """The fit report as an HTML table (a notebook shows it)."""
        from ..report.html import calibration_table

        return calibration_table(self)

    def plot(self, ax=None, record=None, x: str = "d"):
        """Measured and model force of a test.

        Parameters
        ----------
        ax : matplotlib Axes, optional
            Where to draw; None: a new figure.
        record : Record, optional
            The test; default the first test fitted (a loaded calibration has none: give it).
        x : {'d', 'v', 't'}
            Against displacement, velocity or time.

        Returns
        -------
        matplotlib Axes
            The Axes drawn on, left open.
        """
        from ..plots.record import loop

        if record is None and not self.records:
            raise InputError("Calibration.plot: give record= (a loaded calibration keeps no record)")
        record = record if record is not None else self.records[0]
        return loop(record, self.force(record, test=self.test_named(record.name)), ax=ax, x=x,
                    title=f"{self.spec} on {record.name}")

    def solving(self, export):
        """The OpenSees export as a frame analysis runs it.

        A power-law dashpot that defeats Newton goes behind a spring that
        deflects 0.5% of the tested stroke (``export.opensees.solving_springs``).

        Parameters
        ----------
        export : Export
            The calibration's OpenSees export (``export.opensees.opensees_export``).
        """
        from ..export.opensees import solving_springs

        return solving_springs(export, self.tested.get("d"), self.tested.get("v"))

    def export_lines(self, export) -> list[str]:
        """An OpenSees script's header lines of this calibration.

        Its record, tested range and, where a frame analysis runs it
        otherwise, how.

        Parameters
        ----------
        export : Export
            The calibration's OpenSees export.
        """
        from ..export.opensees import solving_advice

        return self.provenance_lines() + solving_advice(export, self.solving(export))

    def to_opensees(self, tag: int = 1, units=None, test: str | None = None):
        """The damper as OpenSees commands.

        Parameters
        ----------
        tag : int
            The damper's uniaxial material tag.
        units : str or tuple, optional
            The OpenSees model's FORCE,LENGTH,TIME, e.g. ``"kN,m,s"`` or
            ``("kN", "m", "s")``; None: kN, mm, s.
        test : str, optional
            The test whose values a parameter fitted per test takes
            (``for_test``; required then, refused otherwise).

        Returns
        -------
        OpenSeesCommands
            A list of (ops function, *args) with ``.apply(ops)`` and
            ``.to_script('py' | 'tcl')`` (the script ``fvd-bridge export
            opensees`` writes).
        """
        from ..export.opensees import OpenSeesCommands, opensees_export

        cal = self.for_test(test)
        export = opensees_export(cal.model, cal.named(), tag, units=units, tested=cal.tested)
        return OpenSeesCommands(export, cal.export_lines(export))

    def to_fmu(self, path, h_max: float | None = None, test: str | None = None) -> str:
        """Write the damper as an FMI 3.0 co-simulation FMU (``export.fmu.build_fmu``).

        Parameters
        ----------
        path : str or path-like
            The .fmu file to write (atomically: nothing is left on failure).
        h_max : float, optional
            The largest integration sub-step [s]; default the calibration record's dt.
        test : str, optional
            The test whose values a parameter fitted per test takes
            (``for_test``; required then, refused otherwise).

        Returns
        -------
        str
            The path written.
        """
        from ..export.fmu import build_fmu

        return build_fmu(self.for_test(test), path, h_max)
