"""Kernels: times when two bounding circles overlap (paper Eq. 5 with accelerations).

The squared distance of the centroids minus the squared sum of the radii is a
polynomial of degree at most 4 in t. Its sign pattern on ``[lo, hi]`` is found without
eigenvalues: the derivatives are isolated from the linear one upward, so that between
consecutive breakpoints each derivative is monotone and every root is bracketed and
bisected to the last bit. Double roots (the circles only grazing) and lower degrees
(no acceleration, no relative motion) need no special case.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def _eval(c, deg, t):
    r = 0.0
    for k in range(deg, -1, -1):
        r = r * t + c[k]
    return r


@njit(cache=True, nogil=True)
def _bisect(c, deg, a, b, fa):
    """A root of c in [a, b], where c is monotone and changes sign (fa = c(a))."""
    neg = fa < 0.0
    for _ in range(2100):
        m = 0.5 * (a + b)
        if m <= a or m >= b:
            break
        fm = _eval(c, deg, m)
        if fm == 0.0:
            return m
        if (fm < 0.0) == neg:
            a = m
        else:
            b = m
    return 0.5 * (a + b)


@njit(cache=True, nogil=True)
def monotone_breakpoints(coeffs, lo, hi):
    """Sorted points from lo to hi between which the polynomial is monotone.

    ``coeffs`` are ascending (``coeffs[k]`` multiplies t**k), degree at most 4.
    """
    deg = coeffs.shape[0] - 1
    while deg > 0 and coeffs[deg] == 0.0:
        deg -= 1
    # derivatives: ders[k] holds the k-th derivative, ascending coefficients
    ders = np.zeros((deg + 1, deg + 1))
    for i in range(deg + 1):
        ders[0, i] = coeffs[i]
    for k in range(1, deg + 1):
        for i in range(deg + 1 - k):
            ders[k, i] = ders[k - 1, i + 1] * (i + 1)
    pts = np.empty(deg + 2)
    pts[0] = lo
    pts[1] = hi
    npts = 2
    # ders[deg - 1] is linear, hence monotone on [lo, hi]; walk down to ders[1]
    for k in range(deg - 1, 0, -1):
        dk = deg - k
        new = np.empty(deg + 2)
        new[0] = lo
        nn = 1
        for s in range(npts - 1):
            a = pts[s]
            b = pts[s + 1]
            fa = _eval(ders[k], dk, a)
            fb = _eval(ders[k], dk, b)
            if fa == 0.0:
                r = a
            elif fb == 0.0 or (fa < 0.0) != (fb < 0.0):
                r = b if fb == 0.0 else _bisect(ders[k], dk, a, b, fa)
            else:
                continue
            if lo < r < hi and r > new[nn - 1]:
                new[nn] = r
                nn += 1
        new[nn] = hi
        nn += 1
        pts = new
        npts = nn
    return pts[:npts]


@njit(cache=True, nogil=True)
def nonpositive_intervals(coeffs, lo, hi):
    """Closed intervals of [lo, hi] where the polynomial is <= 0, merged, as (k, 2)."""
    deg = coeffs.shape[0] - 1
    while deg > 0 and coeffs[deg] == 0.0:
        deg -= 1
    pts = monotone_breakpoints(coeffs, lo, hi)
    out = np.empty((pts.shape[0], 2))
    n = 0
    for s in range(pts.shape[0] - 1):
        a = pts[s]
        b = pts[s + 1]
        fa = _eval(coeffs, deg, a)
        fb = _eval(coeffs, deg, b)
        if fa <= 0.0 and fb <= 0.0:
            x0, x1 = a, b
        elif fa <= 0.0:
            x0, x1 = a, (a if fa == 0.0 else _bisect(coeffs, deg, a, b, fa))
        elif fb <= 0.0:
            x0, x1 = (b if fb == 0.0 else _bisect(coeffs, deg, a, b, fa)), b
        else:
            continue
        if n > 0 and x0 <= out[n - 1, 1]:
            out[n - 1, 1] = max(out[n - 1, 1], x1)
        else:
            out[n, 0] = x0
            out[n, 1] = x1
            n += 1
    return out[:n].copy()


@njit(cache=True, nogil=True)
def circle_overlap_coefficients(ca, ma, ra, cb, mb, rb, inflate):
    """Ascending coefficients of |c_A(t) − c_B(t)|² − (R (1 + inflate))², R = ra + rb.

    ``ma``/``mb`` are motion vectors ``[vx, vy, ax, ay, ω, α]``.
    """
    c = np.zeros(5)
    for k in range(2):
        d0 = ca[k] - cb[k]
        dv = ma[k] - mb[k]
        h = 0.5 * (ma[2 + k] - mb[2 + k])
        c[4] += h * h
        c[3] += 2.0 * h * dv
        c[2] += dv * dv + 2.0 * h * d0
        c[1] += 2.0 * d0 * dv
        c[0] += d0 * d0
    r = (ra + rb) * (1.0 + inflate)
    c[0] -= r * r
    return c


@njit(cache=True, nogil=True)
def overlap_intervals(ca, ma, ra, cb, mb, rb, t_max, inflate):
    """Closed sub-intervals of [0, t_max] where the bounding circles touch or overlap."""
    c = circle_overlap_coefficients(ca, ma, ra, cb, mb, rb, inflate)
    return nonpositive_intervals(c, 0.0, t_max)
