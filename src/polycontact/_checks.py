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
from typing import Any

import numpy as np


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
        raise TypeError(f"{what}: expected a real number, got {type(value).__name__} {value!r}")
    try:
        x = float(value)
    except (TypeError, ValueError, OverflowError):
        raise error(f"{what}: expected a finite number, got {value!r}") from None
    bound = " > 0" if positive else (f" >= {minimum:g}" if minimum is not None else "")
    if not math.isfinite(x) or (positive and x <= 0.0) or (minimum is not None and x < minimum):
        raise error(f"{what}: expected a finite number{bound}, got {x!r}")
    return x


def point(value: Any, what: str, *, error: type[ValueError] = ValueError) -> np.ndarray:
    """``value`` as a float64 array of shape (2,) with finite entries, else ``error``
    naming ``what``; ``TypeError`` if the entries are not real numbers (strings,
    booleans, complex numbers)."""
    try:
        raw = np.asarray(value)
    except (TypeError, ValueError):
        raise error(f"{what}: expected two numbers (x, y), got {value!r}") from None
    if raw.shape != (2,):
        raise error(f"{what}: expected two numbers (x, y), got {value!r}")
    if raw.dtype.kind == "O" or isinstance(value, (list, tuple)):
        for x in value if isinstance(value, (list, tuple)) else raw.ravel():
            if not is_real(x):
                raise TypeError(f"{what}: expected two real numbers, got a {type(x).__name__}")
    elif raw.dtype.kind not in "fiu":
        raise TypeError(
            f"{what}: expected two real numbers, got {type(value).__name__} {value!r}"
        )
    try:
        arr = np.array(raw, dtype=np.float64)
    except (TypeError, ValueError):
        raise error(f"{what}: expected two numbers (x, y), got {value!r}") from None
    if arr.shape != (2,) or not np.isfinite(arr).all():
        raise error(f"{what}: expected two finite numbers (x, y), got {value!r}")
    return arr


def real_array(value: Any, what: str, shape: tuple[int, ...]) -> np.ndarray:
    """``value`` as a new float64 array of ``shape`` with finite entries, else an error
    naming ``what`` and, for a bad entry, its index; ``TypeError`` if the entries are
    not real numbers (strings, booleans, complex numbers, objects).

    >>> real_array([[0, 1], [2.5, 3]], "positions", (2, 2)).tolist()
    [[0.0, 1.0], [2.5, 3.0]]
    >>> real_array([0.0, float("nan")], "angles", (2,))
    Traceback (most recent call last):
    ...
    ValueError: angles[1]: expected a finite number, got nan
    """
    try:
        raw = np.asarray(value)
        if not isinstance(value, np.ndarray) and raw.dtype.kind != "O":
            # nested sequences: NumPy would turn a bool among numbers into a number
            raw = np.asarray(value, dtype=object) if raw.dtype.kind in "biu" else raw
    except (TypeError, ValueError):
        raise ValueError(f"{what}: expected an array of shape {shape}, got "
                         f"{type(value).__name__}") from None
    if raw.dtype.kind == "O":
        for index, x in np.ndenumerate(raw):
            if not is_real(x):
                where = "".join(f"[{i}]" for i in index)
                raise TypeError(f"{what}{where}: expected a real number, got "
                                f"{type(x).__name__} {x!r}")
    elif raw.dtype.kind not in "fiu":
        raise TypeError(f"{what}: expected real numbers, got an array of {raw.dtype}")
    if raw.shape != shape:
        raise ValueError(f"{what}: expected an array of shape {shape}, got shape {raw.shape}")
    try:
        arr = np.array(raw, dtype=np.float64)
    except (TypeError, ValueError, OverflowError):
        raise ValueError(f"{what}: expected finite numbers") from None
    finite = np.isfinite(arr)
    if not finite.all():
        index = tuple(int(i) for i in np.argwhere(~finite)[0])
        where = "".join(f"[{i}]" for i in index[:1]) if arr.ndim else ""
        raise ValueError(f"{what}{where}: expected a finite number, got {float(arr[index])!r}")
    return arr
