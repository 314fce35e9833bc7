"""Kernels: time of impact of two rigidly moving polygonal bodies.

Each body is given by its vertices relative to its area centroid ``r`` (packed loops,
see :mod:`polycontact._kernels`), its centroid at t = 0 ``c0`` and its motion vector
``m = [vx, vy, ax, ay, ω, α]``; at time t its vertices are

    x_i(t) = c0 + v t + a t²/2 + R(ω t + α t²/2) r_i.

Both searches visit only the broad-phase intervals (rows of ``intervals``).

Status codes returned by the searches (see :class:`polycontact.ImpactStatus`):
0 no penetration in the window, 1 hit, 2 already penetrating at t = 0,
3 iteration budget exhausted (no verdict).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from .broad_phase import overlap_intervals
from .relation import _scratch, _state_in
from .validate import closest_on_segment

NO_HIT = 0
HIT = 1
INITIALLY_PENETRATING = 2
OUT_OF_ITERATIONS = 3

_PENETRATING = 2


@njit(cache=True, nogil=True)
def place(r, c0, m, t, out):
    """Write the vertices of the body at time t into ``out`` (same shape as ``r``);
    return the centroid ``(cx, cy)`` at t."""
    th = m[4] * t + 0.5 * m[5] * t * t
    cs = np.cos(th)
    sn = np.sin(th)
    cx = c0[0] + m[0] * t + 0.5 * m[2] * t * t
    cy = c0[1] + m[1] * t + 0.5 * m[3] * t * t
    for i in range(r.shape[0]):
        x = r[i, 0]
        y = r[i, 1]
        out[i, 0] = cx + cs * x - sn * y
        out[i, 1] = cy + sn * x + cs * y
    return cx, cy


@njit(cache=True, nogil=True)
def speed_bound(ma, la, mb, lb, t0, t1):
    """Upper bound of |ṗ − q̇| for every point p of A and q of B, t in [t0, t1].

    With p = c_A + R(θ_A) r_p and |r_p| <= la (likewise q):
    ṗ − q̇ = (v_A − v_B) + (a_A − a_B) t + θ̇_A J R r_p − θ̇_B J R r_q, so
    |ṗ − q̇| <= |Δv + Δa t| + |ω_A + α_A t| la + |ω_B + α_B t| lb. Each term is the
    norm of an affine function of t, hence convex, so its maximum over [t0, t1] is at
    an end.
    """
    lin, wa, wb = _window_rates(ma, mb, t0, t1)
    return lin + wa * la + wb * lb


#: When a body's vertices times the other body's edges are at most
#: :data:`PAIR_SCAN_MAX`, each vertex within reach of the other body's box meets every
#: edge; otherwise, when at most :data:`FEW_VERTICES` are within reach, they meet the
#: edges within reach of their common box, and else a sweep over the edges sorted by
#: smallest x finds each vertex's edges.
FEW_VERTICES = 32
PAIR_SCAN_MAX = 256

#: The pair steps of :func:`pair_step` stop this fraction of the contact resolution
#: short of contact: the probes that follow (each a classification) then cover a gap
#: of lam / 64 instead of lam.
PAIR_GAP = 1.0 / 64.0

#: After a step h shorter than its window, the next window is this many times h: the
#: directional bounds tighten as the window (the angle turned in it) shrinks.
WINDOW_GROWTH = 1.5


@njit(cache=True, nogil=True)
def _bilinear_max(w0, w1, f0, f1):
    """Largest w·f for w between w0 and w1 and f between f0 and f1 (at a corner)."""
    return max(max(w0 * f0, w0 * f1), max(w1 * f0, w1 * f1))


@njit(cache=True, nogil=True)
def _pair_rate(px, py, qx, qy, d, cvx, cvy, rv, ex0, ey0, ex1, ey1, cex, cey, re, mw):
    """Upper bound of the closing rate of vertex p and edge e along their fixed normal.

    n = (p − q)/d, q the point of e nearest p. The edge lies in the half-plane
    {x : (x − q)·n <= 0}, so sep(t) = p(t)·n − max over material points x of e of
    x(t)·n equals d now and never exceeds dist(p(t), e(t)): the pair cannot touch while
    sep > 0. A material point moves along n at v(t)·n + ω(t) f(t) with
    f = (J R(θ) r)·n, and the max of moving points grows no faster than the fastest of
    them, so −sep' <= −Δv(t)·n − ω_v(t) f_p(t) + max over x of ω_e(t) f_x(t), with
    Δv = v_v − v_e. Δv·n and ω are affine in t: their extremes over the window are at its
    ends. f is a sinusoid of amplitude |r| in θ, so while the body turns by at most Θ it
    stays within |r| Θ of its current value (and within ±|r|); along the edge the
    current value is affine in x and |r_x| convex, so the ends bound it. Each product
    ω f is then bounded at a corner of its box (:func:`_bilinear_max`). A negative
    result means the pair is separating throughout the window.

    ``mw`` is a tuple holding, for the vertex body v and the edge body e: Δv at the
    window ends (4), ω_v at the ends, ω_e at the ends, Θ_v, Θ_e, max |Δv|, the window
    length (a tuple, not an array: no reference counting per call).
    """
    inv = 1.0 / d
    nx = (px - qx) * inv
    ny = (py - qy) * inv
    lin = -min(mw[0] * nx + mw[1] * ny, mw[2] * nx + mw[3] * ny)
    fv = (px - cvx) * ny - (py - cvy) * nx
    sv = rv * mw[8]
    rot_v = _bilinear_max(mw[4], mw[5], -min(rv, fv + sv), -max(-rv, fv - sv))
    fa = (ex0 - cex) * ny - (ey0 - cey) * nx
    fb = (ex1 - cex) * ny - (ey1 - cey) * nx
    se = re * mw[9]
    rot_e = _bilinear_max(mw[6], mw[7], max(-re, min(fa, fb) - se), min(re, max(fa, fb) + se))
    return lin + rot_v + rot_e


@njit(cache=True, nogil=True)
def _line_rate(px, py, nx, ny, cvx, cvy, rv, cex, cey, mw):
    """Upper bound of the closing rate of vertex p towards the line of an edge of the
    other body, the line turning with that body (``n``: the edge's outward normal now).

    The signed distance s = (p − x)·n(t), x a point of the line, changes at
    (ṗ − ẋ_p)·n(t) with ẋ_p = v_e + ω_e J (p − c_e), the velocity of the other body's
    point under p. So −s' = −Δv·n(t) − ω_v (J (p − c_v))·n(t) + ω_e (J (p − c_e))·n(t).
    While n turns by at most Θ_e: Δv·n(t) is within |Δv| Θ_e of Δv·n(now) (affine in
    t: extremes at the window ends); (J R_v r_p)·n is within |r_p| (Θ_v + Θ_e) of its
    current value; p − c_e moves by at most δ = h (|Δv| + |ω_v| |r_p|), so
    (J (p − c_e))·n is within δ + (|p − c_e| + δ) Θ_e of its current value. The
    products with ω are bounded at a corner (:func:`_bilinear_max`). The distance from
    p to the edge is at least s, so the pair stays apart while s > 0.
    """
    lin = mw[10]
    t1 = -min(mw[0] * nx + mw[1] * ny, mw[2] * nx + mw[3] * ny) + lin * mw[9]
    gv = (px - cvx) * ny - (py - cvy) * nx
    sv = rv * (mw[8] + mw[9])
    t2 = _bilinear_max(mw[4], mw[5], -min(rv, gv + sv), -max(-rv, gv - sv))
    ux = px - cex
    uy = py - cey
    delta = lin * mw[11] + rv * mw[8]
    ru = np.sqrt(ux * ux + uy * uy) + delta
    ge = ux * ny - uy * nx
    se = delta + ru * mw[9]
    t3 = _bilinear_max(mw[6], mw[7], max(-ru, ge - se), min(ru, ge + se))
    return t1 + t2 + t3


@njit(cache=True, nogil=True)
def _pair_time(px, py, cvx, cvy, rv, ax, ay, bx, by, cex, cey, re, mw, speed, lam, step):
    """The step after pair (p, edge ab) is charged, for a pair nearer than ``lam`` plus
    ``step`` times its plain speed bound ``speed``: the longer of the times it needs to
    come within ``lam`` at its fixed-normal rate (:func:`_pair_rate`, never above
    ``speed``) and, when p is outside the edge's line by more than ``lam``, at its rate
    towards the turning line (:func:`_line_rate`); both are lower bounds of the same
    time. 0 when it is already within ``lam`` (no reliable normal)."""
    qx, qy, d2 = closest_on_segment(px, py, ax, ay, bx, by)
    d = np.sqrt(d2)
    if d <= lam:
        return 0.0
    rate = min(speed, _pair_rate(px, py, qx, qy, d, cvx, cvy, rv, ax, ay, bx, by, cex, cey,
                                 re, mw))
    # (no division when the time is beyond the step: a tiny rate would overflow)
    best = (d - lam) / rate if d - lam < rate * step else step
    ex = bx - ax
    ey = by - ay
    ln = np.sqrt(ex * ex + ey * ey)
    if ln > 0.0 and best < step:
        nx = ey / ln                    # interior on the left: outward on the right
        ny = -ex / ln
        s0 = (px - ax) * nx + (py - ay) * ny
        if s0 > lam:
            rl = _line_rate(px, py, nx, ny, cvx, cvy, rv, cex, cey, mw)
            best = max(best, (s0 - lam) / rl if s0 - lam < rl * step else step)
    return min(step, best)


@njit(cache=True, nogil=True)
def _one_way_step(xv, cv, rv_len, xe, ce, nxt, re_max, order, mw, lin, wv, we, lam, lam_pair,
                  dmin2, step, crit, way, cand, xmin, sorted_x):
    """Vertices of one body against the edges of the other (``wv``, ``we``: the bounds
    of |ω| over the window; ``nxt``, ``re_max``, ``order`` from :func:`edge_table`;
    ``order`` is kept sorted by the edges' smallest x from step to step). The pair that
    sets the step is written to ``crit`` as ``(way, vertex, edge)``. ``cand`` (one
    entry per vertex), ``xmin`` and ``sorted_x`` (one per edge) are scratch.

    Only vertices within reach of the edge body's box are visited; when they are few,
    each meets the edges within reach of their common box, else a sweep over the edges
    sorted by smallest x (``et[2]``, kept nearly sorted from step to step) finds them.
    """
    ne = xe.shape[0]
    x0 = np.inf
    x1 = -np.inf
    y0 = np.inf
    y1 = -np.inf
    lmax = 0.0
    for j in range(ne):
        x0 = min(x0, xe[j, 0])
        x1 = max(x1, xe[j, 0])
        y0 = min(y0, xe[j, 1])
        y1 = max(y1, xe[j, 1])
        lmax = max(lmax, re_max[j])
    if xv.shape[0] * ne <= PAIR_SCAN_MAX:
        for i in range(xv.shape[0]):
            base = lin + wv * rv_len[i]
            px = xv[i, 0]
            py = xv[i, 1]
            # no pair farther than this can shorten the step: skip a vertex that far
            # from the other body's box
            reach = step * (base + we * lmax) + lam
            if px < x0 - reach or px > x1 + reach or py < y0 - reach or py > y1 + reach:
                continue
            for j in range(ne):
                j1 = nxt[j]
                speed = base + we * re_max[j]
                reach = step * speed + lam
                if (min(xe[j, 0], xe[j1, 0]) > px + reach or max(xe[j, 0], xe[j1, 0]) < px - reach
                        or min(xe[j, 1], xe[j1, 1]) > py + reach
                        or max(xe[j, 1], xe[j1, 1]) < py - reach):
                    continue
                d2 = closest_on_segment(px, py, xe[j, 0], xe[j, 1], xe[j1, 0], xe[j1, 1])[2]
                dmin2 = min(dmin2, d2)
                if d2 < reach * reach:     # else it cannot shorten the step
                    new = _pair_time(px, py, cv[0], cv[1], rv_len[i], xe[j, 0], xe[j, 1],
                                     xe[j1, 0], xe[j1, 1], ce[0], ce[1], re_max[j], mw, speed,
                                     lam_pair, step)
                    if new < step:
                        step = new
                        crit[0], crit[1], crit[2] = way, i, j
        return dmin2, step
    # no pair farther than `reach` can shorten the step: skip a vertex that far from
    # the other body's box
    nc = 0
    bx0 = np.inf
    bx1 = -np.inf
    by0 = np.inf
    by1 = -np.inf
    for i in range(xv.shape[0]):
        px = xv[i, 0]
        py = xv[i, 1]
        reach = step * (lin + wv * rv_len[i] + we * lmax) + lam
        if px < x0 - reach or px > x1 + reach or py < y0 - reach or py > y1 + reach:
            continue
        cand[nc] = i
        nc += 1
        bx0 = min(bx0, px - reach)
        bx1 = max(bx1, px + reach)
        by0 = min(by0, py - reach)
        by1 = max(by1, py + reach)
    if nc == 0:
        return dmin2, step
    if nc <= FEW_VERTICES:
        for j in range(ne):
            j1 = nxt[j]
            ax = xe[j, 0]
            ay = xe[j, 1]
            bx = xe[j1, 0]
            by = xe[j1, 1]
            ex0 = min(ax, bx)
            ex1 = max(ax, bx)
            ey0 = min(ay, by)
            ey1 = max(ay, by)
            if ex0 > bx1 or ex1 < bx0 or ey0 > by1 or ey1 < by0:
                continue
            for k in range(nc):
                i = cand[k]
                px = xv[i, 0]
                py = xv[i, 1]
                speed = lin + wv * rv_len[i] + we * re_max[j]
                reach = step * speed + lam
                if ex0 > px + reach or ex1 < px - reach or ey0 > py + reach or ey1 < py - reach:
                    continue
                d2 = closest_on_segment(px, py, ax, ay, bx, by)[2]
                dmin2 = min(dmin2, d2)
                if d2 < reach * reach:     # else it cannot shorten the step
                    new = _pair_time(px, py, cv[0], cv[1], rv_len[i], ax, ay, bx, by, ce[0],
                                     ce[1], re_max[j], mw, speed, lam_pair, step)
                    if new < step:
                        step = new
                        crit[0], crit[1], crit[2] = way, i, j
        return dmin2, step
    maxw = 0.0
    for j in range(ne):
        xmin[j] = min(xe[j, 0], xe[nxt[j], 0])
        maxw = max(maxw, abs(xe[j, 0] - xe[nxt[j], 0]))
    # the previous step's order is nearly right: insertion sort finishes it in ~O(n)
    for k in range(1, ne):
        cur = order[k]
        key = xmin[cur]
        m = k
        while m > 0 and xmin[order[m - 1]] > key:
            order[m] = order[m - 1]
            m -= 1
        order[m] = cur
    for k in range(ne):
        sorted_x[k] = xmin[order[k]]
    for k in range(nc):
        i = cand[k]
        px = xv[i, 0]
        py = xv[i, 1]
        reach = step * (lin + wv * rv_len[i] + we * lmax) + lam
        o = np.searchsorted(sorted_x[:ne], px - reach - maxw)
        while o < ne and sorted_x[o] <= px + reach:
            j = order[o]
            o += 1
            j1 = nxt[j]
            if max(xe[j, 0], xe[j1, 0]) < px - reach:
                continue
            if min(xe[j, 1], xe[j1, 1]) > py + reach or max(xe[j, 1], xe[j1, 1]) < py - reach:
                continue
            d2 = closest_on_segment(px, py, xe[j, 0], xe[j, 1], xe[j1, 0], xe[j1, 1])[2]
            dmin2 = min(dmin2, d2)
            speed = lin + wv * rv_len[i] + we * re_max[j]
            if d2 < (step * speed + lam) ** 2:
                new = _pair_time(px, py, cv[0], cv[1], rv_len[i], xe[j, 0], xe[j, 1],
                                 xe[j1, 0], xe[j1, 1], ce[0], ce[1], re_max[j], mw, speed,
                                 lam_pair, step)
                if new < step:
                    step = new
                    crit[0], crit[1], crit[2] = way, i, j
    return dmin2, step


@njit(cache=True, nogil=True)
def edge_table(starts, r_len):
    """``(nxt, r_max, order, cand, xmin, sorted_x)``: the vertex after each vertex in
    its loop, the largest centroid distance of each edge's two ends, an edge order that
    the sweep keeps sorted by smallest x (starts as 0, 1, ...), and the scratch arrays of
    :func:`_one_way_step` sized for this body (its vertices as candidates, its edges
    swept), so that a search allocates nothing per step."""
    n = r_len.shape[0]
    nxt = np.empty(n, np.int64)
    r_max = np.empty(n)
    for k in range(starts.shape[0] - 1):
        s = starts[k]
        e = starts[k + 1]
        for j in range(s, e):
            j1 = j + 1 if j + 1 < e else s
            nxt[j] = j1
            r_max[j] = max(r_len[j], r_len[j1])
    return nxt, r_max, np.arange(n), np.empty(n, np.int64), np.empty(n), np.empty(n)


@njit(cache=True, nogil=True)
def motion_window(ma, mb, t0, t1):
    """``(mwa, mwb)``: the window tuples of :func:`_pair_rate` and :func:`_line_rate`
    over [t0, t1], for vertices of A against edges of B and the other way round."""
    h = t1 - t0
    dv0x = ma[0] - mb[0] + (ma[2] - mb[2]) * t0
    dv0y = ma[1] - mb[1] + (ma[3] - mb[3]) * t0
    dv1x = ma[0] - mb[0] + (ma[2] - mb[2]) * t1
    dv1y = ma[1] - mb[1] + (ma[3] - mb[3]) * t1
    lin = max(np.hypot(dv0x, dv0y), np.hypot(dv1x, dv1y))
    wa0 = ma[4] + ma[5] * t0
    wa1 = ma[4] + ma[5] * t1
    wb0 = mb[4] + mb[5] * t0
    wb1 = mb[4] + mb[5] * t1
    wa = max(abs(wa0), abs(wa1))
    wb = max(abs(wb0), abs(wb1))
    return ((dv0x, dv0y, dv1x, dv1y, wa0, wa1, wb0, wb1, wa * h, wb * h, lin, h),
            (-dv0x, -dv0y, -dv1x, -dv1y, wb0, wb1, wa0, wa1, wb * h, wa * h, lin, h))


@njit(cache=True, nogil=True)
def slide_time(xv, cv, rv_len, nxt_v, xe, ce, nxt_e, le, j, mw, eps, h, need, first):
    """A time in [0, h] (0 as soon as it is known to be below ``need``; V's vertex
    ``first``, the touching one, is looked at before the rest) during which the interiors of V (vertices ``xv``, centroid
    ``cv``) and E (``xe``, ``ce``, bounding radius ``le``) cannot come to overlap by
    more than 2 ``eps``, certified by the line of E's edge j turning with E; 0 when the
    line does not separate them. ``mw`` is the window tuple (:func:`motion_window`) of
    V's vertices against E's edges over [t, t + h].

    This is what lets a sliding contact (paper Fig. 16) be followed by long steps:
    with n the outward normal of edge j and σ(x) = (x − x_j)·n, E lies in
    {σ <= eps} at all times if all its vertices do now (the line turns with E). Each
    edge of V is charged the time during which either both its ends keep
    σ >= −eps — each end at its rate towards the turning line (:func:`_line_rate`),
    and a segment lies on the side of its ends — or it stays outside E's bounding
    circle (its distance from E's centroid shrinks no faster than |Δv| + |ω_V| max |r|,
    as in the pair bounds). Until the shortest of these times no edge of V meets
    W = {σ < −eps} ∩ (open circle), a convex set that moves with E and holds the
    points of E's interior deeper than eps behind the line. Such a point is outside V
    now (the bodies do not penetrate) and never crosses V's boundary, so it stays
    outside V; hence W ∩ V stays empty (W is connected) and any overlap of the
    interiors lies in the band |σ| <= eps.
    """
    j1 = nxt_e[j]
    ax = xe[j, 0]
    ay = xe[j, 1]
    ex = xe[j1, 0] - ax
    ey = xe[j1, 1] - ay
    ln = np.sqrt(ex * ex + ey * ey)
    if ln == 0.0:
        return 0.0
    nx = ey / ln                        # interior on the left: outward on the right
    ny = -ex / ln
    for k in range(xe.shape[0]):
        if (xe[k, 0] - ax) * nx + (xe[k, 1] - ay) * ny > eps:
            return 0.0
    lin = mw[10]
    wv = max(abs(mw[4]), abs(mw[5]))
    # inside E's circle the touching vertex's edges can only be charged by their ends
    px = xv[first, 0]
    py = xv[first, 1]
    sig = (px - ax) * nx + (py - ay) * ny + eps
    if (px - ce[0]) ** 2 + (py - ce[1]) ** 2 <= le * le and (
            sig < 0.0 or sig < need * _line_rate(px, py, nx, ny, cv[0], cv[1], rv_len[first],
                                                 ce[0], ce[1], mw)):
        return 0.0
    best = h
    for k in range(xv.shape[0]):
        k1 = nxt_v[k]
        t_edge = np.inf
        for m in (k, k1):
            sig = (xv[m, 0] - ax) * nx + (xv[m, 1] - ay) * ny + eps
            if sig < 0.0:
                t_edge = 0.0
                break
            rate = _line_rate(xv[m, 0], xv[m, 1], nx, ny, cv[0], cv[1], rv_len[m], ce[0], ce[1],
                              mw)
            if sig < rate * best:           # else this end holds beyond the best
                t_edge = min(t_edge, sig / rate)
        if t_edge < best:
            gap = np.sqrt(closest_on_segment(ce[0], ce[1], xv[k, 0], xv[k, 1], xv[k1, 0],
                                              xv[k1, 1])[2]) - le
            if gap > 0.0:
                rate = lin + wv * max(rv_len[k], rv_len[k1])
                t_edge = max(t_edge, gap / rate if gap < rate * best else best)
            best = min(best, t_edge)
            if best < need:
                return 0.0
    return best


@njit(cache=True, nogil=True)
def _slide_step(xa, ca, ra_len, nxa, la, xb, cb, rb_len, nxb, lb, ma, mb, t0, t1, crit, eps,
                need):
    """The longest :func:`slide_time` over [t0, t1] by the lines through the pair
    ``crit`` (vertex i of one body, edge j of the other): edge j, or either edge of the
    vertex body at i (with the bodies' roles swapped); 0 if none reaches ``need``."""
    mwa, mwb = motion_window(ma, mb, t0, t1)
    h = t1 - t0
    i = crit[1]
    j = crit[2]
    if crit[0] == 0:
        best = slide_time(xa, ca, ra_len, nxa, xb, cb, nxb, lb, j, mwa, eps, h, need, i)
        for e in range(nxa.shape[0]):
            if best == 0.0 and (e == i or nxa[e] == i):
                best = slide_time(xb, cb, rb_len, nxb, xa, ca, nxa, la, e, mwb, eps, h, need, j)
        return best
    best = slide_time(xb, cb, rb_len, nxb, xa, ca, nxa, la, j, mwb, eps, h, need, i)
    for e in range(nxb.shape[0]):
        if best == 0.0 and (e == i or nxb[e] == i):
            best = slide_time(xa, ca, ra_len, nxa, xb, cb, nxb, lb, e, mwa, eps, h, need, j)
    return best


@njit(cache=True, nogil=True)
def _crit_time(xv, cv, rv, xe, ce, nxt, re_max, i, j, mw, speed, lam, step):
    """:func:`_pair_time` of vertex i against edge j of the other body."""
    j1 = nxt[j]
    return _pair_time(xv[i, 0], xv[i, 1], cv[0], cv[1], rv, xe[j, 0], xe[j, 1], xe[j1, 0],
                      xe[j1, 1], ce[0], ce[1], re_max[j], mw, speed, lam, step)


@njit(cache=True, nogil=True)
def pair_step(xa, ca, ra_len, ea, xb, cb, rb_len, eb, ma, mb, t0, t1, lam, lam_pair, crit):
    """``(distance, step)``: the gap, and a time step in [0, t1 − t0] during which no
    vertex comes within ``lam_pair`` (<= ``lam``) of an edge of the other body.

    ``xa`` are A's vertices placed at t0, ``ca`` its centroid there, ``ra_len[i]`` the
    distance of vertex i from it, ``ea`` its :func:`edge_table` (likewise B); ``ma``,
    ``mb`` the motion vectors. ``crit`` (int64, 3) names the pair that set the last
    step, ``(way, vertex, edge)`` (way 0: vertex of A; −1: none); it is charged first,
    so that the step is near its final value early and the rest of the pairs are
    mostly skipped, and it is updated.

    Each pair p (vertex of one body), e (edge of the other) gets the time of
    :func:`_pair_time`: the longer of two safe bounds, along the pair's fixed normal
    (:func:`_pair_rate`, never above the plain speed bound
    ``|Δv| + |ω_v| |r_p| + |ω_e| max |r_e|``; |r| is convex along the edge) and towards
    the edge's turning line (:func:`_line_rate`); 0 within ``lam_pair``. Boundaries that
    do not cross are at the distance of their nearest vertex–edge pair, and they cannot
    begin to meet without some vertex reaching an edge, so the smallest pair time (both
    ways) is a step without contact. A pair farther than ``lam`` plus the current step
    times its plain speed bound cannot shorten the step and is skipped (whole vertices
    by the other body's box; for large bodies, edges by the box of the few vertices
    left or by a sweep over x).

    ``distance`` is exact when it is at most ``lam``; otherwise it is at least the gap.
    """
    h = t1 - t0
    mwa, mwb = motion_window(ma, mb, t0, t1)
    lin, wa, wb = mwa[10], max(abs(mwa[4]), abs(mwa[5])), max(abs(mwa[6]), abs(mwa[7]))
    step = h
    if crit[0] >= 0:
        i = crit[1]
        j = crit[2]
        if crit[0] == 0:
            step = _crit_time(xa, ca, ra_len[i], xb, cb, eb[0], eb[1], i, j, mwa,
                              lin + wa * ra_len[i] + wb * eb[1][j], lam_pair, step)
        else:
            step = _crit_time(xb, cb, rb_len[i], xa, ca, ea[0], ea[1], i, j, mwb,
                              lin + wb * rb_len[i] + wa * ea[1][j], lam_pair, step)
    dmin2, step = _one_way_step(xa, ca, ra_len, xb, cb, eb[0], eb[1], eb[2], mwa, lin, wa, wb,
                                lam, lam_pair, np.inf, step, crit, 0, ea[3], eb[4], eb[5])
    dmin2, step = _one_way_step(xb, cb, rb_len, xa, ca, ea[0], ea[1], ea[2], mwb, lin, wb, wa,
                                lam, lam_pair, dmin2, step, crit, 1, eb[3], ea[4], ea[5])
    return np.sqrt(dmin2), step


@njit(cache=True, nogil=True)
def _window_rates(ma, mb, t0, t1):
    dvx = ma[0] - mb[0]
    dvy = ma[1] - mb[1]
    dax = ma[2] - mb[2]
    day = ma[3] - mb[3]
    lin = max(np.hypot(dvx + dax * t0, dvy + day * t0), np.hypot(dvx + dax * t1, dvy + day * t1))
    wa = max(abs(ma[4] + ma[5] * t0), abs(ma[4] + ma[5] * t1))
    wb = max(abs(mb[4] + mb[5] * t0), abs(mb[4] + mb[5] * t1))
    return lin, wa, wb


@njit(cache=True, nogil=True)
def state_at(ra, sa, ca, ma, xa, rb, sb, cb, mb, xb, t, eps, scratch):
    """The state of the two bodies placed at time t (``xa``, ``xb`` and ``scratch``, a
    :func:`polycontact._kernels.relation._scratch` tuple, are scratch)."""
    place(ra, ca, ma, t, xa)
    place(rb, cb, mb, t, xb)
    return _placed_state(xa, sa, xb, sb, eps, scratch)


@njit(cache=True, nogil=True)
def _placed_state(xa, sa, xb, sb, eps, scratch):
    """``relate_state`` of placed bodies, with the state kernel's scratch passed in."""
    box, ids, touch, rays, rord = scratch
    return _state_in(xa, sa, 1.0, xb, sb, 1.0, eps, box, ids, touch, rays, rord)


@njit(cache=True, nogil=True)
def _search_scratch(ra, rb):
    """Placed vertices of A and B and the state kernel's scratch (see :func:`state_at`)."""
    return np.empty_like(ra), np.empty_like(rb), _scratch(ra.shape[0] + rb.shape[0])


@njit(cache=True, nogil=True)
def exact_search(ra, sa, ca, ma, la, rb, sb, cb, mb, lb, intervals, time_tol, eps, lam,
                 max_iter):
    """Continuous search for the first penetration (conservative advancement).

    Returns ``(status, t_hi, t_lo, first_contact, iterations, t_reached)``: on a hit the
    bodies penetrate at ``t_hi`` and do not at ``t_lo`` (``t_hi − t_lo`` below
    ``time_tol``); ``first_contact`` is the first visited time with boundary distance
    <= ``lam`` (−1 if none); ``t_reached`` is how far the search got.

    Invariant: no penetration has been skipped before ``t`` (see
    :func:`polycontact.time_of_impact` for the argument). From a non-penetrating time
    t with boundary distance d and speed bound S over a window [t, t + H]:

    - :func:`pair_step` gives a step h <= H during which no vertex–edge pair can
      meet (each pair charged its closing rate along its own normal), so the
      boundaries cannot meet and no penetration can start. If h is at least the probe
      length ``tau = min(time_tol / 2, lam / S)`` it is taken. The pairs are held
      ``lam`` apart until the first contact (so that the first time found within
      ``lam`` is at most a probe late) and ``PAIR_GAP · lam`` apart after it, which
      leaves fewer probes to the hit: where the step to ``lam`` is shorter than tau
      before the first contact, the step to ``PAIR_GAP · lam`` (at most
      ``time_tol / 2``) is taken instead;
    - otherwise the step is ``tau``: a penetration that begins and ends inside it lasts
      less than ``time_tol / 2`` with no point moving more than ``lam`` relative to the
      other body; any other penetration is still penetrating at ``t + tau``.

    - after the first contact, before probing, :func:`_slide_step` tries the lines
      through the touching pair: a step it certifies (the bodies stay on either side
      of a line turning with one of them, up to ``eps``) is taken instead, so a
      sliding contact is followed by long steps, not by probes.

    A penetrating state at the end of a probe is the hit, bracketed by the probe.
    """
    ra_len = np.empty(ra.shape[0])
    for i in range(ra.shape[0]):
        ra_len[i] = np.hypot(ra[i, 0], ra[i, 1])
    rb_len = np.empty(rb.shape[0])
    for i in range(rb.shape[0]):
        rb_len[i] = np.hypot(rb[i, 0], rb[i, 1])
    xa, xb, scratch = _search_scratch(ra, rb)
    return _exact_search(ra, sa, ca, ma, la, rb, sb, cb, mb, lb, intervals, time_tol, eps, lam,
                         max_iter, xa, xb, ra_len, rb_len, edge_table(sa, ra_len),
                         edge_table(sb, rb_len), np.empty(2), np.empty(2),
                         np.full(3, -1, np.int64), scratch)


# The searches run without Numba's reference counting (``_nrt=False``): each step passes
# a dozen arrays down several calls, and their atomic reference counts cost as much as
# the geometry of a small pair. Nothing in them may allocate (the compiler refuses if it
# does): their callers pass every buffer in.
@njit(cache=True, nogil=True, _nrt=False)
def _exact_search(ra, sa, ca, ma, la, rb, sb, cb, mb, lb, intervals, time_tol, eps, lam,
                  max_iter, xa, xb, ra_len, rb_len, ea, eb, pa, pb, crit, scratch):
    """:func:`exact_search` with its buffers passed in (``ea``, ``eb``: :func:`edge_table`
    of each body; ``pa``, ``pb``: the centroids; ``crit``: the critical pair)."""
    lam_pair = PAIR_GAP * lam
    first_contact = -1.0
    it = 0
    t = 0.0
    for k in range(intervals.shape[0]):
        t1 = intervals[k, 0]
        t2 = intervals[k, 1]
        t = t1
        pa[0], pa[1] = place(ra, ca, ma, t, xa)
        pb[0], pb[1] = place(rb, cb, mb, t, xb)
        # after t = 0 an interval opens with the bounding circles just touching: apart
        if t == 0.0 and _placed_state(xa, sa, xb, sb, eps, scratch) == _PENETRATING:
            return INITIALLY_PENETRATING, 0.0, 0.0, 0.0, it, 0.0
        window = t2 - t
        while True:
            it += 1
            if it > max_iter:
                return OUT_OF_ITERATIONS, -1.0, -1.0, first_contact, it, t
            t_end = min(t2, t + window)
            s = speed_bound(ma, la, mb, lb, t, t_end)
            # until the first contact the pairs are stepped to lam, so that the first
            # time found within lam is at most a probe late; then closer
            d, h = pair_step(xa, pa, ra_len, ea, xb, pb, rb_len, eb, ma, mb, t, t_end, lam,
                             lam if first_contact < 0.0 else lam_pair, crit)
            if d <= lam and first_contact < 0.0:
                first_contact = t
            if t >= t2 or s <= 0.0:
                break  # at the end, or no relative motion: the state at t holds to t2
            tau = min(0.5 * time_tol, lam / s)
            if h < tau and first_contact < 0.0:
                # about to touch: step the pairs to lam_pair instead, at most
                # time_tol / 2 at a time (so the first contact found is no later)
                h = min(pair_step(xa, pa, ra_len, ea, xb, pb, rb_len, eb, ma, mb, t, t_end,
                                  lam, lam_pair, crit)[1], 0.5 * time_tol)
            if h < tau and first_contact >= 0.0 and crit[0] >= 0:
                # touching: a line through the touching features may separate them
                h = max(h, _slide_step(xa, pa, ra_len, ea[0], la, xb, pb, rb_len, eb[0], lb,
                                       ma, mb, t, t_end, crit, eps, tau))
            if h >= t_end - t:
                h = t_end - t
                window = 2.0 * window
            else:
                window = max(WINDOW_GROWTH * h, 4.0 * tau)
            probe = h < tau
            if probe:
                h = tau
            t_new = min(t + h, t2)
            if t_new <= t:
                break
            if not probe:
                # a conservative step: the boundaries have not met before t_new, so
                # the interiors do not overlap at t_new (overlap is preceded by touch)
                t = t_new
                pa[0], pa[1] = place(ra, ca, ma, t, xa)
                pb[0], pb[1] = place(rb, cb, mb, t, xb)
                continue
            pa[0], pa[1] = place(ra, ca, ma, t_new, xa)
            pb[0], pb[1] = place(rb, cb, mb, t_new, xb)
            if _placed_state(xa, sa, xb, sb, eps, scratch) == _PENETRATING:
                # the probe is the bracket: t_new − t = tau <= time_tol / 2, finer than
                # asked, so no bisection
                if first_contact < 0.0 or first_contact > t:
                    first_contact = t
                return HIT, t_new, t, first_contact, it, t_new
            t = t_new
    return NO_HIT, -1.0, -1.0, first_contact, it, t


@njit(cache=True, nogil=True)
def sampled_search(ra, sa, ca, ma, rb, sb, cb, mb, intervals, threshold, n, eps):
    """The paper's §3 steps 3–6 on each interval, literally.

    n time points t_1 = T1, ..., t_n = T2 (spacing (T2 − T1)/(n − 1)); t0 is the first
    penetrating one; the next interval is [t0 − (T2 − T1)/n, t0]; stop when
    T2 − T1 < threshold and report T2. Returns ``(status, t_hi, t_lo, first_contact,
    evaluations)``; ``first_contact`` is the earliest sample in contact (−1 if none).
    """
    xa, xb, scratch = _search_scratch(ra, rb)
    return _sampled_search(ra, sa, ca, ma, rb, sb, cb, mb, intervals, threshold, n, eps, xa,
                           xb, scratch)


@njit(cache=True, nogil=True, _nrt=False)
def _sampled_search(ra, sa, ca, ma, rb, sb, cb, mb, intervals, threshold, n, eps, xa, xb,
                    scratch):
    """:func:`sampled_search` with its buffers passed in (see :func:`_exact_search`)."""
    first_contact = -1.0
    evals = 0
    for k in range(intervals.shape[0]):
        lo = intervals[k, 0]
        hi = intervals[k, 1]
        if lo == 0.0:
            evals += 1
            if state_at(ra, sa, ca, ma, xa, rb, sb, cb, mb, xb, 0.0, eps, scratch) == _PENETRATING:
                return INITIALLY_PENETRATING, 0.0, 0.0, 0.0, evals
        found = False
        while True:
            t0 = -1.0
            for i in range(n):
                t = hi if i == n - 1 else lo + i * (hi - lo) / (n - 1)
                evals += 1
                st = state_at(ra, sa, ca, ma, xa, rb, sb, cb, mb, xb, t, eps, scratch)
                if st == 1 and (first_contact < 0.0 or t < first_contact):
                    first_contact = t
                if st == _PENETRATING:
                    t0 = t
                    break
            if t0 < 0.0:
                break
            found = True
            length = hi - lo
            lo = max(t0 - length / n, 0.0)
            hi = t0
            if hi - lo < threshold:
                break
        if found:
            return HIT, hi, lo, first_contact, evals
    return NO_HIT, -1.0, -1.0, first_contact, evals


@njit(cache=True, nogil=True)
def query(ra, sa, ca, ma, la, rb, sb, cb, mb, lb, t_max, inflate, exact, time_tol, eps, lam,
          max_iter, samples):
    """Broad phase and search in one call (one dispatch from Python).

    Returns ``(intervals, status, t_hi, t_lo, first_contact, iterations, t_reached)``:
    :func:`exact_search` when ``exact``, else :func:`sampled_search` with ``samples``
    points (``t_reached`` is then t_hi on a hit, else t_max).
    """
    iv = overlap_intervals(ca, ma, la, cb, mb, lb, t_max, inflate)
    if exact:
        code, hi, lo, contact, its, reached = exact_search(ra, sa, ca, ma, la, rb, sb, cb, mb,
                                                           lb, iv, time_tol, eps, lam,
                                                           max_iter)
        return iv, code, hi, lo, contact, its, reached
    code, hi, lo, contact, its = sampled_search(ra, sa, ca, ma, rb, sb, cb, mb, iv, time_tol,
                                                samples, eps)
    return iv, code, hi, lo, contact, its, hi if code == HIT else t_max
