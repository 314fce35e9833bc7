"""Kernels: every contact feature of two bodies (vertices on or inside the other body,
crossing edges), in the numbering of the packed form.
"""

from __future__ import annotations

import numpy as np

from .jit import njit
from .primitives import bbox, closest_on_segment, loop_index, loop_next, loop_prev, next_vertex, orient, \
    point_segment_distance
from .relation import point_inside


@njit(cache=True, nogil=True)
def _segments_cross(px, py, qx, qy, rx, ry, sx, sy, eps):
    """Proper crossing: no endpoint within eps of the other segment, and they meet."""
    if (
        point_segment_distance(px, py, rx, ry, sx, sy) <= eps
        or point_segment_distance(qx, qy, rx, ry, sx, sy) <= eps
        or point_segment_distance(rx, ry, px, py, qx, qy) <= eps
        or point_segment_distance(sx, sy, px, py, qx, qy) <= eps
    ):
        return False
    o1 = orient(px, py, qx, qy, rx, ry)
    o2 = orient(px, py, qx, qy, sx, sy)
    o3 = orient(rx, ry, sx, sy, px, py)
    o4 = orient(rx, ry, sx, sy, qx, qy)
    return ((o1 > 0.0) != (o2 > 0.0)) and ((o3 > 0.0) != (o4 > 0.0))


@njit(cache=True, nogil=True)
def _vertex_features(xv, sv, xo, so, eps, out_on, out_in):
    """Vertices of one body on (within eps of) or strictly inside the other body.

    Appends ``(vertex, edge, distance)`` rows (global indices) to ``out_on`` for every
    edge within eps, and ``(vertex, nearest edge, distance)`` to ``out_in`` for a vertex
    strictly inside.
    """
    nv = sv[sv.shape[0] - 1]
    no = so[so.shape[0] - 1]
    lo = loop_index(so, no)
    ox0, ox1, oy0, oy1 = bbox(xo, no)
    for i in range(nv):
        px = xv[i, 0]
        py = xv[i, 1]
        if px < ox0 - eps or px > ox1 + eps or py < oy0 - eps or py > oy1 + eps:
            continue
        on = False
        near = np.inf
        near_e = -1
        for f in range(no):
            f1 = next_vertex(f, so, lo)
            d = point_segment_distance(px, py, xo[f, 0], xo[f, 1], xo[f1, 0], xo[f1, 1])
            if d <= eps:
                out_on.append((i, f, d))
                on = True
            if d < near:
                near = d
                near_e = f
        if not on and point_inside(px, py, xo, so):
            out_in.append((i, near_e, near))


@njit(cache=True, nogil=True)
def features(xa, sa, xb, sb, eps):
    """Every contact feature of A and B (global vertex/edge indices of the packed form).

    Returns ``(a_on, b_on, a_in, b_in, cross)``: lists of ``(vertex, edge, distance)``
    for vertices of A on edges of B and of B on edges of A, vertices strictly inside the
    other body with the nearest edge of the other body, and ``(edge_a, edge_b, x, y)``
    for proper crossings. Brute force over all pairs (O(m n)); used lazily.
    """
    a_on = [(0, 0, 0.0)]
    b_on = [(0, 0, 0.0)]
    a_in = [(0, 0, 0.0)]
    b_in = [(0, 0, 0.0)]
    cross = [(0, 0, 0.0, 0.0)]
    a_on.clear()
    b_on.clear()
    a_in.clear()
    b_in.clear()
    cross.clear()
    _vertex_features(xa, sa, xb, sb, eps, a_on, a_in)
    _vertex_features(xb, sb, xa, sa, eps, b_on, b_in)
    na = sa[sa.shape[0] - 1]
    nb = sb[sb.shape[0] - 1]
    la = loop_index(sa, na)
    lb = loop_index(sb, nb)
    for e in range(na):
        e1 = next_vertex(e, sa, la)
        px, py, qx, qy = xa[e, 0], xa[e, 1], xa[e1, 0], xa[e1, 1]
        for f in range(nb):
            f1 = next_vertex(f, sb, lb)
            rx, ry, sx, sy = xb[f, 0], xb[f, 1], xb[f1, 0], xb[f1, 1]
            if max(rx, sx) < min(px, qx) or min(rx, sx) > max(px, qx):
                continue
            if max(ry, sy) < min(py, qy) or min(ry, sy) > max(py, qy):
                continue
            if _segments_cross(px, py, qx, qy, rx, ry, sx, sy, eps):
                o1 = orient(px, py, qx, qy, rx, ry)
                o2 = orient(px, py, qx, qy, sx, sy)
                t = o1 / (o1 - o2)
                cross.append((e, f, rx + t * (sx - rx), ry + t * (sy - ry)))
    return a_on, b_on, a_in, b_in, cross


@njit(cache=True, nogil=True, _nrt=False)
def touch(xa, sa, xb, sb, eps):
    """The touch of two bodies in contact that :attr:`polycontact.Relation.normal`
    chooses: ``(nx, ny, side, vertex, edge)``, the unit normal from A towards B (B's
    inward normal under a vertex of A, A's outward normal under a vertex of B), or
    ``side`` -1 when no vertex lies within ``eps`` of an edge of the other body.

    The candidates are the vertex-on-edge rows of :func:`features` (a vertex within
    ``eps`` of an edge, A's vertices, then B's; each against the other's edges, in
    order). A candidate whose touching vertex keeps its own edges on their side of the
    edge (within 1e-9 of their length) beats one that does not (so a square's corner
    on the end of a flush edge does not offer the normal of the perpendicular edge);
    among equals, the touch farthest from the edge's nearer end wins (measured from
    each end, so a vertex on a vertex scores exactly 0), the first on a tie.

    >>> import numpy as np
    >>> sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    >>> st = np.array([0, 4])
    >>> nx, ny, side, vertex, edge = touch(sq, st, sq + np.array([1.0, 0.5]), st, 1e-12)
    >>> float(nx), float(ny), side, vertex, edge
    (1.0, 0.0, 0, 2, 3)
    """
    best_fits = False
    best_t = -np.inf
    out = (np.nan, np.nan, -1, -1, -1)
    for side in range(2):
        xv, sv, xo, so = (xa, sa, xb, sb) if side == 0 else (xb, sb, xa, sa)
        sign = 1.0 if side == 0 else -1.0
        no = so[so.shape[0] - 1]
        ox0, ox1, oy0, oy1 = bbox(xo, no)
        for kv in range(sv.shape[0] - 1):
            for i in range(sv[kv], sv[kv + 1]):
                px = xv[i, 0]
                py = xv[i, 1]
                if px < ox0 - eps or px > ox1 + eps or py < oy0 - eps or py > oy1 + eps:
                    continue
                ip = loop_prev(i, sv, kv)
                inx = loop_next(i, sv, kv)
                for ko in range(so.shape[0] - 1):
                    for f in range(so[ko], so[ko + 1]):
                        f1 = loop_next(f, so, ko)
                        ax, ay, bx, by = xo[f, 0], xo[f, 1], xo[f1, 0], xo[f1, 1]
                        # the test of :func:`_vertex_features`, the root only near eps
                        d2 = closest_on_segment(px, py, ax, ay, bx, by)[2]
                        if d2 > 4.0 * eps * eps or np.sqrt(d2) > eps:
                            continue
                        ux = bx - ax
                        uy = by - ay
                        length = np.sqrt(ux * ux + uy * uy)
                        nx = sign * -uy / length + 0.0
                        ny = sign * ux / length + 0.0
                        # from each end (exactly 0 on a vertex that is that end)
                        t = ((px - ax) * ux + (py - ay) * uy) / length
                        t1 = ((bx - px) * ux + (by - py) * uy) / length
                        fits = True
                        for w in (ip, inx):
                            rx = xv[w, 0] - px
                            ry = xv[w, 1] - py
                            if sign * (rx * nx + ry * ny) > 1e-9 * np.sqrt(rx * rx + ry * ry):
                                fits = False
                        score = min(t, t1)
                        if (fits and not best_fits) or (fits == best_fits and score > best_t):
                            best_fits = fits
                            best_t = score
                            out = (nx, ny, side, i, f)
    return out
