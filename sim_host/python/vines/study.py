"""Runs, excitations, studies and the modal report of a scene."""

from __future__ import annotations

import json
from typing import Any, Dict, Mapping, Optional, Sequence

import numpy as np
import numpy.typing as npt

from . import _vines
from ._convert import plain_dict, plain_list
from .record import as_record
from .result import Result, _pandas
from .scene import as_scene


def run(scene: Any, record: Any = None) -> Result:
    """Runs a scene: its device and, with one, the bare frame (x_r, E_r).

    Parameters
    ----------
    scene : Scene or path
        The scene, or a scene file's path.
    record : Record, path or (samples, dt), optional
        A record in place of the scene's; of the scene's [record] only
        scale or pga_g and duration_s then apply (as `vines run --record`).
        (samples, dt) is in g.

    Returns
    -------
    Result
        summary.json's fields and the series.

    Raises
    ------
    SceneError, RecordError
        A bad scene or record, named in the message.

    Notes
    -----
    The loop runs in C++ with the GIL released: threads run in parallel.
    """
    s = as_scene(scene, "vines.run: scene")
    r = None if record is None else as_record(record, "vines.run: record")._impl
    return Result(_vines.run(s._impl, r))


def samples(scene: Any, record: Any = None) -> "npt.NDArray[np.float64]":
    """The ground acceleration a run of `scene` steps through.

    Parameters
    ----------
    scene : Scene or path
    record : Record, path or (samples, dt), optional
        As in `run`.

    Returns
    -------
    ndarray
        The record (or `record`) scaled as the scene says and resampled to
        the sensor rate [m/s^2], sample k at t = k / sensor_rate_hz.
    """
    s = as_scene(scene, "vines.samples: scene")
    r = None if record is None else as_record(record, "vines.samples: record")._impl
    return _vines.samples(s._impl, r)


# A sweep's result columns after the keys' values, with their dtypes.
_NUMBERS = ("x_r", "E_r", "peak_top_displacement_m", "elastic_energy_integral", "contacts")
_TEXTS = ("status", "degraded_reasons", "error")


def sweep(scene: Any, grid: Optional[Mapping[str, Any]] = None, set: Optional[Mapping[str, Any]] = None,
          cases: Optional[Sequence[Mapping[str, Any]]] = None, group_by: Optional[str] = None,
          threads: int = 0, as_frame: bool = False, large: bool = False) -> Any:
    """Runs a study of `scene` as `vines sweep` runs one (data/studies/README.md).

    Parameters
    ----------
    scene : Scene or path
    grid : mapping, optional
        ``{"section.key": values}``, values a list (or array) or
        ``{"from", "to", "step" | "count", "scale"}``: every combination runs.
    set : mapping, optional
        ``{"section.key": value}`` fixed for every run.
    cases : sequence of mappings, optional
        Paired keys, ``[{"section.key": value, ...}, ...]``: the runs are
        the cases times the grid.
    group_by : str, optional
        A grid key, checked as [study] group_by is. The rows are per run
        all the same: group them with numpy or pandas (the program's
        per-group statistics of summary.json are not computed here).
    threads : int
        C++ threads (0: every core; at most 1024, as `vines sweep
        --threads`), with the GIL released; Ctrl-C stops the runs and
        raises KeyboardInterrupt.
    as_frame : bool
        A pandas DataFrame instead of a numpy record array.
    large : bool
        Runs a plan of more than 1,000,000 runs (`vines sweep --large`);
        without it such a plan is refused before it takes any memory.

    Returns
    -------
    numpy.recarray or pandas.DataFrame
        One row per run, in results.csv's order: the keys' values
        (results.csv's column names), x_r, E_r, peak_top_displacement_m,
        elastic_energy_integral, contacts, status ("ok", "degraded" or
        "failed"), degraded_reasons, error (a failed run's message; its
        numbers NaN, contacts -1).

    Raises
    ------
    SceneError
        A key that is not a scene key, a bad range, a key set twice, a
        group_by that is not a grid key.
    ValueError
        threads outside 0-1024; a plan of more than 1,000,000 runs without
        large=True, or one whose plan would take more than half the
        machine's memory.
    """
    s = as_scene(scene, "vines.sweep: scene")
    if isinstance(threads, bool) or not isinstance(threads, (int, np.integer)):
        raise TypeError("vines.sweep: threads: an int, not %s" % type(threads).__name__)
    if not 0 <= threads <= 1024:
        raise ValueError("vines.sweep: threads: %d; must be 0 (every core) to 1024" % threads)
    if not isinstance(large, (bool, np.bool_)):
        raise TypeError("vines.sweep: large: a bool, not %s" % type(large).__name__)
    where = s.origin + " (sweep)"
    raw = _vines.sweep(s._impl, plain_dict(grid or {}, where + ": grid"), plain_dict(set or {}, where + ": set"),
                       plain_list(cases or [], where + ": cases"), str(group_by or ""), int(threads),
                       bool(large))
    columns: Dict[str, Any] = {key: np.asarray(values) for key, values in zip(raw["keys"], raw["values"])}
    for name in _NUMBERS:
        columns[name] = raw[name]
    for name in _TEXTS:
        columns[name] = np.asarray(raw[name], dtype=str)
    if as_frame:
        return _pandas().DataFrame(columns)
    return np.rec.fromarrays(list(columns.values()), dtype=[(k, v.dtype) for k, v in columns.items()])


def modal(scene: Any) -> Dict[str, Any]:
    """The frame's modes (with the scene's device floor).

    Returns
    -------
    dict
        frequency_hz, damping_ratio, participation_factor,
        effective_mass_kg, effective_mass_fraction (arrays over the modes),
        mode_shapes (modes x floors), total_mass_kg.
    """
    m = json.loads(_vines.modal(as_scene(scene, "vines.modal: scene")._impl))
    return {k: (v if isinstance(v, float) else np.asarray(v)) for k, v in m.items()}
