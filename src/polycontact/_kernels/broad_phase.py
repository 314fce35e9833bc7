"""Kernels: times when two bounding circles overlap (paper Eq. 5 with accelerations).

With D(t) = c_A(t) − c_B(t) = d0 + dv t + h t² (h = Δa/2, per component), the circles
overlap where f(t) = |D(t)|² − R² <= 0, a polynomial of degree at most 4 in t. Its
sign pattern on ``[lo, hi]`` is found without eigenvalues: the derivatives are isolated
from the linear one upward, so that between consecutive breakpoints each derivative is
monotone and every root is bracketed and bisected to the last bit. Double roots (the
circles only grazing) and lower degrees (no acceleration, no relative motion) need no
special case.

Nothing is expanded into power-basis coefficients: f and its derivatives are evaluated
from D, D' = dv + 2 h t and D'' = 2 h, in coordinates relative to the bodies (f itself
through the sign of |D| − R). Expanded coefficients lose everything at long travel or
far from the origin (|d0|² = 1e18 swallows R² = 2 when d0 = 1e9); these evaluations
keep each root to the float spacing of the positions, and the radius is widened by a
bound of that rounding at each time (:func:`rounding_allowance`), so the intervals are
never too short. The widening is local to the time: R(t) = R0 + R1 t + R2 t² grows as
the positions' terms do (f stays a polynomial of degree at most 4), never by the
rounding at ``t_max`` (a window of 1e27 would otherwise widen the circles by 1e12 from
t = 0 on). The roots are polished by bisection to adjacent floats.
"""

from __future__ import annotations

import numpy as np

from .jit import njit
from .packs import view

_ULP = 2.0**-52
#: Breakpoints of f on [lo, hi]: both ends and at most one root per derivative of
#: degree 1 to 3 (f has degree <= 4).
WORK_POINTS = 6
#: The most intervals a quartic's nonpositive set has within [lo, hi] (its roots cut it
#: in at most five pieces, every other one nonpositive).
MAX_INTERVALS = 3
#: Scratch floats of :func:`overlap_intervals_into`: the motion ``p`` and two levels of
#: breakpoints.
BROAD_PHASE_FLOATS = 8 + 2 * WORK_POINTS


@njit(cache=True, nogil=True)
def relative_motion(ca, ma, cb, mb):
    """``p`` of shape (4, 2): rows d0, dv, h of D(t) = d0 + dv t + h t², the centroid of
    A relative to B's (``ma``, ``mb``: motion vectors ``[vx, vy, ax, ay, ω, α]``), and
    the growth ``(R1, R2)`` of the radius R(t) = r + R1 t + R2 t² (zero here: a fixed
    radius; :func:`overlap_intervals_into` sets it)."""
    return _relative_motion_into(ca, ma, cb, mb, np.empty((4, 2)))


@njit(cache=True, nogil=True, inline="always")
def _relative_motion_into(ca, ma, cb, mb, p):
    """:func:`relative_motion` written into ``p`` (4, 2); returns ``p``."""
    for k in range(2):
        p[0, k] = ca[k] - cb[k]
        p[1, k] = ma[k] - mb[k]
        p[2, k] = 0.5 * (ma[2 + k] - mb[2 + k])
        p[3, k] = 0.0
    return p


@njit(cache=True, nogil=True)
def degree(p):
    """Degree of f = |D|² − R²: 4 with relative acceleration (or a radius growing with
    t²), 2 with relative velocity only (or a radius growing with t), else 0."""
    if p[2, 0] != 0.0 or p[2, 1] != 0.0 or p[3, 1] != 0.0:
        return 4
    if p[1, 0] != 0.0 or p[1, 1] != 0.0 or p[3, 0] != 0.0:
        return 2
    return 0


@njit(cache=True, nogil=True)
def derivative(p, r, k, t):
    """The k-th derivative of f(t) = |D(t)|² − R(t)² at t for k >= 1, R(t) = r + R1 t +
    R2 t² (``(R1, R2)`` = ``p[3]``), evaluated from D, R and their derivatives (no
    expanded coefficients); for k = 0, |D(t)| − R(t), which has the sign of f (R >= 0
    for t >= 0)."""
    dx = p[0, 0] + (p[1, 0] + p[2, 0] * t) * t
    dy = p[0, 1] + (p[1, 1] + p[2, 1] * t) * t
    d1x = p[1, 0] + 2.0 * p[2, 0] * t
    d1y = p[1, 1] + 2.0 * p[2, 1] * t
    d2x = 2.0 * p[2, 0]
    d2y = 2.0 * p[2, 1]
    rho = r + (p[3, 0] + p[3, 1] * t) * t
    rho1 = p[3, 0] + 2.0 * p[3, 1] * t
    rho2 = 2.0 * p[3, 1]
    if k == 0:
        return np.hypot(dx, dy) - rho
    if k == 1:
        return 2.0 * (dx * d1x + dy * d1y - rho * rho1)
    if k == 2:
        return 2.0 * (d1x * d1x + d1y * d1y + dx * d2x + dy * d2y - rho1 * rho1 - rho * rho2)
    if k == 3:
        return 6.0 * (d1x * d2x + d1y * d2y - rho1 * rho2)
    return 6.0 * (d2x * d2x + d2y * d2y - rho2 * rho2)


@njit(cache=True, nogil=True)
def _bisect(p, r, k, a, b, fa):
    """A root of the k-th :func:`derivative` in [a, b], where it is monotone and changes
    sign (fa = its value at a, nonzero, and the value at b nonzero), to adjacent floats.

    The bracket shrinks by false position two steps in three (Illinois: when the same
    end stays put twice, its value is halved, so both ends converge) and by halving
    the third, so it reaches adjacent floats in a few steps for the smooth functions
    here and never in more than three times the halvings alone. Every step keeps a
    sign change inside the bracket: the answer is a root to adjacent floats whichever
    steps were taken."""
    neg = fa < 0.0
    fb = derivative(p, r, k, b)
    kept = 0  # the end that stayed put in the last step: -1 a, +1 b
    for step in range(6300):
        m = 0.5 * (a + b)
        if m <= a or m >= b:
            break
        if step % 3 != 2 and fa != fb:
            x = a - fa * ((b - a) / (fb - fa))
            if a < x < b:
                m = x
        fm = derivative(p, r, k, m)
        if fm == 0.0:
            return m
        if (fm < 0.0) == neg:
            a, fa = m, fm
            if kept == 1:
                fb *= 0.5
            kept = 1
        else:
            b, fb = m, fm
            if kept == -1:
                fa *= 0.5
            kept = -1
    return 0.5 * (a + b)


@njit(cache=True, nogil=True)
def monotone_breakpoints(p, lo, hi, r=0.0):
    """Sorted points from lo to hi between which f = |D|² − R² is monotone (``p`` from
    :func:`relative_motion`; ``r`` the radius at t = 0, which matters only when the
    radius grows)."""
    work = np.empty(2 * WORK_POINTS)
    n = _breakpoints_into(p, r, lo, hi, work)
    return work[:n].copy()


@njit(cache=True, nogil=True)
def _breakpoints_into(p, r, lo, hi, work):
    """:func:`monotone_breakpoints` in ``work[:n]``; returns n. ``work``: at least
    2 :data:`WORK_POINTS` floats (the points of two levels, in turn)."""
    deg = degree(p)
    pts = work[:WORK_POINTS]
    new = work[WORK_POINTS:2 * WORK_POINTS]
    second = False  # whether pts is the second half
    pts[0] = lo
    pts[1] = hi
    npts = 2
    # the (deg − 1)-th derivative is linear, hence monotone on [lo, hi]; walk down to f'
    for k in range(deg - 1, 0, -1):
        new[0] = lo
        nn = 1
        for s in range(npts - 1):
            a = pts[s]
            b = pts[s + 1]
            fa = derivative(p, r, k, a)
            fb = derivative(p, r, k, b)
            if fa == 0.0:
                x = a
            elif fb == 0.0 or (fa < 0.0) != (fb < 0.0):
                x = b if fb == 0.0 else _bisect(p, r, k, a, b, fa)
            else:
                continue
            if lo < x < hi and x > new[nn - 1]:
                new[nn] = x
                nn += 1
        new[nn] = hi
        nn += 1
        pts, new = new, pts
        npts = nn
        second = not second
    if second:
        for q in range(npts):  # (a loop: a slice copy may allocate)
            work[q] = pts[q]
    return npts


@njit(cache=True, nogil=True)
def nonpositive_intervals(p, r, lo, hi):
    """Closed intervals of [lo, hi] where |D(t)| <= r, merged, as (k, 2)."""
    out = np.empty((MAX_INTERVALS, 2))
    n = _intervals_into(p, r, lo, hi, out, np.empty(2 * WORK_POINTS))
    return out[:n].copy()


@njit(cache=True, nogil=True)
def _intervals_into(p, r, lo, hi, out, work):
    """:func:`nonpositive_intervals` in ``out[:n]`` ((:data:`MAX_INTERVALS`, 2)); returns
    n. ``work``: scratch of :func:`_breakpoints_into`."""
    npts = _breakpoints_into(p, r, lo, hi, work)
    n = 0
    for s in range(npts - 1):
        a = work[s]
        b = work[s + 1]
        fa = derivative(p, r, 0, a)
        fb = derivative(p, r, 0, b)
        if fa <= 0.0 and fb <= 0.0:
            x0, x1 = a, b
        elif fa <= 0.0:
            x0, x1 = a, (a if fa == 0.0 else _bisect(p, r, 0, a, b, fa))
        elif fb <= 0.0:
            x0, x1 = (b if fb == 0.0 else _bisect(p, r, 0, a, b, fa)), b
        else:
            continue
        if n > 0 and (x0 <= out[n - 1, 1] or n == out.shape[0]):
            # (touching the last one; or, never for a quartic, no room: the last one
            # grown over this one, which only adds time to search)
            out[n - 1, 1] = max(out[n - 1, 1], x1)
        else:
            out[n, 0] = x0
            out[n, 1] = x1
            n += 1
    return n


@njit(cache=True, nogil=True)
def rounding_allowance(ca, ma, cb, mb, t):
    """A bound of the rounding in the centroids and in D at time t: 16 units of 2**-52
    of the largest |term| of c_A(t) and c_B(t) (initial position, travel at the initial
    speed, travel by the acceleration). It grows with t, so its value at the end of a
    window bounds it over the window."""
    big = 0.0
    for c, m in ((ca, ma), (cb, mb)):
        for k in range(2):
            big += abs(c[k]) + abs(m[k]) * t + 0.5 * abs(m[2 + k]) * t * t
    return 16.0 * _ULP * big


@njit(cache=True, nogil=True)
def overlap_intervals(ca, ma, ra, cb, mb, rb, t_max, inflate):
    """Closed sub-intervals of [0, t_max] where the bounding circles touch or overlap,
    the sum of their radii R enlarged by ``inflate`` (relative), or by the rounding of
    the positions at each time (:func:`rounding_allowance` at t, not at t_max) where
    that is larger (far from the origin, at long travel), so that no instant of overlap
    is dropped."""
    out = np.empty((MAX_INTERVALS, 2))
    n = overlap_intervals_into(ca, ma, ra, cb, mb, rb, t_max, inflate, out,
                               np.empty(BROAD_PHASE_FLOATS))
    return out[:n].copy()


@njit(cache=True, nogil=True)
def overlap_intervals_into(ca, ma, ra, cb, mb, rb, t_max, inflate, out, work):
    """:func:`overlap_intervals` written into ``out[:n]`` ((:data:`MAX_INTERVALS`, 2));
    returns n. ``work``: :data:`BROAD_PHASE_FLOATS` floats of scratch. Nothing is
    allocated (for callers that query many times)."""
    big = ra + rb
    r = max(big * (1.0 + inflate), big + rounding_allowance(ca, ma, cb, mb, 0.0))
    p = _relative_motion_into(ca, ma, cb, mb, view(work, 0, 4, 2, np.float64))
    if big + rounding_allowance(ca, ma, cb, mb, t_max) > r:
        # the radius grows with the terms of the positions, as the allowance at t does:
        # R(t) = r + R1 t + R2 t² >= big + the allowance at t, whatever t_max is
        grow1 = 0.0
        grow2 = 0.0
        for k in range(2):
            grow1 += abs(ma[k]) + abs(mb[k])
            grow2 += 0.5 * (abs(ma[2 + k]) + abs(mb[2 + k]))
        p[3, 0] = 16.0 * _ULP * grow1
        p[3, 1] = 16.0 * _ULP * grow2
    return _intervals_into(p, r, 0.0, t_max, out, work[8:])
