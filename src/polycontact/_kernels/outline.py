"""Kernels: the outline of a union of convex sums, assembled from the uncovered parts of
their edges.

:func:`edge_cover` keeps the parts of the sums' edges that lie in no other sum (the
outline, once each) and those in no other open sum shrunk by eps (where exact fits and
slides lie); :func:`assemble_rings` links the outline's parts into closed rings.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .minkowski import GRID, clip_edge, sum_index
from .primitives import append_part


@njit(cache=True, nogil=True)
def edge_cover(xy, starts, bb, fr, eps):
    """Uncovered parts of the sums' edges.

    Returns ``(outline, loose)``, both (M, 4) segments x0, y0, x1, y1:
    ``outline`` are the parts in no other sum's interior and on no seam, each kept once:
    the boundary of the union, oriented with the union on its left; ``loose`` are the
    parts in no other open sum shrunk by eps, where exact fits and slides lie, less
    those lying within a longer outline part.
    """
    k = starts.shape[0] - 1
    n_edges = xy.shape[0]
    outline = np.empty((4 * n_edges, 4))
    loose = np.empty((4 * n_edges, 4))
    no = 0
    nl = 0
    hint = -1
    # the grid over all sums
    gx0 = bb[:, 0].min()
    gy0 = bb[:, 1].min()
    h = max(bb[:, 2].max() - gx0, bb[:, 3].max() - gy0, 1e-300) / GRID
    sums = (xy, starts, bb, fr)
    index = sum_index(sums, gx0, gy0, h)
    lo1, hi1, lo0, hi0 = index[-4:]
    for p in range(k):
        s = starts[p]
        e = starts[p + 1]
        for i in range(s, e):
            j = i + 1 if i + 1 < e else s
            ax, ay = xy[i, 0], xy[i, 1]
            bx, by = xy[j, 0], xy[j, 1]
            if ax == bx and ay == by:
                continue
            n1, n0, hint = clip_edge(sums, index, p, ax, ay, bx, by, 0.0, 1.0, eps, hint)
            dx = bx - ax
            dy = by - ay
            for r in range(n0):
                outline, no = append_part(outline, no, ax, ay, dx, dy, lo0[r], hi0[r])
            # A loose part within a long outline part of the same edge lies on the
            # outline: no exact fit or slide there (those parts are seams or points).
            length = np.hypot(dx, dy)
            dt = 64.0 * eps / length
            for r in range(n1):
                on_outline = False
                for u in range(n0):
                    if ((hi0[u] - lo0[u]) * length > 128.0 * eps and lo0[u] - dt <= lo1[r]
                            and hi1[r] <= hi0[u] + dt):
                        on_outline = True
                        break
                if not on_outline:
                    loose, nl = append_part(loose, nl, ax, ay, dx, dy, lo1[r], hi1[r])
    return outline[:no], loose[:nl]


@njit(cache=True, nogil=True, inline="always")
def _start_near(seg, order, sx, oi, ex, ey, tol):
    """The first position from ``oi`` in ``order`` (the segments sorted by their
    start's x, ``sx``) of a segment starting within ``tol`` of (ex, ey), or -1."""
    while oi < order.shape[0] and sx[oi] <= ex + tol:
        c = order[oi]
        if abs(seg[c, 1] - ey) <= tol and np.hypot(seg[c, 0] - ex, seg[c, 1] - ey) <= tol:
            return oi
        oi += 1
    return -1


@njit(cache=True, nogil=True)
def _first_clockwise(seg, order, sx, lo, r, tol):
    """Of the segments starting within ``tol`` of segment r's end (``order``, ``sx``:
    the segments sorted by their start's x, from ``lo``), the one first clockwise from
    the way back along r (see :func:`assemble_rings`)."""
    ex = seg[r, 2]
    ey = seg[r, 3]
    back = np.arctan2(seg[r, 1] - ey, seg[r, 0] - ex)
    best = -1
    best_turn = np.inf
    oi = _start_near(seg, order, sx, lo, ex, ey, tol)
    while oi >= 0:
        c = order[oi]
        oi = _start_near(seg, order, sx, oi + 1, ex, ey, tol)
        ang = np.arctan2(seg[c, 3] - seg[c, 1], seg[c, 2] - seg[c, 0])
        turn = back - ang  # clockwise angle from the way back
        while turn <= 0.0:
            turn += 2.0 * np.pi
        while turn > 2.0 * np.pi:
            turn -= 2.0 * np.pi
        if turn < best_turn:
            best_turn = turn
            best = c
    return best


@njit(cache=True, nogil=True)
def assemble_rings(segs, tol):
    """Link outline segments (interior on the left) into closed rings.

    Segments shorter than ``tol`` are dropped; an end links to the start within ``tol``
    of it; where several starts are there (rings touching at a point), the one first
    clockwise from the way back keeps each interior sector in its own ring. A ring that
    passes twice through one point is split there. Returns ``(ok, xy, starts)``;
    ``ok`` is False when some end finds no start, or a start is claimed twice.
    """
    keep = np.empty(segs.shape[0], np.int64)
    n = 0
    for r in range(segs.shape[0]):
        if np.hypot(segs[r, 2] - segs[r, 0], segs[r, 3] - segs[r, 1]) > tol:
            keep[n] = r
            n += 1
    seg = segs[keep[:n]]
    order = np.argsort(seg[:, 0])
    sx = seg[order, 0]
    nxt = np.full(n, -1, np.int64)
    taken = np.zeros(n, np.bool_)
    for r in range(n):
        ex = seg[r, 2]
        ey = seg[r, 3]
        best = -1
        lo = np.searchsorted(sx, ex - tol)
        # one start there (the common case): it, without comparing turns
        starts_there = 0
        oi = _start_near(seg, order, sx, lo, ex, ey, tol)
        while oi >= 0:
            starts_there += 1
            best = order[oi]
            oi = _start_near(seg, order, sx, oi + 1, ex, ey, tol)
        if starts_there > 1:
            best = _first_clockwise(seg, order, sx, lo, r, tol)
        if best < 0 or taken[best]:
            return False, np.empty((0, 2)), np.zeros(1, np.int64)
        taken[best] = True
        nxt[r] = best
    out = np.empty((n, 2))
    rs = np.empty(n + 1, np.int64)
    rs[0] = 0
    w = 0
    nr = 0
    seen = np.zeros(n, np.bool_)
    for r0 in range(n):
        if seen[r0]:
            continue
        r = r0
        while not seen[r]:
            seen[r] = True
            out[w, 0] = seg[r, 0]
            out[w, 1] = seg[r, 1]
            w += 1
            r = nxt[r]
        if r != r0:
            return False, np.empty((0, 2)), np.zeros(1, np.int64)
        nr += 1
        rs[nr] = w
    return True, out[:w], _split_pinched(out[:w], rs[: nr + 1], tol)


@njit(cache=True, nogil=True)
def _split_pinched(xy, starts, tol):
    """Ring starts after cutting every ring at points it passes twice (in place)."""
    new_starts = [0]
    buf = np.empty_like(xy)
    w = 0
    for k in range(starts.shape[0] - 1):
        s = starts[k]
        e = starts[k + 1]
        stack = np.empty(e - s, np.int64)
        depth = 0
        for i in range(s, e):
            # a point met before closes the loop made since then
            cut = -1
            for d in range(depth):
                v = stack[d]
                if abs(xy[v, 0] - xy[i, 0]) <= tol and abs(xy[v, 1] - xy[i, 1]) <= tol:
                    cut = d
                    break
            if cut >= 0:
                for d in range(cut, depth):
                    buf[w] = xy[stack[d]]
                    w += 1
                new_starts.append(w)
                depth = cut
            stack[depth] = i
            depth += 1
        for d in range(depth):
            buf[w] = xy[stack[d]]
            w += 1
        new_starts.append(w)
    xy[:w] = buf[:w]
    st = np.empty(len(new_starts), np.int64)
    for r in range(len(new_starts)):
        st[r] = new_starts[r]
    return st


@njit(cache=True, nogil=True)
def ring_stats(xy, starts):
    """Each loop's signed area and length: ``(area, length)``, (R,) each."""
    n = starts.shape[0] - 1
    area = np.zeros(n)
    length = np.zeros(n)
    for k in range(n):
        s = starts[k]
        e = starts[k + 1]
        ox = xy[s, 0]  # relative to the first vertex: no cancellation far from the origin
        oy = xy[s, 1]
        for i in range(s, e):
            j = i + 1 if i + 1 < e else s
            area[k] += 0.5 * (
                (xy[i, 0] - ox) * (xy[j, 1] - oy) - (xy[j, 0] - ox) * (xy[i, 1] - oy)
            )
            length[k] += np.hypot(xy[j, 0] - xy[i, 0], xy[j, 1] - xy[i, 1])
    return area, length


@njit(cache=True, nogil=True)
def closed_loops(xy, starts):
    """The packed loops with each loop's first point repeated at its end."""
    n = starts.shape[0] - 1
    out = np.empty((xy.shape[0] + n, 2))
    st = np.empty(n + 1, np.int64)
    st[0] = 0
    w = 0
    for k in range(n):
        for i in range(starts[k], starts[k + 1]):
            out[w] = xy[i]
            w += 1
        out[w] = xy[starts[k]]
        w += 1
        st[k + 1] = w
    return out, st
