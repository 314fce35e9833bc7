"""Kernels: the conservative-advancement step of the exact time-of-impact search.

A step from time t0 is a time h during which no vertex of either body comes within a
distance ``lam`` of an edge of the other. Boundaries that do not cross are as far
apart as their nearest vertex–edge pair, and they cannot begin to meet without some
vertex reaching an edge, so no contact (and no penetration) can begin inside the step.

Every bound here is of second order. If a function of time f has f(t0) = g > 0,
f'(t0) = r and |f''| <= K on the window, then f(t0 + τ) >= g + r τ − K τ²/2, which
stays positive until :func:`_root`. The first derivative is exact (the velocities at
t0), so a pair that is separating, or closing slowly, gets a long step; only the
change of the velocities is bounded. For a material point p(t) = c(t) + R(θ(t)) r,

    p̈ = a + (α J − ω² I) R r,   so   |p̈| <= |a| + (|α| + ω²) |r|

over a window where |ω| <= ω_max (ω is affine in t: the largest |ω| is at an end).
Differences of two bodies' points use the relative acceleration Δa.

Pairs are found through a tree of bounding circles over each body's edges
(:func:`edge_table`): a pair of nodes whose circles cannot come within ``lam`` of
each other before the current step is pruned with all the vertex–edge pairs under
it (the circles' centres are material points, held apart along their current
direction by the same second-order bound).
"""

from __future__ import annotations

import numpy as np

from .jit import njit
from .primitives import closest_on_segment, outward_normal


#: Entries of the traversal stack (see :func:`traversal_stack`).
STACK_SIZE = 160


@njit(cache=True, nogil=True)
def edge_table(r, starts):
    """The tables of one body for :func:`pair_step`, from its vertices ``r`` relative to
    its centroid (body frame, t = 0) and its loop ``starts``:
    ``(nxt, links, circles, r_len)``.

    ``nxt`` is the vertex after each vertex in its loop: edge e joins vertex e to
    ``nxt[e]``. ``links`` and ``circles`` describe a binary tree over the edges (each
    node's edges a run of consecutive indices, halved at each level), node 0 the root
    and children after their parent: ``links[k] = (left, right, edge)``, the children
    (−1 at a leaf) and the leaf's edge (−1 inside); ``circles[k] = (cx, cy, rho, rc)``,
    the smallest circle holding the node's edges (:func:`_smallest_circle`; centre
    (cx, cy) in the body frame, radius rho), and the centre's distance from the
    centroid. Leaf e also stands for vertex e, so each vertex is under exactly one leaf.
    ``r_len`` is each vertex's distance from the centroid.

    >>> import numpy as np
    >>> sq = np.array([[-1.0, -1], [1, -1], [1, 1], [-1, 1]])
    >>> nxt, links, circles, r_len = edge_table(sq, np.array([0, 4]))
    >>> nxt.tolist(), links.shape, round(float(circles[0, 2]) ** 2, 9)
    ([1, 2, 3, 0], (7, 3), 2.0)
    """
    n = r.shape[0]
    out = (np.empty(n, np.int64), np.empty((2 * n - 1, 3), np.int64),
           np.empty((2 * n - 1, 4)), np.empty(n))
    edge_table_into(r, starts, out, table_scratch(n))
    return out


@njit(cache=True, nogil=True)
def table_scratch(n):
    """Scratch of :func:`edge_table_into` for bodies of up to ``n`` vertices."""
    return np.empty((2 * n - 1, 2), np.int64), np.empty(2 * n), np.empty(2 * n)


@njit(cache=True, nogil=True, _nrt=False)
def edge_table_into(r, starts, out, scratch):
    """:func:`edge_table` of the body ``(r, starts)`` written into ``out`` = ``(nxt,
    links, circles, r_len)``, arrays of its shapes (n, (2n − 1, 3), (2n − 1, 4), n),
    with no allocation: views of a caller's buffers. ``scratch``: :func:`table_scratch`
    of at least n vertices."""
    nxt, links, circles, r_len = out
    span, px, py = scratch                   # span[k]: node k's edges span[k, 0]:span[k, 1]
    n = r.shape[0]
    for k in range(starts.shape[0] - 1):
        s = starts[k]
        e = starts[k + 1]
        for j in range(s, e):
            nxt[j] = j + 1 if j + 1 < e else s
            r_len[j] = np.sqrt(r[j, 0] * r[j, 0] + r[j, 1] * r[j, 1])
    size = 2 * n - 1
    for k in range(size):
        for c in range(3):
            links[k, c] = -1
    span[0, 0] = 0
    span[0, 1] = n
    count = 1
    for k in range(size):                    # parents before their children
        a = span[k, 0]
        b = span[k, 1]
        m = 0                                # the node's points: its edges' ends
        for e in range(a, b):
            px[m] = r[e, 0]
            py[m] = r[e, 1]
            m += 1
            if nxt[e] != e + 1 or e + 1 == b:
                px[m] = r[nxt[e], 0]
                py[m] = r[nxt[e], 1]
                m += 1
        cx, cy = _smallest_circle(px, py, m, k)
        far = 0.0
        for v in range(m):
            far = max(far, (px[v] - cx) ** 2 + (py[v] - cy) ** 2)
        circles[k, 0] = cx
        circles[k, 1] = cy
        # a hair wider than the farthest end: the square roots are rounded
        circles[k, 2] = np.sqrt(far) * (1.0 + 1e-12) + 1e-300
        circles[k, 3] = np.sqrt(cx * cx + cy * cy)
        if b - a == 1:
            links[k, 2] = a
        else:
            m = (a + b) // 2
            links[k, 0] = count
            links[k, 1] = count + 1
            span[count, 0] = a
            span[count, 1] = m
            span[count + 1, 0] = m
            span[count + 1, 1] = b
            count += 2


@njit(cache=True, nogil=True, _nrt=False)
def _smallest_circle(px, py, m, seed):
    """Centre of the smallest circle holding the points ``px[:m], py[:m]`` (Welzl's
    incremental algorithm, expected O(m) after a pseudo-random shuffle seeded by
    ``seed``; the points are reordered). Rounding can leave a point a hair outside:
    the caller takes the radius as the largest distance from this centre."""
    state = seed % 2147483648
    for i in range(m - 1, 0, -1):            # shuffle (a 31-bit linear congruence)
        state = (state * 1103515245 + 12345) % 2147483648
        j = state % (i + 1)
        px[i], px[j] = px[j], px[i]
        py[i], py[j] = py[j], py[i]
    cx = px[0]
    cy = py[0]
    r2 = 0.0
    for i in range(1, m):
        if (px[i] - cx) ** 2 + (py[i] - cy) ** 2 <= r2 * (1.0 + 1e-12):
            continue
        cx = px[i]
        cy = py[i]
        r2 = 0.0
        for j in range(i):
            if (px[j] - cx) ** 2 + (py[j] - cy) ** 2 <= r2 * (1.0 + 1e-12):
                continue
            cx = 0.5 * (px[i] + px[j])
            cy = 0.5 * (py[i] + py[j])
            r2 = (px[i] - cx) ** 2 + (py[i] - cy) ** 2
            for k in range(j):
                if (px[k] - cx) ** 2 + (py[k] - cy) ** 2 <= r2 * (1.0 + 1e-12):
                    continue
                # the circle through i, j and k
                ax = px[j] - px[i]
                ay = py[j] - py[i]
                bx = px[k] - px[i]
                by = py[k] - py[i]
                det = 2.0 * (ax * by - ay * bx)
                a2 = ax * ax + ay * ay
                b2 = bx * bx + by * by
                if abs(det) <= 1e-12 * (a2 + b2):
                    # (nearly) collinear: the circle on the farthest two
                    c2 = (px[j] - px[k]) ** 2 + (py[j] - py[k]) ** 2
                    if c2 >= a2 and c2 >= b2:
                        cx = 0.5 * (px[j] + px[k])
                        cy = 0.5 * (py[j] + py[k])
                    elif b2 >= a2:
                        cx = 0.5 * (px[i] + px[k])
                        cy = 0.5 * (py[i] + py[k])
                else:
                    cx = px[i] + (by * a2 - ay * b2) / det
                    cy = py[i] + (ax * b2 - bx * a2) / det
                r2 = max((px[i] - cx) ** 2 + (py[i] - cy) ** 2,
                         (px[j] - cx) ** 2 + (py[j] - cy) ** 2,
                         (px[k] - cx) ** 2 + (py[k] - cy) ** 2)
    return cx, cy


@njit(cache=True, nogil=True)
def traversal_stack():
    """Scratch of :func:`pair_step`: node pairs and their times. A tree over n edges is
    at most ceil(log2 n) + 1 deep and the traversal holds at most the two depths plus
    one entries, so :data:`STACK_SIZE` covers any body that fits in memory."""
    return np.empty((STACK_SIZE, 2), np.int64), np.empty(STACK_SIZE)


@njit(cache=True, nogil=True)
def _root(g, r, k, cap):
    """A time in [0, cap] before which f stays positive, for f(0) = g, f'(0) = r and
    |f''| <= k: the first zero of g + r τ − k τ²/2 (``cap`` if it stays positive to
    ``cap``, 0 if g <= 0). Computed without cancellation."""
    if g <= 0.0:
        return 0.0
    if g + (r - 0.5 * k * cap) * cap > 0.0:
        return cap                     # concave, positive at both ends: positive between
    if k > 0.0:
        q = np.sqrt(r * r + 2.0 * k * g)
        return 2.0 * g / (q - r) if r <= 0.0 else (r + q) / k
    return g / -r


@njit(cache=True, nogil=True)
def _root_or_linear(g, r, k, speed, cap):
    """:func:`_root`, or g / ``speed`` when that is later (|f'| <= speed: f >= g − speed τ),
    so that a pair never gets a shorter step than plain conservative advancement."""
    tau = _root(g, r, k, cap)
    if g > speed * tau:
        tau = cap if g >= speed * cap else g / speed
    return tau


@njit(cache=True, nogil=True)
def line_time(p, ax, ay, bx, by, e, kin, level, cap):
    """A time in [0, cap] during which vertex p stays more than ``level`` in front of the
    line of edge ab as the line turns with its body E (0 if it is not now; arguments as
    in :func:`_vertex_edge_time`).

    In E's frame p is at P = Rᵀ(p − c_E) and its signed distance to the line is
    s = n_E·(P − X); with w = p − c_E, P̈ = Rᵀ(ẅ − 2 ω_E J ẇ − ω_E² w − α_E J w), so
    |s''| <= |n·Δa| + K_v |r_p| + 2 W_e |ẇ| + K_e |w|, with |ẇ| <= V + W_v |r_p| and
    |w| growing by at most that speed times the step; s' now is (ṗ − u(p))·n_E. The
    relative acceleration Δa counts only across the line (n turns by at most W_e·cap,
    which adds |Δa| W_e cap), so a body sliding along a still edge while it speeds up or
    slows down keeps long steps.
    """
    px, py, vx, vy, rp = p
    cex, cey, uex, uey, we = e
    ln, lx, ly = outward_normal(ax, ay, bx, by)
    if ln == 0.0:
        return 0.0
    wx = px - cex
    wy = py - cey
    sp = kin[3] + kin[4] * rp
    far = np.sqrt(wx * wx + wy * wy) + cap * sp
    # the relative acceleration (dax, day) across the line, which turns by <= W_e·cap
    k = (abs(kin[6] * lx + kin[7] * ly) + kin[0] * kin[5] * cap + kin[1] * rp
         + 2.0 * kin[5] * sp + kin[2] * far)
    slope = (vx - uex + we * wy) * lx + (vy - uey - we * wx) * ly
    return _root((px - ax) * lx + (py - ay) * ly - level, slope, k, cap)


@njit(cache=True, nogil=True)
def _vertex_edge_time(p, ax, ay, bx, by, ra, rb, e, kin, lam, cap, touch):
    """``(d², τ)``: the squared distance from vertex p to edge ab of the other body E, and
    a time in [0, cap] during which p stays more than ``lam`` from the edge. A pair within
    ``lam`` now gets 0, or, when ``touch`` > 0, the time during which p stays no more
    than ``touch`` behind the edge's turning line (:func:`line_time`; see
    :func:`pair_step` for what that proves).

    ``p`` is ``(px, py, vx, vy, rp)``: the vertex, its velocity, and its distance from
    its body's centroid; ``ra``, ``rb`` those of the edge's ends from E's centroid;
    ``e`` is ``(cex, cey, uex, uey, we)``: E's centroid, velocity and angular velocity,
    so that its point x moves at u(x) = u_E + ω_E J (x − c_E). ``kin`` is
    ``(|Δa|, K_v, K_e, V, W_v, W_e, Δax, Δay)`` (:func:`window_kinematics`): the
    relative acceleration, |α| + ω_max² of p's body and of E, the largest |Δv| and |ω|
    of p's body and of E over the window, and Δa itself.

    The longest of three lower bounds of the same time:

    - fixed normal n = (p − q)/|p − q|, q the nearest point of the edge: every point of
      the (straight, rigid) edge is a convex combination of its ends, so
      dist(p, e) >= min over the ends x of n·(p − x), each a function with value and
      slope known now and |f''| <= |p̈ − ẍ| <= |Δa| + K_v |r_p| + K_e |r_x|;
    - the same with the plain speed bound |f'| <= V + W_v |r_p| + W_e |r_x|
      (:func:`_root_or_linear`);
    - when p is more than ``lam`` outside the edge's line, its signed distance to the
      line turning with E (:func:`line_time`), a lower bound of the distance to the
      edge. Its slope now is the velocity of p relative to E's point under it, so a
      vertex sliding along the line (or closing slowly towards it while the edge
      turns) keeps long steps.
    """
    px, py, vx, vy, rp = p
    cex, cey, uex, uey, we = e
    qx, qy, d2 = closest_on_segment(px, py, ax, ay, bx, by)
    if d2 <= lam * lam:
        if touch > 0.0:
            return d2, line_time(p, ax, ay, bx, by, e, kin, -touch, cap)
        return d2, 0.0
    sp = kin[3] + kin[4] * rp
    if d2 > (lam + cap * (sp + kin[5] * max(ra, rb))) ** 2:
        return d2, cap                  # out of reach at the plain speed bound
    d = np.sqrt(d2)
    nx = (px - qx) / d
    ny = (py - qy) / d
    kp = kin[0] + kin[1] * rp
    uax = uex - we * (ay - cey)
    uay = uey + we * (ax - cex)
    ubx = uex - we * (by - cey)
    uby = uey + we * (bx - cex)
    tau = min(_root_or_linear((px - ax) * nx + (py - ay) * ny - lam,
                              (vx - uax) * nx + (vy - uay) * ny, kp + kin[2] * ra,
                              sp + kin[5] * ra, cap),
              _root_or_linear((px - bx) * nx + (py - by) * ny - lam,
                              (vx - ubx) * nx + (vy - uby) * ny, kp + kin[2] * rb,
                              sp + kin[5] * rb, cap))
    if tau < cap:
        tau = max(tau, line_time(p, ax, ay, bx, by, e, kin, lam, cap))
    return d2, tau


@njit(cache=True, nogil=True)
def _node_time(qa, ka, fa, qb, kb, fb, kin, lam, cap):
    """A time in [0, cap] during which node ``ka`` of A's tree and node ``kb`` of B's
    (``qa``, ``qb``: the ``circles`` of :func:`edge_table`) stay more than ``lam`` apart
    (0 if their circles are that close now). ``fa``, ``fb``: each body's frame at t0,
    ``(c, cos, sin, vx, vy, ω)`` (its centroid, turn, velocity and angular velocity).

    The centres are material points at body-frame ``(cx, cy)``; with u = C_A − C_B and
    n = u/|u| now, |u(t)| >= n·u(t), whose slope now is n·(Ċ_A − Ċ_B) and whose second
    derivative is at most Δa + K_A |r_cA| + K_B |r_cB|; the circles are apart while
    |u| > rho_A + rho_B.
    """
    ca, csa, sna, vax, vay, wa = fa
    cb, csb, snb, vbx, vby, wb = fb
    rx = qa[ka, 0]
    ry = qa[ka, 1]
    xa = csa * rx - sna * ry
    ya = sna * rx + csa * ry
    rx = qb[kb, 0]
    ry = qb[kb, 1]
    xb = csb * rx - snb * ry
    yb = snb * rx + csb * ry
    ux = ca[0] + xa - cb[0] - xb
    uy = ca[1] + ya - cb[1] - yb
    dist = np.sqrt(ux * ux + uy * uy)
    g = dist - qa[ka, 2] - qb[kb, 2] - lam
    if g <= 0.0:
        return 0.0
    slope = ((vax - wa * ya - vbx + wb * yb) * ux + (vay + wa * xa - vby - wb * xb) * uy) / dist
    return _root(g, slope, kin[0] + kin[1] * qa[ka, 3] + kin[2] * qb[kb, 3], cap)


@njit(cache=True, nogil=True)
def _leaf_pair(way, i, j, v, e, kin, lam, step, dmin2, crit, touch):
    """Vertex i of one body (``v``) against edge j of the other (``e``): ``(dmin2,
    step)`` updated, and ``crit`` set to ``(way, i, j)`` when the pair shortens the
    step. Each body is ``(r, nxt, r_len, frame)``: its vertices in the body frame, the
    next vertex and the distance from the centroid of each (:func:`edge_table`), and its
    frame at t0 (see :func:`_node_time`); the three points are placed from the body
    frame, each body turned about its centroid."""
    rv, _, rv_len, (cv, csv, snv, vvx, vvy, wv) = v
    re, nxt_e, re_len, (ce, cse, sne, uex, uey, we) = e
    j1 = nxt_e[j]
    px = cv[0] + csv * rv[i, 0] - snv * rv[i, 1]
    py = cv[1] + snv * rv[i, 0] + csv * rv[i, 1]
    ax = ce[0] + cse * re[j, 0] - sne * re[j, 1]
    ay = ce[1] + sne * re[j, 0] + cse * re[j, 1]
    bx = ce[0] + cse * re[j1, 0] - sne * re[j1, 1]
    by = ce[1] + sne * re[j1, 0] + cse * re[j1, 1]
    d2, tau = _vertex_edge_time(
        (px, py, vvx - wv * (py - cv[1]), vvy + wv * (px - cv[0]), rv_len[i]), ax, ay, bx, by,
        re_len[j], re_len[j1], (ce[0], ce[1], uex, uey, we), kin, lam, step, touch)
    if tau < step:
        step = tau
        crit[0], crit[1], crit[2] = way, i, j
    return min(dmin2, d2), step


@njit(cache=True, nogil=True)
def window_kinematics(ma, mb, t0, t1):
    """``((vax, vay, ωa), (vbx, vby, ωb), kin_ab, kin_ba)``: each body's velocity and
    angular velocity at t0, and the window tuples of the bounds over [t0, t1] for
    vertices of A against edges of B and the other way round:
    ``(|Δa|, K_v, K_e, V, W_v, W_e, Δax, Δay)`` with K = |α| + ω_max², V the largest |Δv|
    and W the largest |ω| over the window (ω and Δv are affine in t: their largest norms
    are at the window's ends), Δa = a_A − a_B."""
    h = t1 - t0
    vax = ma[0] + ma[2] * t0
    vay = ma[1] + ma[3] * t0
    vbx = mb[0] + mb[2] * t0
    vby = mb[1] + mb[3] * t0
    wa = ma[4] + ma[5] * t0
    wb = mb[4] + mb[5] * t0
    wa_max = max(abs(wa), abs(ma[4] + ma[5] * t1))
    wb_max = max(abs(wb), abs(mb[4] + mb[5] * t1))
    dax = ma[2] - mb[2]
    day = ma[3] - mb[3]
    da = np.sqrt(dax * dax + day * day)
    ka = abs(ma[5]) + wa_max * wa_max
    kb = abs(mb[5]) + wb_max * wb_max
    dvx = vax - vbx
    dvy = vay - vby
    lin = np.sqrt(max(dvx * dvx + dvy * dvy, (dvx + dax * h) ** 2 + (dvy + day * h) ** 2))
    return ((vax, vay, wa), (vbx, vby, wb), (da, ka, kb, lin, wa_max, wb_max, dax, day),
            (da, kb, ka, lin, wb_max, wa_max, dax, day))


@njit(cache=True, nogil=True)
def pair_step(a, ca, ma, b, cb, mb, window, gaps, crit, traversal):
    """``(distance, step)``: the gap, and a time step in [0, t1 − t0] during which no
    vertex comes within ``lam_pair`` (<= ``lam``) of an edge of the other body.

    ``a`` is ``(r, table)``: A's vertices in its body frame (relative to its centroid at
    t = 0) and their :func:`edge_table`; ``ca`` its centroid at t0 (likewise B); ``ma``,
    ``mb`` the motion vectors ``[vx, vy, ax, ay, ω, α]``; ``window`` ``(t0, t1)``, over
    which the bounds hold; ``gaps`` ``(lam, lam_pair, touch)``. ``crit`` (int64, 3) names
    the pair that set the last step, ``(way, vertex, edge)`` (way 0: vertex of A; −1:
    none); it is charged first, so that the step is near its final value early and most
    node pairs are pruned, and it is updated. ``traversal``: :func:`traversal_stack`.

    Each vertex–edge pair is charged :func:`_vertex_edge_time`; pairs of tree nodes
    whose circles stay more than ``lam`` apart for the current step
    (:func:`_node_time`) are pruned with every pair under them. ``distance`` is exact
    when it is at most ``lam`` (a pair that close is never pruned while the step is
    positive, and a step of 0 comes from a pair within ``lam_pair``); otherwise it is at
    least the gap.

    With ``touch`` > 0 (bodies in contact), a pair already within ``lam_pair`` is charged
    instead the time during which its vertex stays no more than ``touch`` behind its
    edge's turning line. Then, if the bodies do not penetrate at t0, no penetration
    deeper than ``touch`` begins within the step: an overlap of the interiors begins
    where a vertex p of one body reaches an edge e of the other (edges cannot start to
    cross otherwise, and a vertex meeting a vertex is a vertex on the edges at it).
    Pairs farther than ``lam_pair`` do not meet within the step. A pair within it keeps
    p in front of e's line up to ``touch``; if p entered the other body near e, or near
    a corner of e (at a convex corner the body is behind both edges' lines there, at a
    reflex one behind one of them, and both edges' pairs are within ``lam_pair``), it
    would be behind that line. So a sliding contact — a translating body along a
    straight edge, under an overhang or not — is followed by steps as long as the
    nearest other pair allows.
    """
    t0, t1 = window
    lam, lam_pair, touch = gaps
    stack, stau = traversal
    ra, ea = a
    rb, eb = b
    h = t1 - t0
    tha = ma[4] * t0 + 0.5 * ma[5] * t0 * t0
    thb = mb[4] * t0 + 0.5 * mb[5] * t0 * t0
    (vax, vay, wa), (vbx, vby, wb), kin_ab, kin_ba = window_kinematics(ma, mb, t0, t1)
    fa = (ca, np.cos(tha), np.sin(tha), vax, vay, wa)
    fb = (cb, np.cos(thb), np.sin(thb), vbx, vby, wb)
    va = (ra, ea[0], ea[3], fa)
    vb = (rb, eb[0], eb[3], fb)
    la, qa = ea[1], ea[2]
    lb, qb = eb[1], eb[2]
    step = h
    dmin2 = np.inf
    if crit[0] == 0:
        dmin2, step = _leaf_pair(0, crit[1], crit[2], va, vb, kin_ab, lam_pair, step, dmin2,
                                 crit, touch)
    elif crit[0] == 1:
        dmin2, step = _leaf_pair(1, crit[1], crit[2], vb, va, kin_ba, lam_pair, step, dmin2,
                                 crit, touch)
    stack[0, 0] = 0
    stack[0, 1] = 0
    stau[0] = 0.0
    sp = 1
    while sp > 0:
        sp -= 1
        if stau[sp] >= step:
            continue
        na = stack[sp, 0]
        nb = stack[sp, 1]
        i = la[na, 2]
        j = lb[nb, 2]
        if i >= 0 and j >= 0:
            dmin2, step = _leaf_pair(0, i, j, va, vb, kin_ab, lam_pair, step, dmin2, crit,
                                     touch)
            dmin2, step = _leaf_pair(1, j, i, vb, va, kin_ba, lam_pair, step, dmin2, crit,
                                     touch)
            continue
        # open the wider node (a leaf is never opened)
        if j >= 0 or (i < 0 and qa[na, 2] >= qb[nb, 2]):
            a1, b1, a2, b2 = la[na, 0], nb, la[na, 1], nb
        else:
            a1, b1, a2, b2 = na, lb[nb, 0], na, lb[nb, 1]
        t_1 = _node_time(qa, a1, fa, qb, b1, fb, kin_ab, lam, step)
        t_2 = _node_time(qa, a2, fa, qb, b2, fb, kin_ab, lam, step)
        if t_1 < t_2:                   # the nearer pair is opened first
            a1, b1, t_1, a2, b2, t_2 = a2, b2, t_2, a1, b1, t_1
        if t_1 < step:
            stack[sp, 0] = a1
            stack[sp, 1] = b1
            stau[sp] = t_1
            sp += 1
        if t_2 < step:
            stack[sp, 0] = a2
            stack[sp, 1] = b2
            stau[sp] = t_2
            sp += 1
    return np.sqrt(dmin2), step
