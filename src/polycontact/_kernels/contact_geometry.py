"""Kernels: the geometry of many contacts at once — distance, normal, point, overlap.

For each pair of bodies (packed as in :mod:`polycontact._kernels.world`), by its state:

- **separate** (a near pair): the gap between the boundaries, the unit vector from A's
  closest point to B's, their midpoint, and the vertex and edge that hold the gap;
- **contact**: distance 0; the touch that :attr:`polycontact.Relation.normal` chooses
  (:func:`polycontact._kernels.features.touch`), its edge's normal from A towards B
  and the touching vertex;
- **penetrating**: minus the penetration depth, the unit vector opposite A's smallest
  escape, from the contact segment the escape lies on
  (:func:`polycontact._kernels.convolution.contact_depth_into`), the vertex and edge of
  that segment, the area and centroid of the overlap
  (:func:`polycontact._kernels.overlap.overlap_moments`); the point is the segment's
  vertex when it lies in the other body, else the crossing of the boundaries nearest
  it. A pair whose depth that kernel cannot decide (bodies above
  :data:`polycontact._kernels.convolution.FEW_VERTICES` vertices, contact segments that
  run together) is left with a NaN distance, for the caller's search over convex sums.

Vertices and edges come out as packed rows of each body; the caller maps them to its
numbering. The bodies come as ``rows`` = ``(xy, ls, lo, nl)``, the packed rows of a
World's bodies (the first four fields of its ``bodies`` record). The pairs run in
parallel chunks (one chunk: serial, no thread start); each chunk allocates its scratch
once, and the pairs run without Numba's reference counting (the dozen arrays each pair
passes on cost as much as a small pair's geometry), growing a buffer only where a pair
needs it.
"""

from __future__ import annotations

import numpy as np
from numba import prange

from .jit import njit
from .convolution import DEPTH_MORE_ROWS, DEPTH_UNDECIDED, FEW_VERTICES, contact_depth_of, \
    depth_buffers
from .depth import box_escape
from .features import touch
from .overlap import overlap_moments, overlap_of_tables, overlap_scratch
from .packs import scratch_floats
from .primitives import bbox, closest_on_segment, edge_rows, grow_rows, loop_next
from .relation import NO_WITNESS, moved_state
from .spread import SPREAD, block
from .world import body_view

SEPARATE = 0
CONTACT = 1
PENETRATING = 2

#: What :func:`pair_geometry_into` says: done, or undone for want of room for the
#: boundaries' crossings, or for the depth's pieces (:func:`grown_buffers` makes it).
GEOMETRY_DONE = 0
GEOMETRY_MORE_CROSSINGS = 1
GEOMETRY_MORE_PIECES = 2


@njit(cache=True, nogil=True, _nrt=False)
def closest_features(xa, sa, xb, sb):
    """Closest points of the boundaries of two bodies that do not touch:
    ``(gap, ax, ay, bx, by, side, vertex, edge)``, A's point (ax, ay) and B's (bx, by);
    side 0 when the gap is from a vertex of A to an edge of B, 1 from a vertex of B to
    an edge of A (packed rows). Vertices and edges whose boxes are farther than the
    best gap found are skipped.

    >>> import numpy as np
    >>> sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    >>> st = np.array([0, 4])
    >>> got = closest_features(sq, st, sq + np.array([3.0, 0.5]), st)
    >>> [float(v) for v in got[:5]], got[5:]
    ([2.0, 1.0, 1.0, 3.0, 1.0], (0, 2, 3))
    """
    best = np.inf
    out = (np.inf, 0.0, 0.0, 0.0, 0.0, -1, -1, -1)
    for side in range(2):
        xv, sv, xo, so = (xa, sa, xb, sb) if side == 0 else (xb, sb, xa, sa)
        nv = sv[sv.shape[0] - 1]
        no = so[so.shape[0] - 1]
        ox0, ox1, oy0, oy1 = bbox(xo, no)
        for i in range(nv):
            px = xv[i, 0]
            py = xv[i, 1]
            gx = max(0.0, px - ox1, ox0 - px)
            gy = max(0.0, py - oy1, oy0 - py)
            if gx * gx + gy * gy >= best * best:
                continue
            for ko in range(so.shape[0] - 1):
                for f in range(so[ko], so[ko + 1]):
                    f1 = loop_next(f, so, ko)
                    ax, bx = xo[f, 0], xo[f1, 0]
                    ay, by = xo[f, 1], xo[f1, 1]
                    ex = max(0.0, px - max(ax, bx), min(ax, bx) - px)
                    ey = max(0.0, py - max(ay, by), min(ay, by) - py)
                    if ex * ex + ey * ey >= best * best:
                        continue
                    qx, qy, d2 = closest_on_segment(px, py, ax, ay, bx, by)
                    d = np.sqrt(d2)
                    if d < best:
                        best = d
                        if side == 0:
                            out = (d, px, py, qx, qy, 0, i, f)
                        else:
                            out = (d, qx, qy, px, py, 1, i, f)
    return out


@njit(cache=True, nogil=True, _nrt=False)
def carrier(xa, sa, xb, sb, dx, dy):
    """The vertex-edge pair whose contact segment passes nearest the translation
    (dx, dy) of A: ``(side, vertex, edge)`` as :func:`contact_depth_into` gives them
    (side 0: A's vertex w, segment f − w; side 1: B's vertex v, segment v − e)."""
    best = np.inf
    out = (-1, -1, -1)
    for side in range(2):
        xv, sv, xo, so = (xa, sa, xb, sb) if side == 0 else (xb, sb, xa, sa)
        # side 0: the point w + d of A on B's edge; side 1: v − d of B on A's edge
        sx = dx if side == 0 else -dx
        sy = dy if side == 0 else -dy
        for i in range(sv[sv.shape[0] - 1]):
            px = xv[i, 0] + sx
            py = xv[i, 1] + sy
            for ko in range(so.shape[0] - 1):
                for f in range(so[ko], so[ko + 1]):
                    f1 = loop_next(f, so, ko)
                    d2 = closest_on_segment(px, py, xo[f, 0], xo[f, 1], xo[f1, 0],
                                            xo[f1, 1])[2]
                    if d2 < best:
                        best = d2
                        out = (side, i, f)
    return out


@njit(cache=True, nogil=True, _nrt=False, inline="always")
def _penetrating(ya, sa, yb, sb, e, buffers):
    """Geometry of a penetrating pair: ``(status, depth, nx, ny, px, py, area, cx, cy,
    side, vertex, edge)``, NaN depth when undecided here (see the module docstring), a
    status other than :data:`GEOMETRY_DONE` when a buffer is too short; ``buffers``: as
    :func:`geometry_buffers` makes them.

    The depth is at least that of the deepest vertex of either body inside the other
    (less twice the tolerance: every shorter translation leaves it inside), and is that
    depth when the translation that takes this vertex onto the nearest point of the
    other body's boundary (two tolerances further) ends the overlap: one check of the
    state kernel (:func:`polycontact._kernels.relation.moved_state`), the usual case of
    a corner pressed into a side. Otherwise the contact segments
    (:func:`polycontact._kernels.convolution.contact_depth_of`) search for it, from
    that lower bound, with the witness of the penetration that check found."""
    na = ya.shape[0]
    nb = yb.shape[0]
    depth_buf, scratch, (moved, state_buf) = buffers
    ea, nxa, eb, nxb = scratch[9]
    for side in range(2):
        y, st, e_, nx_ = (ya, sa, ea, nxa) if side == 0 else (yb, sb, eb, nxb)
        edge_rows(y, st, e_, nx_)
    a = (ya, sa, ea[:na], nxa[:na], bbox(ya, na))
    b = (yb, sb, eb[:nb], nxb[:nb], bbox(yb, nb))
    nan = np.nan
    area, cx, cy, nc = overlap_of_tables(a, b, e, scratch)
    if nc < 0:
        return GEOMETRY_MORE_CROSSINGS, nan, nan, nan, nan, nan, nan, nan, nan, -1, -1, -1
    cross, acc, where_a, where_b = scratch[2], scratch[4], scratch[7], scratch[8]
    # the deepest vertex of either body inside the other, onto its nearest boundary
    # point: A moved by (dx, dy)
    deep = 0.0
    side = v = f = -1
    dx = dy = 0.0
    for s in range(2):
        xv, where_v, o = (ya, where_a, b) if s == 0 else (yb, where_b, a)
        dv, vv, fv, qx, qy = _deepest(xv, where_v, o)
        if dv > deep or (s == 0 and dv == deep):
            deep, side, v, f = dv, s, vv, fv
            dx = qx - xv[vv, 0] if s == 0 else xv[vv, 0] - qx
            dy = qy - xv[vv, 1] if s == 0 else xv[vv, 1] - qy
    known = (NO_WITNESS, -1, -1)
    if deep > 0.0:
        g = 1.0 + 2.0 * e / deep
        got, w, i, j = moved_state(a, b, dx * g, dy * g, e, moved[:na], state_buf)
        if not got:
            xv = ya if side == 0 else yb
            return GEOMETRY_DONE, deep, -dx / deep + 0.0, -dy / deep + 0.0, xv[v, 0], \
                xv[v, 1], area, cx, cy, side, v, f
        known = (w, i, j)
    if na + nb > FEW_VERTICES:
        return GEOMETRY_DONE, nan, nan, nan, nan, nan, area, cx, cy, -1, -1, -1
    bound, bdx, bdy = box_escape(ya, yb)
    # A vertex inside the other body by more than a length keeps the bodies penetrating
    # through any translation shorter than it (less the tolerance): no test there.
    d, dx, dy, status, side, v, f = contact_depth_of(a, b, bound, bdx, bdy, e, deep - 2.0 * e,
                                                     known, depth_buf)
    if status == DEPTH_MORE_ROWS:
        return GEOMETRY_MORE_PIECES, nan, nan, nan, nan, nan, nan, nan, nan, -1, -1, -1
    if status == DEPTH_UNDECIDED:
        return GEOMETRY_DONE, nan, nan, nan, nan, nan, area, cx, cy, -1, -1, -1
    if side < 0:
        side, v, f = carrier(ya, sa, yb, sb, dx, dy)
    inside = (where_a if side == 0 else where_b)[v] > 0
    px, py = point_of(ya, yb, side, v, inside, cross, nc, acc)
    nx, ny = normal_of(ya, sa, yb, sb, d, dx, dy, side, f)
    return GEOMETRY_DONE, d, nx, ny, px, py, area, cx, cy, side, v, f


@njit(cache=True, nogil=True, _nrt=False, inline="always")
def _deepest(xv, where_v, o):
    """The vertex of ``xv`` deepest inside the other body among those that ``where_v``
    says lie inside it, and the nearest point of the other body's boundary:
    ``(distance, vertex, edge, qx, qy)`` (distance 0 and vertex -1 when none does);
    ``o`` = ``(xo, so, eo, nxo, box)``, the other body with its edge table (an edge
    whose box is farther than the nearest edge so far is passed over)."""
    xo, _, eo, nxo, _ = o
    best = 0.0
    out = (0.0, -1, -1, 0.0, 0.0)
    for i in range(xv.shape[0]):
        if where_v[i] != 1:
            continue
        px = xv[i, 0]
        py = xv[i, 1]
        near = np.inf
        nf = -1
        qx = qy = 0.0
        for f in range(xo.shape[0]):
            gx = max(0.0, px - eo[f, 4], eo[f, 3] - px)
            gy = max(0.0, py - eo[f, 6], eo[f, 5] - py)
            if gx * gx + gy * gy >= near:
                continue
            g = nxo[f]
            cx, cy, d2 = closest_on_segment(px, py, xo[f, 0], xo[f, 1], xo[g, 0], xo[g, 1])
            if d2 < near:
                near = d2
                nf = f
                qx = cx
                qy = cy
        if near > best:
            best = near
            out = (np.sqrt(near), i, nf, qx, qy)
    return out


@njit(cache=True, nogil=True, _nrt=False)
def normal_of(ya, sa, yb, sb, d, dx, dy, side, f):
    """The unit normal from A towards B of a penetration of depth ``d`` whose escape is
    (dx, dy): opposite the escape, or for a zero escape the normal of the carrying
    edge ``f`` (B's inward normal for side 0, A's outward one for side 1)."""
    if d > 0.0:
        return -dx / d + 0.0, -dy / d + 0.0
    xo, so = (yb, sb) if side == 0 else (ya, sa)
    ko = 0
    while so[ko + 1] <= f:
        ko += 1
    f1 = loop_next(f, so, ko)
    ux = xo[f1, 0] - xo[f, 0]
    uy = xo[f1, 1] - xo[f, 1]
    ln = np.sqrt(ux * ux + uy * uy)
    sign = 1.0 if side == 0 else -1.0
    return sign * -uy / ln + 0.0, sign * ux / ln + 0.0


@njit(cache=True, nogil=True, _nrt=False, inline="always")
def point_of(ya, yb, side, v, inside, cross, nc, acc):
    """A point of the overlap's boundary for a penetrating pair: the carrying vertex
    ``v`` (of A for side 0, of B for side 1) when it lies inside the other body by more
    than the tolerance (``inside``, as the overlap's walk found it), else the
    boundaries' crossing nearest it (``cross[:nc]``, rows of
    :func:`polycontact._kernels.overlap.overlap_moments`), else the point of the
    boundary that kernel left in ``acc``."""
    xv = ya if side == 0 else yb
    px = xv[v, 0]
    py = xv[v, 1]
    if inside:
        return px, py
    if nc == 0:
        return (acc[4], acc[5]) if acc[3] == 1.0 else (px, py)
    best = np.inf
    qx = px
    qy = py
    for c in range(nc):
        d = (cross[c, 4] - px) ** 2 + (cross[c, 5] - py) ** 2
        if d < best:
            best = d
            qx = cross[c, 4]
            qy = cross[c, 5]
    return qx, qy


@njit(cache=True, nogil=True, _nrt=False, inline="always")
def pair_geometry_into(ya, sa, yb, sb, state, e, buffers, out, k):
    """Row k of the outputs ``out`` = (distance, normal, point, area, centroid, side,
    vertex, edge) for one pair in ``state`` (see the module docstring); ``buffers`` as
    :func:`geometry_buffers` makes them. Returns :data:`GEOMETRY_DONE`, or what to grow
    (:func:`grown_buffers`) before calling again (row k then unwritten)."""
    dist, normal, point, area, centroid, side, vert, edge = out
    if state == PENETRATING:
        status, d, nx, ny, px, py, a, cx, cy, s, v, f = _penetrating(ya, sa, yb, sb, e,
                                                                     buffers)
        if status != GEOMETRY_DONE:
            return status
        dist[k] = -d
    elif state == CONTACT:
        nx, ny, s, v, f = touch(ya, sa, yb, sb, e)
        if s < 0:  # (the state kernel's touch lies beyond eps by rounding)
            g, ax, ay, bx, by, s, v, f = closest_features(ya, sa, yb, sb)
            nx, ny = normal_of(ya, sa, yb, sb, 0.0, 0.0, 0.0, s, f)
        xv = ya if s == 0 else yb
        px = xv[v, 0]
        py = xv[v, 1]
        a = 0.0
        cx = px
        cy = py
        dist[k] = 0.0
    else:
        g, ax, ay, bx, by, s, v, f = closest_features(ya, sa, yb, sb)
        if g > 0.0:
            nx = (bx - ax) / g
            ny = (by - ay) / g
        else:
            nx, ny = normal_of(ya, sa, yb, sb, 0.0, 0.0, 0.0, s, f)
        px = 0.5 * (ax + bx)
        py = 0.5 * (ay + by)
        a = 0.0
        cx = px
        cy = py
        dist[k] = g
    if not a > 0.0:  # no overlap (to the rounding): the centroid is the point
        a = 0.0
        cx = px
        cy = py
    normal[k, 0] = nx
    normal[k, 1] = ny
    point[k, 0] = px
    point[k, 1] = py
    area[k] = a
    centroid[k, 0] = cx
    centroid[k, 1] = cy
    side[k] = s
    vert[k] = v
    edge[k] = f
    return GEOMETRY_DONE


@njit(cache=True, nogil=True)
def geometry_buffers(vmax):
    """Scratch of :func:`pair_geometry_into` for bodies of up to ``vmax`` vertices:
    those of the depth's search (:func:`polycontact._kernels.convolution.depth_buffers`),
    of the overlap (:func:`polycontact._kernels.overlap.overlap_scratch`), and of a
    check of the state kernel (a body moved, the kernel's scratch)."""
    m = min(vmax, FEW_VERTICES)
    return (depth_buffers(m, m), overlap_scratch(vmax, vmax, 8 * vmax + 64),
            (np.empty((vmax, 2)), np.empty(scratch_floats(2 * vmax))))


@njit(cache=True, nogil=True)
def grown_buffers(buffers, status, vmax):
    """``buffers`` (:func:`geometry_buffers`) with the one that ``status`` (of
    :func:`pair_geometry_into`) names made longer: room for every crossing of two
    bodies of ``vmax`` vertices, or twice the rows for the depth's pieces."""
    depth_buf, scratch, check = buffers
    if status == GEOMETRY_MORE_CROSSINGS:
        big = vmax * vmax + 1
        scratch = scratch[:2] + (np.empty((big, 6)), np.empty(big + 2 * vmax + 2)) + \
            scratch[4:]
    else:
        depth_buf = (depth_buf[0], grow_rows(depth_buf[1])) + depth_buf[2:]
    return depth_buf, scratch, check


@njit(cache=True, nogil=True)
def _geometry_range(rows, pairs, vmax, lmax, c, chunks, out):
    """:func:`pair_geometry` for the pairs of chunk ``c`` of ``chunks`` (its blocks,
    :mod:`polycontact._kernels.spread`), into ``out``, with one set of buffers."""
    buffers = geometry_buffers(vmax)
    ba = np.empty(lmax + 1, np.int64)
    bb = np.empty(lmax + 1, np.int64)
    for b in range(c, SPREAD * chunks, chunks):
        k, k1 = block(pairs[0].shape[0], chunks, b)
        while k < k1:
            k, status = geometry_into(rows, pairs, k, k1, out, buffers, ba, bb)
            if k < k1:
                buffers = grown_buffers(buffers, status, vmax)


@njit(cache=True, nogil=True, _nrt=False)
def geometry_into(rows, pairs, k0, k1, out, buffers, ba, bb):
    """:func:`pair_geometry_into` for the pairs ``k0:k1`` of :func:`pair_geometry`
    (``rows``, ``pairs`` as there), into ``out``, until one needs a buffer grown:
    ``(that pair, the status saying which)``, or ``(k1, GEOMETRY_DONE)``; ``buffers``:
    :func:`geometry_buffers`; ``ba``, ``bb``: room for the two bodies' loop starts. The
    one compiled copy of the pairs' geometry (its parts are inlined into it)."""
    xy, ls, lo, nl = rows
    pi, pj, states, tols = pairs
    for k in range(k0, k1):
        ya, sa = body_view(xy, ls, lo, nl, pi[k], ba)
        yb, sb = body_view(xy, ls, lo, nl, pj[k], bb)
        status = pair_geometry_into(ya, sa, yb, sb, states[k], tols[k], buffers, out, k)
        if status != GEOMETRY_DONE:
            return k, status
    return k1, GEOMETRY_DONE


@njit(cache=True, nogil=True, parallel=True)
def pair_geometry(rows, pairs, vmax, lmax, chunks):
    """Geometry of the pairs ``pairs`` = ``(pi, pj, states, tols)`` of a World's bodies
    (``rows``, see the module docstring): bodies pi[k] and pj[k] in ``states[k]`` with
    tolerance ``tols[k]``. Returns ``(distance, normal, point, area, centroid, side,
    vertex, edge)`` (vertices and edges as packed rows of each body), in parallel chunks
    (``chunks`` = 1: serial, no thread start); ``vmax``, ``lmax``: the most vertices
    and loops of a body."""
    n = pairs[0].shape[0]
    out = (np.empty(n), np.empty((n, 2)), np.empty((n, 2)), np.empty(n), np.empty((n, 2)),
           np.empty(n, np.int8), np.empty(n, np.int64), np.empty(n, np.int64))
    if chunks == 1:
        _geometry_range(rows, pairs, vmax, lmax, 0, 1, out)
        return out
    for c in prange(chunks):
        _geometry_range(rows, pairs, vmax, lmax, c, chunks, out)
    return out


@njit(cache=True, nogil=True, parallel=True)
def boundary_gaps(rows, pi, pj, lmax, chunks):
    """The gap between the boundaries of each pair (pi[k], pj[k]) of a World's bodies
    (``rows``; see :func:`closest_features`), in parallel chunks."""
    n = pi.shape[0]
    out = np.empty(n)
    if chunks == 1:
        _gaps_range(rows, pi, pj, lmax, 0, 1, out)
        return out
    for c in prange(chunks):
        _gaps_range(rows, pi, pj, lmax, c, chunks, out)
    return out


@njit(cache=True, nogil=True)
def _gaps_range(rows, pi, pj, lmax, c, chunks, out):
    """:func:`boundary_gaps` for the pairs of chunk ``c`` of ``chunks`` (its blocks,
    :mod:`polycontact._kernels.spread`), into ``out``."""
    xy, ls, lo, nl = rows
    ba = np.empty(lmax + 1, np.int64)
    bb = np.empty(lmax + 1, np.int64)
    for b in range(c, SPREAD * chunks, chunks):
        k0, k1 = block(pi.shape[0], chunks, b)
        for k in range(k0, k1):
            ya, sa = body_view(xy, ls, lo, nl, pi[k], ba)
            yb, sb = body_view(xy, ls, lo, nl, pj[k], bb)
            out[k] = closest_features(ya, sa, yb, sb)[0]


@njit(cache=True, nogil=True)
def penetration_finish(xa, sa, xb, sb, e, d, dx, dy):
    """Normal, point and carrying features of a penetration whose depth ``d`` and
    escape (dx, dy) were found elsewhere (the search over convex sums):
    ``(nx, ny, px, py, side, vertex, edge)``, as :func:`pair_geometry_into` gives them."""
    side, v, f = carrier(xa, sa, xb, sb, dx, dy)
    scratch = overlap_scratch(xa.shape[0], xb.shape[0], xa.shape[0] * xb.shape[0] + 1)
    nc = overlap_moments(xa, sa, xb, sb, e, scratch)[3]
    inside = (scratch[7] if side == 0 else scratch[8])[v] > 0
    px, py = point_of(xa, xb, side, v, inside, scratch[2], nc, scratch[4])
    nx, ny = normal_of(xa, sa, xb, sb, d, dx, dy, side, f)
    return nx, ny, px, py, side, v, f


@njit(cache=True, nogil=True, parallel=True)
def caller_features(ls, lo, lmap, vmap, pairs, rows, chunks):
    """The carrying vertices and edges of :func:`pair_geometry` in the caller's
    numbering: ``(vertices, edges)``, each ``(loop, index)`` per pair, (-1, -1) where a
    row is -1 or was made by a repair. ``pairs`` = ``(pi, pj)``, the bodies of each
    pair; ``rows`` = ``(side, vertex, edge)`` as :func:`pair_geometry` gives them (the
    vertex is of pi[k] for side 0, of pj[k] for side 1, the edge of the other body);
    ``ls``, ``lo``: the World's loop starts and each body's first loop entry; ``lmap``,
    ``vmap``: each loop entry's and each row's map (column 0 the vertex, 1 the edge from
    it). In parallel chunks (``chunks`` = 1: serial).

    >>> import numpy as np
    >>> ls = np.array([0, 4, 8])
    >>> vmap = np.array([[q, q] for q in (3, 0, 1, 2, 0, 1, 2, 3)])
    >>> got = caller_features(ls, np.array([0, 1]), np.zeros(3, np.int64), vmap,
    ...                       (np.array([0]), np.array([1])),
    ...                       (np.array([1], np.int8), np.array([2]), np.array([0])), 1)
    >>> got[0].tolist(), got[1].tolist()
    ([[0, 2]], [[0, 3]])
    """
    pi, pj = pairs
    n = pi.shape[0]
    vertices = np.full((n, 2), -1, np.int64)
    edges = np.full((n, 2), -1, np.int64)
    for c in prange(chunks):
        for k in range(n * c // chunks, n * (c + 1) // chunks):
            own, other = (pi[k], pj[k]) if rows[0][k] == 0 else (pj[k], pi[k])
            _numbered(ls, lo, lmap, vmap, own, rows[1][k], 0, vertices[k])
            _numbered(ls, lo, lmap, vmap, other, rows[2][k], 1, edges[k])
    return vertices, edges


@njit(cache=True, nogil=True)
def _numbered(ls, lo, lmap, vmap, b, row, column, out):
    """``out`` = ``(loop, index)`` in the caller's numbering of row ``row`` of body
    ``b`` (see :func:`caller_features`); left as it is for a row -1 or a repair's."""
    if row < 0:
        return
    g = ls[lo[b]] + row
    q = 0
    while ls[lo[b] + q + 1] <= g:
        q += 1
    loop = lmap[lo[b] + q]
    index = vmap[g, column]
    if loop >= 0 and index >= 0:
        out[0] = loop
        out[1] = index
