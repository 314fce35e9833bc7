"""Kernel: penetration depth from the convex Minkowski sums near the origin.

A translation ``d`` of A makes the interiors of A and B overlap exactly when ``d`` lies
in the union ``O`` of the open convex sums ``int(B_i ⊕ (−A_j))`` over convex pieces
``B_i`` of B and ``A_j`` of A (see :mod:`polycontact._kernels.nfp`). The penetration
depth is the distance from the origin to the complement of ``O``: to the outline of the
union (the boundary of the entrance block, translated so A's reference is the origin),
or to an exact fit or slide inside it (sum boundaries covered by no open sum).

Only the part of the union inside the disk of radius ``bound`` (a known escape: the
shortest of the translations out of B's bounding box and, for small bodies, along the
edge normals that separate the projections, :func:`first_escape`) can hold the answer:
only the pairs of pieces whose sum's box meets that disk's box are summed. A sum that
holds the origin at distance ``low`` from its outline proves the depth at least ``low``
(the union holds the sum): when ``bound - low <= eps`` the bound is the depth within eps
and the search stops there (two convex bodies, and about a fifth of the benchmark's
concave 12-gon pairs). The origin's foot on the outline of the deepest such sum is at
that lower bound: when no other open sum covers it and the classifier confirms it, it
is the depth (another third). Else the sums' edges are visited in increasing distance
from the origin, each clipped by the open sums (the one that covered the previous edge first,
the deepest sum on the first edge) until the first uncovered part; the search stops
when the next edge is farther than the best escape found. Uncovered parts, and the
first escape when nothing nearer is found, are confirmed with the state kernel.

Small bodies (at most :data:`polycontact._kernels.convolution.FEW_VERTICES` vertices
in both) first take the vertex-edge contact segments of
:mod:`polycontact._kernels.convolution`, with no convex pieces; this search is their
fallback when that kernel cannot decide (segments that run together: slides, exact
fits).

Many pairs (for ``classify_many(...).distances``): :func:`contact_depths` and
:func:`depths_of_pairs` compute a run of pairs, :func:`pieces_of_bodies` decomposes a
run of bodies, without the GIL (the caller splits the work over threads),
:func:`pair_keys` and :func:`distinct_pairs` find the pairs to compute once and
:func:`distinct_bodies` the bodies to decompose once (see
:func:`polycontact._depth.penetrations`).
"""

from __future__ import annotations

import numpy as np

from .jit import njit
from .cells import segment_grid
from .convolution import FEW_VERTICES, contact_depth, penetrates
from .decompose import ring_pieces
from .minkowski import (GRID, GRID_MIN_SUMS, boxes, clip_edge, frames, in_some_sum, lowest,
                        no_flags, sum_index, sum_into)
from .packs import scratch_floats
from .primitives import bbox, closest_on_segment, origin_distance_sq_framed, origin_foot
from .relation_many import body, oriented


@njit(cache=True, nogil=True)
def _in_disk(ax, ay, bx, by, r):
    """Parameter interval [lo, hi] of segment ab (t in [0, 1]) within distance r of the
    origin (empty when lo >= hi)."""
    dx = bx - ax
    dy = by - ay
    a = dx * dx + dy * dy
    if a == 0.0:
        return 0.0, 1.0 if np.hypot(ax, ay) < r else 0.0
    t0 = -(ax * dx + ay * dy) / a
    fx = ax + t0 * dx
    fy = ay + t0 * dy
    w = r * r - (fx * fx + fy * fy)
    if w <= 0.0:
        return 1.0, 0.0
    half = np.sqrt(w / a)
    return max(0.0, t0 - half), min(1.0, t0 + half)


@njit(cache=True, nogil=True)
def _select_pairs(bb_b, bb_r, bound, bstarts, rstarts, max_vertices):
    """Pairs (i, j) of pieces whose sum's bounding box meets [-bound, bound]^2; the one
    row (-1, -1) when their sums would hold more than ``max_vertices`` vertices.

    Pieces of B sorted by their smallest x; for each piece j of R, the pieces i with
    ``x0_i <= bound - x0_j`` and ``x0_i >= -bound - x1_j - w`` (w: widest piece of B) are
    scanned by binary search, then tested on both axes.
    """
    nb = bb_b.shape[0]
    nr = bb_r.shape[0]
    order = np.argsort(bb_b[:, 0])
    xs = bb_b[order, 0]
    w = 0.0
    for i in range(nb):
        w = max(w, bb_b[i, 2] - bb_b[i, 0])
    cap = 16 + nb + nr
    out = np.empty((cap, 2), np.int64)
    n = 0
    total = 0
    for j in range(nr):
        lo = -bound - bb_r[j, 2]
        hi = bound - bb_r[j, 0]
        ylo = -bound - bb_r[j, 3]
        yhi = bound - bb_r[j, 1]
        k = np.searchsorted(xs, lo - w)
        while k < nb and xs[k] <= hi:
            i = order[k]
            k += 1
            if bb_b[i, 2] < lo or bb_b[i, 1] > yhi or bb_b[i, 3] < ylo:
                continue
            if n == out.shape[0]:
                grown = np.empty((2 * n, 2), np.int64)
                grown[:n] = out[:n]
                out = grown
            out[n, 0] = i
            out[n, 1] = j
            n += 1
            total += bstarts[i + 1] - bstarts[i] + rstarts[j + 1] - rstarts[j]
            if total > max_vertices:
                return np.full((1, 2), -1, np.int64)
    return out[:n]


@njit(cache=True, nogil=True)
def _pair_sums(bxy, bstarts, rxy, rstarts, pairs):
    """Convex sums of the given pairs of convex CCW pieces, in O(p + q) each (packed)."""
    total = 0
    for k in range(pairs.shape[0]):
        i = pairs[k, 0]
        j = pairs[k, 1]
        total += bstarts[i + 1] - bstarts[i] + rstarts[j + 1] - rstarts[j]
    out = np.empty((total, 2))
    starts = np.empty(pairs.shape[0] + 1, np.int64)
    starts[0] = 0
    w = 0
    flags = no_flags()
    for k in range(pairs.shape[0]):
        ps = bstarts[pairs[k, 0]]
        pe = bstarts[pairs[k, 0] + 1]
        w = sum_into(bxy, ps, pe, lowest(bxy, ps, pe), rxy, rstarts[pairs[k, 1]],
                     rstarts[pairs[k, 1] + 1], out, w, flags)
        starts[k + 1] = w
    return out[:w].copy(), starts


@njit(cache=True, nogil=True)
def depth_from_pieces(a, b, pieces_b, pieces_r, escape, eps, max_vertices,
                      grid_from=GRID_MIN_SUMS):
    """Penetration depth of A into B: ``(depth, dx, dy)``, the shortest escape.

    ``a`` = ``(xa, sa)``, ``b`` = ``(xb, sb)``: the packed bodies (interior on the left);
    ``pieces_b`` = ``(bxy, bstarts)``: convex CCW pieces of B; ``pieces_r`` = ``(rxy,
    rstarts)``: convex CCW pieces of −A; ``escape`` = ``(bound, bdx, bdy)``: a
    translation of A, of length ``bound``, that ends the overlap (:func:`first_escape`,
    or :func:`box_escape`).
    Returns ``(bound, bdx, bdy)`` when nothing nearer ends it (confirmed by the state
    kernel; if rounding left it penetrating, the search is made again from the box's
    escape), NaNs when the sums would hold more than ``max_vertices`` vertices (none
    is built). The edges are clipped with the grid of
    :func:`polycontact._kernels.minkowski.sum_index` from ``grid_from`` sums on, else by the
    scan alone (a 12-gon pair makes about 9 sums; the grid's set-up cost 83 of its 105
    us).

    Cost: with P pairs of pieces whose sums' boxes meet the disk of radius ``bound`` and
    K edges of those sums nearer than the depth, O((p + q) log(p + q) + P + K log K)
    plus the clipping of each of those K edges by the sums until one covers it (one,
    usually: the sum that covered the previous edge is tried first) and one state check,
    O((m + n) log(m + n)), per uncovered part nearer than the best escape so far.
    """
    xa, sa = a
    xb, sb = b
    moved = np.empty_like(xa)
    scratch = np.empty(scratch_floats(xa.shape[0] + xb.shape[0]))
    got = _nearest_escape(a, b, pieces_b, pieces_r, escape, eps, max_vertices, grid_from,
                          moved, scratch)
    if got[3] or np.isnan(got[0]) or not penetrates(xa, sa, xb, sb, escape[1], escape[2], eps,
                                                    moved, scratch):
        return got[0], got[1], got[2]
    # (a normal's escape left touching within rounding, yet penetrating: the box's)
    got = _nearest_escape(a, b, pieces_b, pieces_r, box_escape(xa, xb), eps, max_vertices,
                          grid_from, moved, scratch)
    return got[0], got[1], got[2]


@njit(cache=True, nogil=True)
def _nearest_escape(a, b, pieces_b, pieces_r, escape, eps, max_vertices, grid_from, moved,
                    scratch):
    """:func:`depth_from_pieces`'s search: ``(depth, dx, dy, found)``, ``found`` False
    when nothing nearer than ``bound`` was found (then ``escape``, not confirmed);
    ``moved``, ``scratch``: see :func:`polycontact._kernels.convolution.penetrates`.

    The origin's distance to the outline of a sum that holds it is a lower bound of the
    depth (the union holds that sum); when the largest is within ``eps`` of ``bound``,
    the search stops there: the depth is ``bound`` within ``eps``; when the origin's
    foot on that outline escapes, it is the depth.
    """
    xa, sa = a
    xb, sb = b
    bxy, bstarts = pieces_b
    rxy, rstarts = pieces_r
    bound, bdx, bdy = escape
    best = bound
    pairs = _select_pairs(boxes(bxy, bstarts), boxes(rxy, rstarts), bound,
                          bstarts, rstarts, max_vertices)
    if pairs.shape[0] == 1 and pairs[0, 0] < 0:
        return np.nan, np.nan, np.nan, False
    if pairs.shape[0] == 0:
        return best, bdx, bdy, False
    xy, starts = _pair_sums(bxy, bstarts, rxy, rstarts, pairs)
    k = starts.shape[0] - 1
    bb = boxes(xy, starts)
    fr = frames(xy, starts)
    n_edges = xy.shape[0]
    dist = np.empty(n_edges)  # squared distances of the edges from the origin
    owner = np.empty(n_edges, np.int64)
    low = 0.0  # the lower bound
    deepest = -1  # the sum that gives it (the first tried on an edge)
    side = -1  # that sum's edge nearest the origin
    for p in range(k):
        s = starts[p]
        e = starts[p + 1]
        inner = np.inf
        nearest = -1
        for i in range(s, e):
            j = i + 1 if i + 1 < e else s
            owner[i] = p
            if fr[i, 3] == 0.0:
                dist[i] = np.inf
            else:
                if -fr[i, 2] < inner:  # the origin's distance inside edge i
                    inner = -fr[i, 2]
                    nearest = i
                dist[i] = origin_distance_sq_framed(xy[i, 0], xy[i, 1], xy[j, 0], xy[j, 1],
                                                    fr[i, 0], fr[i, 1], fr[i, 2])
        if inner < np.inf and inner > low:
            low = inner
            deepest = p
            side = nearest
    if best - low <= eps:
        return best, bdx, bdy, False
    # The foot of the origin on that edge is at the lower bound: when it escapes (no
    # other open sum covers it; half the benchmark's 12-gon pairs) it is the depth.
    if deepest >= 0:
        fx = low * fr[side, 1]
        fy = -low * fr[side, 0]
        if (not in_some_sum(fx, fy, starts, bb, fr, eps, deepest)
                and not penetrates(xa, sa, xb, sb, fx, fy, eps, moved, scratch)):
            return low, fx, fy, True
    near = np.flatnonzero(dist < best * best)  # (only these are visited: sorted alone)
    by_dist = near[np.argsort(dist[near])]
    # (the grid, if any, over the disk of the first escape)
    sums = (xy, starts, bb, fr)
    index = sum_index(sums, -bound, -bound, 2.0 * bound / GRID, eps, grid_from)
    lo1, hi1, lo0, hi0 = index[-4:]
    hint = deepest
    found = False
    for oi in range(by_dist.shape[0]):
        i = by_dist[oi]
        if dist[i] >= best * best:
            break
        p = owner[i]
        s = starts[p]
        e = starts[p + 1]
        j = i + 1 if i + 1 < e else s
        ax, ay = xy[i, 0], xy[i, 1]
        bx, by = xy[j, 0], xy[j, 1]
        # only the part of the edge inside the disk of the best escape can hold a nearer one
        tlo, thi = _in_disk(ax, ay, bx, by, best)
        if tlo >= thi:
            continue
        n1, n0, hint = clip_edge(sums, index, p, ax, ay, bx, by, tlo, thi, eps, hint)
        if n1 == 0 and n0 == 0:
            continue
        dx = bx - ax
        dy = by - ay
        # Uncovered parts: the outline of the union (n0) or parts covered only within
        # eps (n1: seams, exact fits, slides). Each is confirmed by the classifier at its
        # point nearest the origin, then at its ends and middle.
        for r in range(n0 + n1):
            lo = lo0[r] if r < n0 else lo1[r - n0]
            hi = hi0[r] if r < n0 else hi1[r - n0]
            px0 = ax + lo * dx
            py0 = ay + lo * dy
            px1 = ax + hi * dx
            py1 = ay + hi * dy
            fx, fy, fd = origin_foot(px0, py0, px1, py1)
            if fd >= best:
                continue
            for cx, cy in ((fx, fy), (px0, py0), (px1, py1),
                           (0.5 * (px0 + px1), 0.5 * (py0 + py1))):
                cd = np.hypot(cx, cy)
                if cd < best and not penetrates(xa, sa, xb, sb, cx, cy, eps, moved, scratch):
                    best = cd
                    bdx = cx
                    bdy = cy
                    found = True
                    break
    return best, bdx, bdy, found


#: Up to this many vertices in both bodies, :func:`first_escape` tries the normals of
#: every edge (O((m + n)^2)); above, only the box's axes.
_FEW_NORMALS = 64


@njit(cache=True, nogil=True, inline="always")
def _projection(x, nx, ny, ox, oy):
    """The range ``(min, max)`` of the points x projected onto (nx, ny) from (ox, oy)."""
    lo = np.inf
    hi = -np.inf
    for k in range(x.shape[0]):
        d = nx * (x[k, 0] - ox) + ny * (x[k, 1] - oy)
        lo = min(lo, d)
        hi = max(hi, d)
    return lo, hi


@njit(cache=True, nogil=True)
def _projected_escape(xa, xb, nx, ny, ox, oy):
    """The shorter of the two translations of A along ±(nx, ny) (a unit vector) after
    which the projections of A and B onto it no longer overlap: ``(length, dx, dy)``.
    The projections are taken from the point (ox, oy) near the bodies, so that the
    differences of nearby coordinates far from the origin lose no precision."""
    amin, amax = _projection(xa, nx, ny, ox, oy)
    bmin, bmax = _projection(xb, nx, ny, ox, oy)
    if bmax - amin <= amax - bmin:
        return bmax - amin, nx * (bmax - amin), ny * (bmax - amin)
    return amax - bmin, -nx * (amax - bmin), -ny * (amax - bmin)


@njit(cache=True, nogil=True)
def first_escape(xa, xb):
    """A short translation of A (vertices ``xa``) that ends its overlap with B
    (vertices ``xb``): ``(length, dx, dy)``, the shortest of :func:`box_escape` and, for
    bodies of at most :data:`_FEW_NORMALS` vertices in all, the translations along the
    normal of each edge (consecutive vertices) of either body that separate their
    projections on it (a separating axis: the shapes' projections touch at most).

    Exact for two convex bodies; for concave ones, an upper bound of the depth that
    limits which convex sums :func:`depth_from_pieces` builds (a median of 1.12 times
    the depth on the benchmark's 12-gons, against 1.5 for the box). The normals'
    escapes are touching up to the rounding of the projections: the caller confirms the
    one it returns.

    Examples
    --------
    >>> import numpy as np
    >>> diamond = np.array([[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0]])
    >>> sq = np.array([[0.3, 0.3], [0.5, 0.3], [0.5, 0.5], [0.3, 0.5]])
    >>> [round(float(v), 6) for v in first_escape(sq, diamond)]  # the box's: 0.7
    [0.282843, 0.2, 0.2]
    """
    best, bdx, bdy = box_escape(xa, xb)
    m = xa.shape[0]
    n = xb.shape[0]
    if m + n > _FEW_NORMALS:
        return best, bdx, bdy
    ox = xa[0, 0]
    oy = xa[0, 1]
    for i in range(m + n):
        y = xa if i < m else xb
        k = i if i < m else i - m
        j = k + 1 if k + 1 < y.shape[0] else 0
        ux = y[j, 0] - y[k, 0]
        uy = y[j, 1] - y[k, 1]
        ln = np.sqrt(ux * ux + uy * uy)
        if not ln > 0.0:
            continue
        t, dx, dy = _projected_escape(xa, xb, uy / ln, -ux / ln, ox, oy)
        if t < best:
            best = t
            bdx = dx
            bdy = dy
    return best, bdx, bdy


@njit(cache=True, nogil=True)
def contacts_near(xa, sa, xb, sb, bound, limit):
    """A lower bound, before any decomposition, of the vertices of the convex sums that
    :func:`depth_from_pieces` builds for the escape distance ``bound``, from the
    vertex–edge contacts that can hold without overlap within ``bound`` of the origin
    (translations of A); counted until it passes ``limit``.

    A contact of a strictly convex vertex v of one body with an edge e of the other
    whose direction lies within v's turning cone (reversed: from −u to −w, for v's edges
    u in and w out) is the segment ``v − e`` (``e − v`` for a vertex of A) of
    translations. It lies on an edge of the sum of the pieces that hold v and e (a
    piece's cone at v holds the body's), and comes within ``bound`` of the origin when v
    comes within ``bound`` of e: that sum's box meets the disk, and the sum is built. A
    sum edge holds one such segment with e strictly inside the cone, or up to four with
    e parallel to an edge at v (two parallel edges of the pieces, each with either end
    of the other), so the sums have at least (strict contacts) + (parallel ones) / 4
    edges, hence vertices.

    The edges of each body are listed in a grid of cells no narrower than ``bound`` / 2
    (:func:`polycontact._kernels.cells.segment_grid`) and, in each cell, sorted by
    direction: a vertex reads the cells within ``bound`` of it and, in each, the edges
    of its cone only. Costs O((m + n) log(m + n)) plus the contacts counted.

    Examples
    --------
    Two overlapping squares: their edges are parallel, a quarter each.

    >>> import numpy as np
    >>> sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    >>> st = np.array([0, 4])
    >>> float(contacts_near(sq, st, sq + 0.5, st, 0.6, 100.0))
    1.0
    """
    if not bound > 0.0:
        return 0.0  # (no disk: bodies that do not overlap have no depth)
    got = _contacts_of(xb, sb, xa, sa, bound, limit, 0.0)
    return _contacts_of(xa, sa, xb, sb, bound, limit, got)


@njit(cache=True, nogil=True)
def _contacts_of(xv, sv, xe, se, bound, limit, got):
    """:func:`contacts_near`'s count for the vertices of one body (``xv``, loops ``sv``)
    against the edges of the other (``xe``, ``se``), added to ``got``."""
    ne = xe.shape[0]
    if ne == 0 or xv.shape[0] == 0 or got > limit:
        return got
    # the edges (as the other body gives them) in a grid, each cell's sorted by direction
    seg = np.empty((ne, 4))
    ang = np.empty(ne)
    for k in range(se.shape[0] - 1):
        for i in range(se[k], se[k + 1]):
            j = i + 1 if i + 1 < se[k + 1] else se[k]
            seg[i, 0] = xe[i, 0]
            seg[i, 1] = xe[i, 1]
            seg[i, 2] = xe[j, 0]
            seg[i, 3] = xe[j, 1]
            ang[i] = np.arctan2(xe[j, 1] - xe[i, 1], xe[j, 0] - xe[i, 0])
    x0, y0, h, gx, gy, first, items = segment_grid(seg, xe, 0.0, 0.5 * bound)
    keys = np.empty(items.shape[0])
    for c in range(gx * gy):
        cell = items[first[c]:first[c + 1]]
        cell[:] = cell[np.argsort(ang[cell])]
        for u in range(first[c], first[c + 1]):
            keys[u] = ang[items[u]]
    seen = np.full(ne, -1, np.int64)
    b2 = bound * bound
    reach = int(np.ceil(bound / h))
    for k in range(sv.shape[0] - 1):
        for i in range(sv[k], sv[k + 1]):
            p = i - 1 if i > sv[k] else sv[k + 1] - 1
            q = i + 1 if i + 1 < sv[k + 1] else sv[k]
            px, py = xv[i, 0], xv[i, 1]
            ux, uy = px - xv[p, 0], py - xv[p, 1]
            wx, wy = xv[q, 0] - px, xv[q, 1] - py
            if not ux * wy - uy * wx > 0.0:
                continue  # reflex or straight: none counted
            lo = np.arctan2(-uy, -ux)  # the cone, from -u turning to -w
            hi = lo + np.arctan2(ux * wy - uy * wx, ux * wx + uy * wy)
            c0 = max(int(np.floor((px - x0) / h)) - reach, 0)
            c1 = min(int(np.floor((px - x0) / h)) + reach, gx - 1)
            r0 = max(int(np.floor((py - y0) / h)) - reach, 0)
            r1 = min(int(np.floor((py - y0) / h)) + reach, gy - 1)
            for c in range(c0, c1 + 1):
                for r in range(r0, r1 + 1):
                    f0 = first[c * gy + r]
                    f1 = first[c * gy + r + 1]
                    for turn in (0.0, 2.0 * np.pi):  # (a cone past pi wraps round)
                        u = f0 + np.searchsorted(keys[f0:f1], lo - turn)
                        while u < f1 and keys[u] <= hi - turn:
                            e = items[u]
                            u += 1
                            if seen[e] == i or closest_on_segment(
                                    px, py, seg[e, 0], seg[e, 1], seg[e, 2], seg[e, 3])[2] >= b2:
                                continue
                            seen[e] = i
                            got += _weight(seg[e, 2] - seg[e, 0], seg[e, 3] - seg[e, 1], ux,
                                           uy, wx, wy)
                            if got > limit:
                                return got
    return got


#: Edges whose directions make a sine below this count as parallel in
#: :func:`contacts_near` (a quarter each: rounding of their angles must not count a
#: parallel pair whole).
_PARALLEL_SINE = 1e-9


@njit(cache=True, nogil=True, inline="always")
def _weight(gx, gy, ux, uy, wx, wy):
    """A contact's share of a sum edge in :func:`contacts_near`: 1, or 1/4 for an edge
    (gx, gy) parallel to the vertex's edge in (u) or out (w)."""
    lg = np.hypot(gx, gy)
    if (abs(gx * uy - gy * ux) <= _PARALLEL_SINE * lg * np.hypot(ux, uy)
            or abs(gx * wy - gy * wx) <= _PARALLEL_SINE * lg * np.hypot(wx, wy)):
        return 0.25
    return 1.0


@njit(cache=True, nogil=True)
def box_escape(xa, xb):
    """The shortest of the four axis translations of A (vertices ``xa``) that take it
    out of the bounding box of B (vertices ``xb``): ``(length, dx, dy)``; the first of
    +x, −x, +y, −y on a tie."""
    ax0, ax1, ay0, ay1 = bbox(xa, xa.shape[0])
    bx0, bx1, by0, by1 = bbox(xb, xb.shape[0])
    bound = bx1 - ax0
    bdx = bound
    bdy = 0.0
    if ax1 - bx0 < bound:
        bound = ax1 - bx0
        bdx = -bound
    if by1 - ay0 < bound:
        bound = by1 - ay0
        bdx = 0.0
        bdy = bound
    if ay1 - by0 < bound:
        bound = ay1 - by0
        bdx = 0.0
        bdy = -bound
    return bound, bdx, bdy


# -- many pairs (classify_many's distances) ------------------------------------------------


@njit(cache=True, nogil=True)
def _samebody(x, ls, bs, f, p, q):
    """Whether bodies p and q of a packed batch are equal (loops, orientation, vertices)."""
    if f[p] != f[q] or bs[p + 1] - bs[p] != bs[q + 1] - bs[q]:
        return False
    p0 = ls[bs[p]]
    q0 = ls[bs[q]]
    for k in range(bs[p + 1] - bs[p]):
        if ls[bs[p] + k] - p0 != ls[bs[q] + k] - q0:
            return False
    for i in range(ls[bs[p + 1] - 1] - p0):
        if x[p0 + i, 0] != x[q0 + i, 0] or x[p0 + i, 1] != x[q0 + i, 1]:
            return False
    return True


@njit(cache=True, nogil=True, inline="always")
def _body_key(x, ls, bs, f, p):
    """A weighted sum of the coordinates of body p of a packed batch, with its loops'
    sizes and orientation: equal bodies have equal keys."""
    r0 = ls[bs[p]]
    h = f[p] + (ls[bs[p + 1] - 1] - r0) + 0.5 * (bs[p + 1] - bs[p])
    for i in range(ls[bs[p + 1] - 1] - r0):
        w = 1.0 + 0.6180339887498949 * i - np.floor(0.6180339887498949 * i)
        h += w * x[r0 + i, 0] + (w + 0.25) * x[r0 + i, 1]
    return h


@njit(cache=True, nogil=True)
def pair_keys(batch, pairs, eps):
    """A key of each pair ``pairs[k]`` of a packed batch ``(xa, lsa, bsa, fa, xb, lsb,
    bsb, fb)`` with tolerance ``eps[k]``: equal pairs (equal bodies A and B, equal
    tolerance) have equal keys. The work of a run of pairs, without the GIL (the caller
    splits the pairs over threads)."""
    xa, lsa, bsa, fa, xb, lsb, bsb, fb = batch
    n = pairs.shape[0]
    out = np.empty(n)
    for k in range(n):
        p = pairs[k]
        out[k] = _body_key(xa, lsa, bsa, fa, p) + 0.7548776662466927 * _body_key(
            xb, lsb, bsb, fb, p) + eps[k]
    return out


@njit(cache=True, nogil=True, inline="always")
def _key_slot(key, mask):
    """The first slot of ``key`` in a table of ``mask + 1`` slots: its bits mixed by the
    finalizer of MurmurHash3 (the constants as signed 64-bit integers), so that keys
    that differ in any bit spread over the table. Compiled, the products wrap in int64;
    in plain Python they do not, a different hash as good."""
    h = int(np.float64(key + 0.0).view(np.int64))  # (-0.0 as 0.0)
    h ^= h >> 33
    h *= -49064778989728563
    h ^= h >> 33
    h *= -4265267296055464877
    h ^= h >> 33
    return h & mask


@njit(cache=True, nogil=True)
def _grouped(batch, ids, eps, keys, both):
    """Groups of equal items ``ids[k]`` of a packed batch, found by their ``keys``
    (equal items have equal keys) and compared in full where keys are equal:
    ``(first, slot)``, ``first`` the positions k of the first item of each group in
    increasing order, ``slot[k]`` the position in ``first`` of item k's group. Items are
    bodies A (``both`` False) or pairs of bodies A and B with tolerances ``eps``.

    One pass in order over a hash table of the groups met so far (open addressing,
    linear probing, at most half full): each item is compared with the groups of its
    key only, so the pass takes O(n) expected, and an item joins the first group it
    equals (two groups are never equal)."""
    xa, lsa, bsa, fa, xb, lsb, bsb, fb = batch
    n = ids.shape[0]
    size = 16
    while size < 2 * n:
        size *= 2
    mask = size - 1
    table = np.full(size, -1, np.int64)  # the position of each group's first item
    slot = np.empty(n, np.int64)
    first = np.empty(n, np.int64)
    m = 0
    for k in range(n):
        h = _key_slot(keys[k], mask)
        while True:
            r = table[h]
            if r < 0:
                table[h] = k
                slot[k] = m
                first[m] = k
                m += 1
                break
            if keys[r] == keys[k] and _samebody(xa, lsa, bsa, fa, ids[r], ids[k]) and (
                    not both or (eps[r] == eps[k]
                                 and _samebody(xb, lsb, bsb, fb, ids[r], ids[k]))):
                slot[k] = slot[r]
                break
            h = (h + 1) & mask
    return first[:m].copy(), slot


@njit(cache=True, nogil=True)
def distinct_pairs(batch, pairs, eps, keys):
    """The distinct pairs among ``pairs`` of a packed batch (as :func:`pair_keys`, whose
    ``keys`` they are): ``(first, slot)``, ``first`` the positions k of the first pair
    of each group of equal pairs (equal bodies and tolerance), in increasing order, and
    ``slot[k]`` the position in ``first`` of pair k's group. O(n) expected for n pairs,
    plus a comparison of the bodies per pair whose key another pair shares."""
    return _grouped(batch, pairs, eps, keys, True)


@njit(cache=True, nogil=True)
def distinct_bodies(x, ls, bs, f, ids):
    """The distinct bodies among bodies ``ids`` of a packed batch: ``(first, slot)``,
    ``first`` the ids of the distinct ones (each at its first occurrence, in order) and
    ``slot[k]`` the position in ``first`` of the body equal to ``ids[k]``.

    Bodies are grouped by a weighted sum of their coordinates (equal bodies have equal
    sums), then compared in full within a group: O(n) expected for n bodies, plus the
    comparisons, one per body unless different bodies share a sum.
    """
    n = ids.shape[0]
    keys = np.empty(n)
    for k in range(n):
        keys[k] = _body_key(x, ls, bs, f, ids[k])
    first, slot = _grouped((x, ls, bs, f, x, ls, bs, f), ids, keys, keys, False)
    return ids[first], slot


@njit(cache=True, nogil=True)
def pieces_of_bodies(x, ls, bs, f, ids, negate, rel, ulps, max_ear):
    """Convex CCW pieces of bodies ``ids`` of a packed batch (oriented: interior on the
    left), by :func:`polycontact._kernels.decompose.ring_pieces`, negated (the pieces
    of −A) if ``negate``: ``(xy, starts, first, count, ok)``. Body k's pieces are
    ``starts[first[k]:first[k] + count[k] + 1]`` (rows of ``xy``); ``ok[k]`` is False
    for a body that ring_pieces does not decompose (holes, or a long concave ring):
    the caller decomposes those (its rows are reserved for none)."""
    n = ids.shape[0]
    row = np.zeros(n + 1, np.int64)
    first = np.zeros(n + 1, np.int64)
    for k in range(n):
        p = ids[k]
        v = ls[bs[p + 1] - 1] - ls[bs[p]]
        single = bs[p + 1] - bs[p] == 2
        # convex: the ring itself; else at most 3 (v - 2) vertices of merged triangles
        row[k + 1] = row[k] + (0 if not single else 3 * v if v <= max_ear else v)
        first[k + 1] = first[k] + (v + 1 if single else 0)
    xy = np.empty((row[n], 2))
    starts = np.empty(first[n], np.int64)
    count = np.zeros(n, np.int64)
    ok = np.zeros(n, np.bool_)
    for k in range(n):
        p = ids[k]
        if bs[p + 1] - bs[p] != 2:
            continue
        ring = x[ls[bs[p]] : ls[bs[p] + 1]]
        if f[p] < 0.0:
            ring = ring[::-1].copy()
        done, pxy, pst = ring_pieces(ring, rel, ulps, max_ear)
        if not done:
            continue
        ok[k] = True
        count[k] = pst.shape[0] - 1
        sign = -1.0 if negate else 1.0
        for i in range(pxy.shape[0]):
            xy[row[k] + i, 0] = sign * pxy[i, 0]
            xy[row[k] + i, 1] = sign * pxy[i, 1]
        for i in range(pst.shape[0]):
            starts[first[k] + i] = row[k] + pst[i]
    return xy, starts, first[:n].copy(), count, ok


@njit(cache=True, nogil=True)
def depths_of_pairs(batch, pairs, eps, slot_a, pieces_a, slot_b, pieces_b, max_vertices):
    """Penetration depths ``(P, 3)`` (depth, dx, dy; NaNs as in
    :func:`depth_from_pieces`) of the pairs ``pairs`` of two packed batches, ``batch`` =
    ``(xa, lsa, bsa, fa, xb, lsb, bsb, fb)`` (the form of
    :mod:`polycontact._kernels.relation_many`): pair k's A has the pieces
    of −A number ``slot_a[k]`` of ``pieces_a`` = ``(rxy, rst, rfirst, rcount)`` (see
    :func:`pieces_of_bodies`), its B those number ``slot_b[k]`` of ``pieces_b``;
    ``eps`` per pair."""
    xa, lsa, bsa, fa, xb, lsb, bsb, fb = batch
    rxy, rst, rfirst, rcount = pieces_a
    bxy, bst, bfirst, bcount = pieces_b
    n = pairs.shape[0]
    out = np.empty((n, 3))
    for k in range(n):
        p = pairs[k]
        ya, sa = body(xa, lsa, bsa, p)
        yb, sb = body(xb, lsb, bsb, p)
        ya = oriented(ya, sa, fa[p])
        yb = oriented(yb, sb, fb[p])
        ra = rfirst[slot_a[k]]
        rb = bfirst[slot_b[k]]
        out[k, 0], out[k, 1], out[k, 2] = depth_from_pieces(
            (ya, sa), (yb, sb), (bxy, bst[rb : rb + bcount[slot_b[k]] + 1]),
            (rxy, rst[ra : ra + rcount[slot_a[k]] + 1]), first_escape(ya, yb), eps[k],
            max_vertices)
    return out


@njit(cache=True, nogil=True)
def contact_depths(batch, pairs, eps):
    """Penetration depths ``(P, 3)`` of the pairs ``pairs`` of two packed batches
    (``batch``: as for :func:`depths_of_pairs`) by
    :func:`polycontact._kernels.convolution.contact_depth` from :func:`box_escape` (its
    segments are split lazily: a nearer start saves less than it costs); a
    row of NaNs where that kernel does not decide (the caller takes
    :func:`depths_of_pairs`); ``eps`` per pair."""
    xa, lsa, bsa, fa, xb, lsb, bsb, fb = batch
    n = pairs.shape[0]
    out = np.full((n, 3), np.nan)
    for k in range(n):
        p = pairs[k]
        if (lsa[bsa[p + 1] - 1] - lsa[bsa[p]] + lsb[bsb[p + 1] - 1] - lsb[bsb[p]]
                > FEW_VERTICES):
            continue
        ya, sa = body(xa, lsa, bsa, p)
        yb, sb = body(xb, lsb, bsb, p)
        ya = oriented(ya, sa, fa[p])
        yb = oriented(yb, sb, fb[p])
        bound, bdx, bdy = box_escape(ya, yb)
        got = contact_depth(ya, sa, yb, sb, bound, bdx, bdy, eps[k])
        if got[3]:
            out[k, 0], out[k, 1], out[k, 2] = got[0], got[1], got[2]
    return out
