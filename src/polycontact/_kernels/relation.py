"""Kernels: the relation of two polygonal regions (separate, contact, penetrating).

Both bodies come in the packed form of :attr:`polycontact.Shape.packed`: ``xy`` (V, 2)
float64 with every loop stacked, ``starts`` (L+1,) int64. Loops are oriented so that the
interior is on the left of every edge (outer counter-clockwise, holes clockwise).
:func:`oriented_state` also takes an orientation sign per body (``-1.0``: the interior
is on the right of every edge), so a raw clockwise ring can be classified without a
copy.

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

from .jit import njit
from .cones import cones_overlap, pair_point
from .packs import (STACK_FLOATS, STACK_VERTICES, stack_floats, state_scratch, state_scratch_views,
                    unpack_shape)
from .primitives import bbox, closest_on_segment, orient
from .sweep import sort_into, window_edges


#: The states the state kernels return.
SEPARATE = 0
CONTACT = 1
PENETRATING = 2


@njit(cache=True, nogil=True)
def point_inside(px, py, xy, starts):
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
def _untouched_inside(xv, sv, touch, offset, xo, so, x0, x1, y0, y1):
    """Is the first untouched vertex of some loop of one body strictly inside the other?"""
    for k in range(sv.shape[0] - 1):
        for i in range(sv[k], sv[k + 1]):
            if not touch[offset + i]:
                x = xv[i, 0]
                y = xv[i, 1]
                if x0 <= x <= x1 and y0 <= y <= y1 and point_inside(x, y, xo, so):
                    return True
                break
    return False


#: Pairs with at most this many (A edge, B edge) combinations in the common window are
#: tested all against all; above it the edges are sorted and swept in x.
_ALL_PAIRS = 256


def _edge_pair_test(xa, xb, na, ga, a1, gb, b1, eps, touch):
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
    o1 = orient(px, py, qx, qy, rx, ry)
    o2 = orient(px, py, qx, qy, sx, sy)
    if o1 * o2 > 0.0:
        ta2 = eps * eps * ((qx - px) * (qx - px) + (qy - py) * (qy - py))
        if o1 * o1 > ta2 and o2 * o2 > ta2:
            return 0  # B's edge strictly on one side of A's edge line
    o3 = orient(rx, ry, sx, sy, px, py)
    o4 = orient(rx, ry, sx, sy, qx, qy)
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


_edge_pair = njit(cache=True, nogil=True)(_edge_pair_test)
# Inlined into :func:`moved_state`, which calls it for each pair of edges in its window.
_edge_pair_inlined = njit(nogil=True, _nrt=False, inline="always")(_edge_pair_test)


@njit(cache=True, nogil=True)
def oriented_state(xa, sa, fa, xb, sb, fb, eps):
    """State of A against B; ``fa``/``fb`` = +1.0 or -1.0 (interior left/right).

    :func:`state_in` with scratch allocated only for the pairs its early exits leave
    (an allocation costs as much as a small pair's test).
    """
    na = sa[sa.shape[0] - 1]
    nb = sb[sb.shape[0] - 1]
    apart, ba, bb = _early_exit(xa, na, xb, nb, eps)
    if apart:
        return SEPARATE
    return _overlap_state(xa, sa, fa, xb, sb, fb, eps, ba, bb, state_scratch(na + nb))


# Inlined: as a call (a tuple of tuples returned) it slows the World's pairs down.
@njit(cache=True, nogil=True, inline="always")
def _early_exit(xa, na, xb, nb, eps):
    """``(apart, box of A, box of B)``: apart when the boxes are more than eps apart or
    :func:`_apart` proves the bodies are."""
    ba = bbox(xa, na)
    bb = bbox(xb, nb)
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


# Inlined into its callers: a call that passes a dozen arrays costs more than the early
# exits it makes, on the World's candidate pairs.
@njit(cache=True, nogil=True, inline="always")
def state_in(xa, sa, fa, xb, sb, fb, eps, scratch):
    """:func:`oriented_state` with the state kernel's ``scratch`` (the buffers of
    :func:`polycontact._kernels.packs.state_scratch`, sized for at least the vertices of
    both bodies), so a loop over many pairs allocates nothing per pair.

    Pairs whose boxes are more than eps apart, or that :func:`_apart` proves farther
    apart than eps, are separate at once; the others take :func:`_overlap_state`.
    """
    na = sa[sa.shape[0] - 1]
    nb = sb[sb.shape[0] - 1]
    apart, ba, bb = _early_exit(xa, na, xb, nb, eps)
    if apart:
        return SEPARATE
    return _overlap_state(xa, sa, fa, xb, sb, fb, eps, ba, bb, scratch)


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


def _overlap_test(xa, sa, fa, xb, sb, fb, eps, ba, bb, scratch):
    """The full test of :func:`state_in` (no early exit) for bodies with bounding boxes
    ``ba``, ``bb`` (``(xmin, xmax, ymin, ymax)``) that come within eps of each other."""
    box, ids, touch, rays, rord = scratch
    na = sa[sa.shape[0] - 1]
    nb = sb[sb.shape[0] - 1]
    ax0, ax1, ay0, ay1 = ba
    bx0, bx1, by0, by1 = bb
    wx0, wx1, wy0, wy1 = _window(ba, bb, eps)
    tot = na + nb
    cnt_a = window_edges(xa, sa, 0, wx0, wx1, wy0, wy1, box, ids, 0)  # rows of A's edges
    cnt = window_edges(xb, sb, na, wx0, wx1, wy0, wy1, box, ids, cnt_a)
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
        sort_into(box, cnt, order, ids[:, 3])
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
                px, py = pair_point(g, xa, xb, na)
                if cones_overlap(px, py, xa, fa, xb, fb, na,
                                 (box, ids, order, cnt, swept, maxw), eps, (rays, rord)):
                    return PENETRATING
    # (2) one untouched vertex per loop, strictly inside the other body
    if _untouched_inside(xa, sa, touch, 0, xb, sb, bx0, bx1, by0, by1):
        return PENETRATING
    if _untouched_inside(xb, sb, touch, na, xa, sa, ax0, ax1, ay0, ay1):
        return PENETRATING
    return CONTACT if any_touch else SEPARATE


_overlap_state = njit(cache=True, nogil=True, _nrt=False)(_overlap_test)


# The same test inlined, for the state kernel of one pair of Shapes
# (:func:`relate_shapes_into`): a call with its arguments is a sizeable part of the time
# a pair of small shapes takes. The kernels that loop over many pairs call it: inlined
# into each of them it would multiply their compile time.
_overlap_state_inlined = njit(nogil=True, _nrt=False, inline="always")(_overlap_test)


#: The witnesses :func:`moved_state` gives of a penetration: none (the state kernel
#: decided), two edges that cross, a vertex of A inside B, a vertex of B inside A.
NO_WITNESS = 0
CROSSING = 1
A_INSIDE = 2
B_INSIDE = 3


@njit(cache=True, nogil=True, _nrt=False)
def moved_state(a, b, dx, dy, eps, moved, scratch):
    """Whether A moved by (dx, dy) penetrates B, as :func:`state_in` decides it, and
    why: ``(penetrating, witness, i, j)``, the witness :data:`CROSSING` (A's edge i
    and B's edge j cross properly), :data:`A_INSIDE` (A's vertex i lies inside B, no
    edge within ``eps``), :data:`B_INSIDE` (B's vertex j inside A) or
    :data:`NO_WITNESS`; :func:`witness_holds` tells whether it still holds at another
    translation.

    ``a`` = ``(xa, sa, ea, nxa, box)``: A's packed loops (interior on the left), its
    :func:`polycontact._kernels.primitives.edge_rows` table and successors, its bounding
    box; ``b`` likewise. ``moved`` (shaped like ``xa``) receives A moved; ``scratch`` is
    the state kernel's (:func:`polycontact._kernels.packs.scratch_floats` of both
    bodies' vertices). For the translations of one pair the edge boxes come from the
    tables (a translation shifts them exactly: rounding is monotonic), not from the
    coordinates; the edges whose boxes meet the common window are tested all against
    all, as :func:`_overlap_test` does. A touch (an end within ``eps`` of the other
    edge), or more pairs of edges in the window than :data:`_ALL_PAIRS`, is left to
    :func:`_overlap_test`, so the verdict is the state kernel's in every case.
    """
    xa, sa, ea, nxa, ba = a
    xb, sb, eb, nxb, bb = b
    m = xa.shape[0]
    nb = xb.shape[0]
    for i in range(m):
        moved[i, 0] = xa[i, 0] + dx
        moved[i, 1] = xa[i, 1] + dy
    bm = (ba[0] + dx, ba[1] + dx, ba[2] + dy, ba[3] + dy)
    if _boxes_apart(bm, bb, eps):
        return False, NO_WITNESS, -1, -1
    wx0, wx1, wy0, wy1 = _window(bm, bb, eps)
    views = state_scratch_views(scratch, m + nb)
    box, ids, touch = views[0], views[1], views[2]
    ca = 0
    for i in range(m):
        x0 = ea[i, 3] + dx
        x1 = ea[i, 4] + dx
        y0 = ea[i, 5] + dy
        y1 = ea[i, 6] + dy
        box[ca, 0] = x0 - eps
        box[ca, 1] = x1 + eps
        box[ca, 2] = y0 - eps
        box[ca, 3] = y1 + eps
        ids[ca, 0] = i
        ca += not (x1 < wx0 or x0 > wx1 or y1 < wy0 or y0 > wy1)
    c = ca
    for j in range(nb):
        box[c, 0] = eb[j, 3]
        box[c, 1] = eb[j, 4]
        box[c, 2] = eb[j, 5]
        box[c, 3] = eb[j, 6]
        ids[c, 0] = j
        c += not (eb[j, 4] < wx0 or eb[j, 3] > wx1 or eb[j, 6] < wy0 or eb[j, 5] > wy1)
    if ca * (c - ca) > _ALL_PAIRS:
        return (_overlap_state(moved, sa, 1.0, xb, sb, 1.0, eps, bm, bb, views) == PENETRATING,
                NO_WITNESS, -1, -1)
    touch[:m + nb] = False
    for p in range(ca):
        i = ids[p, 0]
        for q in range(ca, c):
            if (box[q, 0] > box[p, 1] or box[q, 1] < box[p, 0] or box[q, 2] > box[p, 3]
                    or box[q, 3] < box[p, 2]):
                continue
            j = ids[q, 0]
            met = _edge_pair_inlined(moved, xb, m, i, nxa[i], m + j, m + nxb[j], eps, touch)
            if met == 1:  # a touch: the cones decide
                return (_overlap_state(moved, sa, 1.0, xb, sb, 1.0, eps, bm, bb, views)
                        == PENETRATING, NO_WITNESS, -1, -1)
            if met == 2:
                return True, CROSSING, i, j
    # (2) of the state test: the first vertex of each loop (none touches), inside
    for k in range(sa.shape[0] - 1):
        x = moved[sa[k], 0]
        y = moved[sa[k], 1]
        if bb[0] <= x <= bb[1] and bb[2] <= y <= bb[3] and point_inside(x, y, xb, sb):
            return True, A_INSIDE, sa[k], -1
    for k in range(sb.shape[0] - 1):
        x = xb[sb[k], 0]
        y = xb[sb[k], 1]
        if bm[0] <= x <= bm[1] and bm[2] <= y <= bm[3] and point_inside(x, y, moved, sa):
            return True, B_INSIDE, -1, sb[k]
    return False, NO_WITNESS, -1, -1


@njit(cache=True, nogil=True, _nrt=False)
def witness_holds(a, b, dx, dy, eps, witness, i, j, moved, touch):
    """Whether a witness of :func:`moved_state` makes A moved by (dx, dy) penetrate B
    as :func:`state_in` decides it: the two edges still cross properly, or the vertex
    still lies inside the other body with no edge within ``eps`` (computed as the state
    kernel would, from A's rows moved into ``moved``; ``touch``: room for a flag per
    vertex of both bodies). A proper crossing, or a vertex so inside, is a penetration
    whatever else the bodies do there."""
    xa, sa, _, nxa, _ = a
    xb, sb, _, nxb, _ = b
    m = xa.shape[0]
    for r in range(m):
        moved[r, 0] = xa[r, 0] + dx
        moved[r, 1] = xa[r, 1] + dy
    if witness == CROSSING:
        return _edge_pair_inlined(moved, xb, m, i, nxa[i], m + j, m + nxb[j], eps, touch) == 2
    if witness == A_INSIDE:
        return _deep_inside(moved[i, 0], moved[i, 1], xb, sb, nxb, eps)
    if witness == B_INSIDE:
        return _deep_inside(xb[j, 0], xb[j, 1], moved, sa, nxa, eps)
    return False


@njit(cache=True, nogil=True, inline="always")
def _deep_inside(px, py, xo, so, nxo, eps):
    """Whether (px, py) lies inside O with none of O's edges within ``eps``."""
    e2 = eps * eps
    for f in range(xo.shape[0]):
        g = nxo[f]
        if closest_on_segment(px, py, xo[f, 0], xo[f, 1], xo[g, 0], xo[g, 1])[2] <= e2:
            return False
    return point_inside(px, py, xo, so)


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
    return oriented_state(xa, sa, 1.0, xb, sb, 1.0, eps)


# Compiled without Numba's reference counting (``_nrt=False``): the counts of the
# arrays it is called with and passes on cost as much as the test of a small separate
# pair. Nothing in it allocates: the scratch is on its stack (a buffer passed in would
# cost a thread-local look-up and one more array to unbox per call). It takes one bytes
# object per shape (see PACK_HEAD) and reads the bounding boxes and tolerance terms
# cached in them.
@njit(cache=True, nogil=True, _nrt=False)
def relate_shapes_into(pa, pb, eps):
    """:func:`relate_state` of two shapes given by their kernel packs (``Shape._kernel``),
    allocating nothing (its scratch is on the stack).

    ``eps`` below 0 means the default tolerance of the pair: the larger of the two
    shapes' terms held in their packs (``Shape._tolerance``, hence
    :func:`polycontact.default_tolerance` of the pair). Returns -1 (and computes
    nothing) for a pair that needs the scratch and has more than
    :data:`STACK_VERTICES` vertices in all.

    The boxes are those of the packs; they equal :func:`bbox` of the coordinates (a
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
    xa, sa, ba, ta = unpack_shape(pa)
    xb, sb, bb, tb = unpack_shape(pb)
    if eps < 0.0:
        eps = max(ta, tb)
    na = sa[sa.shape[0] - 1]
    nb = sb[sb.shape[0] - 1]
    if _boxes_apart(ba, bb, eps) or _apart(xa, na, xb, nb, ba, bb, eps):
        return SEPARATE
    if na + nb > STACK_VERTICES:
        return -1
    scratch = state_scratch_views(stack_floats(STACK_FLOATS), na + nb)
    return _overlap_state_inlined(xa, sa, 1.0, xb, sb, 1.0, eps, ba, bb, scratch)
