"""A damper test record: time, displacement, force, with derived velocity."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass
class Record:
    """One test of one device on a uniform time grid.

    t [s], d [mm], F [kN], v [mm/s], a [mm/s^2]; ``provenance`` says where
    each column came from (file, column mapping, source units and their
    factors, velocity method and Savitzky-Golay settings); ``warnings`` holds
    the notes the reader made (e.g. resampled time).

    Noise, for propagating it through a model: ``d_noise`` [mm] the
    displacement noise std (estimated by the reader; the rig's true value);
    ``v_noise`` [mm/s] and ``a_noise`` [mm/s^2] per-sample noise std of v
    and a (for a derived velocity: the differentiator's noise gain times
    d_noise at the window used at each sample; for a measured one: its own
    estimated noise; zero for the rig's exact v and a). None: unknown (a
    record built in code).  ``windows``: the Savitzky-Golay windows
    [samples] that made v and a at each sample, (v_window, a_window), for
    a velocity derived from d (None otherwise): the bootstrap differentiates
    its replicates with them (``fit.intervals``).
    """

    t: np.ndarray
    d: np.ndarray
    F: np.ndarray
    v: np.ndarray
    a: np.ndarray
    name: str = "record"
    provenance: dict = field(default_factory=dict)
    warnings: list = field(default_factory=list)
    d_noise: float | None = None
    v_noise: np.ndarray | None = None
    a_noise: np.ndarray | None = None
    windows: tuple | None = None

    #: units of the fields
    UNITS = {"t": "s", "d": "mm", "F": "kN", "v": "mm/s", "a": "mm/s^2"}
    #: the builder of ``from_arrays``: ``records.readers`` sets it on import (the
    #: reader sits above the record and imports it; the record never imports the reader)
    _from_arrays = None

    def __post_init__(self):
        for key in ("t", "d", "F", "v", "a"):
            setattr(self, key, np.asarray(getattr(self, key), dtype=float))
        for key in ("v_noise", "a_noise"):
            x = getattr(self, key)
            if x is not None:
                x = np.asarray(x, dtype=float)
                if x.size not in (1, self.t.size):
                    raise ValueError(f"Record '{self.name}': {key} has {x.size} values for {self.t.size} samples")
                setattr(self, key, np.broadcast_to(x.reshape(-1) if x.size > 1 else x.reshape(()), self.t.shape).copy())
        if self.d_noise is not None:
            self.d_noise = float(self.d_noise)
        sizes = {key: getattr(self, key).size for key in ("t", "d", "F", "v", "a")}
        if len(set(sizes.values())) != 1 or self.t.size < 2:
            raise ValueError(f"Record '{self.name}': fields need one common length >= 2, got {sizes}")

    @classmethod
    def from_arrays(cls, t, d, F, v=None, units=None, name: str = "record") -> "Record":
        """A record from arrays, read as a file is (``records.readers.record_from_arrays``).

        Parameters
        ----------
        t, d, F : array_like
            Time, displacement and force, in ``units``.
        v : array_like, optional
            A measured velocity; None (default): derived from d, as on reading a file.
        units : str, tuple or dict, optional
            FORCE,LENGTH,TIME, e.g. ``("N", "m", "s")`` or ``"kip,in,s"``; None: kN, mm, s.
        name : str
            The record's name in reports and exports.
        """
        return cls._from_arrays(t, d, F, v, units, name)

    @property
    def dt(self) -> float:
        """Sampling step [s]."""
        return float(self.t[1] - self.t[0])

    @property
    def n(self) -> int:
        """Number of samples."""
        return int(self.t.size)

    @property
    def duration(self) -> float:
        """t_end - t_start [s]."""
        return float(self.t[-1] - self.t[0])

    def scales(self) -> dict:
        """Peak magnitudes used to derive 'auto' bounds: F [kN], v [mm/s], d [mm]."""
        return {
            "F": float(np.max(np.abs(self.F))),
            "v": float(np.max(np.abs(self.v))),
            "d": float(np.max(np.abs(self.d - np.median(self.d)))),
        }

    def slice(self, start: int, stop: int, name: str | None = None) -> "Record":
        """Samples [start, stop) as a new record (provenance and warnings kept).

        Parameters
        ----------
        start, stop : int
            Sample indices.
        name : str, optional
            The new record's name; default this one's.

        Returns
        -------
        Record
        """
        s = np.s_[start:stop]
        cut = {k: None if getattr(self, k) is None else getattr(self, k)[s] for k in ("v_noise", "a_noise")}
        return Record(self.t[s], self.d[s], self.F[s], self.v[s], self.a[s],
                      name or self.name, dict(self.provenance, slice=[start, stop]), list(self.warnings),
                      d_noise=self.d_noise, **cut,
                      windows=None if self.windows is None else tuple(w[s] for w in self.windows))
