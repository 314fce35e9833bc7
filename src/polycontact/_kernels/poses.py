"""Kernels: the poses of a World's bodies, set for many bodies in one call.

A body of a World is kept twice (see :mod:`polycontact._kernels.world` for the packed
layout): its **base** rows ``bxy`` (the shape as added, outer loop counter-clockwise,
holes clockwise) with the base's area centroid ``cen``, and the rows ``xy`` where it
stands: ``xy = pos + R(angle) (bxy - cen)``, element by element as
:func:`polycontact._kernels.world.place` computes it, so that a pose set here and one
set body by body give the same bits. Each body's box, default tolerance and cell of the
broad-phase grid follow its rows: the pass that writes the rows also marks the bodies
whose box has left their cell, and a body whose new box stays in its cell costs the grid
nothing (:func:`polycontact._kernels.world.regrid`).

The centroid is :attr:`polycontact.Shape.centroid`'s formula with NumPy's summation
order (:func:`pairwise_sum`), so a body added from raw rings gets the centroid its
``Shape`` would have, to the last bit.
"""

from __future__ import annotations

import math

import numpy as np
from numba import prange

from .jit import njit
from .tolerance import box_extent_magnitude, tolerance_for
from .world import cell_key

#: NumPy's pairwise summation: runs of up to this many terms are summed in 8 lanes.
_BLOCK = 128


@njit(cache=True, nogil=True)
def _block_sum(a, i0, n):
    """NumPy's sum of a run of at most 128 terms (8 lanes; fewer than 8: in order)."""
    if n < 8:
        res = 0.0
        for i in range(n):
            res += a[i0 + i]
        return res
    r0, r1, r2, r3 = a[i0], a[i0 + 1], a[i0 + 2], a[i0 + 3]
    r4, r5, r6, r7 = a[i0 + 4], a[i0 + 5], a[i0 + 6], a[i0 + 7]
    i = 8
    while i < n - n % 8:
        r0 += a[i0 + i]
        r1 += a[i0 + i + 1]
        r2 += a[i0 + i + 2]
        r3 += a[i0 + i + 3]
        r4 += a[i0 + i + 4]
        r5 += a[i0 + i + 5]
        r6 += a[i0 + i + 6]
        r7 += a[i0 + i + 7]
        i += 8
    res = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
    while i < n:
        res += a[i0 + i]
        i += 1
    return res


@njit(cache=True, nogil=True)
def pairwise_sum(a, i0, n):
    """``a[i0:i0 + n].sum()`` bit for bit as NumPy sums a contiguous float64 array (its
    pairwise summation: 8 lanes over runs of up to 128 terms; above, the two halves'
    sums added, the first half a multiple of 8 long), without recursion.

    >>> import numpy as np
    >>> a = np.random.default_rng(0).standard_normal(1000) * 1e8
    >>> float(pairwise_sum(a, 0, 1000)) == float(a.sum())
    True
    """
    if n <= _BLOCK:
        return _block_sum(a, i0, n)
    # the recursion's frames: start, length, halves done, the first half's sum
    start = np.empty(64, np.int64)
    length = np.empty(64, np.int64)
    done = np.empty(64, np.int64)
    left = np.empty(64)
    start[0] = i0
    length[0] = n
    done[0] = 0
    top = 1
    value = 0.0
    while top > 0:
        f = top - 1
        n2 = length[f] // 2
        n2 -= n2 % 8
        if length[f] <= _BLOCK or done[f] == 2:
            value = _block_sum(a, start[f], length[f]) if length[f] <= _BLOCK \
                else left[f] + value
            top -= 1
            if top > 0:  # back in the parent: its first half, or its second
                p = top - 1
                if done[p] == 1:
                    left[p] = value
        else:
            done[f] += 1
            start[top] = start[f] + (0 if done[f] == 1 else n2)
            length[top] = n2 if done[f] == 1 else length[f] - n2
            done[top] = 0
            top += 1
    return value


@njit(cache=True, nogil=True)
def _centroid(xy, starts, work):
    """Area centroid and bounding radius of one body (rows ``xy``, loop ``starts``
    relative to them): :attr:`polycontact.Shape.centroid`'s operations, coordinates
    relative to the first vertex; ``work`` holds at least 3 rows per vertex."""
    n = xy.shape[0]
    ox = xy[0, 0]
    oy = xy[0, 1]
    for k in range(starts.shape[0] - 1):
        s = starts[k]
        e = starts[k + 1]
        for i in range(s, e):
            j = i + 1 if i + 1 < e else s
            x = xy[i, 0] - ox
            y = xy[i, 1] - oy
            xn = xy[j, 0] - ox
            yn = xy[j, 1] - oy
            c = x * yn - xn * y
            work[i] = c
            work[n + i] = (x + xn) * c
            work[2 * n + i] = (y + yn) * c
    a2 = pairwise_sum(work, 0, n)
    cx = ox + pairwise_sum(work, n, n) / (3.0 * a2)
    cy = oy + pairwise_sum(work, 2 * n, n) / (3.0 * a2)
    rad = 0.0
    for i in range(n):
        rad = max(rad, math.hypot(xy[i, 0] - cx, xy[i, 1] - cy))
    return cx, cy, rad


@njit(cache=True, nogil=True)
def centroids(xy, ls, bs, cen, rad):
    """Area centroid (``cen``, (P, 2)) and bounding radius (``rad``) of each body of a
    packed batch: body p has loop starts ``ls[bs[p]:bs[p + 1]]`` (rows of ``xy``, the
    last one its end). See :func:`_centroid`."""
    vmax = 0
    for p in range(bs.shape[0] - 1):
        vmax = max(vmax, ls[bs[p + 1] - 1] - ls[bs[p]])
    work = np.empty(3 * vmax)
    starts = np.empty(ls.shape[0], np.int64)
    for p in range(bs.shape[0] - 1):
        first = ls[bs[p]]
        m = bs[p + 1] - bs[p]
        for k in range(m):
            starts[k] = ls[bs[p] + k] - first
        cx, cy, r = _centroid(xy[first:ls[bs[p + 1] - 1]], starts[:m], work)
        cen[p, 0] = cx
        cen[p, 1] = cy
        rad[p] = r
    return vmax


@njit(cache=True, nogil=True)
def _pose_range(ids, poses, bodies, base, tolerance, store, cells, k0, k1):
    """:func:`pose_rows` for ``ids[k0:k1]``; returns the largest |coordinate| and the
    largest tolerance written."""
    pos, ang = poses
    xy, ls, lo, nl, box, eps = bodies
    bxy, cen = base
    rel, ulps = tolerance
    pos_out, ang_out, ver = store
    keys, slot, origin, left = cells
    big = 0.0
    emax = 0.0
    for k in range(k0, k1):
        b = ids[k]
        a = ang[k] if ang.shape[0] else ang_out[b]
        pos_out[b, 0] = pos[k, 0]
        pos_out[b, 1] = pos[k, 1]
        ang_out[b] = a
        ver[b] += 1
        f = ls[lo[b]]
        e = ls[lo[b] + nl[b]]
        cs = math.cos(a)
        sn = math.sin(a)
        x0 = np.inf
        x1 = -np.inf
        y0 = np.inf
        y1 = -np.inf
        cx = cen[b, 0]
        cy = cen[b, 1]
        for i in range(f, e):
            # place()'s operations, in the same order
            dx = bxy[i, 0] - cx
            dy = bxy[i, 1] - cy
            x = pos[k, 0] + (dx * cs - dy * sn)
            y = pos[k, 1] + (dx * sn + dy * cs)
            xy[i, 0] = x
            xy[i, 1] = y
            x0 = min(x0, x)
            x1 = max(x1, x)
            y0 = min(y0, y)
            y1 = max(y1, y)
        box[b, 0] = x0
        box[b, 1] = x1
        box[b, 2] = y0
        box[b, 3] = y1
        extent, magnitude = box_extent_magnitude(x0, x1, y0, y1)
        eps[b] = tolerance_for(extent, magnitude, rel, ulps)
        if left.shape[0]:
            left[k] = not (slot[b] >= 0 and keys[slot[b]] == cell_key(box, b, origin)[1])
        big = max(big, magnitude)
        emax = max(emax, eps[b])
    return big, emax


@njit(cache=True, nogil=True, parallel=True)
def pose_rows(ids, poses, bodies, base, tolerance, store, cells, chunks):
    """Rows, boxes (``x0, x1, y0, y1``) and default tolerances of the bodies ``ids`` at
    the poses ``poses`` = ``(pos (P, 2), ang (P,))`` (row k for body ``ids[k]``; ``ang``
    empty: each body keeps its angle), written into the World's ``bodies`` record
    (:mod:`polycontact._kernels.world`), and the poses into ``store`` = ``(pos, ang,
    version)`` (each body's version counted up): body b's rows of ``xy`` become its base
    rows turned about its base centroid and moved so that the centroid goes to the
    position (``base`` = ``(bxy, cen)``: the rows as added and each body's centroid).
    ``tolerance`` = ``(rel, ulps)``: the default tolerance's terms
    (:func:`polycontact._kernels.tolerance.tolerance_for`). ``cells`` = ``(keys, slot,
    origin, left)``: the grid's table of cells, each body's slot in it and the grid's
    origin; ``left[k]`` (bool, (P,)) is set when body ``ids[k]``'s new box is out of its
    cell (empty ``left``: not looked at), the bodies :func:`polycontact._kernels.world.regrid`
    has to move. In parallel chunks (``chunks`` = 1: serial, no thread start). Returns
    the largest |coordinate| and the largest tolerance written."""
    n = ids.shape[0]
    if chunks == 1:
        return _pose_range(ids, poses, bodies, base, tolerance, store, cells, 0, n)
    big = np.zeros(chunks)
    emax = np.zeros(chunks)
    for c in prange(chunks):
        big[c], emax[c] = _pose_range(ids, poses, bodies, base, tolerance, store, cells,
                                      n * c // chunks, n * (c + 1) // chunks)
    return big.max(), emax.max()


@njit(cache=True, nogil=True)
def _checks_range(ids, poses, live, rad, owner, limit, k0, k1):
    """Whether the requests ``k0:k1`` of :func:`pose_checks` pass (and their marks)."""
    pos, ang = poses
    ok = True
    for k in range(k0, k1):
        b = ids[k]
        if b < 0 or b >= live.shape[0] or not live[b]:
            ok = False
            continue
        x = pos[k, 0]
        y = pos[k, 1]
        if ang.shape[0] and not math.isfinite(ang[k]):
            ok = False
        # (World._check_reach's test: position plus radius, with its margin)
        if not (abs(x) <= limit and abs(y) <= limit
                and max(abs(x), abs(y)) + rad[b] * (1.0 + 1e-9) <= limit):
            ok = False
        owner[b] = -(k + 1)
    return ok


@njit(cache=True, nogil=True)
def _owned(ids, owner, k0, k1):
    """Whether every body ``ids[k]``, k in ``k0:k1``, carries the mark of its own k."""
    for k in range(k0, k1):
        if owner[ids[k]] != -(k + 1):
            return False
    return True


@njit(cache=True, nogil=True, parallel=True)
def pose_checks(ids, poses, live, rad, owner, limit, chunks):
    """Whether the poses ``poses`` = ``(pos (P, 2), ang (P,) or empty)`` of the bodies
    ``ids`` can all be set at once: every id a live body (``live``, one entry per id),
    none twice, positions and angles finite, and each body's position plus its bounding
    radius ``rad`` within ``limit``. False when one of these may fail: the caller then
    checks the requests one by one (and says which). ``owner`` (one int64 per id, never
    negative before the call) is scratch: each listed body is marked with -(k + 1), its
    request's k, in parallel; a body listed twice then holds the mark of only one of
    its requests, which the second pass sees. In ``chunks`` parallel chunks."""
    n = ids.shape[0]
    if chunks == 1:
        return (_checks_range(ids, poses, live, rad, owner, limit, 0, n)
                and _owned(ids, owner, 0, n))
    ok = np.ones(chunks, np.bool_)
    for c in prange(chunks):
        ok[c] = _checks_range(ids, poses, live, rad, owner, limit, n * c // chunks,
                              n * (c + 1) // chunks)
    if not ok.all():
        return False
    for c in prange(chunks):
        ok[c] = _owned(ids, owner, n * c // chunks, n * (c + 1) // chunks)
    return ok.all()


@njit(cache=True, nogil=True)
def first_repeat(ids, stamp, mark):
    """The first k at which ``ids[k]`` repeats an earlier entry (-1 if none); ``stamp``
    (one entry per id, never equal to ``mark`` before the call) is set to ``mark`` for
    every id seen."""
    for k in range(ids.shape[0]):
        b = ids[k]
        if stamp[b] == mark:
            return k
        stamp[b] = mark
    return -1
