"""Time of impact for many pairs, and the first impacts among many moving bodies.

:func:`time_of_impact_many` answers a list of pairs the caller chose;
:func:`first_impacts` finds, among N moving bodies, every pair that meets within
``[0, t_max]`` without looking at all N(N − 1)/2 pairs (swept bounds, then a
sort-and-sweep: :func:`candidate_pairs`). Both run the pairs on threads, and every
answer agrees with the one :func:`polycontact.time_of_impact` gives for that pair (the
same status and state, times within the time tolerance; the theory page of the
documentation says why, under "Many moving bodies").

Examples
--------
>>> from polycontact import Motion, Shape
>>> sq = Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
>>> [(e.i, e.j) for e in first_impacts([sq, sq.moved((3, 0)), sq.moved((0, 9))],
...                                    [Motion(velocity=(1, 0)), Motion(), Motion()],
...                                    t_max=5)]
[(0, 1)]
"""

from __future__ import annotations

import math
import operator
from collections.abc import Callable, Iterator, Sequence
from contextlib import closing
from dataclasses import dataclass, field
from itertools import chain
from typing import Any, NamedTuple, overload

import numpy as np

from .broad_phase import base_reach, check_motion, check_reach, check_t_max, reach_excess
from .errors import InvalidShapeError
from .impact import Impact, ImpactStatus, check_options, impact_from_kernel
from .limits import (BROAD_PHASE_INFLATION, CONTACT_RESOLUTION, COORDINATE_LIMIT, EXTENT_FLOOR,
                     MAX_ITERATIONS, MAX_SLICES, RELATIVE_TOLERANCE, SAMPLES,
                     SWEPT_ROUNDING_ULPS, TIME_TOLERANCE)
from .motion import Motion
from .relation import RING_ARGS, kernels_unpacked, raw_ring_array
from .shape import Shape, ShapeLike, as_shape
from .tolerances import ROUNDING_FACTOR, check_range
from ._checks import real_array
from ._threads import as_done, map_work, numba_threads, requested, useful

__all__ = ["ImpactBatch", "PairImpact", "PairImpacts", "time_of_impact_many", "first_impacts", "first_impact",
           "candidate_pairs", "event_time"]


@dataclass(frozen=True)
class ImpactBatch:
    """The results of :func:`time_of_impact_many`, as arrays, with each pair's full
    :class:`~polycontact.Impact` on demand.

    Attributes
    ----------
    statuses : ndarray of shape (P,), int8
        0 no hit, 1 hit, 2 penetrating at the start, 3 out of iterations (the codes
        of the compiled search; ``impact(k).status`` is the matching
        :class:`~polycontact.ImpactStatus`).
    collides : ndarray of shape (P,), bool
        ``statuses == 1``.
    times : ndarray of shape (P,), float64
        First penetration time of a hit, NaN otherwise.
    first_contacts : ndarray of shape (P,), float64
        ``Impact.first_contact`` (0 when penetrating at the start), NaN when None.

    Examples
    --------
    >>> from polycontact import Motion, Shape
    >>> sq = Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
    >>> batch = time_of_impact_many([sq, sq], [Motion(velocity=(1, 0))] * 2,
    ...                             [sq.moved((3, 0)), sq.moved((0.5, 0))], [Motion()] * 2,
    ...                             t_max=5)
    >>> len(batch), batch.statuses.tolist(), batch.first_contacts.round(3).tolist()
    (2, [1, 2], [2.0, 0.0])
    """

    statuses: np.ndarray
    collides: np.ndarray
    times: np.ndarray
    first_contacts: np.ndarray
    _make: Callable[[int], Impact] = field(repr=False, compare=False)

    def __post_init__(self) -> None:
        for array in (self.statuses, self.collides, self.times, self.first_contacts):
            array.flags.writeable = False  # a result cannot be changed

    def __len__(self) -> int:
        return int(self.statuses.shape[0])

    def impact(self, k: int) -> Impact:
        """The :class:`~polycontact.Impact` of pair ``k``, agreeing with what
        :func:`polycontact.time_of_impact` returns for it (see the module docstring).

        Parameters
        ----------
        k : int
            A pair index, from ``-len(batch)`` to ``len(batch) - 1``.

        Returns
        -------
        Impact

        Raises
        ------
        IndexError
            ``k`` is not a pair index.

        Examples
        --------
        >>> from polycontact import Motion, Shape
        >>> sq = Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
        >>> batch = time_of_impact_many([sq], [Motion(velocity=(1, 0))],
        ...                             [sq.moved((3, 0))], [Motion()], t_max=5)
        >>> batch.impact(0).status.value, batch.impact(-1).collides
        ('hit', True)
        """
        n = len(self)
        if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or not -n <= k < n:
            raise IndexError(f"k: expected a pair index in [0, {n}), got {k!r}")
        return self._make(int(k) % n)

    def __iter__(self) -> Iterator[Impact]:
        return (self.impact(k) for k in range(len(self)))


class PairImpact(NamedTuple):
    """One pair of moving bodies that meets, and how: an entry of the answers of
    :func:`first_impacts`, :func:`first_impact`, :meth:`polycontact.World.first_impacts`
    and :meth:`polycontact.Scene.impacts`.

    Attributes
    ----------
    i, j : int
        The two bodies in the caller's numbering, ``i < j``: their indices in the
        sequences given to :func:`first_impacts` or in :attr:`polycontact.Scene.bodies`,
        their ids in a :class:`polycontact.World`. Body ``i`` is ``a`` of the impact.
    impact : Impact
        What :func:`polycontact.time_of_impact` answers for body ``i`` against body
        ``j``.

    Examples
    --------
    >>> from polycontact import Motion, Shape
    >>> sq = Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
    >>> event = first_impact([sq, sq.moved((3, 0))], [Motion(velocity=(1, 0)), Motion()],
    ...                      t_max=5)
    >>> event.i, event.j, round(event.impact.time, 3)
    (0, 1, 2.0)
    """

    i: int
    j: int
    impact: Impact


class PairImpacts(Sequence[PairImpact]):
    """The events of :func:`first_impacts`, sorted by time: a sequence of
    :class:`PairImpact` records, each built when it is read, and the arrays of all of
    them at once (what one filters and counts over many events, without a Python
    object per event).

    Attributes
    ----------
    pairs : ndarray of shape (K, 2), int64
        ``(i, j)`` of each event, ``i < j`` in the caller's numbering.
    times : ndarray of shape (K,), float64
        Each event's :func:`event_time`, ascending (ties by ``(i, j)``).
    statuses : ndarray of shape (K,), int8
        The codes of :attr:`ImpactBatch.statuses`: 0 the pair only touches, 1 it
        collides, 2 it penetrates at the start, 3 its search ran out of iterations.

    Examples
    --------
    >>> from polycontact import Motion, Shape
    >>> sq = Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
    >>> events = first_impacts([sq, sq.moved((3, 0)), sq.moved((1.5, 1))],
    ...                        [Motion(velocity=(1, 0)), Motion(), Motion()], t_max=5)
    >>> events.pairs.tolist(), events.times.round(3).tolist(), events.statuses.tolist()
    ([[0, 2], [0, 1]], [0.5, 2.0], [0, 1])
    >>> i, j, impact = events[1]
    >>> i, j, impact.status.value, len(events)
    (0, 1, 'hit', 2)
    """

    __slots__ = ("pairs", "times", "statuses", "_make")

    def __init__(self, pairs: np.ndarray, times: np.ndarray, statuses: np.ndarray,
                 make: Callable[[int], Impact]) -> None:
        for array in (pairs, times, statuses):
            array.flags.writeable = False  # a result cannot be changed
        self.pairs = pairs
        self.times = times
        self.statuses = statuses
        self._make = make

    def renumbered(self, numbers: np.ndarray) -> PairImpacts:
        """The same events with body ``k`` called ``numbers[k]`` (increasing, so that
        ``i < j`` still holds)."""
        return PairImpacts(numbers[self.pairs], self.times, self.statuses, self._make)

    def __len__(self) -> int:
        return int(self.times.shape[0])

    @overload
    def __getitem__(self, k: int) -> PairImpact: ...

    @overload
    def __getitem__(self, k: slice) -> list[PairImpact]: ...

    def __getitem__(self, k: int | slice) -> PairImpact | list[PairImpact]:
        if isinstance(k, slice):
            return [self[q] for q in range(*k.indices(len(self)))]
        n = len(self)
        if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or not -n <= k < n:
            raise IndexError(f"expected an event index in [0, {n}), got {k!r}")
        q = int(k) % n
        return PairImpact(int(self.pairs[q, 0]), int(self.pairs[q, 1]), self._make(q))

    def __iter__(self) -> Iterator[PairImpact]:
        return (self[q] for q in range(len(self)))

    def __eq__(self, other: object) -> bool:
        if isinstance(other, (PairImpacts, list, tuple)):
            return len(self) == len(other) and all(a == b for a, b in zip(self, other))
        return NotImplemented

    __hash__ = None  # type: ignore[assignment]

    def __reduce__(self) -> tuple[Any, ...]:
        # pickled with its records built (their maker is local to the call)
        impacts = [event.impact for event in self]
        return PairImpacts, (self.pairs, self.times, self.statuses, impacts.__getitem__)

    def __repr__(self) -> str:
        return f"<PairImpacts: {len(self)} events>"


# -- validation ------------------------------------------------------------------------
def _sequence(items: Any, what: str) -> list[Any]:
    if isinstance(items, (str, bytes, dict)) or not isinstance(items, (Sequence, np.ndarray)):
        raise TypeError(f"{what}: expected a sequence, got {type(items).__name__}")
    return list(items)


def check_shapes(items: Any, what: str) -> list[Shape]:
    """The bodies of the sequence ``items`` as Shapes (an error naming ``what[k]``)."""
    given = _sequence(items, what)
    if set(map(type, given)) <= {Shape}:
        return given
    out = []
    for k, obj in enumerate(given):
        if type(obj) is Shape:
            out.append(obj)
            continue
        name = f"{what}[{k}]"
        try:
            shape = as_shape(obj, name)
        except InvalidShapeError as exc:
            if str(exc).startswith(name):
                raise
            raise InvalidShapeError(f"{name}: {exc}") from None
        out.append(shape)
    return out


class MotionRows:
    """Motions given as the rows of an (N, 6) float64 array of kernel vectors ``[vx, vy,
    ax, ay, ω, α]`` (:attr:`polycontact.Motion.array`): the batch reads the rows as
    they are, and makes the :class:`~polycontact.Motion` of a row only when asked for
    (``motions[k]``).

    >>> MotionRows(np.array([[1.0, 0, 0, 0, 0.5, 0]]))[0].angular_velocity
    0.5
    """

    def __init__(self, rows: np.ndarray) -> None:
        self.rows = rows

    def __len__(self) -> int:
        return len(self.rows)

    def __getitem__(self, k: int) -> Motion:
        vx, vy, ax, ay, w, alpha = self.rows[k].tolist()
        return Motion(velocity=(vx, vy), acceleration=(ax, ay), angular_velocity=w,
                      angular_acceleration=alpha)


#: Motions as a batch takes them: Motion objects, or the rows of an array.
Motions = list[Motion] | MotionRows


def check_motions(items: Any, what: str, count: int, shapes_what: str) -> Motions:
    """The ``count`` motions of ``items``, one per shape of ``shapes_what`` (an error
    naming ``what``): a sequence of Motions, or an array of shape (count, 6) of their
    kernel vectors (:class:`MotionRows`, finite numbers)."""
    if isinstance(items, np.ndarray) and items.ndim == 2:
        rows = real_array(items, what)
        if rows.shape != (count, 6):
            raise ValueError(f"{what}: expected {count} motions (one per shape of "
                             f"{shapes_what}) as an array of shape ({count}, 6), got shape "
                             f"{rows.shape}")
        finite = np.isfinite(rows)
        if not finite.all():  # (the row named only when one is not)
            k = int(np.argmin(finite.all(axis=1)))
            raise ValueError(f"{what}[{k}]: expected finite numbers, got {rows[k].tolist()}")
        return MotionRows(rows)
    motions = _sequence(items, what)
    if len(motions) != count:
        raise ValueError(f"{what}: expected {count} motions (one per shape of {shapes_what}), "
                         f"got {len(motions)}")
    if set(map(type, motions)) <= {Motion}:
        return motions
    return [m if type(m) is Motion else check_motion(m, f"{what}[{k}]")
            for k, m in enumerate(motions)]


def _rows(*groups: Motions) -> np.ndarray:
    """The kernel vectors of the motions of ``groups``, one group after another, (N, 6)
    (Motions' bytes joined at once; a writable array, as the rows of an array are, so
    that the kernels take one type of motions)."""
    if len(groups) == 1 and isinstance(groups[0], MotionRows):
        return groups[0].rows
    lists = [g for g in groups if not isinstance(g, MotionRows)]
    if len(lists) < len(groups):
        return np.concatenate([_rows(g) for g in groups])
    return np.frombuffer(bytearray().join(map(_BYTES, chain.from_iterable(lists))),
                         np.float64).reshape(-1, 6)


def check_many_options(t_max: float, method: str, time_tolerance: float, samples: int,
                       max_iterations: int,
                       threads: int | None) -> tuple[float, float, int, int, int]:
    """:func:`polycontact.impact.check_options` and ``threads``:
    ``(t_max, time_tolerance, samples, max_iterations, threads)``."""
    t_max, tol = check_options(t_max, method, time_tolerance, samples, max_iterations)
    return t_max, tol, int(samples), int(max_iterations), requested(threads)


# -- the batched search ----------------------------------------------------------------
def _for_batch(kernels: Sequence[bytes],
               threads: int = 1) -> tuple[tuple[np.ndarray, ...], np.ndarray]:
    """Shapes given by their kernel packs (``Shape._kernel``) packed for
    :mod:`polycontact._kernels.impact_batch`: ``(xy, rows, starts, st_off, centroids,
    radii)`` (as :func:`polycontact.relation.shapes_packed` packs them, each shape's
    stored centroid and bounding radius read from its kernel pack), and the shapes'
    extents; copied in compiled code on at most ``threads`` threads."""
    with numba_threads(threads):
        xy, rows, starts, st_off, sizes = kernels_unpacked(kernels, len(kernels))
    return ((xy, rows, starts, st_off, np.ascontiguousarray(sizes[:, :2]),
             np.ascontiguousarray(sizes[:, 2])), sizes[:, 3])


_KERNEL = operator.attrgetter("_kernel")


def empty_result(count: int) -> tuple[np.ndarray, ...]:
    """The raw result arrays of :func:`search_pairs` for ``count`` pairs, unwritten:
    ``(code, t_hi, t_lo, contact, iters, reached, n_iv, iv)``."""
    from ._kernels.broad_phase import MAX_INTERVALS

    return (np.zeros(count, np.int8), np.empty(count), np.empty(count), np.empty(count),
            np.empty(count, np.int64), np.empty(count), np.empty(count, np.int64),
            np.empty((count, MAX_INTERVALS, 2)))


def search_pairs(packed: tuple[np.ndarray, ...], sa: np.ndarray, sb: np.ndarray,
                 ma: np.ndarray, mb: np.ndarray, eps_rel: np.ndarray, t_max: float,
                 method: str, tol: float, samples: int, max_iterations: int,
                 threads: int, wanted: np.ndarray | None = None,
                 motion_rows: tuple[np.ndarray, np.ndarray] | None = None) -> tuple[Any, ...]:
    """Run the pairs ``(shapes[sa[p]], ma[p])`` vs ``(shapes[sb[p]], mb[p])`` of the shapes
    ``packed`` by :func:`_for_batch` through the
    search of ``time_of_impact`` on at most ``threads`` threads (``eps_rel[p]``: the size
    term of pair p's distance tolerance, see :func:`prepare_pairs`); the raw result
    arrays. With ``motion_rows = (ka, kb)``, pair p's motions are ``ma[ka[p]]`` and
    ``mb[kb[p]]`` instead. The tables of the shapes (of those ``wanted`` only, a bool
    mask, when given: at least every shape of a pair) are built in parallel first
    (:func:`polycontact._kernels.impact_batch.body_tables`)."""
    from ._kernels.impact_batch import body_tables, table_sizes
    from ._kernels.swept import impacts_chunk

    exact = method == "exact"
    xy, rows, starts, st_off, centroids, radii = packed
    if wanted is None:
        wanted = np.ones(len(radii), np.bool_)
    f_off, i_off, widest = table_sizes(rows, st_off, wanted)
    floats, ints = np.empty(f_off[-1]), np.empty(i_off[-1], np.int64)
    map_work(lambda u0, u1: body_tables(xy, rows, starts, st_off, centroids, radii, f_off,
                                        i_off, u0, u1, floats, ints),
             len(radii), _TABLE_SECONDS, threads)
    tables = (floats, f_off, ints, i_off, widest)
    p_count = len(sa)
    out = empty_result(p_count)
    order = np.arange(p_count, dtype=np.int64)
    ka, kb = (order, order) if motion_rows is None else motion_rows
    pairs = (sa, sb, ma, mb, ka, kb, eps_rel)
    settings = (t_max, BROAD_PHASE_INFLATION, tol, ROUNDING_FACTOR, CONTACT_RESOLUTION,
                max_iterations, exact, samples)

    def run(todo: np.ndarray) -> None:
        impacts_chunk(todo, pairs, tables, settings, out)

    # many small interleaved chunks: the cost of a pair varies a thousandfold (an
    # empty broad phase against a long slide), so the threads take chunks as they go
    n = useful(threads, p_count * _PAIR_SECONDS)
    n_chunks = 1 if n == 1 else min(-(-p_count // _RESULT_BLOCK), 16 * n)
    todo = [order] if n_chunks == 1 else _interleaved_blocks(p_count, n_chunks)
    for _ in as_done(run, todo, n):
        pass
    return out


#: Pairs whose results lie side by side go to the same chunk in blocks of this many (a
#: cache line holds 64 of the one-byte statuses): two threads writing to one cache line
#: would pass it back and forth at every pair.
_RESULT_BLOCK = 64


def _interleaved_blocks(count: int, n_chunks: int) -> list[np.ndarray]:
    """``range(count)`` in ``n_chunks`` chunks of whole blocks of
    :data:`_RESULT_BLOCK` items, interleaved: chunk c holds blocks c, c + n_chunks,
    c + 2 n_chunks, ... (so that every chunk samples the whole range).

    >>> [c.tolist() for c in _interleaved_blocks(200, 2)]  # doctest: +ELLIPSIS
    [[0, 1, ..., 63, 128, ..., 191], [64, ..., 127, 192, ..., 199]]
    """
    rounds = -(-count // (_RESULT_BLOCK * n_chunks))
    grid = np.arange(rounds * n_chunks * _RESULT_BLOCK, dtype=np.int64).reshape(
        rounds, n_chunks, _RESULT_BLOCK)
    return [c[c < count] for c in grid.transpose(1, 0, 2).reshape(n_chunks, -1)]


#: Seconds of one body's tables, and of one pair's search at the least (both about a
#: 12-gon's), for the threads the work can use (see :mod:`polycontact._threads`).
_TABLE_SECONDS = 2e-6
_PAIR_SECONDS = 2e-6


def _maker(shape_of: Callable[[int, int], Shape], motion_of: Callable[[int, int], Motion],
           raw: tuple[Any, ...], t_max: float, method: str, eps_rel: np.ndarray,
           tol: float) -> Callable[[int], Impact]:
    code, t_hi, t_lo, contact, iters, reached, n_iv, iv = raw

    def make(p: int) -> Impact:
        a, ma = shape_of(p, 0), motion_of(p, 0)
        b, mb = shape_of(p, 1), motion_of(p, 1)
        # (the intervals copied: the result keeps them, not the whole batch's array)
        return impact_from_kernel(a, ma, b, mb, method,
                                  (int(n_iv[p]), int(code[p]), float(t_hi[p]),
                                   float(t_lo[p]), float(contact[p]), int(iters[p]),
                                   float(reached[p])),
                                  t_max, float(eps_rel[p]), tol, iv[p, :n_iv[p]].copy())

    return make


def _names(k: int) -> tuple[str, str]:
    """The names of body k's arguments in ``first_impacts`` and ``candidate_pairs``."""
    return f"shapes[{k}]", f"motions[{k}]"


class _Bodies(NamedTuple):
    """Checked moving bodies (see :func:`_bodies`)."""

    kernels: list[bytes]    # the kernel packs of the distinct shapes
    packed: tuple[np.ndarray, ...]  # their packing for the batch (_for_batch)
    owner: np.ndarray       # each body's index among them
    motions: np.ndarray     # each body's motion as the kernel vector, (N, 6)
    centroids: np.ndarray   # of the distinct shapes, (U, 2)
    radii: np.ndarray       # their bounding radii
    extents: np.ndarray     # the larger sides of their boxes


def _bodies(shapes: list[Shape], rows: np.ndarray, motion_of: Callable[[int], Motion],
            name_of: Callable[[int], tuple[str, str]], t_max: float,
            threads: int) -> _Bodies:
    """The bodies ``(shapes[k], motion_of(k))`` (``rows``: the motions' kernel vectors)
    after the checks ``time_of_impact`` makes:
    coordinates within the range the kernels take, and motions that do not carry them,
    the points' speeds or accelerations beyond it within [0, t_max]. A shape object in
    many bodies is kept once (its kernel pack, read once). The checks run in compiled
    code on at most ``threads`` threads; the bodies it marks are checked again here,
    exactly, and the first that fails is refused, named by ``name_of(k) = (shape's,
    motion's)``."""
    count = len(shapes)
    ids = np.fromiter(map(id, shapes), np.int64, count)
    _, first, owner = np.unique(ids, return_index=True, return_inverse=True)
    uniq = list(map(_KERNEL, map(shapes.__getitem__, first.tolist())))
    owner = owner.reshape(-1).astype(np.int64)
    packed, extents = _for_batch(uniq, threads)
    centroids, radii = packed[4:]
    _refuse_suspects(packed, owner, rows, shapes.__getitem__, motion_of, name_of, t_max,
                     threads)
    return _Bodies(uniq, packed, owner, rows, centroids, radii, extents)


def _refuse_suspects(packed: tuple[np.ndarray, ...], owner: np.ndarray, rows: np.ndarray,
                     shape_of: Callable[[int], Shape], motion_of: Callable[[int], Motion],
                     name_of: Callable[[int], tuple[str, str]], t_max: float,
                     threads: int) -> None:
    """Refuse the first body k (shape ``owner[k]`` of the ``packed`` shapes, moving with
    the kernel vector ``rows[k]``) whose coordinates, or whose motion within [0,
    ``t_max``], lie beyond the range the kernels take: the compiled check
    (:func:`polycontact._kernels.impact_batch.suspect_bodies`, on at most ``threads``
    threads) marks the bodies that may, which are checked again exactly here, as
    ``time_of_impact`` checks them (``shape_of(k)``, ``motion_of(k)``; the error names
    ``name_of(k) = (shape's, motion's)``)."""
    from ._kernels.impact_batch import suspect_bodies

    xy, vrows, _, _, centroids, radii = packed
    count = len(owner)
    suspect = np.zeros(count, np.bool_)
    map_work(lambda k0, k1: suspect_bodies(xy, vrows, centroids, radii, rows, owner, t_max,
                                           COORDINATE_LIMIT, EXTENT_FLOOR, k0, k1, suspect),
             count, _TABLE_SECONDS, threads)
    if suspect.any():
        marked = np.flatnonzero(suspect).tolist()
        for k in marked:
            check_range(shape_of(k).packed[0], name_of(k)[0])
        for k in marked:
            sh, m = shape_of(k), motion_of(k)
            if reach_excess(base_reach(sh), sh.bounding_radius, m._norms, t_max) is not None:
                check_reach(sh, m, t_max, name_of(k)[1])  # raises, naming the motion


_BYTES = operator.attrgetter("_bytes")


def time_of_impact_many(
    shapes_a: Sequence[ShapeLike] | np.ndarray,
    motions_a: Sequence[Motion] | np.ndarray,
    shapes_b: Sequence[ShapeLike] | np.ndarray,
    motions_b: Sequence[Motion] | np.ndarray,
    *,
    t_max: float,
    method: str = "exact",
    time_tolerance: float = TIME_TOLERANCE,
    samples: int = SAMPLES,
    max_iterations: int = MAX_ITERATIONS,
    threads: int | None = None,
    client: Any = None,
    chunk_size: int | None = None,
) -> ImpactBatch:
    """Time of impact of many pairs ``(shapes_a[k], motions_a[k])`` against
    ``(shapes_b[k], motions_b[k])``, in parallel.

    Pair k's answer is the one ``time_of_impact(shapes_a[k], motions_a[k], shapes_b[k],
    motions_b[k], t_max=..., ...)`` gives (the same kernel with the same arguments; times
    within the time tolerance, see the module docstring); the pairs are shared among
    ``threads`` threads, since the compiled search releases the GIL. A shape that appears in many pairs (the same object) has
    its tables built once.

    The result is a batch of arrays (``status``, ``collides``, ``times``,
    ``first_contacts``), what one filters and sorts over many pairs, with
    ``batch.impact(k)`` giving pair k's full :class:`~polycontact.Impact` (features,
    point, normal) on demand: building the P result objects is left to the pairs the
    caller looks at.

    Parameters
    ----------
    shapes_a, shapes_b : sequence of bodies, or ndarray of shape (P, N, 2)
        The bodies at t = 0, P of each: Shapes, shapely Polygons or (N, 2) arrays; or,
        both sides alike, the packed form: P outer
        rings of N vertices each (closed or not, either orientation; ``shapes_b`` may
        have another N), checked, packed and given their centroids in compiled code on
        the threads, with no Python object per pair (the quick form for many pairs,
        with motions as rows). A ring that is not certified valid as given (see
        :func:`polycontact.classify_many`) is decided by :class:`~polycontact.Shape`,
        as in the other forms; ``impact(k)`` makes pair k's two Shapes.
    motions_a, motions_b : sequence of Motion, or ndarray of shape (P, 6)
        Their motions, one per shape: Motions, or their kernel vectors ``[vx, vy, ax,
        ay, ω, α]`` (:attr:`polycontact.Motion.array`) as the rows of an array, read as
        they are (no Motion is made unless ``impact(k)`` asks for it: the quick form
        for many pairs).
    t_max, method, time_tolerance, samples, max_iterations
        As for :func:`polycontact.time_of_impact`, for every pair.
    threads : int, optional
        At most this many threads (default ``numba.get_num_threads()``; see the
        threading policy of :doc:`conventions`).
    client : dask.distributed.Client, optional
        Run the searches on this Dask cluster (default: the current Dask client if
        there is one, see :func:`polycontact.distributed.current_client`), after the same
        checks here; shapes that several tasks use go to every worker once, the others
        with their task; the result is the local call's.
    chunk_size : int, optional
        Pairs per Dask task (default: sized from a first task, see
        :func:`polycontact.distributed.run_spans`).

    Returns
    -------
    ImpactBatch

    Raises
    ------
    TypeError, ValueError, InvalidShapeError
        Naming the argument and the index: ``shapes_b[3]: outer loop: ...``,
        ``motions_a[2]: expected a polycontact.Motion, got tuple``,
        ``motions_b: expected 4 motions (one per shape of shapes_b), got 3``, or a
        motion ``time_of_impact`` refuses because the body's coordinates, speeds or
        accelerations would overflow float64 within ``[0, t_max]``
        (``motions_b[1]: the body's coordinates reach ...``).

    Examples
    --------
    >>> from polycontact import Motion, Shape
    >>> sq = Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
    >>> batch = time_of_impact_many([sq, sq], [Motion(velocity=(1, 0))] * 2,
    ...                             [sq.moved((3, 0)), sq.moved((0, 5))], [Motion()] * 2,
    ...                             t_max=5)
    >>> batch.collides.tolist(), batch.times.round(3).tolist(), batch.statuses.tolist()
    ([True, False], [2.0, nan], [1, 0])
    >>> batch.impact(0).status.value
    'hit'
    """
    from ._cluster import check_chunk_size, current_client

    check_chunk_size(chunk_size)
    remote = current_client(client)
    rings = _ring_arrays(shapes_a, shapes_b)
    if rings is None:
        a = check_shapes(shapes_a, "shapes_a")
        b = check_shapes(shapes_b, "shapes_b")
        counts = (len(a), len(b))
    else:
        counts = (len(rings[0]), len(rings[1]))
    if counts[0] != counts[1]:
        raise ValueError(f"shapes_a and shapes_b differ in length ({counts[0]} and "
                         f"{counts[1]})")
    ma = check_motions(motions_a, "motions_a", counts[0], "shapes_a")
    mb = check_motions(motions_b, "motions_b", counts[1], "shapes_b")
    t_max, tol, samples, max_iterations, threads = check_many_options(
        t_max, method, time_tolerance, samples, max_iterations, threads)
    options = (t_max, method, tol, samples, max_iterations)
    if rings is not None:
        ringed = prepare_rings(*rings, ma, mb, t_max, threads)
        if ringed is not None:
            copies, packed, sa, sb, rows_a, rows_b, eps_rel = ringed
            raw = (search_pairs(packed, sa, sb, rows_a, rows_b, eps_rel, *options, threads)
                   if remote is None else
                   _remote_ring_search(remote, ringed, options, chunk_size))
            return impact_batch(lambda p, s: Shape(copies[s][p]), ma, mb, raw, eps_rel,
                                *options[:3])
        a = check_shapes(rings[0], "shapes_a")  # (refused here, naming the ring)
        b = check_shapes(rings[1], "shapes_b")
    prepared = prepare_pairs(a, b, ma, mb, t_max, threads)
    if remote is None:
        _, packed, sa, sb, rows_a, rows_b, eps_rel = prepared
        raw = search_pairs(packed, sa, sb, rows_a, rows_b, eps_rel, *options, threads)
    else:
        raw = _remote_search(remote, prepared, options, chunk_size)
    pairs = (a, b)
    return impact_batch(lambda p, s: pairs[s][p], ma, mb, raw, prepared[6], *options[:3])


def _ring_arrays(shapes_a: Any, shapes_b: Any) -> tuple[np.ndarray, np.ndarray] | None:
    """``(shapes_a, shapes_b)`` when both are arrays of outer rings, (P, N, 2) and (P',
    M, 2) of real numbers (the packed form of :func:`time_of_impact_many`), else None."""
    arr_a, arr_b = raw_ring_array(shapes_a), raw_ring_array(shapes_b)
    return None if arr_a is None or arr_b is None else (arr_a, arr_b)


def prepare_rings(arr_a: np.ndarray, arr_b: np.ndarray, ma: Motions, mb: Motions,
                  t_max: float, threads: int) -> tuple[Any, ...] | None:
    """:func:`prepare_pairs` of the pairs of outer rings ``arr_a[p]`` and ``arr_b[p]``
    ((P, N, 2) and (P, M, 2) arrays) without a Shape (:func:`_ring_bodies`): ``(copies,
    packed, sa, sb, rows_a, rows_b, eps_rel)``, ``copies`` the two copied ring arrays,
    which a :class:`~polycontact.Shape` is made of when the caller asks (for
    ``impact(k)``). None when a ring is not certified valid as given: the caller then
    makes Shapes, which decide, and name the ring they refuse."""
    p_count = len(arr_a)
    got = _ring_bodies((arr_a, arr_b), _rows(ma, mb),
                       lambda k: ma[k] if k < p_count else mb[k - p_count],
                       lambda k: _pair_names(k, p_count), t_max, threads)
    if got is None:
        return None
    copies, bodies = got
    order = np.arange(p_count, dtype=np.int64)
    eps_rel = RELATIVE_TOLERANCE * np.maximum(bodies.extents[:p_count],
                                              bodies.extents[p_count:])
    return (copies, bodies.packed, order, order + p_count, bodies.motions[:p_count],
            bodies.motions[p_count:], eps_rel)


def _ring_bodies(arrays: Sequence[np.ndarray], motions: np.ndarray,
                 motion_of: Callable[[int], Motion], name_of: Callable[[int], tuple[str, str]],
                 t_max: float, threads: int) -> tuple[tuple[np.ndarray, ...], _Bodies] | None:
    """:func:`_bodies` of the outer rings of ``arrays`` ((P, N, 2) arrays, one after
    another: body k is the k-th ring counted through them) without a Shape: the rings
    copied (float64), checked, oriented counter-clockwise and packed, with their
    centroids, radii and extents, in compiled code on at most ``threads`` threads
    (:func:`polycontact._kernels.impact_batch.ring_bodies`); ``(copies, bodies)``, the
    copied arrays, of which a :class:`~polycontact.Shape` is made where one is needed
    (to refuse a body exactly, or for an ``Impact``), and the bodies, each its own
    shape. None when a ring is not certified valid as given."""
    from ._kernels.impact_batch import pack_rings, ring_bodies

    bases = np.cumsum([0] + [len(arr) for arr in arrays])
    total = int(bases[-1])
    copies = tuple(np.empty(arr.shape) for arr in arrays)
    used = np.empty(total, np.int64)
    sign = np.empty(total, np.int8)
    centroids = np.empty((total, 2))
    radii = np.empty(total)
    extents = np.empty(total)

    def parts(k0: int, k1: int) -> Iterator[tuple[int, int, int, int]]:
        """The rings k0 to k1 - 1 in each array: ``(array, base, p0, p1)``."""
        for side, base in enumerate(bases[:-1].tolist()):
            p0, p1 = max(k0 - base, 0), min(k1 - base, len(arrays[side]))
            if p0 < p1:
                yield side, base, p0, p1

    def check(k0: int, k1: int) -> None:
        for side, base, p0, p1 in parts(k0, k1):
            copies[side][p0:p1] = arrays[side][p0:p1]
            ring_bodies(copies[side], *RING_ARGS, p0, p1, used[base:], sign[base:],
                        centroids[base:], radii[base:], extents[base:])

    map_work(check, total, _RING_SECONDS, threads)
    if (used < 0).any():
        return None
    rows = np.zeros(total + 1, np.int64)
    np.cumsum(used, out=rows[1:])
    xy = np.empty((int(rows[-1]), 2))

    def pack(k0: int, k1: int) -> None:
        for side, base, p0, p1 in parts(k0, k1):
            pack_rings(copies[side], used[base:], sign[base:], rows[base:], p0, p1, xy)

    map_work(pack, total, _RING_SECONDS / 4, threads)
    starts = np.zeros(2 * total, np.int64)
    starts[1::2] = used
    packed = (xy, rows, starts, np.arange(0, 2 * total + 1, 2, dtype=np.int64), centroids,
              radii)
    owner = np.arange(total, dtype=np.int64)

    def shape_of(k: int) -> Shape:
        side = int(np.searchsorted(bases, k, side="right")) - 1
        return Shape(copies[side][k - bases[side]])

    _refuse_suspects(packed, owner, motions, shape_of, motion_of, name_of, t_max, threads)
    return copies, _Bodies([], packed, owner, motions, centroids, radii, extents)


def _moving_bodies(shapes: Any, motions: Any, t_max: float,
                   threads: int) -> tuple[Callable[[int], Shape], Motions, _Bodies]:
    """The bodies ``(shapes[k], motions[k])`` of :func:`first_impacts` and
    :func:`candidate_pairs`, checked over [0, ``t_max``] on at most ``threads`` threads
    (errors naming ``shapes[k]``, ``motions[k]``): ``(shape_of, moves, bodies)``.
    ``shapes`` as a (N, V, 2) ring array is packed without a Shape
    (:func:`_ring_bodies`) unless a ring is not certified valid as given;
    ``shape_of(k)`` is body k's Shape (made when asked, for a ring)."""
    rings = raw_ring_array(shapes)
    if rings is not None:
        moves = check_motions(motions, "motions", len(rings), "shapes")
        got = _ring_bodies((rings,), _rows(moves), moves.__getitem__, _names, t_max, threads)
        if got is not None:
            copies, bodies = got
            return lambda k: Shape(copies[0][k]), moves, bodies
    listed = check_shapes(shapes, "shapes")
    moves = check_motions(motions, "motions", len(listed), "shapes")
    return listed.__getitem__, moves, _bodies(listed, _rows(moves), moves.__getitem__, _names,
                                               t_max, threads)


#: Seconds of checking one raw ring (a 12-gon's) and making it a body, for the threads
#: the work can use (see :mod:`polycontact._threads`).
_RING_SECONDS = 1e-6


def _pair_names(k: int, p_count: int) -> tuple[str, str]:
    """The names of body k of :func:`time_of_impact_many`'s ``2 P`` bodies (the P of
    side a, then the P of side b): ``(shape's, motion's)``."""
    side, q = ("a", k) if k < p_count else ("b", k - p_count)
    return f"shapes_{side}[{q}]", f"motions_{side}[{q}]"


def prepare_pairs(a: list[Shape], b: list[Shape], ma: Motions, mb: Motions,
                  t_max: float, threads: int = 1) -> tuple[Any, ...]:
    """Check every body of the pairs as ``time_of_impact`` does (errors naming where it
    first appears: ``shapes_a[k]``, ``motions_b[k]``, ...; see :func:`_bodies`), then
    the distinct shapes and the inputs of :func:`search_pairs`: the shapes packed, each
    pair's two indices among them, its two motion rows and its ``eps_rel``, the size term of its distance
    tolerance (``RELATIVE_TOLERANCE`` times the larger of the two shapes' extents).
    (:func:`_remote_search` runs :func:`search_pairs` on slices of them in tasks.)"""
    p_count = len(a)
    bodies = _bodies(a + b, _rows(ma, mb),
                     lambda k: ma[k] if k < p_count else mb[k - p_count],
                     lambda k: _pair_names(k, p_count), t_max, threads)
    ia, ib = bodies.owner[:p_count], bodies.owner[p_count:]
    eps_rel = RELATIVE_TOLERANCE * np.maximum(bodies.extents[ia], bodies.extents[ib])
    return (bodies.kernels, bodies.packed, ia, ib, bodies.motions[:p_count],
            bodies.motions[p_count:], eps_rel)


def impact_batch(shape_of: Callable[[int, int], Shape], ma: Motions, mb: Motions,
                 raw: tuple[Any, ...], eps_rel: np.ndarray, t_max: float, method: str,
                 tol: float) -> ImpactBatch:
    """The :class:`ImpactBatch` of the pairs ``(shape_of(p, 0), ma[p])`` vs
    ``(shape_of(p, 1), mb[p])`` from the raw result arrays of :func:`search_pairs`."""
    code, t_hi, _, contact, *_ = raw
    collides = code == 1
    moves = (ma, mb)
    make = _maker(shape_of, lambda p, s: moves[s][p], raw, t_max, method, eps_rel, tol)
    return ImpactBatch(
        statuses=code,
        collides=collides,
        times=np.where(collides, t_hi, np.nan),
        first_contacts=np.where(code == 2, 0.0, np.where(contact >= 0.0, contact, np.nan)),
        _make=make,
    )


# -- on a Dask cluster ------------------------------------------------------------------
def _remote_search(client: Any, prepared: tuple[Any, ...], options: tuple[Any, ...],
                   chunk_size: int | None) -> tuple[Any, ...]:
    """The raw result arrays of :func:`search_pairs` for the prepared pairs
    (:func:`prepare_pairs`'s answer), in tasks on the cluster of ``client``; ``options`` = ``(t_max,
    method, tol, samples, max_iterations)``."""
    uniq, _, sa, sb, rows_a, rows_b, eps_rel = prepared

    def tasks_of(spans: list[tuple[int, int]]) -> tuple[Any, list[Any]]:
        return _impact_tasks(uniq, sa, sb, rows_a, rows_b, eps_rel, spans)

    return _gathered(client, _impact_slice, len(sa), tasks_of, options, chunk_size)


def _gathered(client: Any, fn: Callable[..., tuple[Any, ...]], count: int,
              tasks_of: Callable[[list[tuple[int, int]]], tuple[Any, list[Any]]],
              options: tuple[Any, ...], chunk_size: int | None) -> tuple[Any, ...]:
    """The raw result arrays of ``count`` pairs, from the tasks ``fn(shared, task,
    *options)`` of :func:`polycontact._cluster.run_spans` (``tasks_of``: as there), each
    task's slice written in as it finishes."""
    from ._cluster import run_spans

    raw = empty_result(count)
    with closing(run_spans(client, fn, count, tasks_of, *options, chunk_size=chunk_size,
                           family="many moving bodies")) as results:
        for p0, p1, part in results:
            for whole, got in zip(raw, part):
                whole[p0:p1] = got
    return raw


def _remote_ring_search(client: Any, ringed: tuple[Any, ...], options: tuple[Any, ...],
                        chunk_size: int | None) -> tuple[Any, ...]:
    """:func:`_remote_search` of pairs of rings prepared by :func:`prepare_rings`: each
    task carries the packed rows of its own pairs' bodies, nothing else."""
    _, packed, _, _, rows_a, rows_b, eps_rel = ringed

    def tasks_of(spans: list[tuple[int, int]]) -> tuple[Any, list[Any]]:
        return None, [_ring_task(packed, rows_a, rows_b, eps_rel, p0, p1) for p0, p1 in spans]

    return _gathered(client, _ring_slice, len(rows_a), tasks_of, options, chunk_size)


def _ring_task(packed: tuple[np.ndarray, ...], rows_a: np.ndarray, rows_b: np.ndarray,
               eps_rel: np.ndarray, p0: int, p1: int) -> tuple[Any, ...]:
    """The task of pairs ``p0:p1`` of P pairs of rings packed by :func:`prepare_rings`
    (ring p of side a is body p, of side b body P + p): their bodies packed alone (side
    a's, then side b's), their motion rows and ``eps_rel``.

    >>> sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    >>> _, packed, *rest = prepare_rings(np.stack([sq, sq + 5]), np.stack([sq + 2, sq + 9]),
    ...                                  MotionRows(np.zeros((2, 6))),
    ...                                  MotionRows(np.zeros((2, 6))), 1.0, 1)
    >>> task = _ring_task(packed, rest[2], rest[3], rest[4], 1, 2)
    >>> task[0][0].tolist()[::4], task[0][1].tolist()
    ([[5.0, 5.0], [9.0, 9.0]], [0, 4, 8])
    """
    xy, rows, _, _, centroids, radii = packed
    p_count = len(rows_a)
    pick = np.r_[p0:p1, p_count + p0:p_count + p1]
    used = np.diff(rows)[pick]
    own_rows = np.zeros(len(pick) + 1, np.int64)
    np.cumsum(used, out=own_rows[1:])
    starts = np.zeros(2 * len(pick), np.int64)
    starts[1::2] = used
    own_xy = np.concatenate([xy[rows[p0]:rows[p1]], xy[rows[p_count + p0]:rows[p_count + p1]]])
    own = (own_xy, own_rows, starts, np.arange(0, 2 * len(pick) + 1, 2, dtype=np.int64),
           centroids[pick], radii[pick])
    return own, rows_a[p0:p1], rows_b[p0:p1], eps_rel[p0:p1]


def _ring_slice(shared: None, task: tuple[Any, ...], t_max: float, method: str, tol: float,
                samples: int, max_iterations: int) -> tuple[Any, ...]:
    """One task of :func:`_remote_ring_search`: the local search of its pairs; the raw
    result arrays."""
    packed, rows_a, rows_b, eps_rel = task
    order = np.arange(len(rows_a), dtype=np.int64)
    return search_pairs(packed, order, order + len(order), rows_a, rows_b, eps_rel, t_max,
                        method, tol, samples, max_iterations, 1)


def _impact_tasks(uniq: list[bytes], sa: np.ndarray, sb: np.ndarray, rows_a: np.ndarray,
                  rows_b: np.ndarray, eps_rel: np.ndarray,
                  spans: list[tuple[int, int]]) -> tuple[_ShapePack, list[tuple[Any, ...]]]:
    """The shapes (``uniq``: their kernel packs) several tasks use (sent once to every
    worker) and the tasks: each its slice of pairs, with its own shapes, the pairs'
    shape indices numbering the shared shapes first, then the task's own. Pairs outside
    the ``spans`` play no part."""
    task = np.full(len(sa), -1, np.int64)
    for k, (p0, p1) in enumerate(spans):
        task[p0:p1] = k
    given = task >= 0
    first = np.full(len(uniq), len(spans), np.int64)
    last = np.full(len(uniq), -1, np.int64)
    for s in (sa[given], sb[given]):
        np.minimum.at(first, s, task[given])
        np.maximum.at(last, s, task[given])
    shared_ids = np.flatnonzero(first < last)
    number = np.full(len(uniq), -1, np.int64)
    number[shared_ids] = np.arange(len(shared_ids))
    # the shapes of one task only, grouped by task (ascending within each)
    alone = np.flatnonzero(first == last)
    alone = alone[np.argsort(first[alone], kind="stable")]
    bounds = np.searchsorted(first[alone], np.arange(len(spans) + 1))
    tasks = []
    for k, (p0, p1) in enumerate(spans):
        own = alone[bounds[k]:bounds[k + 1]]
        number[own] = len(shared_ids) + np.arange(len(own))
        ta, tb = sa[p0:p1], sb[p0:p1]
        tasks.append((number[ta], number[tb], _ShapePack([uniq[u] for u in own]),
                      rows_a[p0:p1], rows_b[p0:p1], eps_rel[p0:p1]))
        number[own] = -1
    return _ShapePack([uniq[u] for u in shared_ids]), tasks


def _impact_slice(shared: _ShapePack, task: tuple[Any, ...], t_max: float, method: str,
                  tol: float, samples: int, max_iterations: int) -> tuple[Any, ...]:
    """One task of :func:`time_of_impact_many`: the local search on a slice of pairs
    (only the shapes it uses are packed for the kernel); the raw result arrays."""
    sa, sb, own, rows_a, rows_b, eps_rel = task
    used, inverse = np.unique(np.concatenate([sa, sb]), return_inverse=True)
    n = len(sa)
    inverse = inverse.reshape(-1)
    return search_pairs(_ShapePack.packed([shared, own], used.tolist()), inverse[:n],
                        inverse[n:], rows_a, rows_b, eps_rel, t_max, method, tol, samples,
                        max_iterations, 1)


class _ShapePack:
    """Shapes sent to Dask workers as their kernel packs (``Shape._kernel``, one ``bytes``
    each: coordinates, loop starts, centroid and bounding radius, see
    :func:`polycontact.relation.shapes_packed`).

    A list of :class:`~polycontact.Shape` pickles as a dozen small NumPy buffers per
    shape, which Dask sends one by one (10 000 pairs of small polygons took 12-16 s to
    send against 1 s of work); bytes objects travel as one message. The
    receiving task packs the shapes it needs for the search with :meth:`packed`.

    Examples
    --------
    >>> import pickle
    >>> from polycontact import Shape
    >>> frame = Shape([(0, 0), (6, 0), (6, 6), (0, 6)], [[(2, 2), (4, 2), (4, 4), (2, 4)]])
    >>> back = pickle.loads(pickle.dumps(_ShapePack([frame._kernel,
    ...                                              frame.moved((1, 0))._kernel])))
    >>> xy, rows, starts, st_off, centroids, radii = _ShapePack.packed([back], [1])
    >>> centroids.tolist(), float(radii[0]) == frame.bounding_radius, starts.tolist()
    ([[4.0, 3.0]], True, [0, 4, 8])
    """

    def __init__(self, kernels: Sequence[bytes]) -> None:
        self.kernels = list(kernels)

    def __len__(self) -> int:
        return len(self.kernels)

    @staticmethod
    def packed(packs: Sequence[_ShapePack], chosen: Sequence[int]) -> tuple[np.ndarray, ...]:
        """The shapes ``chosen`` (numbered through ``packs`` one after another) packed as
        :func:`_for_batch` packs them."""
        kernels = [k for p in packs for k in p.kernels]
        return _for_batch([kernels[k] for k in np.asarray(chosen, np.int64).tolist()])[0]


# -- many moving bodies ----------------------------------------------------------------
def candidate_pairs(shapes: Sequence[ShapeLike] | np.ndarray,
                    motions: Sequence[Motion] | np.ndarray, *, t_max: float) -> np.ndarray:
    """Pairs of moving bodies whose swept bounds over ``[0, t_max]`` meet: the pairs
    :func:`first_impacts` searches.

    A superset of the pairs whose bounding circles come within reach of each other in
    the window, hence of every pair that can touch. The boxes are widened as
    :func:`polycontact.time_of_impact`'s broad phase widens the circles (a relative
    inflation and the rounding of positions far from the origin), so every pair it would
    search is here.

    Parameters
    ----------
    shapes, motions, t_max
        As for :func:`first_impacts`: the bodies at t = 0, one motion per body, the end
        of the time window.

    Returns
    -------
    ndarray of shape (K, 2), int64
        Pairs ``(i, j)``, ``i < j``, sorted.

    Raises
    ------
    TypeError, ValueError, InvalidShapeError
        As :func:`first_impacts`, naming ``shapes[k]`` or ``motions[k]``.

    Examples
    --------
    >>> from polycontact import Motion, Shape
    >>> sq = Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
    >>> shapes = [sq, sq.moved((3, 0)), sq.moved((0, 30))]
    >>> motions = [Motion(velocity=(1, 0)), Motion(), Motion()]
    >>> candidate_pairs(shapes, motions, t_max=5).tolist()
    [[0, 1]]
    """
    t_max = check_t_max(t_max)
    threads = requested(None)
    return _candidates(_moving_bodies(shapes, motions, t_max, threads)[2], t_max, threads)


def _candidates(bodies: _Bodies, t_max: float, threads: int) -> np.ndarray:
    """:func:`candidate_pairs` of checked bodies, on at most ``threads`` threads."""
    return swept_pairs(np.ascontiguousarray(bodies.centroids[bodies.owner]), bodies.motions,
                       bodies.radii[bodies.owner], t_max, threads)


#: Seconds of sweep per member of a strip (a box swept against the boxes of one of its
#: strips): the unit of work that :func:`box_pairs` shares among threads.
STRIP_MEMBER_SECONDS = 100e-9

#: Seconds per pair of boxes found, to sort and keep each body's partners once.
PARTNER_SECONDS = 20e-9

#: Seconds to bound one body's path in its boxes: the unit of work of
#: :func:`swept_boxes`' share among threads.
BOX_SECONDS = 50e-9


def time_order(times: np.ndarray) -> np.ndarray:
    """The order of a stable sort of ``times`` (non-negative, or NaN last): the zeros
    first, as they come, then the others sorted. Most pairs of a crowded step meet at
    time 0: they need no sort.

    >>> time_order(np.array([0.5, 0.0, 0.2, 0.0, 0.5])).tolist()
    [1, 3, 2, 0, 4]
    """
    zero = times == 0.0
    later = np.flatnonzero(~zero)
    return np.concatenate([np.flatnonzero(zero), later[np.argsort(times[later], kind="stable")]])


def swept_pairs(centroids: np.ndarray, motions: np.ndarray, radii: np.ndarray,
                t_max: float, threads: int | None = None) -> np.ndarray:
    """The pairs of bodies whose swept boxes meet over [0, ``t_max``] (the swept broad
    phase of :func:`first_impacts` and ``World.sweep``): each body's centroid
    (``centroids``, (N, 2)) follows its motion (``motions``, rows ``vx, vy, ax, ay,
    omega, alpha``) and its bounding circle (``radii``, (N,)) goes with it, in boxes of
    time slices (:func:`swept_boxes`); the pairs of :func:`box_pairs`, on at most
    ``threads`` threads.

    >>> swept_pairs(np.array([[0.0, 0], [3, 0], [0, 30]]),
    ...             np.array([[1.0, 0, 0, 0, 0, 0], [0] * 6, [0] * 6]),
    ...             np.array([0.8, 0.8, 0.8]), 5.0).tolist()
    [[0, 1]]
    """
    n = len(centroids)
    if n < 2:
        return np.empty((0, 2), np.int64)
    boxes, owner = swept_boxes(centroids, motions, radii, t_max, threads)
    return box_pairs(boxes, owner, n, threads)


def swept_boxes(centroids: np.ndarray, motions: np.ndarray, radii: np.ndarray,
                t_max: float, threads: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """The space–time boxes of the swept broad phase: ``(boxes, owner)``, each body's
    boxes over the time slices of [0, ``t_max``] (at most
    :data:`~polycontact.limits.MAX_SLICES`) holding its bounding circle as its centroid
    follows its motion (:func:`polycontact._kernels.swept.boxes_into`: rows ``(x_lo,
    x_hi, y_lo, y_hi, t_lo, t_hi)``, and the body each bounds), the bodies shared among
    at most ``threads`` threads (arguments as for :func:`swept_pairs`).

    >>> boxes, owner = swept_boxes(np.array([[0.0, 0]]), np.array([[0.0] * 6]),
    ...                            np.array([1.0]), 2.0)
    >>> owner.tolist(), boxes[0, 4:].tolist()
    ([0], [0.0, 2.0])
    """
    from ._kernels.swept import boxes_into, slice_starts

    first = slice_starts(motions, radii, t_max, MAX_SLICES)
    boxes = np.empty((first[-1], 6))
    owner = np.empty(first[-1], np.int64)
    ulps = SWEPT_ROUNDING_ULPS * 2.0**-52
    map_work(lambda i0, i1: boxes_into(centroids, motions, radii, t_max, first,
                                       BROAD_PHASE_INFLATION, ulps, i0, i1, boxes, owner),
             len(radii), BOX_SECONDS, threads)
    return boxes, owner


def box_pairs(boxes: np.ndarray, owner: np.ndarray, n_bodies: int,
              threads: int | None = None) -> np.ndarray:
    """Every pair of bodies ``(i, j)``, i < j, two of whose boxes overlap in x, y and
    time (closed intervals), once each, sorted; shape (K, 2).

    ``boxes``: rows ``(x0, x1, y0, y1, t0, t1)``, box k of body ``owner[k]`` (below
    ``n_bodies``). Sort and sweep on the axis (x or y) along which the boxes' centres
    spread most, in strips across the other axis: each box goes to every strip its
    extent there meets, so two boxes that overlap share a strip (the strip of any
    common point), and a box is swept against those of its strips only (about the boxes
    of one row of a crowd, not of a whole column); a pair of boxes is kept in the first
    strip they share only (:func:`polycontact._kernels.swept.box_strips`). The strips
    are swept, and each body's partners sorted, in chunks on at most ``threads``
    threads (:func:`polycontact._threads.map_work`; by default as many as
    ``numba.get_num_threads()``) by kernels that release the GIL; every chunk writes its
    own places, so the answer does not depend on the number of threads.

    >>> boxes = np.array([[0, 1, 0, 1, 0, 1], [0.5, 2, 0.5, 2, 0, 1], [0, 4, 3, 4, 0, 1],
    ...                   [0, 1, 0, 1, 2, 3.0]])
    >>> box_pairs(boxes, np.array([0, 1, 2, 0]), 3).tolist()
    [[0, 1]]
    """
    from ._kernels.swept import (box_strips, distinct_partners, partners_of, sweep_strips,
                                 write_pairs)

    if len(boxes) == 0:
        return np.empty((0, 2), np.int64)
    ax, ox, first, start, members = box_strips(boxes)
    strips = len(start) - 1
    per_strip = STRIP_MEMBER_SECONDS * len(members) / strips
    none = np.empty(0, np.int64)

    def sweep(at: np.ndarray, pi: np.ndarray, pj: np.ndarray) -> None:
        map_work(lambda q0, q1: sweep_strips(boxes, owner, ax, ox, first, start, members,
                                             q0, q1, at, pi, pj), strips, per_strip, threads)

    at = np.zeros(strips + 1, np.int64)
    sweep(none, at, none)  # sorts each strip, counts its pairs into at[q + 1]
    np.cumsum(at, out=at)
    pi = np.empty(at[-1], np.int64)
    pj = np.empty(at[-1], np.int64)
    sweep(at, pi, pj)
    # each body's partners (a pair of bodies meets in several pairs of boxes when a
    # body has several slices): grouped, then sorted and kept once
    part, bucket, kept = partners_of(pi, pj, n_bodies)
    per_body = PARTNER_SECONDS * len(pi) / n_bodies
    map_work(lambda i0, i1: distinct_partners(bucket, part, i0, i1, kept), n_bodies,
             per_body, threads)
    np.cumsum(kept, out=kept)
    out = np.empty((kept[-1], 2), np.int64)
    map_work(lambda i0, i1: write_pairs(bucket, part, kept, i0, i1, out), n_bodies,
             per_body, threads)
    return out


def event_time(impact: Impact) -> float:
    """When a pair's event happens: the time :func:`first_impacts` sorts by.

    Parameters
    ----------
    impact : Impact
        The pair's answer.

    Returns
    -------
    float
        0 when penetrating at the start, the first penetration time of a hit, the time
        the search stopped when it ran out of iterations, else the first contact (inf
        when the bodies never touch).

    Examples
    --------
    >>> from polycontact import Motion, Shape, time_of_impact
    >>> sq = Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
    >>> round(event_time(time_of_impact(sq, Motion(velocity=(1, 0)), sq.moved((3, 0)),
    ...                                 Motion(), t_max=5)), 3)
    2.0
    """
    if impact.status is ImpactStatus.PENETRATING_AT_START:
        return 0.0
    if impact.status is ImpactStatus.HIT and impact.time is not None:
        return impact.time
    if impact.status is ImpactStatus.OUT_OF_ITERATIONS:
        return impact.searched_to
    return impact.first_contact if impact.first_contact is not None else math.inf


def first_impacts(
    shapes: Sequence[ShapeLike] | np.ndarray,
    motions: Sequence[Motion] | np.ndarray,
    *,
    t_max: float,
    method: str = "exact",
    time_tolerance: float = TIME_TOLERANCE,
    samples: int = SAMPLES,
    max_iterations: int = MAX_ITERATIONS,
    threads: int | None = None,
) -> PairImpacts:
    """Every pair of moving bodies that meets within ``[0, t_max]``, sorted by time.

    A pair meets when its bodies touch or penetrate at some time of the window (an
    :class:`~polycontact.Impact` with a ``state``), or when its search ran out of
    iterations (no verdict: reported, never dropped). Each entry is
    ``(i, j, impact)`` with ``i < j`` in the caller's numbering and ``impact`` agreeing
    with ``time_of_impact(shapes[i], motions[i], shapes[j], motions[j], t_max=t_max, ...)``;
    entries are sorted by :func:`event_time`, then by ``(i, j)``. Pairs that collide
    have ``impact.collides``; the others only touch (or penetrate from the start, or
    have no verdict: ``impact.status``).

    Only the pairs whose swept bounds meet are searched (:func:`candidate_pairs`: each
    body's bounding circle along its centroid's path, boxed over time slices, then a
    compiled sort-and-sweep), on ``threads`` threads. The others cannot touch: their
    bounding circles never overlap in the window, and ``time_of_impact`` would find
    nothing for them either.

    Parameters
    ----------
    shapes : sequence of ShapeLike, or ndarray of shape (N, V, 2)
        The bodies at t = 0; or the packed form, N outer rings of V vertices each
        (checked and packed in compiled code, as :func:`time_of_impact_many` takes
        them).
    motions : sequence of Motion, or ndarray of shape (N, 6)
        One per body: Motions, or their kernel vectors as rows (as for
        :func:`time_of_impact_many`).
    t_max : float
        End of the time window (>= 0).
    method : {"exact", "sampled"}, default "exact"
        As for :func:`polycontact.time_of_impact`.
    time_tolerance : float, default :data:`~polycontact.limits.TIME_TOLERANCE`
        As for :func:`polycontact.time_of_impact`.
    samples : int, default :data:`~polycontact.limits.SAMPLES`
        As for :func:`polycontact.time_of_impact`.
    max_iterations : int, default :data:`~polycontact.limits.MAX_ITERATIONS`
        As for :func:`polycontact.time_of_impact`, per pair.
    threads : int, optional
        At most this many threads (default ``numba.get_num_threads()``; see the
        threading policy of :doc:`conventions`).

    Returns
    -------
    PairImpacts
        A sequence of ``(i, j, impact)`` records (:class:`PairImpact`), each built when
        read, with the arrays ``pairs``, ``times`` and ``statuses`` of all of them.

    Raises
    ------
    TypeError, ValueError, InvalidShapeError
        As :func:`time_of_impact_many`, naming ``shapes[k]`` or ``motions[k]``; every
        body is checked, whether or not a pair of it is searched.

    Examples
    --------
    >>> from polycontact import Motion, Shape
    >>> sq = Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
    >>> shapes = [sq, sq.moved((3, 0)), sq.moved((1.5, 1)), sq.moved((0, 30))]
    >>> motions = [Motion(velocity=(1, 0)), Motion(), Motion(), Motion()]
    >>> for i, j, imp in first_impacts(shapes, motions, t_max=5):
    ...     print(i, j, imp.status.value, imp.state.value, round(event_time(imp), 3))
    0 2 no-hit contact 0.5
    0 1 hit penetrating 2.0
    """
    from ._kernels.impact_batch import pair_bodies

    t_max, tol, samples, max_iterations, threads = check_many_options(
        t_max, method, time_tolerance, samples, max_iterations, threads)
    # every body is checked as time_of_impact checks it, searched or not
    shape_of, moves, bodies = _moving_bodies(shapes, motions, t_max, threads)
    pairs = _candidates(bodies, t_max, threads)
    if len(pairs) == 0:
        return _no_events()
    # only the shapes of candidate pairs get tables and are searched
    i, j, oi, oj, eps_rel, wanted = pair_bodies(pairs, bodies.owner, bodies.extents,
                                                RELATIVE_TOLERANCE)
    raw = search_pairs(bodies.packed, oi, oj, bodies.motions, bodies.motions, eps_rel, t_max,
                       method, tol, samples, max_iterations, threads, wanted, (i, j))
    code, t_hi, _, contact, _, reached, *_ = raw
    make = _maker(lambda p, s: shape_of(pairs[p, s]), lambda p, s: moves[pairs[p, s]], raw,
                  t_max, method, eps_rel, tol)
    met = np.flatnonzero((code != 0) | (contact >= 0.0))
    # event_time of each, from the arrays (tested equal)
    when = np.select([code[met] == 2, code[met] == 1, code[met] == 3],
                     [0.0, t_hi[met], reached[met]],
                     np.where(contact[met] >= 0.0, contact[met], math.inf))
    # (the pairs come sorted by (i, j): a stable sort by time sorts by (time, i, j))
    order = time_order(when)
    chosen = met[order]
    return PairImpacts(np.ascontiguousarray(pairs[chosen], dtype=np.int64), when[order],
                       code[chosen].astype(np.int8), lambda k: make(int(chosen[k])))


def _no_events() -> PairImpacts:
    """The answer of :func:`first_impacts` when no pair can meet."""

    def never(k: int) -> Impact:  # (no index reaches it)
        raise IndexError(k)

    return PairImpacts(np.empty((0, 2), np.int64), np.empty(0), np.empty(0, np.int8), never)


def first_impact(
    shapes: Sequence[ShapeLike] | np.ndarray,
    motions: Sequence[Motion] | np.ndarray,
    *,
    t_max: float,
    method: str = "exact",
    time_tolerance: float = TIME_TOLERANCE,
    samples: int = SAMPLES,
    max_iterations: int = MAX_ITERATIONS,
    threads: int | None = None,
) -> PairImpact | None:
    """The first event among many moving bodies.

    The earliest collision (a pair penetrating at the start counts at t = 0, a search
    without a verdict at the time it stopped), or, if no pair collides, the earliest
    touch; ties go to the lowest ``(i, j)``. This is the order of
    :meth:`polycontact.Scene.first_impact`.

    Parameters
    ----------
    shapes, motions, t_max, method, time_tolerance, samples, max_iterations, threads
        As for :func:`first_impacts`.

    Returns
    -------
    PairImpact or None
        ``(i, j, impact)``, or None when no pair meets within ``[0, t_max]``.

    Raises
    ------
    TypeError, ValueError, InvalidShapeError
        As :func:`first_impacts`.

    Examples
    --------
    >>> from polycontact import Motion, Shape
    >>> sq = Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
    >>> shapes = [sq, sq.moved((3, 0)), sq.moved((1.5, 1))]
    >>> motions = [Motion(velocity=(1, 0)), Motion(), Motion()]
    >>> i, j, imp = first_impact(shapes, motions, t_max=5)
    >>> i, j, round(imp.time, 3)
    (0, 1, 2.0)
    """
    events = first_impacts(shapes, motions, t_max=t_max, method=method,
                           time_tolerance=time_tolerance, samples=samples,
                           max_iterations=max_iterations, threads=threads)
    if not len(events):
        return None
    # collisions (penetrating at the start, hits, searches without a verdict) by time
    # before any touch, then by (i, j)
    touch = events.statuses == 0
    first = np.lexsort((events.pairs[:, 1], events.pairs[:, 0],
                        np.where(touch, events.times, 0.0),
                        np.where(touch, math.inf, events.times)))[0]
    return events[int(first)]
