"""Kernels: the exact fits and slides of a no-fit polygon.

The positions inside ``E`` where the interiors do not overlap, ``int(E) \\ O``: points
of the sums' boundaries covered by no open sum, yet surrounded on every side by closed
ones. :func:`degenerate_contacts` finds candidates among the loose parts of
:func:`polycontact._kernels.outline.edge_cover`, :func:`exact_candidates` makes them
exact (snapped to vertices and crossings of the sums, slides merged), and
:func:`touching_contacts` keeps those where A placed there touches B without
overlapping.
"""

from __future__ import annotations

import numpy as np

from .jit import njit
from .cells import listed, polygon_grid, segment_cells, segment_grid
from .minkowski import GRID_MIN_SUMS, in_some_listed
from .primitives import append_part
from .relation import relate_state


@njit(cache=True, nogil=True)
def _arc_of(px, py, fr, s, e, eps):
    """Directions from p entering polygon s:e (edge frames ``fr``): (kind, start, length).

    kind 0: p is not within eps of the polygon; 1: p inside by more than eps (every
    direction); 2: the arc [start, start + length] of entering directions.
    """
    n_act = 0
    th1 = 0.0
    smax = -np.inf
    emin = np.inf
    for i in range(s, e):
        if fr[i, 3] == 0.0:
            continue
        ux = fr[i, 0]
        uy = fr[i, 1]
        f = ux * py - uy * px - fr[i, 2]
        if f < -eps:
            return 0, 0.0, 0.0
        if f > eps:
            continue
        th = np.arctan2(uy, ux)
        if n_act == 0:
            th1 = th
        rel = th - th1
        while rel > np.pi:
            rel -= 2.0 * np.pi
        while rel <= -np.pi:
            rel += 2.0 * np.pi
        smax = max(smax, rel)
        emin = min(emin, rel + np.pi)
        n_act += 1
    if n_act == 0:
        return 1, 0.0, 2.0 * np.pi
    if emin < smax:
        return 0, 0.0, 0.0
    start = th1 + smax
    while start < 0.0:
        start += 2.0 * np.pi
    while start >= 2.0 * np.pi:
        start -= 2.0 * np.pi
    return 2, start, emin - smax


@njit(cache=True, nogil=True)
def surrounded(px, py, starts, bb, fr, eps, ang_tol):
    """Whether the closed sums cover every direction around p (p is inside E).

    ``bb``: the sums' bounding boxes (:func:`polycontact._kernels.minkowski.boxes`);
    ``fr``: their edge frames
    (:func:`polycontact._kernels.minkowski.frames`).
    """
    k = starts.shape[0] - 1
    return _surrounded(px, py, np.arange(k), starts, bb, fr, eps, ang_tol, np.empty((2, k)))


@njit(cache=True, nogil=True)
def _surrounded(px, py, listed, starts, bb, fr, eps, ang_tol, arcs):
    """:func:`surrounded` among the sums ``listed`` (every sum within eps of p), with a
    work array ``arcs`` (2, number of sums), for callers asking about many points."""
    n = 0
    for p in listed:
        if px < bb[p, 0] - eps or px > bb[p, 2] + eps or py < bb[p, 1] - eps or py > bb[p, 3] + eps:
            continue
        kind, st, ln = _arc_of(px, py, fr, starts[p], starts[p + 1], eps)
        if kind == 1:
            return True
        if kind == 2:
            # kept sorted by start (insertion: a few arcs; the order among equal starts
            # does not change the sweep's answer)
            i = n
            while i > 0 and arcs[0, i - 1] > st:
                arcs[0, i] = arcs[0, i - 1]
                arcs[1, i] = arcs[1, i - 1]
                i -= 1
            arcs[0, i] = st
            arcs[1, i] = ln
            n += 1
    if n == 0:
        return False
    first = arcs[0, 0]
    reach = first
    for rep in range(2):
        for oi in range(n):
            st = arcs[0, oi] + 2.0 * np.pi * rep
            if st > reach + ang_tol:
                return False
            reach = max(reach, st + arcs[1, oi])
            if reach >= first + 2.0 * np.pi - ang_tol:
                return True
    return reach >= first + 2.0 * np.pi - ang_tol


@njit(cache=True, nogil=True)
def may_be_surrounded(px, py, vx, vy, starts, bb, fr, eps, ang_tol):
    """False only where :func:`surrounded` is False, at a fraction of its cost (no
    angles): no sum near p (within its box, not outside it by more than eps) enters
    direction v (any non-zero vector; (1, 0) when v is zero), within an angle well
    above ``ang_tol``.

    Why: surrounded(p) holds when some sum holds p inside by more than eps (it has no
    edge within eps of p, and enters every direction), or when the arcs of entering
    directions of the sums around p leave no gap wider than ``ang_tol``; then v is
    within ``ang_tol`` of the arc of some sum s, the intersection of the half-turns
    {d : cross(u, d) >= 0} of the edges u of s within eps of p, so cross(u, v) >=
    -sin(ang_tol) for each of them (unit u and v) and s passes here, where the same
    tests tell which sums are near and which edges within eps.
    """
    return _may_be_surrounded(px, py, vx, vy, np.arange(starts.shape[0] - 1), starts, bb,
                              fr, eps, ang_tol)


@njit(cache=True, nogil=True)
def _may_be_surrounded(px, py, vx, vy, listed, starts, bb, fr, eps, ang_tol):
    """:func:`may_be_surrounded` among the sums ``listed`` (every sum within eps of p)."""
    ln = np.hypot(vx, vy)
    if ln > 0.0:
        vx /= ln
        vy /= ln
    else:
        vx = 1.0
        vy = 0.0
    # (the arcs' angles and these products are rounded: 1e-15 of a turn and a unit)
    slack = 2.0 * ang_tol + 1e-15
    for q in listed:
        if px < bb[q, 0] - eps or px > bb[q, 2] + eps or py < bb[q, 1] - eps or py > bb[q, 3] + eps:
            continue
        enters = True
        for i in range(starts[q], starts[q + 1]):
            if fr[i, 3] == 0.0:
                continue
            f = fr[i, 0] * py - fr[i, 1] * px - fr[i, 2]
            if f < -eps or (f <= eps and fr[i, 0] * vy - fr[i, 1] * vx < -slack):
                enters = False
                break
        if enters:
            return True
    return False


@njit(cache=True, nogil=True)
def _sums_near(near, ax, ay, bx, by, eps, every, marks):
    """The sums listed in the cells of the grid ``near``
    (:func:`polycontact._kernels.cells.polygon_grid`) that the eps-neighbourhood of
    segment ab meets, each once (``every`` sum when the cells do not fit the buffer);
    ``marks`` = ``(cells, seen, out)``: buffers, ``seen[k]`` counting the calls."""
    cells, seen, out = marks
    nc = segment_cells(near, ax, ay, bx, by, eps, cells)
    if nc < 0:
        return every
    k = seen.shape[0] - 1
    stamp = seen[k] = seen[k] + 1
    first, items = near[5], near[6]
    n = 0
    for ci in range(nc):
        for u in range(first[cells[ci]], first[cells[ci] + 1]):
            q = items[u]
            if seen[q] != stamp:
                seen[q] = stamp
                out[n] = q
                n += 1
    return out[:n]


@njit(cache=True, nogil=True)
def degenerate_contacts(xy, starts, bb, fr, loose, eps, ang_tol):
    """Exact-fit points and slide segments among the ``loose`` parts of
    :func:`polycontact._kernels.outline.edge_cover`.

    A loose part is an exact fit (when shorter than 8 eps) or a slide where the closed
    sums cover every direction around it (``ang_tol``: angular gap taken as closed);
    around a short part, the direction to the right of it (away from its own sum) is
    tried first (:func:`may_be_surrounded`: most are vertices of the outline).
    A part is cut at the sums' vertices lying on it; a sub-part whose right side (the
    side away from its own sum) is in no sum is outline and skipped at once. Returns
    ``(points (P, 2), segments (S, 4))``, not deduplicated: the same exact fit is found
    on every edge through it, a slide on the edges of both sides.
    """
    pts = np.empty((loose.shape[0], 2))
    slides = np.empty((loose.shape[0], 4))
    n_pts = 0
    n_slides = 0
    k = starts.shape[0] - 1
    arcs = np.empty((2, k))
    # the sums that may hold a point or pass within eps of it: those listed in its cell
    # (every sum, for few)
    every = np.arange(k)
    grid = k >= GRID_MIN_SUMS and loose.shape[0] > 0
    near = polygon_grid(xy, starts, bb, eps, xy.shape[0] + 16 * k) if grid else (
        polygon_grid(xy[:0], starts[:1], bb, eps, 1))
    marks = (np.empty(3 * (near[3] + near[4]) + 8, np.int64), np.full(k + 1, -1, np.int64),
             np.empty(k, np.int64))
    ts = np.empty(xy.shape[0] + 2)
    off = 64.0 * eps
    for r in range(loose.shape[0]):
        ax, ay, bx, by = loose[r, 0], loose[r, 1], loose[r, 2], loose[r, 3]
        ln = np.hypot(bx - ax, by - ay)
        if ln <= 8.0 * eps:
            mx = 0.5 * (ax + bx)
            my = 0.5 * (ay + by)
            there = listed(near, mx, my) if grid else every
            if _may_be_surrounded(mx, my, by - ay, ax - bx, there, starts, bb, fr, eps,
                                  ang_tol) and (
                    _surrounded(mx, my, there, starts, bb, fr, eps, ang_tol, arcs)):
                pts[n_pts, 0] = mx
                pts[n_pts, 1] = my
                n_pts += 1
            continue
        ux = (bx - ax) / ln
        uy = (by - ay) / ln
        # the cuts: both ends and the sums' vertices on the part, sorted (insertion)
        ts[0] = 0.0
        ts[1] = ln
        nt = 2
        x0 = min(ax, bx) - eps
        x1 = max(ax, bx) + eps
        y0 = min(ay, by) - eps
        y1 = max(ay, by) + eps
        for q in _sums_near(near, ax, ay, bx, by, eps, every, marks) if grid else every:
            if bb[q, 0] > x1 or bb[q, 2] < x0 or bb[q, 1] > y1 or bb[q, 3] < y0:
                continue
            for v in range(starts[q], starts[q + 1]):
                if xy[v, 0] < x0 or xy[v, 0] > x1 or xy[v, 1] < y0 or xy[v, 1] > y1:
                    continue
                dx = xy[v, 0] - ax
                dy = xy[v, 1] - ay
                if abs(ux * dy - uy * dx) <= eps:
                    t = ux * dx + uy * dy
                    if 0.0 < t < ln:
                        i = nt
                        while i > 1 and ts[i - 1] > t:
                            ts[i] = ts[i - 1]
                            i -= 1
                        ts[i] = t
                        nt += 1
        open_at = -1.0
        for q in range(nt - 1):
            t0 = ts[q]
            t1 = ts[q + 1]
            if t1 - t0 <= eps:
                continue
            tm = 0.5 * (t0 + t1)
            mx = ax + tm * ux
            my = ay + tm * uy
            qx = mx + off * uy
            qy = my - off * ux
            inside = (in_some_listed(qx, qy, listed(near, qx, qy) if grid else every, starts,
                                     bb, fr, -1.0, -1)
                      and _surrounded(mx, my, listed(near, mx, my) if grid else every, starts,
                                      bb, fr, eps, ang_tol, arcs))
            if inside and open_at < 0.0:
                open_at = t0
            if not inside and open_at >= 0.0:
                slides, n_slides = append_part(slides, n_slides, ax, ay, ux, uy, open_at, t0)
                open_at = -1.0
        if open_at >= 0.0:
            slides, n_slides = append_part(slides, n_slides, ax, ay, ux, uy, open_at, ln)
            slides[n_slides - 1, 2] = bx  # (the part's end exactly)
            slides[n_slides - 1, 3] = by
    return pts[:n_pts], slides[:n_slides]


@njit(cache=True, nogil=True)
def snap(points, along, xy, starts, tol):
    """Candidate positions made exact (a copy of ``points`` (P, 2) is returned).

    Each point goes to the nearest vertex of the sums within ``tol``; else to the
    nearest crossing within ``tol`` of a line through it with a sum edge passing within
    ``tol``: the line along ``along[k]`` (a slide's direction) or, where that is zero
    (an exact fit), the line of the nearest such edge. Points with neither stay. Ties
    go to the last vertex or edge in the sums' order. The vertices and edges near each
    point are read from a grid of cells (:mod:`polycontact._kernels.cells`), so the cost
    follows the points and the sums' edges, not their product.
    """
    out = points.copy()
    nv = xy.shape[0]
    if points.shape[0] == 0 or nv == 0:
        return out
    nxt = np.empty(nv, np.int64)
    for k in range(starts.shape[0] - 1):
        for i in range(starts[k], starts[k + 1]):
            nxt[i] = i + 1 if i + 1 < starts[k + 1] else starts[k]
    # the vertices (each a segment of length 0, numbered i), then the edges (nv + i),
    # that reach the points' box; listed in the cells within twice tol (the rounding
    # of the cells' bounds is far below it)
    x0 = points[:, 0].min() - tol
    x1 = points[:, 0].max() + tol
    y0 = points[:, 1].min() - tol
    y1 = points[:, 1].max() + tol
    reach = np.empty(2 * nv, np.bool_)
    for s in range(2 * nv):
        i = s if s < nv else s - nv
        j = i if s < nv else nxt[i]
        reach[s] = not (max(xy[i, 0], xy[j, 0]) < x0 or min(xy[i, 0], xy[j, 0]) > x1
                        or max(xy[i, 1], xy[j, 1]) < y0 or min(xy[i, 1], xy[j, 1]) > y1)
    ids = np.flatnonzero(reach)
    seg = np.empty((ids.shape[0], 4))
    for n in range(ids.shape[0]):
        i = ids[n] if ids[n] < nv else ids[n] - nv
        j = i if ids[n] < nv else nxt[i]
        seg[n, 0] = xy[i, 0]
        seg[n, 1] = xy[i, 1]
        seg[n, 2] = xy[j, 0]
        seg[n, 3] = xy[j, 1]
    grid = segment_grid(seg, points, 2.0 * tol)
    for k in range(points.shape[0]):
        px = points[k, 0]
        py = points[k, 1]
        near = ids[listed(grid, px, py)]  # vertices (< nv), then edges (nv + i)
        best = tol
        bi = -1
        for s in near:
            if s >= nv:
                break
            d = np.hypot(xy[s, 0] - px, xy[s, 1] - py)
            if d <= best:
                best = d
                bi = s
        if bi >= 0:
            out[k, 0] = xy[bi, 0]
            out[k, 1] = xy[bi, 1]
            continue
        # the edge nearest to p, among those within tol
        near_e = -1
        near_d = tol
        for s in near:
            if s < nv:
                continue
            i = s - nv
            j = nxt[i]
            ux = xy[j, 0] - xy[i, 0]
            uy = xy[j, 1] - xy[i, 1]
            ln2 = ux * ux + uy * uy
            if ln2 == 0.0:
                continue
            t = min(1.0, max(0.0, ((px - xy[i, 0]) * ux + (py - xy[i, 1]) * uy) / ln2))
            d = np.hypot(xy[i, 0] + t * ux - px, xy[i, 1] + t * uy - py)
            if d <= near_d:
                near_d = d
                near_e = i
        ax_ = along[k, 0]
        ay_ = along[k, 1]
        if ax_ == 0.0 and ay_ == 0.0:
            if near_e < 0:
                continue
            bx_ = xy[near_e, 0]
            by_ = xy[near_e, 1]
            ax_ = xy[nxt[near_e], 0] - bx_
            ay_ = xy[nxt[near_e], 1] - by_
        else:
            bx_ = px
            by_ = py
        la = np.hypot(ax_, ay_)
        ax_ /= la
        ay_ /= la
        best = tol
        for s in near:
            if s < nv:
                continue
            i = s - nv
            j = nxt[i]
            ux = xy[j, 0] - xy[i, 0]
            uy = xy[j, 1] - xy[i, 1]
            ln = np.hypot(ux, uy)
            if ln == 0.0:
                continue
            t = min(1.0, max(0.0, ((px - xy[i, 0]) * ux + (py - xy[i, 1]) * uy) / (ln * ln)))
            if np.hypot(xy[i, 0] + t * ux - px, xy[i, 1] + t * uy - py) > tol:
                continue
            wx = ux / ln
            wy = uy / ln
            den = ax_ * wy - ay_ * wx
            if abs(den) < 1e-6:
                continue
            s_ = ((xy[i, 0] - bx_) * wy - (xy[i, 1] - by_) * wx) / den
            qx = bx_ + s_ * ax_
            qy = by_ + s_ * ay_
            d = np.hypot(qx - px, qy - py)
            if d <= best:
                best = d
                out[k, 0] = qx
                out[k, 1] = qy
    return out


@njit(cache=True, nogil=True)
def merge_collinear(segs, tol):
    """Segments (S, 4) merged where they lie on one line and overlap or meet (within tol).

    Each result runs from its lexicographically smaller end. Segments shorter than
    ``tol`` are dropped.
    """
    n = segs.shape[0]
    s = segs.copy()
    for r in range(n):
        if (s[r, 2], s[r, 3]) < (s[r, 0], s[r, 1]):
            s[r, 0], s[r, 1], s[r, 2], s[r, 3] = s[r, 2], s[r, 3], s[r, 0], s[r, 1]
    keep = np.ones(n, np.bool_)
    for r in range(n):
        if np.hypot(s[r, 2] - s[r, 0], s[r, 3] - s[r, 1]) <= tol:
            keep[r] = False
    changed = True
    while changed:
        changed = False
        for r in range(n):
            if not keep[r]:
                continue
            ln = np.hypot(s[r, 2] - s[r, 0], s[r, 3] - s[r, 1])
            ux = (s[r, 2] - s[r, 0]) / ln
            uy = (s[r, 3] - s[r, 1]) / ln
            for q in range(n):
                if q == r or not keep[q]:
                    continue
                # both ends of q on r's line?
                d0 = ux * (s[q, 1] - s[r, 1]) - uy * (s[q, 0] - s[r, 0])
                d1 = ux * (s[q, 3] - s[r, 1]) - uy * (s[q, 2] - s[r, 0])
                if abs(d0) > tol or abs(d1) > tol:
                    continue
                t0 = ux * (s[q, 0] - s[r, 0]) + uy * (s[q, 1] - s[r, 1])
                t1 = ux * (s[q, 2] - s[r, 0]) + uy * (s[q, 3] - s[r, 1])
                lo = min(t0, t1)
                hi = max(t0, t1)
                if hi < -tol or lo > ln + tol:
                    continue
                # merge q into r: the extreme ends along r's direction
                if lo < 0.0:
                    if t0 <= t1:
                        s[r, 0], s[r, 1] = s[q, 0], s[q, 1]
                    else:
                        s[r, 0], s[r, 1] = s[q, 2], s[q, 3]
                if hi > ln:
                    if t1 >= t0:
                        s[r, 2], s[r, 3] = s[q, 2], s[q, 3]
                    else:
                        s[r, 2], s[r, 3] = s[q, 0], s[q, 1]
                keep[q] = False
                changed = True
                ln = np.hypot(s[r, 2] - s[r, 0], s[r, 3] - s[r, 1])
    return s[keep].copy()


@njit(cache=True, nogil=True)
def exact_candidates(cand, n_pts, sums, starts, snap_tol, near):
    """Candidates (C, 4) of :func:`polycontact._kernels.nfp.entrance_region` (its
    ``n_pts`` exact fits first)
    made exact: each snapped to the sums' vertices or edge crossings within ``snap_tol``
    (:func:`snap`; a slide's ends along the slide), the slides then merged where
    collinear (:func:`merge_collinear` within ``near``) and sorted by their ends; the
    exact fits stay first, as points repeated."""
    pts = snap(cand[:n_pts, :2].copy(), np.zeros((n_pts, 2)), sums, starts, snap_tol)
    ns = cand.shape[0] - n_pts
    ends = np.empty((2 * ns, 2))
    along = np.empty((2 * ns, 2))
    for k in range(ns):
        row = cand[n_pts + k]
        for e in range(2):
            ends[2 * k + e, 0] = row[2 * e]
            ends[2 * k + e, 1] = row[2 * e + 1]
            along[2 * k + e, 0] = row[2] - row[0]
            along[2 * k + e, 1] = row[3] - row[1]
    merged = merge_collinear(snap(ends, along, sums, starts, snap_tol).reshape(-1, 4), near)
    # sorted by (x0, y0, x1, y1), stably (insertion: a few slides)
    order = np.arange(merged.shape[0])
    for i in range(1, order.shape[0]):
        j = i
        while j > 0 and (merged[order[j], 0], merged[order[j], 1], merged[order[j], 2],
                         merged[order[j], 3]) < (merged[order[j - 1], 0],
                                                 merged[order[j - 1], 1],
                                                 merged[order[j - 1], 2],
                                                 merged[order[j - 1], 3]):
            order[j], order[j - 1] = order[j - 1], order[j]
            j -= 1
    out = np.empty((n_pts + merged.shape[0], 4))
    for k in range(n_pts):
        out[k, 0] = out[k, 2] = pts[k, 0]
        out[k, 1] = out[k, 3] = pts[k, 1]
    for k in range(merged.shape[0]):
        out[n_pts + k] = merged[order[k]]
    return out


@njit(cache=True, nogil=True)
def touching(points, segs, xa, sa, xb, sb, a0x, a0y, tol):
    """Whether A (packed ``xa``, ``sa``) moved so that its reference ``(a0x, a0y)`` is at
    each point (P, 2), and at the middle and both ends of each segment (S, 4), touches B
    without overlapping (:func:`polycontact._kernels.relation.relate_state` is 1,
    contact, within ``tol``): ``(points' (P,), segments' (S,))`` bool arrays."""
    moved = np.empty_like(xa)
    at_pts = np.empty(points.shape[0], np.bool_)
    for k in range(points.shape[0]):
        at_pts[k] = _touches_at(points[k, 0], points[k, 1], moved, xa, sa, xb, sb, a0x, a0y,
                                tol)
    at_segs = np.empty(segs.shape[0], np.bool_)
    for k in range(segs.shape[0]):
        x0, y0, x1, y1 = segs[k, 0], segs[k, 1], segs[k, 2], segs[k, 3]
        at_segs[k] = (
            _touches_at(0.5 * (x0 + x1), 0.5 * (y0 + y1), moved, xa, sa, xb, sb, a0x, a0y, tol)
            and _touches_at(x0, y0, moved, xa, sa, xb, sb, a0x, a0y, tol)
            and _touches_at(x1, y1, moved, xa, sa, xb, sb, a0x, a0y, tol))
    return at_pts, at_segs


@njit(cache=True, nogil=True)
def _touches_at(px, py, moved, xa, sa, xb, sb, a0x, a0y, tol):
    """relate_state of A moved by p - a0 (into ``moved``) against B is contact."""
    dx = px - a0x
    dy = py - a0y
    for i in range(xa.shape[0]):
        moved[i, 0] = xa[i, 0] + dx
        moved[i, 1] = xa[i, 1] + dy
    return relate_state(moved, sa, xb, sb, tol) == 1


@njit(cache=True, nogil=True)
def select_contacts(pts, pts_ok, segs, segs_ok, near):
    """The exact fits and slides kept among verified candidates, duplicates merged.

    ``pts`` (P, 2) candidate exact fits and ``segs`` (S, 4) candidate slides, with
    whether each verified (``pts_ok``, ``segs_ok``). The verified slides are kept; a
    point is dropped when it lies within ``near`` of a kept slide or of a point kept
    before it, else kept when verified. Returns ``(fits (F, 2), slides (K, 2, 2))``,
    the fits sorted by x then y.

    Examples
    --------
    >>> import numpy as np
    >>> pts = np.array([[2.0, 0.0], [0.5, 0.0], [1.0, 3.0], [1.0, 3.0 + 1e-12]])
    >>> segs = np.array([[0.0, 0.0, 1.0, 0.0]])
    >>> fits, slides = select_contacts(pts, np.ones(4, np.bool_), segs,
    ...                                np.ones(1, np.bool_), 1e-9)
    >>> fits.tolist(), slides.shape
    ([[1.0, 3.0], [2.0, 0.0]], (1, 2, 2))
    """
    ns = 0
    slides = np.empty((segs.shape[0], 2, 2))
    for k in range(segs.shape[0]):
        if segs_ok[k]:
            for e in range(2):
                slides[ns, e, 0] = segs[k, 2 * e]
                slides[ns, e, 1] = segs[k, 2 * e + 1]
            ns += 1
    slides = slides[:ns]
    on_slide = distance_to_segments(pts, slides)
    fits = np.empty((pts.shape[0], 2))
    nf = 0
    for k in range(pts.shape[0]):
        if on_slide[k] <= near:
            continue
        px = pts[k, 0]
        py = pts[k, 1]
        dup = False
        for f in range(nf):
            if np.hypot(px - fits[f, 0], py - fits[f, 1]) <= near:
                dup = True
                break
        if dup or not pts_ok[k]:
            continue
        # kept sorted by (x, y), stably (insertion: a few fits)
        i = nf
        while i > 0 and (fits[i - 1, 0] > px or (fits[i - 1, 0] == px and fits[i - 1, 1] > py)):
            fits[i, 0] = fits[i - 1, 0]
            fits[i, 1] = fits[i - 1, 1]
            i -= 1
        fits[i, 0] = px
        fits[i, 1] = py
        nf += 1
    return fits[:nf], slides


@njit(cache=True, nogil=True)
def touching_contacts(points, segs, near, xa, sa, xb, sb, a0x, a0y, tol):
    """:func:`select_contacts` of the candidates verified by :func:`touching` (A placed
    there touches B without overlapping), in one call."""
    pts_ok, segs_ok = touching(points, segs, xa, sa, xb, sb, a0x, a0y, tol)
    return select_contacts(points, pts_ok, segs, segs_ok, near)


@njit(cache=True, nogil=True)
def distance_to_segments(p, segs):
    """Distance from each point ``p`` (P, 2) to the nearest of the segments (S, 2, 2): (P,).

    Examples
    --------
    >>> import numpy as np
    >>> distance_to_segments(np.array([[0.5, 1.0], [3.0, 0.0]]),
    ...                      np.array([[[0.0, 0.0], [1.0, 0.0]]])).tolist()
    [1.0, 2.0]
    """
    out = np.full(p.shape[0], np.inf)
    for k in range(p.shape[0]):
        for m in range(segs.shape[0]):
            ax, ay = segs[m, 0, 0], segs[m, 0, 1]
            ux, uy = segs[m, 1, 0] - ax, segs[m, 1, 1] - ay
            dx, dy = p[k, 0] - ax, p[k, 1] - ay
            t = min(max((dx * ux + dy * uy) / (ux * ux + uy * uy), 0.0), 1.0)
            out[k] = min(out[k], np.hypot(dx - t * ux, dy - t * uy))
    return out
