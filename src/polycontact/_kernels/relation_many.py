"""Kernels: classify many pairs at once.

The state kernels are serial: a pair of small bodies takes about a microsecond, too
little for a ``prange`` loop's scheduling per pair; the caller splits the pairs over
threads in chunks instead (the kernels release the GIL), and so for the signed distances;
penetration depths are left to the caller (:func:`polycontact._depth.penetrations`).

A batch of bodies is packed as ``xy`` (V, 2) float64 (every body's loops stacked, body
after body), ``ls`` int64 and ``bs`` int64 (P+1,): the loop starts of body p are
``ls[bs[p]:bs[p + 1]]`` (rows of ``xy``, its last entry is the end of the body), and
``sign`` (P,) float64: +1.0 if the interior is on the left of every edge, -1.0 if on
the right (a clockwise raw ring, classified without a copy).
"""

from __future__ import annotations

import numpy as np

from .jit import njit
from .distance import closest_pair
from .packs import state_scratch
from .primitives import point_segment_sq
from .relation import CONTACT, SEPARATE, state_in
from .rings import pair_tolerance, raw_ring, ring_is_simple_unswept, ring_summary
from .tolerance import extent_magnitude, tolerance_for


@njit(cache=True, nogil=True)
def check_rings(xy, lo, n, rel, ulps, limit, floor):
    """Validate raw rings ``xy[lo[p]:lo[p] + n[p]]``; returns (vertices used or -1, sign).

    ``rel``, ``ulps``, ``limit``, ``floor``: as for
    :func:`polycontact._kernels.rings.raw_ring`."""
    p_count = lo.shape[0]
    used = np.empty(p_count, np.int64)
    sign = np.empty(p_count)
    for p in range(p_count):
        u, s, _, _ = raw_ring(xy[lo[p] : lo[p] + n[p]], rel, ulps, limit, floor)
        used[p] = u
        sign[p] = s
    return used, sign


#: State mark of :func:`_raw_states_into` for a pair with a long ring that only the
#: sweep of :func:`polycontact._kernels.rings.raw_ring` can decide.
_UNDECIDED = -2


@njit(cache=True, nogil=True)
def raw_states_outputs(p_count):
    """Empty arrays for the six results of :func:`raw_states` over ``p_count`` pairs."""
    return (np.empty(p_count, np.int8), np.zeros(p_count), np.empty(p_count, np.int64),
            np.empty(p_count), np.empty(p_count, np.int64), np.empty(p_count))


@njit(cache=True, nogil=True)
def raw_states(xa, xb, tol, rel, ulps, limit, floor, out):
    """Validate and classify P pairs of raw outer rings, ``xa`` (P, N, 2) against
    ``xb`` (P, M, 2), in one pass over the pairs, into ``out``.

    ``out`` is the tuple of arrays ``(states, eps, used_a, sign_a, used_b, sign_b)``
    (P each; int8, float64, int64, float64, int64, float64), written and returned: per
    pair the state (-1 when either ring is not certified valid as given), the tolerance,
    and per ring the vertices used (a repeated closing point dropped; -1 if not
    certified) and the orientation sign (see :func:`polycontact._kernels.rings.raw_ring`). ``tol`` < 0
    means per pair the default tolerance
    (:func:`polycontact._kernels.rings.pair_tolerance` with ``rel`` and ``ulps``);
    ``limit`` and ``floor`` bound the coordinates and extents accepted.

    The pass itself (:func:`_raw_states_into`) allocates nothing; the few pairs it
    leaves undecided (long rings that need a sorted sweep) are finished by
    :func:`_finish_undecided`.
    """
    scratch = state_scratch(xa.shape[1] + xb.shape[1])
    sa = np.zeros(2, np.int64)
    sb = np.zeros(2, np.int64)
    if _raw_states_into(xa, xb, tol, rel, ulps, limit, floor, out, scratch, sa, sb):
        _finish_undecided(xa, xb, tol, rel, ulps, limit, floor, out, scratch, sa, sb)
    return out


@njit(cache=True, nogil=True)
def _finish_undecided(xa, xb, tol, rel, ulps, limit, floor, out, scratch, sa, sb):
    """Validate (with the sorted sweep) and classify the pairs marked ``_UNDECIDED``."""
    states, eps, used_a, sign_a, used_b, sign_b = out
    for p in range(xa.shape[0]):
        if states[p] != _UNDECIDED:
            continue
        na, fa, _, ba = raw_ring(xa[p], rel, ulps, limit, floor)
        nb, fb, _, bb = raw_ring(xb[p], rel, ulps, limit, floor)
        used_a[p] = na
        used_b[p] = nb
        sign_a[p] = fa
        sign_b[p] = fb
        if na < 0 or nb < 0:
            states[p] = -1
            continue
        states[p], eps[p] = _pair_state((xa[p], na, fa, ba), (xb[p], nb, fb, bb), tol, rel,
                                        ulps, sa, sb, scratch)


# Compiled without Numba's reference counting (``_nrt=False``): the pass creates a view
# of every ring and passes arrays down several calls, and the atomic reference-count
# updates of those would cost about as much as classifying a pair of 12-gons. Nothing in
# it may allocate (the compiler refuses if it does).
@njit(cache=True, nogil=True, _nrt=False)
def _raw_states_into(xa, xb, tol, rel, ulps, limit, floor, out, scratch, sa, sb):
    """:func:`raw_states`' pass over the pairs, into its arrays ``out``; a pair with a
    ring that needs the sorted sweep is marked ``_UNDECIDED`` (returns whether any is)."""
    states, eps, used_a, sign_a, used_b, sign_b = out
    undecided = False
    for p in range(xa.shape[0]):
        na, fa, ea, ba = ring_summary(xa[p], rel, ulps, limit, floor)
        nb, fb, eb, bb = ring_summary(xb[p], rel, ulps, limit, floor)
        ka = ring_is_simple_unswept(xa[p], na, ea) if na > 0 else 0
        kb = ring_is_simple_unswept(xb[p], nb, eb) if nb > 0 else 0
        used_a[p] = na if ka != 0 else -1
        used_b[p] = nb if kb != 0 else -1
        sign_a[p] = fa if ka != 0 else 1.0     # as raw_ring gives for an invalid ring
        sign_b[p] = fb if kb != 0 else 1.0
        if ka == 0 or kb == 0:
            states[p] = -1
        elif ka < 0 or kb < 0:
            states[p] = _UNDECIDED
            undecided = True
        else:
            states[p], eps[p] = _pair_state((xa[p], na, fa, ba), (xb[p], nb, fb, bb), tol,
                                            rel, ulps, sa, sb, scratch)
    return undecided


@njit(cache=True, nogil=True)
def _pair_state(ring_a, ring_b, tol, rel, ulps, sa, sb, scratch):
    """``(state, eps)`` of two valid raw rings, each ``(rows, n, sign, box)`` (its rows
    and its :func:`polycontact._kernels.rings.ring_summary` values); ``sa``, ``sb``: two
    loop-start arrays of 2 to write into."""
    ya, na, fa, ba = ring_a
    yb, nb, fb, bb = ring_b
    e = tol if tol >= 0.0 else pair_tolerance(ba, bb, rel, ulps)
    if ba[0] > bb[1] + e or bb[0] > ba[1] + e or ba[2] > bb[3] + e or bb[2] > ba[3] + e:
        return SEPARATE, e  # boxes apart: no call into the state kernel
    sa[1] = na
    sb[1] = nb
    return state_in(ya[:na], sa, fa, yb[:nb], sb, fb, e, scratch), e


@njit(cache=True, nogil=True)
def body(xy, ls, bs, p):
    """``(rows, starts)`` of body ``p`` of a packed batch: its rows of ``xy`` (a view)
    and its loop starts relative to them (a new array)."""
    first = ls[bs[p]]
    starts = ls[bs[p] : bs[p + 1]] - first
    return xy[first : ls[bs[p + 1] - 1]], starts


@njit(cache=True, nogil=True)
def _body_into(xy, ls, bs, p, buf):
    """:func:`body` with the loop starts written into ``buf`` (no allocation)."""
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
def many_states(xa, lsa, bsa, fa, xb, lsb, bsb, fb, tol, rel, ulps):
    """States (int8: 0 separate, 1 contact, 2 penetrating) and tolerances of P pairs.

    ``tol`` < 0 means per pair the default tolerance of the two bodies
    (:func:`polycontact._kernels.tolerance.tolerance_for` of the larger extent and the
    largest |coordinate|, with ``rel`` and ``ulps``).
    """
    p_count = bsa.shape[0] - 1
    states = np.empty(p_count, np.int8)
    eps = np.empty(p_count)
    va, ma = _largest(lsa, bsa)
    vb, mb = _largest(lsb, bsb)
    scratch = state_scratch(va + vb)
    buf_a = np.empty(ma, np.int64)
    buf_b = np.empty(mb, np.int64)
    for p in range(p_count):
        ya, sa = _body_into(xa, lsa, bsa, p, buf_a)
        yb, sb = _body_into(xb, lsb, bsb, p, buf_b)
        if tol >= 0.0:
            e = tol
        else:
            ea, ma = extent_magnitude(ya)
            eb, mb = extent_magnitude(yb)
            e = tolerance_for(max(ea, eb), max(ma, mb), rel, ulps)
        eps[p] = e
        states[p] = state_in(ya, sa, fa[p], yb, sb, fb[p], e, scratch)
    return states, eps


@njit(cache=True, nogil=True)
def oriented(y, s, f):
    """A raw ring's rows with the interior on the left: ``y`` itself when ``f`` > 0,
    else reversed (a copy)."""
    if f > 0.0:
        return y
    return y[::-1].copy()  # raw rings are single loops


#: Up to this many vertices of A times vertices of B, the gap of a separate pair is
#: found by trying every vertex against every edge of the other body, pruned by boxes,
#: with no allocation (for small bodies quicker than :func:`closest_pair`'s sorted
#: sweep, which sorts and allocates); above it, the sweep.
_BRUTE_GAP = 1024


@njit(cache=True, nogil=True)
def _vertices_to_edges(xv, v0, v1, xe, ls, k0, k1, best):
    """Least squared distance, if below ``best``, from the vertices at rows v0:v1 of
    ``xv`` to the edges of the loops k0:k1 of a packed batch (``ls``, rows of ``xe``)."""
    e0 = ls[k0]
    e1 = ls[k1]
    x0 = x1 = xe[e0, 0]
    y0 = y1 = xe[e0, 1]
    for j in range(e0, e1):
        x0 = min(x0, xe[j, 0])
        x1 = max(x1, xe[j, 0])
        y0 = min(y0, xe[j, 1])
        y1 = max(y1, xe[j, 1])
    for i in range(v0, v1):
        px = xv[i, 0]
        py = xv[i, 1]
        # a vertex whose distance to the other body's box is already too large: skip it
        dx = max(x0 - px, px - x1, 0.0)
        dy = max(y0 - py, py - y1, 0.0)
        if dx * dx + dy * dy >= best:
            continue
        for k in range(k0, k1):
            s = ls[k]
            e = ls[k + 1]
            for j in range(s, e):
                j1 = j + 1 if j + 1 < e else s
                ax = xe[j, 0]
                ay = xe[j, 1]
                bx = xe[j1, 0]
                by = xe[j1, 1]
                # the same for the edge's box: skip the projection
                dx = max(min(ax, bx) - px, px - max(ax, bx), 0.0)
                dy = max(min(ay, by) - py, py - max(ay, by), 0.0)
                if dx * dx + dy * dy >= best:
                    continue
                best = min(best, point_segment_sq(px, py, ax, ay, bx, by))
    return best


@njit(cache=True, nogil=True)
def _separate_gap(xa, lsa, bsa, xb, lsb, bsb, p):
    """Boundary gap of separate pair p. Separate boundaries do not cross, so the gap is
    attained at a vertex of one body and an edge of the other; the nearest pair of
    vertices bounds it first, so that most vertices and edges are skipped by their box."""
    a0 = lsa[bsa[p]]
    a1 = lsa[bsa[p + 1] - 1]
    b0 = lsb[bsb[p]]
    b1 = lsb[bsb[p + 1] - 1]
    if (a1 - a0) * (b1 - b0) > _BRUTE_GAP:
        ya, sa = body(xa, lsa, bsa, p)
        yb, sb = body(xb, lsb, bsb, p)
        return closest_pair(ya, sa, yb, sb)[0]
    best = np.inf
    for i in range(a0, a1):
        for j in range(b0, b1):
            dx = xa[i, 0] - xb[j, 0]
            dy = xa[i, 1] - xb[j, 1]
            best = min(best, dx * dx + dy * dy)
    best = _vertices_to_edges(xa, a0, a1, xb, lsb, bsb[p], bsb[p + 1] - 1, best)
    best = _vertices_to_edges(xb, b0, b1, xa, lsa, bsa[p], bsa[p + 1] - 1, best)
    return np.sqrt(best)


@njit(cache=True, nogil=True)
def many_distances(xa, lsa, bsa, fa, xb, lsb, bsb, fb, states, eps):
    """Signed distances of P classified pairs: the boundary gap, or 0; NaN for the
    penetrating pairs, whose depth the caller computes (it needs convex pieces, see
    :func:`polycontact._depth.penetrations`)."""
    p_count = bsa.shape[0] - 1
    out = np.empty(p_count)
    for p in range(p_count):
        if states[p] == SEPARATE:
            out[p] = _separate_gap(xa, lsa, bsa, xb, lsb, bsb, p)
        elif states[p] == CONTACT:
            out[p] = 0.0
        else:
            out[p] = np.nan
    return out
