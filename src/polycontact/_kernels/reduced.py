"""Kernel: which edges of the convex sums can lie on the outline of their union (the
reduced convolution).

A contact of A and B without overlap of their interiors puts a vertex ``v`` of one body
on an edge ``e`` of the other, or vertex on vertex; the placements of A where that
happens form the segments ``v − e`` (up to the reference point: ``v + r`` for an edge
``r`` of the reflected A) of the *convolution* of the two boundaries. Most of those
segments overlap the interiors all along and are inside the entrance block: where
``v`` is a reflex vertex (its interior angle, above π, meets the half-plane behind
``e``), where ``e``'s direction lies outside ``v``'s turning cone (the wedge at ``v``
crosses ``e``'s line), or where ``e`` is a diagonal of a convex decomposition (its
points are interior to their body). What remains, the *reduced convolution*, holds the
outline of the entrance block and every exact fit and slide inside it (the placements
where the bodies touch without overlapping), so only the edges of the convex sums that
lie on it need be clipped against the other sums.

The convex pieces carry what this needs without the original rings: an edge of a piece
is a diagonal when another piece has it the other way; the boundary edges into and out
of a vertex give its turning cone. A vertex where that is not one edge in and one out
(a hole touching the outer loop, a seam the decomposition left) keeps every direction:
keeping an edge in excess only costs time.
"""

from __future__ import annotations

import numpy as np

from .jit import njit

#: Slack (a sine) of the cone test: a direction within this angle outside a vertex's
#: turning cone, or a vertex this close to straight, is kept (rounding of the edge
#: directions is near 1e-16 rad; an edge kept in excess only costs time).
CONE_SLACK = 1e-6

#: Kinds of a piece vertex (column 0 of :func:`piece_cones`).
REFLEX = 0.0
CONE = 1.0
ANY = 2.0


@njit(cache=True, nogil=True)
def _next_rows(starts):
    """Each row's successor within its piece."""
    n = starts[starts.shape[0] - 1]
    nxt = np.empty(n, np.int64)
    for k in range(starts.shape[0] - 1):
        for i in range(starts[k], starts[k + 1]):
            nxt[i] = i + 1 if i + 1 < starts[k + 1] else starts[k]
    return nxt


@njit(cache=True, nogil=True)
def _by_point(px, py):
    """The order of the points ``(px, py)`` by x, then y (stable)."""
    order = np.argsort(py, kind="mergesort")
    return order[np.argsort(px[order], kind="mergesort")]


@njit(cache=True, nogil=True)
def _first_at(px, py, order, x, y):
    """The first position in ``order`` (points sorted by :func:`_by_point`) of a point
    not before (x, y); the point there is (x, y) when some point is."""
    lo = 0
    hi = order.shape[0]
    while lo < hi:
        mid = (lo + hi) // 2
        k = order[mid]
        if px[k] < x or (px[k] == x and py[k] < y):
            lo = mid + 1
        else:
            hi = mid
    return lo


@njit(cache=True, nogil=True)
def piece_cones(xy, starts):
    """What the reduced convolution needs of convex CCW pieces ``(xy, starts)`` of one
    body: ``(boundary, cones)``.

    ``boundary[i]``: whether the piece edge from row i to the next row of its piece lies
    on the body's boundary (no other piece has it the other way). ``cones[i]`` = ``(kind,
    uix, uiy, uox, uoy)`` for the vertex at row i: ``CONE`` with the directions of the
    body's boundary edges into and out of it (a convex or straight vertex), ``REFLEX``
    (no contact there avoids overlap), or ``ANY`` (not one boundary edge in and one out:
    every direction kept).

    Examples
    --------
    An L of three unit squares: the cuts are diagonals, the inner corner (1, 1) reflex.

    >>> import numpy as np
    >>> xy = np.array([(0, 0), (1, 0), (1, 1), (0, 1), (1, 0), (2, 0), (2, 1), (1, 1),
    ...                (0, 1), (1, 1), (1, 2), (0, 2)], float)
    >>> bd, cones = piece_cones(xy, np.array([0, 4, 8, 12]))
    >>> bd.astype(int).tolist()
    [1, 0, 0, 1, 1, 1, 1, 0, 0, 1, 1, 1]
    >>> cones[:, 0].tolist()
    [1.0, 1.0, 0.0, 1.0, 1.0, 1.0, 1.0, 0.0, 1.0, 0.0, 1.0, 1.0]
    """
    n = xy.shape[0]
    nxt = _next_rows(starts)
    sx = xy[:, 0].copy()
    sy = xy[:, 1].copy()
    by_start = _by_point(sx, sy)
    boundary = np.ones(n, np.bool_)
    for i in range(n):
        j = nxt[i]
        # another piece's edge from this edge's end back to its start: a diagonal
        q = _first_at(sx, sy, by_start, xy[j, 0], xy[j, 1])
        while q < n and sx[by_start[q]] == xy[j, 0] and sy[by_start[q]] == xy[j, 1]:
            r = by_start[q]
            if xy[nxt[r], 0] == xy[i, 0] and xy[nxt[r], 1] == xy[i, 1]:
                boundary[i] = False
                break
            q += 1
    # the boundary edges by their end point, to find those into a vertex
    ex = np.empty(n)
    ey = np.empty(n)
    for i in range(n):
        ex[i] = xy[nxt[i], 0]
        ey[i] = xy[nxt[i], 1]
    by_end = _by_point(ex, ey)
    cones = np.empty((n, 5))
    for i in range(n):
        x, y = xy[i, 0], xy[i, 1]
        n_out, out_row = _boundary_at(sx, sy, by_start, x, y, boundary, xy, nxt)
        n_in, in_row = _boundary_at(ex, ey, by_end, x, y, boundary, xy, nxt)
        cones[i, 1:] = 0.0
        if n_out != 1 or n_in != 1:
            cones[i, 0] = ANY
            continue
        uix = x - xy[in_row, 0]
        uiy = y - xy[in_row, 1]
        uox = xy[nxt[out_row], 0] - x
        uoy = xy[nxt[out_row], 1] - y
        turn = uix * uoy - uiy * uox
        if turn < -CONE_SLACK * np.hypot(uix, uiy) * np.hypot(uox, uoy):
            cones[i, 0] = REFLEX
            continue
        cones[i, 0] = CONE
        cones[i, 1] = uix
        cones[i, 2] = uiy
        cones[i, 3] = uox
        cones[i, 4] = uoy
    return boundary, cones


@njit(cache=True, nogil=True)
def _boundary_at(px, py, order, x, y, boundary, xy, nxt):
    """``(count, row)``: how many distinct boundary edges have their point ``(px, py)``
    (their start or their end, sorted by ``order``) at (x, y), and the last one's row."""
    count = 0
    row = -1
    q = _first_at(px, py, order, x, y)
    while q < order.shape[0] and px[order[q]] == x and py[order[q]] == y:
        r = order[q]
        if boundary[r] and not (count == 1 and _same_edge(xy, nxt, r, row)):
            count += 1
            row = r
        q += 1
    return count, row


@njit(cache=True, nogil=True)
def _same_edge(xy, nxt, r, s):
    """Whether rows r and s start the same edge (the same two points)."""
    return (xy[r, 0] == xy[s, 0] and xy[r, 1] == xy[s, 1] and xy[nxt[r], 0] == xy[nxt[s], 0]
            and xy[nxt[r], 1] == xy[nxt[s], 1])


@njit(cache=True, nogil=True, inline="always")
def admits(cones, i, dx, dy):
    """Whether an edge of direction (dx, dy) of the other body, placed on the vertex at
    row i (:func:`piece_cones`), can touch it without overlap: within its turning cone
    (up to :data:`CONE_SLACK`)."""
    kind = cones[i, 0]
    if kind == ANY:
        return True
    if kind == REFLEX:
        return False
    uix, uiy, uox, uoy = cones[i, 1], cones[i, 2], cones[i, 3], cones[i, 4]
    ld = np.hypot(dx, dy)
    return (uix * dy - uiy * dx >= -CONE_SLACK * ld * np.hypot(uix, uiy)
            and dx * uoy - dy * uox >= -CONE_SLACK * ld * np.hypot(uox, uoy))
