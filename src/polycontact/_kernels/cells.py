"""Kernel: uniform grids of cells listing what passes near each cell: segments (for
"which segments come within a distance of this point") or convex polygons (for "which
polygons may hold this point, or meet this segment").

A segment is listed in every cell that its ``margin``-neighbourhood meets, found column
by column (so a long segment costs the cells along it, not its whole bounding box); a
convex polygon in every cell its ``margin``-neighbourhood meets (its extent in each
column of cells, from its edges). Items are listed in increasing order, so that a query
reads those near a point in the order a scan of all of them would meet them.

A grid is ``(x0, y0, h, gx, gy, first, items)``: ``gx`` x ``gy`` square cells of side
``h`` from ``(x0, y0)``, cell ``(c, r)`` (number ``c * gy + r``) listing
``items[first[c * gy + r]:first[c * gy + r + 1]]``.

Examples
--------
>>> import numpy as np
>>> seg = np.array([[0.0, 0.0, 4.0, 0.0], [0.0, 3.0, 4.0, 3.0], [2.0, 0.0, 2.0, 3.0]])
>>> grid = segment_grid(seg, np.array([[1.0, 0.1], [3.0, 2.9]]), 0.5)
>>> listed(grid, 1.0, 0.1).tolist(), listed(grid, 3.0, 2.9).tolist()  # (cells ~1 wide)
([0, 2], [1, 2])
"""

from __future__ import annotations

import numpy as np

from .jit import njit


@njit(cache=True, nogil=True)
def _side(w, ht, cells, margin):
    """The side of about ``cells`` square cells over a w x ht box, none narrower than
    2 ``margin`` (a point is then listed in at most four)."""
    return max(np.sqrt(w * ht / cells), max(w, ht) / cells, 2.0 * margin, 1e-300)


@njit(cache=True, nogil=True)
def _span(ax, ay, bx, by, m, x0, h, c):
    """``(ylo, yhi)``: the y range of segment ab over column c (x in [x0 + c h,
    x0 + (c + 1) h], widened by m), where the segment is (a column it does not reach
    within m gives its nearer end)."""
    xmin = min(ax, bx)
    xmax = max(ax, bx)
    cx0 = min(max(x0 + c * h - m, xmin), xmax)
    cx1 = min(max(x0 + (c + 1) * h + m, xmin), xmax)
    if bx == ax:
        return min(ay, by), max(ay, by)
    ya = ay + (by - ay) * min(max((cx0 - ax) / (bx - ax), 0.0), 1.0)
    yb = ay + (by - ay) * min(max((cx1 - ax) / (bx - ax), 0.0), 1.0)
    return min(ya, yb), max(ya, yb)


@njit(cache=True, nogil=True)
def _columns(lo, hi, x0, h, gx):
    """The columns (first, last) met by [lo, hi] (empty when first > last)."""
    return max(int(np.floor((lo - x0) / h)), 0), min(int(np.floor((hi - x0) / h)), gx - 1)


@njit(cache=True, nogil=True)
def _finish(first, gx, gy):
    """Counts (``first[cell + 1]``) made starts; returns the items array and the fill
    positions."""
    for c in range(gx * gy):
        first[c + 1] += first[c]
    return np.empty(first[gx * gy], np.int64), first[:-1].copy()


@njit(cache=True, nogil=True)
def _put(first, items, fill, cell, s, write):
    """Count (``write`` False) or list item s in a cell."""
    if write:
        items[fill[cell]] = s
        fill[cell] += 1
    else:
        first[cell + 1] += 1


@njit(cache=True, nogil=True)
def segment_grid(seg, points, margin, side=0.0):
    """The cells over the box of ``points`` (P, 2) listing the segments ``seg`` (S, 4)
    rows ``(x0, y0, x1, y1)``, a point being a segment of length 0) within ``margin`` of
    each (about P + S cells, none narrower than ``side``)."""
    x0 = points[:, 0].min()
    y0 = points[:, 1].min()
    w = points[:, 0].max() - x0
    ht = points[:, 1].max() - y0
    h = max(_side(w, ht, points.shape[0] + seg.shape[0], margin), side)
    gx = int(w / h) + 1
    gy = int(ht / h) + 1
    first = np.zeros(gx * gy + 1, np.int64)
    items = first[:0]
    fill = first[:0]
    for write in (False, True):
        if write:
            items, fill = _finish(first, gx, gy)
        for s in range(seg.shape[0]):
            ax, ay, bx, by = seg[s, 0], seg[s, 1], seg[s, 2], seg[s, 3]
            c0, c1 = _columns(min(ax, bx) - margin, max(ax, bx) + margin, x0, h, gx)
            for c in range(c0, c1 + 1):
                ylo, yhi = _span(ax, ay, bx, by, margin, x0, h, c)
                r0, r1 = _columns(ylo - margin, yhi + margin, y0, h, gy)
                for r in range(r0, r1 + 1):
                    _put(first, items, fill, c * gy + r, s, write)
    return x0, y0, h, gx, gy, first, items


@njit(cache=True, nogil=True)
def polygon_grid(xy, starts, bb, margin, cells):
    """The cells over the box of the convex polygons ``(xy, starts)`` (boxes ``bb``,
    rows ``(xmin, ymin, xmax, ymax)``) listing each polygon whose ``margin``-
    neighbourhood meets them. The side follows the polygons' box areas so that about
    ``cells`` entries are listed in all (fewer for polygons smaller than their boxes)."""
    k = starts.shape[0] - 1
    x0 = bb[:, 0].min() - margin
    y0 = bb[:, 1].min() - margin
    w = bb[:, 2].max() + margin - x0
    ht = bb[:, 3].max() + margin - y0
    area = 0.0
    for q in range(k):
        area += (bb[q, 2] - bb[q, 0] + 2.0 * margin) * (bb[q, 3] - bb[q, 1] + 2.0 * margin)
    h = max(_side(w, ht, cells, margin), np.sqrt(area / cells))
    gx = int(w / h) + 1
    gy = int(ht / h) + 1
    first = np.zeros(gx * gy + 1, np.int64)
    items = first[:0]
    fill = first[:0]
    lo = np.empty(gx)
    hi = np.empty(gx)
    for write in (False, True):
        if write:
            items, fill = _finish(first, gx, gy)
        for q in range(k):
            # the polygon's y range in each column, from its edges
            c0, c1 = _columns(bb[q, 0] - margin, bb[q, 2] + margin, x0, h, gx)
            lo[c0:c1 + 1] = np.inf
            hi[c0:c1 + 1] = -np.inf
            for i in range(starts[q], starts[q + 1]):
                j = i + 1 if i + 1 < starts[q + 1] else starts[q]
                ax, ay, bx, by = xy[i, 0], xy[i, 1], xy[j, 0], xy[j, 1]
                e0, e1 = _columns(min(ax, bx) - margin, max(ax, bx) + margin, x0, h, gx)
                for c in range(e0, e1 + 1):
                    ylo, yhi = _span(ax, ay, bx, by, margin, x0, h, c)
                    lo[c] = min(lo[c], ylo)
                    hi[c] = max(hi[c], yhi)
            for c in range(c0, c1 + 1):
                if lo[c] > hi[c]:
                    continue
                r0, r1 = _columns(lo[c] - margin, hi[c] + margin, y0, h, gy)
                for r in range(r0, r1 + 1):
                    _put(first, items, fill, c * gy + r, q, write)
    return x0, y0, h, gx, gy, first, items


@njit(cache=True, nogil=True)
def listed(grid, px, py):
    """The items listed in the cell of (px, py) (a point of the grid's box), in
    increasing order."""
    x0, y0, h, gx, gy, first, items = grid
    c = min(max(int(np.floor((px - x0) / h)), 0), gx - 1)
    r = min(max(int(np.floor((py - y0) / h)), 0), gy - 1)
    cell = c * gy + r
    return items[first[cell]:first[cell + 1]]


@njit(cache=True, nogil=True)
def in_grid(grid, px, py):
    """Whether (px, py) lies in the grid's box (a cell of its own)."""
    x0, y0, h, gx, gy, _, _ = grid
    return x0 <= px <= x0 + gx * h and y0 <= py <= y0 + gy * h


@njit(cache=True, nogil=True)
def segment_cells(grid, ax, ay, bx, by, margin, out):
    """Write into ``out`` the cells that the ``margin``-neighbourhood of segment ab meets
    (a segment inside the grid's box); returns their count, or -1 when ``out`` (at
    least 3 (gx + gy) + 8 long suffices) is too short."""
    x0, y0, h, gx, gy, _, _ = grid
    n = 0
    c0, c1 = _columns(min(ax, bx) - margin, max(ax, bx) + margin, x0, h, gx)
    for c in range(c0, c1 + 1):
        ylo, yhi = _span(ax, ay, bx, by, margin, x0, h, c)
        r0, r1 = _columns(ylo - margin, yhi + margin, y0, h, gy)
        for r in range(r0, r1 + 1):
            if n == out.shape[0]:
                return -1
            out[n] = c * gy + r
            n += 1
    return n
