"""Kernel: find the first defect that makes a set of loops an invalid polygon, exactly.

Every decision is exact for the float64 coordinates given (:mod:`.predicates`): two
features of a polygon are defects only when they truly meet, however close they come
otherwise, and the answer does not depend on where the polygon lies or on its scale.
"""

from __future__ import annotations

import numpy as np

from .jit import njit
from .predicates import collinear_overlap, orientation, segments_meet


#: Defect codes returned by :func:`first_defect`.
OK = 0
SELF_INTERSECTION = 1  # two edges of one loop meet away from their shared vertex
LOOPS_CROSS = 2  # edges of two different loops cross or overlap
SPIKE = 3  # two consecutive edges fold back on each other
ZERO_AREA = 4  # every vertex of a loop lies on one line


@njit(cache=True, nogil=True)
def _same_direction(px, py, qx, qy, rx, ry):
    """Collinear p, q, r (p != q != r): r lies on the same side of q as p (the edges
    p -> q -> r fold back). Parallel vectors point the same way exactly when the signs
    of their coordinates agree."""
    return (_side(px, qx) == _side(rx, qx)) and (_side(py, qy) == _side(ry, qy))


@njit(cache=True, nogil=True, inline="always")
def _side(a, b):
    """-1, 0 or 1 as ``a`` is below, at or above ``b``."""
    return 1 if a > b else (-1 if a < b else 0)


@njit(cache=True, nogil=True)
def _collinear_loop(xy, s, e):
    """Every vertex of the loop in rows ``s:e`` lies on the line through its first
    vertex and its farthest one."""
    ax, ay = xy[s, 0], xy[s, 1]
    far = s
    best = -1.0
    for i in range(s, e):
        d = max(abs(xy[i, 0] - ax), abs(xy[i, 1] - ay))
        if d > best:
            best = d
            far = i
    bx, by = xy[far, 0], xy[far, 1]
    for i in range(s + 1, e):
        if orientation(ax, ay, bx, by, xy[i, 0], xy[i, 1]) != 0:
            return False
    return True


@njit(cache=True, nogil=True)
def first_defect(xy, starts):
    """First pair of edges that makes the loops invalid, decided exactly.

    Returns ``(code, loop_i, edge_i, loop_j, edge_j, x, y)`` with ``code`` one of
    ``OK``, ``SELF_INTERSECTION``, ``LOOPS_CROSS``, ``SPIKE``, ``ZERO_AREA`` (then
    ``loop_i`` is the loop). Edges are swept in order of their smallest x, so the cost is
    O(E log E + pairs whose boxes overlap). Two loops may touch at isolated points
    (OGC-valid); one loop may touch itself nowhere, and no two consecutive edges may
    overlap (fold back). ``(x, y)`` is where (the touching vertex, or a crossing point
    rounded).
    """
    n_loops = starts.shape[0] - 1
    for k in range(n_loops):
        if _collinear_loop(xy, starts[k], starts[k + 1]):
            return ZERO_AREA, k, 0, k, 0, xy[starts[k], 0], xy[starts[k], 1]
    n_edges = xy.shape[0]
    loop_of = np.empty(n_edges, np.int64)
    xmin = np.empty(n_edges)
    xmax = np.empty(n_edges)
    for k in range(n_loops):
        s = starts[k]
        e = starts[k + 1]
        for i in range(s, e):
            j = i + 1 if i + 1 < e else s
            loop_of[i] = k
            xmin[i] = min(xy[i, 0], xy[j, 0])
            xmax[i] = max(xy[i, 0], xy[j, 0])
    order = np.argsort(xmin)
    for oi in range(n_edges):
        i = order[oi]
        k = loop_of[i]
        s = starts[k]
        e = starts[k + 1]
        i1 = i + 1 if i + 1 < e else s
        ax, ay = xy[i, 0], xy[i, 1]
        bx, by = xy[i1, 0], xy[i1, 1]
        for oj in range(oi + 1, n_edges):
            j = order[oj]
            if xmin[j] > xmax[i]:
                break
            kj = loop_of[j]
            sj = starts[kj]
            ej = starts[kj + 1]
            j1 = j + 1 if j + 1 < ej else sj
            cx, cy = xy[j, 0], xy[j, 1]
            dx, dy = xy[j1, 0], xy[j1, 1]
            if min(ay, by) > max(cy, dy) or min(cy, dy) > max(ay, by):
                continue
            if kj == k and (j == i1 or i == j1):
                # Consecutive edges p -> q -> r share q; they are bad only if they fold
                # back: r on the same side of q as p, on the line through them.
                if j == i1:
                    px, py, qx, qy, rx, ry = ax, ay, bx, by, dx, dy
                else:
                    px, py, qx, qy, rx, ry = cx, cy, dx, dy, bx, by
                if not _same_direction(px, py, qx, qy, rx, ry):
                    continue
                o = orientation(px, py, qx, qy, rx, ry)
                if o == 0:
                    first = i if j == i1 else j
                    second = j if j == i1 else i
                    return SPIKE, k, first - s, k, second - s, qx, qy
                continue
            kind, x, y = segments_meet(ax, ay, bx, by, cx, cy, dx, dy)
            if kind == 0:
                continue
            if kj == k:
                a_, b_ = (i, j) if i < j else (j, i)
                return SELF_INTERSECTION, k, a_ - s, k, b_ - s, x, y
            # Different loops may touch at a single point, but not cross or overlap.
            if kind == 2 or _overlap(ax, ay, bx, by, cx, cy, dx, dy):
                if k < kj:
                    return LOOPS_CROSS, k, i - s, kj, j - sj, x, y
                return LOOPS_CROSS, kj, j - sj, k, i - s, x, y
    return OK, -1, -1, -1, -1, 0.0, 0.0


@njit(cache=True, nogil=True)
def _overlap(ax, ay, bx, by, cx, cy, dx, dy):
    """Touching segments ab and cd share a piece of positive length (exact)."""
    if orientation(ax, ay, bx, by, cx, cy) != 0 or orientation(ax, ay, bx, by, dx, dy) != 0:
        return False
    return collinear_overlap(ax, ay, bx, by, cx, cy, dx, dy)


@njit(cache=True, nogil=True)
def loop_signs(xy, starts):
    """The exact orientation of each loop (1 counter-clockwise, -1 clockwise), for
    loops that :func:`first_defect` found valid: the turn at the loop's lowest vertex
    (smallest y, then smallest x), which is a vertex of its convex hull and has no
    straight angle there (the loop would fold back)."""
    n_loops = starts.shape[0] - 1
    out = np.empty(n_loops, np.int64)
    for k in range(n_loops):
        s = starts[k]
        e = starts[k + 1]
        m = s
        for i in range(s + 1, e):
            if xy[i, 1] < xy[m, 1] or (xy[i, 1] == xy[m, 1] and xy[i, 0] < xy[m, 0]):
                m = i
        h = m - 1 if m > s else e - 1
        j = m + 1 if m + 1 < e else s
        out[k] = orientation(xy[h, 0], xy[h, 1], xy[m, 0], xy[m, 1], xy[j, 0], xy[j, 1])
    return out
