"""Ground-motion records: read from a file as `vines run --record` reads
one, or given as samples."""

from __future__ import annotations

import os
from typing import Any, Tuple

import numpy as np
import numpy.typing as npt

from . import _vines
from ._convert import PathLike, path_of, real, samples_array


class Record:
    """A ground-motion record in m/s^2 at a uniform step dt [s].

    Parameters
    ----------
    acc : array_like
        The samples, one-dimensional; sample i is at t0 + i dt.
    dt : float
        The sample step [s].
    units : {"g", "m/s2", "cm/s2"}
        The units of `acc`.
    t0 : float
        The time of the first sample [s].
    name : str
        Names the record in messages and in a run's summary.

    Raises
    ------
    RecordError
        A sample is not finite, dt is not positive, or there are fewer than
        two samples (the rule of a record file).

    See Also
    --------
    Record.load : a record file.
    """

    __slots__ = ("_impl", "_args")

    def __init__(self, acc: npt.ArrayLike, dt: float, units: str = "g", t0: float = 0.0,
                 name: str = "<array>") -> None:
        samples = samples_array(acc, "vines.Record: acc")
        self._impl = _vines.Record.from_array(samples, real(dt, "vines.Record: dt", finite=True),
                                              real(t0, "vines.Record: t0", finite=True), str(units), str(name))
        self._args: Tuple[Any, ...] = ("array",)

    @classmethod
    def load(cls, path: PathLike, format: str = "auto", units: str = "g", column: int = 1,
             dt: float = 0.0) -> "Record":
        """A record file, read as `vines run --record` reads it.

        Parameters
        ----------
        path : str or os.PathLike
            The file; a relative path not found from the working directory
            is looked for in the ground-motions folder, as a scene's record
            is ($VINES_GROUND_MOTIONS, else ../shared/data/ground_motions).
            Record.path is then the file found.
        format : {"auto", "at2", "time-accel", "accel"}
            "accel" is values only: give `dt`.
        units : {"g", "m/s2", "cm/s2"}
            The units of a columns file (an AT2 header says its own).
        column : int
            The acceleration column of a time-accel file (1 = first).
        dt : float
            The sample step of an "accel" file [s].

        Raises
        ------
        RecordError
            The file is missing (the places tried are listed) or malformed.
        """
        given = path_of(path, "vines.Record.load")
        found = given if os.path.exists(given) else _vines.find_record(given)
        record = cls.__new__(cls)
        step = real(dt, "vines.Record.load: dt", finite=True)
        record._impl = _vines.Record.load(found, str(format), str(units), int(column), step)
        record._args = ("file", found, str(format), str(units), int(column), step)
        return record

    @property
    def path(self) -> str:
        """The file read (or the name given)."""
        return self._impl.path

    @property
    def dt(self) -> float:
        """The sample step [s]."""
        return self._impl.dt

    @property
    def t0(self) -> float:
        """The time of the first sample [s]."""
        return self._impl.t0

    @property
    def acc(self) -> "npt.NDArray[np.float64]":
        """The samples [m/s^2] (a copy)."""
        return self._impl.acc

    @property
    def pga(self) -> float:
        """The peak ground acceleration [m/s^2]."""
        return self._impl.pga

    @property
    def t(self) -> "npt.NDArray[np.float64]":
        """The sample times [s]."""
        return self._impl.t0 + self.dt * np.arange(len(self._impl))

    def __len__(self) -> int:
        return len(self._impl)

    def __reduce__(self) -> Tuple[Any, ...]:
        if self._args[0] == "file":
            return (_load, self._args[1:])
        return (Record, (self.acc, self.dt, "m/s2", self.t0, self.path))

    def __repr__(self) -> str:
        return "vines.Record(%r, %d points, dt %g s)" % (self.path, len(self), self.dt)


def _load(path: str, format: str, units: str, column: int, dt: float) -> Record:
    return Record.load(path, format, units, column, dt)


def as_record(record: Any, what: str) -> Record:
    """A Record; a path (read with Record.load); or (samples, dt) in g."""
    if isinstance(record, Record):
        return record
    if isinstance(record, (str, os.PathLike)):
        return Record.load(record)
    if isinstance(record, tuple) and len(record) == 2:
        return Record(record[0], record[1])
    raise TypeError("%s: a vines.Record, a record file's path or (samples in g, dt), not %s"
                    % (what, type(record).__name__))
