"""Kernel: penetration depth of small bodies from their vertex-edge contact segments.

The translations ``d`` of A that make the interiors of A and B overlap form an open set
``O``; the penetration depth is the distance from the origin to its complement. A point
``x`` of the boundary of ``O`` puts A and B in contact without overlap: every contact is
a vertex of one body on the outline of the other (two edges that cross properly overlap
the interiors; two collinear edges that overlap end at such a vertex), and no contact
overlaps them locally. So ``x`` lies on a **contact segment** ``v − e`` (a vertex ``v``
of B, ``e`` an edge of A: A's points of ``e`` brought onto ``v``) or ``e − w`` (an edge
of B, a vertex ``w`` of A) whose vertex is convex and whose wedge lies on the outer side
of the edge: a contact of any other kind overlaps the interiors wherever it holds. At a
vertex-vertex contact that does not overlap, one of its four vertex-edge pairs has that
property (two wedges that do not overlap are separated by a line along an edge of one).

Along one such segment the verdict (overlap or not) can change only where another
contact starts or ends: where another kept segment meets it. Each segment nearer than a
known escape (``bound``) is split at every parameter where another one meets it, up to
the tolerance (the crossing of their lines, when within the tolerance of both segments;
for two nearly parallel ones that only end near each other, their ends projected), and
the verdict is constant on each open piece. A piece whose point nearest the origin
overlaps overlaps all along (the set of escapes is closed); the first piece point, in
increasing distance, that the state kernel calls contact or separate is the depth. The
segments' ends need no test of their own: where the escapes near a vertex-vertex
contact form a wedge, its sides run along kept segments from it, so the contact is the
nearest point of a piece that starts there; where it is a single escape (a triangle
held by three spikes, tip to tip) the overlapping directions are the union of one
convex cone per contact, bounded by kept segments, and these cones cover every
direction only if their sides do not all lie in one open half-plane, so one side leaves
the contact away from the origin and the contact is its piece's nearest point.

Where rounding could hide where two segments meet (two kept segments nearly parallel,
within the tolerance of each other along more than the tolerance: slides, exact fits),
or the bodies are too large for the O(m n) segments, the kernel says so and the caller
takes :func:`polycontact._kernels.depth.depth_from_pieces`.
"""

from __future__ import annotations

import numpy as np

from .jit import njit
from .packs import scratch_floats, state_scratch_views
from .primitives import (bbox, edge_rows, grow_rows, loop_prev, norm, origin_distance_sq,
                         origin_foot)
from .relation import NO_WITNESS, PENETRATING, moved_state, state_in, witness_holds


#: Up to this many vertices in both bodies the contact segments are tried (O(m n)
#: segments, O(K) tests to split each of the K near the origin); above it the caller's
#: search over convex sums.
FEW_VERTICES = 64

#: Two kept segments closer than the tolerance whose directions make a sine below this
#: are "nearly parallel": where they meet is then known only to the rounding / sine,
#: so when they run together (not only end together) the kernel gives up.
_SIN_PARALLEL = 1.0 / 64.0

#: Generous slack (a sine) in the kept-segment test: a near-tie is kept (a segment
#: kept in excess only costs time).
_SIN_SLACK = 1e-6

#: Relative room (of a segment's terms) for the rounding of its distance from the
#: origin when an edge's box says it lies beyond ``bound``: a segment kept in excess
#: only costs time.
_FAR_SLACK = 1e-12


@njit(cache=True, nogil=True, _nrt=False)
def _add_segments(v, o, sign, bound, slack, seg, n, near):
    """Append the kept segments of the vertices of one body against the edges of the
    other nearer than ``bound``: rows ``(x0, y0, x1, y1, squared distance, side, vertex,
    edge)`` of translations of A; ``v``, ``o`` the bodies as :func:`contact_depth_of`
    takes them; ``sign`` +1 when the vertices are B's (``v − e``, side 1), −1 when they
    are A's (``e − w``, side 0).

    Kept: a vertex that may touch the edge (the other body's interior on its left)
    without overlap: convex, and both of its edges on the outer (right) side of the
    edge, each up to :data:`_SIN_SLACK` and ``slack`` (an absolute allowance for the
    rounding of the coordinates) in the cross products. The segment of vertex p and
    edge e is nearer than ``bound`` only if p is, so only the vertices within ``bound``
    of the other body's box, and the edges within it of the vertices' box, are paired.
    ``near`` (one entry per vertex of both bodies) is scratch. (The lists are made
    without branches, a row written whether kept or not: the tests' outcomes follow no
    pattern a branch predictor could learn.)
    """
    xv, sv, ev, _, (vx0, vx1, vy0, vy1) = v
    xe, _, ee, ne, (ex0, ex1, ey0, ey1) = o
    b2 = bound * bound
    # only the edges whose boxes come within bound of V's box can hold one
    m = 0
    for j in range(xe.shape[0]):
        near[m] = j
        m += ((ee[j, 3] < vx1 + bound) & (ee[j, 4] > vx0 - bound) & (ee[j, 5] < vy1 + bound)
              & (ee[j, 6] > vy0 - bound))
    # the convex vertices within bound of the other body's box, after them
    c = m
    for k in range(sv.shape[0] - 1):
        for i in range(sv[k], sv[k + 1]):
            p = loop_prev(i, sv, k)
            gapx = max(0.0, xv[i, 0] - ex1, ex0 - xv[i, 0])
            gapy = max(0.0, xv[i, 1] - ey1, ey0 - xv[i, 1])
            ux, uy, lu = ev[p, 0], ev[p, 1], ev[p, 2]
            wx, wy, lw = ev[i, 0], ev[i, 1], ev[i, 2]
            near[c] = i
            near[c + 1] = p
            c += 2 * ((gapx * gapx + gapy * gapy < b2)
                      & ((ux * wy - uy * wx) >= -(_SIN_SLACK * lu * lw + slack * (lu + lw))))
    for r in range(m, c, 2):
        i = near[r]
        p = near[r + 1]
        px = xv[i, 0]
        py = xv[i, 1]
        ux, uy, lu = ev[p, 0], ev[p, 1], ev[p, 2]
        wx, wy, lw = ev[i, 0], ev[i, 1], ev[i, 2]
        for t in range(m):
            j = near[t]
            gx, gy, lg = ee[j, 0], ee[j, 1], ee[j, 2]
            # the segment is as far from the origin as p from the edge, so at least
            # as far as p from the edge's box (with room for the rounding of its
            # distance, a few units of its terms): the far ones are passed over
            gap = max(ee[j, 3] - px, px - ee[j, 4], ee[j, 5] - py, py - ee[j, 6])
            if gap > bound + _FAR_SLACK * (gap + lg):
                continue
            jj = ne[j]
            x0 = sign * (px - xe[j, 0])
            y0 = sign * (py - xe[j, 1])
            x1 = sign * (px - xe[jj, 0])
            y1 = sign * (py - xe[jj, 1])
            seg[n, 0] = x0
            seg[n, 1] = y0
            seg[n, 2] = x1
            seg[n, 3] = y1
            seg[n, 5] = 0.5 + 0.5 * sign
            seg[n, 6] = i
            seg[n, 7] = j
            if ((gx * wy - gy * wx) > _SIN_SLACK * lg * lw + slack * (lg + lw)
                    or (gx * uy - gy * ux) < -(_SIN_SLACK * lg * lu + slack * (lg + lu))):
                continue
            d = origin_distance_sq(x0, y0, x1, y1)
            seg[n, 4] = d
            n += d < b2
    return n


@njit(cache=True, nogil=True, inline="always")
def _project(px, py, ax, ay, dx, dy, ln2):
    """Parameter of p's projection on the line a + t d, and its distance from it."""
    t = ((px - ax) * dx + (py - ay) * dy) / ln2
    return t, abs((px - ax) * dy - (py - ay) * dx) / np.sqrt(ln2)


@njit(cache=True, nogil=True, _nrt=False)
def _splits(seg, n, s, tol, ts):
    """Parameters in (0, 1) where the other segments meet segment ``s`` or come within
    ``tol`` of it (unsorted, in ``ts``): their count, or -1 when two of them run together
    nearly parallel (where they part is then unknown)."""
    ax, ay, bx, by = seg[s, 0], seg[s, 1], seg[s, 2], seg[s, 3]
    dx = bx - ax
    dy = by - ay
    ln2 = dx * dx + dy * dy
    ln = np.sqrt(ln2)
    if not ln > 0.0:
        return -1
    x0 = min(ax, bx) - tol
    x1 = max(ax, bx) + tol
    y0 = min(ay, by) - tol
    y1 = max(ay, by) + tol
    c = 0
    for r in range(n):
        if r == s:
            continue
        cx, cy, ex, ey = seg[r, 0], seg[r, 1], seg[r, 2], seg[r, 3]
        if (max(cx, ex) < x0 or min(cx, ex) > x1 or max(cy, ey) < y0
                or min(cy, ey) > y1):
            continue
        fx = ex - cx
        fy = ey - cy
        lf = norm(fx, fy)
        if not lf > 0.0:
            return -1
        den = dx * fy - dy * fx
        if abs(den) >= _SIN_PARALLEL * ln * lf:
            # crossing of the lines, if near both segments
            t = ((cx - ax) * fy - (cy - ay) * fx) / den
            u = ((cx - ax) * dy - (cy - ay) * dx) / den
            mt = 2.0 * tol * lf / abs(den)  # tol / (sine x length of s)
            mu = 2.0 * tol * ln / abs(den)
            if -mu <= u <= 1.0 + mu and -mt <= t <= 1.0 + mt:  # (an end near s too)
                ts[c] = t
                c += 1
            continue
        # nearly parallel: they meet (within tol) only if an end of one is near the other
        t0, h0 = _project(cx, cy, ax, ay, dx, dy, ln2)
        t1, h1 = _project(ex, ey, ax, ay, dx, dy, ln2)
        near = h0 <= tol or h1 <= tol
        if not near:
            for px, py in ((ax, ay), (bx, by)):
                if _project(px, py, cx, cy, fx, fy, lf * lf)[1] <= tol:
                    tt = ((px - cx) * fx + (py - cy) * fy) / (lf * lf)
                    if -tol / lf <= tt <= 1.0 + tol / lf:
                        near = True
        if not near:
            continue
        lo = max(0.0, min(t0, t1))
        hi = min(1.0, max(t0, t1))
        if (hi - lo) * ln > tol:
            return -1
        ts[c] = t0
        ts[c + 1] = t1
        c += 2
    return c


@njit(cache=True, nogil=True)
def penetrates(xa, sa, xb, sb, dx, dy, eps, moved, scratch):
    """Whether A moved by (dx, dy) penetrates B (the state kernel's verdict); ``moved``
    (shaped like ``xa``) and ``scratch`` (``scratch_floats`` of both bodies' vertices)
    are written, so that the checks of one pair allocate nothing."""
    for i in range(xa.shape[0]):
        moved[i, 0] = xa[i, 0] + dx
        moved[i, 1] = xa[i, 1] + dy
    views = state_scratch_views(scratch, xa.shape[0] + xb.shape[0])
    return state_in(moved, sa, 1.0, xb, sb, 1.0, eps, views) == PENETRATING


@njit(cache=True, nogil=True, _nrt=False)
def _escapes(a, b, px, py, d, eps, moved, scratch, known):
    """Whether A moved by p = (px, py), a point at distance d of a contact segment, ends
    the overlap, up to the tolerance: first tried 2 ``eps`` further along p (the bodies
    apart there by about ``eps`` where p makes them touch: the state kernel's cheaper
    case, no touch to look into), then at p itself. Every translation nearer than p
    having been found to penetrate, either makes p the depth within 2 ``eps``. ``a``,
    ``b``: the bodies as :func:`contact_depth_of` takes them. Returns ``(escapes,
    known)``.

    A witness of a penetration (two edges crossing, a vertex inside;
    :func:`polycontact._kernels.relation.witness_holds`) that holds both 2 ``eps``
    further and at p makes p penetrate, as the state kernel would say at both: ``known``
    = ``(witness, i, j)``, one found at another translation (``NO_WITNESS``: none), is
    tried first, and the last one the state kernel gives is returned in its place. A
    penetration found 2 ``eps`` further whose witness holds at p too makes p penetrate:
    the state kernel is not asked again there."""
    touch = state_scratch_views(scratch, a[0].shape[0] + b[0].shape[0])[2]
    if d > 0.0:
        f = 1.0 + 2.0 * eps / d
        w, i, j = known
        if (w != NO_WITNESS
                and witness_holds(a, b, px * f, py * f, eps, w, i, j, moved, touch)
                and witness_holds(a, b, px, py, eps, w, i, j, moved, touch)):
            return False, known
        got, w, i, j = moved_state(a, b, px * f, py * f, eps, moved, scratch)
        if not got:
            return True, known
        if w != NO_WITNESS:
            known = (w, i, j)
            if witness_holds(a, b, px, py, eps, w, i, j, moved, touch):
                return False, known
    got, w, i, j = moved_state(a, b, px, py, eps, moved, scratch)
    if got and w != NO_WITNESS:
        known = (w, i, j)
    return not got, known


@njit(cache=True, nogil=True)
def contact_depth(xa, sa, xb, sb, bound, bdx, bdy, eps):
    """Penetration depth of A into B from the contact segments: ``(depth, dx, dy, ok)``.

    ``(xa, sa)``, ``(xb, sb)``: the packed bodies (interior on the left of every
    edge, at most :data:`FEW_VERTICES` vertices in all); ``(bdx, bdy)``: a translation
    of A, of length ``bound``, that ends the overlap
    (:func:`polycontact._kernels.depth.box_escape`). ``ok`` False (and NaNs) when
    this kernel cannot decide exactly (nearly parallel segments that run together, the
    first escape not confirmed, bodies too large): the caller takes the search over
    convex sums.

    Cost: O(m n) segments; with K of them nearer than ``bound``, O(K) to split each
    one nearer than the depth, and one state check, O((m + n) log(m + n)), per piece
    nearer than the depth.

    Examples
    --------
    A triangle in the corner of an L: the shortest escape puts one of its vertices on
    each arm's inner edge (two squares would be refused: their sides slide).

    >>> import numpy as np
    >>> ell = np.array([(0, 0), (4, 0), (4, 1), (1, 1), (1, 4), (0, 4)], float)
    >>> tri = np.array([(1.2, 0.5), (1.7, 1.5), (0.7, 1.0)])
    >>> got = contact_depth(tri, np.array([0, 3]), ell, np.array([0, 6]), 1.5, 0.0, -1.5,
    ...                     1e-12)
    >>> [round(float(v), 6) for v in got]
    [0.583095, 0.3, 0.5, 1.0]
    """
    m = xa.shape[0]
    nb = xb.shape[0]
    if m + nb > FEW_VERTICES:
        return np.nan, np.nan, np.nan, False
    got = contact_depth_into(xa, sa, xb, sb, bound, bdx, bdy, eps, 0.0, depth_buffers(m, nb))
    return got[0], got[1], got[2], got[3]


@njit(cache=True, nogil=True)
def depth_buffers(m, n):
    """Scratch of :func:`contact_depth_into` for bodies of up to ``m`` and ``n``
    vertices: ``(seg, pts, ts, moved, scratch, ea, nxa, eb, nxb, near)``."""
    k = 2 * m * n
    return (np.empty((k + 1, 8)), np.empty((8 * k + 8, 5)), np.empty(2 * k + 2),
            np.empty((m, 2)), np.empty(scratch_floats(m + n)), np.empty((m, 7)),
            np.empty(m, np.int64), np.empty((n, 7)), np.empty(n, np.int64),
            np.empty(3 * (m + n), np.int64))


#: What :func:`contact_depth_of` says of a depth: found, left undecided (the caller's
#: search over convex sums), or not found for want of rows in its buffer of pieces.
DEPTH_FOUND = 1
DEPTH_UNDECIDED = 0
DEPTH_MORE_ROWS = -1


@njit(cache=True, nogil=True)
def contact_depth_into(xa, sa, xb, sb, bound, bdx, bdy, eps, low, buffers):
    """:func:`contact_depth` with its scratch (:func:`depth_buffers`, for at least the
    bodies' vertex counts) passed in, so that a loop over pairs allocates nothing, and
    ``low``, a length below which every translation is known to leave the bodies
    penetrating (their points nearer are not tested; 0: none known). Returns
    ``(depth, dx, dy, ok, side, vertex, edge)``: with the depth, the contact segment it
    lies on, the vertex of one body brought onto the edge of the other (side 0: a vertex
    of A onto an edge of B; 1: a vertex of B onto an edge of A; packed rows of each
    body), or -1, -1, -1 when the escape is ``(bdx, bdy)`` itself."""
    ea, nxa, eb, nxb = buffers[5], buffers[6], buffers[7], buffers[8]
    m = xa.shape[0]
    nb = xb.shape[0]
    edge_rows(xa, sa, ea, nxa)
    edge_rows(xb, sb, eb, nxb)
    a = (xa, sa, ea[:m], nxa[:m], bbox(xa, m))
    b = (xb, sb, eb[:nb], nxb[:nb], bbox(xb, nb))
    while True:
        got = contact_depth_of(a, b, bound, bdx, bdy, eps, low, (NO_WITNESS, -1, -1),
                               buffers)
        if got[3] != DEPTH_MORE_ROWS:
            return got[0], got[1], got[2], got[3] == DEPTH_FOUND, got[4], got[5], got[6]
        buffers = (buffers[0], grow_rows(buffers[1])) + buffers[2:]


@njit(cache=True, nogil=True, _nrt=False)
def contact_depth_of(a, b, bound, bdx, bdy, eps, low, known, buffers):
    """:func:`contact_depth_into` of the bodies ``a`` = ``(xa, sa, ea, nxa, box)``
    (packed loops, :func:`polycontact._kernels.primitives.edge_rows` table and
    successors, bounding box ``(xmin, xmax, ymin, ymax)``) and ``b`` likewise, their
    tables already built: ``(depth, dx, dy, status, side, vertex, edge)``, ``status``
    :data:`DEPTH_FOUND`, :data:`DEPTH_UNDECIDED` or :data:`DEPTH_MORE_ROWS` (the buffer
    of pieces, ``buffers[1]``, too short: nothing found, to be called again with a
    longer one); ``known`` = ``(witness, i, j)``: a witness of a penetration the caller
    found (:func:`polycontact._kernels.relation.moved_state`), tried before the state
    kernel at each point (:func:`_escapes`), or ``(NO_WITNESS, -1, -1)``. Allocates
    nothing."""
    seg, pts, ts, moved, scratch, _, _, _, _, near = buffers
    xa = a[0]
    tol = 4.0 * eps
    n = _add_segments(b, a, 1.0, bound, eps, seg, 0, near)
    n = _add_segments(a, b, -1.0, bound, eps, seg, n, near)
    moved = moved[:xa.shape[0]]
    # Segments and pieces are taken in increasing distance (a linear scan each time:
    # a few of each): a segment is split when it is the nearest thing left, each piece
    # then waits for its turn, and the first piece point that escapes is the depth.
    for s in range(n):
        seg[s, 4] = np.sqrt(seg[s, 4])
    # (pieces' "tried" flags: column 3; the segment index: column 4; a segment is done
    # once its distance is set negative)
    c = 0
    # The nearest segment's foot first: the nearest point of all, so the depth if it
    # escapes (it then needs no split, which nearly parallel segments running together,
    # as a flat face pressed on another, would refuse). Else it is kept as tried.
    s = -1
    for q in range(n):
        if s < 0 or seg[q, 4] < seg[s, 4]:
            s = q
    if s >= 0 and low <= seg[s, 4] < bound:
        px, py, d = origin_foot(seg[s, 0], seg[s, 1], seg[s, 2], seg[s, 3])
        escaped, known = _escapes(a, b, px, py, d, eps, moved, scratch, known)
        if escaped:
            return d, px, py, DEPTH_FOUND, int(seg[s, 5]), int(seg[s, 6]), int(seg[s, 7])
        pts[0, 0] = d
        pts[0, 1] = px
        pts[0, 2] = py
        pts[0, 3] = 1.0
        pts[0, 4] = s
        c = 1
    while True:
        s = -1
        for q in range(n):
            if seg[q, 4] >= 0.0 and (s < 0 or seg[q, 4] < seg[s, 4]):
                s = q
        r = -1
        for q in range(c):
            if pts[q, 3] == 0.0 and (r < 0 or pts[q, 0] < pts[r, 0]):
                r = q
        if s >= 0 and (r < 0 or seg[s, 4] <= pts[r, 0]):
            k = _splits(seg, n, s, tol, ts)
            seg[s, 4] = -1.0 - seg[s, 4]
            if k < 0:
                return np.nan, np.nan, np.nan, DEPTH_UNDECIDED, -1, -1, -1
            c = _pieces(seg, s, ts, k, bound, pts, c)
            if c < 0:  # (more rows needed)
                return np.nan, np.nan, np.nan, DEPTH_MORE_ROWS, -1, -1, -1
            continue
        if r < 0 or not pts[r, 0] < bound:
            break
        d, px, py = pts[r, 0], pts[r, 1], pts[r, 2]
        pts[r, 3] = 1.0
        if d < low or _tried(pts, c, r):
            continue  # (known to penetrate; an end shared by several pieces is tried once)
        escaped, known = _escapes(a, b, px, py, d, eps, moved, scratch, known)
        if escaped:
            q = int(pts[r, 4])
            return d, px, py, DEPTH_FOUND, int(seg[q, 5]), int(seg[q, 6]), int(seg[q, 7])
    if moved_state(a, b, bdx, bdy, eps, moved, scratch)[0]:
        return np.nan, np.nan, np.nan, DEPTH_UNDECIDED, -1, -1, -1
    return bound, bdx, bdy, DEPTH_FOUND, -1, -1, -1


@njit(cache=True, nogil=True, _nrt=False)
def _tried(pts, c, r):
    """Whether another row of ``pts`` holds the point of row r and was tried."""
    for q in range(c):
        if q != r and pts[q, 3] != 0.0 and pts[q, 1] == pts[r, 1] and pts[q, 2] == pts[r, 2]:
            return True
    return False


@njit(cache=True, nogil=True, _nrt=False)
def _pieces(seg, s, ts, k, bound, pts, c):
    """Append to ``pts`` (from row c) the point nearest the origin of each piece of
    segment ``s`` between the ``k`` split parameters ``ts`` (and 0 and 1), when nearer
    than ``bound``, as rows ``(distance, x, y, 0.0, s)``: the new row count, or
    ``-c - 1`` when ``pts`` is too small (nothing written)."""
    ts[k] = 0.0
    ts[k + 1] = 1.0
    k += 2
    for q in range(k):  # clamp to [0, 1] and sort (a few values)
        v = min(1.0, max(0.0, ts[q]))
        r = q
        while r > 0 and ts[r - 1] > v:
            ts[r] = ts[r - 1]
            r -= 1
        ts[r] = v
    if c + k > pts.shape[0]:
        return -c - 1
    ax, ay = seg[s, 0], seg[s, 1]
    dx = seg[s, 2] - ax
    dy = seg[s, 3] - ay
    for q in range(k - 1):
        if ts[q + 1] <= ts[q]:
            continue
        got = origin_foot(ax + ts[q] * dx, ay + ts[q] * dy, ax + ts[q + 1] * dx,
                          ay + ts[q + 1] * dy)
        if got[2] < bound:
            pts[c, 0] = got[2]
            pts[c, 1] = got[0]
            pts[c, 2] = got[1]
            pts[c, 3] = 0.0
            pts[c, 4] = s
            c += 1
    return c
