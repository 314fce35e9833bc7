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


@njit(cache=True, nogil=True)
def lowest(xy, s, e):
    """The lowest vertex (then leftmost) of rows s:e of ``xy``."""
    best = s
    for i in range(s + 1, e):
        if xy[i, 1] < xy[best, 1] or (xy[i, 1] == xy[best, 1] and xy[i, 0] < xy[best, 0]):
            best = i
    return best


@njit(cache=True, nogil=True)
def sum_into(bxy, ps, pe, i0, rxy, qs, qe, out, w):
    """Write the Minkowski sum of the convex CCW pieces ``bxy[ps:pe]`` (lowest vertex
    ``i0``) and ``rxy[qs:qe]`` into ``out`` from row ``w``, counter-clockwise from the
    sum of their lowest vertices, by merging their edges by angle (O(p + q)); returns
    the next free row."""
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
        i0 = lowest(bxy, ps, pe)
        for rj in range(nr):
            w = sum_into(bxy, ps, pe, i0, rxy, rstarts[rj], rstarts[rj + 1], out, w)
            k += 1
            starts[k] = w
    return out[:w], starts


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


@njit(cache=True, nogil=True)
def frames(xy, starts):
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
def in_some_sum(px, py, starts, bb, fr, margin, skip):
    """Whether p lies in some convex sum other than sum ``skip`` (-1: none skipped), of
    boxes ``bb`` (:func:`boxes`) and edge frames ``fr`` (:func:`frames`).

    ``margin`` >= 0: inside a sum by more than ``margin`` (open: on every edge's line's
    inner side by more than it, and likewise of the box). ``margin`` < 0: in a closed
    sum, with no tolerance (for points that the caller puts well inside or outside).
    """
    closed = margin < 0.0
    m = 0.0 if closed else margin
    for q in range(starts.shape[0] - 1):
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


@njit(cache=True, nogil=True)
def _clip(ax, ay, bx, by, fr, s, e, q_first, eps):
    """Parts of segment ab (parameter t in [0, 1]) covered by convex polygon s:e.

    ``fr`` holds the edge frames of :func:`frames`. Returns ``(lo1, hi1, lo0, hi0)``:
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
def sum_index(sums, gx0, gy0, h, grid_from=GRID_MIN_SUMS):
    """What :func:`clip_edge` reads to clip edges by the convex ``sums``, ``(xy, starts,
    bb, fr)`` (the packed sums, their boxes and edge frames): the sums sorted by their
    smallest x (``by_x``, ``xs``) and their widest box (``wmax``); a ``GRID`` x ``GRID``
    grid of cells of side ``h`` from ``(gx0, gy0)`` with the sums containing each cell
    whole (:func:`_cell_cover`), or no grid (0 x 0) for fewer than ``grid_from`` sums
    (the same clips, found by the scan alone), and a buffer of the sums tried on an
    edge; the four interval buffers of the clipped parts."""
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
    cap = 2 * k + 4
    return (by_x, xs, wmax, cover, gx0, gy0, h, tried,
            np.empty(cap), np.empty(cap), np.empty(cap), np.empty(cap))


@njit(cache=True, nogil=True, inline="always")
def _cut(ax, ay, bx, by, fr, starts, q, p, eps, parts, n1, n0):
    """Take from the parts of edge (a, b) of sum p what sum q covers: of ``parts`` =
    ``(lo1, hi1, lo0, hi0)``, from ``lo1[:n1], hi1[:n1]`` its closed interior shrunk by
    eps, from ``lo0[:n0], hi0[:n0]`` its open interior (see :func:`_clip`); returns the
    new ``(n1, n0)``."""
    lo1, hi1, lo0, hi0 = parts
    a1, b1, a0, b0 = _clip(ax, ay, bx, by, fr, starts[q], starts[q + 1], q < p, eps)
    if a1 < b1 and n1 > 0:
        n1 = _compact(lo1, hi1, _subtract(lo1, hi1, n1, a1, b1))
    if a0 < b0 and n0 > 0:
        n0 = _compact(lo0, hi0, _subtract(lo0, hi0, n0, a0, b0))
    return n1, n0


@njit(cache=True, nogil=True, inline="always")
def clip_edge(sums, index, p, ax, ay, bx, by, t0, t1, eps, hint):
    """Clip the part [t0, t1] of edge (a, b) of sum p by the other ``sums`` (``(xy,
    starts, boxes, frames)``: see :func:`sum_index`), until nothing is left. Returns
    ``(n1, n0, hint)``: the parts outside every closed sum shrunk by eps (``lo1[:n1],
    hi1[:n1]`` of the index) and outside every open sum (``lo0[:n0], hi0[:n0]``), as
    parameters along the edge, and the sum that covered the edge whole (else ``hint``
    unchanged).

    The sums covering whole cells along the edge are tried first, then ``hint`` (the
    sum that covered the previous edge: an edge inside the union is then usually done
    after one test), then the others by their smallest x, from the first that can reach
    the edge (none is wider than ``wmax``).
    """
    _, starts, bb, fr = sums
    by_x, xs, wmax, cover, gx0, gy0, h, tried, lo1, hi1, lo0, hi0 = index
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
            n1, n0 = _cut(ax, ay, bx, by, fr, starts, q, p, eps, parts, n1, n0)
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
        n1, n0 = _cut(ax, ay, bx, by, fr, starts, q, p, eps, parts, n1, n0)
        if n1 == 0 and n0 == 0:
            return n1, n0, q
    return n1, n0, hint
