"""Kernels: the outline of a union of convex sums, assembled from the uncovered parts of
their edges.

:func:`edge_cover` keeps the parts of the sums' edges that lie in no other sum (the
outline, once each) and those in no other open sum shrunk by eps (where exact fits and
slides lie); :func:`assemble_rings` links the outline's parts into closed rings;
:func:`tidy_rings` snaps their coordinates to the sums' and drops the vertices that
change nothing.
"""

from __future__ import annotations

import numpy as np

from .jit import njit
from .minkowski import EDGE, GRID, clip_edge, sum_index
from .primitives import append_part, closest_on_segment

#: Outline coordinates within this many units of 2**-52 of the sums' largest
#: |coordinate| of a sum vertex's coordinate are that coordinate (see :func:`tidy_rings`).
SNAP_ULPS = 4.0


@njit(cache=True, nogil=True)
def edge_cover(xy, starts, bb, fr, eps):
    """Uncovered parts of the sums' edges (those marked ``EDGE`` in the frames ``fr``:
    an ``INNER_EDGE``, off the reduced convolution, has none).

    Returns ``(outline, loose)``, both (M, 4) segments x0, y0, x1, y1:
    ``outline`` are the parts in no other sum's interior and on no seam, each kept once:
    the boundary of the union, oriented with the union on its left; ``loose`` are the
    parts in no other open sum shrunk by eps, where exact fits and slides lie, less
    those lying within a longer outline part.
    """
    return clip_edges(xy, starts, bb, fr, eps, outline_index(xy, starts, bb, fr, eps))


@njit(cache=True, nogil=True)
def outline_index(xy, starts, bb, fr, eps):
    """The :func:`polycontact._kernels.minkowski.sum_index` that :func:`clip_edges`
    reads: its cover grid spans every sum."""
    gx0 = bb[:, 0].min()
    gy0 = bb[:, 1].min()
    h = max(bb[:, 2].max() - gx0, bb[:, 3].max() - gy0, 1e-300) / GRID
    return sum_index((xy, starts, bb, fr), gx0, gy0, h, eps)


@njit(cache=True, nogil=True)
def clip_edges(xy, starts, bb, fr, eps, index):
    """:func:`edge_cover` with its index (:func:`outline_index`) given."""
    k = starts.shape[0] - 1
    cap = 4
    for i in range(xy.shape[0]):
        if fr[i, 3] == EDGE:
            cap += 4  # (rows grow when needed)
    outline = np.empty((cap, 4))
    loose = np.empty((cap, 4))
    no = 0
    nl = 0
    hint = -1
    sums = (xy, starts, bb, fr)
    lo1, hi1, lo0, hi0 = index[-4:]
    for p in range(k):
        s = starts[p]
        e = starts[p + 1]
        for i in range(s, e):
            j = i + 1 if i + 1 < e else s
            ax, ay = xy[i, 0], xy[i, 1]
            bx, by = xy[j, 0], xy[j, 1]
            if fr[i, 3] != EDGE or (ax == bx and ay == by):
                continue
            n1, n0, hint = clip_edge(sums, index, p, ax, ay, bx, by, 0.0, 1.0, eps, hint)
            dx = bx - ax
            dy = by - ay
            for r in range(n0):
                outline, no = append_part(outline, no, ax, ay, dx, dy, lo0[r], hi0[r])
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
                if not on_outline:
                    loose, nl = append_part(loose, nl, ax, ay, dx, dy, lo1[r], hi1[r])
    return outline[:no], loose[:nl]


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
def ring_stats(xy, starts):
    """Each loop's signed area and length: ``(area, length)``, (R,) each."""
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
def closed_loops(xy, starts):
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
