"""Kernel: the default distance tolerance, the formula of
:func:`polycontact.tolerances.tolerance_for` (kept bit for bit the same, so that a pair
classified through :class:`polycontact.Shape` and through the lean array path gets the
same tolerance).

>>> import numpy as np
>>> sq = np.array([[0.0, 0.0], [1e-6, 0.0], [1e-6, 1e-6]])
>>> f"{tolerance_of(sq, 1e-12, 64.0):.3g}"
'1e-18'
"""

from __future__ import annotations

import numpy as np

from .jit import njit


@njit(cache=True, nogil=True)
def tolerance_for(extent, magnitude, rel_tol, ulps):
    """``max(rel_tol * extent, ulps * 2**-52 * magnitude)``: ``extent`` the size of the
    largest body, ``magnitude`` the largest |coordinate| involved."""
    return max(rel_tol * extent, ulps * 2.0**-52 * magnitude)


@njit(cache=True, nogil=True)
def box_extent_magnitude(x0, x1, y0, y1):
    """``(extent, magnitude)`` of a bounding box: its larger side, its largest |coordinate|."""
    return max(x1 - x0, y1 - y0), max(-x0, x1, -y0, y1)


@njit(cache=True, nogil=True)
def extent_magnitude(xy):
    """``(extent, magnitude)`` of an (N, 2) array's bounding box (0, 0 when empty)."""
    if xy.shape[0] == 0:
        return 0.0, 0.0
    x0 = np.inf
    x1 = -np.inf
    y0 = np.inf
    y1 = -np.inf
    for i in range(xy.shape[0]):
        x0 = min(x0, xy[i, 0])
        x1 = max(x1, xy[i, 0])
        y0 = min(y0, xy[i, 1])
        y1 = max(y1, xy[i, 1])
    return box_extent_magnitude(x0, x1, y0, y1)


@njit(cache=True, nogil=True)
def tolerance_of(xy, rel_tol, ulps):
    """The default tolerance of one body given as an (N, 2) array (its own bounding
    box): :func:`tolerance_for` of :func:`extent_magnitude`."""
    extent, magnitude = extent_magnitude(xy)
    return tolerance_for(extent, magnitude, rel_tol, ulps)
