"""Named tolerances, each with the reason for its value.

The default distance tolerance follows the **size of the bodies** and the **float
spacing of their coordinates**, never an absolute constant:

    eps = max(RELATIVE_TOLERANCE * extent, ROUNDING_ULPS * 2**-52 * magnitude)

where ``extent`` is the size of the largest body involved (the larger side of its
bounding box) and ``magnitude`` the largest absolute coordinate involved. The first
term is what a user means by "the same place" (a shift of 1e-9 of a body's size is
seen as a shift, at any scale); the second keeps the tolerance above the rounding of
the few operations that produce and compare coordinates (a translation, a rotation, a
difference of two coordinates) when small bodies sit far from the origin. Lengths are
compared with ``eps``; areas with ``eps * length``. The same formula is compiled for
the kernels (:mod:`polycontact._kernels.tolerance`), so every path gives a pair the
same tolerance.

A polygon's own validity is judged with no tolerance at all: exactly, for the float64
coordinates given (exact orientations, :class:`polycontact.Shape`). Two of its features
make it invalid only when they truly meet, however close they come otherwise, so every
polygon GEOS calls valid is accepted, at any scale and position; features of one body
closer than ``eps`` are then decided as touching, like features of two bodies.

Coordinates must lie in ``[-COORDINATE_LIMIT, COORDINATE_LIMIT]`` and every body must
be larger than ``EXTENT_FLOOR``: the kernels form products of up to three coordinate
differences (areas, centroids, Minkowski sums), which would overflow or underflow
float64 beyond these bounds. Inputs outside them are refused with an error that says
so; they are never answered wrongly.

The constants (:mod:`polycontact.limits`, where each is defined with its reason) are
re-exported here. Tolerances are always passed to kernels as arguments (Numba freezes
module globals at compile time), so these constants are only defaults read by the
public functions.
"""

from __future__ import annotations

import numpy as np

from .errors import InvalidShapeError
from .limits import COORDINATE_LIMIT, EXTENT_FLOOR, RELATIVE_TOLERANCE, ROUNDING_ULPS

__all__ = [
    "RELATIVE_TOLERANCE",
    "ROUNDING_ULPS",
    "COORDINATE_LIMIT",
    "EXTENT_FLOOR",
    "tolerance_for",
    "default_tolerance",
    "check_range",
    "snap_grid",
]

_ULP = 2.0**-52

#: :data:`ROUNDING_ULPS` as a factor of the largest |coordinate| (``ROUNDING_ULPS ×
#: 2**-52``): the form the time-of-impact and World kernels take it in.
ROUNDING_FACTOR = ROUNDING_ULPS * _ULP


def tolerance_for(extent: float, magnitude: float) -> float:
    """The absolute tolerance for bodies of size ``extent`` whose coordinates reach
    ``magnitude`` (both >= 0): ``max(RELATIVE_TOLERANCE * extent, ROUNDING_ULPS *
    2**-52 * magnitude)``.

    Examples
    --------
    >>> tolerance_for(1.0, 1.0)                  # a unit body at the origin
    1e-12
    >>> f"{tolerance_for(1e-6, 1e-6):.3g}"       # the same body scaled to a micrometre
    '1e-18'
    >>> round(tolerance_for(1.0, 1e9) / 1e-6, 3)  # a unit body at 1e9: the float spacing
    14.211
    """
    return max(RELATIVE_TOLERANCE * extent, ROUNDING_ULPS * _ULP * magnitude)


def default_tolerance(*bodies: np.ndarray) -> float:
    """The absolute tolerance used when the caller gives none.

    Parameters
    ----------
    *bodies : ndarray of shape (N, 2)
        The coordinates of each body (or of one loop of it): ``extent`` is the largest
        side of any argument's own bounding box, so two unit bodies far apart keep a
        tolerance of their size, and ``magnitude`` the largest absolute coordinate of
        all.

    Returns
    -------
    float
        :func:`tolerance_for` of that extent and magnitude.

    Examples
    --------
    >>> default_tolerance(np.array([[0.0, 0.0], [300.0, -5.0]]))
    3e-10
    >>> default_tolerance(np.array([[0.0, 0.0], [1e-5, 1e-5]]))
    1e-17
    """
    extent = 0.0
    magnitude = 0.0
    for xy in bodies:
        if len(xy):
            lo = xy.min(axis=0)
            hi = xy.max(axis=0)
            extent = max(extent, float(hi[0] - lo[0]), float(hi[1] - lo[1]))
            magnitude = max(magnitude, float(-lo.min()), float(hi.max()))
    return tolerance_for(extent, magnitude)


def check_range(xy: np.ndarray, what: str) -> None:
    """Refuse coordinates that float64 cannot carry through the kernels.

    ``xy`` is a finite float64 (N, 2) array of one body (or loop), ``what`` names it in
    the error. Raises :class:`polycontact.InvalidShapeError` if some absolute coordinate
    exceeds :data:`COORDINATE_LIMIT` or the body's extent is below :data:`EXTENT_FLOOR`
    (and not zero: a zero extent is a degenerate ring, refused elsewhere).

    Examples
    --------
    >>> check_range(np.array([[0.0, 0.0], [1.0, 1.0]]), "a")
    >>> check_range(np.array([[0.0, 0.0], [1e200, 1.0]]), "a")
    Traceback (most recent call last):
    ...
    polycontact.errors.InvalidShapeError: a: coordinate 1e+200 of vertex 1 is beyond ±1e+100: products of coordinates would overflow float64
    """
    big = np.abs(xy) > COORDINATE_LIMIT
    if big.any():
        i, j = (int(k) for k in np.argwhere(big)[0])
        raise InvalidShapeError(
            f"{what}: coordinate {xy[i, j]:g} of vertex {i} is beyond ±{COORDINATE_LIMIT:g}: "
            "products of coordinates would overflow float64"
        )
    if len(xy):
        extent = float(np.max(xy.max(axis=0) - xy.min(axis=0)))
        if 0.0 < extent < EXTENT_FLOOR:
            raise InvalidShapeError(
                f"{what}: extent {extent:g} is below {EXTENT_FLOOR:g}: products of its "
                "lengths would underflow float64 (scale the coordinates up)"
            )


def snap_grid(eps: float) -> float:
    """Snap-rounding grid for GEOS overlays (``grid_size``) of results whose tolerance
    is ``eps``: the power of two just below ``eps / 256``.

    GEOS's floating overlay can drop whole pieces of a union whose edges lie a few ulps
    apart; on a grid it is robust. Snapping moves a vertex by less than a grid step, so
    the outline stays well within the tolerance (a slight shift across a nearly parallel
    edge pair can change the relation by much more than the shift). A power of two keeps
    short binary fractions (0.5, 3.25) exact on the grid, so simple inputs give exact
    unions.

    Examples
    --------
    >>> snap_grid(1e-12) == 2.0**-48
    True
    >>> snap_grid(1.0)
    0.00390625
    """
    return float(2.0 ** np.floor(np.log2(eps / 256.0)))
