"""Kernels: raw rings checked and classified in one call, without a Shape.

A raw ring is an (N, 2) array, closed or not, either orientation. :func:`raw_ring`
certifies that it is a valid simple polygon within the coordinates the kernels carry,
with its orientation, default tolerance and box: convex and most star-shaped rings are
certified in O(n) (:func:`_star_ring_is_simple`), short ones pair by pair, long ones by
a sweep. The certificate is conservative: a ring passes only when no two of its
features that may not meet come within its tolerance eps (at least 64 float spacings
of its coordinates, far above the rounding of the tests), so it is valid by the exact
rules of :func:`polycontact._kernels.validate.first_defect` too. A ring that fails
(invalid, or valid with features closer than eps) is left to
:class:`polycontact.Shape`, which decides exactly and explains.
:func:`classify_raw` validates two rings and classifies them.
"""

from __future__ import annotations

import numpy as np

from .jit import njit
from .primitives import norm, orient, point_segment_distance, segment_meet
from .relation import oriented_state
from .sweep import sorted_edge_boxes
from .tolerance import box_extent_magnitude, tolerance_for


@njit(cache=True, nogil=True)
def _folds(px, py, qx, qy, rx, ry, eps):
    """Consecutive edges p->q->r fold back (r within eps of pq, or p within eps of qr)."""
    o = orient(px, py, qx, qy, rx, ry)
    l1 = (qx - px) * (qx - px) + (qy - py) * (qy - py)
    l2 = (rx - qx) * (rx - qx) + (ry - qy) * (ry - qy)
    if o * o > eps * eps * max(l1, l2):
        return False
    return (
        point_segment_distance(rx, ry, px, py, qx, qy) <= eps
        or point_segment_distance(px, py, qx, qy, rx, ry) <= eps
    )


@njit(cache=True, nogil=True)
def _meet(px, py, qx, qy, rx, ry, sx, sy, eps):
    """Closed segments pq and rs meet within eps (same predicate as ``segment_meet``)."""
    o1 = orient(px, py, qx, qy, rx, ry)
    o2 = orient(px, py, qx, qy, sx, sy)
    t = eps * norm(qx - px, qy - py)
    if (o1 > t and o2 > t) or (o1 < -t and o2 < -t):
        return False
    o3 = orient(rx, ry, sx, sy, px, py)
    o4 = orient(rx, ry, sx, sy, qx, qy)
    t = eps * norm(sx - rx, sy - ry)
    if (o3 > t and o4 > t) or (o3 < -t and o4 < -t):
        return False
    return segment_meet(px, py, qx, qy, rx, ry, sx, sy, eps)[0]


#: Rings with at most this many vertices are checked pair by pair (no sort, no
#: allocation); above it the edges are swept in order of their smallest x.
_SMALL_RING = 24


@njit(cache=True, nogil=True)
def _small_ring_is_simple(xy, n, eps):
    """All pairs of non-adjacent edges, each rejected by its boxes first."""
    for i in range(n - 2):
        px, py = xy[i, 0], xy[i, 1]
        qx, qy = xy[i + 1, 0], xy[i + 1, 1]
        x0 = min(px, qx) - eps
        x1 = max(px, qx) + eps
        y0 = min(py, qy) - eps
        y1 = max(py, qy) + eps
        for j in range(i + 2, n if i > 0 else n - 1):
            j1 = j + 1 if j + 1 < n else 0
            rx, ry = xy[j, 0], xy[j, 1]
            sx, sy = xy[j1, 0], xy[j1, 1]
            if max(rx, sx) < x0 or min(rx, sx) > x1 or max(ry, sy) < y0 or min(ry, sy) > y1:
                continue
            if _meet(px, py, qx, qy, rx, ry, sx, sy, eps):
                return False
    return True


@njit(cache=True, nogil=True)
def _star_ring_is_simple(xy, n, eps):
    """True when the ring is certified simple in O(n) as star-shaped about the mean of
    its vertices c, with every edge more than ``2 eps`` from every edge it does not
    share a vertex with; False means "not certified" (the ring may still be simple).

    Let u_i = x_i − c. If every edge turns the same way about c (cross(u_i, u_(i+1))
    of one strict sign) and the polar angle of u winds once (u_y changes sign exactly
    twice), the edges lie in disjoint wedges about c that tile the plane once, each
    edge touching only its own wedge's two rays, at its ends: the ring is simple.
    Distances: a point of edge i is at least h_i (the distance of its line from c)
    from c, and a point of an edge that is not adjacent to it (or the far end of an
    adjacent edge) lies at least one whole wedge away in angle, so the two are at least
    h_min · sin(min(γ_min, π/2)) apart, γ_min the narrowest wedge. When that exceeds
    ``2 eps`` no two such edges meet within eps and no two consecutive edges fold back,
    which is all :func:`_ring_is_simple` checks. The margin dwarfs the rounding of c,
    the u_i and the products (a few ulps of the coordinates, against eps >= 1e-12 of
    the extent and >= 64 ulps of the largest coordinate), so a certified ring is simple
    by the exact predicate too.
    """
    cx = 0.0
    cy = 0.0
    for i in range(n):
        cx += xy[i, 0]
        cy += xy[i, 1]
    cx /= n
    cy /= n
    ux = xy[n - 1, 0] - cx
    uy = xy[n - 1, 1] - cy
    u2 = ux * ux + uy * uy
    turn = 0.0
    changes = 0
    h2 = np.inf     # min over edges of h_i², h_i = cross_i / |edge i|
    s2 = 1.0        # min over wedges of sin², 1 for a wedge wider than π/2
    for i in range(n):
        wx = xy[i, 0] - cx
        wy = xy[i, 1] - cy
        w2 = wx * wx + wy * wy
        cr = ux * wy - uy * wx
        if turn == 0.0:
            turn = 1.0 if cr > 0.0 else -1.0
        cr *= turn
        if not cr > 0.0:        # also NaN
            return False
        if (uy < 0.0) != (wy < 0.0):
            changes += 1
        ex = wx - ux
        ey = wy - uy
        # ratios before squares: a squared cross product of coordinates near the
        # limits (1e100, 1e-100) would overflow or underflow float64
        h = cr / np.sqrt(ex * ex + ey * ey)
        h2 = min(h2, h * h)
        if ux * wx + uy * wy > 0.0:
            sn = cr / (np.sqrt(u2) * np.sqrt(w2))
            s2 = min(s2, sn * sn)
        ux = wx
        uy = wy
        u2 = w2
    return changes == 2 and h2 * s2 > 4.0 * eps * eps


@njit(cache=True, nogil=True)
def ring_is_simple_unswept(xy, n, eps):
    """:func:`_ring_is_simple` as far as it goes without allocating: 1 simple, 0 not,
    -1 undecided (a ring of more than ``_SMALL_RING`` vertices that
    :func:`_star_ring_is_simple` does not certify and that has no fold: it needs the
    sweep)."""
    if _star_ring_is_simple(xy, n, eps):
        return 1
    for i in range(n):
        h = i - 1 if i > 0 else n - 1
        j = i + 1 if i + 1 < n else 0
        if _folds(xy[h, 0], xy[h, 1], xy[i, 0], xy[i, 1], xy[j, 0], xy[j, 1], eps):
            return 0
    if n <= _SMALL_RING:
        return 1 if _small_ring_is_simple(xy, n, eps) else 0
    return -1


@njit(cache=True, nogil=True)
def _ring_is_simple(xy, n, eps):
    """No two edges of the ring come within eps of each other except consecutive ones
    at their shared vertex, and no two consecutive edges fold back within eps: the rules
    of ``validate.first_defect`` for one loop, with a margin of eps. Rings certified by
    :func:`_star_ring_is_simple` (convex ones, and most star-shaped ones) pass in O(n);
    other short rings test every pair, long ones sweep edges sorted by xmin."""
    known = ring_is_simple_unswept(xy, n, eps)
    if known >= 0:
        return known == 1
    eb = sorted_edge_boxes(xy, n)
    for oi in range(n):
        i = int(eb[oi, 4])
        i1 = i + 1 if i + 1 < n else 0
        x1 = eb[oi, 1] + eps
        y0 = eb[oi, 2] - eps
        y1 = eb[oi, 3] + eps
        for oj in range(oi + 1, n):
            if eb[oj, 0] > x1:
                break
            if eb[oj, 2] > y1 or eb[oj, 3] < y0:
                continue
            j = int(eb[oj, 4])
            j1 = j + 1 if j + 1 < n else 0
            if j == i1 or i == j1:
                continue
            if _meet(xy[i, 0], xy[i, 1], xy[i1, 0], xy[i1, 1],
                     xy[j, 0], xy[j, 1], xy[j1, 0], xy[j1, 1], eps):
                return False
    return True


@njit(cache=True, nogil=True)
def raw_ring(xy, rel, ulps, limit, floor):
    """Check one raw (N, 2) ring; returns ``(n, sign, eps, box)``.

    ``n`` is the number of vertices used (a repeated closing point dropped), or -1 when
    the ring is not certified a valid simple polygon as given (see the module's
    docstring: it may be valid with features closer than eps), or lies outside the
    range the kernels carry (|coordinate| above ``limit``, extent below ``floor``; the
    caller then lets :class:`polycontact.Shape` decide, explain or repair); ``sign`` is
    +1.0 counter-clockwise, -1.0 clockwise; ``eps`` the ring's own default tolerance
    (:func:`polycontact._kernels.tolerance.tolerance_for` of its extent and largest
    |coordinate|, with ``rel`` and ``ulps``); ``box`` the bounding box
    ``(xmin, xmax, ymin, ymax)``.
    """
    n, sign, eps, box = ring_summary(xy, rel, ulps, limit, floor)
    if n > 0 and not _ring_is_simple(xy, n, eps):
        return -1, 1.0, 0.0, (0.0, 0.0, 0.0, 0.0)
    return n, sign, eps, box


@njit(cache=True, nogil=True)
def ring_summary(xy, rel, ulps, limit, floor):
    """:func:`raw_ring` but for the simplicity check (left to the caller)."""
    n = xy.shape[0]
    if xy.shape[1] != 2:
        return -1, 1.0, 0.0, (0.0, 0.0, 0.0, 0.0)
    if n >= 2 and xy[n - 1, 0] == xy[0, 0] and xy[n - 1, 1] == xy[0, 1]:
        n -= 1
    if n < 3:
        return -1, 1.0, 0.0, (0.0, 0.0, 0.0, 0.0)
    # One pass: range (which also refuses NaN and infinities), bounding box and twice
    # the signed area (taken relative to the first vertex, so a small ring far from the
    # origin keeps its digits). Out of range, the products below could overflow: the
    # area is summed only once every coordinate is known to be in range.
    x0 = np.inf
    x1 = -np.inf
    y0 = np.inf
    y1 = -np.inf
    for i in range(n):
        x = xy[i, 0]
        y = xy[i, 1]
        if not (abs(x) <= limit and abs(y) <= limit):
            return -1, 1.0, 0.0, (0.0, 0.0, 0.0, 0.0)
        x0 = min(x0, x)
        x1 = max(x1, x)
        y0 = min(y0, y)
        y1 = max(y1, y)
    extent, magnitude = box_extent_magnitude(x0, x1, y0, y1)
    if extent < floor:
        return -1, 1.0, 0.0, (0.0, 0.0, 0.0, 0.0)
    a2 = 0.0
    ox = xy[0, 0]
    oy = xy[0, 1]
    jx = xy[n - 1, 0]
    jy = xy[n - 1, 1]
    for i in range(n):
        x = xy[i, 0]
        y = xy[i, 1]
        a2 += (jx - ox) * (y - oy) - (x - ox) * (jy - oy)
        jx = x
        jy = y
    eps = tolerance_for(extent, magnitude, rel, ulps)
    # An area compared with an area: eps times the ring's extent.
    if abs(0.5 * a2) <= eps * extent:
        return -1, 1.0, 0.0, (0.0, 0.0, 0.0, 0.0)
    return n, (1.0 if a2 > 0.0 else -1.0), eps, (x0, x1, y0, y1)


@njit(cache=True, nogil=True)
def pair_tolerance(ba, bb, rel, ulps):
    """The default tolerance of two bodies from their bounding boxes ``(xmin, xmax,
    ymin, ymax)``: the larger extent, the largest |coordinate| (as
    :func:`polycontact.default_tolerance`)."""
    ea, ma = box_extent_magnitude(ba[0], ba[1], ba[2], ba[3])
    eb, mb = box_extent_magnitude(bb[0], bb[1], bb[2], bb[3])
    return tolerance_for(max(ea, eb), max(ma, mb), rel, ulps)


@njit(cache=True, nogil=True)
def classify_raw(a, b, tol, rel, ulps, limit, floor):
    """Validate two raw outer rings and classify them in one call.

    Returns ``(state, eps, na, sign_a, nb, sign_b)``; ``state`` is -1 when ring A is not
    valid as given and -2 when ring B is not (the caller re-raises through ``Shape``).
    ``tol`` < 0 means the default tolerance (:func:`pair_tolerance` with ``rel`` and
    ``ulps``); ``limit`` and ``floor`` bound the coordinates and extents accepted (see
    :func:`raw_ring`).
    """
    na, fa, _, ba = raw_ring(a, rel, ulps, limit, floor)
    if na < 0:
        return -1, 0.0, na, fa, 0, 1.0
    nb, fb, _, bb = raw_ring(b, rel, ulps, limit, floor)
    if nb < 0:
        return -2, 0.0, na, fa, nb, fb
    eps = tol if tol >= 0.0 else pair_tolerance(ba, bb, rel, ulps)
    sa = np.empty(2, np.int64)
    sa[0] = 0
    sa[1] = na
    sb = np.empty(2, np.int64)
    sb[0] = 0
    sb[1] = nb
    return oriented_state(a[:na], sa, fa, b[:nb], sb, fb, eps), eps, na, fa, nb, fb
