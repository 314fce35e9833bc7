"""Classification of two bodies: separate, in contact, or penetrating.

The relation of A and B is the relation of A's reference point to the entrance block
E(A, B) (design.md section 2): inside it the interiors overlap (penetrating), on its
boundary they touch (contact), outside it they are apart (separate). The decision is an
exact interior-overlap test with an absolute tolerance that follows the bodies' size and
the float spacing of their coordinates (:func:`polycontact.default_tolerance`; see
:mod:`polycontact._kernels.relation`), so an exact fit, such as a jigsaw piece in its
socket, is contact, and identical shapes penetrate.

Examples
--------
>>> from polycontact import Shape, classify
>>> a = Shape([(0, 0), (2, 0), (2, 2), (0, 2)])
>>> r = classify(a, a.moved((2, 1)))
>>> r.state, r.distance, r.normal.tolist()
(<State.CONTACT: 'contact'>, 0.0, [1.0, 0.0])
"""

from __future__ import annotations

import enum
import operator
import threading
import weakref
from contextlib import closing
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from functools import cached_property
from typing import TYPE_CHECKING, Any, Generic, TypeVar, cast, overload

import numpy as np

from ._checks import finite_number
from ._dispatch import entry_point
from .errors import InvalidShapeError
from .shape import Shape, ShapeLike, as_shape
from .tolerances import (
    COORDINATE_LIMIT,
    EXTENT_FLOOR,
    RELATIVE_TOLERANCE,
    ROUNDING_ULPS,
)

if TYPE_CHECKING:
    from matplotlib.axes import Axes

__all__ = ["State", "Feature", "Relation", "RelationBatch", "classify", "classify_many"]


class State(str, enum.Enum):
    """How two bodies lie: apart, touching, or with overlapping interiors.

    Arrays of states use the codes 0 separate, 1 contact, 2 penetrating (the order of
    the members).

    Examples
    --------
    >>> [s.value for s in State], State("contact") is State.CONTACT
    (['separate', 'contact', 'penetrating'], True)
    """

    SEPARATE = "separate"
    CONTACT = "contact"
    PENETRATING = "penetrating"


_STATES = (State.SEPARATE, State.CONTACT, State.PENETRATING)

_T = TypeVar("_T")


class _cached(Generic[_T]):
    """:func:`functools.cached_property` for a class with ``__slots__`` and no
    ``__dict__``: the value is kept in the instance's ``_cache`` slot (a dict made on
    the first use), computed once per instance (two threads asking at once may both
    compute it; either value is kept).

    Examples
    --------
    >>> class Box:
    ...     __slots__ = ("_cache",)
    ...     @_cached
    ...     def area(self) -> int:
    ...         print("computed")
    ...         return 6
    >>> b = Box()
    >>> b.area
    computed
    6
    >>> b.area
    6
    """

    def __init__(self, func: Callable[[Any], _T]) -> None:
        self.func = func
        self.name = func.__name__
        self.__doc__ = func.__doc__

    @overload
    def __get__(self, obj: None, owner: type | None = None) -> _cached[_T]: ...
    @overload
    def __get__(self, obj: object, owner: type | None = None) -> _T: ...

    def __get__(self, obj: object, owner: type | None = None) -> _cached[_T] | _T:
        if obj is None:
            return self
        try:
            cache: dict[str, Any] = obj._cache  # type: ignore[attr-defined]
        except AttributeError:
            cache = {}
            obj._cache = cache  # type: ignore[attr-defined]
        try:
            return cast(_T, cache[self.name])
        except KeyError:
            value = cache[self.name] = self.func(obj)
            return value


@dataclass(frozen=True)
class Feature:
    """One way the two boundaries meet.

    Every index is 0-based and in the caller's numbering: the position in the vertices
    as passed (a closing point and repeated points counted), whatever orientation they
    were given in; edge ``k`` joins vertex ``k`` and vertex ``k + 1`` (mod the number
    passed) of its loop. For a shape built with ``repair=True`` an index is None where
    the repair created the vertex or edge (see :meth:`Shape.input_vertex`).

    Attributes
    ----------
    body : str
        ``"a"`` or ``"b"``: the body that owns ``vertex`` (and ``own_edge``).
    loop : int
        Loop of ``body``: 0 the outer loop, 1.. the holes in the order given.
    vertex : int or None
        Vertex of ``body``; None for ``"edges-cross"``.
    other_loop : int
        Loop of the other body that holds ``edge``.
    edge : int
        Edge of the OTHER body: the edge the vertex lies on, the nearest edge for
        ``"vertex-inside"``, the crossed edge for ``"edges-cross"``.
    kind : str
        ``"vertex-on-edge"`` (within the tolerance; a vertex sitting on a vertex of
        the other body is reported against both edges that meet there),
        ``"vertex-inside"`` (strictly inside the other body), or ``"edges-cross"``
        (a proper crossing of ``own_edge`` with ``edge``; always reported with
        ``body="a"``).
    own_edge : int or None
        For ``"edges-cross"``, the crossing edge of ``body``; otherwise None.

    Examples
    --------
    >>> cw = [(0, 0), (0, 1), (1, 1), (1, 0)]       # clockwise: stored reversed
    >>> classify(cw, [(1, 0.5), (2, 0), (2, 1)]).features
    (Feature(body='b', loop=0, vertex=0, other_loop=0, edge=2, kind='vertex-on-edge', own_edge=None),)
    """

    body: str
    loop: int | None
    vertex: int | None
    other_loop: int | None
    edge: int | None
    kind: str
    own_edge: int | None = None

    def to_dict(self) -> dict[str, Any]:
        """The feature as a JSON-ready dict.

        Returns
        -------
        dict
            The attributes by name (``own_edge`` only for an edge crossing).

        Examples
        --------
        >>> Feature("a", 0, 2, 0, 1, "vertex-on-edge").to_dict()
        {'body': 'a', 'loop': 0, 'vertex': 2, 'other_loop': 0, 'edge': 1, 'kind': 'vertex-on-edge'}
        """
        out: dict[str, Any] = {"body": self.body, "loop": self.loop, "vertex": self.vertex,
                               "other_loop": self.other_loop, "edge": self.edge,
                               "kind": self.kind}
        if self.own_edge is not None:
            out["own_edge"] = self.own_edge
        return out


class Relation:
    """The relation of two bodies, as returned by :func:`classify`.

    ``state`` and ``tolerance`` are decided by the classification; ``distance``,
    ``features``, ``point`` and ``normal`` are computed on first access and cached.

    Attributes
    ----------
    state : State
    tolerance : float
        The absolute tolerance used: distances up to it count as touching.
    distance : float
        Signed: the gap between the boundaries when separate, 0 at contact, minus the
        penetration depth (length of the smallest translation of A that ends the
        overlap) when penetrating.
    features : tuple of Feature
        Every vertex within the tolerance of the other boundary, every vertex strictly
        inside the other body, every proper edge crossing (A's vertices first, then
        B's, then crossings), numbered as the caller gave the vertices.
    point : ndarray of shape (2,) or None
        A witness point. Contact: a touching vertex (the one of the first feature).
        Penetrating: the crossing point of the first edge crossing if there is one,
        otherwise the first vertex inside, otherwise a touching vertex. Separate: the
        midpoint of the closest pair of boundary points.
    normal : ndarray of shape (2,) or None
        Unit vector from A towards B. Contact: the normal of a touched edge, one that
        keeps the touching vertex's own edges on its side (so at a vertex-on-vertex
        touch of flush edges it is the flush edge's normal), preferring the touch
        farthest from the edge's ends (on a tie, such as a vertex on a vertex, the
        first: A's vertices before B's). :meth:`World.contacts` gives the same.
        Penetrating: the direction opposite the smallest separating translation of A. Separate: None.
    escape : ndarray of shape (2,) or None
        Penetrating only: the smallest translation of A that ends the overlap.

    Examples
    --------
    >>> sq = [(0, 0), (1, 0), (1, 1), (0, 1)]
    >>> r = classify(sq, [(0.75, 0), (2, 0), (2, 1), (0.75, 1)])
    >>> r
    Relation(state='penetrating', tolerance=1.25e-12)
    >>> r.distance, r.normal.tolist(), r.escape.tolist()
    (-0.25, [1.0, 0.0], [-0.25, 0.0])
    """

    # Built by classify with four slot stores (a frozen dataclass's instance dict is a
    # noticeable part of the cost of classify on two small prebuilt shapes); nothing can
    # be changed: ``state`` and ``tolerance`` are properties without setters, the lazy
    # parts are cached in ``_cache`` and there is no instance dict to add attributes to.
    # ``_a`` and ``_b`` are the bodies (a Shape, or the bytes, vertex count and
    # orientation of a raw ring).
    __slots__ = ("_state", "_tolerance", "_a", "_b", "_cache")
    _state: State
    _tolerance: float
    _a: Any
    _b: Any

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        raise TypeError("Relation objects are made by classify()")

    @property
    def state(self) -> State:
        """How the bodies lie (decided by the classification)."""
        return self._state

    @property
    def tolerance(self) -> float:
        """The absolute tolerance used: distances up to it count as touching."""
        t = self._tolerance
        if t < 0.0:  # two Shapes' default: the larger of their terms, as the kernel took
            a, b = self._a, self._b
            t = self._tolerance = a._tolerance if a._tolerance > b._tolerance else b._tolerance
        return t

    def __repr__(self) -> str:
        # Only what is already decided: the lazy parts (a depth can be costly) stay lazy.
        return f"Relation(state={self.state.value!r}, tolerance={self.tolerance:g})"

    def to_dict(self) -> dict[str, Any]:
        """The relation as a JSON-ready dict: the object ``polycontact classify --json``
        prints.

        Only what is returned is computed: separate bodies have no features (nothing
        touches), so their feature search is skipped.

        Returns
        -------
        dict
            ``state``, ``distance``, ``features`` (each :meth:`Feature.to_dict`),
            ``point``, ``normal`` (``[x, y]`` or None) and ``tolerance``.

        Examples
        --------
        >>> import json
        >>> sq = [(0, 0), (1, 0), (1, 1), (0, 1)]
        >>> d = classify(sq, [(1, 0), (2, 0), (2, 1), (1, 1)]).to_dict()
        >>> d["state"], len(d["features"]), d["normal"]
        ('contact', 8, [1.0, 0.0])
        >>> json.loads(json.dumps(d)) == d
        True
        """
        features = () if self.state is State.SEPARATE else self.features
        return {
            "state": self.state.value,
            "distance": float(self.distance),
            "features": [f.to_dict() for f in features],
            "point": _xy(self.point),
            "normal": _xy(self.normal),
            "tolerance": float(self.tolerance),
        }

    def plot(self, ax: Axes | None = None) -> Axes:
        """Draw both bodies, the witness point and the normal; returns the matplotlib Axes.

        Parameters
        ----------
        ax : matplotlib Axes, optional
            Drawn into a new figure when omitted (matplotlib is needed, it is imported
            only here: ``pip install polycontact[plot]``).

        Returns
        -------
        matplotlib Axes

        Examples
        --------
        >>> sq = [(0, 0), (1, 0), (1, 1), (0, 1)]
        >>> ax = classify(sq, [(1, 0), (2, 0), (2, 1), (1, 1)]).plot()
        >>> ax.get_title()
        'contact, distance 0'
        """
        from .plotting.relation import plot_relation

        return plot_relation(self, ax=ax)

    @_cached
    def shapes(self) -> tuple[Shape, Shape]:
        """The two bodies as oriented :class:`Shape` objects (their ``input_vertex`` and
        ``input_edge`` map the stored order to the caller's, used by the features)."""
        return _to_shape(self._a), _to_shape(self._b)

    @_cached
    def _packed(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        a, b = self.shapes
        return (*a.packed, *b.packed)

    @_cached
    def _closest(self) -> tuple[float, float, float, float, float]:
        from ._kernels.distance import closest_pair

        return cast("tuple[float, float, float, float, float]", closest_pair(*self._packed))

    @_cached
    def _penetration(self) -> tuple[float, float, float]:
        from ._depth import penetration

        return penetration(*self._packed, self.tolerance)

    @_cached
    def distance(self) -> float:
        """Signed distance (see the class docstring)."""
        if self.state is State.CONTACT:
            return 0.0
        if self.state is State.SEPARATE:
            return float(self._closest[0])
        return -float(self._penetration[0])

    @_cached
    def escape(self) -> np.ndarray | None:
        """Smallest translation of A that ends the overlap (penetrating only)."""
        if self.state is not State.PENETRATING:
            return None
        return _read_only(np.array(self._penetration[1:]))

    @_cached
    def _raw_features(self) -> tuple[Any, ...]:
        from ._kernels.features import features

        return cast("tuple[Any, ...]", features(*self._packed, self.tolerance))

    @_cached
    def features(self) -> tuple[Feature, ...]:
        """Every feature of the meeting (see the class docstring)."""
        if self.state is State.SEPARATE:
            return ()  # nothing within the tolerance: no search (O(m + n) and more)
        a, b = self.shapes
        a_on, b_on, a_in, b_in, cross = self._raw_features
        out: list[Feature] = []
        # the kernels give packed rows of the stored loops: map them to the caller's
        for body, own, other, on, inside in (("a", a, b, a_on, a_in), ("b", b, a, b_on, b_in)):
            for kind, rows in (("vertex-on-edge", on), ("vertex-inside", inside)):
                k, v = own._to_input([r[0] for r in rows], 0)
                ko, e = other._to_input([r[1] for r in rows], 1)
                out += [Feature(body, *x, kind) for x in zip(k, v, ko, e)]
        k, e = a._to_input([r[0] for r in cross], 1)
        ko, f = b._to_input([r[1] for r in cross], 1)
        out += [Feature("a", x[0], None, x[1], x[2], "edges-cross", x[3])
                for x in zip(k, ko, f, e)]
        return tuple(out)

    @_cached
    def point(self) -> np.ndarray | None:
        """Witness point (see the class docstring), a read-only array."""
        p = self._witness()
        return None if p is None else _read_only(p)

    def _witness(self) -> np.ndarray | None:
        if self.state is State.SEPARATE:
            _, px, py, qx, qy = self._closest
            return np.array([0.5 * (px + qx), 0.5 * (py + qy)])
        a_on, b_on, a_in, b_in, cross = self._raw_features
        xa, _, xb, _ = self._packed
        if self.state is State.PENETRATING:
            if cross:
                return np.array(cross[0][2:])
            if a_in:
                return cast("np.ndarray", xa[a_in[0][0]].copy())
            if b_in:
                return cast("np.ndarray", xb[b_in[0][0]].copy())
        if a_on:
            return cast("np.ndarray", xa[a_on[0][0]].copy())
        if b_on:
            return cast("np.ndarray", xb[b_on[0][0]].copy())
        return None

    @_cached
    def normal(self) -> np.ndarray | None:
        """Unit normal from A towards B (see the class docstring), a read-only array."""
        n = self._unit_normal()
        return None if n is None else _read_only(n)

    def _unit_normal(self) -> np.ndarray | None:
        if self.state is State.SEPARATE:
            return None
        if self.state is State.PENETRATING:
            d = -np.asarray(self._penetration[1:])
            return cast("np.ndarray", d / np.hypot(*d) + 0.0)
        from ._kernels.features import touch

        # the touch World.contacts gives too (see that kernel for the rule)
        nx, ny, side, _, _ = touch(*self._packed, self.tolerance)
        return None if side < 0 else np.array([nx, ny])


def _read_only(arr: np.ndarray) -> np.ndarray:
    """``arr`` (a result's own array) made read-only: a result cannot be changed."""
    arr.flags.writeable = False
    return arr


def _xy(p: np.ndarray | None) -> list[float] | None:
    """A point or vector as a JSON-ready ``[x, y]`` (None stays None)."""
    return None if p is None else [float(v) for v in p]


def _to_shape(src: Any) -> Shape:
    if isinstance(src, Shape):
        return src
    raw, n, sign = src  # the bytes of a C-contiguous float64 (N, 2) ring, copied at call
    arr = np.frombuffer(raw, dtype=np.float64).reshape(-1, 2)
    ring = arr[:n] if sign > 0 else arr[:n][::-1]
    return Shape._trusted([np.array(ring, dtype=np.float64)], inputs=raw_ring_inputs(n, sign))


def raw_ring_inputs(n: int, sign: float) -> tuple[np.ndarray, np.ndarray]:
    """The map to the caller's numbering (``Shape._input``) of a raw ring that the ring
    kernels accepted with ``n`` vertices, stored reversed when ``sign`` < 0 (clockwise):
    only a closing point was dropped (it is the caller's vertex n, so edge n - 1 ends
    there)."""
    index = np.arange(n, dtype=np.int64)
    edge = index if sign > 0 else np.roll(index[::-1], -1)
    vertex = index if sign > 0 else index[::-1]
    return (np.zeros(1, dtype=np.int64), np.ascontiguousarray(np.stack([vertex, edge], axis=1)))


def _check_tolerance(tolerance: Any) -> float:
    return finite_number(tolerance, "tolerance", minimum=0.0)


_F64 = np.dtype(np.float64)
_ND = np.ndarray
_KERNELS: list[Any] = []


def _kr() -> Any:
    """The relation kernels module (imported on first use: numba loads lazily)."""
    if not _KERNELS:
        from ._kernels import relation

        _KERNELS.append(relation)
    return _KERNELS[0]


_RAW: list[Any] = []  # [classify_raw], bound on first use

#: The default-tolerance rule and the range of coordinates, as the ring kernels take them.
RING_ARGS = (RELATIVE_TOLERANCE, ROUNDING_ULPS, COORDINATE_LIMIT, EXTENT_FLOOR)


_new = object.__new__


def _bind_state_into(pa: bytes, pb: bytes, eps: float) -> int:
    """The first call of :func:`classify` on two Shapes: binds ``relate_shapes_into``'s
    entry point (see polycontact._dispatch) to ``_state_into``, then classifies.

    Binding replaces this function, so the calls after it check nothing (threads
    binding at once bind the same entry point).
    """
    global _state_into
    # (bound by a call with the caller's own tolerance: a made-up one could make the
    # binding call far costlier than the classification asked for)
    _state_into = entry_point(_kr().relate_shapes_into, (pa, pb, eps))
    return int(_state_into(pa, pb, eps))


def _bind_state_full(xa: np.ndarray, sa: np.ndarray, xb: np.ndarray, sb: np.ndarray,
                     eps: float) -> int:
    """:func:`_bind_state_into` for ``relate_state`` on the shapes' arrays (``_state_full``)."""
    global _state_full
    # (a tolerance of 1.0 on a large unit ring made every vertex touch every edge near
    # it: the binding call took minutes)
    _state_full = entry_point(_kr().relate_state, (xa, sa, xb, sb, eps))
    return int(_state_full(xa, sa, xb, sb, eps))


#: The state kernels for two Shapes: ``relate_shapes_into`` on the shapes' kernel packs,
#: and ``relate_state`` on their arrays for pairs with more vertices than the former's
#: scratch on the stack holds; each bound on its first call.
_state_into: Callable[[bytes, bytes, float], int] = _bind_state_into
_state_full: Callable[[np.ndarray, np.ndarray, np.ndarray, np.ndarray, float], int] = (
    _bind_state_full)

def classify(a: ShapeLike, b: ShapeLike, *, tolerance: float | None = None) -> Relation:
    """Classify two bodies: separate, contact or penetrating.

    Parameters
    ----------
    a, b : ShapeLike
        The bodies, in any form :func:`polycontact.shape.as_shape` takes. An array is an
        outer loop (closed or not, either orientation).
        C-contiguous float64 arrays take a lean path: one compiled call validates both
        rings and classifies them; a ring it cannot certify (an invalid one, or a valid
        one with features closer than the tolerance) goes through :class:`Shape`, which
        decides exactly, explains the defect, or cleans repeated vertices.
    tolerance : float, optional
        Absolute tolerance; distances up to it count as touching. Default:
        :func:`polycontact.default_tolerance` of both bodies: ``max(1e-12 × the larger
        body's extent, 64 × 2**-52 × the largest |coordinate|)``, so a shift of 1e-9 of
        a body's size is seen at every scale, and far from the origin the tolerance
        stays above the float spacing of the coordinates.

    Returns
    -------
    Relation
        ``state`` and ``tolerance`` at once; ``distance``, ``features``, ``point`` and
        ``normal`` computed on first access (from copies of array inputs).

    Raises
    ------
    InvalidShapeError
        If a body is not a valid polygon (the message says which body and why).

    Examples
    --------
    >>> import numpy as np
    >>> sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    >>> [classify(sq, sq + d).state.value for d in ([2.0, 0.0], [1.0, 0.5], [0.5, 0.5])]
    ['separate', 'contact', 'penetrating']
    >>> round(classify(sq, sq + [0.75, 0.5]).distance, 12)
    -0.25
    """
    if isinstance(a, Shape) and isinstance(b, Shape):
        # Shapes (prebuilt: a simulation's loop), the fastest path: the state kernel is
        # called without the dispatcher's type resolution (its arguments have fixed
        # types: see polycontact._dispatch) with one bytes object per shape (its kernel
        # pack, which holds its bounding box and its default-tolerance term too: -1.0
        # asks the kernel for the larger of the two, so that no float object of the
        # shapes is read here: reading them is slow when GEOS has emptied the caches);
        # its scratch is on its stack (nothing allocated).
        eps = -1.0 if tolerance is None else _check_tolerance(tolerance)
        code = _state_into(a._kernel, b._kernel, eps)
        if code < 0:  # more vertices than the stack scratch holds
            if eps < 0.0:
                eps = a._tolerance if a._tolerance > b._tolerance else b._tolerance
            code = _state_full(a._xy, a._starts, b._xy, b._starts, eps)
        obj = _new(Relation)
        obj._state = _STATES[code]
        obj._tolerance = eps  # (below 0: the pair's default, read on first access)
        obj._a = a
        obj._b = b
        return obj
    return _classify_other(a, b, tolerance)


def _classify_other(a: ShapeLike, b: ShapeLike, tolerance: float | None) -> Relation:
    """:func:`classify` of bodies that are not both Shapes (and its first call)."""
    tol = -1.0 if tolerance is None else _check_tolerance(tolerance)
    if (
        type(a) is _ND
        and type(b) is _ND
        and a.dtype is _F64
        and b.dtype is _F64
        and a.ndim == 2
        and b.ndim == 2
        and a.flags.c_contiguous
        and b.flags.c_contiguous
    ):
        if not _RAW:
            from ._kernels.rings import classify_raw

            _RAW.append(classify_raw)
        code, eps, na, fa, nb, fb = _RAW[0](a, b, tol, *RING_ARGS)
        if code >= 0:
            # The lean path: the bytes are the copy the lazy parts are computed from.
            obj = _new(Relation)
            obj._state = _STATES[code]
            obj._tolerance = eps
            obj._a = (a.tobytes(), na, fa)
            obj._b = (b.tobytes(), nb, fb)
            return obj
    return classify(as_shape(a, "a"), as_shape(b, "b"), tolerance=tolerance)


@dataclass(frozen=True, eq=False)
class RelationBatch:
    """The relations of many pairs, as returned by :func:`classify_many`.

    Attributes
    ----------
    states : ndarray of shape (P,), int8
        0 separate, 1 contact, 2 penetrating (the order of :class:`State`).
    tolerances : ndarray of shape (P,), float64
        The absolute tolerance used for each pair.
    distances : ndarray of shape (P,), float64
        Signed distances as in :attr:`Relation.distance`; computed (in parallel) on
        first access and cached.

    Examples
    --------
    >>> sq = [(0, 0), (1, 0), (1, 1), (0, 1)]
    >>> batch = classify_many([sq, sq], [[(1, 0), (2, 0), (2, 1)], [(3, 0), (4, 0), (4, 1)]])
    >>> batch.states.tolist(), batch.distances.tolist(), batch.state(1)
    ([1, 0], [0.0, 2.0], <State.SEPARATE: 'separate'>)
    """

    states: np.ndarray
    tolerances: np.ndarray
    _pack: Callable[[], tuple[Any, ...]] = field(repr=False)  # the packed pairs, built on demand
    _threads: int = field(default=1, repr=False)  # the most threads of the distances

    def __len__(self) -> int:
        return int(self.states.shape[0])

    def state(self, i: int) -> State:
        """The :class:`State` of one pair.

        Parameters
        ----------
        i : int
            A pair index.

        Returns
        -------
        State
            ``State`` of ``states[i]``.

        Examples
        --------
        >>> sq = [(0, 0), (1, 0), (1, 1), (0, 1)]
        >>> classify_many([sq], [[(0.5, 0), (2, 0), (2, 1)]]).state(0)
        <State.PENETRATING: 'penetrating'>
        """
        return _STATES[int(self.states[i])]

    def __post_init__(self) -> None:
        self.states.flags.writeable = False
        self.tolerances.flags.writeable = False

    @cached_property
    def distances(self) -> np.ndarray:
        """Signed distance of every pair (gap, 0 at contact, minus the depth), read-only."""
        from ._depth import penetrations
        from ._kernels import relation_many as km
        from ._threads import numba_threads

        pack = self._pack()
        xa, lsa, bsa, fa, xb, lsb, bsb, fb = pack
        states, eps = self.states, self.tolerances
        out = np.concatenate(_split(len(states), lambda p0, p1: km.many_distances(
            xa, lsa, bsa[p0 : p1 + 1], fa[p0:p1], xb, lsb, bsb[p0 : p1 + 1], fb[p0:p1],
            states[p0:p1], eps[p0:p1]), self._threads))
        with numba_threads(self._threads):
            pen = np.flatnonzero(self.states == _STATES.index(State.PENETRATING))
            if pen.size:
                out[pen] = -penetrations(pack, pen, self.tolerances[pen])[:, 0]
        return _read_only(out)


def _split(count: int, fn: Any, threads: int) -> list[Any]:
    """Run ``fn(p0, p1)`` over chunks of range(count) on at most ``threads`` threads (the
    kernels release the GIL), no more than the work can use (a pair costs about
    :data:`polycontact._threads.PAIR_SECONDS`); returns the results in order."""
    from ._threads import PAIR_SECONDS, map_work

    return map_work(fn, count, PAIR_SECONDS, threads)


def raw_ring_array(arr: Any) -> np.ndarray | None:
    """``arr`` if it is a (P, N, 2) array of real rings, else None."""
    if not (isinstance(arr, np.ndarray) and arr.ndim == 3 and arr.shape[2] == 2):
        return None
    if arr.dtype.kind not in "fiu":
        return None
    return arr


def _ring_pack(arr: np.ndarray, used: np.ndarray, sign: np.ndarray) -> tuple[Any, ...]:
    """Packed batch form of P validated rings ``arr`` (P, N, 2), ``used[p]`` vertices each."""
    p_count, n = arr.shape[0], arr.shape[1]
    lo = np.arange(p_count, dtype=np.int64) * n
    ls = np.empty(2 * p_count, dtype=np.int64)
    ls[0::2] = lo
    ls[1::2] = lo + used
    return arr.reshape(-1, 2), ls, np.arange(0, 2 * p_count + 1, 2, dtype=np.int64), sign


def _pack_ring_array(arr: np.ndarray, what: str) -> tuple[Any, ...]:
    """:func:`pack_bodies` of a (P, N, 2) ring array: a float64 copy, its rings checked
    in one kernel pass (as :func:`_classify_arrays` checks them), packed as they are;
    when a ring is not certified valid, every ring goes through ``pack_bodies``, whose
    errors name it (``shapes_a[3]: ...``)."""
    from ._kernels import relation_many as km

    copy = np.array(arr, dtype=np.float64, order="C")
    p_count, n = copy.shape[0], copy.shape[1]
    used, sign = km.check_rings(copy.reshape(-1, 2), np.arange(p_count, dtype=np.int64) * n,
                                np.full(p_count, n, dtype=np.int64), *RING_ARGS)
    if (used < 0).any():
        return pack_bodies(list(copy), what)
    return _ring_pack(copy, used, sign)


def _classify_arrays(
    arr_a: np.ndarray, arr_b: np.ndarray, tol: float, threads: int
) -> RelationBatch | None:
    """:func:`classify_many` of two (P, N, 2) ring arrays in one kernel pass per thread;
    None if some ring is not certified valid as given (the caller then decides and
    explains through ``Shape``)."""
    from ._kernels import relation_many as km

    out = km.raw_states_outputs(arr_a.shape[0])
    # The rings are copied (float64, C order), each chunk by the thread that classifies
    # it, just before (in parallel, and still in cache for the kernel): the distances,
    # computed on first access, read the copies, never the caller's arrays, which the
    # caller may have reused since. The copies live in buffers of _BUFFERS.
    buf_a, buf_b = _BUFFERS.take(arr_a.size), _BUFFERS.take(arr_b.size)
    copy_a = buf_a[: arr_a.size].reshape(arr_a.shape)
    copy_b = buf_b[: arr_b.size].reshape(arr_b.shape)

    def chunk(p0: int, p1: int) -> None:
        copy_a[p0:p1] = arr_a[p0:p1]
        copy_b[p0:p1] = arr_b[p0:p1]
        km.raw_states(copy_a[p0:p1], copy_b[p0:p1], tol, *RING_ARGS,
                      tuple(o[p0:p1] for o in out))

    try:
        _split(arr_a.shape[0], chunk, threads)
    except BaseException:
        _BUFFERS.give(buf_a, buf_b)
        raise
    states, eps, used_a, sign_a, used_b, sign_b = out
    if (states < 0).any():
        _BUFFERS.give(buf_a, buf_b)
        return None
    batch = RelationBatch(
        states, eps,
        lambda: (*_ring_pack(copy_a, used_a, sign_a), *_ring_pack(copy_b, used_b, sign_b)),
        threads,
    )
    weakref.finalize(batch, _BUFFERS.give, buf_a, buf_b)  # reused once the batch is gone
    return batch


class _BufferPool:
    """Float64 buffers for the copies of :func:`classify_many`'s ring arrays, reused once
    the batch that held one is gone. A fresh array of tens of megabytes has its pages
    mapped on first touch, a sizeable part of a batch's classification; a loop of
    batches reuses the same few buffers instead.

    >>> pool = _BufferPool()
    >>> b = pool.take(10); pool.give(b); pool.take(8) is b
    True
    """

    #: Buffers kept for reuse at most (the largest are kept), and their floats at most
    #: (64 MiB: a batch of 100 000 pairs of 12-gons needs 38 MB).
    KEEP = 2
    KEEP_FLOATS = 8 * 2**20

    def __init__(self) -> None:
        self._free: list[np.ndarray] = []
        self._lock = threading.Lock()

    def take(self, size: int) -> np.ndarray:
        """A buffer of at least ``size`` floats (at most twice as many: a small batch
        does not hold a large buffer)."""
        with self._lock:  # (the free list is sorted by size)
            for k, buf in enumerate(self._free):
                if size <= buf.size <= 2 * size:
                    return self._free.pop(k)
        return np.empty(size)

    def give(self, *buffers: np.ndarray) -> None:
        """Take ``buffers`` back (no one reads them any more)."""
        with self._lock:
            self._free.extend(buffers)
            self._free.sort(key=lambda b: b.size)
            del self._free[: max(0, len(self._free) - self.KEEP)]
            while sum(b.size for b in self._free) > self.KEEP_FLOATS:
                del self._free[-1]


_BUFFERS = _BufferPool()


def _pack_sequence(items: Sequence[Any] | np.ndarray, what: str,
                   made: list[Any] | None = None) -> tuple[Any, ...]:
    """Pack Shapes, polygons and raw (N, 2) rings; raw rings are checked in a kernel.
    ``made``, if given, receives the Shape packed for each item (None for a raw ring
    packed as it is, stored reversed where ``sign`` < 0)."""
    from ._kernels import relation_many as km

    if set(map(type, items)) <= {Shape}:  # (every body a Shape: packed without a loop)
        if made is not None:
            made[:] = items
        xy, rows, starts, st_off, _ = shapes_packed(list(items))
        return xy, starts + np.repeat(rows[:-1], np.diff(st_off)), st_off, np.ones(len(items))
    bodies: list[Any] = []
    raw: list[int] = []
    for i, it in enumerate(items):
        if isinstance(it, Shape):
            bodies.append(it)
        elif isinstance(it, np.ndarray) and it.dtype == np.float64 and it.ndim == 2 and (
            it.shape[1] == 2
        ):
            bodies.append(it)
            raw.append(i)
        else:
            bodies.append(as_shape(it, f"{what}[{i}]"))
    sign = np.ones(len(bodies))
    if raw:
        rings = [bodies[i] for i in raw]
        n = np.array([len(r) for r in rings], dtype=np.int64)
        lo = np.zeros(len(rings), dtype=np.int64)
        lo[1:] = np.cumsum(n)[:-1]
        xy = np.concatenate(rings) if rings else np.empty((0, 2))
        used, sg = km.check_rings(xy, lo, n, *RING_ARGS)
        for k, i in enumerate(raw):
            if used[k] < 0:
                bodies[i] = as_shape(items[i], f"{what}[{i}]")
            else:
                bodies[i] = bodies[i][: used[k]]
                sign[i] = sg[k]
    if made is not None:
        made[:] = [body if isinstance(body, Shape) else None for body in bodies]
    chunks = []
    ls: list[int] = []
    bs = [0]
    row = 0
    for body in bodies:
        if isinstance(body, Shape):
            xy, st = body.packed
            chunks.append(xy)
            ls.extend((st + row).tolist())
        else:
            chunks.append(body)
            ls.extend((row, row + len(body)))
        row += len(chunks[-1])
        bs.append(len(ls))
    xy = np.ascontiguousarray(np.concatenate(chunks)) if chunks else np.empty((0, 2))
    return xy, np.array(ls, dtype=np.int64), np.array(bs, dtype=np.int64), sign


def shapes_packed(shapes: Sequence[Any]) -> tuple[np.ndarray, ...]:
    """The stored coordinates of many shapes one after another, ``(xy, rows, starts,
    st_off, sizes)``: shape k's rows are ``xy[rows[k]:rows[k + 1]]``, its loop starts
    (relative to its first row) ``starts[st_off[k]:st_off[k + 1]]`` and ``sizes[k]`` its
    area centroid, bounding radius and extent. Each shape's kernel pack (the bytes
    ``classify`` hands the kernels) is joined with the others and read in compiled code,
    in parallel: per shape, only the few tens of nanoseconds of the join.

    >>> sq = Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
    >>> [a.tolist() for a in shapes_packed([sq, sq])[1:4]]
    [[0, 4, 8], [0, 4, 0, 4], [0, 2, 4]]
    >>> shapes_packed([sq])[4].round(6).tolist()
    [[0.5, 0.5, 0.707107, 1.0]]
    """
    return kernels_unpacked(map(_KERNEL, shapes), len(shapes))


def kernels_unpacked(kernels: Iterable[bytes], count: int) -> tuple[np.ndarray, ...]:
    """:func:`shapes_packed` of the ``count`` shapes whose kernel packs
    (``Shape._kernel``) are ``kernels``: the packs joined, then read in compiled code on
    the threads the threading policy gives.

    >>> sq = Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
    >>> kernels_unpacked([sq._kernel], 1)[1].tolist()
    [0, 4]
    """
    from ._kernels.packs import unpack_shapes
    from ._threads import chunks

    out: tuple[np.ndarray, ...] = unpack_shapes(
        np.frombuffer(b"".join(kernels), np.float64), count, chunks(count, _UNPACK_WORK))
    return out


#: Copying a shape's kernel pack (a 12-gon's) in pair classifications (see
#: :func:`polycontact._threads.chunks`).
_UNPACK_WORK = 0.1


_KERNEL = operator.attrgetter("_kernel")


def pack_bodies(items: Any, what: str, made: list[Any] | None = None) -> tuple[Any, ...]:
    if isinstance(items, np.ndarray) and items.ndim == 3:
        items = list(items)
    if isinstance(items, (str, bytes)) or not isinstance(items, Sequence | np.ndarray):
        raise TypeError(
            f"{what}: expected a sequence of bodies or an array of shape (P, N, 2), "
            f"got {type(items).__name__}"
        )
    return _pack_sequence(items, what, made)


def pack_states(xa: np.ndarray, lsa: np.ndarray, bsa: np.ndarray, fa: np.ndarray,
                xb: np.ndarray, lsb: np.ndarray, bsb: np.ndarray, fb: np.ndarray,
                tol: float, threads: int) -> tuple[np.ndarray, np.ndarray]:
    """States and tolerances of the pairs of two packed batches (``pack_bodies``), on at
    most ``threads`` threads, each into its part of the results."""
    from ._kernels import relation_many as km

    p_count = len(fa)
    states = np.empty(p_count, np.int8)
    eps = np.empty(p_count)

    def chunk(p0: int, p1: int) -> None:
        states[p0:p1], eps[p0:p1] = km.many_states(
            xa, lsa, bsa[p0 : p1 + 1], fa[p0:p1], xb, lsb, bsb[p0 : p1 + 1], fb[p0:p1], tol,
            RELATIVE_TOLERANCE, ROUNDING_ULPS,
        )

    _split(p_count, chunk, threads)
    return states, eps


def _remote_states(client: Any, packs: tuple[Any, ...], tol: float,
                    chunk_size: int | None) -> tuple[np.ndarray, np.ndarray]:
    """The states and tolerances of the packed pairs ``packs`` (both sides'
    ``pack_bodies``) as :func:`classify_many` computes them, in tasks on the cluster of
    ``client`` (each with the slices of the packed arrays its pairs need)."""
    from ._cluster import run_spans

    count = len(packs[3])
    states = np.empty(count, np.int8)
    tols = np.empty(count)

    def tasks_of(spans: list[tuple[int, int]]) -> tuple[Any, list[Any]]:
        return None, [(_pack_slice(packs[:4], p0, p1), _pack_slice(packs[4:], p0, p1))
                      for p0, p1 in spans]

    with closing(run_spans(client, _states_task, count, tasks_of, tol,
                           chunk_size=chunk_size, family="classification")) as results:
        for p0, p1, (st, e) in results:
            states[p0:p1] = st
            tols[p0:p1] = e
    return states, tols


def _remote_arrays(client: Any, arr_a: np.ndarray, arr_b: np.ndarray, tol: float,
                   chunk_size: int | None, threads: int) -> RelationBatch | None:
    """:func:`_classify_arrays` in tasks on the cluster of ``client``: each task checks
    and classifies its slice of the two ring arrays in one kernel pass, as locally, so
    the calling process only copies the arrays (on ``threads`` threads) and sends them.
    None if some ring is not certified valid as given (the caller then decides and
    explains through ``Shape``, here)."""
    from ._cluster import run_spans
    from ._kernels import relation_many as km

    copy_a = np.empty(arr_a.shape)
    copy_b = np.empty(arr_b.shape)

    def copy(p0: int, p1: int) -> None:
        copy_a[p0:p1] = arr_a[p0:p1]
        copy_b[p0:p1] = arr_b[p0:p1]

    _split(len(arr_a), copy, threads)
    out = km.raw_states_outputs(len(arr_a))

    def tasks_of(spans: list[tuple[int, int]]) -> tuple[Any, list[Any]]:
        return None, [(copy_a[p0:p1], copy_b[p0:p1]) for p0, p1 in spans]

    with closing(run_spans(client, _ring_states_task, len(arr_a), tasks_of, tol,
                           chunk_size=chunk_size, family="ring arrays")) as results:
        for p0, p1, part in results:
            for whole, got in zip(out, part):
                whole[p0:p1] = got
    states, eps, used_a, sign_a, used_b, sign_b = out
    if (states < 0).any():
        return None
    return RelationBatch(
        states, eps,
        lambda: (*_ring_pack(copy_a, used_a, sign_a), *_ring_pack(copy_b, used_b, sign_b)),
        threads,
    )


def _ring_states_task(_: Any, task: tuple[np.ndarray, np.ndarray],
                      tol: float) -> tuple[np.ndarray, ...]:
    """One task of :func:`_remote_arrays`: the checks and states of its pairs of rings
    (:func:`polycontact._kernels.relation_many.raw_states`)."""
    from ._kernels import relation_many as km

    xa, xb = task
    out: tuple[np.ndarray, ...] = km.raw_states(xa, xb, tol, *RING_ARGS,
                                                km.raw_states_outputs(len(xa)))
    return out


def _pack_slice(pack: tuple[Any, ...], p0: int, p1: int) -> tuple[Any, ...]:
    """The bodies ``p0:p1`` of a ``pack_bodies`` result ``(xy, ls, bs, sign)``, packed
    alone (their rows, loop starts and body starts renumbered from 0)."""
    xy, ls, bs, sign = pack
    b0, b1 = int(bs[p0]), int(bs[p1])
    r0 = int(ls[b0]) if b1 > b0 else 0
    r1 = int(ls[b1 - 1]) if b1 > b0 else 0
    return (xy[r0:r1], ls[b0:b1] - r0, bs[p0:p1 + 1] - b0, sign[p0:p1])


def _states_task(_: Any, task: tuple[Any, ...], tol: float) -> tuple[np.ndarray, np.ndarray]:
    """One task of :func:`_remote_states`."""
    (xa, lsa, bsa, fa), (xb, lsb, bsb, fb) = task
    return pack_states(xa, lsa, bsa, fa, xb, lsb, bsb, fb, tol, 1)


def classify_many(
    shapes_a: Sequence[ShapeLike] | np.ndarray, shapes_b: Sequence[ShapeLike] | np.ndarray, *,
    tolerance: float | None = None, threads: int | None = None, client: Any = None,
    chunk_size: int | None = None,
) -> RelationBatch:
    """Classify many pairs ``(shapes_a[i], shapes_b[i])`` in one call.

    The pairs are shared among threads (the compiled kernels release the GIL), as many
    as the threading policy of :doc:`conventions` gives; the signed distances, on first
    access, run in parallel too. With a Dask client the pairs run as tasks on the
    cluster instead, after the same checks here, with the same result (ring arrays are
    checked in the tasks, in the pass that classifies them; a ring they cannot certify
    is decided here, with the error a local call gives).

    Parameters
    ----------
    shapes_a, shapes_b : sequence of bodies, or ndarray of shape (P, N, 2)
        Bodies as for :func:`classify` (Shape, shapely Polygon, (N, 2) array), or the
        packed form: a float64 array of P outer rings of N vertices each (closed or
        not, either orientation), copied once (the distances, computed on first
        access, are those of the rings as they were at the call).
    tolerance : float, optional
        Absolute tolerance for every pair; default per pair as in :func:`classify`.
    threads : int, optional
        At most this many threads (default ``numba.get_num_threads()``).
    client : dask.distributed.Client, optional
        Run on this Dask cluster; by default the current Dask client if there is one
        (see :func:`polycontact.distributed.current_client`).
    chunk_size : int, optional
        Pairs per Dask task (default: sized from a first task, see
        :func:`polycontact.distributed.run_spans`).

    Returns
    -------
    RelationBatch
        ``states`` (int8 codes), ``tolerances``, and ``distances`` on demand.

    Examples
    --------
    >>> import numpy as np
    >>> sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    >>> batch = classify_many(np.stack([sq, sq, sq]), np.stack([sq + 2, sq + 1, sq + 0.5]))
    >>> batch.states.tolist(), batch.distances.round(6).tolist()
    ([0, 1, 2], [1.414214, 0.0, -0.5])
    """
    from ._cluster import check_chunk_size, current_client
    from ._threads import requested

    tol = -1.0 if tolerance is None else _check_tolerance(tolerance)
    n_threads = requested(threads)
    check_chunk_size(chunk_size)
    remote = current_client(client)
    arr_a = raw_ring_array(shapes_a)
    arr_b = raw_ring_array(shapes_b)
    if arr_a is not None and arr_b is not None and len(arr_a) == len(arr_b):
        batch = (_classify_arrays(arr_a, arr_b, tol, n_threads) if remote is None else
                 _remote_arrays(remote, arr_a, arr_b, tol, chunk_size, n_threads))
        if batch is not None:
            return batch
    pa = _pack_ring_array(arr_a, "shapes_a") if arr_a is not None else pack_bodies(
        shapes_a, "shapes_a")
    pb = _pack_ring_array(arr_b, "shapes_b") if arr_b is not None else pack_bodies(
        shapes_b, "shapes_b")
    if len(pa[3]) != len(pb[3]):
        raise ValueError(
            f"shapes_a and shapes_b differ in length ({len(pa[3])} and {len(pb[3])})"
        )
    if remote is None:
        xa, lsa, bsa, fa = pa
        xb, lsb, bsb, fb = pb
        states, eps = pack_states(xa, lsa, bsa, fa, xb, lsb, bsb, fb, tol, n_threads)
    else:
        states, eps = _remote_states(remote, (*pa, *pb), tol, chunk_size)
    return RelationBatch(states, eps, lambda: (*pa, *pb), n_threads)
