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
import os
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from typing import Any, NamedTuple

import numpy as np

from .broad_phase import check_motion, check_reach, check_t_max, reach_excess
from .errors import InvalidShapeError
from .impact import Impact, ImpactStatus, body_frame, check_options, impact_from_kernel
from .limits import (BROAD_PHASE_INFLATION, CONTACT_RESOLUTION, MAX_ITERATIONS, MAX_SLICES,
                     RELATIVE_TOLERANCE, SAMPLES, SWEPT_ROUNDING_ULPS, TIME_TOLERANCE)
from .motion import Motion
from .shape import Shape, ShapeLike, as_shape
from .tolerances import ROUNDING_FACTOR

__all__ = ["ImpactBatch", "PairImpact", "time_of_impact_many", "first_impacts", "first_impact",
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


# -- validation ------------------------------------------------------------------------
def _sequence(items: Any, what: str) -> list[Any]:
    if isinstance(items, (str, bytes, dict)) or not isinstance(items, (Sequence, np.ndarray)):
        raise TypeError(f"{what}: expected a sequence, got {type(items).__name__}")
    return list(items)


def check_shapes(items: Any, what: str) -> list[Shape]:
    """The bodies of the sequence ``items`` as Shapes (an error naming ``what[k]``)."""
    out = []
    for k, obj in enumerate(_sequence(items, what)):
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


def check_motions(items: Any, what: str, count: int, shapes_what: str) -> list[Motion]:
    """The ``count`` Motions of the sequence ``items``, one per shape of ``shapes_what``
    (an error naming ``what``)."""
    motions = _sequence(items, what)
    if len(motions) != count:
        raise ValueError(f"{what}: expected {count} motions (one per shape of {shapes_what}), "
                         f"got {len(motions)}")
    return [m if type(m) is Motion else check_motion(m, f"{what}[{k}]")
            for k, m in enumerate(motions)]


def check_many_options(t_max: float, method: str, time_tolerance: float, samples: int,
                       max_iterations: int,
                       threads: int | None) -> tuple[float, float, int, int, int]:
    """:func:`polycontact.impact.check_options` and ``threads``:
    ``(t_max, time_tolerance, samples, max_iterations, threads)``."""
    t_max, tol = check_options(t_max, method, time_tolerance, samples, max_iterations)
    if threads is None:
        threads = os.cpu_count() or 1
    elif isinstance(threads, bool) or not isinstance(threads, (int, np.integer)) or threads < 1:
        raise ValueError(f"threads: expected an integer >= 1 or None, got {threads!r}")
    return t_max, tol, int(samples), int(max_iterations), int(threads)


# -- the batched search ----------------------------------------------------------------
def _pack(shapes: list[Shape]) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The shapes' packed body frames (``_kernels.impact.pack_body``, built once per
    shape) one after another, with their offsets: ``(floats, f_off, ints, i_off)``
    (see ``impacts_chunk``)."""
    packs = [body_frame(s)[3] for s in shapes]
    f_off = np.zeros(len(packs) + 1, np.int64)
    i_off = np.zeros(len(packs) + 1, np.int64)
    np.cumsum([len(f) for f, _ in packs], out=f_off[1:])
    np.cumsum([len(i) for _, i in packs], out=i_off[1:])
    if not packs:
        return np.empty(0), f_off, np.empty(0, np.int64), i_off
    return (np.concatenate([f for f, _ in packs]), f_off,
            np.concatenate([i for _, i in packs]), i_off)


def search_pairs(shapes: list[Shape], sa: np.ndarray, sb: np.ndarray, ma: np.ndarray,
                 mb: np.ndarray, eps_rel: np.ndarray, t_max: float, method: str, tol: float,
                 samples: int, max_iterations: int, threads: int) -> tuple[Any, ...]:
    """Run the pairs ``(shapes[sa[p]], ma[p])`` vs ``(shapes[sb[p]], mb[p])`` through the
    search of ``time_of_impact`` on ``threads`` threads (``eps_rel[p]``: the size term
    of pair p's distance tolerance, see :func:`_extents`); the raw result arrays."""
    from ._kernels.broad_phase import MAX_INTERVALS
    from ._kernels.swept import impacts_chunk

    exact = method == "exact"
    tables = _pack(shapes)
    p_count = len(sa)
    code = np.zeros(p_count, np.int8)
    t_hi = np.empty(p_count)
    t_lo = np.empty(p_count)
    contact = np.empty(p_count)
    iters = np.empty(p_count, np.int64)
    reached = np.empty(p_count)
    n_iv = np.empty(p_count, np.int64)
    iv = np.empty((p_count, MAX_INTERVALS, 2))
    out = (code, t_hi, t_lo, contact, iters, reached, n_iv, iv)

    pairs = (sa, sb, ma, mb, eps_rel)
    settings = (t_max, BROAD_PHASE_INFLATION, tol, ROUNDING_FACTOR, CONTACT_RESOLUTION,
                max_iterations, exact, samples)

    def run(todo: np.ndarray) -> None:
        impacts_chunk(todo, pairs, tables, settings, out)

    # many small interleaved chunks: the cost of a pair varies a thousandfold (an
    # empty broad phase against a long slide), so the threads take chunks as they go
    order = np.arange(p_count, dtype=np.int64)
    if threads == 1 or p_count < 64:
        run(order)
    else:
        n_chunks = min(p_count // 16, 16 * threads)
        with ThreadPoolExecutor(threads) as pool:
            list(pool.map(run, [order[c::n_chunks].copy() for c in range(n_chunks)]))
    return out


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


def _unique(shapes: list[Shape]) -> tuple[list[Shape], np.ndarray]:
    """Distinct shape objects (a shape used by many pairs is packed once) and each
    input's index among them."""
    seen: dict[int, int] = {}
    uniq: list[Shape] = []
    index = np.empty(len(shapes), np.int64)
    for k, s in enumerate(shapes):
        u = seen.get(id(s))
        if u is None:
            u = seen[id(s)] = len(uniq)
            uniq.append(s)
        index[k] = u
    return uniq, index


def _motion_array(motions: list[Motion]) -> np.ndarray:
    """The rows ``Motion.array`` of every motion, in one NumPy call."""
    return np.array([m._array for m in motions], dtype=np.float64).reshape(len(motions), 6)


def _names(k: int) -> tuple[str, str]:
    """The names of body k's arguments in ``first_impacts`` and ``candidate_pairs``."""
    return f"shapes[{k}]", f"motions[{k}]"


def _extents(shapes: list[Shape], motions: list[Motion],
             name_of: Callable[[int], tuple[str, str]], t_max: float) -> np.ndarray:
    """Each body's extent (the larger side of its bounding box: its pairs' distance
    tolerance has the size term ``RELATIVE_TOLERANCE * max(extent_a, extent_b)``, as in
    ``time_of_impact``), after the checks ``time_of_impact`` makes: the coordinates
    (once per shape, with its body frame), then motions that would carry coordinates,
    speeds or accelerations beyond float64's safe range within [0, t_max]. Errors name
    the body's arguments, ``name_of(k) = (shape's, motion's)`` (made only for an error)."""
    bases = [(s._frame or body_frame(s, tables=False, what=name_of(k)[0]))[2]
             for k, s in enumerate(shapes)]
    for k, (s, m, base) in enumerate(zip(shapes, motions, bases)):
        if reach_excess(base, s.bounding_radius, m._norms, t_max) is not None:
            check_reach(s, m, t_max, name_of(k)[1])  # raises, naming the motion
    return np.array([float(s._extent) for s in shapes], dtype=np.float64)


def time_of_impact_many(
    shapes_a: Any,
    motions_a: Any,
    shapes_b: Any,
    motions_b: Any,
    *,
    t_max: float,
    method: str = "exact",
    time_tolerance: float = TIME_TOLERANCE,
    samples: int = SAMPLES,
    max_iterations: int = MAX_ITERATIONS,
    threads: int | None = None,
) -> ImpactBatch:
    """Time of impact of many pairs ``(shapes_a[k], motions_a[k])`` against
    ``(shapes_b[k], motions_b[k])``, in parallel.

    Pair k's answer is the one ``time_of_impact(shapes_a[k], motions_a[k], shapes_b[k],
    motions_b[k], t_max=..., ...)`` gives (the same kernel with the same arguments; times
    within the time tolerance, see the module docstring); the pairs are shared among ``threads`` threads, since the compiled
    search releases the GIL. A shape that appears in many pairs (the same object) has
    its tables built once.

    The result is a batch of arrays (``status``, ``collides``, ``times``,
    ``first_contacts``), what one filters and sorts over many pairs, with
    ``batch.impact(k)`` giving pair k's full :class:`~polycontact.Impact` (features,
    point, normal) on demand: building the P result objects is left to the pairs the
    caller looks at.

    Parameters
    ----------
    shapes_a, shapes_b : sequence of Shape, shapely Polygon or array_like of shape (N, 2)
        The bodies at t = 0, P of each.
    motions_a, motions_b : sequence of Motion
        Their motions, one per shape.
    t_max, method, time_tolerance, samples, max_iterations
        As for :func:`polycontact.time_of_impact`, for every pair.
    threads : int, optional
        Threads to use (default: one per CPU).

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
    a = check_shapes(shapes_a, "shapes_a")
    b = check_shapes(shapes_b, "shapes_b")
    if len(a) != len(b):
        raise ValueError(f"shapes_a and shapes_b differ in length ({len(a)} and {len(b)})")
    ma = check_motions(motions_a, "motions_a", len(a), "shapes_a")
    mb = check_motions(motions_b, "motions_b", len(b), "shapes_b")
    t_max, tol, samples, max_iterations, threads = check_many_options(
        t_max, method, time_tolerance, samples, max_iterations, threads)
    uniq, sa, sb, rows_a, rows_b, eps_rel = prepare_pairs(a, b, ma, mb, t_max)
    raw = search_pairs(uniq, sa, sb, rows_a, rows_b, eps_rel, t_max, method, tol, samples,
                       max_iterations, threads)
    return impact_batch(a, b, ma, mb, raw, eps_rel, t_max, method, tol)


def prepare_pairs(a: list[Shape], b: list[Shape], ma: list[Motion], mb: list[Motion],
                  t_max: float) -> tuple[Any, ...]:
    """Check every body of the pairs as ``time_of_impact`` does (errors naming where it
    first appears: ``shapes_a[k]``, ``motions_b[k]``, ...), then the inputs of
    :func:`search_pairs`: the distinct shapes, each pair's two indices among them, its two
    motion rows and its ``eps_rel``. (:func:`polycontact.distributed.time_of_impact_many`
    runs this in the caller's process and :func:`search_pairs` on slices.)"""
    # a body (the same shape and motion objects) in many pairs is prepared once
    p_count = len(a)
    seen: dict[tuple[int, int], int] = {}
    body = np.empty(2 * p_count, np.int64)
    b_shapes: list[Shape] = []
    b_motions: list[Motion] = []
    first: list[int] = []                      # where each body first appears
    for k, (s, m) in enumerate(zip(a + b, ma + mb)):
        u = seen.setdefault((id(s), id(m)), len(b_shapes))
        if u == len(b_shapes):
            b_shapes.append(s)
            b_motions.append(m)
            first.append(k)
        body[k] = u

    def name_of(u: int) -> tuple[str, str]:
        k = first[u]
        side, q = ("a", k) if k < p_count else ("b", k - p_count)
        return f"shapes_{side}[{q}]", f"motions_{side}[{q}]"

    extent = _extents(b_shapes, b_motions, name_of, t_max)
    uniq, index = _unique(b_shapes)
    rows = _motion_array(b_motions)
    ba, bb = body[:p_count], body[p_count:]
    eps_rel = RELATIVE_TOLERANCE * np.maximum(extent[ba], extent[bb])
    return uniq, index[ba], index[bb], rows[ba], rows[bb], eps_rel


def impact_batch(a: list[Shape], b: list[Shape], ma: list[Motion], mb: list[Motion],
                 raw: tuple[Any, ...], eps_rel: np.ndarray, t_max: float, method: str,
                 tol: float) -> ImpactBatch:
    """The :class:`ImpactBatch` of the pairs ``(a[p], ma[p])`` vs ``(b[p], mb[p])`` from
    the raw result arrays of :func:`search_pairs`."""
    code, t_hi, _, contact, *_ = raw
    collides = code == 1
    pairs = (a, b)
    moves = (ma, mb)
    make = _maker(lambda p, s: pairs[s][p], lambda p, s: moves[s][p], raw, t_max, method,
                  eps_rel, tol)
    return ImpactBatch(
        statuses=code,
        collides=collides,
        times=np.where(collides, t_hi, np.nan),
        first_contacts=np.where(code == 2, 0.0, np.where(contact >= 0.0, contact, np.nan)),
        _make=make,
    )


# -- many moving bodies ----------------------------------------------------------------
def candidate_pairs(shapes: Sequence[ShapeLike], motions: Sequence[Motion], *,
                    t_max: float) -> np.ndarray:
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
    shapes = check_shapes(shapes, "shapes")
    motions = check_motions(motions, "motions", len(shapes), "shapes")
    t_max = check_t_max(t_max)
    _extents(shapes, motions, _names, t_max)
    return _candidates(shapes, motions, t_max)


def _candidates(shapes: list[Shape], motions: list[Motion], t_max: float) -> np.ndarray:
    from ._kernels.swept import box_pairs, swept_boxes

    n = len(shapes)
    if n < 2:
        return np.empty((0, 2), np.int64)
    cent = np.array([s.centroid for s in shapes], dtype=np.float64).reshape(n, 2)
    rad = np.array([s.bounding_radius for s in shapes], dtype=np.float64)
    boxes, owner = swept_boxes(cent, _motion_array(motions), rad, t_max, MAX_SLICES,
                               BROAD_PHASE_INFLATION, SWEPT_ROUNDING_ULPS * 2.0**-52)
    pairs: np.ndarray = box_pairs(boxes, owner, n)
    return pairs


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
    shapes: Sequence[ShapeLike],
    motions: Sequence[Motion],
    *,
    t_max: float,
    method: str = "exact",
    time_tolerance: float = TIME_TOLERANCE,
    samples: int = SAMPLES,
    max_iterations: int = MAX_ITERATIONS,
    threads: int | None = None,
) -> list[PairImpact]:
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
    shapes : sequence of ShapeLike
        The bodies at t = 0.
    motions : sequence of Motion
        One per body.
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
        Threads for the searches (default: one per CPU).

    Returns
    -------
    list of PairImpact
        ``(i, j, impact)`` records.

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
    shapes = check_shapes(shapes, "shapes")
    motions = check_motions(motions, "motions", len(shapes), "shapes")
    t_max, tol, samples, max_iterations, threads = check_many_options(
        t_max, method, time_tolerance, samples, max_iterations, threads)
    # every body is checked as time_of_impact checks it, searched or not
    extent = _extents(shapes, motions, _names, t_max)
    pairs = _candidates(shapes, motions, t_max)
    if len(pairs) == 0:
        return []
    # only the bodies of candidate pairs are packed and searched
    used = np.unique(pairs)
    local = np.empty(len(shapes), np.int64)
    local[used] = np.arange(len(used))
    sub_shapes = [shapes[k] for k in used]
    sub_motions = [motions[k] for k in used]
    uniq, index = _unique(sub_shapes)
    m = _motion_array(sub_motions)
    eps_rel = RELATIVE_TOLERANCE * np.maximum(extent[pairs[:, 0]], extent[pairs[:, 1]])
    i, j = local[pairs[:, 0]], local[pairs[:, 1]]
    raw = search_pairs(uniq, index[i], index[j], m[i], m[j], eps_rel, t_max, method, tol,
                       samples, max_iterations, threads)
    i, j = pairs[:, 0], pairs[:, 1]
    code, _, _, contact, *_ = raw
    make = _maker(lambda p, s: shapes[pairs[p, s]], lambda p, s: motions[pairs[p, s]], raw,
                  t_max, method, eps_rel, tol)
    events = [PairImpact(int(i[p]), int(j[p]), make(int(p)))
              for p in np.flatnonzero((code != 0) | (contact >= 0.0))]
    events.sort(key=lambda e: (event_time(e.impact), e.i, e.j))
    return events


def _first_order(event: PairImpact) -> tuple[Any, ...]:
    """:meth:`polycontact.Scene.first_impact`'s order: collisions (penetrating at the
    start, hits, searches without a verdict) by time before any touch."""
    imp = event.impact
    touch_only = imp.status is ImpactStatus.NO_HIT
    return (math.inf if touch_only else event_time(imp),
            event_time(imp) if touch_only else 0.0, event.i, event.j)


def first_impact(
    shapes: Sequence[ShapeLike],
    motions: Sequence[Motion],
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
    return min(events, key=_first_order) if events else None
