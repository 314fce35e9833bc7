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

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, cast

import numpy as np
import numpy.typing as npt

from ._checks import finite_number, points, real_array
from ._checks import point as point_arg
from .motion import Motion
from .relation import Relation, classify, raw_ring_inputs
from .bodies import BodyLike, as_shape
from .shape import Shape
from .tolerances import RELATIVE_TOLERANCE, ROUNDING_FACTOR, check_range, default_tolerance

__all__ = ["World", "WorldBody", "Contacts", "Query"]

#: query_many tests every body's box, not the grid's cells, up to this many bodies.
_SCAN_BODIES = 64


def _k() -> Any:
    from ._kernels import world

    return world


def _chunks(count: int) -> int:
    """Parallel chunks for ``count`` items: 1 (serial, no thread start) below 4096."""
    import numba

    return 1 if count < 4096 else 4 * numba.get_num_threads()


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
    """Every pair of bodies in contact or penetrating, as returned by
    :meth:`World.contacts`.

    Attributes
    ----------
    pairs : ndarray of shape (K, 2), int64
        Body ids, smaller first, sorted.
    states : ndarray of shape (K,), int8
        1 contact, 2 penetrating.
    tolerances : ndarray of shape (K,), float64
        The tolerance each pair was classified with.
    container_ids, container_states : ndarray of shape (M,)
        Bodies that touch the container's boundary (1) or leave it / enter a hole (2);
        empty without a container.
    ids : ndarray of shape (N,), int64
        Every body of the world when asked, sorted.
    container : Shape or None
        The world's container.
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
    # each body's map to the caller's numbering (see World._inputs), by id
    _inputs: dict[int, Any] = field(default_factory=dict, repr=False)

    def __post_init__(self) -> None:
        for array in (self.pairs, self.states, self.tolerances, self.container_ids,
                      self.container_states, self.ids):
            array.flags.writeable = False  # a result cannot be changed

    def __len__(self) -> int:
        return len(self.states)

    def relation(self, k: int) -> Relation:
        """The full :class:`~polycontact.Relation` of pair ``k`` (features, point,
        normal, depth), as :func:`polycontact.classify` gives it."""
        k = _integer(k, "k")
        if not 0 <= k < len(self.states):
            raise IndexError(f"k: pair {k} out of range (0..{len(self.states) - 1})")
        i, j = (int(v) for v in self.pairs[k])
        xy, ls, lo, nl = self._store
        a = _stored_shape(xy, ls, int(lo[i]), int(nl[i]), self._inputs.get(i))
        b = _stored_shape(xy, ls, int(lo[j]), int(nl[j]), self._inputs.get(j))
        return classify(a, b, tolerance=self._tolerance)

    @property
    def penetrating(self) -> np.ndarray:
        """The pairs that penetrate, (P, 2)."""
        return cast("np.ndarray", self.pairs[self.states == 2])

    def shape(self, id: int) -> Shape:
        """The Shape of body ``id`` as it was when the contacts were found."""
        id = _integer(id, "id")
        _, _, lo, nl = self._store
        if id not in set(self.ids.tolist()):
            raise IndexError(f"id: no body {id} among the contacts' bodies")
        return _stored_shape(self._store[0], self._store[1], int(lo[id]), int(nl[id]),
                             self._inputs.get(id))

    def to_dict(self, names: Any = None) -> dict[str, Any]:
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
            ``"contact"`` or ``"penetrating"``, witness ``point``) and
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
                          "state": "contact" if self.states[k] == 1 else "penetrating",
                          "point": None if point is None else [float(v) for v in point]})
        container = [{"body": i, "name": name(i), "state": "contact" if s == 1 else "outside"}
                     for i, s in zip(self.container_ids.tolist(),
                                     self.container_states.tolist())]
        return {"bodies": len(self.ids), "container": self.container is not None,
                "contacts": pairs, "container_contacts": container}

    def plot(self, ax: Any = None) -> Any:
        """Draw the bodies (penetrating ones red, those leaving the container orange),
        the container, the contact points and penetrations; returns the matplotlib Axes.

        See :func:`polycontact.plotting.plot_contacts`.
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


def _angle(angle: Any) -> float:
    return finite_number(angle, "angle")


def _integer(value: Any, what: str) -> int:
    """``value`` as an int, if it is an integer (Python or NumPy, not a bool), else a
    TypeError naming ``what``: a float id is not rounded to a body."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"{what}: expected an integer, got {type(value).__name__} {value!r}")
    return int(value)


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
        base._input,
    )


def _body_tolerances(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """:func:`polycontact.default_tolerance` of each body alone, from its box corners
    (B, 2), vectorised with the same operations. A pair's default tolerance is the larger
    of its two bodies' (a maximum of per-body terms), which the kernels take."""
    extent = np.maximum(hi[:, 0] - lo[:, 0], hi[:, 1] - lo[:, 1])
    magnitude = np.maximum(-lo.min(axis=1), hi.max(axis=1))
    return cast("np.ndarray", np.maximum(RELATIVE_TOLERANCE * extent, ROUNDING_FACTOR * magnitude))


def _stored_shape(xy: np.ndarray, ls: np.ndarray, lo: int, nl: int,
                  inputs: Any = None) -> Shape:
    """The Shape of a body stored at loop-start row ``lo`` with ``nl`` loops (a copy),
    numbered as the caller gave it: ``inputs`` is the body's entry of
    ``World._inputs`` (None: the stored order is the caller's)."""
    st = ls[lo : lo + nl + 1]
    if isinstance(inputs, int):  # a raw ring stored reversed, of that many vertices
        inputs = raw_ring_inputs(inputs, -1.0)
    return Shape._trusted([xy[st[k] : st[k + 1]].copy() for k in range(nl)], inputs=inputs)


def _pow2(n: int) -> int:
    return 1 << max(6, (n - 1).bit_length())


class World:
    """Bodies that stay valid between calls, with a compiled, incremental broad phase.

    Parameters
    ----------
    container : Shape, shapely Polygon or array_like of shape (N, 2), optional
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
    """

    def __init__(self, container: BodyLike | None = None) -> None:
        # id -> [name, base, position, angle, motion, shape]; base, position and shape
        # are None until asked for (bodies added by add_many are kept as coordinates).
        self._records: dict[int, list[Any]] = {}
        # Each body's map to the caller's numbering, where the stored order is not the
        # caller's: ``Shape._input`` of the shape as added, or the vertex count of a
        # raw ring stored reversed (the map is made when asked for). Ids are never
        # reused, so an entry stays right for the contacts found before a removal.
        self._inputs: dict[int, Any] = {}
        self._shared = False  # a Contacts holds self._xy: copy it before writing in place
        self._next = 0
        cap = 64
        self._box = np.zeros((cap, 4))
        self._eps = np.zeros(cap)
        self._lo = np.zeros(cap, np.int64)
        self._nl = np.zeros(cap, np.int64)
        self._level = np.full(cap, -1, np.int64)
        self._slot = np.full(cap, -1, np.int64)
        self._nxt = np.full(cap, -1, np.int64)
        self._prv = np.full(cap, -1, np.int64)
        self._xy = np.zeros((1024, 2))
        self._ls = np.zeros(256, np.int64)
        self._vtop = 0
        self._ltop = 0
        self._garbage = 0
        self._vmax = 0
        self._lmax = 1
        self._emax = 0.0  # an upper bound of the bodies' tolerances (never lowered)
        self._origin: np.ndarray | None = None
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

    # -- bodies ----------------------------------------------------------------------
    def __len__(self) -> int:
        return len(self._records)

    def __contains__(self, id: Any) -> bool:
        return id in self._records

    @property
    def ids(self) -> np.ndarray:
        """Ids of the bodies, ascending."""
        return np.array(sorted(self._records), dtype=np.int64)

    def bodies(self) -> tuple[WorldBody, ...]:
        """Every body (read-only records), by id."""
        return tuple(self.body(i) for i in sorted(self._records))

    def body(self, id: int) -> WorldBody:
        """The body with this id (a read-only record)."""
        id = _integer(id, "id")
        try:
            rec = self._records[id]
        except KeyError:
            raise KeyError(f"id: no body {id!r} in this world (never added, or removed)") from None
        if rec[5] is None:
            rec[5] = _stored_shape(self._xy, self._ls, int(self._lo[id]), int(self._nl[id]),
                                   self._inputs.get(id))
        if rec[1] is None:
            rec[1] = rec[5]
        if rec[2] is None:
            rec[2] = rec[1].centroid.copy()
        return WorldBody(int(id), rec[0], rec[5], rec[1], rec[2], rec[3], rec[4])

    def add(self, shape: BodyLike, position: npt.ArrayLike | None = None, angle: float = 0.0, *,
            motion: Motion | None = None, name: str | None = None) -> int:
        """Add a body; returns its id (ids are never reused).

        Parameters
        ----------
        shape : Shape, shapely Polygon or array_like of shape (N, 2)
        position : (x, y), optional
            Where the shape's area centroid goes; None keeps the shape where it is.
        angle : float
            Radians, counter-clockwise, about the centroid.
        motion : Motion, optional
            Stored with the body for the moving-body queries.
        name : str, optional
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
        self._store_many(np.array([b]), [placed.packed])
        self._index(b)
        self._records[b] = [name, base, None if pos is None else pos.copy(), ang, motion, placed]
        self._inputs[b] = base._input
        return b

    def add_many(self, shapes: Any, *, names: Any = None) -> np.ndarray:
        """Add many bodies where their coordinates are; returns their ids.

        Raw rings are validated together in one compiled call (as
        :func:`polycontact.classify_many` does) and the broad phase takes them in one
        pass, so this is much faster than :meth:`add` in a loop; the answers are the
        same.

        Parameters
        ----------
        shapes : sequence of bodies, or ndarray of shape (P, N, 2)
            As for :func:`polycontact.classify_many`.
        names : sequence of str, optional

        Examples
        --------
        >>> import numpy as np, polycontact as pc
        >>> sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
        >>> w = pc.World()
        >>> w.add_many(np.stack([sq, sq + 1, sq + 3])).tolist()
        [0, 1, 2]
        >>> w.contacts().pairs.tolist()
        [[0, 1]]
        """
        from .relation import pack_bodies

        made: list[Any] = []
        xy, ls, bs, sign = pack_bodies(shapes, "shapes", made)
        count = len(sign)
        if names is not None:
            if isinstance(names, (str, bytes)) or not isinstance(names, (Sequence, np.ndarray)):
                raise TypeError(f"names: expected a sequence of {count} strings, got "
                                f"{type(names).__name__}")
            names = list(names)
            if len(names) != count or not all(isinstance(n, str) for n in names):
                raise ValueError(f"names: expected {count} strings")
        loops = []
        for p in range(count):
            st = ls[bs[p] : bs[p + 1]]
            rows = xy[st[0] : st[-1]]
            if sign[p] < 0:  # a clockwise raw ring: stored counter-clockwise, as Shape does
                rows = rows[::-1]
            loops.append((rows, st - st[0]))
        xy_all = np.concatenate([r for r, _ in loops]) if loops else np.empty((0, 2))
        check_range(xy_all, "shapes")
        first = self._next
        self._next += count
        self._grow_bodies(self._next)
        ids = np.arange(first, first + count, dtype=np.int64)
        self._store_many(ids, loops)
        for k, b in enumerate(ids.tolist()):
            self._records[b] = [None if names is None else names[k], None, None, 0.0, None,
                                None]
            if made[k] is not None:
                self._inputs[b] = made[k]._input
            elif sign[k] < 0:
                self._inputs[b] = len(loops[k][0])
        self._index_many(ids)
        return ids

    def move(self, id: int, position: Any = None, angle: float | None = None) -> None:
        """Put body ``id`` at a new pose (None keeps the current position or angle); the
        pose applies to the shape as added."""
        id = _integer(id, "id")
        rec = self.body(id)
        pos = rec.position if position is None else point_arg(position, "position")
        if self._shared:
            self._xy = self._xy.copy()
            self._shared = False
        ang = rec.angle if angle is None else _angle(angle)
        placed = _place(rec.base, pos, ang, "body placed at position")
        self._unindex(id)
        xy, starts = placed.packed
        lo = self._lo[id]
        first = self._ls[lo]
        self._xy[first : first + len(xy)] = xy  # same vertex count: in place
        self._set_box(id, xy)
        self._index(id)
        self._records[id] = [rec.name, rec.base, pos.copy(), ang, rec.motion, placed]

    def remove(self, id: int) -> None:
        """Take body ``id`` out of the world."""
        id = _integer(id, "id")
        self.body(id)
        self._unindex(id)
        lo, nl = self._lo[id], self._nl[id]
        self._garbage += int(self._ls[lo + nl] - self._ls[lo])
        del self._records[id]
        if self._garbage > 1024 and self._garbage > self._vtop // 2:
            self._compact()

    # -- storage (private) -------------------------------------------------------------
    def _grow_bodies(self, n: int) -> None:
        cap = len(self._eps)
        if n <= cap:
            return
        new = max(n, 2 * cap)
        for name in ("_box", "_eps", "_lo", "_nl", "_level", "_slot", "_nxt", "_prv"):
            old = getattr(self, name)
            arr = np.full((new, *old.shape[1:]), -1 if old.dtype == np.int64 else 0.0,
                          old.dtype)
            arr[:cap] = old
            setattr(self, name, arr)

    def _set_box(self, b: int, xy: np.ndarray) -> None:
        lo = xy.min(axis=0)
        hi = xy.max(axis=0)
        self._box[b] = (lo[0], hi[0], lo[1], hi[1])
        self._eps[b] = _body_tolerances(lo[None, :], hi[None, :])[0]
        self._emax = max(self._emax, float(self._eps[b]))

    def _compact(self) -> None:
        """Drop the coordinates of removed bodies (moves overwrite in place)."""
        ids = np.array(sorted(self._records), np.int64)
        old_xy, old_ls, old_lo, old_nl = self._xy, self._ls, self._lo.copy(), self._nl.copy()
        self._vtop = self._ltop = self._garbage = 0
        self._xy = np.zeros((max(1024, 2 * len(old_xy) // 2), 2))
        self._ls = np.zeros(max(256, len(old_ls)), np.int64)
        self._shared = False
        loops = []
        for b in ids.tolist():
            st = old_ls[old_lo[b] : old_lo[b] + old_nl[b] + 1]
            loops.append((old_xy[st[0] : st[-1]], st - st[0]))
        self._store_many(ids, loops)

    def _store_many(self, ids: np.ndarray, loops: list[Any]) -> None:
        """Append bodies given as (rows, local loop starts), and set boxes and tolerances."""
        if not loops:
            return
        nv = np.array([len(r) for r, _ in loops], np.int64)
        nl = np.array([len(st) - 1 for _, st in loops], np.int64)
        v_need, l_need = int(nv.sum()), int((nl + 1).sum())
        if self._vtop + v_need > len(self._xy):
            self._xy = np.concatenate([self._xy, np.zeros((max(v_need, len(self._xy)), 2))])
        if self._ltop + l_need > len(self._ls):
            self._ls = np.concatenate([self._ls, np.zeros(max(l_need, len(self._ls)),
                                                          np.int64)])
        voff = self._vtop + np.concatenate([[0], np.cumsum(nv)[:-1]])
        loff = self._ltop + np.concatenate([[0], np.cumsum(nl + 1)[:-1]])
        rows = np.concatenate([r for r, _ in loops])
        self._xy[self._vtop : self._vtop + v_need] = rows
        self._ls[self._ltop : self._ltop + l_need] = np.concatenate(
            [st + o for (_, st), o in zip(loops, voff.tolist())])
        self._lo[ids] = loff
        self._nl[ids] = nl
        self._vtop += v_need
        self._ltop += l_need
        self._vmax = max(self._vmax, int(nv.max()))
        self._lmax = max(self._lmax, int(nl.max()))
        lo = np.minimum.reduceat(rows, voff - voff[0])
        hi = np.maximum.reduceat(rows, voff - voff[0])
        self._box[ids] = np.c_[lo[:, 0], hi[:, 0], lo[:, 1], hi[:, 1]]
        self._eps[ids] = _body_tolerances(lo, hi)
        self._emax = max(self._emax, float(self._eps[ids].max()))

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
        return np.fromiter(self._records, np.int64, len(self._records))

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
    def contacts(self, tolerance: float | None = None) -> Contacts:
        """Every pair of bodies in contact or penetrating, and the bodies that touch or
        leave the container.

        Parameters
        ----------
        tolerance : float, optional
            Absolute tolerance for every pair; default per pair as in
            :func:`polycontact.classify`.

        Returns
        -------
        Contacts
        """
        k = _k()
        tol = self._tol(tolerance)
        alive = np.sort(self._alive())
        pi, pj = k.candidate_pairs(self._grid(), self._box, self._eps, tol, alive, self._next)
        states, used = k.classify_pairs(self._bodies(), tol, pi, pj, self._vmax, self._lmax,
                                        _chunks(len(pi)))
        hit = np.flatnonzero(states)
        if self._next < 2**31:  # one key per pair, no overflow: one sort, not a lexsort
            hit = hit[np.argsort(pi[hit] * self._next + pj[hit], kind="stable")]
        else:
            hit = hit[np.lexsort((pj[hit], pi[hit]))]
        pairs = np.stack([pi[hit], pj[hit]], axis=1)
        states, used = states[hit], used[hit]
        if self._container is not None and len(alive):
            cst = k.container_states(self._bodies(), tol, alive, self._hazards(), self._vmax,
                                     self._lmax, self._hmax, _chunks(len(alive)))
            c_ids, c_states = alive[cst > 0], cst[cst > 0]
        else:
            c_ids, c_states = np.empty(0, np.int64), np.empty(0, np.int8)
        self._shared = True
        store = (self._xy, self._ls, self._lo.copy(), self._nl.copy())
        return Contacts(pairs, states, used, c_ids, c_states, store,
                        None if tolerance is None else tol, alive, self._container,
                        self._inputs)

    def query(self, shape: BodyLike, position: npt.ArrayLike | None = None, angle: float = 0.0, *,
              tolerance: float | None = None) -> Query:
        """How ``shape``, placed like :meth:`add` would place it, lies among the bodies.

        Returns
        -------
        Query
            ``ids`` and ``states`` of the bodies it touches or penetrates,
            ``container_state``, ``inside_container`` and ``fits``.
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

    def query_many(self, shape: BodyLike, positions: npt.ArrayLike, angles: npt.ArrayLike = 0.0, *,
                   tolerance: float | None = None) -> np.ndarray:
        """Worst state over every body and the container (outside counts as 2) of
        ``shape`` placed at each of P poses, in one compiled call.

        Parameters
        ----------
        shape : Shape, shapely Polygon or array_like of shape (N, 2)
        positions : array_like of shape (P, 2)
            Where the shape's area centroid goes: real numbers (not strings, booleans
            or complex numbers), finite and within ±1e100.
        angles : float or array_like of shape (P,)
            Radians, about the centroid.

        Returns
        -------
        ndarray of shape (P,), int8
        """
        base = as_shape(shape, "shape")
        pos = points(positions, "positions")
        if np.ndim(angles) == 0 and not isinstance(angles, (str, bytes)):
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
        # A few bodies: testing every box is cheaper than visiting the grid's cells
        # (measured on the swim layout, 43 bodies: ~140 vs ~270 ns per placement).
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
    def first_impacts(self, t_max: float, **options: Any) -> list[tuple[int, int, Any]]:
        """Every pair of bodies that meets within ``[0, t_max]`` as they follow their
        motions (the ``motion`` given to :meth:`add`; a body without one stays put),
        sorted by time: ``(id_a, id_b, impact)`` with ``id_a < id_b``.

        ``impact`` equals :func:`polycontact.time_of_impact` of the two bodies as placed
        now; only pairs whose swept bounds meet are searched
        (:func:`polycontact.first_impacts`, whose ``options`` these are). The container
        is not a moving hazard: leaving it is not reported here.

        Examples
        --------
        >>> import polycontact as pc
        >>> sq = pc.Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
        >>> w = pc.World()
        >>> a = w.add(sq, (0.5, 0.5), motion=pc.Motion(velocity=(1, 0)))
        >>> b = w.add(sq, (3.5, 0.5))
        >>> [(i, j, round(imp.time, 3)) for i, j, imp in w.first_impacts(5)]
        [(0, 1, 2.0)]
        """
        from .impacts import first_impacts

        ids, shapes, motions = self._moving()
        return [(ids[e.i], ids[e.j], e.impact)
                for e in first_impacts(shapes, motions, t_max, **options)]

    def first_impact(self, t_max: float, **options: Any) -> tuple[int, int, Any] | None:
        """The first event among the moving bodies, ``(id_a, id_b, impact)``: the
        earliest collision, else the earliest touch; None when no pair meets (the order
        of :func:`polycontact.first_impact`, whose ``options`` these are)."""
        from .impacts import first_impact

        ids, shapes, motions = self._moving()
        e = first_impact(shapes, motions, t_max, **options)
        return None if e is None else (ids[e.i], ids[e.j], e.impact)

    def _moving(self) -> tuple[list[int], list[Shape], list[Motion]]:
        ids = sorted(self._records)
        bodies = [self.body(k) for k in ids]
        return ids, [b.shape for b in bodies], [b.motion or Motion() for b in bodies]

    def plot(self, ax: Any = None, *, labels: bool | None = None) -> Any:
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

    def feasible_region(self, shape: BodyLike, angle: float = 0.0) -> Any:
        """Positions of ``shape``'s area centroid (turned by ``angle``) where it lies in
        the container and penetrates no body: the container's inner-fit polygon minus
        the union of the bodies' no-fit polygons, with exact fits and slides kept.

        Returns
        -------
        shapely geometry
            Polygon(s) where the shape has room; points and segments where it fits
            exactly or slides; empty when it cannot go anywhere.

        Raises
        ------
        ValueError
            Without a container (the free region would be unbounded).
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
