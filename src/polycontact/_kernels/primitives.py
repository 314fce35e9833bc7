"""Kernels: the geometric primitives every other kernel builds on.

Orientation, norms and bounding boxes; the point of a segment nearest a point, and
segment meets; the point of a segment nearest the origin (the depth kernels measure
translations from it); a loop's next and previous vertex; growing a row buffer. Each is
the one copy the kernels share.

>>> orient(0.0, 0.0, 1.0, 0.0, 0.0, 1.0), point_segment_distance(0.0, 1.0, -1.0, 0.0, 1.0, 0.0)
(1.0, 1.0)
"""

from __future__ import annotations

import numpy as np

from .jit import njit


@njit(cache=True, nogil=True)
def orient(ax, ay, bx, by, cx, cy):
    """Twice the signed area of triangle abc: positive when c is left of ab."""
    return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)


@njit(cache=True, nogil=True)
def norm(x, y):
    """The length of (x, y)."""
    return np.sqrt(x * x + y * y)


@njit(cache=True, nogil=True)
def bbox(xy, n):
    """``(xmin, xmax, ymin, ymax)`` of the first n rows of ``xy``."""
    x0 = np.inf
    x1 = -np.inf
    y0 = np.inf
    y1 = -np.inf
    for i in range(n):
        x = xy[i, 0]
        y = xy[i, 1]
        x0 = min(x0, x)
        x1 = max(x1, x)
        y0 = min(y0, y)
        y1 = max(y1, y)
    return x0, x1, y0, y1


@njit(cache=True, nogil=True)
def outward_normal(ax, ay, bx, by):
    """``(length, nx, ny)`` of edge ab and its unit outward normal (the interior is on
    the edge's left, so the normal points right); the normal is (0, 0) for a point."""
    ex = bx - ax
    ey = by - ay
    ln = np.sqrt(ex * ex + ey * ey)
    if ln == 0.0:
        return 0.0, 0.0, 0.0
    return ln, ey / ln, -ex / ln


@njit(cache=True, nogil=True)
def closest_on_segment(px, py, ax, ay, bx, by):
    """``(qx, qy, d2)``: the point q of the closed segment ab nearest p, and |p − q|²."""
    dx = bx - ax
    dy = by - ay
    den = dx * dx + dy * dy
    t = 0.0
    if den > 0.0:
        t = ((px - ax) * dx + (py - ay) * dy) / den
        t = min(1.0, max(0.0, t))
    qx = ax + t * dx
    qy = ay + t * dy
    return qx, qy, (px - qx) * (px - qx) + (py - qy) * (py - qy)


@njit(cache=True, nogil=True)
def point_segment_distance(px, py, ax, ay, bx, by):
    """The distance from p to the closed segment ab."""
    return np.sqrt(closest_on_segment(px, py, ax, ay, bx, by)[2])


@njit(cache=True, nogil=True, inline="always")
def point_segment_sq(px, py, ax, ay, bx, by):
    """Squared distance from (px, py) to the segment from (ax, ay) to (bx, by)."""
    ux = bx - ax
    uy = by - ay
    wx = px - ax
    wy = py - ay
    den = ux * ux + uy * uy
    t = (wx * ux + wy * uy) / den if den > 0.0 else 0.0
    t = min(max(t, 0.0), 1.0)
    dx = wx - t * ux
    dy = wy - t * uy
    return dx * dx + dy * dy


@njit(cache=True, nogil=True)
def segment_meet(ax, ay, bx, by, cx, cy, dx, dy, eps):
    """Whether closed segments ab and cd meet (within eps); returns (meets, x, y).

    A proper crossing returns its crossing point; a touch returns the touching endpoint.
    """
    for px, py, sx, sy, tx, ty in (
        (cx, cy, ax, ay, bx, by),
        (dx, dy, ax, ay, bx, by),
        (ax, ay, cx, cy, dx, dy),
        (bx, by, cx, cy, dx, dy),
    ):
        if point_segment_distance(px, py, sx, sy, tx, ty) <= eps:
            return True, px, py
    return proper_crossing(ax, ay, bx, by, cx, cy, dx, dy)


@njit(cache=True, nogil=True)
def proper_crossing(ax, ay, bx, by, cx, cy, dx, dy):
    """``(crosses, x, y)``: whether segments ab and cd cross properly (the ends of each
    strictly on both sides of the other's line), and where (0, 0 when they do not)."""
    o1 = orient(ax, ay, bx, by, cx, cy)
    o2 = orient(ax, ay, bx, by, dx, dy)
    o3 = orient(cx, cy, dx, dy, ax, ay)
    o4 = orient(cx, cy, dx, dy, bx, by)
    if ((o1 > 0.0 and o2 < 0.0) or (o1 < 0.0 and o2 > 0.0)) and (
        (o3 > 0.0 and o4 < 0.0) or (o3 < 0.0 and o4 > 0.0)
    ):
        s = o1 / (o1 - o2)
        return True, cx + s * (dx - cx), cy + s * (dy - cy)
    return False, 0.0, 0.0


@njit(cache=True, nogil=True, inline="always")
def origin_foot(ax, ay, bx, by):
    """Point of segment ab nearest the origin, and its distance."""
    dx = bx - ax
    dy = by - ay
    den = dx * dx + dy * dy
    t = 0.0
    if den > 0.0:
        t = min(1.0, max(0.0, -(ax * dx + ay * dy) / den))
    px = ax + t * dx
    py = ay + t * dy
    return px, py, norm(px, py)


@njit(cache=True, nogil=True, inline="always")
def origin_distance_sq(ax, ay, bx, by):
    """Squared distance from the origin to segment ab."""
    dx = bx - ax
    dy = by - ay
    s = -(ax * dx + ay * dy)
    if s <= 0.0:
        return ax * ax + ay * ay
    den = dx * dx + dy * dy
    if s >= den:
        return bx * bx + by * by
    c = (ax * dy - ay * dx) / np.sqrt(den)  # (squared after the division: no overflow)
    return c * c


@njit(cache=True, nogil=True, inline="always")
def origin_distance_sq_framed(ax, ay, bx, by, ux, uy, c):
    """Squared distance from the origin to segment ab, of unit direction (ux, uy) and
    line offset c (:func:`polycontact._kernels.minkowski.frames`: the origin lies at -c
    from the line): no division."""
    s = -(ax * ux + ay * uy)  # where the foot of the line falls, from a towards b
    if s <= 0.0:
        return ax * ax + ay * ay
    if s >= (bx - ax) * ux + (by - ay) * uy:
        return bx * bx + by * by
    return c * c


@njit(cache=True, nogil=True, inline="always")
def loop_next(i, starts, k):
    """The vertex after vertex i of loop k of packed loops ``starts``."""
    return i + 1 if i + 1 < starts[k + 1] else starts[k]


@njit(cache=True, nogil=True, inline="always")
def loop_prev(i, starts, k):
    """The vertex before vertex i of loop k of packed loops ``starts``."""
    return i - 1 if i > starts[k] else starts[k + 1] - 1


# (no reference counting: the pair kernels that call it pass their buffers)
@njit(cache=True, nogil=True, _nrt=False, inline="always")
def edge_rows(x, starts, e, nxt):
    """Each edge's direction, length and box, written into ``e``: rows ``(gx, gy,
    length, xmin, xmax, ymin, ymax)`` of edge i, from vertex i to the next of its loop,
    whose row goes to ``nxt[i]``; the table the kernels of a pair share instead of each
    recomputing it.

    >>> import numpy as np
    >>> e, nxt = np.empty((3, 7)), np.empty(3, np.int64)
    >>> edge_rows(np.array([[0.0, 0.0], [4.0, 0.0], [0.0, 3.0]]), np.array([0, 3]), e, nxt)
    >>> e[1].tolist(), nxt.tolist()
    ([-4.0, 3.0, 5.0, 0.0, 4.0, 0.0, 3.0], [1, 2, 0])
    """
    for k in range(starts.shape[0] - 1):
        for i in range(starts[k], starts[k + 1]):
            j = loop_next(i, starts, k)
            nxt[i] = j
            ax = x[i, 0]
            ay = x[i, 1]
            bx = x[j, 0]
            by = x[j, 1]
            gx = bx - ax
            gy = by - ay
            e[i, 0] = gx
            e[i, 1] = gy
            e[i, 2] = np.sqrt(gx * gx + gy * gy)
            e[i, 3] = min(ax, bx)
            e[i, 4] = max(ax, bx)
            e[i, 5] = min(ay, by)
            e[i, 6] = max(ay, by)


@njit(cache=True, nogil=True)
def next_vertex(i, starts, loop_of):
    """The vertex after vertex i in its loop (``loop_of``: :func:`loop_index`)."""
    return loop_next(i, starts, loop_of[i])


@njit(cache=True, nogil=True)
def loop_index(starts, n):
    """The loop of each of the n vertices of packed loops ``starts``."""
    loop_of = np.empty(n, np.int64)
    for k in range(starts.shape[0] - 1):
        for i in range(starts[k], starts[k + 1]):
            loop_of[i] = k
    return loop_of


@njit(cache=True, nogil=True)
def grow_rows(arr):
    """A float64 copy of the 2-d ``arr`` with twice its rows and four more (the new
    rows uninitialised), for buffers that fill as they go."""
    out = np.empty((2 * arr.shape[0] + 4, arr.shape[1]))
    out[: arr.shape[0]] = arr
    return out


@njit(cache=True, nogil=True)
def append_part(rows, n, ax, ay, dx, dy, lo, hi):
    """Write the part [lo, hi] of the edge from (ax, ay) along (dx, dy) into row n of
    ``rows`` (grown when full) as ``(x0, y0, x1, y1)``: ``(rows, n + 1)``."""
    if n == rows.shape[0]:
        rows = grow_rows(rows)
    rows[n, 0] = ax + lo * dx
    rows[n, 1] = ay + lo * dy
    rows[n, 2] = ax + hi * dx
    rows[n, 3] = ay + hi * dy
    return rows, n + 1
