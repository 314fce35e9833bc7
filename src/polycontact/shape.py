"""Shapes: an outer loop and any number of holes, validated and normalised.

Frame convention (followed everywhere in polycontact): coordinates are float64 in one
fixed world frame, x to the right and y up; angles are radians, counter-clockwise
positive. Outer loops are stored counter-clockwise and holes clockwise, whatever order
the caller gave, so "interior on the left" holds for every edge. Loop 0 is the outer
loop, loops 1.. are the holes in the order given. Vertex and edge indices are 0-based;
edge ``k`` of a loop joins its vertex ``k`` and vertex ``(k + 1) % n``. Indices that
leave the library (features, entrance-block elements, the command line) are in the
caller's numbering, the order of the vertices as passed, whatever the stored orientation
and with repeated or closing points counted; :meth:`Shape.input_vertex`,
:meth:`Shape.input_edge` and :meth:`Shape.input_loop` map the stored order
(:attr:`Shape.loops`) to it.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any, Protocol, Union

import numpy as np
import numpy.typing as npt

from ._checks import finite_number, is_real, point, real_array, shown
from ._json import load_json
from .errors import InvalidShapeError
from .motion import Motion
from .tolerances import (
    COORDINATE_LIMIT,
    EXTENT_FLOOR,
    check_range,
    default_tolerance,
    tolerance_for,
)

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from shapely import Polygon
    from shapely.geometry.base import BaseGeometry

__all__ = ["Shape", "ShapeLike", "GeoInterface", "as_shape", "SHAPE_FORMS"]

ArrayLike = Any


def _clean_ring(ring: ArrayLike, what: str) -> np.ndarray:
    """Float64 (N, 2) copy of a ring: closing point and consecutive repeats dropped."""
    if isinstance(ring, (str, bytes)):
        raise TypeError(f"{what}: expected an array of real numbers, got {type(ring).__name__}")
    try:
        arr = real_array(ring, what, InvalidShapeError)
    except TypeError:
        where = _first_unreal(ring)
        if where is None:
            raise
        i, x = where
        value = x.item() if isinstance(x, np.generic) else x  # 0j, not np.complex128(0j)
        raise TypeError(f"{what}: vertex {i}: expected real numbers, got {shown(value)} "
                        f"({type(x).__name__})") from None
    if arr.ndim != 2 or arr.shape[1] != 2:
        raise InvalidShapeError(
            f"{what}: expected an array of shape (N, 2), got shape {arr.shape}"
        )
    bad = ~np.isfinite(arr).all(axis=1)
    if bad.any():
        i = int(np.flatnonzero(bad)[0])
        raise InvalidShapeError(
            f"{what}: vertex {i} has a non-finite coordinate {arr[i].tolist()}"
        )
    if len(arr) == 0:
        raise InvalidShapeError(f"{what}: no vertices")
    check_range(arr, what)
    keep = np.ones(len(arr), dtype=bool)
    keep[1:] = np.any(arr[1:] != arr[:-1], axis=1)
    arr = arr[keep]
    while len(arr) > 1 and np.all(arr[-1] == arr[0]):
        arr = arr[:-1]
    if len(arr) < 3 or len(np.unique(arr, axis=0)) < 3:
        raise InvalidShapeError(
            f"{what}: fewer than 3 distinct vertices ({len(np.unique(arr, axis=0))})"
        )
    return arr


def _whole_shape(obj: Any) -> bool:
    """Whether ``obj`` is a shape in a form other than an array of vertices: a Shape, a
    Shapely geometry, anything with ``__geo_interface__``, a mapping, text or WKB."""
    return (isinstance(obj, (Shape, str, bytes, bytearray, memoryview, Mapping))
            or hasattr(obj, "__geo_interface__") or hasattr(obj, "geom_type"))


def _other_form(obj: Any, holes: Sequence[ArrayLike], repair: bool) -> Shape:
    """The Shape of a shape given in a form other than an array (see
    :func:`_whole_shape`), through :func:`as_shape`; such a form carries its own holes."""
    if len(list(holes)):
        raise TypeError(f"holes: a {type(obj).__name__} carries its own holes; pass "
                        "holes only with an array of vertices")
    return as_shape(obj, "vertices", repair=repair)


#: The forms a shape may take, as error messages list them.
SHAPE_FORMS = "Shape, (N, 2) array, shapely Polygon, GeoJSON or vertices mapping, WKT, WKB"

_MAPPING_KEYS = {"vertices", "holes", "name"}
_HEX = re.compile(r"(?:[0-9A-Fa-f]{2})+")


def as_shape(obj: ShapeLike, what: str = "shape", *, repair: bool = False) -> Shape:
    """``obj`` as a :class:`Shape`, whatever form it is given in.

    Everywhere polycontact takes a shape (the functions, :class:`Shape` itself,
    ``classify_many``, worlds, scenes, the command line) it accepts the same forms:

    - a :class:`Shape` (returned as it is);
    - an array-like of shape (N, 2): the outer loop, closed or not, either orientation;
    - a Shapely ``Polygon`` (or a ``MultiPolygon`` of exactly one part);
    - anything with ``__geo_interface__`` (GeoPandas, other geometry libraries);
    - a GeoJSON mapping: ``Polygon``, a ``MultiPolygon`` of one part, or a ``Feature``
      holding one;
    - a vertices mapping ``{"vertices": [[x, y], ...], "holes": [...]}`` (an optional
      ``"name"`` is ignored), the form of the scene files' bodies;
    - WKT text (``"POLYGON ((0 0, 1 0, 0 1, 0 0))"``), JSON text of one of the mappings
      above or of a list of vertices (``"[[0, 0], [1, 0], [0, 1]]"``), WKB bytes or hex
      WKB text.

    ``Shape(obj)`` takes every one of these forms too; ``as_shape`` names the argument
    in its errors, which is what a function of your own wants.

    Parameters
    ----------
    obj : ShapeLike
        One of the forms above.
    what : str, default "shape"
        The argument's name, put at the start of every error message.
    repair : bool, default False
        Passed to :class:`Shape`: try ``shapely.make_valid`` on an invalid polygon.

    Returns
    -------
    Shape
        ``obj`` itself when it is already a Shape.

    Raises
    ------
    TypeError
        ``obj`` is of no accepted type (the message names ``what``).
    InvalidShapeError
        ``obj`` is of an accepted type but not a valid polygon (a ``ValueError``).

    Examples
    --------
    >>> import shapely
    >>> forms = [
    ...     [(0, 0), (1, 0), (1, 1), (0, 1)],
    ...     shapely.box(0, 0, 1, 1),
    ...     {"type": "Polygon", "coordinates": [[[0, 0], [1, 0], [1, 1], [0, 1], [0, 0]]]},
    ...     {"vertices": [[0, 0], [1, 0], [1, 1], [0, 1]]},
    ...     "POLYGON ((0 0, 1 0, 1 1, 0 1, 0 0))",
    ...     shapely.box(0, 0, 1, 1).wkb,
    ... ]
    >>> [as_shape(f).area for f in forms]
    [1.0, 1.0, 1.0, 1.0, 1.0, 1.0]
    >>> as_shape(3, "a")
    Traceback (most recent call last):
    ...
    TypeError: a: expected a shape (Shape, (N, 2) array, shapely Polygon, GeoJSON or vertices mapping, WKT, WKB), got int
    """
    if isinstance(obj, Shape):
        return obj
    try:
        return _coerce(obj, repair)
    except InvalidShapeError as exc:
        raise InvalidShapeError(f"{what}: {exc}") from None
    except TypeError as exc:
        raise TypeError(f"{what}: {exc}") from None


def _coerce(obj: Any, repair: bool) -> Shape:
    if isinstance(obj, (bytes, bytearray, memoryview)):
        return Shape.from_shapely(_from_wkb(bytes(obj)), repair=repair)
    if isinstance(obj, str):
        return _from_text(obj, repair)
    if hasattr(obj, "geom_type") and hasattr(obj, "wkb"):  # a shapely geometry
        return Shape.from_shapely(obj, repair=repair)
    if isinstance(obj, Mapping):
        return _from_mapping(obj, repair)
    geo = getattr(obj, "__geo_interface__", None)
    if isinstance(geo, Mapping):
        return _from_mapping(geo, repair)
    if isinstance(obj, (np.ndarray, list, tuple)):
        return Shape(obj, repair=repair)
    raise TypeError(f"expected a shape ({SHAPE_FORMS}), got {type(obj).__name__}")


def _from_mapping(data: Mapping[str, Any], repair: bool) -> Shape:
    if "vertices" in data:
        unknown = sorted(set(data) - _MAPPING_KEYS)
        if unknown:
            raise InvalidShapeError(
                f"unknown key {unknown[0]!r} (a vertices mapping has 'vertices', 'holes', 'name')"
            )
        holes = data.get("holes", ())
        if holes is None or isinstance(holes, (str, bytes, Mapping)):
            raise InvalidShapeError("vertices mapping: 'holes' must be a list of rings")
        return Shape(data["vertices"], holes, repair=repair)
    if "type" in data:
        return Shape.from_geojson(dict(data), repair=repair)
    raise InvalidShapeError(
        "expected a GeoJSON mapping (with 'type') or a vertices mapping (with 'vertices'), "
        f"got keys {sorted(map(str, data))}"
    )


def _from_text(text: str, repair: bool) -> Shape:
    stripped = text.strip()
    if not stripped:
        raise InvalidShapeError("empty text: no shape in it")
    if stripped.startswith(("{", "[")):
        try:
            data = load_json(text)
        except ValueError as exc:
            raise InvalidShapeError(f"not valid JSON ({exc})") from None
        if isinstance(data, list):  # the vertices alone: [[x, y], ...]
            return Shape(data, repair=repair)
        if not isinstance(data, Mapping):
            raise InvalidShapeError("JSON text: expected an object or a list of vertices")
        return _from_mapping(data, repair)
    if _HEX.fullmatch(stripped):  # hex WKB, as shapely's ``wkb_hex``
        return Shape.from_shapely(_from_wkb(bytes.fromhex(stripped)), repair=repair)
    return Shape.from_wkt(text, repair=repair)


def _from_wkb(data: bytes) -> Any:
    import shapely

    if not data:
        raise InvalidShapeError("empty WKB: no shape in it")
    try:
        return shapely.from_wkb(data)
    except Exception as exc:  # noqa: BLE001 - GEOS raises its own error types
        raise InvalidShapeError(f"not valid WKB ({exc})") from None


def _first_unreal(ring: ArrayLike) -> tuple[int, Any] | None:
    """``(vertex, coordinate)``: the first coordinate of ``ring`` that is not a real number
    (a string, a bool, a complex number, None...); None if no vertex holds one (for the
    message of a ring refused for its type)."""
    if not isinstance(ring, (list, tuple, np.ndarray)):  # (a set or a mapping has no order)
        return None
    for i, row in enumerate(ring):
        if isinstance(row, (str, bytes)) or not hasattr(row, "__iter__"):
            if not is_real(row):
                return i, row
            continue
        for x in row:
            if not is_real(x):
                return i, x
    return None


def _loop_name(k: int) -> str:
    return "outer loop" if k == 0 else f"hole {k - 1}"


class Shape:
    """A closed polygonal region: an outer loop and zero or more holes.

    Parameters
    ----------
    vertices : array_like of shape (N, 2), or a whole shape (ShapeLike)
        The outer loop, closed or not, in either orientation. Or a shape in any other
        form polycontact takes (:func:`as_shape`), holes included: a Shape, a
        Shapely ``Polygon``, anything with ``__geo_interface__``, a GeoJSON or vertices
        mapping ``{"vertices": ..., "holes": ...}``, WKT or JSON text, WKB.
    holes : sequence of array_like of shape (M, 2), optional
        Hole loops, closed or not, in either orientation (None or empty: no holes).
        Only with an array of vertices: the other forms carry their own holes.
    repair : bool, default False
        If the loops are invalid, try ``shapely.make_valid(method="structure")`` and keep
        the result when it is a single polygon, valid exactly and within the tolerance
        of the loops (where GEOS's result moves the outline further, the loops are read
        from GEOS's noding instead; where it still meets itself, it is snap-rounded onto
        a grid far finer than the tolerance: ``shapely.set_precision``).
        Every vertex of the result lies within the tolerance of the loops.
        :attr:`repairs` then says what changed. Indices still refer to the caller's
        vertices where the repaired loops keep them (or, snapped, keep them within one
        grid step); a vertex or edge the repair created has none (see
        :meth:`input_vertex`).

    Raises
    ------
    InvalidShapeError
        Fewer than 3 distinct vertices, a non-finite coordinate, a coordinate beyond
        ±1e100 or an extent below 1e-100 (see :func:`polycontact.tolerances.check_range`),
        zero area, a self-intersection (with its point and the two edges), a zero-width
        spike, a hole outside or crossing its outer loop, overlapping holes, holes that
        cut the solid in pieces. Every test is exact for the float64 coordinates given
        (exact orientations): features are defects only where they truly meet, however
        close they come otherwise, so a polygon GEOS calls valid is accepted at every
        scale and position. Features closer than the tolerance are then decided as
        touching by the functions that take the shape.
    TypeError
        Coordinates that are not real numbers (strings, booleans, complex numbers: the
        message names the loop and the vertex), or ``holes`` with a form that carries
        its own.

    A Shape is immutable: its arrays are read-only and no attribute can be rebound.

    Examples
    --------
    >>> sq = Shape([(0, 0), (0, 2), (2, 2), (2, 0)])    # clockwise: stored reversed
    >>> sq.area, sq.centroid.tolist(), sq.exterior[1].tolist()
    (4.0, [1.0, 1.0], [2.0, 2.0])
    >>> import shapely
    >>> Shape(shapely.box(0, 0, 2, 2)).area, Shape("POLYGON ((0 0, 2 0, 0 2, 0 0))").area
    (4.0, 2.0)
    >>> Shape([(0, 0), (2, 2), (2, 0), (0, 2)])
    Traceback (most recent call last):
    ...
    polycontact.errors.InvalidShapeError: outer loop: self-intersection at (1, 1) between edge 0 and edge 2
    """

    __slots__ = ("_loops", "_xy", "_starts", "_area", "_centroid", "_radius", "repairs",
                 "_frame", "_extent", "_magnitude", "_tolerance", "_input", "_kernel")

    def __setattr__(self, name: str, value: Any) -> None:
        # Each slot is bound once, at construction; only the time-of-impact search's
        # private cache of body-frame tables (``_frame``) is filled in later.
        if name != "_frame" and _bound(self, name):
            raise AttributeError(f"Shape is immutable: cannot rebind {name!r}")
        object.__setattr__(self, name, value)

    def __delattr__(self, name: str) -> None:
        raise AttributeError(f"Shape is immutable: cannot delete {name!r}")

    def __init__(
        self, vertices: ArrayLike, holes: Sequence[ArrayLike] | None = (), *,
        repair: bool = False
    ) -> None:
        if holes is None:
            holes = ()
        if _whole_shape(vertices):
            self._adopt(_other_form(vertices, holes, repair))
            return
        if isinstance(holes, np.ndarray) and holes.ndim == 2:
            raise InvalidShapeError(
                "holes: expected a sequence of (M, 2) loops, got a single (M, 2) array; "
                "wrap it in a list"
            )
        try:
            loops = [_clean_ring(vertices, "outer loop")]
            loops += [_clean_ring(h, f"hole {i}") for i, h in enumerate(holes)]
            given = list(loops)
            self._init_from_loops(loops, repairs=(), rings=[vertices, *holes])
        except InvalidShapeError as exc:
            if not repair:
                raise
            self._init_repaired(vertices, holes, str(exc))
            return
        self._input = _input_maps([vertices, *holes], given, self._loops)

    # -- construction -------------------------------------------------------------
    def _adopt(self, other: Shape) -> None:
        """Take the state of ``other`` (immutable, so its arrays are shared)."""
        for name in Shape.__slots__:
            if _bound(other, name):
                object.__setattr__(self, name, object.__getattribute__(other, name))

    @classmethod
    def _trusted(
        cls,
        loops: Sequence[np.ndarray],
        repairs: tuple[str, ...] = (),
        inputs: tuple[np.ndarray, np.ndarray] | None = None,
    ) -> Shape:
        """Build from loops already oriented and valid (e.g. a rigid motion of a Shape).

        ``inputs`` is the map to the caller's numbering (``_input`` of the shape moved);
        None means the loops are in the caller's numbering already.
        """
        self = cls.__new__(cls)
        self._set(loops, repairs)
        if inputs is None:
            inputs = _identity_map(self._starts)
        self._input = inputs
        return self

    def _set(self, loops: Sequence[np.ndarray], repairs: tuple[str, ...]) -> None:
        lens = [len(r) for r in loops]
        xy = np.ascontiguousarray(np.concatenate(loops), dtype=np.float64)
        # What the default tolerance needs (see polycontact.default_tolerance), cached so
        # that classify() computes it from two floats per shape.
        lo = xy.min(axis=0)
        hi = xy.max(axis=0)
        extent = max(float(hi[0] - lo[0]), float(hi[1] - lo[1]))
        magnitude = max(float(-lo.min()), float(hi.max()))
        if not magnitude <= COORDINATE_LIMIT or extent < EXTENT_FLOOR:
            check_range(xy, "shape")  # e.g. moved() beyond the range: says so
        starts = np.zeros(len(loops) + 1, dtype=np.int64)
        starts[1:] = np.cumsum(lens)
        xy.flags.writeable = False
        starts.flags.writeable = False
        self._xy = xy
        self._starts = starts
        # body-frame tables of the time-of-impact search
        self._frame: tuple[Any, ...] | None = None
        self._loops = tuple(xy[starts[k] : starts[k + 1]] for k in range(len(loops)))
        # Area and centroid (paper Eq. 3-4), summed over every loop: the clockwise holes
        # contribute negative area, which removes them. Coordinates are taken relative to
        # the first vertex so that a small shape far from the origin keeps its digits.
        origin = xy[0]
        x = xy[:, 0] - origin[0]
        y = xy[:, 1] - origin[1]
        nxt = np.empty(len(xy), dtype=np.int64)
        for k in range(len(loops)):
            s, e = starts[k], starts[k + 1]
            nxt[s:e] = np.roll(np.arange(s, e), -1)
        cross = x * y[nxt] - x[nxt] * y
        a2 = float(cross.sum())
        if _area_clear(a2, x, y, nxt, hi - lo):
            centroid = [origin[0] + float(((x + x[nxt]) * cross).sum()) / (3.0 * a2),
                        origin[1] + float(((y + y[nxt]) * cross).sum()) / (3.0 * a2)]
        else:  # a sliver, or a body rounded away: only the exact sums can tell
            a2, centroid = _exact_area_centroid(xy, nxt)
        if not a2 > 0.0:
            # (a rigid motion far from the origin rounded the body away)
            raise InvalidShapeError(
                f"shape: coordinates up to {magnitude:g} cannot carry a shape of size "
                f"{extent:g}: rounded to float64 there, it has no area"
            )
        self._area = 0.5 * a2
        self._centroid = np.array(centroid)
        self._centroid.flags.writeable = False
        self._radius = float(
            np.max(np.hypot(xy[:, 0] - self._centroid[0], xy[:, 1] - self._centroid[1]))
        )
        self._extent = extent
        self._magnitude = magnitude
        # default_tolerance of this shape alone; of a pair, the larger of the two (the
        # rule is a max of terms that grow with the extent and the magnitude)
        self._tolerance = tolerance_for(extent, magnitude)
        self._kernel = _kernel_pack(xy, starts, lo, hi, self._tolerance,
                                    (*centroid, self._radius, extent))
        self.repairs = repairs

    def _init_from_loops(self, loops: list[np.ndarray], repairs: tuple[str, ...],
                         rings: Sequence[ArrayLike] | None = None) -> None:
        # ``rings``: the loops as the caller passed them (messages use their numbering);
        # None when ``loops`` are already in the numbering to report.
        # Every test is exact for the coordinates given: features are defects only where
        # they truly meet, however close they come otherwise (closer than the tolerance,
        # the classification decides them as touching). Nothing depends on where the
        # origin is or on the unit.
        signs = _check_loops(loops)
        for k, ring in enumerate(loops):
            if (k == 0) != (signs[k] > 0):
                loops[k] = ring[::-1].copy()
        if len(loops) > 1:
            _check_hole_placement(loops, loops if rings is None else rings)
        self._set(loops, repairs)

    def _init_repaired(self, vertices: ArrayLike, holes: Sequence[ArrayLike], why: str) -> None:
        from ._repair import repaired

        def check(poly: Any) -> None:
            _check_loops(_polygon_loops(poly))

        try:
            rings = [np.asarray(r, dtype=float).reshape(-1, 2) for r in (vertices, *holes)]
        except (TypeError, ValueError) as exc:
            raise InvalidShapeError(f"cannot repair: {why} ({exc})") from None
        poly, grid, note = repaired(rings, why, check)
        try:
            loops = _polygon_loops(poly)
            note += f"; now {sum(len(r) for r in loops)} vertices in {len(loops)} loop(s)"
            raw_area = _valid_area(rings)
            if raw_area is not None:
                note += f", area changed by {raw_area - float(poly.area):g}"
            self._init_from_loops(loops, repairs=(note,))
        except InvalidShapeError as exc:
            raise InvalidShapeError(f"cannot repair: {why}; the repaired polygon: {exc}") from None
        self._input = _repaired_maps(self, rings, grid)

    # -- properties ---------------------------------------------------------------
    @property
    def exterior(self) -> np.ndarray:
        """Outer loop, ndarray of shape (N, 2), float64, counter-clockwise, read-only."""
        return self._loops[0]

    @property
    def holes(self) -> tuple[np.ndarray, ...]:
        """Hole loops, each an ndarray of shape (M, 2), float64, clockwise, read-only."""
        return self._loops[1:]

    @property
    def loops(self) -> tuple[np.ndarray, ...]:
        """Every loop, outer first, as stored (outer counter-clockwise, holes clockwise,
        repeated and closing points dropped). Its indices are the stored numbering; the
        features report the caller's (see :meth:`input_vertex`)."""
        return self._loops

    def input_loop(self, loop: int) -> int | None:
        """The caller's index of a stored loop.

        Parameters
        ----------
        loop : int
            A stored loop (0 the outer loop, 1.. the holes).

        Returns
        -------
        int or None
            The same index (the holes are kept in the order given), or None for a loop
            that ``repair=True`` made and that holds none of the caller's vertices.

        Examples
        --------
        >>> Shape([(0, 0), (4, 0), (4, 4), (0, 4)], [[(1, 1), (2, 1), (2, 2)]]).input_loop(1)
        1
        """
        self._check_loop(loop)
        k = int(self._input[0][loop])
        return None if k < 0 else k

    def input_vertex(self, loop: int, i: int) -> int | None:
        """The caller's index of a stored vertex.

        Parameters
        ----------
        loop : int
            A stored loop.
        i : int
            A vertex of that loop as stored (:attr:`loops`).

        Returns
        -------
        int or None
            Its position in the vertices as passed (0-based, repeated and closing points
            counted), whatever the stored orientation; None for a vertex that
            ``repair=True`` created (where the repair cut an edge).

        Examples
        --------
        >>> sq = Shape([(0, 0), (0, 2), (2, 2), (2, 0), (0, 0)])  # clockwise, closed
        >>> sq.exterior[0].tolist(), sq.input_vertex(0, 0), sq.input_vertex(0, 3)
        ([2.0, 0.0], 3, 0)
        """
        return self._lookup(loop, i, 0)

    def input_edge(self, loop: int, i: int) -> int | None:
        """The caller's index of a stored edge.

        Parameters
        ----------
        loop : int
            A stored loop.
        i : int
            An edge of that loop as stored: it joins stored vertices ``i`` and ``i + 1``.

        Returns
        -------
        int or None
            The caller's edge ``k``, joining their vertices ``k`` and ``k + 1`` (mod the
            number of vertices passed), that holds it: where repeated points were
            dropped, the one edge of non-zero length between them. None for an edge
            that ``repair=True`` made and that lies on no single edge of the caller's.

        Examples
        --------
        >>> sq = Shape([(0, 0), (0, 2), (2, 2), (2, 0)])          # clockwise
        >>> sq.exterior[0].tolist(), sq.exterior[1].tolist(), sq.input_edge(0, 0)
        ([2.0, 0.0], [2.0, 2.0], 2)
        """
        return self._lookup(loop, i, 1)

    def _to_input(self, packed: Sequence[int], column: int) -> tuple[list[Any], list[Any]]:
        """Caller's loops and indices (None where there is none) of the vertices
        (``column`` 0) or edges (1) at rows ``packed`` of :attr:`packed`, in bulk."""
        rows = np.asarray(packed, dtype=np.int64)
        loops = self._input[0][np.searchsorted(self._starts, rows, side="right") - 1]
        index = self._input[1][rows, column]
        return ([None if k < 0 else k for k in loops.tolist()],
                [None if i < 0 else i for i in index.tolist()])

    def _check_loop(self, loop: int) -> None:
        if not 0 <= loop < len(self._loops):
            raise IndexError(f"loop {loop} is out of range for {len(self._loops)} loop(s)")

    def _lookup(self, loop: int, i: int, column: int) -> int | None:
        self._check_loop(loop)
        n = int(self._starts[loop + 1] - self._starts[loop])
        if not 0 <= i < n:
            raise IndexError(f"index {i} is out of range for loop {loop} of {n} vertices")
        k = int(self._input[1][self._starts[loop] + i, column])
        return None if k < 0 else k

    @property
    def packed(self) -> tuple[np.ndarray, np.ndarray]:
        """``(xy, starts)``: all loops stacked and the row where each starts (kernel form)."""
        return self._xy, self._starts

    @property
    def n_vertices(self) -> int:
        """Number of vertices over all loops."""
        return int(self._xy.shape[0])

    @property
    def area(self) -> float:
        """Area of the solid region (holes removed)."""
        return self._area

    @property
    def centroid(self) -> np.ndarray:
        """Area centroid (paper Eq. 3-4, holes removed), ndarray of shape (2,)."""
        return self._centroid

    @property
    def bounding_radius(self) -> float:
        """Largest distance from the centroid to a vertex (L_A of paper Eq. 5)."""
        return self._radius

    # -- rigid motions ------------------------------------------------------------
    def moved(self, translation: ArrayLike = (0.0, 0.0), angle: float = 0.0) -> Shape:
        """This shape rotated by ``angle`` about its centroid, then translated.

        Parameters
        ----------
        translation : (dx, dy), default (0, 0)
            Two finite real numbers.
        angle : float, default 0
            Radians, counter-clockwise.

        Returns
        -------
        Shape
            The moved shape (numbered as this one).

        Raises
        ------
        TypeError
            Strings, booleans or complex numbers, naming the argument.
        ValueError
            Other bad values, or moved coordinates beyond ±1e100.

        Examples
        --------
        >>> Shape([(0, 0), (2, 0), (2, 2), (0, 2)]).moved((1, 0)).centroid.tolist()
        [2.0, 1.0]
        """
        c = self._centroid
        t = point(translation, "translation", error=InvalidShapeError)
        angle = finite_number(angle, "angle")
        cs, sn = np.cos(angle), np.sin(angle)
        rot = np.array([[cs, sn], [-sn, cs]])  # row-vector form of R(angle)
        xy = (self._xy - c) @ rot + c + t
        try:
            return Shape._trusted(
                [xy[self._starts[k] : self._starts[k + 1]] for k in range(len(self._loops))],
                self.repairs,
                self._input,
            )
        except InvalidShapeError as exc:  # moved beyond the range of coordinates
            raise InvalidShapeError(f"translation: the moved {exc}") from None

    def at(self, motion: Motion, t: float) -> Shape:
        """The shape placed by a motion at a time.

        Parameters
        ----------
        motion : Motion
            How the shape moves about its area centroid from where it is.
        t : float
            The time.

        Returns
        -------
        Shape
            ``self.moved(*motion.pose(t))``.

        Examples
        --------
        >>> from polycontact import Motion
        >>> sq = Shape([(0, 0), (2, 0), (2, 2), (0, 2)])
        >>> sq.at(Motion(velocity=(1, 0), acceleration=(0, 2)), 3.0).centroid.tolist()
        [4.0, 10.0]
        """
        if not isinstance(motion, Motion):
            raise TypeError(f"motion: expected a polycontact.Motion, got "
                            f"{type(motion).__name__}")
        translation, angle = motion.pose(t)
        return self.moved(translation, angle)

    # -- interchange ----------------------------------------------------------------
    @classmethod
    def from_shapely(cls, geom: BaseGeometry, *, repair: bool = False) -> Shape:
        """Shape from a shapely Polygon (or a MultiPolygon of exactly one part).

        Examples
        --------
        >>> import shapely
        >>> Shape.from_shapely(shapely.box(0, 0, 1, 1)).area
        1.0
        """
        import shapely

        if not isinstance(geom, shapely.Geometry):
            raise InvalidShapeError(f"expected a shapely geometry, got {type(geom).__name__}")
        if geom.geom_type == "MultiPolygon" and len(geom.geoms) == 1:
            geom = geom.geoms[0]
        if geom.geom_type != "Polygon":
            raise InvalidShapeError(f"expected one Polygon, got a {geom.geom_type}")
        if geom.is_empty:
            raise InvalidShapeError("the polygon is empty")
        return cls._from_rings(np.asarray(geom.exterior.coords)[:, :2],
                               [np.asarray(r.coords)[:, :2] for r in geom.interiors], repair)

    @classmethod
    def _from_rings(cls, exterior: Any, holes: list[Any], repair: bool) -> Shape:
        """Shape of an interchange format's rings. An empty interior ring (WKT's
        ``POLYGON ((...), EMPTY)``, GeoJSON's ``[]``) holds nothing (GEOS calls the
        polygon valid): it is left out, and the holes after it keep their numbers."""
        kept = [k for k, h in enumerate(holes)
                if not (isinstance(h, (list, tuple, np.ndarray)) and len(h) == 0)]
        shape = cls(exterior, [holes[k] for k in kept], repair=repair)
        if len(kept) < len(holes):
            number = np.array([0] + [k + 1 for k in kept])
            loops = shape._input[0]
            object.__setattr__(shape, "_input", (
                frozen_ints(np.where(loops < 0, -1, number[np.maximum(loops, 0)])),
                shape._input[1]))
        return shape

    def to_shapely(self) -> Polygon:
        """The shape as a ``shapely.Polygon``."""
        import shapely

        return shapely.Polygon(self.exterior, self.holes)

    @classmethod
    def from_wkt(cls, text: str, *, repair: bool = False) -> Shape:
        """Shape from WKT text, e.g. ``"POLYGON ((0 0, 1 0, 0 1, 0 0))"``."""
        import shapely

        try:
            geom = shapely.from_wkt(text)
        except Exception as exc:
            reason = " ".join(str(exc).split())  # (GEOS quotes the text: cut it short)
            raise InvalidShapeError(
                f"not valid WKT: {reason if len(reason) <= 120 else reason[:117] + '...'}"
            ) from None
        return cls.from_shapely(geom, repair=repair)

    def to_wkt(self) -> str:
        """The shape as WKT text."""
        return str(self.to_shapely().wkt)

    @classmethod
    def from_geojson(cls, data: str | dict[str, Any], *, repair: bool = False) -> Shape:
        """Shape from a GeoJSON Polygon (a mapping, its rings lists or tuples as Python's
        geo interface gives them, or JSON text); a Feature is unwrapped."""
        if isinstance(data, str):
            try:
                data = load_json(data)
            except ValueError as exc:
                raise InvalidShapeError(f"not valid JSON: {exc}") from None
        if not isinstance(data, dict):
            raise InvalidShapeError("GeoJSON: expected an object")
        if data.get("type") == "Feature":
            data = data.get("geometry") or {}
        if data.get("type") == "MultiPolygon" and len(data.get("coordinates", [])) == 1:
            data = {"type": "Polygon", "coordinates": data["coordinates"][0]}
        if data.get("type") != "Polygon":
            raise InvalidShapeError(f"GeoJSON: expected a Polygon, got {data.get('type')!r}")
        rings = data.get("coordinates")
        if not isinstance(rings, (list, tuple)) or not rings:
            raise InvalidShapeError("GeoJSON: 'coordinates' must be a non-empty list of rings")
        return cls._from_rings(rings[0], list(rings[1:]), repair)

    @property
    def __geo_interface__(self) -> dict[str, Any]:
        """GeoJSON-like mapping (the Python geo interface), closed rings."""
        return self.to_geojson()

    def to_geojson(self) -> dict[str, Any]:
        """The shape as a GeoJSON Polygon mapping with closed rings."""
        rings = [np.vstack([r, r[:1]]).tolist() for r in self._loops]
        return {"type": "Polygon", "coordinates": rings}

    def plot(self, ax: Axes | None = None, *, numbers: bool = False, **style: Any) -> Axes:
        """Draw the shape (solid filled, holes open); returns the matplotlib Axes.

        Parameters
        ----------
        ax : matplotlib Axes, optional
            Drawn into a new figure when omitted (matplotlib is needed, imported only
            here: ``pip install 'polycontact[plot]'``).
        numbers : bool, default False
            Write each vertex's number, as features report it (see
            :func:`polycontact.plotting.plot_shape`).
        **style
            Passed to the matplotlib patch (``facecolor``, ``alpha``, ``label``...).

        Returns
        -------
        matplotlib Axes

        Examples
        --------
        >>> ax = Shape([(0, 0), (2, 0), (2, 1), (0, 1)]).plot(numbers=True)
        >>> ax.get_title(), len(ax.texts)
        ('4 vertices, 0 holes, area 2', 4)
        """
        from .plotting.shape import plot_shape

        return plot_shape(self, ax, numbers=numbers, **style)

    def __repr__(self) -> str:
        holes = f", {len(self.holes)} hole(s)" if self.holes else ""
        return f"<Shape {len(self.exterior)} vertices{holes}, area {self._area:g}>"


def _valid_area(rings: Sequence[np.ndarray]) -> float | None:
    """The area of the loops as GEOS reads them, where GEOS calls them valid."""
    import shapely

    raw = shapely.Polygon(rings[0], rings[1:])
    return float(raw.area) if raw.is_valid else None


def _polygon_loops(poly: Any) -> list[np.ndarray]:
    """The loops of a shapely Polygon, cleaned as :class:`Shape` cleans a caller's."""
    loops = [_clean_ring(np.asarray(poly.exterior.coords), "outer loop")]
    loops += [_clean_ring(np.asarray(r.coords), f"hole {i}") for i, r in enumerate(poly.interiors)]
    return loops


def _identity_map(starts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The map of loops already in the caller's numbering (see :func:`_input_maps`)."""
    local = np.arange(int(starts[-1]), dtype=np.int64) - np.repeat(starts[:-1], np.diff(starts))
    return (frozen_ints(np.arange(len(starts) - 1)),
            frozen_ints(np.stack([local, local], axis=1)))


def frozen_ints(a: np.ndarray) -> np.ndarray:
    """``a`` as a C-contiguous int64 array (copied only when it is not one), made
    read-only."""
    a = np.ascontiguousarray(a, dtype=np.int64)
    a.flags.writeable = False
    return a


def _ring_map(raw: np.ndarray, reverse: bool) -> np.ndarray:
    """(n, 2): the caller's vertex and edge index of each stored vertex and edge of a ring.

    ``raw`` is the ring as passed (float64, already validated by :func:`_clean_ring`); the
    stored ring drops its consecutive repeats and closing points, and is reversed when
    ``reverse``. A stored vertex is the first vertex of its run of repeats; a stored edge
    is the caller's edge from the last vertex of one run to the first of the next.
    """
    keep = np.ones(len(raw), dtype=bool)
    keep[1:] = np.any(raw[1:] != raw[:-1], axis=1)
    first = np.flatnonzero(keep)
    end = len(raw)
    if len(first) > 1 and np.all(raw[first[-1]] == raw[0]):  # closing point(s)
        end = int(first[-1])
        first = first[:-1]
    vertex = first
    edge = np.append(first[1:], end) - 1
    if reverse:
        vertex = vertex[::-1]
        edge = np.roll(edge[::-1], -1)
    return np.stack([vertex, edge], axis=1)


def _input_maps(
    rings: Sequence[ArrayLike], cleaned: Sequence[np.ndarray], stored: Sequence[np.ndarray]
) -> tuple[Any, ...]:
    """``(loop map, packed (n, 2) vertex and edge map)`` of the ``stored`` loops built
    from the caller's ``rings`` through ``cleaned`` (:func:`_clean_ring`); a stored loop
    that differs from its cleaned ring is its reversal."""
    maps = []
    for ring, clean, loop in zip(rings, cleaned, stored):
        m = _ring_map(np.asarray(ring, dtype=np.float64), not np.array_equal(clean, loop))
        if len(m) != len(loop) or not np.array_equal(
            np.asarray(ring, dtype=np.float64).reshape(-1, 2)[m[:, 0]], loop
        ):
            raise RuntimeError("internal error: the map to the caller's numbering does not "
                               "follow _clean_ring")
        maps.append(m)
    return frozen_ints(np.arange(len(maps))), frozen_ints(np.concatenate(maps))


class GeoInterface(Protocol):
    """Anything with ``__geo_interface__`` (the Python geo interface)."""

    @property
    def __geo_interface__(self) -> Mapping[str, Any]: ...


#: The type of a shape argument: every form :func:`as_shape` takes (WKT and JSON text
#: are ``str``, WKB ``bytes``; Shapely geometries have ``__geo_interface__``).
ShapeLike = Union[Shape, GeoInterface, Mapping[str, Any], npt.ArrayLike]


def _repaired_maps(shape: Shape, rings: Sequence[ArrayLike], grid: float) -> tuple[Any, ...]:
    """The map of a repaired shape to the caller's ``rings``.

    A stored loop belongs to the caller's loop that shares most of its vertices; a stored
    vertex is the first caller's vertex of that loop at the same coordinates (where the
    repair snapped onto a grid of step ``grid`` > 0: the first within one step in x and
    y, when none is at the same coordinates); a stored edge is the caller's edge, next to
    a vertex at one of its ends, that holds both ends within the tolerance. What the
    repair created maps to -1.
    """
    raws = [np.asarray(r, dtype=np.float64).reshape(-1, 2) for r in rings]
    where = [_VertexFinder(raw, grid) for raw in raws]
    eps = default_tolerance(*raws, shape.packed[0])
    loop_map = []
    rows = []
    for ring in shape.loops:
        pts = list(map(tuple, ring.tolist()))
        hits = [sum(bool(found(p)) for p in pts) for found in where]
        k = int(np.argmax(hits)) if hits and max(hits) > 0 else -1
        loop_map.append(k)
        rows.append(np.full((len(ring), 2), -1, dtype=np.int64))
        if k < 0:
            continue
        raw, found, n = raws[k], where[k], len(raws[k])
        for i, p in enumerate(pts):
            rows[-1][i, 0] = (found(p) or [-1])[0]
            q = pts[(i + 1) % len(pts)]
            near = {(c + d) % n for c in found(p) + found(q) for d in (-1, 0)}
            for c in sorted(near):
                s, e = raw[c], raw[(c + 1) % n]
                if np.any(s != e) and max(_to_segment(ring[i], s, e),
                                           _to_segment(ring[(i + 1) % len(ring)], s, e)) <= eps:
                    rows[-1][i, 1] = c
                    break
    return frozen_ints(np.array(loop_map)), frozen_ints(np.concatenate(rows))


class _VertexFinder:
    """The caller's vertices of one ring at a point: those at its very coordinates, or
    (with a ``grid`` step > 0, when there are none) those within one step of it in x
    and y, in the caller's order."""

    def __init__(self, raw: np.ndarray, grid: float) -> None:
        self._raw = raw
        self._grid = grid
        self._exact: dict[tuple[float, ...], list[int]] = {}
        self._cells: dict[tuple[int, int], list[int]] = {}
        for c, p in enumerate(map(tuple, raw.tolist())):
            self._exact.setdefault(p, []).append(c)
            if grid > 0.0:
                self._cells.setdefault(self._cell(p), []).append(c)

    def _cell(self, p: tuple[float, ...]) -> tuple[int, int]:
        return math.floor(p[0] / self._grid), math.floor(p[1] / self._grid)

    def __call__(self, p: tuple[float, ...]) -> list[int]:
        if p in self._exact or self._grid == 0.0:
            return self._exact.get(p, [])
        cx, cy = self._cell(p)
        near = [c for dx in (-1, 0, 1) for dy in (-1, 0, 1)
                for c in self._cells.get((cx + dx, cy + dy), [])
                if max(abs(self._raw[c, 0] - p[0]), abs(self._raw[c, 1] - p[1])) <= self._grid]
        return sorted(near)


def _to_segment(p: np.ndarray, s: np.ndarray, e: np.ndarray) -> float:
    """Distance from point ``p`` to the segment from ``s`` to ``e`` (not a point)."""
    u = e - s
    t = min(1.0, max(0.0, float(np.dot(p - s, u)) / float(np.dot(u, u))))
    return float(np.hypot(*(s + t * u - p)))


def _fmt(v: float) -> str:
    return f"{v:.12g}"


def _kernel_pack(xy: np.ndarray, starts: np.ndarray, lo: np.ndarray, hi: np.ndarray,
                 tolerance: float, sizes: tuple[float, ...]) -> bytes:
    """The shape as the bytes of one float64 array, the layout of
    :data:`polycontact._kernels.packs.PACK_HEAD`: loop count, bounding box ``(xmin,
    ymin, xmax, ymax)`` (``lo``, ``hi``: the minima and maxima of ``xy``), the shape's
    default-tolerance term (``Shape._tolerance``), the loop ``starts`` as int64 bit
    patterns, ``xy`` row by row, then ``sizes``: the area centroid, the bounding radius
    and the extent (:data:`polycontact._kernels.packs.PACK_TAIL`, what a batch of
    moving bodies reads of each shape). :func:`polycontact.classify` passes it to the
    state kernel: one object to unbox per shape, immutable and holding its data in
    itself."""
    return np.concatenate(
        ((len(starts) - 1.0,), lo, hi, (tolerance,), starts.view(np.float64), xy.reshape(-1),
         sizes)
    ).tobytes()


def _bound(obj: Any, name: str) -> bool:
    try:
        object.__getattribute__(obj, name)
    except AttributeError:
        return False
    return True


def _check_loops(loops: list[np.ndarray]) -> np.ndarray:
    """Refuse loops that are not a valid polygon's (exactly: see
    :mod:`polycontact._kernels.validate`); returns each loop's orientation (1
    counter-clockwise, -1 clockwise)."""
    from ._kernels import validate as kv

    xy = np.ascontiguousarray(np.concatenate(loops))
    starts = np.zeros(len(loops) + 1, dtype=np.int64)
    starts[1:] = np.cumsum([len(r) for r in loops])
    code, ki, ei, kj, ej, x, y = kv.first_defect(xy, starts)
    at = f"({_fmt(x)}, {_fmt(y)})"
    if code == kv.ZERO_AREA:
        raise InvalidShapeError(f"{_loop_name(ki)}: zero area (all vertices on one line)")
    if code == kv.SELF_INTERSECTION:
        raise InvalidShapeError(
            f"{_loop_name(ki)}: self-intersection at {at} between edge {ei} and edge {ej}"
        )
    if code == kv.SPIKE:
        raise InvalidShapeError(
            f"{_loop_name(ki)}: edges {ei} and {ej} fold back on each other at {at} "
            "(zero-width spike)"
        )
    if code == kv.LOOPS_CROSS:
        raise InvalidShapeError(
            f"{_loop_name(kj)} crosses {'the ' if ki == 0 else ''}{_loop_name(ki)} at {at} "
            f"(edge {ej} of {_loop_name(kj)}, edge {ei} of {_loop_name(ki)})"
        )
    return np.asarray(kv.loop_signs(xy, starts))


def _area_clear(a2: float, x: np.ndarray, y: np.ndarray, nxt: np.ndarray,
                span: np.ndarray) -> bool:
    """Whether twice the area ``a2``, summed in floats from ``x``, ``y`` (coordinates less
    the first vertex's, which rounds them by 2**-53 of themselves) over the edges
    i -> ``nxt[i]``, is positive beyond its rounding: (n + 8) × 2**-52 × the sum of the
    products' magnitudes, bounded first by the bounding box's sides ``span`` (two
    multiplications), then, where that is not enough, summed."""
    n = len(x)
    unit = (n + 8) * 2.0**-52
    cheap = unit * 2.0 * n * float(span[0]) * float(span[1])
    if a2 > cheap:
        return True
    if cheap < 2.0**-1000:
        return False  # (products near underflow: the exact sums decide)
    return a2 > unit * float(np.abs(x * y[nxt]).sum() + np.abs(x[nxt] * y).sum())


def _exact_area_centroid(xy: np.ndarray, nxt: np.ndarray) -> tuple[float, list[float]]:
    """Twice the area and the centroid of packed loops (edges i -> ``nxt[i]``), summed
    in exact rationals and rounded once: for slivers, whose float sums round to noise."""
    from fractions import Fraction

    pts = [(Fraction(a), Fraction(b)) for a, b in xy.tolist()]
    a2 = sx = sy = Fraction(0)
    for i, j in enumerate(nxt.tolist()):
        (xi, yi), (xj, yj) = pts[i], pts[j]
        c = xi * yj - xj * yi
        a2 += c
        sx += (xi + xj) * c
        sy += (yi + yj) * c
    if a2 <= 0:
        return 0.0, [np.nan, np.nan]
    return float(a2), [float(sx / (3 * a2)), float(sy / (3 * a2))]


def _check_hole_placement(loops: list[np.ndarray], rings: Sequence[ArrayLike]) -> None:
    """Loops no longer cross; holes must lie in the outer loop and not in each other.
    ``rings`` are the loops as the caller numbers them (a vertex is named by that
    number)."""
    import shapely

    outer = shapely.Polygon(loops[0])
    holes = np.array([shapely.Polygon(h) for h in loops[1:]], dtype=object)
    inside = shapely.covers(outer, holes)
    if not inside.all():
        i = int(np.flatnonzero(~inside)[0])
        raw = np.asarray(rings[i + 1], dtype=np.float64).reshape(-1, 2)
        out = np.flatnonzero(~shapely.covers(outer, shapely.points(raw)))
        v = int(out[0]) if len(out) else 0
        p = raw[v]
        raise InvalidShapeError(
            f"hole {i} lies outside the outer loop (its vertex {v} is at "
            f"({_fmt(p[0])}, {_fmt(p[1])}))"
        )
    if len(holes) > 1:
        tree = shapely.STRtree(holes)
        left, right = tree.query(holes, predicate="intersects")
        for i, j in zip(left.tolist(), right.tolist()):
            if i < j and shapely.relate_pattern(holes[i], holes[j], "2********"):
                raise InvalidShapeError(f"hole {i} and hole {j} overlap")
    # What is left for GEOS to find: touches that cut the solid into pieces.
    reason = shapely.is_valid_reason(shapely.Polygon(loops[0], loops[1:]))
    if reason.startswith("Interior is disconnected"):
        where = reason[reason.find("[") + 1 : reason.find("]")].split()
        raise InvalidShapeError(
            f"the holes cut the shape in pieces: its interior is disconnected at "
            f"({', '.join(where)})"
        )
    if reason != "Valid Geometry":
        raise InvalidShapeError(f"invalid holes: {reason}")
