"""Kernels: edges sorted by their smallest x, for the sweeps.

The state kernel and the ring check find the pairs of edges whose boxes meet by
sorting edge boxes on xmin and sweeping: :func:`window_edges` lists one body's edges
in a window, :func:`sort_into` orders rows without allocating (a bucket pass, then
insertion, a heap sort when keys bunch), :func:`sorted_edge_boxes` sorts a ring's
edges row by row.
"""

from __future__ import annotations

import numpy as np

from .jit import njit


@njit(cache=True, nogil=True)
def window_edges(xy, starts, offset, wx0, wx1, wy0, wy1, box, ids, cnt):
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
def sort_into(box, cnt, order, start):
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
def sorted_edge_boxes(xy, n):
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
