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

A polygon's own validity is judged on a finer scale: two of its features meet only
when float64 cannot tell them apart (:func:`validation_tolerance`, 4 float spacings of
its largest coordinate), so every polygon GEOS calls valid is accepted, at any scale.

Coordinates must lie in ``[-COORDINATE_LIMIT, COORDINATE_LIMIT]`` and every body must
be larger than ``EXTENT_FLOOR``: the kernels form products of up to three coordinate
differences (areas, centroids, Minkowski sums), which would overflow or underflow
float64 beyond these bounds. Inputs outside them are refused with an error that says
so; they are never answered wrongly.

Tolerances are always passed to kernels as arguments (Numba freezes module globals at
compile time), so these constants are only defaults read by the public functions.
"""

from __future__ import annotations

import numpy as np

from .errors import InvalidShapeError

__all__ = [
    "RELATIVE_TOLERANCE",
    "ROUNDING_ULPS",
    "COORDINATE_LIMIT",
    "EXTENT_FLOOR",
    "VALIDATION_ULPS",
    "tolerance_for",
    "validation_tolerance",
    "default_tolerance",
    "check_range",
    "snap_grid",
]

#: Relative to the size of the bodies: 1e-12 of a body's extent counts as zero. Far
#: below any gap a user means (a shift of 1e-9 of a body's size is seen, 1000 times
#: the tolerance), far above the rounding of arithmetic on coordinates of that size.
RELATIVE_TOLERANCE = 1e-12

#: Relative to the float spacing of the coordinates: 64 units in the last place of the
#: largest absolute coordinate (64 * 2**-52 ~ 1.4e-14 of it). A translation or rotation of a
#: small body far from the origin moves its vertices by rounding errors of a few ulps
#: of its coordinates; 64 ulps is well above that and still resolves 1e-4 at 1e9.
ROUNDING_ULPS = 64.0

#: Largest absolute coordinate accepted. Products of three coordinate differences (up to
#: (2e100)**3 = 8e300) stay finite in float64 (max ~1.8e308).
COORDINATE_LIMIT = 1e100

#: Smallest body extent accepted: products of three lengths (1e-300) stay normal floats.
EXTENT_FLOOR = 1e-100

#: A polygon is refused as invalid (two of its features meet) only when they are
#: closer than float64 can tell apart: 4 units in the last place of its largest
#: absolute coordinate, about the rounding of a distance computed from such coordinates. This
#: is far below :func:`tolerance_for` on purpose: a valid polygon (GEOS's "very skinny
#: polygon", 10 wide and 1e15 long) is accepted, and its features closer than the
#: classification tolerance are then decided as touching.
VALIDATION_ULPS = 4.0

_ULP = 2.0**-52


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


def validation_tolerance(magnitude: float) -> float:
    """Distance below which two features of one polygon whose coordinates reach
    ``magnitude`` cannot be told apart in float64: ``VALIDATION_ULPS * 2**-52 *
    magnitude``.

    Examples
    --------
    >>> round(validation_tolerance(1e9) / 1e-7, 3)    # 4 float spacings at 1e9
    8.882
    """
    return VALIDATION_ULPS * _ULP * magnitude


def default_tolerance(*bodies: np.ndarray) -> float:
    """The absolute tolerance used when the caller gives none.

    Each argument is the (N, 2) coordinate array of one body (or one loop of it):
    ``extent`` is the largest side of any argument's own bounding box, so two unit
    bodies far apart keep a tolerance of their size, and ``magnitude`` the largest
    absolute coordinate of all. See :func:`tolerance_for`.

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
