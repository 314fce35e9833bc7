"""Argument checks shared by the public functions: numbers and points, with errors that
name the argument.

>>> finite_number(2, "t_max", minimum=0.0)
2.0
>>> finite_number(0.0, "time_tolerance", positive=True)
Traceback (most recent call last):
...
ValueError: time_tolerance: expected a finite number > 0, got 0.0
>>> finite_number("1e-3", "tolerance")
Traceback (most recent call last):
...
TypeError: tolerance: expected a real number, got str '1e-3'
>>> point((1, 2), "reference").tolist()
[1.0, 2.0]
"""

from __future__ import annotations

import decimal
import math
import numbers
from collections.abc import Mapping
from typing import Any

import numpy as np

from .tolerances import COORDINATE_LIMIT


def is_real(x: Any) -> bool:
    """Whether ``x`` is one real number: an int, float, fraction or decimal (Python or
    NumPy), not a bool, a string or a complex number."""
    return isinstance(x, (numbers.Real, decimal.Decimal)) and not isinstance(x, (bool, np.bool_))


def finite_number(
    value: Any,
    what: str,
    *,
    minimum: float | None = None,
    positive: bool = False,
    error: type[ValueError] = ValueError,
) -> float:
    """``value`` as a finite float (``>= minimum``, or ``> 0`` if ``positive``), else
    ``error`` naming ``what``.

    Only real numbers are taken (Python and NumPy integers and floats, fractions,
    decimals, 0-d real arrays); anything else raises ``TypeError`` naming ``what`` and
    the type given: a string is not parsed, a complex number not truncated, and
    ``True`` is not a number here."""
    if (type(value) is float and value - value == 0.0  # finite: inf - inf and nan are nan
            and (not positive or value > 0.0) and (minimum is None or value >= minimum)):
        return value  # the common case, in nanoseconds: a finite float within bounds
    if isinstance(value, np.ndarray) and value.ndim == 0 and value.dtype.kind in "fiu":
        value = value[()]
    if not is_real(value):
        raise TypeError(f"{what}: expected a real number, got {type(value).__name__} "
                        f"{shown(value)}")
    try:
        x = float(value)
    except (TypeError, ValueError, OverflowError):
        raise error(f"{what}: expected a finite number, got {shown(value)}") from None
    bound = " > 0" if positive else (f" >= {minimum:g}" if minimum is not None else "")
    if not math.isfinite(x) or (positive and x <= 0.0) or (minimum is not None and x < minimum):
        raise error(f"{what}: expected a finite number{bound}, got {x!r}")
    return x


def real_array(value: Any, what: str, error: type[ValueError] = ValueError) -> np.ndarray:
    """``value`` as a new float64 array, if it holds real numbers only.

    Integers and floats are converted; strings, booleans, complex numbers, sets,
    mappings and other objects raise ``TypeError`` naming ``what`` and the type given (a
    string such as ``"1.5"`` is not parsed, an imaginary part not dropped, a set has no
    order); a ragged nesting or a number beyond float64 raises ``error``.
    """
    if isinstance(value, (str, bytes, set, frozenset, Mapping)):
        raise TypeError(f"{what}: expected real numbers, got {type(value).__name__}")
    try:
        arr = np.asarray(value)
    except (TypeError, ValueError) as exc:
        raise error(f"{what}: not an array of numbers ({exc})") from None
    kind = arr.dtype.kind
    if isinstance(value, (list, tuple)) and kind in "fiu":  # NumPy made numbers of bools
        if _holds_bool(value):
            raise TypeError(f"{what}: expected real numbers, got an element of type bool")
    if kind == "O":
        for x in arr.ravel():
            if not is_real(x):
                raise TypeError(
                    f"{what}: expected real numbers, got an element of type {type(x).__name__}"
                )
    elif kind not in "fiu":
        raise TypeError(f"{what}: expected real numbers, got an array of dtype {arr.dtype}")
    try:
        return np.array(arr, dtype=np.float64)
    except (TypeError, ValueError, OverflowError) as exc:
        raise error(f"{what}: not an array of numbers ({exc})") from None


def one_value(value: Any) -> bool:
    """Whether ``value`` is given as one value rather than as many (a list, tuple, set,
    mapping, string or array of dimension 1 or more), without converting it (a ragged
    list would not convert).

    >>> one_value(0.5), one_value(np.float64(1)), one_value([0.5]), one_value("0.5")
    (True, True, False, False)
    """
    if isinstance(value, np.ndarray):
        return value.ndim == 0
    return not isinstance(value, (str, bytes, list, tuple, set, frozenset, Mapping))


def _holds_bool(value: Any) -> bool:
    """Whether a (nested) list or tuple holds a bool or an array of bools (NumPy would
    make them numbers)."""
    items = [value]
    while items:
        item = items.pop()
        if isinstance(item, (bool, np.bool_)):
            return True
        if isinstance(item, np.ndarray):
            if item.dtype.kind == "b":
                return True
            if item.dtype.kind == "O":
                items.extend(item.ravel().tolist())
        elif isinstance(item, (list, tuple)):
            items.extend(item)
    return False


def points(value: Any, what: str, shape: tuple[int, ...] = (-1, 2)) -> np.ndarray:
    """``value`` as a new float64 array of ``shape`` (-1: any length) whose entries are
    finite and within ±:data:`~polycontact.tolerances.COORDINATE_LIMIT` (products of
    coordinates must not overflow), else an error naming ``what``: ``TypeError`` for
    entries that are not real numbers (see :func:`real_array`), ``ValueError``
    otherwise, with the index of the first bad entry.

    >>> points([(0, 1), (2, 3)], "positions").tolist()
    [[0.0, 1.0], [2.0, 3.0]]
    >>> points([(0, 1), (2, 1e200)], "positions")
    Traceback (most recent call last):
    ...
    ValueError: positions[1]: 1e+200 is beyond ±1e+100: products of coordinates would overflow float64
    """
    arr = real_array(value, what)
    if arr.ndim != len(shape) or any(n not in (-1, m) for n, m in zip(shape, arr.shape)):
        want = ", ".join("N" if n < 0 else str(n) for n in shape)
        raise ValueError(f"{what}: expected an array of shape ({want}), got shape {arr.shape}")
    bad = ~np.isfinite(arr) | (np.abs(arr) > COORDINATE_LIMIT)
    if bad.any():
        at = tuple(int(i) for i in np.argwhere(bad)[0])
        where = f"{what}[{at[0]}]" if len(at) > 1 else what
        x = float(arr[at])
        if not math.isfinite(x):
            raise ValueError(f"{where}: expected finite numbers, got {x!r}")
        raise ValueError(f"{where}: {x:g} is beyond ±{COORDINATE_LIMIT:g}: products of "
                         "coordinates would overflow float64")
    return arr


def point(value: Any, what: str, *, error: type[ValueError] = ValueError,
          limit: float | None = COORDINATE_LIMIT) -> np.ndarray:
    """``value`` as a new float64 array of shape (2,) with finite entries within
    ±``limit`` (None: any), else ``error`` naming ``what``; ``TypeError`` if the entries
    are not real numbers (strings, booleans, complex numbers) or ``value`` is a string,
    a set or a mapping."""
    arr = real_array(value, what, error)
    if arr.shape != (2,):
        raise error(f"{what}: expected two numbers (x, y), got {shown(value)}")
    if not np.isfinite(arr).all():
        raise error(f"{what}: expected two finite numbers (x, y), got {shown(value)}")
    if limit is not None and np.abs(arr).max() > limit:
        raise error(f"{what}: {shown(value)} is beyond ±{limit:g}: products of "
                    "coordinates would overflow float64")
    return arr


def shown(value: Any) -> str:
    """``value`` as an error message shows it: its repr cut to 60 characters, an
    integer too long for that by its number of digits.

    >>> shown(10**400), shown([1.5, 2])
    ('an integer of 401 digits', '[1.5, 2]')
    """
    text = repr(value)
    if len(text) <= 60:
        return text
    if isinstance(value, int) and not isinstance(value, bool):
        return f"an integer of {len(text.lstrip('-'))} digits"
    return text[:57] + "..."
