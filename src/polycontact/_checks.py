"""Argument checks shared by the public functions: numbers and points, with errors that
name the argument.

>>> finite_number(2, "t_max", minimum=0.0)
2.0
>>> finite_number(0.0, "time_tolerance", positive=True)
Traceback (most recent call last):
...
ValueError: time_tolerance: expected a finite number > 0, got 0.0
>>> point((1, 2), "reference").tolist()
[1.0, 2.0]
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np


def finite_number(
    value: Any,
    what: str,
    *,
    minimum: float | None = None,
    positive: bool = False,
    error: type[ValueError] = ValueError,
) -> float:
    """``value`` as a finite float (``>= minimum``, or ``> 0`` if ``positive``), else
    ``error`` naming ``what``. Booleans are refused: ``True`` is not a number here."""
    if isinstance(value, bool):
        raise error(f"{what}: expected a number, got {value!r}")
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise error(f"{what}: expected a number, got {value!r}") from None
    bound = " > 0" if positive else (f" >= {minimum:g}" if minimum is not None else "")
    if not math.isfinite(x) or (positive and x <= 0.0) or (minimum is not None and x < minimum):
        raise error(f"{what}: expected a finite number{bound}, got {x!r}")
    return x


def point(value: Any, what: str, *, error: type[ValueError] = ValueError) -> np.ndarray:
    """``value`` as a float64 array of shape (2,) with finite entries, else ``error``
    naming ``what``."""
    try:
        arr = np.array(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise error(f"{what}: expected two numbers (x, y), got {value!r}") from None
    if arr.shape != (2,) or not np.isfinite(arr).all():
        raise error(f"{what}: expected two finite numbers (x, y), got {value!r}")
    return arr
