"""Python and numpy values as the plain values a scene or a study takes
(bool, int, float, str, list, dict), converted exactly, and paths as str;
a TypeError naming what was expected otherwise."""

from __future__ import annotations

import math
import numbers
import os
from collections.abc import Mapping
from typing import Any, Dict, List, Union

import numpy as np

PathLike = Union[str, "os.PathLike[str]"]
Plain = Union[bool, int, float, str, list, dict]

_EXPECTED = "bool, int, float, str, a list or array of them, or a dict"


def _number(value: Any, where: str) -> Plain:
    """A numpy (or other) scalar as the Python number holding it exactly."""
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, numbers.Integral):
        return int(value)
    if isinstance(value, (float, np.floating)):
        f = float(value)
        if not math.isnan(f) and np.longdouble(f) != np.longdouble(value):  # rounded, or overflowed to inf
            raise TypeError("%s: %r has no exact double value" % (where, value))
        return f
    raise TypeError("%s: a value of type %s (%s)" % (where, type(value).__name__, _EXPECTED))


def real(value: Any, where: str, finite: bool = False) -> float:
    """A number argument as a float: a TypeError for another type (bool, str,
    None...), a ValueError for an int too large for a double or, with
    `finite`, a NaN or infinity; each naming `where`."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (numbers.Real, np.integer, np.floating)):
        raise TypeError("%s: a number (int or float), not %s" % (where, type(value).__name__))
    try:
        f = float(value)
    except OverflowError:
        raise ValueError("%s: %r does not fit a double" % (where, value)) from None
    if finite and not math.isfinite(f):
        raise ValueError("%s: %r is not finite" % (where, value))
    return f


def samples_array(value: Any, where: str) -> "np.ndarray[Any, np.dtype[np.float64]]":
    """An array of samples as float64: a TypeError for a masked array (its
    mask would be dropped) and for kinds that are not numbers (bool, str,
    object, complex), naming `where`."""
    if isinstance(value, np.ma.MaskedArray):
        raise TypeError("%s: a masked array (its mask would be lost): fill or drop the masked samples first "
                        "(numpy.ma.filled, .compressed)" % where)
    a = np.asarray(value)
    if a.dtype.kind not in "iuf":
        raise TypeError("%s: numbers (an array of int or float), not %s" % (where, a.dtype))
    return a.astype(float)


def plain(value: Any, where: str) -> Plain:
    """`value` as bool, int, float, str, list or dict (nested), exactly:
    numpy scalars become Python numbers, arrays and tuples lists, mappings
    dicts, paths strings. `where` names the value in the TypeError raised
    for anything else ("origin: section.key")."""
    if isinstance(value, str):
        return value
    if isinstance(value, os.PathLike):
        return str(os.fspath(value))
    if isinstance(value, Mapping):
        return plain_dict(value, where)
    if isinstance(value, np.ndarray):
        if value.dtype.kind not in "biufUO":
            raise TypeError("%s: an array of %s (%s)" % (where, value.dtype, _EXPECTED))
        return plain(value[()], where) if value.ndim == 0 else [plain(v, where) for v in value]
    if isinstance(value, np.str_):
        return str(value)
    if isinstance(value, (list, tuple, range)):
        return [plain(v, where) for v in value]
    return _number(value, where)


def plain_dict(value: Any, where: str) -> Dict[str, Any]:
    """A mapping as a dict of plain values (see plain); TypeError otherwise."""
    if not isinstance(value, Mapping):
        raise TypeError("%s: a dict, not %s" % (where, type(value).__name__))
    return {str(k): plain(v, "%s.%s" % (where, k)) for k, v in value.items()}


def plain_list(value: Any, where: str) -> List[Any]:
    """A sequence (or array) as a list of plain values; TypeError otherwise."""
    if isinstance(value, (str, Mapping)) or not isinstance(value, (list, tuple, np.ndarray)):
        raise TypeError("%s: a list, not %s" % (where, type(value).__name__))
    return [plain(v, where) for v in value]


def path_of(value: Any, what: str) -> str:
    """A str or os.PathLike as a str; TypeError naming `what` otherwise."""
    if isinstance(value, (str, os.PathLike)):
        return str(os.fspath(value))
    raise TypeError("%s: a path (str or os.PathLike), not %s" % (what, type(value).__name__))

