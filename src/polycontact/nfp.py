"""No-fit polygon and inner-fit polygon of arbitrary polygons with holes.

A orbits, B is fixed. The no-fit polygon is the entrance block seen as a region,

    E(A, B) = B ⊕ (a0 − A) = { a0 + d : (A + d) ∩ B ≠ ∅ },

the set of positions of A's reference point ``a0`` at which A touches or overlaps B;
its outline is ∂E(A, B) = E(A(1), B(0)) ∪ E(A(0), B(1)) (paper §5(6)). It is built as
the union of the convex sums ``B_i ⊕ (a0 − A_j)`` of convex pieces of B and A (holes
included: the pieces come from a triangulation of the solid region, by ear clipping or
GEOS, merged Hertel–Mehlhorn style), each sum made in O(p + q) by merging edge angles.
The union's outline is assembled directly: the parts of the sums' edges that lie inside
no other sum are linked into rings (GEOS unions the sums only if that ever failed).
Two rings without holes are decomposed, summed and outlined in one kernel call (a convex
ring is its own piece; ear clipping a ring of up to 64 vertices again costs less than
looking its pieces up from Python); the other decompositions (GEOS's triangulation of
larger rings and of shapes with holes) are cached by coordinates, so a nesting code
calling this for many pairs of the same pieces decomposes each piece once.

An area union loses the positions where A fits exactly: a jigsaw piece in its socket
(an isolated point) or a square sliding in a slot of its own width (a segment). They are
the positions inside ``E`` where the interiors do not overlap; polycontact finds them
separately (see :mod:`polycontact._kernels.fits`) and reports them as
:attr:`NoFitPolygon.exact_fits` and :attr:`NoFitPolygon.slides`.

Examples
--------
>>> import polycontact as pc
>>> a = pc.Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
>>> b = pc.Shape([(0, 0), (3, 0), (3, 3), (0, 3)], holes=[[(1, 1), (2, 1), (2, 2), (1, 2)]])
>>> nfp = pc.no_fit_polygon(a, b, reference="origin")
>>> nfp.region.area, len(nfp.region.interiors), nfp.exact_fits.tolist()
(16.0, 0, [[1.0, 1.0]])
"""

from __future__ import annotations

import functools
import struct
import sys
from collections.abc import Callable
from dataclasses import dataclass, field
from types import SimpleNamespace
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt
import shapely
import shapely.affinity

from ._checks import finite_number
from ._checks import point as point_arg
from ._pieces import pieces_of_geometry, pieces_packed
from .errors import InvalidShapeError, NfpTooLargeError
from . import limits
from .limits import (ANGLE_TOLERANCE, EAR_CLIPPING_MAX, HOLE_WIDTH_FACTOR,
                     RELATIVE_TOLERANCE, ROUNDING_ULPS, SNAP_FACTOR)
from .shape import Shape, ShapeLike, as_shape
from .tolerances import check_range, snap_grid, tolerance_for

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from shapely.geometry.base import BaseGeometry

    from .relation import State

__all__ = ["NoFitPolygon", "no_fit_polygon", "inner_fit_polygon", "fallback_count"]

#: The empty exact fits and slides of most results, shared: read-only (and empty).
_NO_FITS = np.empty((0, 2))
_NO_FITS.flags.writeable = False
_NO_SLIDES = np.empty((0, 2, 2))
_NO_SLIDES.flags.writeable = False
_NO_CANDIDATES = np.empty((0, 4))
_NO_CANDIDATES.flags.writeable = False

#: The reference "origin" of every result that asks for it, shared: read-only.
_ORIGIN = np.zeros(2)
_ORIGIN.flags.writeable = False

#: The outline kernel's status when the clipping would take more tests than allowed.
_TOO_MANY_TESTS = -2.0

#: How many regions GEOS has built since import because the outline parts did not link
#: into rings (see :func:`fallback_count`).
_FALLBACKS = 0


def fallback_count() -> int:
    """How many no-fit (or inner-fit) regions were built by the GEOS fallback.

    The outline of the union of sums is assembled by polycontact's own kernel; if its
    parts ever fail to link into rings (they always should), GEOS unions the sums
    instead. That path is correct but hides a defect of the assembly, so it is counted:
    the test suite asserts that the count stays zero over its corpora.

    Examples
    --------
    >>> import polycontact as pc
    >>> before = fallback_count()
    >>> _ = pc.no_fit_polygon([(0, 0), (1, 0), (1, 1)], [(0, 0), (2, 0), (0, 2)])
    >>> fallback_count() - before
    0
    """
    return _FALLBACKS


@functools.cache
def _kernels() -> SimpleNamespace:
    """The compiled kernels, imported on first use (Numba loads only when needed)."""
    from ._kernels import fits, minkowski, nfp

    return SimpleNamespace(nfp=nfp, minkowski=minkowski, fits=fits)


#: WKB header of a one-ring polygon in the machine's byte order (that of the kernels'
#: float64 coordinates): byte order, type 3, rings, points.
_WKB_POLYGON = struct.Struct("=BIII")
_WKB_BYTE_ORDER = 1 if sys.byteorder == "little" else 0

@dataclass(frozen=True, eq=False)
class NoFitPolygon:
    """The no-fit polygon of A orbiting a fixed B.

    ``region`` is built on first access and cached: :func:`no_fit_polygon` keeps the
    outline's rings as its kernel returned them (private arrays) and makes the Shapely
    geometry only when asked for it, as a nesting code that tests a few placements
    against most of its no-fit polygons never needs. The object is immutable, so the
    cached geometry cannot go stale; pickling and copying carry the built geometry. The
    coordinates are also offered as data, without a geometry: :attr:`rings`.

    Attributes
    ----------
    region : shapely Polygon or MultiPolygon
        The closed set of reference positions where A touches or overlaps B, with its
        true holes (positions where A sits in a hole or concavity of B, or B in a hole
        of A, without touching), and no holes narrower than the tolerance.
    exact_fits : ndarray of shape (P, 2), float64
        Isolated reference positions inside ``region`` where A touches B without
        overlapping (every small move makes them overlap). Read-only, as every array
        of the result.
    slides : ndarray of shape (S, 2, 2), float64
        Segments inside ``region`` along which A touches B without overlapping, each
        as its two end points.
    reference : ndarray of shape (2,), float64
        A's reference point ``a0`` (A at its given coordinates has it there).
    a, b : Shape
        The orbiting and the fixed shape.
    tolerance : float
        Absolute distance tolerance used.

    Examples
    --------
    >>> import polycontact as pc
    >>> sq = pc.Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
    >>> slot = pc.Shape([(0, 0), (3, 0), (3, 3), (2, 3), (2, 1), (1, 1), (1, 3), (0, 3)])
    >>> nfp = pc.no_fit_polygon(sq, slot, reference="origin")
    >>> nfp.region.area, nfp.exact_fits.tolist(), nfp.slides.tolist()
    (16.0, [], [[[1.0, 1.0], [1.0, 3.0]]])
    """

    region: BaseGeometry
    exact_fits: np.ndarray
    slides: np.ndarray
    reference: np.ndarray
    a: Shape = field(repr=False)
    b: Shape = field(repr=False)
    tolerance: float = 0.0

    if not TYPE_CHECKING:  # (mypy keeps checking attribute names)

        def __getattr__(self, name: str) -> Any:
            # ``region`` of a result of no_fit_polygon is built from the kernel's rings
            # (``_rings``) on first access. Only called for attributes not found the
            # normal way.
            d = self.__dict__
            rings = d.get("_rings") if name == "region" else None
            if rings is None:
                raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")
            region = d["region"] = _region_of(*rings)
            return region

    def __getstate__(self) -> dict[str, Any]:
        # pickles and copies carry the geometry, not the private rings (an unpickled
        # array would be writable again)
        state = dict(self.__dict__, region=self.region)
        state.pop("_rings", None)
        return state

    def __setstate__(self, state: dict[str, Any]) -> None:
        # (unpickled arrays are writable: a result's are not)
        for key in ("exact_fits", "slides", "reference"):
            state[key].flags.writeable = False
        self.__dict__.update(state)

    @property
    def rings(self) -> tuple[np.ndarray, ...]:
        """The region's boundary as coordinates: read-only (n, 2) float64 arrays,
        each ring closed (its first vertex repeated last), outer boundaries
        counter-clockwise and holes clockwise, polygon by polygon (each exterior
        followed by its holes), the same coordinates as ``region``'s.

        A region of one ring (the common case) is given without building ``region``.

        Returns
        -------
        tuple of ndarray of shape (n, 2)

        Examples
        --------
        >>> import polycontact as pc
        >>> sq = pc.Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
        >>> pc.no_fit_polygon(sq, sq, reference="origin").rings[0].tolist()
        [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0], [-1.0, -1.0]]
        """
        rings = self.__dict__.get("_rings")
        if rings is not None and _one_ring(*rings):
            # (the kernel's array, private until now: read-only from here on)
            buf, _, vertices, _ = rings
            buf.setflags(write=False)
            return (buf[: 2 * int(vertices)].reshape(-1, 2),)
        out = []
        for part in shapely.get_parts(shapely.orient_polygons(self.region)):
            if part.is_empty:
                continue
            for ring in (part.exterior, *part.interiors):
                xy = shapely.get_coordinates(ring)
                xy.flags.writeable = False
                out.append(xy)
        return tuple(out)

    def contains(self, point: npt.ArrayLike, *, tolerance: float | None = None) -> State:
        """How A placed with its reference at ``point`` relates to B.

        Parameters
        ----------
        point : (x, y)
            Where A's reference point goes.
        tolerance : float, optional
            As for :func:`polycontact.classify`.

        Returns
        -------
        State
            The state :func:`polycontact.classify` gives for A moved so that its
            reference is at ``point``, against B: ``PENETRATING`` inside the region
            (except on exact fits and slides), ``CONTACT`` on its boundary, exact fits
            and slides, ``SEPARATE`` outside.

        Examples
        --------
        >>> import polycontact as pc
        >>> sq = pc.Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
        >>> nfp = pc.no_fit_polygon(sq, sq, reference="origin")
        >>> [nfp.contains(p).value for p in [(0, 0), (1, 0.5), (2, 0)]]
        ['penetrating', 'contact', 'separate']
        """
        from .relation import classify

        p = point_arg(point, "point")
        moved = self.a.moved(p - self.reference)
        return classify(moved, self.b, tolerance=tolerance).state

    @property
    def outline(self) -> BaseGeometry:
        """The region's boundary (every ring) as a shapely geometry."""
        return self.region.boundary

    @property
    def __geo_interface__(self) -> dict[str, Any]:
        """The region as a GeoJSON-like (Multi)Polygon mapping, for Shapely, GeoPandas
        and other geometry libraries (exact fits and slides are in :meth:`to_dict`)."""
        return dict(self.region.__geo_interface__)

    def to_dict(self) -> dict[str, Any]:
        """The no-fit polygon as a JSON-ready dict: the object ``polycontact nfp --json``
        prints.

        Returns
        -------
        dict
            ``reference`` (``[x, y]``), ``region`` (GeoJSON), ``area``, ``holes`` (their
            number), ``exact_fits`` (``[[x, y], ...]``), ``slides`` (``[[[x0, y0],
            [x1, y1]], ...]``) and ``tolerance``.

        Examples
        --------
        >>> import polycontact as pc
        >>> sq = pc.Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
        >>> d = pc.no_fit_polygon(sq, sq.moved((3, 0))).to_dict()
        >>> d["area"], d["holes"], d["region"]["type"]
        (4.0, 0, 'Polygon')
        """
        import json

        return {
            "reference": self.reference.tolist(),
            "region": json.loads(shapely.to_geojson(self.region)),
            "area": float(self.region.area),
            "holes": sum(len(g.interiors) for g in shapely.get_parts(self.region)),
            "exact_fits": self.exact_fits.tolist(),
            "slides": self.slides.tolist(),
            "tolerance": float(self.tolerance),
        }

    def plot(self, ax: Axes | None = None, *,
             placement: npt.ArrayLike | None = None) -> Axes:
        """Draw B, the region with its holes, exact fits and slides, and A at
        ``placement``.

        Parameters
        ----------
        ax : matplotlib Axes, optional
            Drawn into a new figure when omitted.
        placement : (x, y), optional
            Where A's reference point is drawn (see
            :func:`polycontact.plotting.plot_nfp`).

        Returns
        -------
        matplotlib Axes

        Examples
        --------
        >>> import polycontact as pc
        >>> sq = pc.Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
        >>> ax = pc.no_fit_polygon(sq, sq.moved((3, 0))).plot(placement=(2.5, 0.5))
        """
        from .plotting.nfp import plot_nfp

        return plot_nfp(self, placement, ax)


def no_fit_polygon(
    a: ShapeLike, b: ShapeLike, reference: npt.ArrayLike | None = None, *,
    tolerance: float | None = None
) -> NoFitPolygon:
    """No-fit polygon of ``a`` orbiting the fixed ``b``.

    Parameters
    ----------
    a, b : ShapeLike
        The orbiting and the fixed shape; holes allowed.
    reference : None, "centroid", "origin" or array_like of shape (2,)
        A's reference point: its area centroid (default), the origin (plain
        translations of A's coordinates, the convention of nesting codes), or a point.
    tolerance : float, optional
        Absolute distance tolerance; default
        :func:`polycontact.default_tolerance` of the sums' coordinates.

    Returns
    -------
    NoFitPolygon

    Examples
    --------
    >>> import polycontact as pc
    >>> a = pc.Shape([(0, 0), (2, 0), (2, 1), (0, 1)])
    >>> nfp = pc.no_fit_polygon(a, a, reference="origin")
    >>> nfp.region.bounds, nfp.region.area
    ((-2.0, -1.0, 2.0, 1.0), 8.0)

    Notes
    -----
    Cost, for A of m and B of n vertices cut into k_A and k_B convex pieces: the
    decomposition (ear clipping up to 64 vertices, redone on each call; GEOS's
    constrained triangulation beyond and with holes, cached by coordinates), then
    k_A k_B convex sums of O(k_A n + k_B m) vertices in all, each sum in linear time.
    Only the sum edges on the reduced convolution (a convex vertex of one body with an
    edge of the other whose direction fits its turning cone: the only places where the
    bodies can touch without overlapping) can hold the outline, exact fits and slides;
    each is clipped by the sums listed in the cells of a grid along it (those within
    the tolerance of the cell), starting from the sum that covered the previous edge,
    each long sum from its edge facing the segment. The time thus follows the size of
    the reduced convolution times the sums met near it, not the product of all edges
    with all sums (figures: ``benchmarks/bench_bounds.py`` and
    ``benchmarks/bench_scaling.py``).

    Refused before the work, with :class:`~polycontact.NfpTooLargeError` naming the
    estimate and the limit: sums of more than
    :data:`~polycontact.limits.MAX_SUM_VERTICES` vertices (memory), or a clipping of
    more than :data:`~polycontact.limits.MAX_CLIP_TESTS` edge–sum tests (time; the
    sums listed near each edge, counted once the sums are built). Both are read at
    each call: set ``polycontact.limits.MAX_CLIP_TESTS`` (or ``MAX_SUM_VERTICES``) to
    allow more.
    """
    a = as_shape(a, "a")
    b = as_shape(b, "b")
    a0 = _reference(a, reference, b)

    def pieces() -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        bxy, bst = _convex_pieces(b)
        axy, ast = _convex_pieces(a)
        return bxy, bst, a0 - axy, ast

    xa, sa = a.packed
    xb, sb = b.packed
    out = None
    if len(sa) == 2 and len(sb) == 2:
        # two rings: decomposed and summed in one kernel call (see polycontact._pieces)
        ax, ay = a0.tolist()
        out = _kernels().nfp.ring_entrance(
            xb, xa, ax, ay, _tolerance(tolerance), RELATIVE_TOLERANCE, ROUNDING_ULPS,
            ANGLE_TOLERANCE, SNAP_FACTOR, HOLE_WIDTH_FACTOR, EAR_CLIPPING_MAX,
            limits.MAX_SUM_VERTICES, limits.MAX_CLIP_TESTS)
    if out is None or not out[0][0]:
        out = _entrance_kernel(*pieces(), tolerance)
    region, pts, segs, eps = _entrance_result(out, pieces)
    fits, slides = _clean_degenerate(pts, segs, eps, lambda: _touching(a, b, a0, eps))
    for array in (fits, slides, a0):
        if array is not _NO_FITS and array is not _NO_SLIDES and array is not _ORIGIN:
            array.flags.writeable = False  # a result cannot be changed (shared ones are not)
    # Built as the frozen dataclass's __init__ would, at a fraction of its cost; with
    # the kernel's rings, ``region`` is made on first access (NoFitPolygon.__getattr__)
    nfp = _new(NoFitPolygon)
    _set_dict(nfp, "__dict__", {
        "exact_fits": fits, "slides": slides, "reference": a0, "a": a, "b": b,
        "tolerance": eps, ("_rings" if type(region) is tuple else "region"): region})
    return nfp


_new = object.__new__
_set_dict = object.__setattr__


def inner_fit_polygon(
    a: ShapeLike, container: ShapeLike, reference: npt.ArrayLike | None = None, *,
    tolerance: float | None = None
) -> BaseGeometry:
    """Reference positions at which ``a`` lies inside ``container`` (touching allowed).

    The inner-fit polygon of nesting: with ``container`` a bin (or a hole, passed as a
    shape of its own), the positions where A can be placed. It is the set of positions
    where A does not overlap the complement of the container, i.e. a box around the
    container minus E(A, box \\ container), plus the exact fits and slides of that
    entrance block: a piece exactly as wide as the bin slides along a segment, a piece
    that fits exactly sits at a point.

    Parameters
    ----------
    a, container : ShapeLike
    reference, tolerance :
        As in :func:`no_fit_polygon`.

    Returns
    -------
    shapely geometry
        A Polygon or MultiPolygon when the free positions have area; a point, segment or
        GeometryCollection (areas, points, segments) otherwise; empty when A cannot fit.

    Examples
    --------
    >>> import polycontact as pc
    >>> bin_ = pc.Shape([(0, 0), (10, 0), (10, 4), (0, 4)])
    >>> pc.inner_fit_polygon([(0, 0), (2, 0), (2, 1), (0, 1)], bin_, "origin").bounds
    (0.0, 0.0, 8.0, 3.0)
    >>> pc.inner_fit_polygon([(0, 0), (2, 0), (2, 4), (0, 4)], bin_, "origin").wkt
    'LINESTRING (0 0, 8 0)'
    """
    a = as_shape(a, "a")
    c = as_shape(container, "container")
    a0 = _reference(a, reference, c)
    axy, ast = _convex_pieces(a)
    r = a0 - axy
    span = float(np.max(np.ptp(a.exterior, axis=0)))
    x0, y0 = c.exterior.min(axis=0) - 2.0 * span - 1.0
    x1, y1 = c.exterior.max(axis=0) + 2.0 * span + 1.0
    outside = shapely.box(x0, y0, x1, y1).difference(c.to_shapely())
    fxy, fst = pieces_of_geometry(outside)
    blocked, pts, segs, eps = _entrance_result(
        _entrance_kernel(fxy, fst, r, ast, tolerance), lambda: (fxy, fst, r, ast))
    if type(blocked) is tuple:
        blocked = _region_of(*blocked)
    cx0, cy0 = c.exterior.min(axis=0) + r.min(axis=0)
    cx1, cy1 = c.exterior.max(axis=0) + r.max(axis=0)
    free = shapely.box(cx0, cy0, cx1, cy1).difference(blocked)
    free = _drop_slivers(free, eps)
    c_poly = c.to_shapely()
    a_poly = a.to_shapely()

    def fits(p: np.ndarray) -> bool:
        placed = shapely.affinity.translate(a_poly, *(p - a0))
        spill = placed.difference(c_poly)
        return bool(spill.area <= eps * (placed.length + c_poly.length))

    def check(pts: np.ndarray, segs: np.ndarray) -> tuple[list[bool], list[bool]]:
        return [fits(p) for p in pts], [
            fits(0.5 * (s[:2] + s[2:])) and fits(s[:2]) and fits(s[2:]) for s in segs]

    fit_pts, slide_segs = _clean_degenerate(pts, segs, eps, lambda: _checked(check))
    parts = [free] if not free.is_empty else []
    parts += [shapely.Point(p) for p in fit_pts]
    parts += [shapely.LineString(s) for s in slide_segs]
    if not parts:
        return shapely.Polygon()
    return shapely.union_all(parts)


# -- helpers -----------------------------------------------------------------------------


def _reference(a: Shape, reference: Any, b: Shape) -> np.ndarray:
    """A's reference point, refused when the region around it cannot be represented.

    The region's coordinates reach about ``|a0| + |A| + |B|``; if the default tolerance
    there (:func:`polycontact.tolerances.tolerance_for`) is as large as the smaller body,
    float64 cannot tell the region's features apart (a unit square with its reference
    at 1e100 had an empty region): the reference is refused, never answered wrongly.
    """
    if reference is None or (isinstance(reference, str) and reference == "centroid"):
        return np.array(a.centroid, dtype=np.float64)
    if isinstance(reference, str):
        if reference != "origin":
            raise ValueError(
                f"reference: expected 'centroid', 'origin' or a point (x, y), "
                f"got {reference!r}"
            )
        a0, off = _ORIGIN, 0.0
    else:
        a0 = point_arg(reference, "reference")
        check_range(a0.reshape(1, 2), "reference")
        off = float(np.abs(a0).max())
    # the shapes' largest |coordinate| and extent are cached on them
    reach = off + a._magnitude + b._magnitude
    size = min(a._extent, b._extent)
    if tolerance_for(0.0, reach) >= size:
        raise ValueError(
            f"reference ({a0[0]:g}, {a0[1]:g}): the region's coordinates reach {reach:g}, "
            f"where float64's rounding tolerance {tolerance_for(0.0, reach):g} is not "
            f"below the bodies' size {size:g}; choose a reference nearer the bodies"
        )
    return a0


def _tolerance(tolerance: float | None) -> float:
    """The tolerance for the kernel: -1 asks it for the default of the sums' coordinates."""
    if tolerance is None:
        return -1.0
    return finite_number(tolerance, "tolerance", positive=True)


def _convex_pieces(shape: Shape) -> tuple[np.ndarray, np.ndarray]:
    """Convex CCW pieces of a shape, packed; cached by coordinates."""
    return pieces_packed(*shape.packed)


def _entrance_kernel(
    bxy: np.ndarray, bst: np.ndarray, rxy: np.ndarray, rst: np.ndarray, tolerance: float | None
) -> tuple[Any, ...]:
    """The outline kernel's answer for E = B ⊕ R from convex pieces (see
    :func:`_entrance_result`); too many sums' vertices are refused first."""
    total = len(bxy) * (len(rst) - 1) + len(rxy) * (len(bst) - 1)
    if total > limits.MAX_SUM_VERTICES:
        raise NfpTooLargeError(
            f"no-fit polygon: the {len(bst) - 1} x {len(rst) - 1} convex sums of the "
            f"shapes' pieces would hold {total:.3g} vertices, more than "
            f"limits.MAX_SUM_VERTICES = {limits.MAX_SUM_VERTICES:.3g} (memory); set "
            f"polycontact.limits.MAX_SUM_VERTICES to allow more"
        )
    out: tuple[Any, ...] = _kernels().nfp.entrance_packed(
        bxy, bst, rxy, rst, _tolerance(tolerance), RELATIVE_TOLERANCE, ROUNDING_ULPS,
        ANGLE_TOLERANCE, SNAP_FACTOR, HOLE_WIDTH_FACTOR, limits.MAX_CLIP_TESTS
    )
    return out


def _entrance_result(
    out: tuple[Any, ...], pieces: Callable[[], tuple[np.ndarray, ...]]
) -> tuple[Any, np.ndarray, np.ndarray, float]:
    """(region, candidate fits, candidate slides, eps) from the kernel's answer ``out``
    (:func:`polycontact._kernels.nfp.entrance_packed`) for E = B ⊕ R.

    The outline is assembled from the uncovered parts of the sums' edges (see
    :mod:`polycontact._kernels.nfp`); the region is then given as the arguments of
    :func:`_region_of` (a tuple: the kernel's array, its numbers of rings and vertices,
    and the width under which a ring is dropped), for the caller to build when needed. If the parts do not link
    into rings (they always should), GEOS unions the sums of the convex pieces
    ``pieces()`` (B's, then R's) instead, and the region is that geometry. Rings
    thinner than the tolerance (rounding seams and pinholes) are dropped.
    """
    (_, eps, status, n_pts, n_rings, n_vertices, n_cand, tests), buf = out
    if status == _TOO_MANY_TESTS:
        raise NfpTooLargeError(
            f"no-fit polygon: clipping the edges of its convex sums would take about "
            f"{tests:.3g} edge–sum tests (the sums near each edge that can lie on the "
            f"outline, counted before clipping), more than limits.MAX_CLIP_TESTS = "
            f"{limits.MAX_CLIP_TESTS:.3g} (time); set polycontact.limits.MAX_CLIP_TESTS "
            f"to allow more"
        )
    if status < 0.0:
        raise InvalidShapeError(
            "no-fit polygon: the Minkowski sums of the shapes overflow float64 "
            "(coordinates or reference point too large)"
        )
    region: Any
    if status:
        region = (buf, n_rings, n_vertices, HOLE_WIDTH_FACTOR * eps)
    else:
        global _FALLBACKS
        _FALLBACKS += 1
        sums, starts, _ = _kernels().minkowski.convex_sums(*pieces())
        ids = np.repeat(np.arange(len(starts) - 1), np.diff(starts))
        region = _union_of_sums(shapely.polygons(shapely.linearrings(sums, indices=ids)), eps)
    if not n_cand:
        return region, _NO_FITS, _NO_CANDIDATES, eps
    cand = _unpack(buf, n_rings, n_vertices)[3]
    return region, cand[: int(n_pts), :2], cand[int(n_pts) :], eps


def _unpack(
    buf: np.ndarray, rings: float, vertices: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``(ring_xy, ring_starts, ring_stats, candidates)`` of
    :func:`polycontact._kernels.nfp.entrance_region` from the ``buf`` of
    :func:`~polycontact._kernels.nfp.entrance_packed` and its numbers of rings and
    vertices: views of ``buf`` (the starts a copy, as integers)."""
    nr = int(rings)
    nv = int(vertices)
    s = 2 * nv + nr + 1
    return (buf[: 2 * nv].reshape(nv, 2), buf[2 * nv : s].astype(np.int64),
            buf[s : s + 2 * nr].reshape(nr, 2), buf[s + 2 * nr :].reshape(-1, 4))


def _region_of(buf: np.ndarray, rings: float, vertices: float, width: float) -> Any:
    """The region from the kernel's rings (``_rings`` of a :class:`NoFitPolygon`, see
    :func:`_entrance_result`)."""
    if _one_ring(buf, rings, vertices, width):
        # one ring, the common case: WKB is the quickest way to hand it to GEOS
        nv = int(vertices)
        header = _WKB_POLYGON.pack(_WKB_BYTE_ORDER, 3, 1, nv)
        return shapely.from_wkb(header + buf[: 2 * nv].tobytes())
    return _polygon_from_rings(*_unpack(buf, rings, vertices)[:3], width)


def _union_of_sums(polys: Any, eps: float) -> Any:
    """GEOS union of convex sums (the fallback of :func:`_entrance_result`), slivers dropped.

    On a snap-rounding grid (:func:`polycontact.tolerances.snap_grid`): GEOS's floating
    union of polygons whose edges lie a few ulps apart can drop whole pieces.
    """
    return _drop_slivers(shapely.union_all(polys, grid_size=snap_grid(eps)), eps)


def _polygon_from_rings(
    xy: np.ndarray, starts: np.ndarray, stats: np.ndarray, width: float
) -> Any:
    """(Multi)Polygon from closed CCW shells and CW holes; rings thinner than width dropped."""
    shells: list[Any] = []
    holes: list[Any] = []
    for k in range(len(starts) - 1):
        area, length = stats[k]
        if 2.0 * abs(area) <= width * length:
            continue
        (shells if area > 0 else holes).append(xy[starts[k] : starts[k + 1]])
    if not shells:
        return shapely.Polygon()
    if len(shells) == 1:
        return shapely.Polygon(shells[0], holes)
    shell_polys = [shapely.Polygon(r) for r in shells]
    owned: list[list[np.ndarray]] = [[] for _ in shells]
    for h in holes:
        nxt = np.roll(h, -1, axis=0)
        i = int(np.argmax(np.hypot(*(nxt - h).T)))
        mx, my = 0.5 * (h[i] + nxt[i])
        inside = [k for k, sp in enumerate(shell_polys) if shapely.contains_xy(sp, mx, my)]
        best = min(inside, key=lambda k: shell_polys[k].area) if inside else 0
        owned[best].append(h)
    return shapely.MultiPolygon([shapely.Polygon(r, hs) for r, hs in zip(shells, owned)])


def _one_ring(buf: np.ndarray, rings: float, vertices: float, width: float) -> bool:
    """Whether the kernel's rings (see :func:`_region_of`) are one shell that is kept
    (not thinner than ``width``): the region is then that ring, without holes."""
    if rings != 1.0:
        return False
    s = 2 * int(vertices) + 2  # the ring's (area, length) follow its coordinates and starts
    return bool(2.0 * buf[s] > width * buf[s + 1])


def _drop_slivers(geom: Any, eps: float) -> Any:
    """Fill holes and drop parts thinner than the tolerance (twice area over length)."""
    width = HOLE_WIDTH_FACTOR * eps
    out = []
    changed = False
    for part in shapely.get_parts(geom):
        if part.geom_type != "Polygon":
            changed = True
            continue
        if 2.0 * part.area <= width * part.exterior.length:
            changed = True
            continue
        holes = [r for r in part.interiors if 2.0 * shapely.Polygon(r).area > width * r.length]
        if len(holes) != len(part.interiors):
            changed = True
            part = shapely.Polygon(part.exterior, holes)
        out.append(part)
    if not changed:
        return geom
    if not out:
        return shapely.Polygon()
    return out[0] if len(out) == 1 else shapely.MultiPolygon(out)


def _touching(
    a: Shape, b: Shape, a0: np.ndarray, eps: float
) -> Callable[[np.ndarray, np.ndarray, float], tuple[np.ndarray, np.ndarray]]:
    """The selection of :func:`_clean_degenerate` for the no-fit polygon: the candidates
    where A with its reference there (at a slide's middle and both ends) touches B
    without overlapping, verified by the classifier and selected in one kernel call."""
    touching_contacts = _kernels().fits.touching_contacts
    xa, sa = a.packed
    xb, sb = b.packed
    tol = HOLE_WIDTH_FACTOR * eps
    ax, ay = a0.tolist()

    def select(pts: np.ndarray, segs: np.ndarray, near: float) -> Any:
        return touching_contacts(np.ascontiguousarray(pts), segs, near, xa, sa, xb, sb, ax,
                                 ay, tol)

    return select


def _checked(
    check: Callable[[np.ndarray, np.ndarray], tuple[Any, Any]]
) -> Callable[[np.ndarray, np.ndarray, float], tuple[np.ndarray, np.ndarray]]:
    """The selection of :func:`_clean_degenerate` from a predicate ``check(pts, segs)``:
    whether each point (P, 2) and each slide (S, 4: its middle and both ends) verifies,
    two bool sequences."""

    def select(pts: np.ndarray, segs: np.ndarray, near: float) -> Any:
        pts_ok, segs_ok = check(pts, segs)
        return _kernels().fits.select_contacts(
            np.ascontiguousarray(pts), np.asarray(pts_ok, dtype=np.bool_), segs,
            np.asarray(segs_ok, dtype=np.bool_), near)

    return select


def _clean_degenerate(
    pts: np.ndarray, segs: np.ndarray, eps: float, make_select: Any
) -> tuple[np.ndarray, np.ndarray]:
    """The verified exact fits and slides among the candidates, duplicates merged.

    The candidates found on the edges with the margin ``eps`` are within a few eps of
    the true positions; exact fits and slide ends are vertices of some sum or crossings
    of sum edges, and the kernel has snapped them to those (within
    ``SNAP_FACTOR * eps``) and merged collinear slides. ``make_select()`` gives
    ``select(pts, segs, near)``: the verified candidates with fits on a kept slide or
    near a kept fit dropped (:func:`polycontact._kernels.fits.select_contacts`, after
    the no-fit polygon's check :func:`_touching` or any other, :func:`_checked`).
    """
    if len(pts) == 0 and len(segs) == 0:
        return _NO_FITS, _NO_SLIDES
    if len(pts) > 1:
        # the same exact fit, found on every edge through it, is verified once (the
        # first of equal points is the one the selection would keep)
        pts = pts[np.sort(np.unique(pts, axis=0, return_index=True)[1])]
    fits, slides = make_select()(pts, segs, HOLE_WIDTH_FACTOR * eps)
    return (fits if len(fits) else _NO_FITS), (slides if len(slides) else _NO_SLIDES)
