"""Kernels: the closest points of two bodies' boundaries (all loops).

>>> import numpy as np
>>> sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
>>> st = np.array([0, 4])
>>> [float(v) for v in closest_pair(sq, st, sq + np.array([3.0, 0.5]), st)]
[2.0, 1.0, 0.5, 3.0, 0.5]
"""

from __future__ import annotations

import numpy as np

from .jit import njit
from .primitives import bbox, closest_on_segment, loop_index, next_vertex, norm, proper_crossing


@njit(cache=True, nogil=True)
def _segment_closest(px, py, qx, qy, rx, ry, sx, sy):
    """Distance between segments pq and rs, with a closest pair ``(x1, y1, x2, y2)``."""
    crosses, x, y = proper_crossing(px, py, qx, qy, rx, ry, sx, sy)
    if crosses:
        return 0.0, x, y, x, y
    best = np.inf
    x1 = y1 = x2 = y2 = 0.0
    for k in range(4):
        if k == 0:
            ux, uy, ax, ay, bx, by, on_first = px, py, rx, ry, sx, sy, True
        elif k == 1:
            ux, uy, ax, ay, bx, by, on_first = qx, qy, rx, ry, sx, sy, True
        elif k == 2:
            ux, uy, ax, ay, bx, by, on_first = rx, ry, px, py, qx, qy, False
        else:
            ux, uy, ax, ay, bx, by, on_first = sx, sy, px, py, qx, qy, False
        cx, cy, _ = closest_on_segment(ux, uy, ax, ay, bx, by)
        d = norm(ux - cx, uy - cy)
        if d < best:
            best = d
            if on_first:
                x1, y1, x2, y2 = ux, uy, cx, cy
            else:
                x1, y1, x2, y2 = cx, cy, ux, uy
    return best, x1, y1, x2, y2


@njit(cache=True, nogil=True)
def closest_pair(xa, sa, xb, sb):
    """Closest points of the boundaries of A and B: ``(distance, xa, ya, xb, yb)``.

    Edges of B are sorted by their smallest x; each edge of A only visits the edges of
    B whose boxes come within the best distance found so far (started from a vertex
    pair near the middle of B), so close pairs prune the rest.
    """
    na = sa[sa.shape[0] - 1]
    nb = sb[sb.shape[0] - 1]
    la = loop_index(sa, na)
    lb = loop_index(sb, nb)
    bx0, bx1, by0, by1 = bbox(xb, nb)
    # Upper bound first: the vertex of A nearest B's box centre, to its nearest B vertex.
    cx = 0.5 * (bx0 + bx1)
    cy = 0.5 * (by0 + by1)
    ia = 0
    dmin = np.inf
    for i in range(na):
        d = norm(xa[i, 0] - cx, xa[i, 1] - cy)
        if d < dmin:
            dmin = d
            ia = i
    best = np.inf
    r0 = r1 = r2 = r3 = 0.0
    for j in range(nb):
        d = norm(xa[ia, 0] - xb[j, 0], xa[ia, 1] - xb[j, 1])
        if d < best:
            best = d
            r0, r1, r2, r3 = xa[ia, 0], xa[ia, 1], xb[j, 0], xb[j, 1]
    bxmin = np.empty(nb)
    maxw = 0.0
    for j in range(nb):
        j1 = next_vertex(j, sb, lb)
        bxmin[j] = min(xb[j, 0], xb[j1, 0])
        maxw = max(maxw, abs(xb[j, 0] - xb[j1, 0]))
    order = np.argsort(bxmin)
    sorted_x = bxmin[order]
    for i in range(na):
        i1 = next_vertex(i, sa, la)
        px, py = xa[i, 0], xa[i, 1]
        qx, qy = xa[i1, 0], xa[i1, 1]
        x0 = min(px, qx)
        x1 = max(px, qx)
        y0 = min(py, qy)
        y1 = max(py, qy)
        if x0 > bx1 + best or x1 < bx0 - best or y0 > by1 + best or y1 < by0 - best:
            continue
        o = np.searchsorted(sorted_x, x0 - best - maxw)
        while o < nb:
            j = order[o]
            o += 1
            if sorted_x[o - 1] > x1 + best:
                break
            j1 = next_vertex(j, sb, lb)
            rx, ry = xb[j, 0], xb[j, 1]
            sx, sy = xb[j1, 0], xb[j1, 1]
            if max(rx, sx) < x0 - best:
                continue
            if min(ry, sy) > y1 + best or max(ry, sy) < y0 - best:
                continue
            d, c0, c1, c2, c3 = _segment_closest(px, py, qx, qy, rx, ry, sx, sy)
            if d < best:
                best = d
                r0, r1, r2, r3 = c0, c1, c2, c3
                if best == 0.0:
                    return best, r0, r1, r2, r3
    return best, r0, r1, r2, r3


@njit(cache=True, nogil=True)
def boundary_distance(xa, sa, xb, sb):
    """Minimum Euclidean distance between the boundaries of A and B (all loops).

    0 when the boundaries touch or cross. It is not the distance between the regions:
    a body deep inside another is at a positive boundary distance. See
    :func:`closest_pair` for the search.

    Examples
    --------
    >>> import numpy as np
    >>> sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    >>> st = np.array([0, 4])
    >>> float(boundary_distance(sq, st, sq + np.array([3.0, 0.0]), st))
    2.0
    """
    return closest_pair(xa, sa, xb, sb)[0]
