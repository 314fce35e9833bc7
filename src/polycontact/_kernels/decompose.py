"""Kernel: merge the triangles of a polygon into convex pieces (Hertel–Mehlhorn).

The triangles come from a triangulation without Steiner points (GEOS's constrained
Delaunay triangulation of the polygon, holes included). Two pieces that share a
diagonal are merged whenever the result stays convex; greedy merging yields at most
four times the minimum number of convex pieces, and in practice close to it.
"""

from __future__ import annotations

import numpy as np

from .jit import njit
from .primitives import orient
from .tolerance import tolerance_of


#: Up to this many half-edges (three per triangle), :func:`convex_pieces` pairs them
#: by a plain O(h^2) search rather than by sorting.
_FEW_HALF_EDGES = 96


@njit(cache=True, nogil=True)
def convex_pieces(vxy, tri, rel_tol, ulps):
    """Convex pieces covering the union of triangles.

    ``vxy`` (V, 2) float64 holds the vertices and ``tri`` (T, 3) int64 the triangles as
    vertex indices (either orientation). Two triangles are neighbours when they share
    an edge, i.e. two vertex indices. Triangles whose doubled area is at most ``eps``
    times their longest edge are dropped (zero area), with ``eps`` the default
    tolerance of the vertices (:func:`polycontact._kernels.tolerance.tolerance_of`
    with ``rel_tol`` and ``ulps``). Returns ``(xy, starts)``: the
    pieces packed like a shape's loops, each counter-clockwise, piece ``k`` in rows
    ``starts[k]:starts[k + 1]``. Vertices where two merged edges go straight on are
    removed.
    """
    n_tri = tri.shape[0]
    nv = vxy.shape[0]
    vx = vxy[:, 0]
    vy = vxy[:, 1]
    eps = tolerance_of(vxy, rel_tol, ulps)
    org = np.empty(3 * n_tri, np.int64)
    nxt = np.empty(3 * n_tri, np.int64)
    prv = np.empty(3 * n_tri, np.int64)
    alive = np.zeros(3 * n_tri, np.bool_)
    nh = 0
    for t in range(n_tri):
        a = tri[t, 0]
        b = tri[t, 1]
        c = tri[t, 2]
        o = orient(vx[a], vy[a], vx[b], vy[b], vx[c], vy[c])
        longest = max(np.hypot(vx[b] - vx[a], vy[b] - vy[a]),
                      np.hypot(vx[c] - vx[b], vy[c] - vy[b]),
                      np.hypot(vx[a] - vx[c], vy[a] - vy[c]))
        if abs(o) <= eps * longest:
            continue
        org[nh] = a
        org[nh + 1] = b if o > 0.0 else c
        org[nh + 2] = c if o > 0.0 else b
        for k in range(3):
            nxt[nh + k] = nh + (k + 1) % 3
            prv[nh + k] = nh + (k + 2) % 3
            alive[nh + k] = True
        nh += 3
    # Twins: half-edge u->v of one triangle and v->u of its neighbour (sorted keys; for
    # few triangles, a plain search, which is faster there).
    twin = np.full(nh, -1, np.int64)
    if nh <= _FEW_HALF_EDGES:
        for h in range(nh):
            u = org[h]
            v = org[nxt[h]]
            for g in range(nh):
                if org[g] == v and org[nxt[g]] == u:
                    twin[h] = g
                    break
    else:
        keys = np.empty(nh, np.int64)
        for h in range(nh):
            keys[h] = org[h] * nv + org[nxt[h]]
        order = np.argsort(keys)
        sorted_keys = keys[order]
        for h in range(nh):
            back = org[nxt[h]] * nv + org[h]
            r = np.searchsorted(sorted_keys, back)
            if r < nh and sorted_keys[r] == back:
                twin[h] = order[r]
    # Union-find over pieces (one per triangle at first) to skip diagonals inside a piece.
    parent = np.arange(nh // 3)
    for h in range(nh):
        g = twin[h]
        if g < h:
            continue
        p = h // 3
        while parent[p] != p:
            p = parent[p]
        q = g // 3
        while parent[q] != q:
            q = parent[q]
        if p == q:
            continue
        u = org[h]
        v = org[g]
        # After the merge: prv[h] -> u -> nxt[g] ... prv[g] -> v -> nxt[h]
        a = org[prv[h]]
        b = org[nxt[nxt[g]]]
        if orient(vx[a], vy[a], vx[u], vy[u], vx[b], vy[b]) < 0.0:
            continue
        a = org[prv[g]]
        b = org[nxt[nxt[h]]]
        if orient(vx[a], vy[a], vx[v], vy[v], vx[b], vy[b]) < 0.0:
            continue
        nxt[prv[h]] = nxt[g]
        prv[nxt[g]] = prv[h]
        nxt[prv[g]] = nxt[h]
        prv[nxt[h]] = prv[g]
        alive[h] = False
        alive[g] = False
        parent[q] = p
    # Walk the remaining cycles.
    out = np.empty((nh, 2))
    starts = np.empty(nh + 1, np.int64)
    seen = ~alive
    n_out = 0
    n_pieces = 0
    starts[0] = 0
    for h0 in range(nh):
        if seen[h0]:
            continue
        h = h0
        while not seen[h]:
            seen[h] = True
            u = org[h]
            a = org[prv[h]]
            b = org[nxt[h]]
            # drop straight-through vertices left by merges (exactly collinear)
            if orient(vx[a], vy[a], vx[u], vy[u], vx[b], vy[b]) != 0.0:
                out[n_out, 0] = vx[u]
                out[n_out, 1] = vy[u]
                n_out += 1
            h = nxt[h]
        n_pieces += 1
        starts[n_pieces] = n_out
    return out[:n_out].copy(), starts[: n_pieces + 1].copy()


@njit(cache=True, nogil=True)
def is_convex(xy):
    """Whether the CCW ring ``xy`` (shape (N, 2)) turns left or goes straight everywhere."""
    n = xy.shape[0]
    for i in range(n):
        j = (i + 1) % n
        k = (i + 2) % n
        if orient(xy[i, 0], xy[i, 1], xy[j, 0], xy[j, 1], xy[k, 0], xy[k, 1]) < 0.0:
            return False
    return True


@njit(cache=True, nogil=True)
def _ear_quality(xy, p, i, q, nxt):
    """Shape quality of the ear at i (1 equilateral, near 0 thin) or -1 if not an ear.

    An ear is a strictly convex vertex whose triangle (p, i, q) holds no other
    remaining vertex, boundary included (vertices equal to p, i or q excepted).
    """
    o = orient(xy[p, 0], xy[p, 1], xy[i, 0], xy[i, 1], xy[q, 0], xy[q, 1])
    if o <= 0.0:
        return -1.0
    j = nxt[q]
    while j != p:
        x = xy[j, 0]
        y = xy[j, 1]
        if not ((x == xy[p, 0] and y == xy[p, 1]) or (x == xy[i, 0] and y == xy[i, 1])
                or (x == xy[q, 0] and y == xy[q, 1])):
            if (orient(xy[p, 0], xy[p, 1], xy[i, 0], xy[i, 1], x, y) >= 0.0
                    and orient(xy[i, 0], xy[i, 1], xy[q, 0], xy[q, 1], x, y) >= 0.0
                    and orient(xy[q, 0], xy[q, 1], xy[p, 0], xy[p, 1], x, y) >= 0.0):
                return -1.0
        j = nxt[j]
    d2 = ((xy[i, 0] - xy[p, 0]) ** 2 + (xy[i, 1] - xy[p, 1]) ** 2
          + (xy[q, 0] - xy[i, 0]) ** 2 + (xy[q, 1] - xy[i, 1]) ** 2
          + (xy[p, 0] - xy[q, 0]) ** 2 + (xy[p, 1] - xy[q, 1]) ** 2)
    return 2.0 * np.sqrt(3.0) * o / d2


@njit(cache=True, nogil=True)
def ear_triangles(xy):
    """Triangles of a simple CCW ring by ear clipping, best-shaped ear first (O(n^2)).

    Vertices where the ring goes straight on are skipped first. Clipping the fattest
    ear each time gives triangles close to a Delaunay triangulation, which merge into
    fewer convex pieces than a fan. Returns ``(ok, tri)`` with ``tri`` (T, 3) int64,
    the triangles as indices into ``xy``; ``ok`` is False when no ear is left (only
    possible through rounding in a near-degenerate ring).
    """
    n = xy.shape[0]
    nxt = np.empty(n, np.int64)
    prv = np.empty(n, np.int64)
    alive = np.ones(n, np.bool_)
    for i in range(n):
        nxt[i] = (i + 1) % n
        prv[i] = (i - 1) % n
    left = n
    # drop straight-through vertices
    i = 0
    steps = 0
    while steps < left and left > 3:
        p = prv[i]
        q = nxt[i]
        if orient(xy[p, 0], xy[p, 1], xy[i, 0], xy[i, 1], xy[q, 0], xy[q, 1]) == 0.0:
            nxt[p] = q
            prv[q] = p
            alive[i] = False
            left -= 1
            i = p
            steps = 0
        else:
            i = q
            steps += 1
    quality = np.full(n, -1.0)
    for i in range(n):
        if alive[i]:
            quality[i] = _ear_quality(xy, prv[i], i, nxt[i], nxt)
    tri = np.empty((max(left - 2, 1), 3), np.int64)
    nt = 0
    while left > 3:
        best = -1
        for i in range(n):
            if alive[i] and quality[i] > 0.0 and (best < 0 or quality[i] > quality[best]):
                best = i
        if best < 0:
            return False, tri[:0]
        p = prv[best]
        q = nxt[best]
        tri[nt, 0] = p
        tri[nt, 1] = best
        tri[nt, 2] = q
        nt += 1
        nxt[p] = q
        prv[q] = p
        alive[best] = False
        left -= 1
        quality[p] = _ear_quality(xy, prv[p], p, q, nxt)
        quality[q] = _ear_quality(xy, p, q, nxt[q], nxt)
    for i in range(n):
        if alive[i]:
            tri[nt, 0] = prv[i]
            tri[nt, 1] = i
            tri[nt, 2] = nxt[i]
            nt += 1
            break
    return True, tri[:nt].copy()


@njit(cache=True, nogil=True)
def ring_pieces(xy, rel_tol, ulps, max_ear):
    """Convex pieces of a simple CCW ring in one call: ``(ok, xy, starts)``.

    The ring itself when it is convex; else best-ear triangles merged by
    :func:`convex_pieces` when it has at most ``max_ear`` vertices. ``ok`` is False
    when neither applies (the caller triangulates another way).
    """
    if is_convex(xy):
        return True, xy.copy(), np.array([0, xy.shape[0]], np.int64)
    if xy.shape[0] <= max_ear:
        ok, tri = ear_triangles(xy)
        if ok:
            pxy, st = convex_pieces(xy, tri, rel_tol, ulps)
            return True, pxy, st
    return False, np.empty((0, 2)), np.zeros(1, np.int64)
