"""Kernel: find the first defect that makes a set of loops an invalid polygon."""

from __future__ import annotations

import numpy as np

from .jit import njit
from .primitives import orient, point_segment_distance, segment_meet


#: Defect codes returned by :func:`first_defect`.
OK = 0
SELF_INTERSECTION = 1  # two edges of one loop meet away from their shared vertex
LOOPS_CROSS = 2  # edges of two different loops cross or overlap
SPIKE = 3  # two consecutive edges fold back on each other


@njit(cache=True, nogil=True)
def first_defect(xy, starts, eps):
    """First pair of edges that makes the loops invalid.

    Returns ``(code, loop_i, edge_i, loop_j, edge_j, x, y)`` with ``code`` one of
    ``OK``, ``SELF_INTERSECTION``, ``LOOPS_CROSS``, ``SPIKE``. Edges are swept in order
    of their smallest x, so the cost is O(E log E + pairs whose x-ranges overlap).
    Two loops may touch at isolated points (OGC-valid); one loop may not touch itself.
    """
    n_loops = starts.shape[0] - 1
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
            if xmin[j] > xmax[i] + eps:
                break
            kj = loop_of[j]
            sj = starts[kj]
            ej = starts[kj + 1]
            j1 = j + 1 if j + 1 < ej else sj
            cx, cy = xy[j, 0], xy[j, 1]
            dx, dy = xy[j1, 0], xy[j1, 1]
            if min(ay, by) > max(cy, dy) + eps or min(cy, dy) > max(ay, by) + eps:
                continue
            if kj == k and (j == i1 or i == j1):
                # Consecutive edges share a vertex; they are bad only if they fold back.
                if j == i1:
                    px, py, qx, qy, rx, ry = ax, ay, bx, by, dx, dy
                else:
                    px, py, qx, qy, rx, ry = cx, cy, dx, dy, bx, by
                # p -> q -> r folds back if r lies on segment pq or p lies on qr.
                if point_segment_distance(rx, ry, px, py, qx, qy) <= eps or (
                    point_segment_distance(px, py, qx, qy, rx, ry) <= eps
                ):
                    first = i if j == i1 else j
                    second = j if j == i1 else i
                    return SPIKE, k, first - s, k, second - s, qx, qy
                continue
            meets, x, y = segment_meet(ax, ay, bx, by, cx, cy, dx, dy, eps)
            if not meets:
                continue
            if kj == k:
                a_, b_ = (i, j) if i < j else (j, i)
                return SELF_INTERSECTION, k, a_ - s, k, b_ - s, x, y
            # Different loops may touch at a single point, but not cross or overlap.
            if _loops_cross_here(ax, ay, bx, by, cx, cy, dx, dy, eps):
                if k < kj or (k == kj and i < j):
                    return LOOPS_CROSS, k, i - s, kj, j - sj, x, y
                return LOOPS_CROSS, kj, j - sj, k, i - s, x, y
    return OK, -1, -1, -1, -1, 0.0, 0.0


@njit(cache=True, nogil=True)
def _loops_cross_here(ax, ay, bx, by, cx, cy, dx, dy, eps):
    """Segments of two loops meet: is it more than a touch at one point?

    A proper crossing, or a collinear overlap of positive length, is refused. A touch
    (an endpoint on the other segment) is accepted here; whether the loops then cross
    at that vertex is decided by the containment test of the caller.
    """
    o1 = orient(ax, ay, bx, by, cx, cy)
    o2 = orient(ax, ay, bx, by, dx, dy)
    o3 = orient(cx, cy, dx, dy, ax, ay)
    o4 = orient(cx, cy, dx, dy, bx, by)
    la = np.hypot(bx - ax, by - ay)
    lc = np.hypot(dx - cx, dy - cy)
    t1 = eps * la
    t3 = eps * lc
    if ((o1 > t1 and o2 < -t1) or (o1 < -t1 and o2 > t1)) and (
        (o3 > t3 and o4 < -t3) or (o3 < -t3 and o4 > t3)
    ):
        return True
    # collinear overlap of positive length
    if abs(o1) <= t1 and abs(o2) <= t1 and la > 0.0:
        ux = (bx - ax) / la
        uy = (by - ay) / la
        s0 = (cx - ax) * ux + (cy - ay) * uy
        s1 = (dx - ax) * ux + (dy - ay) * uy
        lo = max(0.0, min(s0, s1))
        hi = min(la, max(s0, s1))
        if hi - lo > eps:
            return True
    return False
