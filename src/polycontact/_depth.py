"""Penetration depth of one pair or of many: the depth kernels on the bodies' convex
pieces, and the refusal of bodies too large for it.

Small bodies take the contact segments of
:func:`polycontact._kernels.convolution.contact_depth` (no decomposition); the others,
and the pairs that kernel cannot decide, the search over convex Minkowski sums of
:mod:`polycontact._kernels.depth`, on pieces from :mod:`polycontact._pieces`. When the
sums near the overlap would hold more than :data:`~polycontact.limits.MAX_SUM_VERTICES`
vertices, the kernels build none and say so; :class:`~polycontact.DepthTooLargeError`
is raised here.

Examples
--------
>>> import numpy as np
>>> sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
>>> st = np.array([0, 4])
>>> [float(v) for v in penetration(sq, st, sq + np.array([0.75, 0.5]), st, 1e-12)]
[0.25, -0.25, 0.0]
"""

from __future__ import annotations

from typing import Any, cast

import numpy as np
import numpy.typing as npt

from ._pieces import pieces_packed
from ._threads import map_work
from .errors import DepthTooLargeError
from . import limits
from .limits import EAR_CLIPPING_MAX, RELATIVE_TOLERANCE, ROUNDING_ULPS

__all__ = ["penetration", "penetrations"]

#: The work of one pair's depth, and of one body's convex pieces (seconds, 12-gons):
#: the unit by which the pairs and bodies are split over threads.
DEPTH_SECONDS = 10e-6
PIECES_SECONDS = 5e-6
#: The work of one pair's key (:func:`polycontact._kernels.depth.pair_keys`).
KEY_SECONDS = 50e-9


def penetration(xa: np.ndarray, sa: np.ndarray, xb: np.ndarray, sb: np.ndarray,
                eps: float) -> tuple[float, float, float]:
    """Smallest translation ``(dx, dy)`` of A after which the interiors no longer overlap.

    Returns ``(depth, dx, dy)``; the bodies are packed (outer loop first, interior on
    the left of every edge). Bodies of at most
    :data:`polycontact._kernels.convolution.FEW_VERTICES` vertices in all take
    :func:`polycontact._kernels.convolution.contact_depth` (no decomposition), unless
    it cannot decide. Otherwise the first escape is
    :func:`polycontact._kernels.depth.first_escape`'s (out of B's bounding box, or along
    an edge normal); then :func:`polycontact._kernels.depth.depth_from_pieces` looks for
    a nearer one on the union of the convex sums of the pieces of B and −A (decomposed
    in O(n log n), cached by coordinates).

    Cost: the decomposition (cached), then O(P log P + K log K) for the P pairs of
    pieces whose sums reach the disk of the first escape and their K edges, plus the
    clipping of each edge nearer than the depth (usually by one sum; by up to P when it
    is uncovered) and one state check, O((m + n) log(m + n)), per uncovered part nearer
    than the best escape so far. When one body is small or convex, P = O(m + n) and the
    whole is near O((m + n) log(m + n)). Two large concave bodies whose pieces are long
    (stars) make P grow with the product of their piece counts even for a shallow
    overlap, up to about m n / 4 for deeply interlocked ones: O(P + K P) at worst
    (figures: ``benchmarks/bench_scaling.py``).

    Raises
    ------
    DepthTooLargeError
        When the convex sums near the overlap would hold more than
        :data:`~polycontact.limits.MAX_SUM_VERTICES` vertices (read at each call):
        before the bodies are decomposed when the vertex-edge contacts within the first
        escape already prove it (:func:`polycontact._kernels.depth.contacts_near`, a
        lower bound), else once the pieces near the overlap are counted.

    Examples
    --------
    >>> import numpy as np
    >>> sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    >>> st = np.array([0, 4])
    >>> [float(v) for v in penetration(sq, st, sq + np.array([0.5, 0.0]), st, 1e-12)]
    [0.5, -0.5, 0.0]
    """
    from ._kernels.convolution import FEW_VERTICES, contact_depth
    from ._kernels.depth import box_escape, contacts_near, depth_from_pieces, first_escape

    if len(xa) + len(xb) <= FEW_VERTICES:
        fast = contact_depth(xa, sa, xb, sb, *box_escape(xa, xb), eps)
        if fast[3]:
            return fast[0], fast[1], fast[2]
    escape = first_escape(xa, xb)
    limit = limits.MAX_SUM_VERTICES
    # refused before decomposing (GEOS's triangulation of 10^5 vertices takes seconds)
    # when the contacts near the overlap already prove the sums too large
    lower = contacts_near(xa, sa, xb, sb, escape[0], float(limit))
    if lower > limit:
        raise _too_large(len(xa), len(xb),
                         f"at least {lower:.0f} (counted from the vertex-edge contacts "
                         f"within the first escape, {escape[0]:.3g} length units)")
    bxy, bst = pieces_packed(xb, sb)
    axy, ast = pieces_packed(xa, sa)
    got = depth_from_pieces((xa, sa), (xb, sb), (bxy, bst), (-axy, ast), escape, eps, limit)
    if np.isnan(got[0]):
        raise _too_large(len(xa), len(xb), "more")
    return cast("tuple[float, float, float]", got)


def penetrations(batch: tuple[np.ndarray, ...], pairs: np.ndarray,
                 eps: np.ndarray) -> np.ndarray:
    """Penetration depths of the pairs ``pairs`` of two packed batches, in parallel:
    ``(P, 3)`` rows ``(depth, dx, dy)``, each equal to :func:`penetration` of the pair;
    ``eps`` per pair. ``batch`` is ``(xa, lsa, bsa, fa, xb, lsb, bsb, fb)``, the bodies
    A and B in the packed form of :mod:`polycontact._kernels.relation_many`.

    Each distinct pair (the same two bodies and tolerance, found by keys computed in
    parallel) is computed once: by
    :func:`polycontact._kernels.depth.contact_depths`, then the pairs it leaves by
    :func:`polycontact._kernels.depth.depths_of_pairs`, each distinct body among those
    decomposed once, in parallel (on the threads of
    :func:`polycontact._threads.map_work`).

    Raises
    ------
    DepthTooLargeError
        As :func:`penetration`, for the first pair too large.

    Examples
    --------
    >>> import numpy as np
    >>> sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    >>> ls, bs, f = np.array([0, 4]), np.array([0, 2]), np.ones(1)
    >>> penetrations((sq, ls, bs, f, sq + 0.5, ls, bs, f), np.array([0]), np.array([1e-12]))
    array([[ 0.5, -0.5,  0. ]])
    """
    from ._kernels.depth import contact_depths, distinct_pairs, pair_keys

    xa, lsa, bsa, fa, xb, lsb, bsb, fb = batch
    pairs = np.asarray(pairs, dtype=np.int64)
    eps = np.ascontiguousarray(eps, dtype=np.float64)
    # equal pairs (the same A, B and tolerance) have the same depth: one computation
    keys = _joined_rows(map_work(lambda p0, p1: pair_keys(batch, pairs[p0:p1], eps[p0:p1]),
                                 len(pairs), KEY_SECONDS))
    one, group = cast("tuple[npt.NDArray[np.int64], npt.NDArray[np.int64]]",
                      distinct_pairs(batch, pairs, eps, keys))
    todo, todo_eps = pairs[one], eps[one]
    out = _joined_rows(map_work(lambda p0, p1: contact_depths(batch, todo[p0:p1],
                                                              todo_eps[p0:p1]),
                                len(todo), DEPTH_SECONDS))
    rest = np.flatnonzero(np.isnan(out[:, 0]))  # (large bodies, or undecided)
    if rest.size:
        out[rest] = _depths_by_pieces(batch, pairs[one[rest]], eps[one[rest]])
    bad = np.flatnonzero(np.isnan(out[:, 0]))
    if bad.size:
        p = pairs[one[bad[0]]]
        raise _too_large(int(lsa[bsa[p + 1] - 1] - lsa[bsa[p]]),
                         int(lsb[bsb[p + 1] - 1] - lsb[bsb[p]]), "more")
    return out[group]


def _too_large(m: int, n: int, estimate: str) -> DepthTooLargeError:
    """The error of a depth whose convex sums would hold ``estimate`` vertices, more
    than the limit."""
    return DepthTooLargeError(
        f"penetration depth: the convex sums of the pieces near the overlap would hold "
        f"{estimate} vertices, more than limits.MAX_SUM_VERTICES = "
        f"{limits.MAX_SUM_VERTICES:.3g} (memory); the bodies ({m} and {n} vertices) are "
        f"too large and interlocked for this depth (set "
        f"polycontact.limits.MAX_SUM_VERTICES to allow more)"
    )


def _batch_pieces(x: np.ndarray, ls: np.ndarray, bs: np.ndarray, f: np.ndarray,
                  ids: np.ndarray, negate: bool) -> tuple[np.ndarray, ...]:
    """:func:`polycontact._kernels.depth.pieces_of_bodies`, with the bodies it leaves
    decomposed by :func:`polycontact._pieces.pieces_packed` (GEOS) and appended."""
    from ._kernels.depth import pieces_of_bodies
    from ._kernels.relation_many import body

    parts = map_work(lambda p0, p1: pieces_of_bodies(x, ls, bs, f, ids[p0:p1], negate,
                                                     RELATIVE_TOLERANCE, ROUNDING_ULPS,
                                                     EAR_CLIPPING_MAX),
                     len(ids), PIECES_SECONDS)
    xy, st, first, count, ok = _joined_pieces(parts)
    if ok.all():
        return xy, st, first, count
    more_xy, more_st = [xy], [st]
    rows, at = len(xy), len(st)
    for k in np.flatnonzero(~ok):
        y, s = body(x, ls, bs, ids[k])
        if f[ids[k]] < 0.0:  # a raw clockwise ring
            y = y[::-1].copy()
        pxy, pst = pieces_packed(y, s)
        more_xy.append(-pxy if negate else pxy)
        more_st.append(pst + rows)
        first[k], count[k] = at, len(pst) - 1
        rows += len(pxy)
        at += len(pst)
    return np.concatenate(more_xy), np.concatenate(more_st), first, count


def _depths_by_pieces(batch: tuple[np.ndarray, ...], pairs: np.ndarray,
                      eps: np.ndarray) -> Any:
    """:func:`polycontact._kernels.depth.depths_of_pairs` of the pairs ``pairs`` of
    ``batch`` (as for :func:`penetrations`), each distinct body decomposed once (NaN
    rows as there)."""
    from ._kernels.depth import depths_of_pairs, distinct_bodies

    xa, lsa, bsa, fa, xb, lsb, bsb, fb = batch
    ua, slot_a = distinct_bodies(xa, lsa, bsa, fa, pairs)
    ub, slot_b = distinct_bodies(xb, lsb, bsb, fb, pairs)
    ra = _batch_pieces(xa, lsa, bsa, fa, ua, True)
    rb = _batch_pieces(xb, lsb, bsb, fb, ub, False)
    return _joined_rows(map_work(
        lambda p0, p1: depths_of_pairs(batch, pairs[p0:p1], eps[p0:p1], slot_a[p0:p1], ra,
                                       slot_b[p0:p1], rb, limits.MAX_SUM_VERTICES),
        len(pairs), DEPTH_SECONDS))


def _joined_rows(parts: list[np.ndarray]) -> np.ndarray:
    """The rows (depths, or keys) of consecutive runs of pairs, as one array."""
    return parts[0] if len(parts) == 1 else np.concatenate(parts)


def _joined_pieces(parts: list[tuple[np.ndarray, ...]]) -> tuple[np.ndarray, ...]:
    """The pieces ``(xy, starts, first, count, ok)`` of consecutive runs of bodies
    (:func:`polycontact._kernels.depth.pieces_of_bodies` of each), as those of all the
    bodies: each run's starts shifted by the rows, and its firsts by the starts, before
    it."""
    if len(parts) == 1:
        return parts[0]
    rows = np.cumsum([0] + [len(p[0]) for p in parts])
    at = np.cumsum([0] + [len(p[1]) for p in parts])
    return (np.concatenate([p[0] for p in parts]),
            np.concatenate([p[1] + r for p, r in zip(parts, rows)]),
            np.concatenate([p[2] + a for p, a in zip(parts, at)]),
            np.concatenate([p[3] for p in parts]), np.concatenate([p[4] for p in parts]))
