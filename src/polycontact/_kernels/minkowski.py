"""Kernels: convex Minkowski sums, and the clipping of their edges by each other.

Shared by the no-fit polygon (:mod:`polycontact._kernels.nfp`) and the penetration
depth (:mod:`polycontact._kernels.depth`): the sums of pairs of convex CCW pieces
(:func:`sum_into`, O(p + q) each), their boxes and edge frames, and the parts of an
edge that other sums leave uncovered (:func:`clip_edge` over :func:`sum_index`: the sums
sorted by x, and a grid whose cells remember the sums that contain them whole).
"""

from __future__ import annotations

import numpy as np

from .jit import njit

from .cells import in_grid, polygon_grid, segment_cells
from .reduced import admits, piece_cones


@njit(cache=True, nogil=True)
def lowest(xy, s, e):
    """The lowest vertex (then leftmost) of rows s:e of ``xy``."""
    best = s
    for i in range(s + 1, e):
        if xy[i, 1] < xy[best, 1] or (xy[i, 1] == xy[best, 1] and xy[i, 0] < xy[best, 0]):
            best = i
    return best


@njit(cache=True, nogil=True)
def sum_into(bxy, ps, pe, i0, rxy, qs, qe, out, w, reduced):
    """Write the Minkowski sum of the convex CCW pieces ``bxy[ps:pe]`` (lowest vertex
    ``i0``) and ``rxy[qs:qe]`` into ``out`` from row ``w``, counter-clockwise from the
    sum of their lowest vertices, by merging their edges by angle (O(p + q)); returns
    the next free row.

    ``reduced`` = ``(keep, b_pieces, r_pieces)``: when ``keep`` has rows, ``keep[k]``
    is set for each sum edge written (from row k to the next) to whether it lies on the
    reduced convolution (:mod:`polycontact._kernels.reduced`), from the
    :func:`polycontact._kernels.reduced.piece_cones` of both sets of pieces; an edge
    that is a vertex of one piece plus an edge of the other is on it when that edge is
    on its body's boundary and its direction is admitted by the vertex's cone; an edge
    made of two parallel ones, when either is, at either end of the other.
    """
    keep, (bbd, bcone), (rbd, rcone) = reduced
    flags = keep.shape[0] > 0
    n = pe - ps
    m = qe - qs
    j0 = lowest(rxy, qs, qe)
    i = 0
    j = 0
    while i < n or j < m:
        pi = ps + (i0 - ps + i) % n
        qj = qs + (j0 - qs + j) % m
        out[w, 0] = bxy[pi, 0] + rxy[qj, 0]
        out[w, 1] = bxy[pi, 1] + rxy[qj, 1]
        w += 1
        pn = ps + (i0 - ps + i + 1) % n
        qn = qs + (j0 - qs + j + 1) % m
        if i == n:
            c = -1.0  # (only R's edges left)
        elif j == m:
            c = 1.0  # (only B's)
        else:
            c = (bxy[pn, 0] - bxy[pi, 0]) * (rxy[qn, 1] - rxy[qj, 1]) - (
                bxy[pn, 1] - bxy[pi, 1]
            ) * (rxy[qn, 0] - rxy[qj, 0])
        # (a NaN turn, from non-finite input, advances both: the loop always ends)
        b_edge = not c < 0.0
        r_edge = not c > 0.0
        if flags:
            # (parallel edges, both advancing: each edge may pair with either end of
            # the other, the vertex it leaves or the one it reaches)
            both = b_edge and r_edge
            bdx = bxy[pn, 0] - bxy[pi, 0]
            bdy = bxy[pn, 1] - bxy[pi, 1]
            rdx = rxy[qn, 0] - rxy[qj, 0]
            rdy = rxy[qn, 1] - rxy[qj, 1]
            keep[w - 1] = (
                (b_edge and bbd[pi] and (admits(rcone, qj, bdx, bdy)
                                         or (both and admits(rcone, qn, bdx, bdy))))
                or (r_edge and rbd[qj] and (admits(bcone, pi, rdx, rdy)
                                            or (both and admits(bcone, pn, rdx, rdy)))))
        if b_edge:
            i += 1
        if r_edge:
            j += 1
    return w


@njit(cache=True, nogil=True)
def no_flags():
    """The ``reduced`` argument of :func:`sum_into` that asks for no flags."""
    none = (np.zeros(0, np.bool_), np.zeros((0, 5)))
    return np.zeros(0, np.bool_), none, none


@njit(cache=True, nogil=True)
def convex_sums(bxy, bstarts, rxy, rstarts):
    """Minkowski sums of every pair of convex CCW pieces, in O(p + q) each.

    ``(bxy, bstarts)`` and ``(rxy, rstarts)`` are packed convex pieces (B's and the
    reflected A's). Returns packed sums ``(xy, starts, keep)``, counter-clockwise,
    ordered with the pieces of B outermost; ``keep[k]``: whether the edge from row k
    (to the next of its sum) lies on the reduced convolution (see :func:`sum_into`).
    """
    nb = bstarts.shape[0] - 1
    nr = rstarts.shape[0] - 1
    total = nr * bxy.shape[0] + nb * rxy.shape[0]
    out = np.empty((total, 2))
    keep = np.empty(max(total, 1), np.bool_)
    reduced = (keep, piece_cones(bxy, bstarts), piece_cones(rxy, rstarts))
    starts = np.empty(nb * nr + 1, np.int64)
    starts[0] = 0
    w = 0
    k = 0
    for bi in range(nb):
        ps = bstarts[bi]
        pe = bstarts[bi + 1]
        i0 = lowest(bxy, ps, pe)
        for rj in range(nr):
            w = sum_into(bxy, ps, pe, i0, rxy, rstarts[rj], rstarts[rj + 1], out, w, reduced)
            k += 1
            starts[k] = w
    return out[:w], starts, keep[:w]


@njit(cache=True, nogil=True)
def boxes(xy, starts):
    """Each loop's bounding box, rows ``(xmin, ymin, xmax, ymax)``."""
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


#: Column 3 of :func:`frames`: an edge of zero length (no line), an edge, and an edge
#: off the reduced convolution (:func:`mark_inner`: it bounds its sum like any other but
#: cannot lie on the outline of the union).
ZERO_LENGTH = 0.0
EDGE = 1.0
INNER_EDGE = 2.0


@njit(cache=True, nogil=True)
def frames(xy, starts):
    """Per edge of packed loops: unit direction (ux, uy), offset c, and ``EDGE`` (1) if
    not zero-length (``ZERO_LENGTH``, 0, and no line, if it is).

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
                fr[i, 3] = EDGE
    return fr


@njit(cache=True, nogil=True)
def mark_inner(xy, starts, fr, keep, eps):
    """Mark in the frames ``fr`` (:func:`frames`, in place) of the packed sums ``(xy,
    starts)`` the edges off the reduced convolution (``keep`` False, see
    :func:`convex_sums`) as ``INNER_EDGE``, unless another edge of their sum on the same
    line (consecutive edges whose shorter one ends within ``eps`` of the other's line,
    zero-length ones between them skipped) is on it.

    :func:`_clip` sees a sum's edges along a line as one: the outline along it is kept
    once, by the first sum whose edge there is an ``EDGE``; a line of mixed edges would
    keep the outline there twice, or not at all.

    >>> import numpy as np
    >>> sq = np.array([(0, 0), (1, 0), (2, 0), (2, 2), (0, 2)], float)
    >>> st = np.array([0, 5])
    >>> fr = frames(sq, st)
    >>> mark_inner(sq, st, fr, np.array([True, False, False, True, False]), 1e-12)
    >>> fr[:, 3].tolist()
    [1.0, 1.0, 2.0, 1.0, 2.0]
    """
    for k in range(starts.shape[0] - 1):
        s = starts[k]
        e = starts[k + 1]
        edges = np.empty(e - s, np.int64)  # (the sum's edges of non-zero length)
        length = np.empty(e - s)
        m = 0
        for i in range(s, e):
            if fr[i, 3] != ZERO_LENGTH:
                j = i + 1 if i + 1 < e else s
                edges[m] = i
                length[m] = np.hypot(xy[j, 0] - xy[i, 0], xy[j, 1] - xy[i, 1])
                m += 1
        kept = np.empty(m, np.bool_)
        on_line = np.empty(m, np.bool_)  # (edge t and the next on one line)
        for t in range(m):
            u = (t + 1) % m
            kept[t] = keep[edges[t]]
            on_line[t] = _one_line(fr, edges[t], edges[u], min(length[t], length[u]), eps)
        for t in range(2 * m):  # (twice round: a line may wrap past the first edge)
            if on_line[t % m] and kept[t % m]:
                kept[(t + 1) % m] = True
        for t in range(2 * m - 1, -1, -1):
            if on_line[t % m] and kept[(t + 1) % m]:
                kept[t % m] = True
        for t in range(m):
            if not kept[t]:
                fr[edges[t], 3] = INNER_EDGE


@njit(cache=True, nogil=True)
def _one_line(fr, i, j, shorter, eps):
    """Whether edges i and j (frames ``fr``, non-zero length, the shorter ``shorter``
    long) run the same way on one line: the shorter one's far end is within ``eps`` of
    the other's line."""
    if fr[i, 0] * fr[j, 0] + fr[i, 1] * fr[j, 1] <= 0.0:
        return False
    return abs(fr[i, 0] * fr[j, 1] - fr[i, 1] * fr[j, 0]) * shorter <= eps


@njit(cache=True, nogil=True)
def in_some_sum(px, py, starts, bb, fr, margin, skip):
    """Whether p lies in some convex sum other than sum ``skip`` (-1: none skipped), of
    boxes ``bb`` (:func:`boxes`) and edge frames ``fr`` (:func:`frames`).

    ``margin`` >= 0: inside a sum by more than ``margin`` (open: on every edge's line's
    inner side by more than it, and likewise of the box). ``margin`` < 0: in a closed
    sum, with no tolerance (for points that the caller puts well inside or outside).
    """
    return in_some_listed(px, py, np.arange(starts.shape[0] - 1), starts, bb, fr, margin,
                          skip)


@njit(cache=True, nogil=True)
def in_some_listed(px, py, listed, starts, bb, fr, margin, skip):
    """:func:`in_some_sum` among the sums ``listed`` only (every sum that may hold p)."""
    closed = margin < 0.0
    m = 0.0 if closed else margin
    for q in listed:
        if q == skip:
            continue
        x0 = bb[q, 0] + m
        x1 = bb[q, 2] - m
        y0 = bb[q, 1] + m
        y1 = bb[q, 3] - m
        if closed:
            if px < x0 or px > x1 or py < y0 or py > y1:
                continue
        elif px <= x0 or px >= x1 or py <= y0 or py >= y1:
            continue
        inside = True
        for i in range(starts[q], starts[q + 1]):
            if fr[i, 3] != 0.0:
                f = fr[i, 0] * py - fr[i, 1] * px - fr[i, 2]
                if f < m or (f == m and not closed):
                    inside = False
                    break
        if inside:
            return True
    return False


#: Polygons of more edges than this are clipped from the edge facing the segment
#: (:func:`_facing`): finding it costs a binary search.
_FACING_FROM = 16


@njit(cache=True, nogil=True)
def _facing(mx, my, xy, s, e):
    """An edge of the convex CCW polygon ``xy[s:e]`` whose line has the point m on its
    outer side when m lies outside near it: the edge closing the fan triangle from
    vertex s that holds m's direction (found by bisection), or an edge at vertex s when
    m lies outside the polygon's angle there."""
    ox = xy[s, 0]
    oy = xy[s, 1]
    wx = mx - ox
    wy = my - oy
    if (xy[s + 1, 0] - ox) * wy - (xy[s + 1, 1] - oy) * wx < 0.0:
        return s  # right of the first edge's line
    lo = s + 1
    hi = e - 1
    while lo < hi:  # the last ray from vertex s with m on its left
        mid = (lo + hi + 1) // 2
        if (xy[mid, 0] - ox) * wy - (xy[mid, 1] - oy) * wx >= 0.0:
            lo = mid
        else:
            hi = mid - 1
    return lo  # (e - 1: the edge back to vertex s)


@njit(cache=True, nogil=True)
def _clip(ax, ay, bx, by, xy, fr, s, e, q_first, eps):
    """Parts of segment ab (parameter t in [0, 1]) covered by convex polygon
    ``xy[s:e]``.

    ``fr`` holds the edge frames of :func:`frames`. Returns
    ``(lo1, hi1, lo0, hi0)``: the open interval inside the polygon by more than eps
    (empty when lo >= hi), and the
    interval to remove from the union's outline: strictly inside, or along a collinear
    edge of the polygon that runs the other way (a seam between two sums) or the same
    way when the polygon comes first (``q_first``; the duplicate outline edge is kept
    once) and that edge is not an ``INNER_EDGE`` (which is never kept itself).
    """
    # (intervals within (-1, 2), which holds the segment: an edge's line cutting the
    # segment's line beyond it then empties them at once; the intervals do not depend
    # on the order of the edges, and a long polygon's are taken from the one facing the
    # segment, which ends the loop soonest when the segment lies outside)
    lo1 = -1.0
    hi1 = 2.0
    lo0 = -1.0
    hi0 = 2.0
    empty0 = False
    first = s if e - s <= _FACING_FROM else _facing(0.5 * (ax + bx), 0.5 * (ay + by), xy,
                                                    s, e)
    for k in range(s, e):
        i = first + k - s
        if i >= e:
            i -= e - s
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
            if same and not (q_first and fr[i, 3] == EDGE):
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
def _compact(lo, hi, m):
    """Drop the empty intervals (lo > hi) among ``lo[:m], hi[:m]``; their new count."""
    n = 0
    for r in range(m):
        if lo[r] <= hi[r]:
            lo[n] = lo[r]
            hi[n] = hi[r]
            n += 1
    return n


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


#: Side of the grid (cells per side) whose cells remember the sums containing them whole.
GRID = 32


#: Fewer sums than this are clipped without the grid: setting up its cells would cost
#: more than scanning the few sums' boxes for every edge.
GRID_MIN_SUMS = 256


@njit(cache=True, nogil=True)
def sum_index(sums, gx0, gy0, h, eps, grid_from=GRID_MIN_SUMS):
    """What :func:`clip_edge` reads to clip edges by the convex ``sums``, ``(xy, starts,
    bb, fr)`` (the packed sums, their boxes and edge frames): the sums sorted by their
    smallest x (``by_x``, ``xs``) and their widest box (``wmax``); a ``GRID`` x ``GRID``
    grid of cells of side ``h`` from ``(gx0, gy0)`` with the sums containing each cell
    whole (:func:`_cell_cover`), and a grid listing the sums that come within ``eps`` of
    each of its cells (:func:`polycontact._kernels.cells.polygon_grid`, about as many
    entries as the sums have vertices), or neither (0 x 0) for fewer than ``grid_from``
    sums (the same clips, found by the scan alone); a buffer of the sums tried on an
    edge and one of cells, with a mark per sum; the four interval buffers of the
    clipped parts."""
    xy, starts, bb, fr = sums
    k = starts.shape[0] - 1
    by_x = np.argsort(bb[:, 0])
    xs = bb[by_x, 0]
    wmax = 0.0
    for q in range(k):
        wmax = max(wmax, bb[q, 2] - bb[q, 0])
    g = GRID if k >= grid_from else 0
    cover = _cell_cover(xy, starts, bb, fr, gx0, gy0, h, g)
    tried = np.full(_PER_CELL * (g + 2) * 4 + 4, -1, np.int64)
    near = polygon_grid(xy, starts, bb, eps, xy.shape[0] + 16 * k) if g else (
        polygon_grid(xy[:0], starts[:1], bb, eps, 1))
    # (cells along an edge, and per sum the last edge that tried it)
    marks = (np.empty(3 * (near[3] + near[4]) + 8, np.int64), np.full(k + 1, -1, np.int64))
    cap = 2 * k + 4
    return (by_x, xs, wmax, cover, gx0, gy0, h, tried, near, marks,
            np.empty(cap), np.empty(cap), np.empty(cap), np.empty(cap))


@njit(cache=True, nogil=True)
def clip_tests(sums, index, eps):
    """An upper bound, known before any clipping, of the tests of an edge against a sum
    that :func:`clip_edge` makes over every ``EDGE`` of the ``sums`` (``(xy, starts,
    bb, fr)``), reading ``index`` (:func:`sum_index`): the sums listed in the cells
    along each edge (the cover grid's and the hint's are among them); 0 without a grid,
    for few sums. Costs the cells along the edges, no clipping."""
    xy, starts, _, fr = sums
    near, marks = index[8], index[9]
    if index[3].shape[0] == 0:
        return 0
    cells = marks[0]
    first = near[5]
    total = 0
    for p in range(starts.shape[0] - 1):
        for i in range(starts[p], starts[p + 1]):
            if fr[i, 3] != EDGE:
                continue
            j = i + 1 if i + 1 < starts[p + 1] else starts[p]
            nc = segment_cells(near, xy[i, 0], xy[i, 1], xy[j, 0], xy[j, 1], eps, cells)
            for c in range(nc):
                total += first[cells[c] + 1] - first[cells[c]]
    return total


@njit(cache=True, nogil=True, inline="always")
def _cut(ax, ay, bx, by, xy, fr, starts, q, p, eps, parts, n1, n0):
    """Take from the parts of edge (a, b) of sum p what sum q covers: of ``parts`` =
    ``(lo1, hi1, lo0, hi0)``, from ``lo1[:n1], hi1[:n1]`` its closed interior shrunk by
    eps, from ``lo0[:n0], hi0[:n0]`` its open interior (see :func:`_clip`); returns the
    new ``(n1, n0)``."""
    lo1, hi1, lo0, hi0 = parts
    a1, b1, a0, b0 = _clip(ax, ay, bx, by, xy, fr, starts[q], starts[q + 1], q < p, eps)
    if a1 < b1 and n1 > 0:
        n1 = _compact(lo1, hi1, _subtract(lo1, hi1, n1, a1, b1))
    if a0 < b0 and n0 > 0:
        n0 = _compact(lo0, hi0, _subtract(lo0, hi0, n0, a0, b0))
    return n1, n0


# Compiled once and called (not inlined) by the no-fit polygon's outline and the depth's
# escape search; it allocates nothing, so its callers' arrays pass without reference counts.
@njit(cache=True, nogil=True, _nrt=False)
def clip_edge(sums, index, p, ax, ay, bx, by, t0, t1, eps, hint):
    """Clip the part [t0, t1] of edge (a, b) of sum p by the other ``sums`` (``(xy,
    starts, boxes, frames)``: see :func:`sum_index`), until nothing is left. Returns
    ``(n1, n0, hint)``: the parts outside every closed sum shrunk by eps (``lo1[:n1],
    hi1[:n1]`` of the index) and outside every open sum (``lo0[:n0], hi0[:n0]``), as
    parameters along the edge, and the sum that covered the edge whole (else ``hint``
    unchanged).

    The sums covering whole cells along the edge are tried first, then ``hint`` (the
    sum that covered the previous edge: an edge inside the union is then usually done
    after one test), then the others: those listed in the cells along the part (each
    once), or without that grid by their smallest x, from the first that can reach the
    edge (none is wider than ``wmax``).
    """
    xy, starts, bb, fr = sums
    by_x, xs, wmax, cover, gx0, gy0, h, tried, near, marks, lo1, hi1, lo0, hi0 = index
    parts = (lo1, hi1, lo0, hi0)
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
            n1, n0 = _cut(ax, ay, bx, by, xy, fr, starts, q, p, eps, parts, n1, n0)
            if n1 == 0 and n0 == 0:
                return n1, n0, hint
    x0 = min(ax, bx) - eps
    x1 = max(ax, bx) + eps
    y0 = min(ay, by) - eps
    y1 = max(ay, by) + eps
    if g > 0:
        # the sums listed in the cells along the part clipped: those within eps of it
        pax = ax + t0 * (bx - ax)
        pay = ay + t0 * (by - ay)
        pbx = ax + t1 * (bx - ax)
        pby = ay + t1 * (by - ay)
        cells, seen = marks
        nc = -1
        if in_grid(near, pax, pay) and in_grid(near, pbx, pby):
            nc = segment_cells(near, pax, pay, pbx, pby, eps, cells)
        if nc >= 0:
            stamp = seen[k] = seen[k] + 1  # (this edge's mark)
            for v in range(nt):
                seen[tried[v]] = stamp
            if hint >= 0:
                if hint != p:
                    n1, n0 = _cut(ax, ay, bx, by, xy, fr, starts, hint, p, eps, parts, n1,
                                  n0)
                    if n1 == 0 and n0 == 0:
                        return n1, n0, hint
                seen[hint] = stamp
            first, items = near[5], near[6]
            for ci in range(nc):
                cell = cells[ci]
                for u in range(first[cell], first[cell + 1]):
                    q = items[u]
                    if q == p or seen[q] == stamp:
                        continue
                    seen[q] = stamp
                    if bb[q, 0] > x1 or bb[q, 2] < x0 or bb[q, 1] > y1 or bb[q, 3] < y0:
                        continue
                    n1, n0 = _cut(ax, ay, bx, by, xy, fr, starts, q, p, eps, parts, n1, n0)
                    if n1 == 0 and n0 == 0:
                        return n1, n0, q
            return n1, n0, hint
    first = np.searchsorted(xs, x0 - wmax)
    for qi in range(first - 1, k):
        q = hint if qi < first else by_x[qi]
        if qi >= first and xs[qi] > x1:
            break  # sorted by their smallest x: none further can meet the edge
        if q < 0 or (qi >= first and q == hint):
            continue
        if q == p or bb[q, 0] > x1 or bb[q, 2] < x0 or bb[q, 1] > y1 or bb[q, 3] < y0:
            continue
        n1, n0 = _cut(ax, ay, bx, by, xy, fr, starts, q, p, eps, parts, n1, n0)
        if n1 == 0 and n0 == 0:
            return n1, n0, q
    return n1, n0, hint
