"""Kernels: classify many pairs at once.

The state kernels are serial: for small pairs (about a microsecond each) a ``prange``
version measured 2-3 times slower on a 2-core machine; the caller splits the pairs over
threads instead (the kernels release the GIL). The signed distances (penetration depths
cost far more per pair) use ``prange``.

A batch of bodies is packed as ``xy`` (V, 2) float64 (every body's loops stacked, body
after body), ``ls`` int64 and ``bs`` int64 (P+1,): the loop starts of body p are
``ls[bs[p]:bs[p + 1]]`` (rows of ``xy``, its last entry is the end of the body), and
``sign`` (P,) float64: +1.0 if the interior is on the left of every edge, -1.0 if on
the right (a clockwise raw ring, classified without a copy).
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from .relation import CONTACT, SEPARATE, _raw_ring, _scratch, _state_in, closest_pair, penetration


@njit(cache=True, nogil=True)
def check_rings(xy, lo, n, rel):
    """Validate raw rings ``xy[lo[p]:lo[p] + n[p]]``; returns (vertices used or -1, sign)."""
    p_count = lo.shape[0]
    used = np.empty(p_count, np.int64)
    sign = np.empty(p_count)
    for p in range(p_count):
        u, s, _, _ = _raw_ring(xy[lo[p] : lo[p] + n[p]], rel)
        used[p] = u
        sign[p] = s
    return used, sign


@njit(cache=True, nogil=True)
def raw_states(xa, xb, tol, rel):
    """Validate and classify P pairs of raw outer rings, ``xa`` (P, N, 2) against
    ``xb`` (P, M, 2), in one pass over the pairs.

    Returns ``(states, eps, used_a, sign_a, used_b, sign_b)``: per pair the state
    (int8; -1 when either ring is not valid as given), the tolerance, and per ring
    the vertices used (a repeated closing point dropped; -1 if invalid) and the
    orientation sign (see :func:`polycontact._kernels.relation._raw_ring`).
    ``tol`` < 0 means per pair ``rel`` × the largest absolute coordinate of the pair.
    """
    p_count = xa.shape[0]
    states = np.empty(p_count, np.int8)
    eps = np.zeros(p_count)
    used_a = np.empty(p_count, np.int64)
    used_b = np.empty(p_count, np.int64)
    sign_a = np.empty(p_count)
    sign_b = np.empty(p_count)
    box, ids, touch, rays, rord = _scratch(xa.shape[1] + xb.shape[1])
    sa = np.zeros(2, np.int64)
    sb = np.zeros(2, np.int64)
    for p in range(p_count):
        na, fa, sca, ba = _raw_ring(xa[p], rel)
        nb, fb, scb, bb = _raw_ring(xb[p], rel)
        used_a[p] = na
        used_b[p] = nb
        sign_a[p] = fa
        sign_b[p] = fb
        if na < 0 or nb < 0:
            states[p] = -1
            continue
        e = tol if tol >= 0.0 else rel * max(sca, scb)
        eps[p] = e
        if ba[0] > bb[1] + e or bb[0] > ba[1] + e or ba[2] > bb[3] + e or bb[2] > ba[3] + e:
            states[p] = SEPARATE  # boxes apart: no call into the state kernel
            continue
        sa[1] = na
        sb[1] = nb
        states[p] = _state_in(
            xa[p][:na], sa, fa, xb[p][:nb], sb, fb, e, box, ids, touch, rays, rord
        )
    return states, eps, used_a, sign_a, used_b, sign_b


@njit(cache=True, nogil=True)
def _body(xy, ls, bs, p):
    first = ls[bs[p]]
    starts = ls[bs[p] : bs[p + 1]] - first
    return xy[first : ls[bs[p + 1] - 1]], starts


@njit(cache=True, nogil=True)
def _body_into(xy, ls, bs, p, buf):
    """:func:`_body` with the loop starts written into ``buf`` (no allocation)."""
    first = ls[bs[p]]
    m = bs[p + 1] - bs[p]
    for k in range(m):
        buf[k] = ls[bs[p] + k] - first
    return xy[first : ls[bs[p + 1] - 1]], buf[:m]


@njit(cache=True, nogil=True)
def _largest(ls, bs):
    """Most vertices and most loop starts of one body in a packed batch."""
    v = 0
    m = 0
    for p in range(bs.shape[0] - 1):
        v = max(v, ls[bs[p + 1] - 1] - ls[bs[p]])
        m = max(m, bs[p + 1] - bs[p])
    return v, m


@njit(cache=True, nogil=True)
def _scale(xy):
    s = 1.0
    for i in range(xy.shape[0]):
        s = max(s, abs(xy[i, 0]), abs(xy[i, 1]))
    return s


@njit(cache=True, nogil=True)
def many_states(xa, lsa, bsa, fa, xb, lsb, bsb, fb, tol, rel):
    """States (int8: 0 separate, 1 contact, 2 penetrating) and tolerances of P pairs.

    ``tol`` < 0 means per pair ``rel`` × the largest absolute coordinate of the pair.
    """
    p_count = bsa.shape[0] - 1
    states = np.empty(p_count, np.int8)
    eps = np.empty(p_count)
    va, ma = _largest(lsa, bsa)
    vb, mb = _largest(lsb, bsb)
    box, ids, touch, rays, rord = _scratch(va + vb)
    buf_a = np.empty(ma, np.int64)
    buf_b = np.empty(mb, np.int64)
    for p in range(p_count):
        ya, sa = _body_into(xa, lsa, bsa, p, buf_a)
        yb, sb = _body_into(xb, lsb, bsb, p, buf_b)
        e = tol if tol >= 0.0 else rel * max(_scale(ya), _scale(yb))
        eps[p] = e
        states[p] = _state_in(ya, sa, fa[p], yb, sb, fb[p], e, box, ids, touch, rays, rord)
    return states, eps


@njit(cache=True, nogil=True)
def _oriented(y, s, f):
    if f > 0.0:
        return y
    return y[::-1].copy()  # raw rings are single loops


@njit(cache=True, nogil=True, parallel=True)
def many_distances(xa, lsa, bsa, fa, xb, lsb, bsb, fb, states, eps):
    """Signed distances of P classified pairs: the boundary gap, 0, or minus the depth."""
    p_count = bsa.shape[0] - 1
    out = np.empty(p_count)
    for p in prange(p_count):
        ya, sa = _body(xa, lsa, bsa, p)
        yb, sb = _body(xb, lsb, bsb, p)
        if states[p] == SEPARATE:
            out[p] = closest_pair(ya, sa, yb, sb)[0]
        elif states[p] == CONTACT:
            out[p] = 0.0
        else:
            out[p] = -penetration(
                _oriented(ya, sa, fa[p]), sa, _oriented(yb, sb, fb[p]), sb, eps[p]
            )[0]
    return out
