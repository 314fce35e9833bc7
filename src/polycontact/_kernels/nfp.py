"""Kernels for the no-fit polygon: convex Minkowski sums and exact-fit candidates.

``E(A, B)`` is the union of the convex sums ``C_ij = B_i ⊕ (a0 − A_j)`` over convex
pieces ``B_i`` of B and ``A_j`` of A. The interiors of A and B overlap exactly when the
reference point lies in the union ``O`` of the OPEN sums; ``E`` is the closure of ``O``.
The exact fits and slides are ``int(E) \\ O``: points of the sums' boundaries covered by
no open sum, yet surrounded on every side by closed ones. :func:`degenerate_contacts`
finds them: it subtracts every open sum (shrunk by ``eps``) from every boundary edge, then
keeps the remaining parts around which the closed sums cover every direction.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .decompose import ring_pieces
from .relation import relate_state
from .tolerance import tolerance_of
from .validate import closest_on_segment

#: Outline coordinates within this many units of 2**-52 of the sums' largest
#: |coordinate| of a sum vertex's coordinate are that coordinate (see :func:`tidy_rings`).
SNAP_ULPS = 4.0


@njit(cache=True, nogil=True)
def _lowest(xy, s, e):
    best = s
    for i in range(s + 1, e):
        if xy[i, 1] < xy[best, 1] or (xy[i, 1] == xy[best, 1] and xy[i, 0] < xy[best, 0]):
            best = i
    return best


@njit(cache=True, nogil=True)
def convex_sums(bxy, bstarts, rxy, rstarts):
    """Minkowski sums of every pair of convex CCW pieces, in O(p + q) each.

    ``(bxy, bstarts)`` and ``(rxy, rstarts)`` are packed convex pieces (B's and the
    reflected A's). Returns packed sums ``(xy, starts)``, counter-clockwise, ordered
    with the pieces of B outermost.
    """
    nb = bstarts.shape[0] - 1
    nr = rstarts.shape[0] - 1
    total = nr * bxy.shape[0] + nb * rxy.shape[0]
    out = np.empty((total, 2))
    starts = np.empty(nb * nr + 1, np.int64)
    starts[0] = 0
    w = 0
    k = 0
    for bi in range(nb):
        ps = bstarts[bi]
        pe = bstarts[bi + 1]
        i0 = _lowest(bxy, ps, pe)
        for rj in range(nr):
            w = sum_into(bxy, ps, pe, i0, rxy, rstarts[rj], rstarts[rj + 1], out, w)
            k += 1
            starts[k] = w
    return out[:w], starts


@njit(cache=True, nogil=True)
def _bboxes(xy, starts):
    k = starts.shape[0] - 1
    bb = np.empty((k, 4))
    for p in range(k):
        s = starts[p]
        e = starts[p + 1]
        bb[p, 0] = xy[s:e, 0].min()
        bb[p, 1] = xy[s:e, 1].min()
        bb[p, 2] = xy[s:e, 0].max()
        bb[p, 3] = xy[s:e, 1].max()
    return bb


@njit(cache=True, nogil=True)
def _frames(xy, starts):
    """Per edge of packed loops: unit direction (ux, uy), offset c, and 1 if not zero-length.

    The signed distance of p from edge i's line (positive on its left) is
    ``ux * py - uy * px - c``.
    """
    fr = np.zeros((xy.shape[0], 4))
    for k in range(starts.shape[0] - 1):
        s = starts[k]
        e = starts[k + 1]
        for i in range(s, e):
            j = i + 1 if i + 1 < e else s
            ux = xy[j, 0] - xy[i, 0]
            uy = xy[j, 1] - xy[i, 1]
            ln = np.hypot(ux, uy)
            if ln > 0.0:
                ux /= ln
                uy /= ln
                fr[i, 0] = ux
                fr[i, 1] = uy
                fr[i, 2] = ux * xy[i, 1] - uy * xy[i, 0]
                fr[i, 3] = 1.0
    return fr


@njit(cache=True, nogil=True)
def _clip(ax, ay, bx, by, fr, s, e, q_first, eps):
    """Parts of segment ab (parameter t in [0, 1]) covered by convex polygon s:e.

    ``fr`` holds the edge frames of :func:`_frames`. Returns ``(lo1, hi1, lo0, hi0)``:
    the open interval inside the polygon by more than eps (empty when lo >= hi), and the
    interval to remove from the union's outline: strictly inside, or along a collinear
    edge of the polygon that runs the other way (a seam between two sums) or the same
    way when the polygon comes first (``q_first``; the duplicate outline edge is kept
    once).
    """
    lo1 = -np.inf
    hi1 = np.inf
    lo0 = -np.inf
    hi0 = np.inf
    empty0 = False
    for i in range(s, e):
        if fr[i, 3] == 0.0:
            continue
        ux = fr[i, 0]
        uy = fr[i, 1]
        f0 = ux * ay - uy * ax - fr[i, 2]
        f1 = ux * by - uy * bx - fr[i, 2]
        df = f1 - f0
        # margin eps
        if df == 0.0:
            if f0 <= eps:
                hi1 = -np.inf
        else:
            tc = (eps - f0) / df
            if df > 0.0:
                lo1 = max(lo1, tc)
            else:
                hi1 = min(hi1, tc)
        # outline: margin 0, collinear edges handled apart
        if abs(f0) <= eps and abs(f1) <= eps:
            same = ux * (bx - ax) + uy * (by - ay) > 0.0
            if same and not q_first:
                empty0 = True
        elif df == 0.0:
            if f0 <= 0.0:
                empty0 = True
        else:
            tc = -f0 / df
            if df > 0.0:
                lo0 = max(lo0, tc)
            else:
                hi0 = min(hi0, tc)
        if lo1 >= hi1 and (empty0 or lo0 >= hi0):
            break
    if empty0:
        hi0 = -np.inf
    return lo1, hi1, lo0, hi0


@njit(cache=True, nogil=True)
def _subtract(lo, hi, n, a, b):
    """Remove the open interval (a, b) from the n closed intervals lo[:n], hi[:n]."""
    m = n
    for r in range(n):
        x = lo[r]
        y = hi[r]
        if b <= x or a >= y:
            continue
        if a >= x:
            hi[r] = a
            if b <= y:
                lo[m] = b
                hi[m] = y
                m += 1
        elif b <= y:
            lo[r] = b
        else:
            lo[r] = 1.0
            hi[r] = -1.0  # dropped
    return m


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

    ``bb``: the sums' bounding boxes (:func:`_bboxes`); ``fr``: their edge frames
    (:func:`_frames`).
    """
    k = starts.shape[0] - 1
    return _surrounded(px, py, starts, bb, fr, eps, ang_tol, np.empty((2, k)))


@njit(cache=True, nogil=True)
def _surrounded(px, py, starts, bb, fr, eps, ang_tol, arcs):
    """:func:`surrounded` with a work array ``arcs`` (2, number of sums), for callers
    asking about many points."""
    k = starts.shape[0] - 1
    n = 0
    for p in range(k):
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
def _may_be_surrounded(px, py, vx, vy, starts, bb, fr, eps, ang_tol):
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
    ln = np.hypot(vx, vy)
    if ln > 0.0:
        vx /= ln
        vy /= ln
    else:
        vx = 1.0
        vy = 0.0
    # (the arcs' angles and these products are rounded: 1e-15 of a turn and a unit)
    slack = 2.0 * ang_tol + 1e-15
    for q in range(starts.shape[0] - 1):
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


#: Sums remembered per grid cell as containing the whole cell (tried first on an edge).
_PER_CELL = 4


@njit(cache=True, nogil=True)
def _cell_cover(xy, starts, bb, fr, x0, y0, h, g):
    """For a g x g grid of cells of side h from (x0, y0): up to ``_PER_CELL`` sums that
    contain each cell (its four corners inside the closed convex sum), -1 elsewhere."""
    inside = np.zeros((g + 1, g + 1), np.bool_)
    cover = np.full((g, g, _PER_CELL), -1, np.int64)
    cnt = np.zeros((g, g), np.int64)
    for q in range(starts.shape[0] - 1):
        i0 = max(0, int(np.ceil((bb[q, 0] - x0) / h)))
        i1 = min(g, int(np.floor((bb[q, 2] - x0) / h)))
        j0 = max(0, int(np.ceil((bb[q, 1] - y0) / h)))
        j1 = min(g, int(np.floor((bb[q, 3] - y0) / h)))
        if i1 <= i0 or j1 <= j0:
            continue
        for i in range(i0, i1 + 1):
            for j in range(j0, j1 + 1):
                px = x0 + i * h
                py = y0 + j * h
                ok = True
                for e in range(starts[q], starts[q + 1]):
                    if fr[e, 3] != 0.0 and fr[e, 0] * py - fr[e, 1] * px - fr[e, 2] < 0.0:
                        ok = False
                        break
                inside[i, j] = ok
        for i in range(i0, i1):
            for j in range(j0, j1):
                if (cnt[i, j] < _PER_CELL and inside[i, j] and inside[i + 1, j]
                        and inside[i, j + 1] and inside[i + 1, j + 1]):
                    cover[i, j, cnt[i, j]] = q
                    cnt[i, j] += 1
    return cover


@njit(cache=True, nogil=True)
def edge_cover(xy, starts, bb, fr, eps):
    """Uncovered parts of the sums' edges.

    Returns ``(outline, loose)``, both (M, 4) segments x0, y0, x1, y1:
    ``outline`` are the parts in no other sum's interior and on no seam, each kept once:
    the boundary of the union, oriented with the union on its left; ``loose`` are the
    parts in no other open sum shrunk by eps, where exact fits and slides lie, less
    those lying within a longer outline part.
    """
    k = starts.shape[0] - 1
    n_edges = xy.shape[0]
    outline = np.empty((4 * n_edges, 4))
    loose = np.empty((4 * n_edges, 4))
    no = 0
    nl = 0
    hint = -1
    # the grid over all sums
    gx0 = bb[:, 0].min()
    gy0 = bb[:, 1].min()
    h = max(bb[:, 2].max() - gx0, bb[:, 3].max() - gy0, 1e-300) / _GRID
    index = sum_index(xy, starts, bb, fr, gx0, gy0, h)
    lo1, hi1, lo0, hi0 = index[-4:]
    for p in range(k):
        s = starts[p]
        e = starts[p + 1]
        for i in range(s, e):
            j = i + 1 if i + 1 < e else s
            ax, ay = xy[i, 0], xy[i, 1]
            bx, by = xy[j, 0], xy[j, 1]
            if ax == bx and ay == by:
                continue
            n1, n0, hint = clip_edge(xy, starts, bb, fr, index, p, ax, ay, bx, by, 0.0, 1.0,
                                     eps, hint)
            dx = bx - ax
            dy = by - ay
            for r in range(n0):
                if no == outline.shape[0]:
                    outline = _grow(outline)
                outline[no, 0] = ax + lo0[r] * dx
                outline[no, 1] = ay + lo0[r] * dy
                outline[no, 2] = ax + hi0[r] * dx
                outline[no, 3] = ay + hi0[r] * dy
                no += 1
            # A loose part within a long outline part of the same edge lies on the
            # outline: no exact fit or slide there (those parts are seams or points).
            length = np.hypot(dx, dy)
            dt = 64.0 * eps / length
            for r in range(n1):
                on_outline = False
                for u in range(n0):
                    if ((hi0[u] - lo0[u]) * length > 128.0 * eps and lo0[u] - dt <= lo1[r]
                            and hi1[r] <= hi0[u] + dt):
                        on_outline = True
                        break
                if on_outline:
                    continue
                if nl == loose.shape[0]:
                    loose = _grow(loose)
                loose[nl, 0] = ax + lo1[r] * dx
                loose[nl, 1] = ay + lo1[r] * dy
                loose[nl, 2] = ax + hi1[r] * dx
                loose[nl, 3] = ay + hi1[r] * dy
                nl += 1
    return outline[:no], loose[:nl]


@njit(cache=True, nogil=True)
def _compact(lo, hi, m):
    n = 0
    for r in range(m):
        if lo[r] <= hi[r]:
            lo[n] = lo[r]
            hi[n] = hi[r]
            n += 1
    return n


@njit(cache=True, nogil=True)
def _grow(arr):
    out = np.empty((2 * arr.shape[0] + 4, arr.shape[1]))
    out[: arr.shape[0]] = arr
    return out


@njit(cache=True, nogil=True, inline="always")
def _start_near(seg, order, sx, oi, ex, ey, tol):
    """The first position from ``oi`` in ``order`` (the segments sorted by their
    start's x, ``sx``) of a segment starting within ``tol`` of (ex, ey), or -1."""
    while oi < order.shape[0] and sx[oi] <= ex + tol:
        c = order[oi]
        if abs(seg[c, 1] - ey) <= tol and np.hypot(seg[c, 0] - ex, seg[c, 1] - ey) <= tol:
            return oi
        oi += 1
    return -1


@njit(cache=True, nogil=True)
def _first_clockwise(seg, order, sx, lo, r, tol):
    """Of the segments starting within ``tol`` of segment r's end (``order``, ``sx``:
    the segments sorted by their start's x, from ``lo``), the one first clockwise from
    the way back along r (see :func:`assemble_rings`)."""
    ex = seg[r, 2]
    ey = seg[r, 3]
    back = np.arctan2(seg[r, 1] - ey, seg[r, 0] - ex)
    best = -1
    best_turn = np.inf
    oi = _start_near(seg, order, sx, lo, ex, ey, tol)
    while oi >= 0:
        c = order[oi]
        oi = _start_near(seg, order, sx, oi + 1, ex, ey, tol)
        ang = np.arctan2(seg[c, 3] - seg[c, 1], seg[c, 2] - seg[c, 0])
        turn = back - ang  # clockwise angle from the way back
        while turn <= 0.0:
            turn += 2.0 * np.pi
        while turn > 2.0 * np.pi:
            turn -= 2.0 * np.pi
        if turn < best_turn:
            best_turn = turn
            best = c
    return best


@njit(cache=True, nogil=True)
def assemble_rings(segs, tol):
    """Link outline segments (interior on the left) into closed rings.

    Segments shorter than ``tol`` are dropped; an end links to the start within ``tol``
    of it; where several starts are there (rings touching at a point), the one first
    clockwise from the way back keeps each interior sector in its own ring. A ring that
    passes twice through one point is split there. Returns ``(ok, xy, starts)``;
    ``ok`` is False when some end finds no start, or a start is claimed twice.
    """
    keep = np.empty(segs.shape[0], np.int64)
    n = 0
    for r in range(segs.shape[0]):
        if np.hypot(segs[r, 2] - segs[r, 0], segs[r, 3] - segs[r, 1]) > tol:
            keep[n] = r
            n += 1
    seg = segs[keep[:n]]
    order = np.argsort(seg[:, 0])
    sx = seg[order, 0]
    nxt = np.full(n, -1, np.int64)
    taken = np.zeros(n, np.bool_)
    for r in range(n):
        ex = seg[r, 2]
        ey = seg[r, 3]
        best = -1
        lo = np.searchsorted(sx, ex - tol)
        # one start there (the common case): it, without comparing turns
        starts_there = 0
        oi = _start_near(seg, order, sx, lo, ex, ey, tol)
        while oi >= 0:
            starts_there += 1
            best = order[oi]
            oi = _start_near(seg, order, sx, oi + 1, ex, ey, tol)
        if starts_there > 1:
            best = _first_clockwise(seg, order, sx, lo, r, tol)
        if best < 0 or taken[best]:
            return False, np.empty((0, 2)), np.zeros(1, np.int64)
        taken[best] = True
        nxt[r] = best
    out = np.empty((n, 2))
    rs = np.empty(n + 1, np.int64)
    rs[0] = 0
    w = 0
    nr = 0
    seen = np.zeros(n, np.bool_)
    for r0 in range(n):
        if seen[r0]:
            continue
        r = r0
        while not seen[r]:
            seen[r] = True
            out[w, 0] = seg[r, 0]
            out[w, 1] = seg[r, 1]
            w += 1
            r = nxt[r]
        if r != r0:
            return False, np.empty((0, 2)), np.zeros(1, np.int64)
        nr += 1
        rs[nr] = w
    return True, out[:w], _split_pinched(out[:w], rs[: nr + 1], tol)


@njit(cache=True, nogil=True)
def _split_pinched(xy, starts, tol):
    """Ring starts after cutting every ring at points it passes twice (in place)."""
    new_starts = [0]
    buf = np.empty_like(xy)
    w = 0
    for k in range(starts.shape[0] - 1):
        s = starts[k]
        e = starts[k + 1]
        stack = np.empty(e - s, np.int64)
        depth = 0
        for i in range(s, e):
            # a point met before closes the loop made since then
            cut = -1
            for d in range(depth):
                v = stack[d]
                if abs(xy[v, 0] - xy[i, 0]) <= tol and abs(xy[v, 1] - xy[i, 1]) <= tol:
                    cut = d
                    break
            if cut >= 0:
                for d in range(cut, depth):
                    buf[w] = xy[stack[d]]
                    w += 1
                new_starts.append(w)
                depth = cut
            stack[depth] = i
            depth += 1
        for d in range(depth):
            buf[w] = xy[stack[d]]
            w += 1
        new_starts.append(w)
    xy[:w] = buf[:w]
    st = np.empty(len(new_starts), np.int64)
    for r in range(len(new_starts)):
        st[r] = new_starts[r]
    return st


@njit(cache=True, nogil=True)
def _in_some_sum(px, py, starts, bb, fr):
    """Whether p lies in some closed sum (no tolerance: used at a distance 64 eps)."""
    for q in range(starts.shape[0] - 1):
        if px < bb[q, 0] or px > bb[q, 2] or py < bb[q, 1] or py > bb[q, 3]:
            continue
        inside = True
        for i in range(starts[q], starts[q + 1]):
            if fr[i, 3] != 0.0 and fr[i, 0] * py - fr[i, 1] * px - fr[i, 2] < 0.0:
                inside = False
                break
        if inside:
            return True
    return False


@njit(cache=True, nogil=True)
def degenerate_contacts(xy, starts, bb, fr, loose, eps, ang_tol):
    """Exact-fit points and slide segments among the ``loose`` parts of :func:`edge_cover`.

    A loose part is an exact fit (when shorter than 8 eps) or a slide where the closed
    sums cover every direction around it (``ang_tol``: angular gap taken as closed);
    around a short part, the direction to the right of it (away from its own sum) is
    tried first (:func:`_may_be_surrounded`: most are vertices of the outline).
    A part is cut at the sums' vertices lying on it; a sub-part whose right side (the
    side away from its own sum) is in no sum is outline and skipped at once. Returns
    ``(points (P, 2), segments (S, 4))``, not deduplicated: the same exact fit is found
    on every edge through it, a slide on the edges of both sides.
    """
    pts = np.empty((loose.shape[0], 2))
    slides = np.empty((loose.shape[0], 4))
    n_pts = 0
    n_slides = 0
    arcs = np.empty((2, starts.shape[0] - 1))
    ts = np.empty(xy.shape[0] + 2)
    off = 64.0 * eps
    for r in range(loose.shape[0]):
        ax, ay, bx, by = loose[r, 0], loose[r, 1], loose[r, 2], loose[r, 3]
        ln = np.hypot(bx - ax, by - ay)
        if ln <= 8.0 * eps:
            mx = 0.5 * (ax + bx)
            my = 0.5 * (ay + by)
            if _may_be_surrounded(mx, my, by - ay, ax - bx, starts, bb, fr, eps, ang_tol) and (
                    _surrounded(mx, my, starts, bb, fr, eps, ang_tol, arcs)):
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
        for q in range(starts.shape[0] - 1):
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
            inside = _in_some_sum(mx + off * uy, my - off * ux, starts, bb, fr) and _surrounded(
                mx, my, starts, bb, fr, eps, ang_tol, arcs
            )
            if inside and open_at < 0.0:
                open_at = t0
            if not inside and open_at >= 0.0:
                if n_slides == slides.shape[0]:
                    slides = _grow(slides)
                slides[n_slides, 0] = ax + open_at * ux
                slides[n_slides, 1] = ay + open_at * uy
                slides[n_slides, 2] = ax + t0 * ux
                slides[n_slides, 3] = ay + t0 * uy
                n_slides += 1
                open_at = -1.0
        if open_at >= 0.0:
            if n_slides == slides.shape[0]:
                slides = _grow(slides)
            slides[n_slides, 0] = ax + open_at * ux
            slides[n_slides, 1] = ay + open_at * uy
            slides[n_slides, 2] = bx
            slides[n_slides, 3] = by
            n_slides += 1
    return pts[:n_pts], slides[:n_slides]


@njit(cache=True, nogil=True)
def tidy_rings(xy, starts, sums, eps):
    """The outline's rings as they are reported: ``(xy, starts)``, open rings.

    - A coordinate within the rounding of a sum vertex's coordinate on the same axis
      (:data:`SNAP_ULPS` units of 2**-52 of the sums' largest |coordinate|) is that
      coordinate (:func:`_snap_to_sums`, in place): a crossing computed as -2.2e-16 on
      the line x = 0 is 0.
    - A vertex within ``eps`` of the segment joining the vertices kept before and after
      it (one that changes nothing) is dropped (:func:`without_collinear`).

    >>> import numpy as np
    >>> ring = np.array([[-1.5, -1.5], [-2.220446049250313e-16, -1.5], [3.0, -1.5],
    ...                  [3.0, 4.0], [1.5, 4.0], [-1.5, 4.0]])
    >>> xy, st = tidy_rings(ring.copy(), np.array([0, 6]), ring, 1e-12)
    >>> xy.tolist(), st.tolist()
    ([[-1.5, -1.5], [3.0, -1.5], [3.0, 4.0], [-1.5, 4.0]], [0, 4])
    """
    _snap_to_sums(xy, sums)
    return without_collinear(xy, starts, eps)


@njit(cache=True, nogil=True)
def _snap_to_sums(xy, sums):
    """Each coordinate of ``xy`` (in place) within :data:`SNAP_ULPS` units of 2**-52 of
    the sums' largest |coordinate| of a coordinate of a sum vertex on the same axis
    becomes the nearest such. Few vertices against few sums (the common case) are
    compared directly; more against the sorted coordinates."""
    if xy.shape[0] == 0:
        return
    mag = 0.0
    for i in range(sums.shape[0]):
        mag = max(mag, abs(sums[i, 0]), abs(sums[i, 1]))
    near = SNAP_ULPS * 2.0**-52 * mag
    direct = xy.shape[0] * sums.shape[0] <= 4096
    for c in range(2):
        values = sums[:, c] if direct else np.sort(sums[:, c])
        for i in range(xy.shape[0]):
            v = xy[i, c]
            best = v
            gap = near  # the nearest within it
            lo, hi = 0, values.shape[0]
            if not direct:
                k = np.searchsorted(values, v)
                lo, hi = max(k - 1, 0), min(k + 1, values.shape[0])
            for m in range(lo, hi):
                d = abs(values[m] - v)
                if d <= gap:
                    best = values[m]
                    gap = d
                    if d == 0.0:
                        break  # (a sum vertex's own coordinate, the common case)
            xy[i, c] = best


@njit(cache=True, nogil=True)
def without_collinear(xy, starts, eps):
    """``(xy, starts)`` of the rings (open) without the vertices that lie within ``eps``
    of the segment joining the vertices kept before and after them: every dropped vertex
    stays within ``eps`` of the segment that replaces it, so the outline moves by at most
    ``eps``. The arrays themselves when there is none (nothing is allocated then); a
    ring with no vertex off its neighbours' segment (a sliver, dropped later) is kept as
    it is.
    """
    some = False
    for r in range(starts.shape[0] - 1):
        s = starts[r]
        n = starts[r + 1] - s
        for i in range(n if n > 3 else 0):
            if not _off_segment(xy, s + (i - 1) % n, s + i, s + (i + 1) % n, eps):
                some = True
                break
    if not some:
        return xy, starts
    keep = np.ones(xy.shape[0], np.bool_)
    for r in range(starts.shape[0] - 1):
        # passes from the kept vertex farthest off its kept neighbours' segment (a
        # corner, never dropped), until one drops nothing
        while _drop_collinear(xy, starts[r], starts[r + 1] - starts[r], keep, eps):
            pass
    out = np.empty((int(keep.sum()), 2))
    new_starts = np.empty_like(starts)
    new_starts[0] = 0
    w = 0
    for r in range(starts.shape[0] - 1):
        for i in range(starts[r], starts[r + 1]):
            if keep[i]:
                out[w] = xy[i]
                w += 1
        new_starts[r + 1] = w
    return out, new_starts


@njit(cache=True, nogil=True)
def _drop_collinear(xy, s, n, keep, eps):
    """One pass of :func:`without_collinear` over the ring of ``n`` vertices at row
    ``s``: from its kept vertex farthest off the segment of its kept neighbours, each
    kept vertex is dropped when every vertex between the anchor (the last one kept) and
    the next kept one, dropped ones included, lies within ``eps`` of the segment joining
    these two. Returns whether it dropped any (none when no vertex is more than ``eps`` off
    its neighbours' segment: a sliver, left as it is); a ring keeps 3 vertices at
    least."""
    first = -1
    far = eps * eps
    for i in range(n):
        if keep[s + i]:
            d2 = closest_on_segment(xy[s + i, 0], xy[s + i, 1],
                                    *_kept_neighbours(xy, s, n, keep, i))[2]
            if d2 > far:
                far = d2
                first = i
    if first < 0:
        return False
    count = 0
    for i in range(n):
        count += keep[s + i]
    dropped = False
    anchor = first
    cand = _next_kept(keep, s, n, first)
    while cand != first and count > 3:
        after = _next_kept(keep, s, n, cand)
        fine = True
        m = (anchor + 1) % n
        while fine and m != after:
            fine = not _off_segment(xy, s + anchor, s + m, s + after, eps)
            m = (m + 1) % n
        if fine:
            keep[s + cand] = False
            count -= 1
            dropped = True
        else:
            anchor = cand
        cand = after
    return dropped


@njit(cache=True, nogil=True)
def _next_kept(keep, s, n, i):
    """The index (in the ring of ``n`` at row ``s``) of the first kept vertex after i."""
    j = (i + 1) % n
    while not keep[s + j]:
        j = (j + 1) % n
    return j


@njit(cache=True, nogil=True)
def _kept_neighbours(xy, s, n, keep, i):
    """``(ax, ay, bx, by)``: the kept vertices before and after vertex i of a ring."""
    j = (i - 1) % n
    while not keep[s + j]:
        j = (j - 1) % n
    k = _next_kept(keep, s, n, i)
    return xy[s + j, 0], xy[s + j, 1], xy[s + k, 0], xy[s + k, 1]


@njit(cache=True, nogil=True)
def _off_segment(xy, a, m, b, eps):
    """Whether vertex m is farther than eps from the segment from vertex a to vertex b."""
    return closest_on_segment(xy[m, 0], xy[m, 1], xy[a, 0], xy[a, 1], xy[b, 0],
                              xy[b, 1])[2] > eps * eps


@njit(cache=True, nogil=True)
def _ring_stats(xy, starts):
    n = starts.shape[0] - 1
    area = np.zeros(n)
    length = np.zeros(n)
    for k in range(n):
        s = starts[k]
        e = starts[k + 1]
        ox = xy[s, 0]  # relative to the first vertex: no cancellation far from the origin
        oy = xy[s, 1]
        for i in range(s, e):
            j = i + 1 if i + 1 < e else s
            area[k] += 0.5 * (
                (xy[i, 0] - ox) * (xy[j, 1] - oy) - (xy[j, 0] - ox) * (xy[i, 1] - oy)
            )
            length[k] += np.hypot(xy[j, 0] - xy[i, 0], xy[j, 1] - xy[i, 1])
    return area, length


@njit(cache=True, nogil=True)
def entrance_region(bxy, bstarts, rxy, rstarts, eps, rel_tol, ulps, ang_tol):
    """Everything the no-fit polygon needs, in one call (few arrays: boxing costs).

    ``(bxy, bstarts)``: convex pieces of B; ``(rxy, rstarts)``: convex pieces of
    ``a0 − A``. ``eps <= 0`` means the default tolerance of the sums' coordinates
    (:func:`polycontact._kernels.tolerance.tolerance_of` with ``rel_tol`` and ``ulps``).
    Returns ``(ring_xy, ring_starts, ring_stats, candidates, meta)``: the outline's
    rings, closed (each ends with its first point); their signed area and length
    (R, 2); candidate exact fits then candidate slides as segments (C, 4), an exact
    fit as a zero-length segment; ``meta`` =
    ``[eps, ok, number of candidate exact fits]``, ``ok`` = 0 when the outline parts
    did not link into rings (the caller then unions the sums another way), -1 when the
    sums are not finite (input beyond float64: the caller refuses it).
    """
    return _entrance(bxy, bstarts, rxy, rstarts, eps, rel_tol, ulps, ang_tol)[2:]


@njit(cache=True, nogil=True)
def _finite(xy):
    """Whether every coordinate is finite (without the array of ``np.isfinite``)."""
    for i in range(xy.shape[0]):
        if not (np.isfinite(xy[i, 0]) and np.isfinite(xy[i, 1])):
            return False
    return True


@njit(cache=True, nogil=True)
def _entrance(bxy, bstarts, rxy, rstarts, eps, rel_tol, ulps, ang_tol):
    """:func:`entrance_region`'s answer preceded by the sums ``(xy, starts)``."""
    sums, starts = convex_sums(bxy, bstarts, rxy, rstarts)
    if not _finite(sums):
        # error code, not a crash: the caller refuses the input
        meta = np.array([1.0, -1.0, 0.0])
        return (sums, starts, sums[:0], np.zeros(1, np.int64), np.empty((0, 2)),
                np.empty((0, 4)), meta)
    if eps <= 0.0:
        eps = tolerance_of(sums, rel_tol, ulps)
    meta = np.array([eps, 1.0, 0.0])
    if starts.shape[0] == 2:
        # one sum: its vertices are the sums' (nothing to snap)
        ring_xy, rs = without_collinear(sums, np.array([0, sums.shape[0]], np.int64), eps)
        area, length = _ring_stats(ring_xy, rs)
        ring_xy, ring_starts = _closed(ring_xy, rs)
        return (sums, starts, ring_xy, ring_starts, np.column_stack((area, length)),
                np.empty((0, 4)), meta)
    bb = _bboxes(sums, starts)
    fr = _frames(sums, starts)
    outline, loose = edge_cover(sums, starts, bb, fr, eps)
    ok, ring_xy, ring_starts = assemble_rings(outline, 4.0 * eps)
    ring_xy, ring_starts = tidy_rings(ring_xy, ring_starts, sums, eps)
    area, length = _ring_stats(ring_xy, ring_starts)
    pts, segs = degenerate_contacts(sums, starts, bb, fr, loose, eps, ang_tol)
    cand = np.empty((pts.shape[0] + segs.shape[0], 4))
    cand[: pts.shape[0], 0:2] = pts
    cand[: pts.shape[0], 2:4] = pts
    cand[pts.shape[0]:] = segs
    meta[1] = 1.0 if ok else 0.0
    meta[2] = pts.shape[0]
    ring_xy, ring_starts = _closed(ring_xy, ring_starts)
    return sums, starts, ring_xy, ring_starts, np.column_stack((area, length)), cand, meta


@njit(cache=True, nogil=True)
def ring_entrance(bxy, axy, a0x, a0y, eps, rel_tol, ulps, ang_tol, snap_f, near_f, max_ear,
                  max_sum):
    """:func:`entrance_region` of two simple CCW rings B and A (no holes), each cut into
    convex pieces here (:func:`polycontact._kernels.decompose.ring_pieces`, up to
    ``max_ear`` vertices), A's reflected through ``(a0x, a0y)``: one call where a
    decomposition cached by the caller would cost more to look up than to redo.

    Returns ``(head, buf)`` as :func:`entrance_packed`; ``head[0]`` (ok) is 0 (and the
    rest empty) when a ring is too large or has no ear left, or the sums would hold more
    than ``max_sum`` vertices: the caller then decomposes the rings another way (or
    refuses them) and calls :func:`entrance_packed`.
    """
    okb, bp, bst = ring_pieces(bxy, rel_tol, ulps, max_ear)
    oka, ap, ast = ring_pieces(axy, rel_tol, ulps, max_ear)
    total = bp.shape[0] * (ast.shape[0] - 1) + ap.shape[0] * (bst.shape[0] - 1)
    if not (okb and oka) or total > max_sum:
        return _pack(False, bp, bst, bp[:0], np.zeros(1, np.int64), np.empty((0, 2)),
                     np.empty((0, 4)), np.zeros(3), snap_f, near_f)
    r = np.empty_like(ap)
    for i in range(ap.shape[0]):
        r[i, 0] = a0x - ap[i, 0]
        r[i, 1] = a0y - ap[i, 1]
    return _pack(True, *_entrance(bp, bst, r, ast, eps, rel_tol, ulps, ang_tol), snap_f,
                 near_f)


@njit(cache=True, nogil=True)
def entrance_packed(bxy, bstarts, rxy, rstarts, eps, rel_tol, ulps, ang_tol, snap_f, near_f):
    """:func:`entrance_region`'s answer as two objects, ``(head, buf)``: returning an
    array to Python costs about half a microsecond each, a third of a small no-fit
    polygon's kernel time with five. The candidates are made exact here, where the sums
    are at hand (see :func:`_exact_candidates`; ``snap_f`` and ``near_f`` times the
    tolerance are its ``snap`` and ``near``).

    ``head`` = ``(ok, eps, status, candidate fits, rings, ring vertices, candidates)``,
    floats (``ok`` = 1; ``status`` is
    ``meta[1]`` of :func:`entrance_region`); ``buf`` (float64) holds, one after the
    other, the rings' coordinates (x0, y0, x1, ...), their starts (rings + 1), their
    (area, length) and the candidates (4 each); see
    :func:`polycontact.nfp._unpack`.
    """
    return _pack(True, *_entrance(bxy, bstarts, rxy, rstarts, eps, rel_tol, ulps, ang_tol),
                 snap_f, near_f)


@njit(cache=True, nogil=True)
def _pack(ok, sums, starts, ring_xy, ring_starts, stats, cand, meta, snap_f, near_f):
    """``(head, buf)`` of :func:`entrance_packed` from :func:`_entrance`'s answer."""
    if cand.shape[0]:
        n_pts = int(meta[2])
        cand = _exact_candidates(cand, n_pts, sums, starts, snap_f * meta[0],
                                 near_f * meta[0])
    nv = ring_xy.shape[0]
    nr = ring_starts.shape[0] - 1
    nc = cand.shape[0]
    buf = np.empty(2 * nv + (nr + 1) + 2 * nr + 4 * nc)
    w = 0
    for i in range(nv):
        buf[w] = ring_xy[i, 0]
        buf[w + 1] = ring_xy[i, 1]
        w += 2
    for k in range(nr + 1):
        buf[w] = ring_starts[k]
        w += 1
    for k in range(nr):
        buf[w] = stats[k, 0]
        buf[w + 1] = stats[k, 1]
        w += 2
    for k in range(nc):
        for c in range(4):
            buf[w] = cand[k, c]
            w += 1
    head = (1.0 if ok else 0.0, meta[0], meta[1], meta[2], float(nr), float(nv), float(nc))
    return head, buf


@njit(cache=True, nogil=True)
def _exact_candidates(cand, n_pts, sums, starts, snap_tol, near):
    """Candidates (C, 4) of :func:`entrance_region` (its ``n_pts`` exact fits first)
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
def _touches_at(px, py, moved, xa, sa, xb, sb, a0x, a0y, tol):
    """relate_state of A moved by p - a0 (into ``moved``) against B is contact."""
    dx = px - a0x
    dy = py - a0y
    for i in range(xa.shape[0]):
        moved[i, 0] = xa[i, 0] + dx
        moved[i, 1] = xa[i, 1] + dy
    return relate_state(moved, sa, xb, sb, tol) == 1


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


@njit(cache=True, nogil=True)
def _closed(xy, starts):
    """The packed loops with each loop's first point repeated at its end."""
    n = starts.shape[0] - 1
    out = np.empty((xy.shape[0] + n, 2))
    st = np.empty(n + 1, np.int64)
    st[0] = 0
    w = 0
    for k in range(n):
        for i in range(starts[k], starts[k + 1]):
            out[w] = xy[i]
            w += 1
        out[w] = xy[starts[k]]
        w += 1
        st[k + 1] = w
    return out, st


@njit(cache=True, nogil=True)
def snap(points, along, xy, starts, tol):
    """Candidate positions made exact (a copy of ``points`` (P, 2) is returned).

    Each point goes to the nearest vertex of the sums within ``tol``; else to the
    nearest crossing within ``tol`` of a line through it with a sum edge passing within
    ``tol``: the line along ``along[k]`` (a slide's direction) or, where that is zero
    (an exact fit), the line of the nearest such edge. Points with neither stay.
    """
    out = points.copy()
    nv = xy.shape[0]
    nxt = np.empty(nv, np.int64)
    for k in range(starts.shape[0] - 1):
        for i in range(starts[k], starts[k + 1]):
            nxt[i] = i + 1 if i + 1 < starts[k + 1] else starts[k]
    for k in range(points.shape[0]):
        px = points[k, 0]
        py = points[k, 1]
        best = tol
        bi = -1
        for i in range(nv):
            d = np.hypot(xy[i, 0] - px, xy[i, 1] - py)
            if d <= best:
                best = d
                bi = i
        if bi >= 0:
            out[k, 0] = xy[bi, 0]
            out[k, 1] = xy[bi, 1]
            continue
        # the edge nearest to p, among those within tol
        near_e = -1
        near_d = tol
        for i in range(nv):
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
        for i in range(nv):
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
            s = ((xy[i, 0] - bx_) * wy - (xy[i, 1] - by_) * wx) / den
            qx = bx_ + s * ax_
            qy = by_ + s * ay_
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


#: Side of the grid (cells per side) whose cells remember the sums containing them whole.
_GRID = 32

#: Fewer sums than this are clipped without the grid: setting up its cells would cost
#: more than scanning the few sums' boxes for every edge.
_GRID_MIN_SUMS = 256


@njit(cache=True, nogil=True)
def sum_index(xy, starts, bb, fr, gx0, gy0, h, grid_from=_GRID_MIN_SUMS):
    """What :func:`clip_edge` reads to clip edges by the convex sums ``(xy, starts)``
    (boxes ``bb``, edge frames ``fr``): the sums sorted by their smallest x (``by_x``,
    ``xs``) and their widest box (``wmax``); a ``_GRID`` x ``_GRID`` grid of cells of
    side ``h`` from ``(gx0, gy0)`` with the sums containing each cell whole
    (:func:`_cell_cover`), or no grid (0 x 0) for fewer than ``grid_from`` sums (the
    same clips, found by the scan alone), and a buffer of the sums tried on an edge;
    the four interval buffers of the clipped parts."""
    k = starts.shape[0] - 1
    by_x = np.argsort(bb[:, 0])
    xs = bb[by_x, 0]
    wmax = 0.0
    for q in range(k):
        wmax = max(wmax, bb[q, 2] - bb[q, 0])
    g = _GRID if k >= grid_from else 0
    cover = _cell_cover(xy, starts, bb, fr, gx0, gy0, h, g)
    tried = np.full(_PER_CELL * (g + 2) * 4 + 4, -1, np.int64)
    cap = 2 * k + 4
    return (by_x, xs, wmax, cover, gx0, gy0, h, tried,
            np.empty(cap), np.empty(cap), np.empty(cap), np.empty(cap))


@njit(cache=True, nogil=True, inline="always")
def _cut(ax, ay, bx, by, fr, starts, q, p, eps, lo1, hi1, n1, lo0, hi0, n0):
    """Take from the parts of edge (a, b) of sum p what sum q covers: from
    ``lo1[:n1], hi1[:n1]`` its closed interior shrunk by eps, from ``lo0[:n0],
    hi0[:n0]`` its open interior (see :func:`_clip`); returns the new ``(n1, n0)``."""
    a1, b1, a0, b0 = _clip(ax, ay, bx, by, fr, starts[q], starts[q + 1], q < p, eps)
    if a1 < b1 and n1 > 0:
        n1 = _compact(lo1, hi1, _subtract(lo1, hi1, n1, a1, b1))
    if a0 < b0 and n0 > 0:
        n0 = _compact(lo0, hi0, _subtract(lo0, hi0, n0, a0, b0))
    return n1, n0


@njit(cache=True, nogil=True, inline="always")
def clip_edge(xy, starts, bb, fr, index, p, ax, ay, bx, by, t0, t1, eps, hint):
    """Clip the part [t0, t1] of edge (a, b) of sum p by the other sums
    (:func:`sum_index`), until nothing is left. Returns ``(n1, n0, hint)``: the parts
    outside every closed sum shrunk by eps (``lo1[:n1], hi1[:n1]`` of the index) and
    outside every open sum (``lo0[:n0], hi0[:n0]``), as parameters along the edge, and
    the sum that covered the edge whole (else ``hint`` unchanged).

    The sums covering whole cells along the edge are tried first, then ``hint`` (the
    sum that covered the previous edge: an edge inside the union is then usually done
    after one test), then the others by their smallest x, from the first that can reach
    the edge (none is wider than ``wmax``).
    """
    by_x, xs, wmax, cover, gx0, gy0, h, tried, lo1, hi1, lo0, hi0 = index
    k = starts.shape[0] - 1
    lo1[0] = t0
    hi1[0] = t1
    lo0[0] = t0
    hi0[0] = t1
    n1 = 1
    n0 = 1
    # the cells' covering sums (up to 2 g samples along the edge), each once
    g = cover.shape[0]
    nt = 0
    steps = min(2 * g, 1 + int(np.hypot(bx - ax, by - ay) / h))
    for st in range(steps + 1 if g > 0 else 0):
        t = st / steps
        ci = int(np.floor((ax + t * (bx - ax) - gx0) / h))
        cj = int(np.floor((ay + t * (by - ay) - gy0) / h))
        if ci < 0 or cj < 0 or ci >= g or cj >= g:
            continue
        for u in range(_PER_CELL):
            q = cover[ci, cj, u]
            if q < 0 or q == p:
                continue
            seen = False
            for v in range(nt):
                if tried[v] == q:
                    seen = True
                    break
            if seen or nt == tried.shape[0]:
                continue
            tried[nt] = q
            nt += 1
            n1, n0 = _cut(ax, ay, bx, by, fr, starts, q, p, eps, lo1, hi1, n1, lo0, hi0, n0)
            if n1 == 0 and n0 == 0:
                return n1, n0, hint
    x0 = min(ax, bx) - eps
    x1 = max(ax, bx) + eps
    y0 = min(ay, by) - eps
    y1 = max(ay, by) + eps
    first = np.searchsorted(xs, x0 - wmax)
    for qi in range(first - 1, k):
        q = hint if qi < first else by_x[qi]
        if qi >= first and xs[qi] > x1:
            break  # sorted by their smallest x: none further can meet the edge
        if q < 0 or (qi >= first and q == hint):
            continue
        if q == p or bb[q, 0] > x1 or bb[q, 2] < x0 or bb[q, 1] > y1 or bb[q, 3] < y0:
            continue
        n1, n0 = _cut(ax, ay, bx, by, fr, starts, q, p, eps, lo1, hi1, n1, lo0, hi0, n0)
        if n1 == 0 and n0 == 0:
            return n1, n0, q
    return n1, n0, hint


@njit(cache=True, nogil=True)
def sum_into(bxy, ps, pe, i0, rxy, qs, qe, out, w):
    """Write the Minkowski sum of the convex CCW pieces ``bxy[ps:pe]`` (lowest vertex
    ``i0``) and ``rxy[qs:qe]`` into ``out`` from row ``w``, counter-clockwise from the
    sum of their lowest vertices, by merging their edges by angle (O(p + q)); returns
    the next free row."""
    n = pe - ps
    m = qe - qs
    j0 = _lowest(rxy, qs, qe)
    i = 0
    j = 0
    while i < n or j < m:
        pi = ps + (i0 - ps + i) % n
        qj = qs + (j0 - qs + j) % m
        out[w, 0] = bxy[pi, 0] + rxy[qj, 0]
        out[w, 1] = bxy[pi, 1] + rxy[qj, 1]
        w += 1
        if i == n:
            j += 1
            continue
        if j == m:
            i += 1
            continue
        pn = ps + (i0 - ps + i + 1) % n
        qn = qs + (j0 - qs + j + 1) % m
        c = (bxy[pn, 0] - bxy[pi, 0]) * (rxy[qn, 1] - rxy[qj, 1]) - (
            bxy[pn, 1] - bxy[pi, 1]
        ) * (rxy[qn, 0] - rxy[qj, 0])
        # (a NaN turn, from non-finite input, advances both: the loop always ends)
        if not c < 0.0:
            i += 1
        if not c > 0.0:
            j += 1
    return w
