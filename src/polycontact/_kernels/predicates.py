"""Kernels: exact signs of orientations, and exact meets of segments.

:func:`orientation` gives the sign of ``(b − a) × (c − a)`` for float64 points exactly:
a float filter with a proven error bound (Shewchuk's, "Adaptive Precision
Floating-Point Arithmetic and Fast Robust Geometric Predicates", 1997) decides almost
every case; where it cannot, the determinant is summed exactly as an expansion of
float64 numbers (the six products ``ax·by``... each split into two floats without
rounding, then added without rounding) and the sign read off its largest component.

The exact sum needs each product of two nonzero coordinates and its rounding error to
stay normal floats: the x and the y coordinates are first scaled apart by powers of two
(which round nothing and leave the sign alone) so that the largest of each is near
2**505. A product still below 2**-960 (coordinates spanning about 2**985 in x and in y
at once, like 5e-324 beside 1) is summed apart, its factors lifted by 2**500 each;
the two sums are compared, and added exactly where they are of one size. Coordinates
up to 1e100 in magnitude (:data:`polycontact.limits.COORDINATE_LIMIT`) keep every
step within float64's range.

>>> orientation(0.0, 0.0, 1.0, 0.0, 0.5, 5e-324), orientation(0.0, 0.0, 1.0, 1.0, 3.0, 3.0)
(1, 0)
>>> orientation(5e-324, 1.0, 1.0, 5e-324, 0.5, 0.5)  # 1 beside 5e-324, in x and in y
-1
"""

from __future__ import annotations

import math

import numpy as np

from .jit import njit

_EPS = 2.0**-53
#: Shewchuk's bound on the rounding of the filtered determinant (relative to the sum
#: of the two products' magnitudes), for ``|det| >= bound``.
_FILTER = (3.0 + 16.0 * _EPS) * _EPS
#: Absolute allowance of the filter: products that underflow lose up to 2**-1075 each.
_FILTER_FLOOR = 2.0**-1000
_SPLITTER = 2.0**27 + 1.0
_TOP = 505
#: Smallest product of two scaled coordinates whose rounding error is a normal float.
_BOTTOM = 2.0**-960
#: Power of two each factor of a smaller product is lifted by before it is multiplied.
_LIFT = 500


@njit(cache=True, nogil=True, inline="always")
def _two_sum(a, b):
    x = a + b
    bv = x - a
    av = x - bv
    return x, (a - av) + (b - bv)


@njit(cache=True, nogil=True, inline="always")
def _split(a):
    c = _SPLITTER * a
    big = c - a
    hi = c - big
    return hi, a - hi


@njit(cache=True, nogil=True, inline="always")
def _two_product(a, b):
    x = a * b
    ah, al = _split(a)
    bh, bl = _split(b)
    err = x - ah * bh - al * bh - ah * bl
    return x, al * bl - err


@njit(cache=True, nogil=True)
def _expansion(terms):
    """The nonoverlapping expansion of the exact sum of ``terms`` (Shewchuk's
    Grow-Expansion): components of increasing magnitude, zeros among them, whose sign
    and magnitude are those of the last nonzero one (which is more than half the sum)."""
    n = terms.shape[0]
    h = np.zeros(n)
    for k in range(n):
        q = terms[k]
        for i in range(k):
            q, h[i] = _two_sum(q, h[i])
        h[k] = q
    return h


@njit(cache=True, nogil=True)
def _top(h):
    """The last nonzero component of an expansion (0.0 if there is none)."""
    for i in range(h.shape[0] - 1, -1, -1):
        if h[i] != 0.0:
            return h[i]
    return 0.0


@njit(cache=True, nogil=True)
def _exact_orientation(ax, ay, bx, by, cx, cy):
    """The sign of the orientation summed exactly (see the module's docstring)."""
    mx = max(abs(ax), abs(bx), abs(cx))
    my = max(abs(ay), abs(by), abs(cy))
    if mx == 0.0 or my == 0.0:
        return 0  # three points on an axis
    # x and y scaled apart (the sign does not change): the largest of each near 2**505
    sx = _TOP - math.frexp(mx)[1]
    sy = _TOP - math.frexp(my)[1]
    v = np.empty(6)
    v[0] = math.ldexp(ax, sx)
    v[1] = math.ldexp(ay, sy)
    v[2] = math.ldexp(bx, sx)
    v[3] = math.ldexp(by, sy)
    v[4] = math.ldexp(cx, sx)
    v[5] = math.ldexp(cy, sy)
    # det = ax·by − ax·cy − ay·bx + ay·cx + bx·cy − by·cx
    big = np.zeros(12)
    tiny = np.zeros(12)  # the products below 2**-960, each times 2**1000
    pairs = ((0, 3, 1.0), (0, 5, -1.0), (1, 2, -1.0), (1, 4, 1.0), (2, 5, 1.0), (3, 4, -1.0))
    m = 0
    for p, q, s in pairs:
        x, y = _two_product(v[p], v[q])
        if abs(x) < _BOTTOM and v[p] != 0.0 and v[q] != 0.0:
            x, y = _two_product(math.ldexp(v[p], _LIFT), math.ldexp(v[q], _LIFT))
            tiny[m] = s * x
            tiny[m + 1] = s * y
        else:
            big[m] = s * x
            big[m + 1] = s * y
        m += 2
    e = _expansion(big)
    t = _expansion(tiny)
    top = _top(e)
    low = _top(t)
    if top == 0.0 or low == 0.0:
        top = top if top != 0.0 else low
        return 0 if top == 0.0 else (1 if top > 0.0 else -1)
    # |E| > |top| / 2 and |T| < 2 |low| 2**-1000: E decides unless it is as small as T
    # (|low| < 2**44, so E at or above 2**-950 decides before any lifting could overflow)
    if abs(top) >= 2.0**-950 or math.ldexp(abs(top), 2 * _LIFT) > 4.0 * abs(low):
        return 1 if top > 0.0 else -1
    both = np.empty(24)  # (E is below 2**-955 here: lifting it by 2**1000 is exact)
    for i in range(12):
        both[i] = math.ldexp(e[i], 2 * _LIFT)
        both[12 + i] = t[i]
    top = _top(_expansion(both))
    return 0 if top == 0.0 else (1 if top > 0.0 else -1)


@njit(cache=True, nogil=True)
def orientation(ax, ay, bx, by, cx, cy):
    """The exact sign of the orientation of a, b, c: 1 when c is left of the line from
    a to b, -1 right, 0 on it."""
    left = (ax - cx) * (by - cy)
    right = (ay - cy) * (bx - cx)
    det = left - right
    if abs(det) > _FILTER * (abs(left) + abs(right)) + _FILTER_FLOOR:
        return 1 if det > 0.0 else -1
    return _exact_orientation(ax, ay, bx, by, cx, cy)


@njit(cache=True, nogil=True, inline="always")
def _within(p, a, b):
    """``p`` lies in the closed interval between ``a`` and ``b`` (exact)."""
    return min(a, b) <= p <= max(a, b)


@njit(cache=True, nogil=True)
def on_segment(px, py, ax, ay, bx, by, o):
    """Point p, whose orientation against segment ab is ``o``, lies on the closed
    segment (exact: a collinear point lies on it when it is within its box)."""
    return o == 0 and _within(px, ax, bx) and _within(py, ay, by)


@njit(cache=True, nogil=True)
def segments_meet(ax, ay, bx, by, cx, cy, dx, dy):
    """How the closed segments ab and cd meet, exactly: ``(kind, x, y)``.

    ``kind`` is 0 when they do not meet, 1 when they touch (an end of one lies on the
    other, collinear overlaps included), 2 when they cross properly (each has its ends
    strictly on both sides of the other's line). ``(x, y)`` is where: the touching end,
    or the crossing point (rounded).
    """
    o1 = orientation(ax, ay, bx, by, cx, cy)
    o2 = orientation(ax, ay, bx, by, dx, dy)
    if o1 == o2 and o1 != 0:
        return 0, 0.0, 0.0
    o3 = orientation(cx, cy, dx, dy, ax, ay)
    o4 = orientation(cx, cy, dx, dy, bx, by)
    if o3 == o4 and o3 != 0:
        return 0, 0.0, 0.0
    if o1 != 0 and o2 != 0 and o3 != 0 and o4 != 0:
        # strictly on both sides, both ways
        d1 = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
        d2 = (bx - ax) * (dy - ay) - (by - ay) * (dx - ax)
        s = d1 / (d1 - d2) if d1 != d2 else 0.5
        return 2, cx + s * (dx - cx), cy + s * (dy - cy)
    if on_segment(cx, cy, ax, ay, bx, by, o1):
        return 1, cx, cy
    if on_segment(dx, dy, ax, ay, bx, by, o2):
        return 1, dx, dy
    if on_segment(ax, ay, cx, cy, dx, dy, o3):
        return 1, ax, ay
    if on_segment(bx, by, cx, cy, dx, dy, o4):
        return 1, bx, by
    return 0, 0.0, 0.0


@njit(cache=True, nogil=True)
def collinear_overlap(ax, ay, bx, by, cx, cy, dx, dy):
    """Collinear segments ab and cd (both orientations of c and d against ab zero)
    share a piece of positive length (exact)."""
    if ax != bx:
        lo = max(min(ax, bx), min(cx, dx))
        hi = min(max(ax, bx), max(cx, dx))
    else:
        lo = max(min(ay, by), min(cy, dy))
        hi = min(max(ay, by), max(cy, dy))
    return lo < hi
