"""Kernels: whether the open interior cones of two bodies overlap at a touch point.

Part (3) of the state decision (:mod:`polycontact._kernels.relation`): every edge of
either body within eps of the touch point gives rays leaving it; sorted by angle, each
body's interior in a direction is decided by its nearest ray clockwise of it.
"""

from __future__ import annotations

import numpy as np

from .jit import njit
from .primitives import norm, point_segment_distance


@njit(cache=True, nogil=True)
def pair_point(g, xa, xb, na):
    """Vertex g of the pair's numbering (A's vertices, then B's from ``na``)."""
    if g < na:
        return xa[g, 0], xa[g, 1]
    return xb[g - na, 0], xb[g - na, 1]


# Inlined into the state kernel: a call passes seven arrays, and in the batch pass (no
# reference counting) that call costs about as much as the test.
@njit(cache=True, nogil=True, inline="always")
def cones_overlap(px, py, xa, fa, xb, fb, na, edges, eps, ray_scratch):
    """Whether the open interior cones of A and B at the touch point p overlap.

    Every edge of either body within eps of p gives rays leaving p: along the edge from
    its near end (or both ways when p is inside the edge). A ray whose interior side is
    counter-clockwise of it is "opening"; sorted by angle, the interior of a body in a
    direction d is decided by the body's nearest ray clockwise of d (rays of one body
    alternate opening/closing around p, so holes touching the outer loop work too).
    ``edges`` is the state kernel's edge table ``(box, ids, order, cnt, swept, maxw)``:
    ``cnt`` rows of edge boxes and vertex ids; if ``swept``, ordered by ``order`` (xmin
    ascending; ``maxw`` the widest edge) and only the rows near p are read; otherwise
    every row is read. ``ray_scratch`` is ``(rays, rord)``: at least 2 cnt rows of 6,
    ``(pseudo-angle, length of the edge left from p, opening, of A, unit direction)``,
    and as many ints, their order.
    """
    box, ids, order, cnt, swept, maxw = edges
    rays, rord = ray_scratch
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
        ux, uy = pair_point(ids[i, 0], xa, xb, na)
        wx, wy = pair_point(ids[i, 1], xa, xb, na)
        if point_segment_distance(px, py, ux, uy, wx, wy) > eps:
            continue
        du = norm(px - ux, py - uy)
        dw = norm(px - wx, py - wy)
        le = norm(wx - ux, wy - uy)
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
