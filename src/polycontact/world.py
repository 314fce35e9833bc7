"""Many bodies: a World that keeps its bodies and a broad phase between calls.

A body is a :class:`~polycontact.Shape` plus a pose: ``position`` is where its area
centroid goes and ``angle`` (radians, counter-clockwise) turns it about that centroid.
States use the codes of :func:`polycontact.classify_many`: 0 separate, 1 contact,
2 penetrating. A container (a Shape, holes allowed) makes "outside the container" a
collision: its exterior and its holes are hazards, and a body that crosses into one is
penetrating (2), one that touches one is in contact (1).

Every pair goes through the same state kernel as :func:`polycontact.classify`, with the
same default tolerance (:func:`polycontact.default_tolerance` of the two bodies), so a
World never answers differently from the pairwise calls. The broad phase is a loose
hierarchical grid in compiled code (see :mod:`polycontact._kernels.world`), updated
body by body on :meth:`World.add`, :meth:`World.move` and :meth:`World.remove`.

Examples
--------
>>> import polycontact as pc
>>> sq = pc.Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
>>> w = pc.World(container=pc.Shape([(0, 0), (3, 0), (3, 1), (0, 1)]))
>>> a, b = w.add(sq, (0.5, 0.5)), w.add(sq, (1.5, 0.5), name="b")
>>> c = w.contacts()
>>> c.pairs.tolist(), c.states.tolist(), c.container_ids.tolist()
([[0, 1]], [1], [0, 1])
>>> w.query(sq, (2.5, 0.5)).fits, w.query(sq, (2.0, 0.5)).ids.tolist()
(True, [1])
>>> w.query_many(sq, [(2.5, 0.5), (2.2, 0.5), (3.0, 0.5)]).tolist()
[1, 2, 2]
"""

from __future__ import annotations

import weakref
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from functools import cache, cached_property
from typing import TYPE_CHECKING, Any, cast

import numpy as np
import numpy.typing as npt

from ._checks import finite_number, one_value, points, real_array
from ._checks import point as point_arg
from .motion import Motion
from .relation import Relation, classify
from .impacts import PairImpact, PairImpacts, first_impact, first_impacts, swept_pairs, \
    time_order
from .limits import (BROAD_PHASE_INFLATION, CONTACT_RESOLUTION, COORDINATE_LIMIT, MAX_ITERATIONS,
                     RELATIVE_TOLERANCE, ROUNDING_ULPS, SAMPLES, TIME_TOLERANCE)
from .shape import Shape, ShapeLike, as_shape, frozen_ints
from .tolerances import ROUNDING_FACTOR, check_range, default_tolerance
from ._threads import chunks as _chunks

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from shapely.geometry.base import BaseGeometry

__all__ = ["World", "WorldBody", "Contacts", "Query", "Sweep"]

#: query_many tests every body's box, not the grid's cells, up to this many bodies.
_SCAN_BODIES = 64


@cache
def _k() -> Any:
    """The World's kernels, imported on first use (loading them takes a while)."""
    from ._kernels import world

    return world


#: Per-body arrays of a World: name -> (shape of an entry, dtype, value of a free slot).
_BODY_ARRAYS: dict[str, tuple[tuple[int, ...], Any, Any]] = {
    "_box": ((4,), np.float64, 0.0),     # bounding box x0, x1, y0, y1
    "_eps": ((), np.float64, 0.0),       # default tolerance
    "_lo": ((), np.int64, 0),            # first loop-start entry in _ls
    "_nl": ((), np.int64, 0),            # number of loops
    "_level": ((), np.int64, -1),        # grid: level, hash slot, cell-list links
    "_slot": ((), np.int64, -1),
    "_nxt": ((), np.int64, -1),
    "_prv": ((), np.int64, -1),
    "_pos": ((2,), np.float64, 0.0),     # pose: where the centroid is, and the turn
    "_ang": ((), np.float64, 0.0),
    "_cen": ((2,), np.float64, 0.0),     # centroid and bounding radius of the base
    "_rad": ((), np.float64, 0.0),
    "_ver": ((), np.int64, 0),           # pose version (the cached Shape's validity)
    "_live": ((), np.bool_, False),
    "_stamp": ((), np.int64, 0),         # duplicate check of set_poses
}


#: The work of one item of the passes that are not classifications, in units of one
#: pair's classification (see :func:`polycontact._threads.chunks`).
_POSE_WORK = 0.25  # placing a body (a 12-gon) and updating its box (memory-bound)
_GRID_WORK = 0.3  # moving a body to another cell of the grid (memory-bound)
_GEOMETRY_WORK = 8.0  # the geometry of a penetrating pair, a pair's swept search
_EVENT_WORK = 0.05  # gathering a sweep's event from its pair (memory-bound)
_NUMBERING_WORK = 0.1  # a pair's carrying vertex and edge in the caller's numbering
_TURN_ROOMS = 2  # rooms for a sweep's turned frames that a World keeps (see _turn_room)
#: A room for a sweep's turned frames: rows, their lengths, circles.
_Room = tuple[np.ndarray, np.ndarray, np.ndarray]
_BODY_WORK = 6.0  # a body's broad-phase query and the classification of its pairs


@dataclass(frozen=True)
class WorldBody:
    """One body of a :class:`World` (a read-only record).

    Attributes
    ----------
    id : int
        Stable id given by :meth:`World.add`.
    name : str or None
    shape : Shape
        The body where it stands (its pose applied).
    base : Shape
        The shape as given to :meth:`World.add`.
    position : ndarray of shape (2,)
        Where the area centroid of ``base`` was put.
    angle : float
        Turn about that centroid, radians, counter-clockwise.
    motion : Motion or None
        The motion given to :meth:`World.add` (not used by the static queries).

    Examples
    --------
    >>> w = World()
    >>> i = w.add([(0, 0), (2, 0), (2, 2), (0, 2)], (5, 5), angle=0.5, name="plate")
    >>> body = w.body(i)
    >>> body.id, body.name, body.position.tolist(), body.angle
    (0, 'plate', [5.0, 5.0], 0.5)
    """

    id: int
    name: str | None
    shape: Shape = field(repr=False)
    base: Shape = field(repr=False)
    position: np.ndarray
    angle: float
    motion: Motion | None = None

    def __post_init__(self) -> None:
        self.position.flags.writeable = False  # (the world's own record: read-only)


@dataclass(frozen=True, eq=False)
class Contacts:
    """Every pair of bodies in contact or penetrating (and, with a margin, every pair
    nearer than it), with the geometry of each contact, as returned by
    :meth:`World.contacts`.

    The geometry arrays are computed together, in one compiled pass over the pairs (in
    parallel), the first time one of them is read; nothing in it makes a Python object
    per pair. Row k describes ``pairs[k]`` = (a, b), from a towards b.

    Attributes
    ----------
    pairs : ndarray of shape (K, 2), int64
        Body ids, smaller first, sorted.
    states : ndarray of shape (K,), int8
        1 contact, 2 penetrating; 0 a pair apart by at most the margin.
    tolerances : ndarray of shape (K,), float64
        The tolerance each pair was classified with.
    distances : ndarray of shape (K,), float64
        The gap between the boundaries when apart, 0 at contact, minus the penetration
        depth (the length of the smallest translation of a that ends the overlap) when
        penetrating: ``classify(a, b).distance``, within the pair's tolerance.
    normals : ndarray of shape (K, 2), float64
        Unit vectors from a towards b: from a's closest point to b's when apart, the
        touched edge's normal at contact (as ``Relation.normal``), opposite a's
        smallest escape when penetrating (moving a by ``distances[k] * normals[k]``
        ends the overlap).
    points : ndarray of shape (K, 2), float64
        A contact point: the midpoint of the closest points when apart, the touching
        vertex at contact; when penetrating, a point of the overlap's boundary: the
        vertex of the contact segment that carries the depth when it lies inside the
        other body, else the boundaries' crossing nearest it.
    overlap_areas : ndarray of shape (K,), float64
        Area of the intersection of the two bodies (holes excluded); 0 unless they
        penetrate.
    overlap_centroids : ndarray of shape (K, 2), float64
        Its area centroid; ``points[k]`` when the area is 0.
    vertex_sides : ndarray of shape (K,), int8
        Which body owns the vertex that carries the contact: 0 a (its edge is b's), 1 b.
    vertices, edges : ndarray of shape (K, 2), int64
        That vertex as ``(loop, index)`` in its body's numbering as the caller gave it
        (loop 0 the outer loop, 1.. the holes; the index counting repeated and closing
        points, whatever the orientation given), and the edge of the other body it lies
        on, faces or is nearest to, likewise (edge i joins vertex i and i + 1 of its
        loop); -1 where the shape's repair made the vertex or edge.
    container_ids, container_states : ndarray of shape (M,)
        Bodies that touch the container's boundary (1) or leave it / enter a hole (2);
        empty without a container.
    ids : ndarray of shape (N,), int64
        Every body of the world when asked, sorted.
    container : Shape or None
        The world's container.
    margin : float
        The margin asked for.

    Examples
    --------
    >>> w = World(container=[(0, 0), (2.5, 0), (2.5, 1), (0, 1)])
    >>> ids = [w.add([(0, 0), (1, 0), (1, 1), (0, 1)], (x, 0.5)) for x in (0.5, 1.25, 2.2)]
    >>> c = w.contacts()
    >>> c.pairs.tolist(), c.states.tolist(), c.overlap_areas.round(9).tolist()
    ([[0, 1], [1, 2]], [2, 2], [0.25, 0.05])
    >>> c.container_ids.tolist(), c.container_states.tolist()
    ([0, 1, 2], [1, 1, 2])
    """

    pairs: np.ndarray
    states: np.ndarray
    tolerances: np.ndarray
    container_ids: np.ndarray
    container_states: np.ndarray
    _store: tuple[Any, ...] = field(repr=False)  # the coordinates as they were
    _tolerance: float | None = field(repr=False)
    ids: np.ndarray = field(default_factory=lambda: np.empty(0, np.int64), repr=False)
    container: Shape | None = field(default=None, repr=False)
    margin: float = 0.0

    def __post_init__(self) -> None:
        for array in (self.pairs, self.states, self.tolerances, self.container_ids,
                      self.container_states, self.ids):
            array.flags.writeable = False  # a result cannot be changed

    def __len__(self) -> int:
        return len(self.states)

    @cached_property
    def _geometry(self) -> tuple[np.ndarray, ...]:
        return _contact_geometry(self._store, self.pairs, self.states, self.tolerances)

    @property
    def distances(self) -> np.ndarray:
        """Signed distance of every pair (see the class docstring)."""
        return self._geometry[0]

    @property
    def normals(self) -> np.ndarray:
        """Unit normal of every pair, from its first body towards its second."""
        return self._geometry[1]

    @property
    def points(self) -> np.ndarray:
        """Contact point of every pair (see the class docstring)."""
        return self._geometry[2]

    @property
    def overlap_areas(self) -> np.ndarray:
        """Area of each pair's intersection (0 unless penetrating)."""
        return self._geometry[3]

    @property
    def overlap_centroids(self) -> np.ndarray:
        """Centroid of each pair's intersection (the point when the area is 0)."""
        return self._geometry[4]

    @property
    def vertex_sides(self) -> np.ndarray:
        """0 when the carrying vertex is the first body's, 1 when the second's."""
        return self._geometry[5]

    @property
    def vertices(self) -> np.ndarray:
        """The carrying vertex, ``(loop, index)`` in the caller's numbering."""
        return self._geometry[6]

    @property
    def edges(self) -> np.ndarray:
        """The edge of the other body, ``(loop, index)`` in the caller's numbering."""
        return self._geometry[7]

    def relation(self, k: int) -> Relation:
        """The full :class:`~polycontact.Relation` of pair ``k`` (features, point,
        normal, depth), as :func:`polycontact.classify` gives it.

        Parameters
        ----------
        k : int
            A row of :attr:`pairs`.

        Returns
        -------
        Relation

        Examples
        --------
        >>> w = World()
        >>> ids = [w.add([(0, 0), (1, 0), (1, 1), (0, 1)], (x, 0.5)) for x in (0.5, 1.5)]
        >>> w.contacts().relation(0).state.value
        'contact'
        """
        k = _integer(k, "k")
        if not 0 <= k < len(self.states):
            raise IndexError(f"k: pair {k} out of range (0..{len(self.states) - 1})")
        i, j = (int(v) for v in self.pairs[k])
        return classify(_snapshot_shape(self._store, i), _snapshot_shape(self._store, j),
                        tolerance=self._tolerance)

    @property
    def penetrating_pairs(self) -> np.ndarray:
        """The pairs that penetrate, (P, 2): the rows of :attr:`pairs` whose state is 2."""
        return cast("np.ndarray", self.pairs[self.states == 2])

    def shape(self, id: int) -> Shape:
        """The shape of a body where it stood when the contacts were found.

        Parameters
        ----------
        id : int
            One of :attr:`ids`.

        Returns
        -------
        Shape

        Examples
        --------
        >>> w = World()
        >>> i = w.add([(0, 0), (1, 0), (1, 1), (0, 1)])
        >>> c = w.contacts()
        >>> w.move(i, (5, 5))
        >>> c.shape(i).centroid.tolist()
        [0.5, 0.5]
        """
        id = _integer(id, "id")
        if id not in set(self.ids.tolist()):
            raise IndexError(f"id: no body {id} among the contacts' bodies")
        return _snapshot_shape(self._store, int(id))

    def to_dict(self, names: Sequence[str] | Mapping[int, str] | None = None) -> dict[str, Any]:
        """The contacts as a JSON-ready dict: the object ``polycontact contacts --json``
        prints.

        Parameters
        ----------
        names : sequence or mapping of str, optional
            A name for each body id (``names[id]``); default the id as text.

        Returns
        -------
        dict
            ``bodies`` (their number), ``container`` (whether there is one),
            ``contacts`` (per pair: ids ``a``, ``b``, their ``names``, ``state``
            ``"contact"``, ``"penetrating"`` or, with a margin, ``"separate"``, witness
            ``point``) and
            ``container_contacts`` (per body: ``body``, ``name``, ``state``
            ``"contact"`` or ``"outside"``).

        Examples
        --------
        >>> import polycontact as pc
        >>> w = pc.World()
        >>> sq = [(0, 0), (1, 0), (1, 1), (0, 1)]
        >>> ids = [w.add(sq), w.add(sq, position=(1.5, 0.5))]
        >>> w.contacts().to_dict()["contacts"]
        [{'a': 0, 'b': 1, 'names': ['0', '1'], 'state': 'contact', 'point': [1.0, 0.0]}]
        """
        def name(i: int) -> str:
            return str(i) if names is None else str(names[i])

        pairs = []
        for k, (i, j) in enumerate(self.pairs.tolist()):
            point = self.relation(k).point
            pairs.append({"a": i, "b": j, "names": [name(i), name(j)],
                          "state": _STATE_NAMES[int(self.states[k])],
                          "point": None if point is None else [float(v) for v in point]})
        container = [{"body": i, "name": name(i), "state": "contact" if s == 1 else "outside"}
                     for i, s in zip(self.container_ids.tolist(),
                                     self.container_states.tolist())]
        return {"bodies": len(self.ids), "container": self.container is not None,
                "contacts": pairs, "container_contacts": container}

    def plot(self, ax: Axes | None = None) -> Axes:
        """Draw the bodies (penetrating ones red, those leaving the container orange),
        the container, the contact points and penetrations.

        Parameters
        ----------
        ax : matplotlib Axes, optional
            Drawn into a new figure when omitted (see
            :func:`polycontact.plotting.plot_contacts`).

        Returns
        -------
        matplotlib Axes

        Examples
        --------
        >>> w = World()
        >>> ids = [w.add([(0, 0), (1, 0), (1, 1), (0, 1)], (x, 0.5)) for x in (0.5, 1.2)]
        >>> ax = w.contacts().plot()
        """
        from .plotting.world import plot_contacts

        return plot_contacts(self, ax=ax)


@dataclass(frozen=True)
class Query:
    """Answer of :meth:`World.query`.

    Attributes
    ----------
    ids, states : ndarray
        The bodies the placed shape touches (1) or penetrates (2), sorted by id.
    container_state : int
        0 inside, 1 touching the container's boundary, 2 outside or crossing it (0
        without a container).
    inside_container : bool
        ``container_state < 2``.
    fits : bool
        Inside the container and penetrating no body (touching allowed).
    shape : Shape
        The shape as placed.

    Examples
    --------
    >>> w = World()
    >>> i = w.add([(0, 0), (1, 0), (1, 1), (0, 1)])
    >>> q = w.query([(0, 0), (1, 0), (1, 1), (0, 1)], (1.0, 0.5))
    >>> q.ids.tolist(), q.states.tolist(), q.fits
    ([0], [2], False)
    """

    ids: np.ndarray
    states: np.ndarray
    container_state: int
    shape: Shape = field(repr=False)

    def __post_init__(self) -> None:
        self.ids.flags.writeable = False  # a result cannot be changed
        self.states.flags.writeable = False

    @property
    def inside_container(self) -> bool:
        return self.container_state < 2

    @property
    def fits(self) -> bool:
        return self.container_state < 2 and not bool((self.states == 2).any())


@dataclass(frozen=True, eq=False)
class Sweep:
    """Answer of :meth:`World.sweep`: every pair that meets within the step, sorted by
    time, then by ids.

    The points and normals are computed together, in one compiled pass, the first time
    one of them is read (the bodies placed at each pair's time and classified there).

    Attributes
    ----------
    pairs : ndarray of shape (K, 2), int64
        Body ids, smaller first.
    times : ndarray of shape (K,)
        When the pair first touches (the exact search's first contact, within the
        contact resolution; 0 when touching or penetrating at the start; for a search
        that ran out of iterations, how far it got).
    states : ndarray of shape (K,), int8
        2 when the bodies penetrate within the step (or at its start), 1 when they only
        touch.
    penetration_times : ndarray of shape (K,)
        The first penetration time (``time_of_impact(...).time``; 0 when penetrating at
        the start), NaN for a pair that only touches.
    statuses : ndarray of shape (K,), int8
        The search's code: 0 no penetration, 1 hit, 2 penetrating at the start, 3 out of
        iterations (no verdict).
    dt : float
        The step.
    points, normals : ndarray of shape (K, 2)
        Contact point and unit normal (from the first body of the pair towards the
        second) at ``times``, as :attr:`Contacts.points` and :attr:`Contacts.normals`
        give them for the bodies placed there.

    Examples
    --------
    >>> w = World()
    >>> ids = [w.add([(0, 0), (1, 0), (1, 1), (0, 1)], (x, 0.5)) for x in (0.5, 3.5)]
    >>> s = w.sweep(2.0, [(1.0, 0.0), (-1.0, 0.0)])
    >>> s.pairs.tolist(), s.times.round(4).tolist(), s.statuses.tolist()
    ([[0, 1]], [1.0], [1])
    """

    pairs: np.ndarray
    times: np.ndarray
    states: np.ndarray
    penetration_times: np.ndarray
    statuses: np.ndarray
    dt: float
    _events: tuple[Any, ...] = field(repr=False)  # what the points and normals come from

    def __len__(self) -> int:
        return len(self.times)

    @cached_property
    def _geometry(self) -> tuple[np.ndarray, np.ndarray]:
        from ._kernels.world_sweep import event_geometry

        point, normal = event_geometry(*self._events, _chunks(len(self.times), _GEOMETRY_WORK))
        for k in np.flatnonzero(np.isnan(normal[:, 0])).tolist():
            point[k], normal[k] = _event_by_shapes(self._events, k)
        point.flags.writeable = False
        normal.flags.writeable = False
        return point, normal

    @property
    def points(self) -> np.ndarray:
        """Contact point of every pair at its time."""
        return self._geometry[0]

    @property
    def normals(self) -> np.ndarray:
        """Unit normal of every pair at its time, from its first body to its second."""
        return self._geometry[1]


def _event_by_shapes(ev: tuple[Any, ...], k: int) -> tuple[np.ndarray, np.ndarray]:
    """Point and normal of pair k of a Sweep's events by :func:`polycontact.classify`
    (for bodies too large for the compiled depth)."""
    (ei, ej, times, _), (ids, pos, ang, _, _, motion, _), (bxy, ls, lo, nl, cen) = ev[:3]
    shapes = []
    for row in (ei[k], ej[k]):
        b, c, turn, m = ids[row], pos[row], ang[row], motion[row]
        st = ls[lo[b] : lo[b] + nl[b] + 1]
        r = bxy[st[0] : st[-1]] - cen[b]
        cs, sn = np.cos(turn), np.sin(turn)
        xy = np.c_[r[:, 0] * cs - r[:, 1] * sn, r[:, 0] * sn + r[:, 1] * cs] + c
        loops = [xy[st[q] - st[0] : st[q + 1] - st[0]] for q in range(len(st) - 1)]
        moving = Motion(velocity=(m[0], m[1]), acceleration=(m[2], m[3]),
                        angular_velocity=m[4], angular_acceleration=m[5])
        shapes.append(Shape._trusted(loops).at(moving, float(times[k])))
    r = classify(shapes[0], shapes[1])
    point = r.point if r.point is not None else np.full(2, np.nan)
    normal = r.normal if r.normal is not None else np.full(2, np.nan)
    return point, normal


def _taken() -> bool:
    """The owner of a room of turned frames taken by a sweep that is running."""
    return True


def _free() -> None:
    """The owner of a room of turned frames that no Sweep reads."""
    return None


def _angle(angle: Any) -> float:
    return finite_number(angle, "angle")


def _integer(value: Any, what: str) -> int:
    """``value`` as an int, if it is an integer (Python or NumPy, not a bool), else a
    TypeError naming ``what``: a float id is not rounded to a body."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"{what}: expected an integer, got {type(value).__name__} {value!r}")
    return int(value)


def _id_array(ids: Any, what: str) -> np.ndarray:
    """``ids`` as a 1-d int64 array (not checked against a World), else an error naming
    ``what``."""
    raw = np.asarray(ids)
    if raw.ndim != 1:
        raise ValueError(f"{what}: expected a 1-d sequence of body ids, got shape "
                         f"{raw.shape}")
    if raw.dtype.kind not in "iu" and not (raw.dtype.kind == "O" and all(
            isinstance(v, (int, np.integer)) and not isinstance(v, (bool, np.bool_))
            for v in raw.tolist())) and len(raw):
        raise TypeError(f"{what}: expected integer body ids, got {raw.dtype}")
    return np.ascontiguousarray(raw, dtype=np.int64)


def _floats(value: Any, what: str) -> np.ndarray:
    """``value`` itself if it is a C-contiguous float64 array (read during the call
    only), else :func:`polycontact._checks.real_array` of it (a new array)."""
    if type(value) is np.ndarray and value.dtype == np.float64 and value.flags.c_contiguous:
        return value
    return real_array(value, what)


def _values(value: Any, what: str, count: int) -> np.ndarray:
    """``value`` as a new float64 array of ``count`` finite real numbers, else an error
    naming ``what`` (and the index of a number that is not finite)."""
    arr = real_array(value, what)
    if arr.shape != (count,):
        raise ValueError(f"{what}: expected {count} numbers, got shape {arr.shape}")
    bad = ~np.isfinite(arr)
    if bad.any():
        k = int(np.argmax(bad))
        raise ValueError(f"{what}[{k}]: expected a finite number, got {float(arr[k])!r}")
    return arr


def _place(base: Shape, position: np.ndarray | None, angle: float, what: str) -> Shape:
    """``base`` turned by ``angle`` about its centroid, centroid moved to ``position``."""
    if position is None and angle == 0.0:
        return base
    xy, starts = base.packed
    c = base.centroid
    p = c if position is None else position
    out = np.empty_like(xy)
    _k().place(xy, float(c[0]), float(c[1]), float(p[0]), float(p[1]), angle, out)
    check_range(out, what)
    return Shape._trusted(
        [out[starts[k] : starts[k + 1]] for k in range(len(starts) - 1)], base.repairs,
        base._input
    )


def _body_tolerances(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """:func:`polycontact.default_tolerance` of each body alone, from its box corners
    (B, 2), vectorised with the same operations. A pair's default tolerance is the larger
    of its two bodies' (a maximum of per-body terms), which the kernels take."""
    extent = np.maximum(hi[:, 0] - lo[:, 0], hi[:, 1] - lo[:, 1])
    magnitude = np.maximum(-lo.min(axis=1), hi.max(axis=1))
    return cast("np.ndarray", np.maximum(RELATIVE_TOLERANCE * extent, ROUNDING_FACTOR * magnitude))


def _stored_rows(xy: np.ndarray, ls: np.ndarray, bs: np.ndarray, sign: np.ndarray,
                 objects: list[Shape | None]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A packed batch (:func:`polycontact.relation._pack`) as a World stores it: its rows
    with the clockwise raw rings reversed (as :class:`Shape` stores them), each row's
    vertex and edge in the caller's numbering, and each loop-start entry's loop in the
    caller's numbering (-1 at a body's end entry)."""
    rows = xy.copy()
    vmap = np.empty((len(xy), 2), np.int64)
    lmap = np.full(len(ls), -1, np.int64)
    raw = np.array([o is None for o in objects], dtype=bool)
    for q in np.flatnonzero(~raw).tolist():
        obj = objects[q]
        assert obj is not None
        f, e = int(ls[bs[q]]), int(ls[bs[q + 1] - 1])
        vmap[f:e] = obj._input[1]
        lmap[bs[q] : bs[q + 1] - 1] = obj._input[0]
    p = np.flatnonzero(raw)
    if len(p):
        first = ls[bs[p]]
        n = ls[bs[p] + 1] - first
        lmap[bs[p]] = 0
        own = np.repeat(np.arange(len(p)), n)
        local = np.arange(int(n.sum())) - np.repeat(np.cumsum(n) - n, n)
        at = first[own] + local
        rev = sign[p][own] < 0.0
        # a clockwise ring is stored reversed: stored row r is the caller's vertex
        # n - 1 - r, stored edge r (rows r, r + 1) the caller's edge n - 2 - r (mod n)
        nn = n[own]
        rows[at] = np.where(rev[:, None], xy[first[own] + nn - 1 - local], xy[at])
        vmap[at, 0] = np.where(rev, nn - 1 - local, local)
        vmap[at, 1] = np.where(rev, (nn - 2 - local) % nn, local)
    return rows, vmap, lmap


_STATE_NAMES = ("separate", "contact", "penetrating")


def _snapshot_shape(store: tuple[Any, ...], b: int) -> Shape:
    """Body ``b``'s Shape from a Contacts' ``store`` (rows, loop starts, each body's
    first loop entry and loop count, the maps to the caller's numbering)."""
    xy, ls, lo, nl, lmap, vmap = store[:6]
    return _body_shape(xy, ls, lmap, vmap, int(lo[b]), int(nl[b]), ())


def _body_shape(xy: np.ndarray, ls: np.ndarray, lmap: np.ndarray, vmap: np.ndarray, lo: int,
                nl: int, repairs: tuple[str, ...]) -> Shape:
    """The Shape of the body whose loop starts are ``ls[lo:lo + nl + 1]`` (rows of
    ``xy``), numbered as the caller gave it (``lmap``, ``vmap``; a copy)."""
    st = ls[lo : lo + nl + 1]
    loops = [xy[st[k] : st[k + 1]].copy() for k in range(nl)]
    return Shape._trusted(loops, repairs,
                          (frozen_ints(lmap[lo : lo + nl]), frozen_ints(vmap[st[0] : st[-1]])))


def _contact_geometry(store: tuple[Any, ...], pairs: np.ndarray, states: np.ndarray,
                      tolerances: np.ndarray) -> tuple[np.ndarray, ...]:
    """The geometry arrays of :class:`Contacts` (see its docstring), in its order."""
    from ._kernels import contact_geometry as kg

    xy, ls, lo, nl, lmap, vmap, vmax, lmax = store
    pi = np.ascontiguousarray(pairs[:, 0])
    pj = np.ascontiguousarray(pairs[:, 1])
    dist, normal, point, area, cen, side, vert, edge = kg.pair_geometry(
        (xy, ls, lo, nl), (pi, pj, states, tolerances), vmax, lmax,
        _chunks(len(pi), _GEOMETRY_WORK))
    for k in np.flatnonzero(np.isnan(dist)).tolist():
        # a depth the contact segments leave undecided: the search over convex sums
        from ._depth import penetration

        a = _snapshot_shape(store, int(pi[k]))
        b = _snapshot_shape(store, int(pj[k]))
        d, dx, dy = penetration(*a.packed, *b.packed, float(tolerances[k]))
        got = kg.penetration_finish(*a.packed, *b.packed, float(tolerances[k]), d, dx, dy)
        dist[k] = -d
        normal[k], point[k] = got[0:2], got[2:4]
        side[k], vert[k], edge[k] = got[4:7]
        if not area[k] > 0.0:
            cen[k] = point[k]
    vertices, edges = kg.caller_features(ls, lo, lmap, vmap, (pi, pj), (side, vert, edge),
                                         _chunks(len(pi), _NUMBERING_WORK))
    for arr in (dist, normal, point, area, cen, side, vertices, edges):
        arr.flags.writeable = False
    return dist, normal, point, area, cen, side, vertices, edges


def _pow2(n: int) -> int:
    return 1 << max(6, (n - 1).bit_length())


class World:
    """Bodies that stay valid between calls, with a compiled, incremental broad phase.

    Parameters
    ----------
    container : ShapeLike, optional
        The region bodies must stay in (holes are defects to avoid). Without one,
        nothing is outside.

    Examples
    --------
    >>> import polycontact as pc
    >>> w = pc.World()
    >>> i = w.add(pc.Shape([(0, 0), (2, 0), (2, 2), (0, 2)]), (5, 5), name="plate")
    >>> w.body(i).shape.centroid.tolist(), len(w)
    ([5.0, 5.0], 1)
    >>> w.move(i, (0, 0), angle=0.5); w.remove(i); len(w)
    0

    Notes
    -----
    A World is used by one thread at a time: its calls run in parallel inside, but two
    threads calling one World at once (a sweep while another thread moves bodies, or
    two sweeps) can each read the other's half-done work. Give each thread its own
    World, or hold a lock around the calls (and around reading the ``Contacts`` and
    ``Sweep`` it returns, which compute their arrays on first access).
    """

    # the per-body arrays (see _BODY_ARRAYS)
    _box: np.ndarray
    _eps: np.ndarray
    _lo: np.ndarray
    _nl: np.ndarray
    _level: np.ndarray
    _slot: np.ndarray
    _nxt: np.ndarray
    _prv: np.ndarray
    _pos: np.ndarray
    _ang: np.ndarray
    _cen: np.ndarray
    _rad: np.ndarray
    _ver: np.ndarray
    _live: np.ndarray
    _stamp: np.ndarray

    def __init__(self, container: ShapeLike | None = None) -> None:
        # id -> [name, base, motion, shape, version of shape]; base and shape are None
        # until asked for (bodies added by add_many are kept as coordinates); shape is
        # rebuilt when the body's pose version (_ver) has moved on.
        self._records: dict[int, list[Any]] = {}
        self._shared = False  # a Contacts holds self._xy: copy it before writing in place
        self._next = 0
        self._mark = 0  # stamp of the last duplicate check (see _ids)
        cap = 64
        for name, (shape, dtype, fill) in _BODY_ARRAYS.items():
            setattr(self, name, np.full((cap, *shape), fill, dtype))
        # rows of every body where it stands (_xy) and as added (_bxy), with each row's
        # vertex and edge in the caller's numbering (_vmap); loop starts (_ls) with each
        # loop's index in the caller's numbering (_lmap)
        self._xy = np.zeros((1024, 2))
        self._bxy = np.zeros((1024, 2))
        self._vmap = np.zeros((1024, 2), np.int64)
        self._ls = np.zeros(256, np.int64)
        self._lmap = np.zeros(256, np.int64)
        self._vtop = 0
        self._ltop = 0
        self._garbage = 0
        self._vmax = 0
        self._lmax = 1
        self._emax = 0.0  # an upper bound of the bodies' tolerances (never lowered)
        self._origin: np.ndarray | None = None
        self._frames: Any = None  # the sweep's body-frame tables (see _sweep_frames)
        # rooms for the sweep's turned frames, each with the Sweep that reads it
        self._turn_pool: list[tuple[Callable[[], object], _Room]] = []
        self._keys = np.full(64, -1, np.int64)
        self._heads = np.full(64, -1, np.int64)
        self._filled = 0
        self._lvl_count = np.zeros(1024, np.int64)
        self._nfp_cache: dict[Any, Any] = {}
        self._container: Shape | None = None
        if container is not None:
            self._set_container(as_shape(container, "container"))

    # -- container -------------------------------------------------------------------
    def _set_container(self, c: Shape) -> None:
        self._container = c
        lo = c.exterior.min(axis=0)
        hi = c.exterior.max(axis=0)
        margin = float(np.max(hi - lo))
        self._margin = margin
        frame = np.array([[lo[0] - margin, lo[1] - margin], [hi[0] + margin, lo[1] - margin],
                          [hi[0] + margin, hi[1] + margin], [lo[0] - margin, hi[1] + margin]])
        hazards = [[frame, c.exterior[::-1]]] + [[h[::-1]] for h in c.holes]
        rows: list[Any] = []
        starts: list[int] = []
        lo_h: list[int] = []
        nl_h: list[int] = []
        top = 0
        for loops in hazards:
            lo_h.append(len(starts))
            nl_h.append(len(loops))
            for r in loops:
                starts.append(top)
                rows.append(r)
                top += len(r)
            starts.append(top)
        self._hxy = np.ascontiguousarray(np.concatenate(rows), dtype=np.float64)
        self._hls = np.array(starts, np.int64)
        self._hlo = np.array(lo_h, np.int64)
        self._hnl = np.array(nl_h, np.int64)
        self._hmax = max(len(frame) + len(c.exterior), *(len(h) for h in c.holes), 0)
        self._cbox = np.array([lo[0], hi[0], lo[1], hi[1]])
        self._ceps = default_tolerance(c.packed[0])

    @property
    def container(self) -> Shape | None:
        """The container, or None."""
        return self._container

    def __getstate__(self) -> dict[str, Any]:
        """What pickling keeps: everything but the rooms of the sweeps' turned frames
        (scratch, each weakly tied to the Sweep that reads it)."""
        state = self.__dict__.copy()
        state["_turn_pool"] = []
        return state

    # -- bodies ----------------------------------------------------------------------
    def __len__(self) -> int:
        return len(self._records)

    def __contains__(self, id: Any) -> bool:
        return id in self._records

    @property
    def ids(self) -> np.ndarray:
        """Ids of the bodies, ascending."""
        return self._alive()

    def bodies(self) -> tuple[WorldBody, ...]:
        """Every body (read-only records), by id."""
        return tuple(self.body(i) for i in sorted(self._records))

    def body(self, id: int) -> WorldBody:
        """One body of the world, as a read-only record.

        Parameters
        ----------
        id : int
            A body of this world.

        Returns
        -------
        WorldBody
            Its id, name, shape where it stands, shape as added, pose and motion.

        Raises
        ------
        KeyError
            ``id`` is not a body of this world.

        Examples
        --------
        >>> w = World()
        >>> i = w.add([(0, 0), (2, 0), (2, 2), (0, 2)], (5, 5), name="plate")
        >>> b = w.body(i)
        >>> b.name, b.position.tolist(), b.shape.centroid.tolist(), b.base.centroid.tolist()
        ('plate', [5.0, 5.0], [5.0, 5.0], [1.0, 1.0])
        """
        rec = self._record(id, "id")
        b = int(id)
        if rec[3] is None or rec[4] != self._ver[b]:
            rec[3] = self._stored_shape(self._xy, b, rec[1])
            rec[4] = int(self._ver[b])
        if rec[1] is None:
            rec[1] = self._stored_shape(self._bxy, b, None)
        return WorldBody(b, rec[0], rec[3], rec[1], self._pos[b].copy(), float(self._ang[b]),
                         rec[2])

    def _record(self, id: Any, what: str) -> list[Any]:
        try:
            return self._records[_integer(id, what)]
        except KeyError:
            raise KeyError(f"{what}: no body {id!r} in this world (never added, or "
                           "removed)") from None

    def _stored_shape(self, xy: np.ndarray, b: int, base: Shape | None) -> Shape:
        """Body ``b``'s Shape from rows ``xy`` (``_xy`` where it stands, ``_bxy`` as
        added), numbered as the caller gave it (``base``'s repairs kept)."""
        return _body_shape(xy, self._ls, self._lmap, self._vmap, int(self._lo[b]),
                           int(self._nl[b]), () if base is None else base.repairs)

    def add(self, shape: ShapeLike, position: npt.ArrayLike | None = None, angle: float = 0.0, *,
            motion: Motion | None = None, name: str | None = None) -> int:
        """Add a body: a shape placed in the world (:meth:`add_many` adds many in one
        call).

        Parameters
        ----------
        shape : ShapeLike
            The body's shape, in any form :func:`polycontact.shape.as_shape` takes.
        position : (x, y), optional
            Where the shape's area centroid goes; None keeps the shape where it is.
        angle : float, default 0
            Radians, counter-clockwise, about the centroid.
        motion : Motion, optional
            Stored with the body for :meth:`first_impacts` and :meth:`first_impact`.
        name : str, optional

        Returns
        -------
        int
            The body's id (ids are never reused).

        Examples
        --------
        >>> w = World()
        >>> sq = [(0, 0), (1, 0), (1, 1), (0, 1)]
        >>> w.add(sq), w.add(sq, (3, 0), angle=0.25, name="b")
        (0, 1)
        """
        base = as_shape(shape, "shape")
        pos = None if position is None else point_arg(position, "position")
        ang = _angle(angle)
        if motion is not None and not isinstance(motion, Motion):
            raise TypeError(f"motion: expected a polycontact.Motion, got {type(motion).__name__}")
        if name is not None and not isinstance(name, str):
            raise TypeError(f"name: expected a str, got {type(name).__name__}")
        placed = _place(base, pos, ang, "shape placed at position")
        b = self._next
        self._next += 1
        self._grow_bodies(b + 1)
        xy, starts = base.packed
        lmap = np.append(base._input[0], -1)
        self._store(np.array([b]), placed.packed[0], xy, base._input[1], starts, lmap,
                    np.array([0, len(starts)]))
        self._pos[b] = base.centroid if pos is None else pos
        self._ang[b] = ang
        self._cen[b] = base.centroid
        self._rad[b] = base.bounding_radius
        self._index(b)
        self._records[b] = [name, base, motion, placed, 0]
        return b

    def add_many(self, shapes: Sequence[ShapeLike] | np.ndarray,
                 positions: npt.ArrayLike | None = None, angles: npt.ArrayLike | None = None,
                 *, names: Sequence[str] | None = None) -> np.ndarray:
        """Add many bodies; returns their ids.

        Each body goes where :meth:`add` would put it: with ``positions``, its area
        centroid goes to ``positions[k]``, turned by ``angles[k]`` (radians,
        counter-clockwise) about it; without, it stays where its coordinates are. Raw
        rings are validated together in one compiled call (as
        :func:`polycontact.classify_many` does), the poses are applied in one compiled
        pass and the broad phase takes the bodies in one pass, so this is much faster
        than :meth:`add` in a loop; the answers are the same, to the last bit.

        Parameters
        ----------
        shapes : sequence of ShapeLike, or ndarray of shape (P, N, 2)
            As for :func:`polycontact.classify_many`.
        positions : array_like of shape (P, 2), optional
            Where each body's area centroid goes.
        angles : array_like of shape (P,), optional
            Turn of each body about its centroid (radians); 0 when omitted.
        names : sequence of str, optional
            One per body.

        Returns
        -------
        ndarray of shape (P,), int64
            The new bodies' ids, in the order given.

        Examples
        --------
        >>> import numpy as np, polycontact as pc
        >>> sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
        >>> w = pc.World()
        >>> w.add_many(np.stack([sq, sq + 1, sq + 3])).tolist()
        [0, 1, 2]
        >>> w.contacts().pairs.tolist()
        [[0, 1]]
        >>> w.add_many([sq, sq], positions=[(10, 0), (11, 0)], angles=[0.0, np.pi / 2]).tolist()
        [3, 4]
        >>> w.poses([3, 4])[0].tolist()
        [[10.0, 0.0], [11.0, 0.0]]
        """
        from ._kernels.poses import centroids, pose_rows
        from .relation import pack_bodies

        objects: list[Shape | None] = []
        xy, ls, bs, sign = pack_bodies(shapes, "shapes", objects)
        count = len(sign)
        if names is not None:
            if isinstance(names, (str, bytes)) or not isinstance(names, (Sequence, np.ndarray)):
                raise TypeError(f"names: expected a sequence of {count} strings, got "
                                f"{type(names).__name__}")
            names = list(names)
            if len(names) != count or not all(isinstance(n, str) for n in names):
                raise ValueError(f"names: expected {count} strings")
        pos = None if positions is None else points(positions, "positions", (count, 2))
        ang = None if angles is None else _values(angles, "angles", count)
        rows, vmap, lmap = _stored_rows(xy, ls, bs, sign, objects)
        check_range(rows, "shapes")
        cen = np.empty((count, 2))
        rad = np.empty(count)
        centroids(rows, ls, bs, cen, rad)
        placed = pos is not None or ang is not None
        p = cen if pos is None else pos
        a = np.zeros(count) if ang is None else ang
        if placed:
            self._check_reach(p, a, rad, None, cen, rows, ls, bs,
                              "shapes[{k}] placed at positions[{k}]")
        first = self._next
        self._next += count
        self._grow_bodies(self._next)
        ids = np.arange(first, first + count, dtype=np.int64)
        self._cen[ids] = cen
        self._rad[ids] = rad
        self._store(ids, rows, rows, vmap, ls, lmap, bs)
        if placed and count:
            _, emax = pose_rows(ids, (np.ascontiguousarray(p), a), self._bodies(),
                                (self._bxy, self._cen), (RELATIVE_TOLERANCE, ROUNDING_ULPS),
                                (self._pos, self._ang, self._ver),
                                (self._keys, self._slot, np.zeros(2), np.empty(0, np.bool_)),
                                _chunks(count, _POSE_WORK))
            self._emax = max(self._emax, float(emax))  # (the poses stored by pose_rows)
        else:
            self._pos[ids] = p
            self._ang[ids] = a
        for k, b in enumerate(ids.tolist()):
            self._records[b] = [None if names is None else names[k], objects[k], None, None,
                                -1]
        self._index_many(ids)
        return ids

    def set_poses(self, ids: npt.ArrayLike, positions: npt.ArrayLike,
                  angles: npt.ArrayLike | None = None) -> None:
        """Put every listed body at a new pose, in one compiled call.

        Body ``ids[k]``'s area centroid goes to ``positions[k]`` and it is turned by
        ``angles[k]`` (radians, counter-clockwise) from the shape as added, as
        :meth:`move` would put it (the same bits). Its coordinates are rewritten from
        the shape as added, its box and tolerance follow, and the broad phase is
        updated incrementally: a body that stays in its grid cell costs it nothing.

        Parameters
        ----------
        ids : array_like of int, shape (P,)
            Bodies of this world, each at most once.
        positions : array_like of shape (P, 2)
        angles : array_like of shape (P,), optional
            Omitted: each body keeps its angle.

        Raises
        ------
        KeyError
            An id that is not a body of this world (``ids[k]``).
        ValueError, TypeError
            Positions or angles that are not finite real numbers of the right shape, or
            an id listed twice, each naming the argument and the index;
            :class:`polycontact.InvalidShapeError` when a pose would carry a body's
            coordinates beyond the range the kernels take.

        Examples
        --------
        >>> import numpy as np, polycontact as pc
        >>> sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
        >>> w = pc.World()
        >>> ids = w.add_many(np.stack([sq, sq + 5]))
        >>> w.set_poses(ids, [(0.5, 0.5), (1.5, 0.5)])
        >>> w.contacts().pairs.tolist(), w.poses()[0].tolist()
        ([[0, 1]], [[0.5, 0.5], [1.5, 0.5]])
        """
        from ._kernels.poses import pose_checks

        idx = _id_array(ids, "ids")
        pos = _floats(positions, "positions")
        if pos.shape != (len(idx), 2):
            pos = points(positions, "positions", (len(idx), 2))  # (says what is wrong)
        if angles is None:
            ang = np.empty(0)  # (each body keeps its angle)
        elif one_value(angles):
            ang = np.full(len(idx), finite_number(angles, "angles"))
        else:
            ang = _floats(angles, "angles")
            if ang.shape != (len(idx),):
                ang = _values(angles, "angles", len(idx))
        # every check in one parallel pass; only when it finds something, one by one
        if not pose_checks(idx, (pos, ang), self._live[: self._next], self._rad,
                           self._stamp, COORDINATE_LIMIT, _chunks(len(idx), _POSE_WORK)):
            idx = self._ids(ids, "ids", unique=True)
            pos = points(positions, "positions", (len(idx), 2))
            if len(ang):
                ang = _values(ang, "angles", len(idx))
            self._check_reach(pos, ang if len(ang) else self._ang[idx], self._rad[idx], idx,
                              None, None, None, None, "body ids[{k}] placed at positions[{k}]")
        self._write_poses(idx, pos, ang)

    def poses(self, ids: npt.ArrayLike | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Where the bodies stand: their positions and angles, as new arrays.

        Parameters
        ----------
        ids : array_like of int, shape (P,), optional
            Bodies of this world; default every body, by id.

        Returns
        -------
        positions : ndarray of shape (P, 2)
            Where each body's area centroid is.
        angles : ndarray of shape (P,)
            Its turn about that centroid, radians, counter-clockwise.

        Examples
        --------
        >>> w = World()
        >>> i = w.add([(0, 0), (2, 0), (2, 2), (0, 2)], (5, 5), angle=0.5)
        >>> positions, angles = w.poses()
        >>> positions.tolist(), angles.tolist()
        ([[5.0, 5.0]], [0.5])
        """
        idx = self.ids if ids is None else self._ids(ids, "ids", unique=False)
        return self._pos[idx].copy(), self._ang[idx].copy()

    def move(self, id: int, position: npt.ArrayLike | None = None,
             angle: float | None = None) -> None:
        """Put one body at a new pose (:meth:`set_poses` moves many in one call).

        Parameters
        ----------
        id : int
            A body of this world.
        position : (x, y), optional
            Where its area centroid goes; None keeps the current position.
        angle : float, optional
            Its turn (radians, counter-clockwise) from the shape as added; None keeps
            the current angle.

        Raises
        ------
        KeyError
            ``id`` is not a body of this world.

        Examples
        --------
        >>> w = World()
        >>> i = w.add([(0, 0), (2, 0), (2, 2), (0, 2)])
        >>> w.move(i, (10, 0))
        >>> w.body(i).shape.centroid.tolist()
        [10.0, 0.0]
        """
        self._record(id, "id")
        b = int(id)
        pos = self._pos[b].copy() if position is None else point_arg(position, "position")
        ang = float(self._ang[b]) if angle is None else _angle(angle)
        idx = np.array([b], np.int64)
        self._check_reach(pos[None], np.array([ang]), self._rad[idx], idx, None, None, None,
                          None, "body placed at position")
        self._write_poses(idx, pos[None], np.array([ang]))

    def remove(self, id: int) -> None:
        """Take a body out of the world (its id is not given again).

        Parameters
        ----------
        id : int
            A body of this world.

        Raises
        ------
        KeyError
            ``id`` is not a body of this world.

        Examples
        --------
        >>> w = World()
        >>> i = w.add([(0, 0), (1, 0), (0, 1)])
        >>> w.remove(i); i in w, len(w)
        (False, 0)
        """
        self._record(id, "id")
        self._unindex(id)
        lo, nl = self._lo[id], self._nl[id]
        self._garbage += int(self._ls[lo + nl] - self._ls[lo])
        self._live[id] = False
        del self._records[id]
        if self._garbage > 1024 and self._garbage > self._vtop // 2:
            self._compact()

    # -- poses (private) ---------------------------------------------------------------
    def _ids(self, ids: Any, what: str, unique: bool) -> np.ndarray:
        """``ids`` as an int64 array of live bodies (each once when ``unique``), else an
        error naming ``what`` and the index."""
        from ._kernels.poses import first_repeat

        idx = _id_array(ids, what)
        bad = (idx < 0) | (idx >= self._next)
        bad[~bad] = ~self._live[idx[~bad]]
        if bad.any():
            k = int(np.argmax(bad))
            raise KeyError(f"{what}[{k}]: no body {int(idx[k])} in this world (never added, "
                           "or removed)")
        if unique:
            self._mark += 1
            k = int(first_repeat(idx, self._stamp, self._mark))
            if k >= 0:
                raise ValueError(f"{what}[{k}]: body {int(idx[k])} is listed twice")
        return idx

    def _check_reach(self, pos: np.ndarray, ang: np.ndarray, rad: np.ndarray,
                     ids: np.ndarray | None, cen: np.ndarray | None, rows: np.ndarray | None,
                     ls: np.ndarray | None, bs: np.ndarray | None, what: str) -> None:
        """Refuse poses that would put a body's coordinates beyond the kernels' range,
        naming ``what`` (formatted with the index k). A body passes at once when its
        position plus its bounding radius stays well inside; the few others are placed
        and checked (the stored bodies ``ids``, or the batch ``rows``/``ls``/``bs`` with
        centroids ``cen``)."""
        reach = np.abs(pos).max(axis=1, initial=0.0) + rad * (1.0 + 1e-9)
        for k in np.flatnonzero(~(reach <= COORDINATE_LIMIT)).tolist():
            if ids is not None:
                b = int(ids[k])
                lo, nl = int(self._lo[b]), int(self._nl[b])
                base = self._bxy[self._ls[lo] : self._ls[lo + nl]]
                c = self._cen[b]
            else:
                assert cen is not None and rows is not None and ls is not None and bs is not None
                base = rows[ls[bs[k]] : ls[bs[k + 1] - 1]]
                c = cen[k]
            out = np.empty_like(base)
            _k().place(base, float(c[0]), float(c[1]), float(pos[k, 0]), float(pos[k, 1]),
                       float(ang[k]), out)
            check_range(out, what.format(k=k))

    def _write_poses(self, idx: np.ndarray, pos: np.ndarray, ang: np.ndarray) -> None:
        """Set the checked poses (``ang`` empty: the bodies keep their angles): rows,
        boxes, tolerances, then the grid (only the bodies that left their cell)."""
        from ._kernels.poses import pose_rows

        if not len(idx):
            return
        if self._shared:  # a Contacts keeps the rows: write a new array
            every = len(idx) == len(self._records)
            self._xy = np.empty_like(self._xy) if every else self._xy.copy()
            self._shared = False
        out = np.empty(len(idx), np.bool_)
        _, emax = pose_rows(idx, (pos, ang), self._bodies(), (self._bxy, self._cen),
                            (RELATIVE_TOLERANCE, ROUNDING_ULPS),
                            (self._pos, self._ang, self._ver),
                            (self._keys, self._slot, self._origin, out),
                            _chunks(len(idx), _POSE_WORK))
        self._emax = max(self._emax, float(emax))
        left = idx[out]
        made, done = _k().regrid(left, self._keys, self._heads, self._nxt, self._prv,
                                 self._slot, self._level, self._lvl_count, self._box,
                                 self._origin, self._filled, _chunks(len(left), _GRID_WORK))
        self._filled += made
        if done < len(left):  # the table would be more than half full: a new one, with
            self._rebuild(extra=int(left[0]))  # every body in the cell of its new box

    # -- storage (private) -------------------------------------------------------------
    def _grow_bodies(self, n: int) -> None:
        cap = len(self._eps)
        if n <= cap:
            return
        new = max(n, 2 * cap)
        for name, (shape, dtype, fill) in _BODY_ARRAYS.items():
            old = getattr(self, name)
            arr = np.full((new, *shape), fill, dtype)
            arr[:cap] = old
            setattr(self, name, arr)

    def _compact(self) -> None:
        """Drop the coordinates of removed bodies (poses overwrite in place)."""
        ids = np.array(sorted(self._records), np.int64)
        rows: list[np.ndarray] = []
        starts: list[np.ndarray] = []
        loops: list[np.ndarray] = []
        bs = [0]
        top = 0
        for b in ids.tolist():
            lo, nl = int(self._lo[b]), int(self._nl[b])
            st = self._ls[lo : lo + nl + 1]
            rows.append(np.arange(st[0], st[-1]))
            starts.append(st - st[0] + top)
            loops.append(self._lmap[lo : lo + nl + 1])
            top += int(st[-1] - st[0])
            bs.append(bs[-1] + nl + 1)
        take = np.concatenate(rows) if rows else np.empty(0, np.int64)
        old = (self._xy[take], self._bxy[take], self._vmap[take])
        ls = np.concatenate(starts) if starts else np.empty(0, np.int64)
        lmap = np.concatenate(loops) if loops else np.empty(0, np.int64)
        self._vtop = self._ltop = self._garbage = 0
        self._xy = np.zeros((max(1024, len(self._xy) // 2), 2))
        self._bxy = np.zeros_like(self._xy)
        self._vmap = np.zeros((len(self._xy), 2), np.int64)
        self._ls = np.zeros(max(256, len(self._ls)), np.int64)
        self._lmap = np.zeros_like(self._ls)
        self._shared = False
        self._frames = None
        self._store(ids, *old, ls, lmap, np.array(bs, np.int64))

    def _store(self, ids: np.ndarray, xy: np.ndarray, bxy: np.ndarray, vmap: np.ndarray,
               ls: np.ndarray, lmap: np.ndarray, bs: np.ndarray) -> None:
        """Append a packed batch of bodies: rows ``xy`` where they stand, ``bxy`` as added,
        ``vmap`` (rows, 2) each row's vertex and edge in the caller's numbering; body p's
        loop starts ``ls[bs[p]:bs[p + 1]]`` (rows of the batch; the last is its end) and
        ``lmap`` each loop's index in the caller's numbering. Sets boxes, tolerances and
        marks the bodies live (not the poses, nor the grid)."""
        if not len(ids):
            return
        v_need, l_need = len(xy), len(ls)
        if self._vtop + v_need > len(self._xy):
            grow = max(v_need, len(self._xy))
            self._xy = np.concatenate([self._xy, np.zeros((grow, 2))])
            self._bxy = np.concatenate([self._bxy, np.zeros((grow, 2))])
            self._vmap = np.concatenate([self._vmap, np.zeros((grow, 2), np.int64)])
        if self._ltop + l_need > len(self._ls):
            grow = max(l_need, len(self._ls))
            self._ls = np.concatenate([self._ls, np.zeros(grow, np.int64)])
            self._lmap = np.concatenate([self._lmap, np.zeros(grow, np.int64)])
        v0, l0 = self._vtop, self._ltop
        self._xy[v0 : v0 + v_need] = xy
        self._bxy[v0 : v0 + v_need] = bxy
        self._vmap[v0 : v0 + v_need] = vmap
        self._ls[l0 : l0 + l_need] = ls + v0
        self._lmap[l0 : l0 + l_need] = lmap
        self._lo[ids] = l0 + bs[:-1]
        nl = np.diff(bs) - 1
        self._nl[ids] = nl
        self._vtop += v_need
        self._ltop += l_need
        first = ls[bs[:-1]]
        nv = ls[bs[1:] - 1] - first
        self._vmax = max(self._vmax, int(nv.max()))
        self._lmax = max(self._lmax, int(nl.max()))
        lo = np.minimum.reduceat(xy, first)
        hi = np.maximum.reduceat(xy, first)
        self._box[ids] = np.c_[lo[:, 0], hi[:, 0], lo[:, 1], hi[:, 1]]
        self._eps[ids] = _body_tolerances(lo, hi)
        self._emax = max(self._emax, float(self._eps[ids].max()))
        self._live[ids] = True

    def _index(self, b: int) -> None:
        if self._origin is None:
            box = self._box[b]
            self._origin = np.array([0.5 * (box[0] + box[1]), 0.5 * (box[2] + box[3])])
        if 2 * (self._filled + 1) > len(self._keys):
            self._rebuild(extra=b)
            return
        self._filled += _k().grid_insert(self._keys, self._heads, self._nxt, self._prv,
                                         self._slot, self._level, self._lvl_count, self._box,
                                         self._origin, b)

    def _index_many(self, ids: np.ndarray) -> None:
        if self._origin is None and len(ids):
            self._origin = np.array([0.5 * (self._box[ids[0], 0] + self._box[ids[0], 1]),
                                     0.5 * (self._box[ids[0], 2] + self._box[ids[0], 3])])
        todo = ids
        while len(todo):
            made, done = _k().grid_insert_many(self._keys, self._heads, self._nxt, self._prv,
                                               self._slot, self._level, self._lvl_count,
                                               self._box, self._origin, todo, self._filled)
            self._filled += made
            todo = todo[done:]
            if len(todo):
                self._rebuild(extra=int(todo[0]), pending=todo)
                todo = todo[1:]

    def _unindex(self, b: int) -> None:
        _k().grid_remove(self._heads, self._nxt, self._prv, self._slot, self._level,
                         self._lvl_count, b)

    def _rebuild(self, extra: int, pending: np.ndarray | None = None) -> None:
        """A new table, four times the live bodies (amortised: when it is half full).
        ``extra`` is indexed too; ``pending`` (not yet indexed) is left out."""
        skip = set() if pending is None else set(pending.tolist())
        alive = np.array(sorted({*(set(self._records) - skip), extra}), np.int64)
        cap = _pow2(4 * (len(alive) + len(skip)) + 16)
        self._keys = np.full(cap, -1, np.int64)
        self._heads = np.full(cap, -1, np.int64)
        self._filled = _k().grid_rebuild(self._keys, self._heads, self._nxt, self._prv,
                                          self._slot, self._level, self._lvl_count, self._box,
                                          self._origin, alive)

    def _alive(self) -> np.ndarray:
        return np.flatnonzero(self._live[: self._next]).astype(np.int64)

    def _levels(self) -> np.ndarray:
        return np.flatnonzero(self._lvl_count).astype(np.int64)

    def _tol(self, tolerance: Any) -> float:
        if tolerance is None:
            return -1.0
        tol = finite_number(tolerance, "tolerance", minimum=0.0)
        if self._container is not None and tol >= 0.25 * self._margin:
            raise ValueError(
                f"tolerance: {tol:g} is not small against the container (size "
                f"{self._margin:g}); give at most a quarter of it"
            )
        return tol

    def _grid(self) -> tuple[Any, ...]:
        """The broad phase's record of the kernels (``polycontact._kernels.world``)."""
        return (self._keys, self._heads, self._nxt, self._level, self._lvl_count,
                self._levels(), self._origin if self._origin is not None else np.zeros(2))

    def _bodies(self) -> tuple[Any, ...]:
        """The stored bodies' record of the kernels (``polycontact._kernels.world``)."""
        return (self._xy, self._ls, self._lo, self._nl, self._box, self._eps)

    def _hazards(self) -> tuple[Any, ...]:
        return (self._hxy, self._hls, self._hlo, self._hnl, self._cbox, self._ceps)

    # -- queries ---------------------------------------------------------------------
    def contacts(self, *, tolerance: float | None = None, margin: float = 0.0) -> Contacts:
        """Every pair of bodies in contact or penetrating, with the geometry of each
        contact, and the bodies that touch or leave the container.

        Parameters
        ----------
        tolerance : float, optional
            Absolute tolerance for every pair; default per pair as in
            :func:`polycontact.classify`.
        margin : float, optional
            Also return the pairs apart by at most this gap (state 0, a positive
            distance): the near-contact lists of DEM and the contact initiation of DDA.

        Returns
        -------
        Contacts
            ``pairs`` and ``states`` at once; ``distances``, ``normals``, ``points``,
            ``overlap_areas``, ``overlap_centroids`` and the carrying ``vertices`` and
            ``edges`` computed in one compiled pass when first read.

        Examples
        --------
        >>> import polycontact as pc
        >>> w = pc.World()
        >>> sq = [(0, 0), (1, 0), (1, 1), (0, 1)]
        >>> ids = [w.add(sq, (0.5, 0.5)), w.add(sq, (1.25, 0.5)), w.add(sq, (2.5, 0.5))]
        >>> c = w.contacts(margin=0.5)
        >>> c.pairs.tolist(), c.states.tolist(), c.distances.tolist()
        ([[0, 1], [1, 2]], [2, 0], [-0.25, 0.25])
        >>> c.normals.tolist(), c.overlap_areas.tolist()
        ([[1.0, 0.0], [1.0, 0.0]], [0.25, 0.0])
        """
        k = _k()
        tol = self._tol(tolerance)
        gap = finite_number(margin, "margin", minimum=0.0)
        alive = self._alive()
        pairs, states, used = k.contact_pairs(
            self._grid(), self._bodies(), (self._pos, self._rad), tol, alive, self._next, gap,
            k.CLASSIFIED if gap > 0.0 else k.TOUCHING, self._vmax, self._lmax,
            _chunks(len(alive), _BODY_WORK))
        if gap > 0.0:
            from ._kernels.contact_geometry import boundary_gaps

            keep = states > 0
            near = np.flatnonzero(~keep)
            gaps = boundary_gaps(self._bodies()[:4], pairs[near, 0], pairs[near, 1],
                                 self._lmax, _chunks(len(near)))
            keep[near[gaps <= gap]] = True
            pairs, states, used = pairs[keep], states[keep], used[keep]
        if self._container is not None and len(alive):
            cst = k.container_states(self._bodies(), tol, alive, self._hazards(), self._vmax,
                                     self._lmax, self._hmax, _chunks(len(alive)))
            c_ids, c_states = alive[cst > 0], cst[cst > 0]
        else:
            c_ids, c_states = np.empty(0, np.int64), np.empty(0, np.int8)
        self._shared = True
        store = (self._xy, self._ls, self._lo.copy(), self._nl.copy(), self._lmap, self._vmap,
                 self._vmax, self._lmax)
        return Contacts(pairs, states, used, c_ids, c_states, store,
                        None if tolerance is None else tol, alive, self._container, gap)

    def query(self, shape: ShapeLike, position: npt.ArrayLike | None = None, angle: float = 0.0, *,
              tolerance: float | None = None) -> Query:
        """How ``shape``, placed like :meth:`add` would place it, lies among the bodies.

        Parameters
        ----------
        shape : ShapeLike
            The shape to place (it is not added).
        position : (x, y), optional
            Where its area centroid goes; None keeps it where it is.
        angle : float, default 0
            Radians, counter-clockwise, about the centroid.
        tolerance : float, optional
            Absolute tolerance for every pair; default per pair as in
            :func:`polycontact.classify`.

        Returns
        -------
        Query
            ``ids`` and ``states`` of the bodies it touches or penetrates,
            ``container_state``, ``inside_container`` and ``fits``.

        Examples
        --------
        >>> w = World(container=[(0, 0), (4, 0), (4, 2), (0, 2)])
        >>> sq = [(0, 0), (1, 0), (1, 1), (0, 1)]
        >>> i = w.add(sq, (0.5, 0.5))
        >>> q = w.query(sq, (1.5, 0.5))
        >>> q.ids.tolist(), q.states.tolist(), q.container_state, q.fits
        ([0], [1], 1, True)
        """
        base = as_shape(shape, "shape")
        pos = None if position is None else point_arg(position, "position")
        placed = _place(base, pos, _angle(angle), "shape placed at position")
        tol = self._tol(tolerance)
        qxy, qs = placed.packed
        qeps = default_tolerance(qxy)
        k = _k()
        if self._records:
            ids, states = k.query_states((qxy, qs, qeps), self._grid(), self._bodies(), tol,
                                         self._emax, self._next, self._vmax, self._lmax)
        else:
            ids, states = np.empty(0, np.int64), np.empty(0, np.int8)
        cstate = 0
        if self._container is not None:
            cstate = int(k.query_container((qxy, qs, qeps), tol, self._hazards()))
        return Query(ids, states, cstate, placed)

    def query_many(self, shape: ShapeLike, positions: npt.ArrayLike, angles: npt.ArrayLike = 0.0, *,
                   tolerance: float | None = None) -> np.ndarray:
        """Worst state over every body and the container (outside counts as 2) of
        ``shape`` placed at each of P poses, in one compiled call.

        Parameters
        ----------
        shape : ShapeLike
            The shape to place (it is not added).
        positions : array_like of shape (P, 2)
            Where the shape's area centroid goes: real numbers (not strings, booleans
            or complex numbers), finite and within ±1e100.
        angles : float or array_like of shape (P,), default 0
            Radians, about the centroid.
        tolerance : float, optional
            As for :meth:`query`.

        Returns
        -------
        ndarray of shape (P,), int8
            0 where the placed shape is apart from everything, 1 where it touches a
            body or the container's boundary, 2 where it penetrates a body or leaves the
            container.

        Examples
        --------
        >>> w = World(container=[(0, 0), (4, 0), (4, 2), (0, 2)])
        >>> sq = [(0, 0), (1, 0), (1, 1), (0, 1)]
        >>> i = w.add(sq, (0.5, 0.5))
        >>> w.query_many(sq, [(2.5, 1.0), (1.5, 0.5), (1.2, 0.5), (3.9, 1.0)]).tolist()
        [0, 1, 2, 2]
        """
        base = as_shape(shape, "shape")
        pos = points(positions, "positions")
        if one_value(angles):
            ang = np.full(len(pos), _angle(angles))
        else:
            ang = real_array(angles, "angles")
            if ang.shape != (len(pos),):
                raise ValueError(f"angles: expected a number or {len(pos)} numbers, got "
                                 f"shape {ang.shape}")
            if not np.isfinite(ang).all():
                k = int(np.flatnonzero(~np.isfinite(ang))[0])
                raise ValueError(f"angles[{k}]: expected a finite number, got {ang[k]!r}")
        tol = self._tol(tolerance)
        sxy, ss = base.packed
        c = base.centroid
        has_c = self._container is not None
        # A few bodies: testing every box is cheaper than visiting the grid's cells.
        scan = self._alive() if len(self._records) <= _SCAN_BODIES else np.empty(0, np.int64)
        hz = self._hazards() if has_c else (np.zeros((1, 2)), np.zeros(2, np.int64),
                                            np.zeros(0, np.int64), np.zeros(0, np.int64),
                                            np.zeros(4), 0.0)
        settings = (RELATIVE_TOLERANCE, ROUNDING_FACTOR, tol, self._emax, self._next,
                    self._vmax, self._lmax, has_c, self._hmax if has_c else 0)
        states: np.ndarray = _k().query_many(
            (sxy, ss, float(c[0]), float(c[1])), (pos[:, 0].copy(), pos[:, 1].copy(), ang),
            self._grid(), self._bodies(), hz, settings, scan, _chunks(len(pos)))
        return states

    # -- moving bodies ---------------------------------------------------------------
    def sweep(self, dt: float, velocities: npt.ArrayLike,
              angular_velocities: npt.ArrayLike | None = None,
              accelerations: npt.ArrayLike | None = None,
              angular_accelerations: npt.ArrayLike | None = None, *,
              time_tolerance: float | None = None,
              max_iterations: int = MAX_ITERATIONS) -> Sweep:
        """Every pair of bodies that comes into contact within ``[0, dt]`` as every body
        moves from where it stands, with its first contact time, point, normal and
        state. The bodies are not moved.

        Body ``ids[k]`` (the world's :attr:`ids`, ascending) moves about its centroid
        with velocity ``velocities[k]``, angular velocity ``angular_velocities[k]``
        (radians per unit of time), and the constant accelerations, turning within the
        step (design.md §3). Candidate pairs come from the swept broad phase of
        :func:`polycontact.first_impacts` (each body's bounding circle along its path,
        boxed over time slices), so no pair that can touch is left out; each runs the
        exact search of :func:`polycontact.time_of_impact`, and agrees with it (the same
        kernel and arguments, the rotation taken about the body's pose; times within
        the time tolerance). Pairs touching or penetrating at the start are reported
        at time 0. The container is not swept.

        Each body is turned to its pose once for all its pairs, into memory the World
        keeps for the next sweeps (about 1 KB per 12-gon, for two sweeps at once: the
        points and normals of a Sweep, computed when first read, come from it, so a
        Sweep that is still referenced keeps its own).

        Parameters
        ----------
        dt : float
            The step (>= 0).
        velocities : array_like of shape (N, 2)
        angular_velocities, accelerations, angular_accelerations : array_like, optional
            Of shapes (N,), (N, 2), (N,); zero when omitted.
        time_tolerance : float, optional
            How precisely the first penetration time of a pair that collides is
            located (as for ``time_of_impact``); default
            :data:`~polycontact.limits.TIME_TOLERANCE` times ``dt``.
        max_iterations : int
            The exact search's budget per pair (see ``time_of_impact``).

        Returns
        -------
        Sweep

        Examples
        --------
        >>> import polycontact as pc
        >>> w = pc.World()
        >>> sq = [(0, 0), (1, 0), (1, 1), (0, 1)]
        >>> ids = [w.add(sq, (0.5, 0.5)), w.add(sq, (3.5, 0.5)), w.add(sq, (0.5, 5.0))]
        >>> s = w.sweep(1.0, [(2.5, 0.0), (0.0, 0.0), (0.0, 0.0)])
        >>> s.pairs.tolist(), s.times.round(4).tolist(), s.states.tolist()
        ([[0, 1]], [0.8], [2])
        >>> s.penetration_times.round(3).tolist()
        [0.8]
        >>> s.normals.round(6).tolist()
        [[1.0, 0.0]]
        """
        from ._kernels.world_sweep import sweep_events, sweep_search, turned_frames

        step = finite_number(dt, "dt", minimum=0.0)
        ids = self.ids
        n = len(ids)
        motion = np.zeros((n, 6))
        motion[:, 0:2] = points(velocities, "velocities", (n, 2))
        for col, arr, name in ((4, angular_velocities, "angular_velocities"),
                               (5, angular_accelerations, "angular_accelerations")):
            if arr is not None:
                motion[:, col] = _values(arr, name, n)
        if accelerations is not None:
            motion[:, 2:4] = points(accelerations, "accelerations", (n, 2))
        tol = TIME_TOLERANCE * step if time_tolerance is None else finite_number(
            time_tolerance, "time_tolerance", positive=True)
        tol = tol if tol > 0.0 else TIME_TOLERANCE
        if isinstance(max_iterations, bool) or not isinstance(max_iterations, (int, np.integer)) \
                or max_iterations < 1:
            raise ValueError(f"max_iterations: expected an integer >= 1, got {max_iterations!r}")
        pos = self._pos[ids]
        rad = self._rad[ids]
        self._check_motions(ids, motion, step, pos, rad)
        cand = swept_pairs(pos, motion, rad, step)
        paired = np.zeros(n, np.bool_)
        paired[cand.reshape(-1)] = True
        bodies = ids[np.flatnonzero(paired)]  # (in the pairs, each once, in order)
        self._sweep_frames(bodies)
        tint, tflt, tio, tfo = self._frames[:4]
        box = self._box
        extent = np.maximum(box[:, 1] - box[:, 0], box[:, 3] - box[:, 2])
        pi = np.ascontiguousarray(cand[:, 0])
        pj = np.ascontiguousarray(cand[:, 1])
        base = (self._bxy, self._ls, self._lo, self._nl, self._cen)
        tables = (tint, tflt, tio, tfo)
        slot, frames = self._turn_room(len(tflt))
        owner: Callable[[], object] = _free  # (the room let go if no Sweep is made)
        try:
            turned_frames(base, tables, bodies, self._ang, frames,
                          _chunks(len(bodies), _POSE_WORK))
            code, t_hit, t_contact, state = sweep_search(
                pi, pj, (ids, self._pos, self._ang, self._rad, extent, motion), base, tables,
                frames, (self._xy, self._ls, self._lo, self._nl),
                (step, BROAD_PHASE_INFLATION, tol, RELATIVE_TOLERANCE, ROUNDING_FACTOR,
                 CONTACT_RESOLUTION, int(max_iterations)),
                self._vmax, self._lmax, _chunks(len(pi), _GEOMETRY_WORK))
            met = np.flatnonzero(state > 0)
            # by time, then by pair: the candidate pairs come sorted by pair, and a stable
            # sort keeps that order among equal times
            order = met[time_order(t_contact[met])]
            pairs, i, j, times, states, hit, codes, start = sweep_events(
                order, pi, pj, ids, (code, t_hit, t_contact, state),
                _chunks(len(order), _EVENT_WORK))
            # what the points and normals come from, if asked: the events as rows of the
            # bodies, and the bodies as they stand now (the World may move them after)
            events = ((i, j, times, start),
                      (ids, pos, self._ang[ids], rad, extent[ids], motion, RELATIVE_TOLERANCE),
                      (self._bxy, self._ls, self._lo.copy(), self._nl.copy(), self._cen),
                      (tint, tflt, tio.copy(), tfo.copy()), frames, self._vmax, self._lmax,
                      ROUNDING_FACTOR)
            out = Sweep(pairs, times, states, hit, codes, step, events)
            owner = weakref.ref(out)  # (its points read the room)
        finally:
            self._turn_pool[slot] = (owner, frames)
        return out

    def _turn_room(self, circles: int) -> tuple[int, _Room]:
        """Room for a sweep's turned frames (the World's rows, and ``circles`` floats;
        see :func:`polycontact._kernels.world_sweep.turned_frames`), and its slot in the
        pool: a room that no live Sweep reads (its points may be asked for later), else
        a new one. Two rooms take turns in a loop of sweeps; a new one of some hundred
        megabytes would cost more in page faults than the turning itself."""
        rows = len(self._bxy)
        free = [k for k, (owner, _) in enumerate(self._turn_pool) if owner() is None]
        fits = [k for k in free if len(self._turn_pool[k][1][1]) >= rows
                and len(self._turn_pool[k][1][2]) >= circles]
        if fits:
            k, room = fits[0], self._turn_pool[fits[0]][1]
        else:
            room = (np.empty((rows, 2)), np.empty(rows), np.empty(circles))
            # a free room too small, else a new slot, else (every room read by a live
            # Sweep, which keeps it) the first slot
            n = len(self._turn_pool)
            k = free[0] if free else (n if n < _TURN_ROOMS else 0)
            if k == n:
                self._turn_pool.append((_taken, room))
        self._turn_pool[k] = (_taken, room)  # (until its Sweep is made)
        return k, room

    def _check_motions(self, ids: np.ndarray, motion: np.ndarray, dt: float, pos: np.ndarray,
                       rad: np.ndarray) -> None:
        """Refuse motions that would carry a body's coordinates, its points' speeds or
        accelerations beyond the kernels' range within the step (as
        :func:`polycontact.time_of_impact` does), naming the argument that carries them
        (the largest term of the bound) and the body's row (``pos``, ``rad``: the
        bodies' centroids and bounding radii, rows as ``ids``)."""
        from ._kernels.world_sweep import motion_maxima

        if not len(ids):
            return
        # the bounds below with an upper bound of each term over the bodies (see
        # motion_maxima; for the angular speed within the step, the largest |w| plus the
        # largest |alpha| dt): rounding is monotone, so when these hold, every body's do
        # (the usual case, decided in one compiled pass)
        with np.errstate(over="ignore", invalid="ignore"):
            bv, ba, bw, bal, br, bb = motion_maxima(motion, pos, rad,
                                                    _chunks(len(ids), _POSE_WORK)).tolist()
            bwm = bw + bal * dt
            if (bb + bv * dt + 0.5 * ba * dt * dt <= COORDINATE_LIMIT
                    and bv + ba * dt + bwm * br <= COORDINATE_LIMIT
                    and ba + bal * br + bwm * bwm * br <= COORDINATE_LIMIT
                    and bw + bal * dt <= COORDINATE_LIMIT):
                return
            v = np.hypot(motion[:, 0], motion[:, 1])
            acc = np.hypot(motion[:, 2], motion[:, 3])
            w, alpha = np.abs(motion[:, 4]), np.abs(motion[:, 5])
            w_max = w + alpha * dt
            base = np.abs(pos).max(axis=1, initial=0.0) + rad
            # the index of the argument a term comes from (-1: the pose, not an argument)
            vel, accel, ang_vel, ang_accel = (np.full(len(ids), i) for i in range(4))
            pose = np.full(len(ids), -1)
            spin = np.where(w >= alpha * dt, ang_vel, ang_accel)  # the leading angular one
            bounds: list[tuple[str, list[tuple[np.ndarray, np.ndarray]]]] = [
                ("coordinates reach", [(base, pose), (v * dt, vel),
                                       (0.5 * acc * dt * dt, accel)]),
                ("points' speeds reach", [(v, vel), (acc * dt, accel), (w_max * rad, spin)]),
                ("points' accelerations reach", [(acc, accel), (alpha * rad, ang_accel),
                                                 (w_max * w_max * rad, spin)]),
                ("angular speed reaches", [(w, ang_vel), (alpha * dt, ang_accel)])]
        arguments = ("velocities", "accelerations", "angular_velocities",
                     "angular_accelerations")
        for name, terms in bounds:
            with np.errstate(over="ignore", invalid="ignore"):
                value = np.sum([term for term, _ in terms], axis=0)
            bad = ~(value <= COORDINATE_LIMIT)
            if bad.any():
                k = int(np.argmax(bad))
                # the argument whose term is largest in that row (a NaN term counts as inf)
                lead = max(((float(np.nan_to_num(term[k], nan=np.inf)), int(arg[k]))
                            for term, arg in terms if arg[k] >= 0), default=(0.0, 0))[1]
                raise ValueError(
                    f"{arguments[lead]}[{k}]: body {int(ids[k])}'s {name} "
                    f"{float(value[k]):g} within dt = {dt:g}, beyond ±{COORDINATE_LIMIT:g}: "
                    "products of coordinates would overflow float64")

    def _sweep_frames(self, bodies: np.ndarray) -> None:
        """Build the sweep's circle trees (one per body, about its base rows) of the
        ``bodies`` that have none yet (see :mod:`polycontact._kernels.world_sweep`)."""
        from ._kernels.world_sweep import frame_tables

        if self._frames is None or len(self._frames[2]) < len(self._eps):
            old = self._frames
            tio = np.full(len(self._eps), -1, np.int64)
            tfo = np.full(len(self._eps), -1, np.int64)
            if old is not None:
                tio[: len(old[2])] = old[2]
                tfo[: len(old[3])] = old[3]
                self._frames = (old[0], old[1], tio, tfo, old[4], old[5])
            else:
                self._frames = (np.empty(0, np.int64), np.empty(0), tio, tfo, 0, 0)
        tint, tflt, tio, tfo, itop, ftop = self._frames
        todo = bodies[tio[bodies] < 0]
        if len(todo):
            nv = self._ls[self._lo[todo] + self._nl[todo]] - self._ls[self._lo[todo]]
            ni = nv + 3 * (2 * nv - 1)
            nf = 4 * (2 * nv - 1)
            tio[todo] = itop + np.cumsum(ni) - ni
            tfo[todo] = ftop + np.cumsum(nf) - nf
            itop += int(ni.sum())
            ftop += int(nf.sum())
            if itop > len(tint):
                tint = np.concatenate([tint, np.empty(max(itop - len(tint), len(tint)), np.int64)])
            if ftop > len(tflt):
                tflt = np.concatenate([tflt, np.empty(max(ftop - len(tflt), len(tflt)))])
            frame_tables((self._bxy, self._ls, self._lo, self._nl, self._cen), todo,
                         (tint, tflt, tio, tfo))
        self._frames = (tint, tflt, tio, tfo, itop, ftop)

    def first_impacts(self, *, t_max: float, method: str = "exact",
                      time_tolerance: float = TIME_TOLERANCE, samples: int = SAMPLES,
                      max_iterations: int = MAX_ITERATIONS,
                      threads: int | None = None) -> PairImpacts:
        """Every pair of bodies that meets within ``[0, t_max]`` as they follow their
        motions, sorted by time.

        Each body follows the ``motion`` given to :meth:`add` (a body without one stays
        put) from where it stands now; only pairs whose swept bounds meet are searched,
        as by :func:`polycontact.first_impacts`. The container is not a moving hazard:
        leaving it is not reported here.

        Parameters
        ----------
        t_max : float
            End of the time window (>= 0).
        method, time_tolerance, samples, max_iterations, threads
            As for :func:`polycontact.first_impacts`.

        Returns
        -------
        PairImpacts
            ``(id_a, id_b, impact)`` records with ``id_a < id_b`` the bodies' ids and
            ``impact`` what :func:`polycontact.time_of_impact` answers for the two bodies
            as placed now (``pairs`` holds the ids too).

        Examples
        --------
        >>> import polycontact as pc
        >>> sq = pc.Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
        >>> w = pc.World()
        >>> a = w.add(sq, (0.5, 0.5), motion=pc.Motion(velocity=(1, 0)))
        >>> b = w.add(sq, (3.5, 0.5))
        >>> [(e.i, e.j, round(e.impact.time, 3)) for e in w.first_impacts(t_max=5)]
        [(0, 1, 2.0)]
        """
        ids, shapes, motions = self._moving()
        return first_impacts(shapes, motions, t_max=t_max, method=method,
                             time_tolerance=time_tolerance, samples=samples,
                             max_iterations=max_iterations,
                             threads=threads).renumbered(np.asarray(ids, dtype=np.int64))

    def first_impact(self, *, t_max: float, method: str = "exact",
                     time_tolerance: float = TIME_TOLERANCE, samples: int = SAMPLES,
                     max_iterations: int = MAX_ITERATIONS,
                     threads: int | None = None) -> PairImpact | None:
        """The first event among the moving bodies: the earliest collision, else the
        earliest touch (the order of :func:`polycontact.first_impact`).

        Parameters
        ----------
        t_max, method, time_tolerance, samples, max_iterations, threads
            As for :meth:`first_impacts`.

        Returns
        -------
        PairImpact or None
            ``(id_a, id_b, impact)``, or None when no pair meets.

        Examples
        --------
        >>> import polycontact as pc
        >>> sq = pc.Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
        >>> w = pc.World()
        >>> ids = [w.add(sq, (0.5, 0.5), motion=pc.Motion(velocity=(1, 0))),
        ...        w.add(sq, (3.5, 0.5)), w.add(sq, (0.5, 3.0))]
        >>> e = w.first_impact(t_max=5)
        >>> e.i, e.j, e.impact.status.value
        (0, 1, 'hit')
        >>> w.remove(ids[1])
        >>> w.first_impact(t_max=5) is None
        True
        """
        ids, shapes, motions = self._moving()
        e = first_impact(shapes, motions, t_max=t_max, method=method,
                         time_tolerance=time_tolerance, samples=samples,
                         max_iterations=max_iterations, threads=threads)
        return None if e is None else PairImpact(ids[e.i], ids[e.j], e.impact)

    def _moving(self) -> tuple[list[int], list[Shape], list[Motion]]:
        ids = sorted(self._records)
        bodies = [self.body(k) for k in ids]
        return ids, [b.shape for b in bodies], [b.motion or Motion() for b in bodies]

    def plot(self, ax: Axes | None = None, *, labels: bool | None = None) -> Axes:
        """Draw the bodies where they stand, with their ids, and the container; returns
        the matplotlib Axes. ``world.contacts().plot()`` draws the contacts too.

        Parameters
        ----------
        ax : matplotlib Axes, optional
            Drawn into a new figure when omitted (matplotlib is needed, imported only
            here: ``pip install 'polycontact[plot]'``).
        labels : bool, optional
            Write each body's id (and name) at its centroid; by default for up to 100
            bodies (see :func:`polycontact.plotting.plot_world`).

        Returns
        -------
        matplotlib Axes

        Examples
        --------
        >>> w = World()
        >>> i = w.add([(0, 0), (1, 0), (1, 1), (0, 1)], name="plate")
        >>> w.plot().get_title()
        '1 body'
        """
        from .plotting.world import plot_world

        return plot_world(self, ax, labels=labels)

    def feasible_region(self, shape: ShapeLike, angle: float = 0.0) -> BaseGeometry:
        """Where a shape can go: the positions of its area centroid (turned by
        ``angle``) where it lies in the container and penetrates no body.

        The container's inner-fit polygon minus the union of the bodies' no-fit
        polygons, with exact fits and slides kept.

        Parameters
        ----------
        shape : ShapeLike
            The shape to place.
        angle : float, default 0
            Its turn about its centroid, radians, counter-clockwise.

        Returns
        -------
        shapely geometry
            Polygon(s) where the shape has room; points and segments where it fits
            exactly or slides; empty when it cannot go anywhere.

        Raises
        ------
        ValueError
            Without a container (the free region would be unbounded).

        Examples
        --------
        >>> w = World(container=[(0, 0), (3, 0), (3, 1), (0, 1)])
        >>> i = w.add([(0, 0), (1, 0), (1, 1), (0, 1)], (0.5, 0.5))
        >>> region = w.feasible_region([(0, 0), (1, 0), (1, 1), (0, 1)])
        >>> region.geom_type, [round(v, 6) for v in region.bounds]
        ('LineString', [1.5, 0.5, 2.5, 0.5])
        """
        import shapely
        from shapely import affinity

        from .nfp import inner_fit_polygon, no_fit_polygon

        if self._container is None:
            raise ValueError("feasible_region: the world has no container, the free "
                             "region would be unbounded")
        cache = isinstance(shape, Shape)
        base = as_shape(shape, "shape")
        ang = _angle(angle)
        a = _place(base, None, ang, "shape")
        ifp = inner_fit_polygon(a, self._container)
        regions, fits, slides = [], [], []
        for rec in self.bodies():
            # The NFP around the body with its centroid at the origin, kept per pair of
            # (shape, angle): bodies added from one Shape share it, translated.
            # (Only for a Shape the caller holds: a new Shape made from an array on each
            # call would never be found again.)
            key = (id(base), ang, id(rec.base), rec.angle)
            hit = self._nfp_cache.get(key) if cache else None
            if hit is None:
                nfp = no_fit_polygon(a, _place(rec.base, np.zeros(2), rec.angle, "body"))
                hit = (nfp.region, nfp.exact_fits, nfp.slides, base, rec.base)
                if cache:
                    self._nfp_cache[key] = hit
            dx, dy = (float(v) for v in rec.position)
            regions.append(affinity.translate(hit[0], dx, dy))
            fits.extend(hit[1] + rec.position)
            slides.append(hit[2] + rec.position)
        if not regions:
            return ifp
        free = ifp.difference(shapely.union_all(regions))
        # Exact fits and slides: positions where the shape touches without overlapping
        # but every neighbourhood overlaps. They lie on the regions' boundaries (two
        # regions meeting), on their own fits and slides, or on the lower-dimensional
        # parts of the inner-fit polygon. Every such piece not already in ``free`` is
        # cut at its crossings and kept where the exact query says the shape fits.
        lines = [r.boundary for r in regions] + [shapely.LineString(s) for s in
                                                  np.concatenate(slides) if len(s)]
        lines += [g for g in shapely.get_parts(ifp) if g.geom_type == "LineString"]
        cand = shapely.union_all(lines).intersection(ifp).difference(free)
        segs: Any = []
        for g in shapely.get_parts(cand):
            if g.geom_type == "LineString":
                xy = np.asarray(g.coords)
                segs.extend(np.stack([xy[:-1], xy[1:]], axis=1))
        pts: Any = [np.asarray(g.coords)[0] for g in shapely.get_parts(ifp)
               if g.geom_type == "Point"]
        pts += list(fits) + [s[0] for s in segs] + [s[1] for s in segs]
        keep = [free] if not free.is_empty else []
        if segs:
            segs = np.array(segs)
            ok = self.query_many(base, segs.mean(axis=1), ang) < 2
            keep += [shapely.LineString(s) for s in segs[ok]]
        if pts:
            pts = np.unique(np.array(pts), axis=0)
            ok = self.query_many(base, pts, ang) < 2
            keep += [shapely.Point(p) for p in pts[ok]]
        return shapely.union_all(keep) if keep else shapely.Polygon()
