"""Named tolerances, each with the reason for its value.

Tolerances are always passed to kernels as arguments (Numba freezes module globals at
compile time), so these constants are only defaults read by the public functions.
"""

from __future__ import annotations

import numpy as np

__all__ = ["RELATIVE_TOLERANCE", "default_tolerance"]

#: Distances below ``RELATIVE_TOLERANCE * scale`` count as zero, where ``scale`` is the
#: largest absolute coordinate involved (at least 1). 1e-12 is about 4500 units in the
#: last place of a float64 coordinate: far above the rounding of the few arithmetic
#: operations that produce the inputs (a translation, a rotation), and far below any gap
#: a user means: a shift of 1e-9 of a shape's size is still seen as a shift.
RELATIVE_TOLERANCE = 1e-12


def default_tolerance(*coordinate_arrays: np.ndarray) -> float:
    """The absolute tolerance used when the caller gives none.

    Examples
    --------
    >>> default_tolerance(np.array([[0.0, 0.0], [300.0, -5.0]]))
    3e-10
    """
    scale = 1.0
    for xy in coordinate_arrays:
        if len(xy):
            scale = max(scale, float(np.max(np.abs(xy))))
    return RELATIVE_TOLERANCE * scale
