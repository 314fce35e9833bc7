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

from .relation import boundary_distance, relate_state

NO_HIT = 0
HIT = 1
INITIALLY_PENETRATING = 2
OUT_OF_ITERATIONS = 3

_PENETRATING = 2


@njit(cache=True, nogil=True)
def place(r, c0, m, t, out):
    """Write the vertices of the body at time t into ``out`` (same shape as ``r``)."""
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


#: Largest m·n for which :func:`pair_step` (all vertex–edge pairs, no allocation) is
#: used; above it the sweep of ``boundary_distance`` is cheaper per iteration.
PAIR_STEP_MAX = 1024


@njit(cache=True, nogil=True)
def _point_segment2(px, py, ax, ay, bx, by):
    """Squared distance from p to the segment ab."""
    dx = bx - ax
    dy = by - ay
    den = dx * dx + dy * dy
    u = 0.0
    if den > 0.0:
        u = ((px - ax) * dx + (py - ay) * dy) / den
        u = min(1.0, max(0.0, u))
    ex = ax + u * dx - px
    ey = ay + u * dy - py
    return ex * ex + ey * ey


@njit(cache=True, nogil=True)
def _one_way_step(xa, ra_len, sa, xb, sb, rb_len, lin, wa, wb, dmin2, step):
    for k in range(sb.shape[0] - 1):
        s = sb[k]
        e = sb[k + 1]
        for j in range(s, e):
            j1 = j + 1 if j + 1 < e else s
            reach_b = wb * max(rb_len[j], rb_len[j1])
            for i in range(xa.shape[0]):
                d2 = _point_segment2(xa[i, 0], xa[i, 1], xb[j, 0], xb[j, 1], xb[j1, 0],
                                     xb[j1, 1])
                dmin2 = min(dmin2, d2)
                speed = lin + wa * ra_len[i] + reach_b
                reach = step * speed
                if d2 < reach * reach:   # this pair closes sooner than the best so far
                    step = np.sqrt(d2) / speed
    return dmin2, step


@njit(cache=True, nogil=True)
def pair_step(xa, sa, ra_len, xb, sb, rb_len, lin, wa, wb):
    """``(distance, step)``: the boundary distance, and a time step that no vertex–edge
    pair can close.

    ``ra_len[i]`` is the distance of vertex i of A from A's centroid (likewise B);
    ``lin``, ``wa``, ``wb`` bound |Δv + Δa t|, |ω_A + α_A t|, |ω_B + α_B t| over the
    window. A point q of edge e of B moves relative to a vertex p of A at most at
    ``lin + wa |r_p| + wb max(|r_e0|, |r_e1|)`` (|r| is convex along the edge), so the
    distance from p to e cannot close before distance / speed. Boundaries that do not
    cross are at the distance of their nearest vertex–edge pair, and they cannot begin
    to meet without some vertex reaching an edge, so the smallest such time over all
    pairs (both ways) is a step without contact. Per pair, a vertex near its centroid
    is not charged the speed of the farthest one: the step is never shorter than
    distance / :func:`speed_bound`.
    """
    dmin2, step = _one_way_step(xa, ra_len, sa, xb, sb, rb_len, lin, wa, wb, np.inf, np.inf)
    dmin2, step = _one_way_step(xb, rb_len, sb, xa, sa, ra_len, lin, wb, wa, dmin2, step)
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
def state_at(ra, sa, ca, ma, xa, rb, sb, cb, mb, xb, t, eps):
    """relate_state of the two bodies placed at time t (xa, xb are scratch arrays)."""
    place(ra, ca, ma, t, xa)
    place(rb, cb, mb, t, xb)
    return relate_state(xa, sa, xb, sb, eps)


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

    - ``d / S`` is a step during which the boundaries cannot meet (the distance is
      S-Lipschitz), so no penetration can start; for small bodies (m·n <=
      ``PAIR_STEP_MAX``) the longer step of :func:`pair_step` (each vertex–edge pair
      charged its own speed) is used. If the step is at least the probe length
      ``tau = min(time_tol / 2, lam / S)`` it is taken;
    - otherwise the step is ``tau``: a penetration that begins and ends inside it lasts
      less than ``time_tol / 2`` with no point moving more than ``lam`` relative to the
      other body; any other penetration is still penetrating at ``t + tau``.

    A penetrating state at the end of a step is bisected back to the previous time.
    """
    xa = np.empty_like(ra)
    xb = np.empty_like(rb)
    ra_len = np.empty(ra.shape[0])
    for i in range(ra.shape[0]):
        ra_len[i] = np.hypot(ra[i, 0], ra[i, 1])
    rb_len = np.empty(rb.shape[0])
    for i in range(rb.shape[0]):
        rb_len[i] = np.hypot(rb[i, 0], rb[i, 1])
    small = ra.shape[0] * rb.shape[0] <= PAIR_STEP_MAX
    first_contact = -1.0
    it = 0
    t = 0.0
    for k in range(intervals.shape[0]):
        t1 = intervals[k, 0]
        t2 = intervals[k, 1]
        t = t1
        place(ra, ca, ma, t, xa)
        place(rb, cb, mb, t, xb)
        # after t = 0 an interval opens with the bounding circles just touching: apart
        if t == 0.0 and relate_state(xa, sa, xb, sb, eps) == _PENETRATING:
            return INITIALLY_PENETRATING, 0.0, 0.0, 0.0, it, 0.0
        window = t2 - t
        while True:
            it += 1
            if it > max_iter:
                return OUT_OF_ITERATIONS, -1.0, -1.0, first_contact, it, t
            t_end = min(t2, t + window)
            lin, wa, wb = _window_rates(ma, mb, t, t_end)
            s = lin + wa * la + wb * lb
            if small:
                d, h = pair_step(xa, sa, ra_len, xb, sb, rb_len, lin, wa, wb)
            else:
                d = boundary_distance(xa, sa, xb, sb)
                h = d / s if s > 0.0 else np.inf
            if d <= lam and first_contact < 0.0:
                first_contact = t
            if t >= t2 or s <= 0.0:
                break  # at the end, or no relative motion: the state at t holds to t2
            tau = min(0.5 * time_tol, lam / s)
            if h >= t_end - t:
                h = t_end - t
                window = 2.0 * window
            else:
                window = max(4.0 * h, 4.0 * tau)
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
                place(ra, ca, ma, t, xa)
                place(rb, cb, mb, t, xb)
                continue
            st = state_at(ra, sa, ca, ma, xa, rb, sb, cb, mb, xb, t_new, eps)
            if st == _PENETRATING:
                lo = t
                hi = t_new
                goal = 0.1 * tau
                while hi - lo > goal:
                    mid = 0.5 * (lo + hi)
                    if mid <= lo or mid >= hi:
                        break
                    it += 1
                    if state_at(ra, sa, ca, ma, xa, rb, sb, cb, mb, xb, mid, eps) == _PENETRATING:
                        hi = mid
                    else:
                        lo = mid
                if first_contact < 0.0 or first_contact > lo:
                    first_contact = lo
                return HIT, hi, lo, first_contact, it, hi
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
    xa = np.empty_like(ra)
    xb = np.empty_like(rb)
    first_contact = -1.0
    evals = 0
    for k in range(intervals.shape[0]):
        lo = intervals[k, 0]
        hi = intervals[k, 1]
        if lo == 0.0:
            evals += 1
            if state_at(ra, sa, ca, ma, xa, rb, sb, cb, mb, xb, 0.0, eps) == _PENETRATING:
                return INITIALLY_PENETRATING, 0.0, 0.0, 0.0, evals
        found = False
        while True:
            t0 = -1.0
            for i in range(n):
                t = hi if i == n - 1 else lo + i * (hi - lo) / (n - 1)
                evals += 1
                st = state_at(ra, sa, ca, ma, xa, rb, sb, cb, mb, xb, t, eps)
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
