"""Kernels: the relation of two polygonal regions (separate, contact, penetrating).

Both bodies come in the packed form of :attr:`polycontact.Shape.packed`: ``xy`` (V, 2)
float64 with every loop stacked, ``starts`` (L+1,) int64. Loops are oriented so that the
interior is on the left of every edge (outer counter-clockwise, holes clockwise). The
private ``_state`` also takes an orientation sign per body (``-1.0``: the interior is on
the right of every edge), so a raw clockwise ring can be classified without a copy.

The state decision (the reference point of A against the entrance block E(A, B)):
the interiors overlap iff (1) an edge of A properly crosses an edge of B, or (2) a loop
vertex lies strictly inside the other body (distance to its boundary above eps), or
(3) at a point where the boundaries touch (a vertex within eps of the other boundary)
the open interior cones of A and B overlap with positive angle. For (2) one vertex per
loop that touches nothing is enough: an arc of a loop between touches lies wholly inside
or wholly outside the other body, and an arc inside it makes the cones overlap at its
end, which (3) sees. Pairs of edges are found with a sweep over x restricted to the
common bounding box, so the cost is O((m + n) log(m + n) + pairs whose boxes meet).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .tolerance import box_extent_magnitude, tolerance_for
from .validate import _orient, _point_segment_distance, closest_on_segment, segment_meet
from .views import stack_floats, vector, view

SEPARATE = 0
CONTACT = 1
PENETRATING = 2


@njit(cache=True, nogil=True)
def _norm(x, y):
    return np.sqrt(x * x + y * y)


@njit(cache=True, nogil=True)
def _bbox(xy, n):
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
def _next_vertex(i, starts, loop_of):
    k = loop_of[i]
    return i + 1 if i + 1 < starts[k + 1] else starts[k]


@njit(cache=True, nogil=True)
def _loop_index(starts, n):
    loop_of = np.empty(n, np.int64)
    for k in range(starts.shape[0] - 1):
        for i in range(starts[k], starts[k + 1]):
            loop_of[i] = k
    return loop_of


@njit(cache=True, nogil=True)
def _inside(px, py, xy, starts):
    """Crossing-number test of a point against every loop (holes count); the point is
    assumed farther than the tolerance from the boundary."""
    inside = False
    for k in range(starts.shape[0] - 1):
        s = starts[k]
        e = starts[k + 1]
        j = e - 1
        for i in range(s, e):
            yi = xy[i, 1]
            yj = xy[j, 1]
            if (yi > py) != (yj > py):
                xi = xy[i, 0]
                xj = xy[j, 0]
                if px < xi + (py - yi) * (xj - xi) / (yj - yi):
                    inside = not inside
            j = i
    return inside


@njit(cache=True, nogil=True)
def _edge_table(xy, starts, offset, wx0, wx1, wy0, wy1, box, ids, cnt):
    """Append the edges of one body whose bounding box meets the window.

    ``box[r] = (xmin, xmax, ymin, ymax)``, ``ids[r] = (vertex, next vertex)`` in the
    global numbering of the pair (vertices of B after those of A: ``offset``).
    """
    for k in range(starts.shape[0] - 1):
        s = starts[k]
        e = starts[k + 1]
        for i in range(s, e):
            j = i + 1 if i + 1 < e else s
            x0 = min(xy[i, 0], xy[j, 0])
            x1 = max(xy[i, 0], xy[j, 0])
            y0 = min(xy[i, 1], xy[j, 1])
            y1 = max(xy[i, 1], xy[j, 1])
            if x1 < wx0 or x0 > wx1 or y1 < wy0 or y0 > wy1:
                continue
            box[cnt, 0] = x0
            box[cnt, 1] = x1
            box[cnt, 2] = y0
            box[cnt, 3] = y1
            ids[cnt, 0] = offset + i
            ids[cnt, 1] = offset + j
            cnt += 1
    return cnt


@njit(cache=True, nogil=True)
def _sort_into(box, cnt, order, start):
    """Write into ``order[:cnt]`` the order of the first cnt rows of box by xmin.

    A bucket pass (one bucket per row over the range of xmin; ``start`` is scratch of
    at least cnt + 1 entries) followed by an insertion pass: O(cnt) for spread-out keys.
    If the insertion pass does too much work (keys bunched in a few buckets) it falls
    back to a heap sort in place (nothing is allocated: the batch pass that calls this
    runs without reference counting).
    """
    if cnt == 0:
        return
    lo = np.inf
    hi = -np.inf
    for i in range(cnt):
        lo = min(lo, box[i, 0])
        hi = max(hi, box[i, 0])
    if cnt > 32 and hi > lo:
        scale = (cnt - 1) / (hi - lo)
        for k in range(cnt + 1):
            start[k] = 0
        for i in range(cnt):
            start[int((box[i, 0] - lo) * scale) + 1] += 1
        for k in range(cnt):
            start[k + 1] += start[k]
        for i in range(cnt):
            k = int((box[i, 0] - lo) * scale)
            order[start[k]] = i
            start[k] += 1
    else:
        for i in range(cnt):
            order[i] = i
    budget = 8 * cnt + 64
    for i in range(1, cnt):
        cur = order[i]
        key = box[cur, 0]
        j = i
        while j > 0 and box[order[j - 1], 0] > key:
            order[j] = order[j - 1]
            j -= 1
            budget -= 1
        order[j] = cur
        if budget < 0:
            _heap_sort(box, cnt, order)
            return


@njit(cache=True, nogil=True)
def _heap_sort(box, cnt, order):
    """Sort the permutation ``order[:cnt]`` by ``box[order[k], 0]`` in place."""
    for root in range(cnt // 2 - 1, -1, -1):
        _sift_down(box, order, root, cnt)
    for end in range(cnt - 1, 0, -1):
        order[0], order[end] = order[end], order[0]
        _sift_down(box, order, 0, end)


@njit(cache=True, nogil=True)
def _sift_down(box, order, root, end):
    while True:
        child = 2 * root + 1
        if child >= end:
            return
        if child + 1 < end and box[order[child + 1], 0] > box[order[child], 0]:
            child += 1
        if box[order[root], 0] >= box[order[child], 0]:
            return
        order[root], order[child] = order[child], order[root]
        root = child


@njit(cache=True, nogil=True)
def _pt(g, xa, xb, na):
    if g < na:
        return xa[g, 0], xa[g, 1]
    return xb[g - na, 0], xb[g - na, 1]


# Inlined into the state kernel: a call passes seven arrays, and in the batch pass (no
# reference counting) that call cost about as much as the test; measured 50 -> 45 ms per
# 100 000 pairs of 12-gons (one thread), single pairs within noise (+0.1 us).
@njit(cache=True, nogil=True, inline="always")
def _cones_overlap(
    px, py, xa, fa, xb, fb, na, box, ids, order, cnt, swept, maxw, eps, rays, rord
):
    """Whether the open interior cones of A and B at the touch point p overlap.

    Every edge of either body within eps of p gives rays leaving p: along the edge from
    its near end (or both ways when p is inside the edge). A ray whose interior side is
    counter-clockwise of it is "opening"; sorted by angle, the interior of a body in a
    direction d is decided by the body's nearest ray clockwise of d (rays of one body
    alternate opening/closing around p, so holes touching the outer loop work too).
    If ``swept``, the edge rows are ordered by ``order`` (xmin ascending; ``maxw`` the
    widest edge) and only the rows near p are read; otherwise every row is read.
    ``rays`` (at least 2 cnt rows of 6) and ``rord`` (as many ints) are scratch: rows
    ``(pseudo-angle, length of the edge left from p, opening, of A, unit direction)``, and their order.
    """
    lo = 0
    if swept:
        hi = cnt
        xlo = px - eps - maxw
        while lo < hi:
            mid = (lo + hi) // 2
            if box[order[mid], 0] < xlo:
                lo = mid + 1
            else:
                hi = mid
    r = 0
    for oi in range(lo, cnt):
        i = order[oi] if swept else oi
        if box[i, 0] > px + eps:
            if swept:
                break
            continue
        if box[i, 1] < px - eps or box[i, 2] > py + eps or box[i, 3] < py - eps:
            continue
        a_side = 1.0 if ids[i, 0] < na else 0.0
        flip = fa if a_side > 0.0 else fb
        ux, uy = _pt(ids[i, 0], xa, xb, na)
        wx, wy = _pt(ids[i, 1], xa, xb, na)
        if _point_segment_distance(px, py, ux, uy, wx, wy) > eps:
            continue
        du = _norm(px - ux, py - uy)
        dw = _norm(px - wx, py - wy)
        le = _norm(wx - ux, wy - uy)
        if le == 0.0:
            continue
        ex = (wx - ux) / le
        ey = (wy - uy) / le
        # Each ray's length is what is left of the edge from p: the sliver test below
        # measures how far apart two rays get before one of them ends.
        if du > eps or dw <= eps:  # ray from p (or from w) back along the edge
            if not (du <= eps and dw <= eps):
                _put_ray(rays, r, -ex, -ey, du, flip < 0.0, a_side)
                r += 1
        if dw > eps:  # ray from p (or from u) forward along the edge
            _put_ray(rays, r, ex, ey, dw, flip > 0.0, a_side)
            r += 1
    if r == 0:
        return False
    # Order by angle: insertion sort (a touch point has a handful of rays).
    for q in range(r):
        key = rays[q, 0]
        m = q
        while m > 0 and rays[rord[m - 1], 0] > key:
            rord[m] = rord[m - 1]
            m -= 1
        rord[m] = q
    for q in range(r):
        i1 = rord[q]
        i2 = rord[(q + 1) % r]
        gap = rays[i2, 0] - rays[i1, 0]  # in pseudo-angle units (a full turn is 4)
        if q == r - 1:
            gap += 4.0
        if gap < 2.0:
            # Less than half a turn: skip a sliver whose rays end within eps of each
            # other (true angle below 1 radian and angle x shorter length <= eps).
            sin_gap = rays[i1, 4] * rays[i2, 5] - rays[i1, 5] * rays[i2, 4]
            cos_gap = rays[i1, 4] * rays[i2, 4] + rays[i1, 5] * rays[i2, 5]
            # (arcsin x >= x: the arcsin is needed only when sin_gap x length is small)
            short = min(rays[i1, 1], rays[i2, 1])
            if cos_gap > _COS_ONE_RADIAN and sin_gap * short <= eps and (
                np.arcsin(min(1.0, max(0.0, sin_gap))) * short <= eps
            ):
                continue
        mid = rays[i1, 0] + 0.5 * gap
        if mid > 2.0:
            mid -= 4.0
        if _interior_at(mid, rays, r, 1.0) and _interior_at(mid, rays, r, 0.0):
            return True
    return False


_COS_ONE_RADIAN = np.cos(1.0)


@njit(cache=True, nogil=True)
def _pseudo_angle(dx, dy):
    """A number in (-2, 2] that increases with ``atan2(dy, dx)`` (no trigonometry)."""
    p = dx / (abs(dx) + abs(dy))
    return 1.0 - p if dy >= 0.0 else p - 1.0


@njit(cache=True, nogil=True)
def _put_ray(rays, r, ux, uy, length, opening, a_side):
    """Row r of the ray table: pseudo-angle, edge length, opening, of A, unit direction."""
    rays[r, 0] = _pseudo_angle(ux, uy)
    rays[r, 1] = length
    rays[r, 2] = 1.0 if opening else 0.0
    rays[r, 3] = a_side
    rays[r, 4] = ux
    rays[r, 5] = uy


@njit(cache=True, nogil=True)
def _interior_at(theta, rays, r, a_side):
    """Interior flag of one body (``a_side`` 1.0 for A) in pseudo-angle direction
    theta: its nearest ray clockwise."""
    best = -1
    best_gap = np.inf
    for i in range(r):
        if rays[i, 3] != a_side:
            continue
        gap = theta - rays[i, 0]
        if gap < 0.0:
            gap += 4.0
        if gap < best_gap:
            best_gap = gap
            best = i
    if best < 0:
        return False
    return rays[best, 2] > 0.0


@njit(cache=True, nogil=True)
def _untouched_inside(xv, sv, touch, offset, xo, so, x0, x1, y0, y1):
    """Is the first untouched vertex of some loop of one body strictly inside the other?"""
    for k in range(sv.shape[0] - 1):
        for i in range(sv[k], sv[k + 1]):
            if not touch[offset + i]:
                x = xv[i, 0]
                y = xv[i, 1]
                if x0 <= x <= x1 and y0 <= y <= y1 and _inside(x, y, xo, so):
                    return True
                break
    return False


#: Pairs with at most this many (A edge, B edge) combinations in the common window are
#: tested all against all; above it the edges are sorted and swept in x.
_ALL_PAIRS = 256


@njit(cache=True, nogil=True)
def _edge_pair(xa, xb, na, ga, a1, gb, b1, eps, touch):
    """Edge ga->a1 of A against edge gb->b1 of B (B's rows offset by na).

    Marks in ``touch`` every end vertex within eps of the other edge; returns 1 if some
    did, 2 if the edges cross properly (and no end is within eps), 0 otherwise.
    """
    px, py = xa[ga, 0], xa[ga, 1]
    qx, qy = xa[a1, 0], xa[a1, 1]
    rx, ry = xb[gb - na, 0], xb[gb - na, 1]
    sx, sy = xb[b1 - na, 0], xb[b1 - na, 1]
    # An end is "beyond eps" of a line when its orientation exceeds eps x the edge
    # length; compared squared, so no square root is taken.
    o1 = _orient(px, py, qx, qy, rx, ry)
    o2 = _orient(px, py, qx, qy, sx, sy)
    if o1 * o2 > 0.0:
        ta2 = eps * eps * ((qx - px) * (qx - px) + (qy - py) * (qy - py))
        if o1 * o1 > ta2 and o2 * o2 > ta2:
            return 0  # B's edge strictly on one side of A's edge line
    o3 = _orient(rx, ry, sx, sy, px, py)
    o4 = _orient(rx, ry, sx, sy, qx, qy)
    if o3 * o4 > 0.0:
        tb2 = eps * eps * ((sx - rx) * (sx - rx) + (sy - ry) * (sy - ry))
        if o3 * o3 > tb2 and o4 * o4 > tb2:
            return 0
    e2 = eps * eps
    near = 0
    if closest_on_segment(px, py, rx, ry, sx, sy)[2] <= e2:
        touch[ga] = True
        near = 1
    if closest_on_segment(qx, qy, rx, ry, sx, sy)[2] <= e2:
        touch[a1] = True
        near = 1
    if closest_on_segment(rx, ry, px, py, qx, qy)[2] <= e2:
        touch[gb] = True
        near = 1
    if closest_on_segment(sx, sy, px, py, qx, qy)[2] <= e2:
        touch[b1] = True
        near = 1
    if near:
        return 1
    if ((o1 > 0.0) != (o2 > 0.0)) and ((o3 > 0.0) != (o4 > 0.0)):
        return 2
    return 0


@njit(cache=True, nogil=True)
def _state(xa, sa, fa, xb, sb, fb, eps):
    """State of A against B; ``fa``/``fb`` = +1.0 or -1.0 (interior left/right).

    :func:`_state_in` with scratch allocated only for the pairs its early exits leave
    (an allocation costs as much as a small pair's test).
    """
    na = sa[sa.shape[0] - 1]
    nb = sb[sb.shape[0] - 1]
    apart, ba, bb = _early_exit(xa, na, xb, nb, eps)
    if apart:
        return SEPARATE
    box, ids, touch, rays, rord = _scratch(na + nb)
    return _overlap_state(xa, sa, fa, xb, sb, fb, eps, ba, bb, box, ids, touch, rays, rord)


@njit(cache=True, nogil=True)
def _scratch(size):
    """Scratch buffers for :func:`_state_in` for up to ``size`` vertices in all: edge
    boxes, edge ids, touch flags, and the rays at one touch point with their order
    (views of one allocation)."""
    return _scratch_views(np.empty(scratch_floats(size)), size)


@njit(cache=True, nogil=True)
def scratch_floats(size):
    """Length of a float64 buffer that holds the scratch of the state kernel for pairs
    of up to ``size`` vertices in all (see :func:`relate_shapes_into`).

    >>> scratch_floats(24)
    554
    """
    r = size + 1
    return 22 * r + (size + 8) // 8


@njit(cache=True, nogil=True, inline="always")
def _scratch_views(buf, size):
    """:func:`_scratch`'s five buffers as views of ``buf`` (of at least
    ``scratch_floats(size)`` floats): edge boxes (r, 4), edge ids (r, 4) int64, touch
    flags, rays (2 r, 6), ray order (2 r) int64, with r = size + 1."""
    r = size + 1
    return (
        view(buf, 0, r, 4, np.float64),
        view(buf, 16 * r, r, 4, np.int64),
        vector(buf, 22 * r, 8 * (scratch_floats(size) - 22 * r), np.bool_),
        view(buf, 4 * r, 2 * r, 6, np.float64),
        vector(buf, 20 * r, 2 * r, np.int64),
    )


# Inlined: as a call (a tuple of tuples returned) it made the World's pairs ~25 ns slower.
@njit(cache=True, nogil=True, inline="always")
def _early_exit(xa, na, xb, nb, eps):
    """``(apart, box of A, box of B)``: apart when the boxes are more than eps apart or
    :func:`_apart` proves the bodies are."""
    ba = _bbox(xa, na)
    bb = _bbox(xb, nb)
    return _boxes_apart(ba, bb, eps) or _apart(xa, na, xb, nb, ba, bb, eps), ba, bb


@njit(cache=True, nogil=True)
def _boxes_apart(ba, bb, eps):
    """Bounding boxes ``(xmin, xmax, ymin, ymax)`` more than eps apart."""
    return ba[0] > bb[1] + eps or bb[0] > ba[1] + eps or ba[2] > bb[3] + eps or bb[2] > ba[3] + eps


@njit(cache=True, nogil=True)
def _window(ba, bb, eps):
    """The common window of two bounding boxes, widened by eps."""
    return (max(ba[0], bb[0]) - eps, min(ba[1], bb[1]) + eps, max(ba[2], bb[2]) - eps,
            min(ba[3], bb[3]) + eps)


# Inlined into its callers: a call that passes a dozen arrays cost about 50 ns (more
# than the early exits it makes), measured on the World's candidate pairs.
@njit(cache=True, nogil=True, inline="always")
def _state_in(xa, sa, fa, xb, sb, fb, eps, box, ids, touch, rays, rord):
    """:func:`_state` with the scratch buffers of :func:`_scratch` (sized for at least
    the vertices of both bodies), so a loop over many pairs allocates nothing per pair.

    Pairs whose boxes are more than eps apart, or that :func:`_apart` proves farther
    apart than eps, are separate at once; the others take :func:`_overlap_state`.
    """
    na = sa[sa.shape[0] - 1]
    nb = sb[sb.shape[0] - 1]
    apart, ba, bb = _early_exit(xa, na, xb, nb, eps)
    if apart:
        return SEPARATE
    return _overlap_state(xa, sa, fa, xb, sb, fb, eps, ba, bb, box, ids, touch, rays, rord)


#: Rounding allowance of :func:`_apart`, in units of the larger of eps and the largest
#: |coordinate| of the pair: 64 × 2**-52, above the rounding of its projections (about
#: 30 × 2**-52 of the largest |coordinate|) plus that of the distances and orientations
#: the full test computes (a few × 2**-52 of it).
_APART_ROUNDING = 64.0 * 2.0**-52


@njit(cache=True, nogil=True)
def _apart(xa, na, xb, nb, ba, bb, eps):
    """True when a line proves A and B farther apart than eps (then the full test answers
    separate too); False means "not proven" (they may still be apart).

    The line is normal to u, the unit vector from the centre of A's bounding box ``ba``
    to that of B's ``bb``: every vertex of B must project onto u beyond every vertex of
    A by more than eps plus :data:`_APART_ROUNDING` × max(eps, largest |coordinate|).
    A polygon (holes too) projects onto the range of its vertices' projections, so the
    two regions are then farther apart than eps, with a margin above the rounding of the
    projections (taken from A's box centre, so each is off by at most about 30 × 2**-52
    of the largest |coordinate|, and |u| by a few units of 2**-53). With that margin no
    distance the full test computes falls within eps and no orientation it compares
    changes sign, so it would answer separate as well. Costs one pass over A's vertices
    and stops at the first vertex of B that does not clear; convex, concave and far
    from the origin alike (boxes that overlap at their corners, interleaved spikes fall
    through).
    """
    cx = 0.5 * (ba[0] + ba[1])
    cy = 0.5 * (ba[2] + ba[3])
    ux = 0.5 * (bb[0] + bb[1]) - cx
    uy = 0.5 * (bb[2] + bb[3]) - cy
    m = max(abs(ux), abs(uy))
    if not m > 0.0:
        return False
    ux /= m  # scaled first: the norm below neither overflows nor underflows
    uy /= m
    n = np.sqrt(ux * ux + uy * uy)
    ux /= n
    uy /= n
    mag = max(-ba[0], ba[1], -ba[2], ba[3], -bb[0], bb[1], -bb[2], bb[3])
    hi = -np.inf
    for i in range(na):
        hi = max(hi, (xa[i, 0] - cx) * ux + (xa[i, 1] - cy) * uy)
    lim = hi + eps + _APART_ROUNDING * max(eps, mag)
    for j in range(nb):
        if not (xb[j, 0] - cx) * ux + (xb[j, 1] - cy) * uy > lim:
            return False
    return True


def _overlap_test(xa, sa, fa, xb, sb, fb, eps, ba, bb, box, ids, touch, rays, rord):
    """The full test of :func:`_state_in` (no early exit) for bodies with bounding boxes
    ``ba``, ``bb`` (``(xmin, xmax, ymin, ymax)``) that come within eps of each other."""
    na = sa[sa.shape[0] - 1]
    nb = sb[sb.shape[0] - 1]
    ax0, ax1, ay0, ay1 = ba
    bx0, bx1, by0, by1 = bb
    wx0, wx1, wy0, wy1 = _window(ba, bb, eps)
    tot = na + nb
    cnt_a = _edge_table(xa, sa, 0, wx0, wx1, wy0, wy1, box, ids, 0)  # rows of A's edges
    cnt = _edge_table(xb, sb, na, wx0, wx1, wy0, wy1, box, ids, cnt_a)
    touch[:tot] = False
    any_touch = False
    maxw = 0.0
    # ids columns: 0, 1 the edge's vertices; 2 the sweep order; 3 scratch of the sort
    order = ids[:, 2]
    swept = cnt_a * (cnt - cnt_a) > _ALL_PAIRS
    if not swept:
        # Few edges in the window: every A edge against every B edge, no sort.
        for i in range(cnt_a):
            x0 = box[i, 0] - eps
            x1 = box[i, 1] + eps
            y0 = box[i, 2] - eps
            y1 = box[i, 3] + eps
            for j in range(cnt_a, cnt):
                if box[j, 0] > x1 or box[j, 1] < x0 or box[j, 2] > y1 or box[j, 3] < y0:
                    continue
                met = _edge_pair(xa, xb, na, ids[i, 0], ids[i, 1], ids[j, 0], ids[j, 1], eps, touch)
                if met == 2:
                    return PENETRATING
                if met == 1:
                    any_touch = True
    else:
        _sort_into(box, cnt, order, ids[:, 3])
        for oi in range(cnt):
            i = order[oi]
            xi1 = box[i, 1] + eps
            yi0 = box[i, 2] - eps
            yi1 = box[i, 3] + eps
            maxw = max(maxw, box[i, 1] - box[i, 0])
            i_in_a = i < cnt_a
            for oj in range(oi + 1, cnt):
                j = order[oj]
                if box[j, 0] > xi1:
                    break
                if (j < cnt_a) == i_in_a or box[j, 2] > yi1 or box[j, 3] < yi0:
                    continue
                ea = i if i_in_a else j
                eb = j if i_in_a else i
                met = _edge_pair(
                    xa, xb, na, ids[ea, 0], ids[ea, 1], ids[eb, 0], ids[eb, 1], eps, touch
                )
                if met == 2:
                    return PENETRATING
                if met == 1:
                    any_touch = True
    # (3) cones at the touch points
    if any_touch:
        for g in range(tot):
            if touch[g]:
                px, py = _pt(g, xa, xb, na)
                if _cones_overlap(
                    px, py, xa, fa, xb, fb, na, box, ids, order, cnt, swept, maxw, eps, rays,
                    rord,
                ):
                    return PENETRATING
    # (2) one untouched vertex per loop, strictly inside the other body
    if _untouched_inside(xa, sa, touch, 0, xb, sb, bx0, bx1, by0, by1):
        return PENETRATING
    if _untouched_inside(xb, sb, touch, na, xa, sa, ax0, ax1, ay0, ay1):
        return PENETRATING
    return CONTACT if any_touch else SEPARATE


_overlap_state = njit(cache=True, nogil=True, _nrt=False)(_overlap_test)
# The same test inlined, for the state kernel of one pair of Shapes
# (:func:`relate_shapes_into`): a call that passes fourteen arguments cost 0.03-0.1 us
# of the 0.3-0.7 us a pair of 12-gons takes (contact and penetrating pairs; one process,
# three classes of 200 pairs). The kernels that loop over many pairs call it: inlined
# into each of them it would multiply their compile time.
_overlap_state_inlined = njit(nogil=True, _nrt=False, inline="always")(_overlap_test)


@njit(cache=True, nogil=True)
def relate_state(xa, sa, xb, sb, eps):
    """State of A against B: 0 separate, 1 contact, 2 penetrating (interiors overlap).

    Parameters
    ----------
    xa, sa, xb, sb : packed loops of A and B (see :attr:`polycontact.Shape.packed`),
        oriented with the interior on the left of every edge.
    eps : float
        Absolute tolerance: distances up to eps count as touching.

    Examples
    --------
    >>> import numpy as np
    >>> sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    >>> st = np.array([0, 4])
    >>> [relate_state(sq, st, sq + d, st, 1e-12) for d in ([2.0, 0.0], [1.0, 0.0], [0.5, 0.5])]
    [0, 1, 2]
    """
    return _state(xa, sa, 1.0, xb, sb, 1.0, eps)


#: Layout of a shape's kernel pack (``Shape._kernel``, built once per shape by
#: :func:`polycontact.shape._kernel_pack`): one ``bytes`` object holding, as float64,
#: the loop count, the bounding box as ``(xmin, ymin, xmax, ymax)``, the shape's
#: default-tolerance term (``Shape._tolerance``: the kernel takes the larger of the two
#: shapes', so the caller reads no float object), the loop starts (int64 bit patterns,
#: L + 1 of them) and then the packed coordinates row by row. A
#: ``bytes`` object holds its data in itself: unboxing it reads one object, where an
#: ndarray's header, shape and data are three allocations (0.26 against 0.43-0.52 us per
#: call of two packs when other code has evicted the caches; the same when warm).
PACK_HEAD = 6


@njit(cache=True, nogil=True, inline="always")
def _unpack(pack):
    """``(xy, starts, box, tolerance)`` of a shape's kernel pack (views: nothing is
    allocated), the box as ``(xmin, xmax, ymin, ymax)``, the shape's default-tolerance
    term."""
    pack = vector(pack, 0, len(pack) // 8, np.float64)
    nl = int(pack[0])
    starts = vector(pack, PACK_HEAD, nl + 1, np.int64)
    n = starts[nl]
    xy = view(pack, PACK_HEAD + nl + 1, n, 2, np.float64)
    return xy, starts, (pack[1], pack[3], pack[2], pack[4]), pack[5]


#: Vertices (both bodies together) of the pairs :func:`relate_shapes_into` classifies with
#: its scratch on the stack (45 kB); larger pairs take :func:`relate_state`, whose
#: allocation costs little beside their test.
STACK_VERTICES = 256
_STACK_FLOATS = getattr(scratch_floats, "py_func", scratch_floats)(STACK_VERTICES)


# Compiled without Numba's reference counting (``_nrt=False``): the counts of the
# arrays it is called with and passes on cost ~0.1 us per call, as much as the test of a
# small separate pair. Nothing in it allocates: the scratch is on its stack (a buffer
# passed in cost a thread-local look-up and one more array to unbox per call, about
# 0.05 us). It takes one bytes object per shape (see PACK_HEAD) and reads the bounding
# boxes and tolerance terms cached in them.
@njit(cache=True, nogil=True, _nrt=False)
def relate_shapes_into(pa, pb, eps):
    """:func:`relate_state` of two shapes given by their kernel packs (``Shape._kernel``),
    allocating nothing (its scratch is on the stack).

    ``eps`` below 0 means the default tolerance of the pair: the larger of the two
    shapes' terms held in their packs (``Shape._tolerance``, hence
    :func:`polycontact.default_tolerance` of the pair). Returns -1 (and computes
    nothing) for a pair that needs the scratch and has more than
    :data:`STACK_VERTICES` vertices in all.

    The boxes are those of the packs; they equal :func:`_bbox` of the coordinates (a
    minimum or maximum is exact) up to the sign of a zero, which no use of a box sees:
    boxes are compared, summed with a nonzero bound (a valid shape's box has positive
    width and height) or shifted by eps before a comparison.

    Examples
    --------
    >>> from polycontact import Shape
    >>> sq = Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
    >>> [relate_shapes_into(sq._kernel, sq.moved(d)._kernel, -1.0)
    ...  for d in ([2, 0], [1, 0], [0.5, 0.5])]
    [0, 1, 2]
    >>> t = np.linspace(0.0, 2.0 * np.pi, 130, endpoint=False)
    >>> big = Shape(np.c_[np.cos(t), np.sin(t)])
    >>> relate_shapes_into(big._kernel, big._kernel, 1e-12)
    -1
    """
    xa, sa, ba, ta = _unpack(pa)
    xb, sb, bb, tb = _unpack(pb)
    if eps < 0.0:
        eps = max(ta, tb)
    na = sa[sa.shape[0] - 1]
    nb = sb[sb.shape[0] - 1]
    if _boxes_apart(ba, bb, eps) or _apart(xa, na, xb, nb, ba, bb, eps):
        return SEPARATE
    if na + nb > STACK_VERTICES:
        return -1
    box, ids, touch, rays, rord = _scratch_views(stack_floats(_STACK_FLOATS), na + nb)
    return _overlap_state_inlined(xa, sa, 1.0, xb, sb, 1.0, eps, ba, bb, box, ids, touch, rays,
                                  rord)


@njit(cache=True, nogil=True)
def _segment_closest(px, py, qx, qy, rx, ry, sx, sy):
    """Distance between segments pq and rs, with a closest pair ``(x1, y1, x2, y2)``."""
    o1 = _orient(px, py, qx, qy, rx, ry)
    o2 = _orient(px, py, qx, qy, sx, sy)
    o3 = _orient(rx, ry, sx, sy, px, py)
    o4 = _orient(rx, ry, sx, sy, qx, qy)
    if ((o1 > 0.0 and o2 < 0.0) or (o1 < 0.0 and o2 > 0.0)) and (
        (o3 > 0.0 and o4 < 0.0) or (o3 < 0.0 and o4 > 0.0)
    ):
        t = o1 / (o1 - o2)
        x = rx + t * (sx - rx)
        y = ry + t * (sy - ry)
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
        d = _norm(ux - cx, uy - cy)
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
    la = _loop_index(sa, na)
    lb = _loop_index(sb, nb)
    bx0, bx1, by0, by1 = _bbox(xb, nb)
    # Upper bound first: the vertex of A nearest B's box centre, to its nearest B vertex.
    cx = 0.5 * (bx0 + bx1)
    cy = 0.5 * (by0 + by1)
    ia = 0
    dmin = np.inf
    for i in range(na):
        d = _norm(xa[i, 0] - cx, xa[i, 1] - cy)
        if d < dmin:
            dmin = d
            ia = i
    best = np.inf
    r0 = r1 = r2 = r3 = 0.0
    for j in range(nb):
        d = _norm(xa[ia, 0] - xb[j, 0], xa[ia, 1] - xb[j, 1])
        if d < best:
            best = d
            r0, r1, r2, r3 = xa[ia, 0], xa[ia, 1], xb[j, 0], xb[j, 1]
    bxmin = np.empty(nb)
    maxw = 0.0
    for j in range(nb):
        j1 = _next_vertex(j, sb, lb)
        bxmin[j] = min(xb[j, 0], xb[j1, 0])
        maxw = max(maxw, abs(xb[j, 0] - xb[j1, 0]))
    order = np.argsort(bxmin)
    sorted_x = bxmin[order]
    for i in range(na):
        i1 = _next_vertex(i, sa, la)
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
            j1 = _next_vertex(j, sb, lb)
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


@njit(cache=True, nogil=True)
def _folds(px, py, qx, qy, rx, ry, eps):
    """Consecutive edges p->q->r fold back (r within eps of pq, or p within eps of qr)."""
    o = _orient(px, py, qx, qy, rx, ry)
    l1 = (qx - px) * (qx - px) + (qy - py) * (qy - py)
    l2 = (rx - qx) * (rx - qx) + (ry - qy) * (ry - qy)
    if o * o > eps * eps * max(l1, l2):
        return False
    return (
        _point_segment_distance(rx, ry, px, py, qx, qy) <= eps
        or _point_segment_distance(px, py, qx, qy, rx, ry) <= eps
    )


@njit(cache=True, nogil=True)
def _meet(px, py, qx, qy, rx, ry, sx, sy, eps):
    """Closed segments pq and rs meet within eps (same predicate as ``segment_meet``)."""
    o1 = _orient(px, py, qx, qy, rx, ry)
    o2 = _orient(px, py, qx, qy, sx, sy)
    t = eps * _norm(qx - px, qy - py)
    if (o1 > t and o2 > t) or (o1 < -t and o2 < -t):
        return False
    o3 = _orient(rx, ry, sx, sy, px, py)
    o4 = _orient(rx, ry, sx, sy, qx, qy)
    t = eps * _norm(sx - rx, sy - ry)
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
def _ring_is_simple_unswept(xy, n, eps):
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
    """No two edges of the ring meet except consecutive ones at their shared vertex,
    and no two consecutive edges fold back: the rules of ``validate.first_defect`` for
    one loop. Rings certified by :func:`_star_ring_is_simple` (convex ones, and most
    star-shaped ones) pass in O(n); other short rings test every pair, long ones sweep
    edges sorted by xmin."""
    known = _ring_is_simple_unswept(xy, n, eps)
    if known >= 0:
        return known == 1
    eb = _sorted_edge_boxes(xy, n)
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
def _sorted_edge_boxes(xy, n):
    """Rows ``(xmin, xmax, ymin, ymax, edge)`` of a ring's n edges, ordered by xmin.

    The rows are placed by a bucket pass (one bucket per edge over the range of xmin)
    and finished by an insertion pass on the rows themselves, so the sweep that follows
    reads them contiguously; O(n) for spread-out keys. If the insertion pass does too
    much work (keys bunched in a few buckets) it falls back to ``np.argsort``.
    """
    key = np.empty(n)
    lo = np.inf
    hi = -np.inf
    for i in range(n):
        j = i + 1 if i + 1 < n else 0
        k = min(xy[i, 0], xy[j, 0])
        key[i] = k
        lo = min(lo, k)
        hi = max(hi, k)
    scale = (n - 1) / (hi - lo) if hi > lo else 0.0
    start = np.zeros(n + 1, np.int64)
    for i in range(n):
        start[int((key[i] - lo) * scale) + 1] += 1
    for k in range(n):
        start[k + 1] += start[k]
    eb = np.empty((n, 5))
    for i in range(n):
        b = int((key[i] - lo) * scale)
        r = start[b]
        start[b] = r + 1
        j = i + 1 if i + 1 < n else 0
        eb[r, 0] = key[i]
        eb[r, 1] = max(xy[i, 0], xy[j, 0])
        eb[r, 2] = min(xy[i, 1], xy[j, 1])
        eb[r, 3] = max(xy[i, 1], xy[j, 1])
        eb[r, 4] = i
    budget = 8 * n + 64
    for r in range(1, n):
        k = eb[r, 0]
        if eb[r - 1, 0] <= k:
            continue
        c1 = eb[r, 1]
        c2 = eb[r, 2]
        c3 = eb[r, 3]
        c4 = eb[r, 4]
        s = r
        while s > 0 and eb[s - 1, 0] > k:
            for c in range(5):
                eb[s, c] = eb[s - 1, c]
            s -= 1
        budget -= r - s
        eb[s, 0] = k
        eb[s, 1] = c1
        eb[s, 2] = c2
        eb[s, 3] = c3
        eb[s, 4] = c4
        if budget < 0:
            return eb[np.argsort(eb[:, 0])]
    return eb


@njit(cache=True, nogil=True)
def _raw_ring(xy, rel, ulps, limit, floor):
    """Check one raw (N, 2) ring; returns ``(n, sign, eps, box)``.

    ``n`` is the number of vertices used (a repeated closing point dropped), or -1 when
    the ring is not a valid simple polygon as given, or lies outside the range the
    kernels carry (|coordinate| above ``limit``, extent below ``floor``; the caller then
    lets :class:`polycontact.Shape` explain or repair); ``sign`` is +1.0
    counter-clockwise, -1.0 clockwise; ``eps`` the ring's own default tolerance
    (:func:`polycontact._kernels.tolerance.tolerance_for` of its extent and largest
    |coordinate|, with ``rel`` and ``ulps``); ``box`` the bounding box
    ``(xmin, xmax, ymin, ymax)``.
    """
    n, sign, eps, box = _ring_summary(xy, rel, ulps, limit, floor)
    if n > 0 and not _ring_is_simple(xy, n, eps):
        return -1, 1.0, 0.0, (0.0, 0.0, 0.0, 0.0)
    return n, sign, eps, box


@njit(cache=True, nogil=True)
def _ring_summary(xy, rel, ulps, limit, floor):
    """:func:`_raw_ring` but for the simplicity check (left to the caller)."""
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
    :func:`_raw_ring`).
    """
    na, fa, _, ba = _raw_ring(a, rel, ulps, limit, floor)
    if na < 0:
        return -1, 0.0, na, fa, 0, 1.0
    nb, fb, _, bb = _raw_ring(b, rel, ulps, limit, floor)
    if nb < 0:
        return -2, 0.0, na, fa, nb, fb
    eps = tol if tol >= 0.0 else pair_tolerance(ba, bb, rel, ulps)
    sa = np.empty(2, np.int64)
    sa[0] = 0
    sa[1] = na
    sb = np.empty(2, np.int64)
    sb[0] = 0
    sb[1] = nb
    return _state(a[:na], sa, fa, b[:nb], sb, fb, eps), eps, na, fa, nb, fb


@njit(cache=True, nogil=True)
def _segments_cross(px, py, qx, qy, rx, ry, sx, sy, eps):
    """Proper crossing: no endpoint within eps of the other segment, and they meet."""
    if (
        _point_segment_distance(px, py, rx, ry, sx, sy) <= eps
        or _point_segment_distance(qx, qy, rx, ry, sx, sy) <= eps
        or _point_segment_distance(rx, ry, px, py, qx, qy) <= eps
        or _point_segment_distance(sx, sy, px, py, qx, qy) <= eps
    ):
        return False
    o1 = _orient(px, py, qx, qy, rx, ry)
    o2 = _orient(px, py, qx, qy, sx, sy)
    o3 = _orient(rx, ry, sx, sy, px, py)
    o4 = _orient(rx, ry, sx, sy, qx, qy)
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
    lo = _loop_index(so, no)
    ox0, ox1, oy0, oy1 = _bbox(xo, no)
    for i in range(nv):
        px = xv[i, 0]
        py = xv[i, 1]
        if px < ox0 - eps or px > ox1 + eps or py < oy0 - eps or py > oy1 + eps:
            continue
        on = False
        near = np.inf
        near_e = -1
        for f in range(no):
            f1 = _next_vertex(f, so, lo)
            d = _point_segment_distance(px, py, xo[f, 0], xo[f, 1], xo[f1, 0], xo[f1, 1])
            if d <= eps:
                out_on.append((i, f, d))
                on = True
            if d < near:
                near = d
                near_e = f
        if not on and _inside(px, py, xo, so):
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
    la = _loop_index(sa, na)
    lb = _loop_index(sb, nb)
    for e in range(na):
        e1 = _next_vertex(e, sa, la)
        px, py, qx, qy = xa[e, 0], xa[e, 1], xa[e1, 0], xa[e1, 1]
        for f in range(nb):
            f1 = _next_vertex(f, sb, lb)
            rx, ry, sx, sy = xb[f, 0], xb[f, 1], xb[f1, 0], xb[f1, 1]
            if max(rx, sx) < min(px, qx) or min(rx, sx) > max(px, qx):
                continue
            if max(ry, sy) < min(py, qy) or min(ry, sy) > max(py, qy):
                continue
            if _segments_cross(px, py, qx, qy, rx, ry, sx, sy, eps):
                o1 = _orient(px, py, qx, qy, rx, ry)
                o2 = _orient(px, py, qx, qy, sx, sy)
                t = o1 / (o1 - o2)
                cross.append((e, f, rx + t * (sx - rx), ry + t * (sy - ry)))
    return a_on, b_on, a_in, b_in, cross
