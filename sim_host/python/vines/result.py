"""What a run returns: summary.json's fields and the series, as Python
attributes and numpy arrays."""

from __future__ import annotations

import importlib
import json
from typing import Any, Dict, List, Mapping, Optional

import numpy as np
import numpy.typing as npt

Array = npt.NDArray[np.float64]

# Channels only one device has: NaN in a run (or a step) of another device.
VINES_CHANNELS = ("particle_x", "particle_v", "wall_left", "wall_right", "contact_force", "mode")
TMD_CHANNELS = ("tmd_x", "tmd_v")
FLOOR_CHANNELS = ("x", "v", "acc", "drift")


def blank_absent(values: Dict[str, Any], device: str) -> Dict[str, Any]:
    """Sets the channels `device` has not ("vines", "tmd" or "none") to NaN."""
    absent = (() if device == "vines" else VINES_CHANNELS) + (() if device == "tmd" else TMD_CHANNELS)
    for name in absent:
        v = values[name]
        values[name] = np.full(np.shape(v), np.nan) if np.ndim(v) else float("nan")
    return values


def frame_columns(values: Mapping[str, Any], prefix: str = "") -> Dict[str, Any]:
    """One column a scalar channel, one a floor of each floor channel (x1,
    x2, ...), the channels the device has not left out."""
    columns: Dict[str, Any] = {}
    for name, v in values.items():
        if name in FLOOR_CHANNELS:
            for j in range(v.shape[1]):
                columns["%s%s%d" % (prefix, name, j + 1)] = v[:, j]
        elif name != "t" and not np.all(np.isnan(v)):
            columns[prefix + name] = v
    return columns


def _pandas() -> Any:
    try:
        return importlib.import_module("pandas")
    except ImportError:
        raise ImportError("a DataFrame needs pandas (Debian: apt-get install python3-pandas)") from None


def _frame(t: Array, columns: Mapping[str, Any]) -> Any:
    """A pandas DataFrame of `columns`, indexed by t."""
    pandas = _pandas()
    return pandas.DataFrame(columns, index=pandas.Index(t, name="t"))


class Series:
    """Time series at the scene's output rate.

    Attributes
    ----------
    t : ndarray
        Time [s].
    ag : ndarray
        Ground acceleration [m/s^2].
    x, v, acc, drift : ndarray
        Rows x stories: relative displacement [m], velocity [m/s],
        absolute acceleration [m/s^2], story drift [m].
    elastic_energy : ndarray
        E_e so far [J s].
    particle_x, particle_v, wall_left, wall_right, contact_force, mode : ndarray
        VI NES: the sphere and the walls [m, m/s], contact force [N], the
        contact mode; NaN without a VI NES.
    tmd_x, tmd_v : ndarray
        TMD mass [m, m/s]; NaN without a TMD.
    """

    t: Array
    ag: Array
    x: Array
    v: Array
    acc: Array
    drift: Array
    elastic_energy: Array
    particle_x: Array
    particle_v: Array
    wall_left: Array
    wall_right: Array
    contact_force: Array
    mode: Array
    tmd_x: Array
    tmd_v: Array

    def __init__(self, arrays: Mapping[str, Any]) -> None:
        self.__dict__.update(arrays)

    def to_frame(self) -> Any:
        """A pandas DataFrame indexed by t: ag, x1..xN, v1..vN, acc1..accN,
        drift1..driftN, elastic_energy and the device's channels."""
        return _frame(self.t, frame_columns(self.__dict__))

    def __repr__(self) -> str:
        return "vines.Series(%d rows: %s)" % (len(self.t), ", ".join(sorted(self.__dict__)))


class Result:
    """A run of a scene.

    Attributes
    ----------
    summary : dict
        summary.json's fields; each is an attribute too (``x_r``, ``E_r``,
        ``peak_top_displacement_m``, ``contacts``, ``status``, ``counters``,
        ``modal``, ...).
    series : Series
        The device run's series; each is an attribute too (``t``, ``x``,
        ``particle_x``, ...).
    bare : Series or None
        The bare frame's series (None without a device).

    A Result pickles and deep-copies as plain data.
    """

    def __init__(self, raw: Mapping[str, Any]) -> None:
        self.summary: Dict[str, Any] = json.loads(raw["summary"])
        device = self.summary.get("device", "none")
        self.series = Series(blank_absent(dict(raw["series"]), device))
        self.bare: Optional[Series] = (Series(blank_absent(dict(raw["bare_series"]), "none"))
                                       if "bare_series" in raw else None)

    def __getattr__(self, name: str) -> Any:
        summary = self.__dict__.get("summary", {})
        if name in summary:
            return summary[name]
        series = self.__dict__.get("series")
        if series is not None and name in series.__dict__:
            return series.__dict__[name]
        raise AttributeError("vines.Result has no field %r" % name)

    def __dir__(self) -> List[str]:
        series = self.__dict__.get("series")
        return sorted(set(super().__dir__()) | set(self.__dict__.get("summary", {}))
                      | set(series.__dict__ if series is not None else ()))

    @property
    def degraded(self) -> bool:
        """True unless the status is "ok"."""
        return bool(self.summary["status"] != "ok")

    def to_frame(self, bare: bool = False) -> Any:
        """The device run's series as a pandas DataFrame.

        Parameters
        ----------
        bare : bool
            Add the bare frame's x, v, acc and drift as bare_x1, ...

        Returns
        -------
        pandas.DataFrame
            Indexed by t: ag, x1..xN, v1..vN, acc1..accN, drift1..driftN,
            elastic_energy and the device's channels (see `Series.to_frame`).

        Raises
        ------
        ImportError
            Without pandas (Debian: python3-pandas).
        """
        columns = frame_columns(self.series.__dict__)
        if bare and self.bare is not None:
            floors = {k: v for k, v in self.bare.__dict__.items() if k in FLOOR_CHANNELS}
            columns.update(frame_columns(floors, "bare_"))
        return _frame(self.t, columns)

    def __repr__(self) -> str:
        s = self.summary
        parts = ["scene %r" % s["scene"], "status %s" % s["status"],
                 "peak %.6g m" % s["peak_top_displacement_m"]]
        if "x_r" in s:
            parts += ["x_r %.4g" % s["x_r"], "E_r %.4g" % s["E_r"]]
        return "vines.Result(" + ", ".join(parts) + ")"
