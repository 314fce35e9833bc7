"""Kernels for the no-fit polygon: its outline, exact fits and slides in one call.

``E(A, B)`` is the union of the convex sums ``C_ij = B_i ⊕ (a0 − A_j)`` over convex
pieces ``B_i`` of B and ``A_j`` of A (:mod:`polycontact._kernels.minkowski`). The
interiors of A and B overlap exactly when the reference point lies in the union ``O``
of the OPEN sums; ``E`` is the closure of ``O``. Its outline is assembled from the sums'
uncovered edge parts (:mod:`polycontact._kernels.outline`); the exact fits and slides
are ``int(E) \\ O`` (:mod:`polycontact._kernels.fits`).
"""

from __future__ import annotations

import numpy as np

from .jit import njit
from .decompose import ring_pieces
from .fits import degenerate_contacts, exact_candidates
from .minkowski import boxes, clip_tests, convex_sums, frames, mark_inner
from .outline import (assemble_rings, clip_edges, closed_loops, outline_index, ring_stats,
                      tidy_rings, without_collinear)
from .tolerance import tolerance_of


@njit(cache=True, nogil=True)
def entrance_region(bxy, bstarts, rxy, rstarts, eps, rel_tol, ulps, ang_tol, max_tests):
    """Everything the no-fit polygon needs, in one call (few arrays: boxing costs).

    ``(bxy, bstarts)``: convex pieces of B; ``(rxy, rstarts)``: convex pieces of
    ``a0 − A``. ``eps <= 0`` means the default tolerance of the sums' coordinates
    (:func:`polycontact._kernels.tolerance.tolerance_of` with ``rel_tol`` and ``ulps``).
    Returns ``(ring_xy, ring_starts, ring_stats, candidates, meta)``: the outline's
    rings, closed (each ends with its first point); their signed area and length
    (R, 2); candidate exact fits then candidate slides as segments (C, 4), an exact
    fit as a zero-length segment; ``meta`` =
    ``[eps, ok, number of candidate exact fits, clip tests]``, ``ok`` = 0 when the
    outline parts did not link into rings (the caller then unions the sums another way),
    -1 when the sums are not finite (input beyond float64: the caller refuses it), -2
    (nothing computed) when clipping the sums' edges would take more than
    ``max_tests`` edge–sum tests (:func:`polycontact._kernels.minkowski.clip_tests`,
    the last entry of ``meta``: the caller refuses the work).
    """
    return _entrance(bxy, bstarts, rxy, rstarts, eps, rel_tol, ulps, ang_tol, max_tests)[2:]


@njit(cache=True, nogil=True)
def _finite(xy):
    """Whether every coordinate is finite (without the array of ``np.isfinite``)."""
    for i in range(xy.shape[0]):
        if not (np.isfinite(xy[i, 0]) and np.isfinite(xy[i, 1])):
            return False
    return True


@njit(cache=True, nogil=True, inline="always")
def _entrance(bxy, bstarts, rxy, rstarts, eps, rel_tol, ulps, ang_tol, max_tests):
    """:func:`entrance_region`'s answer preceded by the sums ``(xy, starts)``.

    Inlined in each of its callers (one each) rather than compiled on its own: linked
    into them, its compiled code would be optimised and emitted once more for each
    (a compile several seconds longer, for no faster code)."""
    sums, starts, keep = convex_sums(bxy, bstarts, rxy, rstarts)
    if not _finite(sums):
        # error code, not a crash: the caller refuses the input
        return _nothing(sums, starts, np.array([1.0, -1.0, 0.0, 0.0]))
    if eps <= 0.0:
        eps = tolerance_of(sums, rel_tol, ulps)
    meta = np.array([eps, 1.0, 0.0, 0.0])
    if starts.shape[0] == 2:
        # one sum: its vertices are the sums' (nothing to snap)
        ring_xy, rs = without_collinear(sums, np.array([0, sums.shape[0]], np.int64), eps)
        area, length = ring_stats(ring_xy, rs)
        ring_xy, ring_starts = closed_loops(ring_xy, rs)
        return (sums, starts, ring_xy, ring_starts, np.column_stack((area, length)),
                np.empty((0, 4)), meta)
    bb = boxes(sums, starts)
    fr = frames(sums, starts)
    # (edges off the reduced convolution: none of the outline)
    mark_inner(sums, starts, fr, keep, eps)
    index = outline_index(sums, starts, bb, fr, eps)
    meta[3] = clip_tests((sums, starts, bb, fr), index, eps)
    if meta[3] > max_tests:
        meta[1] = -2.0  # (refused before clipping)
        return _nothing(sums, starts, meta)
    outline, loose = clip_edges(sums, starts, bb, fr, eps, index)
    ok, ring_xy, ring_starts = assemble_rings(outline, 4.0 * eps)
    ring_xy, ring_starts = tidy_rings(ring_xy, ring_starts, sums, eps)
    area, length = ring_stats(ring_xy, ring_starts)
    pts, segs = degenerate_contacts(sums, starts, bb, fr, loose, eps, ang_tol)
    cand = np.empty((pts.shape[0] + segs.shape[0], 4))
    cand[: pts.shape[0], 0:2] = pts
    cand[: pts.shape[0], 2:4] = pts
    cand[pts.shape[0]:] = segs
    meta[1] = 1.0 if ok else 0.0
    meta[2] = pts.shape[0]
    ring_xy, ring_starts = closed_loops(ring_xy, ring_starts)
    return sums, starts, ring_xy, ring_starts, np.column_stack((area, length)), cand, meta


@njit(cache=True, nogil=True)
def _nothing(sums, starts, meta):
    """:func:`_entrance`'s answer with no outline nor candidates (``meta`` says why)."""
    return (sums, starts, sums[:0], np.zeros(1, np.int64), np.empty((0, 2)),
            np.empty((0, 4)), meta)


@njit(cache=True, nogil=True)
def ring_entrance(bxy, axy, a0x, a0y, eps, rel_tol, ulps, ang_tol, snap_f, near_f, max_ear,
                  max_sum, max_tests):
    """:func:`entrance_region` of two simple CCW rings B and A (no holes), each cut into
    convex pieces here (:func:`polycontact._kernels.decompose.ring_pieces`, up to
    ``max_ear`` vertices), A's reflected through ``(a0x, a0y)``: one call where a
    decomposition cached by the caller would cost more to look up than to redo.

    Returns ``(head, buf)`` as :func:`entrance_packed`; ``head[0]`` (ok) is 0 (and the
    rest empty) when a ring is too large or has no ear left, or the sums would hold more
    than ``max_sum`` vertices: the caller then decomposes the rings another way (or
    refuses them) and calls :func:`entrance_packed`. ``max_tests``: as for
    :func:`entrance_region`.
    """
    okb, bp, bst = ring_pieces(bxy, rel_tol, ulps, max_ear)
    oka, ap, ast = ring_pieces(axy, rel_tol, ulps, max_ear)
    total = bp.shape[0] * (ast.shape[0] - 1) + ap.shape[0] * (bst.shape[0] - 1)
    if not (okb and oka) or total > max_sum:
        return _pack(False, *_nothing(bp, bst, np.zeros(4)), snap_f, near_f)
    r = np.empty_like(ap)
    for i in range(ap.shape[0]):
        r[i, 0] = a0x - ap[i, 0]
        r[i, 1] = a0y - ap[i, 1]
    return _pack(True, *_entrance(bp, bst, r, ast, eps, rel_tol, ulps, ang_tol, max_tests),
                 snap_f, near_f)


@njit(cache=True, nogil=True)
def entrance_packed(bxy, bstarts, rxy, rstarts, eps, rel_tol, ulps, ang_tol, snap_f, near_f,
                    max_tests):
    """:func:`entrance_region`'s answer as two objects, ``(head, buf)``: returning an
    array to Python costs about half a microsecond each, a third of a small no-fit
    polygon's kernel time with five. The candidates are made exact here, where the sums
    are at hand (see :func:`exact_candidates`; ``snap_f`` and ``near_f`` times the
    tolerance are its ``snap`` and ``near``).

    ``head`` = ``(ok, eps, status, candidate fits, rings, ring vertices, candidates,
    clip tests)``, floats (``ok`` = 1; ``status`` and the clip tests are ``meta[1]``
    and ``meta[3]`` of :func:`entrance_region`); ``buf`` (float64) holds, one after the
    other, the rings' coordinates (x0, y0, x1, ...), their starts (rings + 1), their
    (area, length) and the candidates (4 each); see
    :func:`polycontact.nfp._unpack`.
    """
    return _pack(True, *_entrance(bxy, bstarts, rxy, rstarts, eps, rel_tol, ulps, ang_tol,
                                  max_tests), snap_f, near_f)


@njit(cache=True, nogil=True)
def _pack(ok, sums, starts, ring_xy, ring_starts, stats, cand, meta, snap_f, near_f):
    """``(head, buf)`` of :func:`entrance_packed` from :func:`_entrance`'s answer."""
    if cand.shape[0]:
        n_pts = int(meta[2])
        cand = exact_candidates(cand, n_pts, sums, starts, snap_f * meta[0],
                                 near_f * meta[0])
    nv = ring_xy.shape[0]
    nr = ring_starts.shape[0] - 1
    nc = cand.shape[0]
    buf = np.empty(2 * nv + (nr + 1) + 2 * nr + 4 * nc)
    w = 0
    for i in range(nv):
        buf[w] = ring_xy[i, 0]
        buf[w + 1] = ring_xy[i, 1]
        w += 2
    for k in range(nr + 1):
        buf[w] = ring_starts[k]
        w += 1
    for k in range(nr):
        buf[w] = stats[k, 0]
        buf[w + 1] = stats[k, 1]
        w += 2
    for k in range(nc):
        for c in range(4):
            buf[w] = cand[k, c]
            w += 1
    head = (1.0 if ok else 0.0, meta[0], meta[1], meta[2], float(nr), float(nv), float(nc),
            meta[3])
    return head, buf
