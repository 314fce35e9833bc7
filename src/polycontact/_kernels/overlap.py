"""Kernel: the area and centroid of the intersection of two polygonal regions.

The boundary of A ∩ B is made of the parts of A's boundary inside B and of B's boundary
inside A (holes included: a hole's loop is part of its body's boundary). By Green's
theorem the area and the first moments of the intersection are sums over those parts:
for a piece from u to v (coordinates taken from a local origin),

    2 area += u × v,   6 area · centroid += (u + v) (u × v),

the fan of triangles from the origin, whose signed sum over closed chains is the region
they enclose. Each edge is cut where it properly crosses the other boundary; its pieces
are inside or outside the other body alternately, starting from the status of its first
vertex (outside when it lies outside the other body's box, else a point-in-polygon
test), so the walk along a loop costs one test at most. Edges with a vertex within the
tolerance of the other boundary (touches, shared and collinear pieces) are cut at those
vertices too, and each piece is classified by its midpoint instead: inside, outside, or
on the other boundary. A piece on the other boundary belongs to the intersection's
boundary when both interiors lie on the same side of it (the edges run the same way);
it is counted once, from A's side, and never from B's. Only edges whose boxes meet the
common window of the two bodies' boxes are examined; their boxes come from each body's
edge table (:func:`polycontact._kernels.primitives.edge_rows`), which the caller may
share with the other kernels of the pair (:func:`overlap_of_tables`).

The area is exact up to the tolerance band: pieces within ``eps`` of the other boundary
are classified by the tolerance, an error of at most ``eps`` times their length.
"""

from __future__ import annotations

import numpy as np

from .jit import njit
from .primitives import bbox, edge_rows, loop_next, orient, point_segment_distance


@njit(cache=True, nogil=True, _nrt=False)
def where(px, py, x, starts, eps):
    """1 when (px, py) lies inside the region ``(x, starts)`` by more than ``eps``, 0
    within ``eps`` of its boundary, -1 outside (crossing number over every loop).

    >>> import numpy as np
    >>> sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    >>> st = np.array([0, 4])
    >>> [int(where(px, 0.5, sq, st, 1e-9)) for px in (0.5, 1.0, 2.0)]
    [1, 0, -1]
    """
    inside = False
    for k in range(starts.shape[0] - 1):
        for i in range(starts[k], starts[k + 1]):
            j = loop_next(i, starts, k)
            ax, ay, bx, by = x[i, 0], x[i, 1], x[j, 0], x[j, 1]
            if point_segment_distance(px, py, ax, ay, bx, by) <= eps:
                return 0
            if (ay > py) != (by > py):
                if px < ax + (py - ay) * (bx - ax) / (by - ay):
                    inside = not inside
    return 1 if inside else -1


@njit(cache=True, nogil=True, _nrt=False)
def _on_same_way(px, py, ux, uy, x, starts, eps):
    """Whether an edge of ``(x, starts)`` within ``eps`` of (px, py) runs the way of
    (ux, uy) (interiors on the same side)."""
    for k in range(starts.shape[0] - 1):
        for i in range(starts[k], starts[k + 1]):
            j = loop_next(i, starts, k)
            ax, ay, bx, by = x[i, 0], x[i, 1], x[j, 0], x[j, 1]
            if point_segment_distance(px, py, ax, ay, bx, by) <= eps:
                if (bx - ax) * ux + (by - ay) * uy > 0.0:
                    return True
    return False


@njit(cache=True, nogil=True, inline="always")
def _green(ux, uy, vx, vy, ox, oy, acc):
    """Add the piece u → v (from the origin (ox, oy)) to ``acc`` = (2 area, 6 area cx,
    6 area cy) relative to the origin; the first piece's midpoint goes to ``acc[4:6]``
    (``acc[3]`` set to 1: a point of the intersection's boundary)."""
    if acc[3] == 0.0:
        acc[3] = 1.0
        acc[4] = 0.5 * (ux + vx)
        acc[5] = 0.5 * (uy + vy)
    ax = ux - ox
    ay = uy - oy
    bx = vx - ox
    by = vy - oy
    c = ax * by - bx * ay
    acc[0] += c
    acc[1] += (ax + bx) * c
    acc[2] += (ay + by) * c


@njit(cache=True, nogil=True, _nrt=False)
def _sorted(ts, n):
    """Sort ``ts[:n]`` in place (a few values)."""
    for q in range(1, n):
        v = ts[q]
        r = q
        while r > 0 and ts[r - 1] > v:
            ts[r] = ts[r - 1]
            r -= 1
        ts[r] = v


@njit(cache=True, nogil=True, _nrt=False)
def _pieces_by_midpoint(edge, x, starts, eps, ts, n, first_side, ox, oy, acc):
    """Add the pieces of edge p → q (``edge`` = ``(px, py, qx, qy)``) between the sorted
    cut parameters ``ts[:n]`` (0 and 1 included) that lie inside the other region
    ``(x, starts)``, classified by their midpoints; a piece on its boundary counts when
    ``first_side`` (A's pass) and an edge there runs the same way."""
    px, py, qx, qy = edge
    dx = qx - px
    dy = qy - py
    for q in range(n - 1):
        t0 = ts[q]
        t1 = ts[q + 1]
        if not t1 > t0:
            continue
        mx = px + 0.5 * (t0 + t1) * dx
        my = py + 0.5 * (t0 + t1) * dy
        w = where(mx, my, x, starts, eps)
        if w == 0:
            if not (first_side and _on_same_way(mx, my, dx, dy, x, starts, eps)):
                continue
        elif w < 0:
            continue
        _green(px + t0 * dx, py + t0 * dy, px + t1 * dx, py + t1 * dy, ox, oy, acc)


@njit(cache=True, nogil=True, _nrt=False)
def _near_cuts(px, py, qx, qy, x, starts, eps, ts, n):
    """Append to ``ts`` (from n) the parameters along p → q of the other region's
    vertices within ``eps`` of the edge, and of the proper crossings of its edges;
    returns the new count."""
    dx = qx - px
    dy = qy - py
    ln2 = dx * dx + dy * dy
    ex0 = min(px, qx) - eps
    ex1 = max(px, qx) + eps
    ey0 = min(py, qy) - eps
    ey1 = max(py, qy) + eps
    for k in range(starts.shape[0] - 1):
        for i in range(starts[k], starts[k + 1]):
            ax, ay = x[i, 0], x[i, 1]
            if (ex0 <= ax <= ex1 and ey0 <= ay <= ey1
                    and point_segment_distance(ax, ay, px, py, qx, qy) <= eps):
                ts[n] = min(1.0, max(0.0, ((ax - px) * dx + (ay - py) * dy) / ln2))
                n += 1
            j = loop_next(i, starts, k)
            bx, by = x[j, 0], x[j, 1]
            if (max(ax, bx) < ex0 or min(ax, bx) > ex1 or max(ay, by) < ey0
                    or min(ay, by) > ey1):
                continue
            o1 = orient(px, py, qx, qy, ax, ay)
            o2 = orient(px, py, qx, qy, bx, by)
            o3 = orient(ax, ay, bx, by, px, py)
            o4 = orient(ax, ay, bx, by, qx, qy)
            if (o1 > 0.0) != (o2 > 0.0) and (o3 > 0.0) != (o4 > 0.0) and o3 != o4:
                ts[n] = min(1.0, max(0.0, o3 / (o3 - o4)))
                n += 1
    return n


@njit(cache=True, nogil=True, inline="always")
def _edge_box_meets(e, i, wx0, wx1, wy0, wy1):
    """Whether the box of edge i (row i of an edge table) meets the window."""
    return not (e[i, 4] < wx0 or e[i, 3] > wx1 or e[i, 6] < wy0 or e[i, 5] > wy1)


@njit(cache=True, nogil=True, _nrt=False, inline="always")
def _crossings(a, b, eps, window, deg_a, deg_b, cross, boxes, ids):
    """Proper crossings of A's and B's edges in the ``window`` (``(wx0, wx1, wy0,
    wy1)``): rows of ``cross`` = ``(edge of A, edge of B, t along A's edge, t along B's
    edge, x, y)``; an edge with an end within ``eps`` of an edge of the other body is
    marked in ``deg_a``/``deg_b`` (its pieces are classified by midpoints). ``a``, ``b``:
    the bodies as :func:`overlap_of_tables` takes them. ``boxes`` (rows of 4) and ``ids``
    (one per vertex of B) are scratch: B's edges in the window. Returns the count, or -1
    when ``cross`` is too short."""
    xa, _, ea, nxa, _ = a
    xb, _, eb, nxb, _ = b
    wx0, wx1, wy0, wy1 = window
    m = 0  # (B's edges in the window listed without branches: a row written for each)
    for f in range(xb.shape[0]):
        boxes[m, 0] = eb[f, 3] - eps
        boxes[m, 1] = eb[f, 4] + eps
        boxes[m, 2] = eb[f, 5] - eps
        boxes[m, 3] = eb[f, 6] + eps
        ids[m] = f
        m += _edge_box_meets(eb, f, wx0, wx1, wy0, wy1)
    c = 0
    for e in range(xa.shape[0]):
        ex0, ex1, ey0, ey1 = ea[e, 3], ea[e, 4], ea[e, 5], ea[e, 6]
        if m == 0 or ex1 < wx0 or ex0 > wx1 or ey1 < wy0 or ey0 > wy1:
            continue
        e1 = nxa[e]
        px, py, qx, qy = xa[e, 0], xa[e, 1], xa[e1, 0], xa[e1, 1]
        # squared: "an end farther than eps from the other edge's line"
        e_pq = eps * eps * ((qx - px) ** 2 + (qy - py) ** 2)
        for g in range(m):
            if (boxes[g, 0] > ex1 or boxes[g, 1] < ex0 or boxes[g, 2] > ey1
                    or boxes[g, 3] < ey0):
                continue
            f = ids[g]
            f1 = nxb[f]
            rx, ry, sx, sy = xb[f, 0], xb[f, 1], xb[f1, 0], xb[f1, 1]
            o1 = orient(px, py, qx, qy, rx, ry)
            o2 = orient(px, py, qx, qy, sx, sy)
            far_pq = o1 * o1 > e_pq and o2 * o2 > e_pq
            if far_pq and (o1 > 0.0) == (o2 > 0.0):
                continue  # B's edge on one side of A's line, beyond eps
            o3 = orient(rx, ry, sx, sy, px, py)
            o4 = orient(rx, ry, sx, sy, qx, qy)
            e_rs = eps * eps * ((sx - rx) ** 2 + (sy - ry) ** 2)
            far_rs = o3 * o3 > e_rs and o4 * o4 > e_rs
            if far_rs and (o3 > 0.0) == (o4 > 0.0):
                continue
            if not (far_pq and far_rs) and (
                    point_segment_distance(px, py, rx, ry, sx, sy) <= eps
                    or point_segment_distance(qx, qy, rx, ry, sx, sy) <= eps
                    or point_segment_distance(rx, ry, px, py, qx, qy) <= eps
                    or point_segment_distance(sx, sy, px, py, qx, qy) <= eps):
                deg_a[e] = True
                deg_b[f] = True
                continue
            if (o1 > 0.0) == (o2 > 0.0) or (o3 > 0.0) == (o4 > 0.0):
                continue
            if c == cross.shape[0]:
                return -1
            te = o3 / (o3 - o4)
            cross[c, 0] = e
            cross[c, 1] = f
            cross[c, 2] = te
            cross[c, 3] = o1 / (o1 - o2)
            cross[c, 4] = px + te * (qx - px)
            cross[c, 5] = py + te * (qy - py)
            c += 1
    return c


@njit(cache=True, nogil=True, _nrt=False, inline="always")
def _boundary_inside(v, o, eps, frame, deg, cross, col, sums, where_v):
    """Add the parts of body V's boundary inside body O (see the module docstring):
    ``v``, ``o`` the bodies as :func:`overlap_of_tables` takes them, ``frame`` =
    ``(wx0, wx1, wy0, wy1, ox, oy)`` the window and the local origin, ``deg`` V's edges to classify by midpoints, ``cross`` the crossings, with
    V's edge in column ``col`` (0: V is A, whose pieces on O's boundary count) and its
    parameter in ``col + 2``; ``sums`` = ``(ts, acc)``: the cut parameters' scratch and
    the sums of :func:`_green`. Each vertex's place goes to ``where_v`` (as
    :func:`where` gives it)."""
    xv, sv, ev, nxv, _ = v
    xo, so, _, _, bo = o
    wx0, wx1, wy0, wy1, ox, oy = frame
    ts, acc = sums
    nc = cross.shape[0]
    first_side = col == 0
    for k in range(sv.shape[0] - 1):
        s0 = sv[k]
        s1 = sv[k + 1]
        # start the walk at a vertex outside O's box: known to be outside
        start = -1
        for i in range(s0, s1):
            if (xv[i, 0] < bo[0] - eps or xv[i, 0] > bo[1] + eps or xv[i, 1] < bo[2] - eps
                    or xv[i, 1] > bo[3] + eps):
                start = i
                break
        status = -1
        if start < 0:
            start = s0
            status = where(xv[s0, 0], xv[s0, 1], xo, so, eps)
        e = start
        for _ in range(s1 - s0):
            e1 = nxv[e]
            px, py, qx, qy = xv[e, 0], xv[e, 1], xv[e1, 0], xv[e1, 1]
            if not _edge_box_meets(ev, e, wx0, wx1, wy0, wy1):
                status = -1  # outside O's box: outside, and so is its end
                where_v[e1] = status
                e = e1
                continue
            n = 0
            for c in range(nc):
                if cross[c, col] == e:
                    ts[n] = cross[c, col + 2]
                    n += 1
            if deg[e] or status == 0:
                n = _near_cuts(px, py, qx, qy, xo, so, eps, ts, n)
                ts[n] = 0.0
                ts[n + 1] = 1.0
                _sorted(ts, n + 2)
                _pieces_by_midpoint((px, py, qx, qy), xo, so, eps, ts, n + 2, first_side, ox,
                                    oy, acc)
                status = where(qx, qy, xo, so, eps)
            else:
                _sorted(ts, n)
                t0 = 0.0
                inside = status > 0
                for q in range(n + 1):
                    t1 = ts[q] if q < n else 1.0
                    if inside:
                        _green(px + t0 * (qx - px), py + t0 * (qy - py),
                               px + t1 * (qx - px), py + t1 * (qy - py), ox, oy, acc)
                    inside = not inside
                    t0 = t1
                status = -1 if inside else 1  # (flipped once past the last piece)
            where_v[e1] = status
            e = e1


@njit(cache=True, nogil=True)
def overlap_scratch(na, nb, cap):
    """Scratch of :func:`overlap_moments` for bodies of up to ``na`` and ``nb`` vertices
    and ``cap`` crossings: ``(deg_a, deg_b, cross, ts, acc, boxes, ids, where_a,
    where_b, tables)``. After the call ``acc[4:6]`` holds a point of the intersection's
    boundary (the midpoint of a piece of it) when ``acc[3]`` is 1, and ``where_a``,
    ``where_b`` (int8, one per vertex) where each vertex of A and of B lies (as
    :func:`where` gives it: 1 inside the other body by more than ``eps``), known from
    the walk (not filled when ``cross`` is too short); ``tables``: room for both
    bodies' edge tables (:func:`overlap_moments` fills them; :func:`overlap_of_tables`
    takes them filled)."""
    return (np.empty(na, np.bool_), np.empty(nb, np.bool_), np.empty((cap, 6)),
            np.empty(cap + na + nb + 2), np.empty(6), np.empty((nb, 4)),
            np.empty(nb, np.int64), np.empty(na, np.int8), np.empty(nb, np.int8),
            (np.empty((na, 7)), np.empty(na, np.int64), np.empty((nb, 7)),
             np.empty(nb, np.int64)))


@njit(cache=True, nogil=True, _nrt=False)
def overlap_moments(xa, sa, xb, sb, eps, scratch):
    """Area and centroid of A ∩ B: ``(area, cx, cy, crossings)``; the proper crossings
    of the boundaries are left in ``cross[:crossings]`` (rows as :func:`_crossings`
    writes them), -1 when ``cross`` is too short (nothing else computed).

    ``scratch``: :func:`overlap_scratch` for at least the bodies' vertex counts (where
    it leaves a point of the boundary and each vertex's place, see there). The area is
    0 (and the centroid NaN) when the interiors do not overlap by more than the
    rounding.

    Examples
    --------
    >>> import numpy as np
    >>> sq = np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]])
    >>> st = np.array([0, 4])
    >>> got = overlap_moments(sq, st, sq + 1.0, st, 1e-12, overlap_scratch(4, 4, 16))
    >>> [float(v) for v in got]
    [1.0, 1.5, 1.5, 2.0]
    """
    na = xa.shape[0]
    nb = xb.shape[0]
    ea, nxa, eb, nxb = scratch[9]
    edge_rows(xa, sa, ea, nxa)
    edge_rows(xb, sb, eb, nxb)
    return overlap_of_tables((xa, sa, ea[:na], nxa[:na], bbox(xa, na)),
                             (xb, sb, eb[:nb], nxb[:nb], bbox(xb, nb)), eps, scratch)


@njit(cache=True, nogil=True, _nrt=False)
def overlap_of_tables(a, b, eps, scratch):
    """:func:`overlap_moments` of the bodies ``a`` = ``(xa, sa, ea, nxa, box)`` (packed
    loops, :func:`polycontact._kernels.primitives.edge_rows` table and successors,
    bounding box ``(xmin, xmax, ymin, ymax)``) and ``b`` likewise, their tables already
    built (``scratch``'s own are not used)."""
    xa, sa, _, _, ba = a
    xb, sb, _, _, bb = b
    deg_a, deg_b, cross, ts, acc, boxes, ids, where_a, where_b, _ = scratch
    acc[:] = 0.0
    na = xa.shape[0]
    nb = xb.shape[0]
    wx0 = max(ba[0], bb[0]) - eps
    wx1 = min(ba[1], bb[1]) + eps
    wy0 = max(ba[2], bb[2]) - eps
    wy1 = min(ba[3], bb[3]) + eps
    where_a[:na] = -1
    where_b[:nb] = -1
    if wx0 > wx1 or wy0 > wy1:
        return 0.0, np.nan, np.nan, 0
    deg_a[:na] = False
    deg_b[:nb] = False
    window = (wx0, wx1, wy0, wy1)
    nc = _crossings(a, b, eps, window, deg_a, deg_b, cross, boxes, ids)
    if nc < 0:
        return 0.0, np.nan, np.nan, -1
    frame = (wx0, wx1, wy0, wy1, 0.5 * (wx0 + wx1), 0.5 * (wy0 + wy1))
    for col in range(2):  # A's boundary inside B, then B's inside A (one inlined copy)
        v, o, deg, where_v = (a, b, deg_a, where_a) if col == 0 else (b, a, deg_b, where_b)
        _boundary_inside(v, o, eps, frame, deg, cross[:nc], col, (ts, acc), where_v)
    if not acc[0] > 0.0:
        return 0.0, np.nan, np.nan, nc
    ox, oy = frame[4], frame[5]
    return 0.5 * acc[0], ox + acc[1] / (3.0 * acc[0]), oy + acc[2] / (3.0 * acc[0]), nc
