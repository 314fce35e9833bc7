"""Kernels: time of impact of two rigidly moving polygonal bodies.

Each body is given by its vertices relative to its area centroid ``r`` (packed loops,
see :mod:`polycontact._kernels`), its centroid at t = 0 ``c0`` and its motion vector
``m = [vx, vy, ax, ay, ω, α]``; at time t its vertices are

    x_i(t) = c0 + v t + a t²/2 + R(ω t + α t²/2) r_i.

Both searches visit only the broad-phase intervals (rows of ``intervals``).

Tolerances are local to the time examined (:func:`local_tolerances`): the distance
tolerance follows the bodies' size (``eps_rel``) and the float spacing of their
coordinates at that time (``ulps`` times the largest |coordinate|), the contact
resolution stays well above it, and the time tolerance is never finer than the float
spacing of t (:func:`effective_time_tolerance`). Nothing depends on how far the search
could go (``t_max``).

Status codes returned by the searches (see :class:`polycontact.ImpactStatus`):
0 no penetration in the window, 1 hit, 2 already penetrating at t = 0,
3 iteration budget exhausted (no verdict).
"""

from __future__ import annotations

import numpy as np

from .jit import njit
from .advance import STACK_SIZE, edge_table, line_time, pair_step, window_kinematics
from .broad_phase import BROAD_PHASE_FLOATS, MAX_INTERVALS, overlap_intervals_into
from .packs import scratch_floats, state_scratch_views, vector, view
from .primitives import closest_on_segment, outward_normal
from .relation import state_in


NO_HIT = 0
HIT = 1
INITIALLY_PENETRATING = 2
OUT_OF_ITERATIONS = 3

_PENETRATING = 2

#: The contact resolution is at least this many distance tolerances: the pair steps
#: hold pairs ``PAIR_GAP`` of it apart, and a touching pair's certificate (allowing
#: ``eps`` behind an edge's line) is sound only while ``eps`` is well inside that gap
#: (2 ``eps`` <= ``PAIR_GAP`` · λ): a vertex that slipped ``eps`` past a corner is then
#: still a touching pair of both edges there.
LAM_PER_EPS = 128.0

#: The time tolerance is never below this many units of 2**-52 |t| (the float spacing
#: of t is at most 2**-52 |t|): a probe of half of it moves t by at least one float.
TIME_ULPS = 4.0

_ULP = 2.0**-52
_TINY = 2.2250738585072014e-308


@njit(cache=True, nogil=True)
def effective_time_tolerance(time_tol, t):
    """The time tolerance used at time t: ``time_tol``, or what float64 resolves at t
    (``TIME_ULPS`` · 2**-52 |t|) when that is larger.

    >>> effective_time_tolerance(1e-4, 2.0), effective_time_tolerance(1e-300, 1.0) > 1e-16
    (0.0001, True)
    """
    return max(time_tol, TIME_ULPS * _ULP * abs(t), _TINY)


@njit(cache=True, nogil=True)
def _reach(c0, m, radius, t0, t1):
    """An upper bound of the magnitudes that make a body's coordinates over [t0, t1]:
    for each component the largest |term| sum |c0| + |v| t + |a| t²/2 (t the larger of
    |t0|, |t1|), plus its bounding radius. It bounds every |coordinate|, and also the
    rounding of computing one: a body far from the origin that passes near it has small
    coordinates there, known only to the float spacing of its terms (regression test
    test_impact_oracle::test_tolerance_follows_the_terms_of_a_position_not_the_position)."""
    tt = max(abs(t0), abs(t1))
    out = 0.0
    for k in range(2):
        out = max(out, abs(c0[k]) + abs(m[k]) * tt + 0.5 * abs(m[2 + k]) * tt * tt)
    return out + radius


@njit(cache=True, nogil=True)
def local_tolerances(ca, ma, la, cb, mb, lb, t0, t1, eps_rel, ulps, lam0):
    """``(eps, lam)`` valid over [t0, t1]: the distance tolerance
    ``max(eps_rel, ulps · M)``, M a bound of every |coordinate| of both bodies over the
    window (as :func:`polycontact.tolerances.tolerance_for`), and the contact resolution
    ``max(lam0, LAM_PER_EPS · eps)``.

    >>> import numpy as np
    >>> m = np.zeros(6)
    >>> eps, lam = local_tolerances(np.array([1e9, 0]), m, 1.0, np.array([1e9 + 3, 0]), m,
    ...                             1.0, 0.0, 1.0, 1e-12, 64 * 2.0**-52, 1e-6)
    >>> round(eps / 1e-6, 2), lam == 128 * eps
    (14.21, True)
    """
    mag = max(_reach(ca, ma, la, t0, t1), _reach(cb, mb, lb, t0, t1))
    eps = max(eps_rel, ulps * mag)
    return eps, max(lam0, LAM_PER_EPS * eps)


@njit(cache=True, nogil=True)
def local_end(ca, ma, la, cb, mb, lb, t):
    """The end of the longest window from t over which :func:`local_tolerances` stays
    local to t: no body's :func:`_reach` grows by more than M, the larger reach of the
    two at t, so the distance tolerance over the window is at most twice its value at
    t (t >= 0). Each |term| of a coordinate grows over [t, t + w] by at most
    (|v| + |a| t) w + |a| w²/2 per component. The window spans at least a fixed
    fraction of t (M includes the travel |v| t + |a| t²/2), so windows that keep doubling
    cross any length in a number of steps logarithmic in it.

    >>> import numpy as np
    >>> m = np.array([1.0, 0, 0, 0, 0, 0])
    >>> local_end(np.zeros(2), m, 1.0, np.array([3.0, 0]), np.zeros(6), 1.0, 0.0)
    4.0
    """
    mag = max(_reach(ca, ma, la, t, t), _reach(cb, mb, lb, t, t))
    w = np.inf
    for m in (ma, mb):
        for k in range(2):
            acc = abs(m[2 + k])
            lin = abs(m[k]) + acc * t
            if lin > 0.0 or acc > 0.0:
                den = lin + np.sqrt(lin * lin + 2.0 * acc * mag)
                # (a window past 2**1022 is left unbounded: its quotient nears the float
                # range)
                if den > mag * 2.0**-1021:
                    w = min(w, 2.0 * mag / den)
    return t + w


@njit(cache=True, nogil=True)
def centre(c0, m, t):
    """The centroid ``(cx, cy)`` at time t of a body whose centroid is ``c0`` at t = 0."""
    return c0[0] + m[0] * t + 0.5 * m[2] * t * t, c0[1] + m[1] * t + 0.5 * m[3] * t * t


@njit(cache=True, nogil=True)
def place(r, c0, m, t, out):
    """Write the vertices of the body at time t into ``out`` (same shape as ``r``);
    return the centroid ``(cx, cy)`` at t."""
    th = m[4] * t + 0.5 * m[5] * t * t
    cs = np.cos(th)
    sn = np.sin(th)
    cx, cy = centre(c0, m, t)
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
    kin = window_kinematics(ma, mb, t0, t1)[2]
    return kin[3] + kin[4] * la + kin[5] * lb


@njit(cache=True, nogil=True)
def fixed_relative_pose(ca, ma, la, cb, mb, lb, ulps):
    """Whether B keeps its pose in A's frame over any window (up to the rounding of the
    coordinates): then no motion can bring the bodies closer or apart, and the state at
    t = 0 holds throughout.

    B seen from A is ``R(−θ_A)(c_B − c_A) + R(θ_B − θ_A) r``: constant when the bodies
    turn alike (equal ω and α: the relative rotation is constant), their centroids
    translate alike (equal velocity and acceleration: ``Δ = c_B − c_A`` is constant) and
    either they do not turn or ``R(−θ_A) Δ`` stays put, i.e. they turn about one centre
    (``Δ = 0``; a polynomial ``Δ`` of constant norm is constant, so no other
    translation keeps it). Centroids closer than the rounding of the coordinates
    (``ulps`` times the larger reach at t = 0, the float-spacing term of the distance
    tolerance) count as one centre: B then moves by at most twice that in A's frame,
    less than the rounding of placing either body.

    >>> import numpy as np
    >>> spin = np.array([1.0, 0.0, 0.0, 0.0, 3.0, 0.0])
    >>> c = np.zeros(2)
    >>> fixed_relative_pose(c, spin, 1.0, c, spin.copy(), 2.0, 64 * 2.0**-52)
    True
    >>> fixed_relative_pose(c, spin, 1.0, c + 0.5, spin.copy(), 2.0, 64 * 2.0**-52)
    False
    """
    for k in range(6):
        if ma[k] != mb[k]:
            return False
    if ma[4] == 0.0 and ma[5] == 0.0:
        return True
    gap = np.hypot(cb[0] - ca[0], cb[1] - ca[1])
    reach = max(_reach(ca, ma, la, 0.0, 0.0), _reach(cb, mb, lb, 0.0, 0.0))
    return 2.0 * gap <= ulps * reach


#: The pair steps of :func:`pair_step` stop this fraction of the contact resolution
#: short of contact: the probes that follow (each a classification) then cover a gap
#: of lam / 64 instead of lam.
PAIR_GAP = 1.0 / 64.0

#: A step shorter than this fraction of the one before it (or than the time tolerance)
#: suggests contact is near: the search then classifies the bodies a tolerance after the
#: step's end, which can end it (see :func:`_exact_search`).
GUESS_SHRINK = 0.2

#: After a step h shorter than its window, the next window is this many times h. The
#: window enters the bounds through the largest |ω| and |Δv| over it (with angular or
#: linear acceleration) and the angle turned in it (slide steps), so a shorter window
#: gives tighter bounds; a longer one lets a step run further.
WINDOW_GROWTH = 3.0


@njit(cache=True, nogil=True)
def slide_time(v, e, j, kin, eps, h, need, first):
    """A time in [0, h] (0 as soon as it is known to be below ``need``; V's vertex
    ``first``, the touching one, is looked at before the rest) during which the
    interiors of V and E cannot come to overlap by more than 2 ``eps``, certified by the
    line of E's edge j turning with E; 0 when the line does not separate them. Each body
    is placed at the window's start, ``(x, c, m, r_len, nxt, radius)``: its vertices, its
    centroid, its ``(vx, vy, ω)`` now, its vertices' distances from the centroid, the
    next vertex of each, its bounding radius. ``kin`` is the window tuple of V's vertices
    against E's edges (:func:`polycontact._kernels.advance.window_kinematics`).

    This is what lets a sliding contact (paper Fig. 16) be followed by long steps past
    corners: with n the outward normal of edge j and σ(x) = (x − x_j)·n, E lies in
    {σ <= eps} at all times if all its vertices do now (the line turns with E). Each
    edge of V is charged the time during which either both its ends keep
    σ >= −eps — each end by the second-order bound towards the turning line
    (:func:`polycontact._kernels.advance.line_time`), and a segment lies on the side
    of its ends — or it stays outside E's bounding circle (its distance from E's
    centroid shrinks no faster than V + W_v max |r|, as in the pair bounds). Until the
    shortest of these times no edge of V meets W = {σ < −eps} ∩ (open circle), a convex
    set that moves with E and holds the points of E's interior deeper than eps behind
    the line. Such a point is outside V now (the bodies do not penetrate) and never
    crosses V's boundary, so it stays outside V; hence W ∩ V stays empty (W is
    connected) and any overlap of the interiors lies in the band |σ| <= eps.
    """
    xv, _, _, rv_len, nxt_v, _ = v
    xe, ce, _, _, nxt_e, le = e
    j1 = nxt_e[j]
    ax = xe[j, 0]
    ay = xe[j, 1]
    bx = xe[j1, 0]
    by = xe[j1, 1]
    ln, nx, ny = outward_normal(ax, ay, bx, by)
    if ln == 0.0:
        return 0.0
    for k in range(xe.shape[0]):
        if (xe[k, 0] - ax) * nx + (xe[k, 1] - ay) * ny > eps:
            return 0.0
    # inside E's circle the touching vertex's edges can only be charged by their ends
    px = xv[first, 0]
    py = xv[first, 1]
    if (px - ce[0]) ** 2 + (py - ce[1]) ** 2 <= le * le and _end_time(
            v, first, ax, ay, bx, by, e, kin, eps, need) < need:
        return 0.0
    best = h
    for k in range(xv.shape[0]):
        k1 = nxt_v[k]
        t_edge = min(_end_time(v, k, ax, ay, bx, by, e, kin, eps, best),
                     _end_time(v, k1, ax, ay, bx, by, e, kin, eps, best))
        if t_edge < best:
            gap = np.sqrt(closest_on_segment(ce[0], ce[1], xv[k, 0], xv[k, 1], xv[k1, 0],
                                              xv[k1, 1])[2]) - le
            if gap > 0.0:
                rate = kin[3] + kin[4] * max(rv_len[k], rv_len[k1])
                t_edge = max(t_edge, gap / rate if gap < rate * best else best)
            best = min(best, t_edge)
            if best < need:
                return 0.0
    return best


@njit(cache=True, nogil=True)
def _end_time(v, m, ax, ay, bx, by, e, kin, eps, cap):
    """How long V's vertex m keeps σ >= −eps for the line of ab turning with E
    (:func:`polycontact._kernels.advance.line_time`), up to ``cap`` (``v``, ``e``: as
    for :func:`slide_time`)."""
    xv, cv, mv, rv_len, _, _ = v
    ce, me = e[1], e[2]
    x = xv[m, 0]
    y = xv[m, 1]
    return line_time((x, y, mv[0] - mv[2] * (y - cv[1]), mv[1] + mv[2] * (x - cv[0]), rv_len[m]),
                     ax, ay, bx, by, (ce[0], ce[1], me[0], me[1], me[2]), kin, -eps, cap)


@njit(cache=True, nogil=True)
def _slide_step(pa, pb, ma, mb, t0, t1, crit, eps, need):
    """The longest :func:`slide_time` over [t0, t1] by the lines through the pair
    ``crit`` (vertex i of one body, edge j of the other): edge j, or either edge of the
    vertex body at i (with the bodies' roles swapped); 0 if none reaches ``need``.
    ``pa``, ``pb``: each body placed at t0, ``(x, c, r_len, nxt, radius)``."""
    mva, mvb, kin_ab, kin_ba = window_kinematics(ma, mb, t0, t1)
    xa, ca, ra_len, nxa, la = pa
    xb, cb, rb_len, nxb, lb = pb
    va = (xa, ca, mva, ra_len, nxa, la)
    vb = (xb, cb, mvb, rb_len, nxb, lb)
    h = t1 - t0
    i = crit[1]
    j = crit[2]
    if crit[0] == 0:
        best = slide_time(va, vb, j, kin_ab, eps, h, need, i)
        for e in range(nxa.shape[0]):
            if best == 0.0 and (e == i or nxa[e] == i):
                best = slide_time(vb, va, e, kin_ba, eps, h, need, j)
        return best
    best = slide_time(vb, va, j, kin_ba, eps, h, need, i)
    for e in range(nxb.shape[0]):
        if best == 0.0 and (e == i or nxb[e] == i):
            best = slide_time(va, vb, e, kin_ab, eps, h, need, j)
    return best


@njit(cache=True, nogil=True)
def state_at(a, ma, b, mb, t, eps, placed):
    """The state of the two bodies placed at time t: ``a``, ``b`` as for
    :func:`exact_search`; ``placed`` = ``(xa, xb, scratch)`` is where they are placed and
    the state kernel's scratch (:func:`polycontact._kernels.packs.state_scratch`)."""
    xa, xb, scratch = placed
    place(a[0], a[2], ma, t, xa)
    place(b[0], b[2], mb, t, xb)
    return state_in(xa, a[1], 1.0, xb, b[1], 1.0, eps, scratch)


@njit(cache=True, nogil=True)
def work_floats(size):
    """Length of the float64 scratch ``work`` of :func:`exact_query` and
    :func:`sampled_query` for two bodies of ``size`` vertices in all (see
    :func:`_work_views`).

    >>> work_floats(16)
    923
    """
    return (2 * MAX_INTERVALS + BROAD_PHASE_FLOATS + 4 + 3 * STACK_SIZE + 4 + 2 * size
            + scratch_floats(size))


@njit(cache=True, nogil=True, inline="always")
def _interval_views(work):
    """The broad-phase intervals (MAX_INTERVALS, 2) and the broad phase's scratch, the
    first floats of ``work`` (see :func:`_work_views`)."""
    k = 2 * MAX_INTERVALS
    return view(work, 0, MAX_INTERVALS, 2, np.float64), work[k:k + BROAD_PHASE_FLOATS]


@njit(cache=True, nogil=True, inline="always")
def _work_views(work, na, nb):
    """The buffers of a query on bodies of ``na`` and ``nb`` vertices as views of
    ``work`` (at least :func:`work_floats` (na + nb) floats; a shorter one raises):
    ``(intervals (MAX_INTERVALS, 2), broad-phase scratch, placed, stepping)`` with
    ``placed`` = ``(xa (na, 2), xb (nb, 2), state scratch)`` (see :func:`state_at`) and
    ``stepping`` = ``(pa, pb, crit (3, int64), (stack (STACK_SIZE, 2, int64), stau))``:
    the centroids, the critical pair and the traversal stack of
    :func:`polycontact._kernels.advance.pair_step`. ``crit`` is set to −1 (what
    :func:`polycontact._kernels.advance.pair_step` expects before the first step)."""
    size = na + nb
    if work.shape[0] < work_floats(size):
        raise ValueError("time of impact: the scratch buffer is too short for the bodies")
    iv, bw = _interval_views(work)
    k = 2 * MAX_INTERVALS + BROAD_PHASE_FLOATS
    pa = work[k:k + 2]
    pb = work[k + 2:k + 4]
    crit = vector(work, k + 4, 3, np.int64)  # (4 floats: crit, with a spare)
    crit[:] = -1
    stack = view(work, k + 8, STACK_SIZE, 2, np.int64)
    k += 8 + 2 * STACK_SIZE
    stau = work[k:k + STACK_SIZE]
    k += STACK_SIZE
    xa = view(work, k, na, 2, np.float64)
    xb = view(work, k + 2 * na, nb, 2, np.float64)
    k += 2 * size
    placed = (xa, xb, state_scratch_views(work[k:k + scratch_floats(size)], size))
    return iv, bw, placed, (pa, pb, crit, (stack, stau))


@njit(cache=True, nogil=True)
def exact_search(a, ma, b, mb, intervals, search):
    """Continuous search for the first penetration (conservative advancement).

    ``a`` is the body A, ``(r, starts, c0, radius)``: its vertices relative to its area
    centroid (packed loops), its centroid at t = 0 and its bounding radius; ``ma`` its
    motion vector ``[vx, vy, ax, ay, ω, α]`` (likewise B). ``intervals`` (k, 2): the
    broad-phase intervals searched. ``search`` is ``(time_tol, eps_rel, ulps, lam,
    max_iter)``: the time tolerance, the terms of the distance tolerance, the contact
    resolution asked for, the iteration budget.

    Returns ``(status, t_hi, t_lo, first_contact, iterations, t_reached)``: on a hit the
    bodies penetrate at ``t_hi`` and do not at ``t_lo`` (``t_hi − t_lo`` below the
    effective time tolerance at ``t_hi``, :func:`effective_time_tolerance`; no
    penetration begins before ``t_lo``); ``first_contact`` is the first visited time
    with boundary distance <= the contact resolution (−1 if none); ``t_reached`` is
    how far the search got.

    The distance tolerance and the contact resolution are local (:func:`local_tolerances`
    from ``eps_rel``, ``ulps`` and ``lam``, the resolution asked for, over windows that
    end where the reach at most doubles, :func:`local_end`, whatever the length of the
    broad-phase interval: a window as long as ``t_max`` would scale them by it); the
    resolution also covers the float spacing of t: a probe moves t by at least a float,
    so λ is at least S · ``TIME_ULPS`` · 2**-52 |t|.

    Invariant: no penetration has been skipped before ``t`` (see
    :func:`polycontact.time_of_impact` for the argument). From a non-penetrating time
    t with boundary distance d and speed bound S over a window [t, t + H]:

    - :func:`pair_step` gives a step h <= H during which no vertex–edge pair can
      meet (second-order bounds, see :mod:`polycontact._kernels.advance`), so the
      boundaries cannot meet and no penetration can start. After a step shorter than
      the time tolerance or than ``GUESS_SHRINK`` times the one before, the bodies are
      classified at ``t + h + 0.99 tol``: penetrating there is the hit, bracketed
      by (t + h, that time). If h is at least the probe
      length ``tau = lam / S`` it is taken. The pairs are held
      ``lam`` apart until the first contact (so that the first time found within
      ``lam`` is at most a probe late) and ``PAIR_GAP · lam`` apart after it, which
      leaves fewer probes to the hit: where the step to ``lam`` is shorter than tau
      before the first contact, the step to ``PAIR_GAP · lam`` (at most ``tau``) is
      taken instead;
    - otherwise the step is ``tau``: a penetration that begins and ends inside it has
      no point moving more than ``lam`` relative to the other body (it is shallower
      than ``lam``); any other penetration is still penetrating at ``t + tau``.

    - after the first contact the steps hold touching pairs to their edges' turning
      lines (``touch = eps`` in :func:`pair_step`: no penetration beyond ``eps``
      begins), and before probing :func:`_slide_step` tries the lines through the
      touching pair as separators (the bodies stay on either side of a line turning
      with one of them, up to ``eps``), so a sliding contact is followed by long
      steps, not by probes.

    A penetrating state at the end of a probe is the hit: the probe brackets it, and
    bisection (:func:`_narrow`) narrows the bracket to the time tolerance. The time
    tolerance thus decides how precisely ``t_hi`` is reported, never whether a hit is
    found, nor how many probes are taken.
    """
    return exact_search_tables(a, edge_table(a[0], a[1]), ma, b, edge_table(b[0], b[1]), mb,
                               intervals, search)


@njit(cache=True, nogil=True)
def exact_search_tables(a, ea, ma, b, eb, mb, intervals, search):
    """:func:`exact_search` with each body's :func:`polycontact._kernels.advance.edge_table`
    given (``ea``, ``eb``: built once per shape by the caller)."""
    _, _, placed, stepping = _work_views(np.empty(work_floats(a[0].shape[0] + b[0].shape[0])),
                                         a[0].shape[0], b[0].shape[0])
    return _exact_search(a, ea, ma, b, eb, mb, intervals, search, placed, stepping, False)


# The searches run without Numba's reference counting (``_nrt=False``): each step passes
# a dozen arrays down several calls, and their atomic reference counts cost as much as
# the geometry of a small pair. Nothing in them may allocate (the compiler refuses if it
# does): their callers pass every buffer in.
@njit(cache=True, nogil=True, _nrt=False)
def _exact_search(a, ea, ma, b, eb, mb, intervals, search, placed, stepping,
                  apart_at_start):
    """:func:`exact_search` with its buffers passed in (``ea``, ``eb``: the
    :func:`polycontact._kernels.advance.edge_table` of each body; ``placed``,
    ``stepping``: see :func:`_work_views`). The bodies are placed only to be classified
    or for a slide: the steps read each vertex they need from the body frame. With
    ``apart_at_start`` the caller has classified the bodies at t = 0 (they do not
    penetrate there), and they are not classified there again."""
    time_tol, eps_rel, ulps, lam0, max_iter = search
    ra, sa, ca, la = a
    rb, sb, cb, lb = b
    pa, pb, crit, traversal = stepping
    xa, xb, _ = placed
    first_contact = -1.0
    t_guess = -1.0
    h_prev = np.inf
    it = 0
    t = 0.0
    # B fixed in A's frame (identical motions, or a common spin about one centre): the
    # relative speed is zero, however fast each body moves, and the state at t = 0
    # holds over every interval
    still = fixed_relative_pose(ca, ma, la, cb, mb, lb, ulps)
    for k in range(intervals.shape[0]):
        t1 = intervals[k, 0]
        t2 = intervals[k, 1]
        t = t1
        pa[0], pa[1] = centre(ca, ma, t)
        pb[0], pb[1] = centre(cb, mb, t)
        # after t = 0 an interval opens with the bounding circles just touching: apart
        if t == 0.0 and not apart_at_start and state_at(a, ma, b, mb, t,
                                 tolerance_at(ca, ma, la, cb, mb, lb, t, eps_rel, ulps),
                                 placed) == _PENETRATING:
            return INITIALLY_PENETRATING, 0.0, 0.0, 0.0, it, 0.0
        window = t2 - t
        while True:
            it += 1
            if it > max_iter:
                return OUT_OF_ITERATIONS, -1.0, -1.0, first_contact, it, t
            # (never past where the tolerances would stop being those of t)
            t_end = min(t2, t + window, local_end(ca, ma, la, cb, mb, lb, t))
            s = 0.0 if still else speed_bound(ma, la, mb, lb, t, t_end)
            tol = effective_time_tolerance(time_tol, t)
            # tolerances local to the window; a probe moves t by at least a float, which
            # moves the points by up to s times that: the resolution covers it
            eps, lam = local_tolerances(ca, ma, la, cb, mb, lb, t, t_end, eps_rel, ulps, lam0)
            lam = max(lam, TIME_ULPS * _ULP * abs(t) * s)
            lam_pair = PAIR_GAP * lam
            # until the first contact the pairs are stepped to lam, so that the first
            # time found within lam is at most a probe late; then closer
            # once touching, a touching pair is held to its edge's line instead (a slide
            # is stepped over, see pair_step)
            d, h = pair_step((ra, ea), pa, ma, (rb, eb), pb, mb, (t, t_end),
                             (lam, lam if first_contact < 0.0 else lam_pair,
                              0.0 if first_contact < 0.0 else eps), crit, traversal)
            if d <= lam and first_contact < 0.0:
                first_contact = t
            if t >= t2 or s <= 0.0:
                break  # at the end, or no relative motion: the state at t holds to t2
            if (h < tol or h < GUESS_SHRINK * h_prev) and t + h >= t_guess:
                # no contact before t + h: a penetration (just under) a tolerance later
                # brackets the first one in (t + h, t_guess], as finely as asked. Worth a
                # classification when the step is short or shrinking fast (the pair
                # bounds converge quadratically near contact), once per guess.
                t_guess = min(t + h + 0.99 * effective_time_tolerance(time_tol, t + h), t2)
                if state_at(a, ma, b, mb, t_guess,
                            tolerance_at(ca, ma, la, cb, mb, lb, t_guess, eps_rel, ulps),
                            placed) == _PENETRATING:
                    return HIT, t_guess, t + h, first_contact if first_contact >= 0.0 else t + h, \
                        it, t_guess
            h_prev = h
            # the probe length follows the resolution, not the time tolerance: a
            # penetrating probe end is narrowed to the tolerance by bisection
            tau = min(lam / s, t_end - t)
            if h < tau and first_contact < 0.0:
                # about to touch: step the pairs to lam_pair instead, at most a probe
                # at a time (so the first contact found is no later)
                h = min(pair_step((ra, ea), pa, ma, (rb, eb), pb, mb, (t, t_end),
                                  (lam, lam_pair, 0.0), crit, traversal)[1], tau)
            if h < tau and first_contact >= 0.0 and crit[0] >= 0:
                # touching: a line through the touching features may separate them
                place(ra, ca, ma, t, xa)
                place(rb, cb, mb, t, xb)
                h = max(h, _slide_step((xa, pa, ea[3], ea[0], la), (xb, pb, eb[3], eb[0], lb),
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
                pa[0], pa[1] = centre(ca, ma, t)
                pb[0], pb[1] = centre(cb, mb, t)
                continue
            pa[0], pa[1] = centre(ca, ma, t_new)
            pb[0], pb[1] = centre(cb, mb, t_new)
            if state_at(a, ma, b, mb, t_new,
                        tolerance_at(ca, ma, la, cb, mb, lb, t_new, eps_rel, ulps),
                        placed) == _PENETRATING:
                # the probe brackets the first penetration (no point moved more than
                # lam in it); narrowed to the time tolerance by bisection
                if first_contact < 0.0 or first_contact > t:
                    first_contact = t
                lo, hi, it = _narrow(a, ma, b, mb, t, t_new, (time_tol, eps_rel, ulps), it,
                                     placed)
                return HIT, hi, lo, first_contact, it, hi
            t = t_new
    return NO_HIT, -1.0, -1.0, first_contact, it, t


@njit(cache=True, nogil=True, _nrt=False)
def _narrow(a, ma, b, mb, lo, hi, tols, it, placed):
    """Bisect [lo, hi] (no penetration at lo, penetration at hi) until it is no longer
    than the effective time tolerance at hi; ``(lo, hi, it)``, each classification
    counted in ``it``. ``tols``: ``(time_tol, eps_rel, ulps)``."""
    time_tol, eps_rel, ulps = tols
    ca, la = a[2], a[3]
    cb, lb = b[2], b[3]
    while hi - lo > effective_time_tolerance(time_tol, hi):
        mid = 0.5 * (lo + hi)
        if mid <= lo or mid >= hi:
            break
        it += 1
        if state_at(a, ma, b, mb, mid, tolerance_at(ca, ma, la, cb, mb, lb, mid, eps_rel, ulps),
                    placed) == _PENETRATING:
            hi = mid
        else:
            lo = mid
    return lo, hi, it


@njit(cache=True, nogil=True)
def tolerance_at(ca, ma, la, cb, mb, lb, t, eps_rel, ulps):
    """The distance tolerance at time t (:func:`local_tolerances` on [t, t])."""
    return max(eps_rel, ulps * max(_reach(ca, ma, la, t, t), _reach(cb, mb, lb, t, t)))


@njit(cache=True, nogil=True)
def sampled_search(a, ma, b, mb, intervals, threshold, n, eps_rel, ulps, max_iter):
    """The paper's §3 steps 3–6 on each interval, literally (``a``, ``ma``, ``b``,
    ``mb``, ``intervals``: as for :func:`exact_search`), at most ``max_iter``
    classifications.

    n time points t_1 = T1, ..., t_n = T2 (spacing (T2 − T1)/(n − 1)); t0 is the first
    penetrating one; the next interval is [t0 − (T2 − T1)/n, t0]; stop when
    T2 − T1 < threshold (or the interval is a single float) and report T2. Each sample
    is classified with the distance tolerance at its time (:func:`local_tolerances`).
    Returns ``(status, t_hi, t_lo, first_contact, evaluations)``; ``first_contact`` is
    the earliest sample in contact (−1 if none); the status is ``OUT_OF_ITERATIONS``
    (no verdict, ``t_lo`` the sample it stopped at) when the budget is spent first.
    """
    _, _, placed, _ = _work_views(np.empty(work_floats(a[0].shape[0] + b[0].shape[0])),
                                  a[0].shape[0], b[0].shape[0])
    return _sampled_search(a, ma, b, mb, intervals, threshold, n, eps_rel, ulps, max_iter,
                           placed)


@njit(cache=True, nogil=True, _nrt=False)
def _sampled_search(a, ma, b, mb, intervals, threshold, n, eps_rel, ulps, max_iter, placed):
    """:func:`sampled_search` with its buffers passed in (see :func:`_exact_search`)."""
    ca, la = a[2], a[3]
    cb, lb = b[2], b[3]
    first_contact = -1.0
    evals = 0
    for k in range(intervals.shape[0]):
        lo = intervals[k, 0]
        hi = intervals[k, 1]
        if lo == 0.0:
            evals += 1
            if state_at(a, ma, b, mb, 0.0,
                        tolerance_at(ca, ma, la, cb, mb, lb, 0.0, eps_rel, ulps),
                        placed) == _PENETRATING:
                return INITIALLY_PENETRATING, 0.0, 0.0, 0.0, evals
        found = False
        while True:
            t0 = -1.0
            for i in range(n):
                t = hi if i == n - 1 else lo + i * (hi - lo) / (n - 1)
                evals += 1
                if evals > max_iter:
                    # (the samples before t were classified: t is how far it got)
                    return OUT_OF_ITERATIONS, -1.0, t, first_contact, evals
                st = state_at(a, ma, b, mb, t,
                              tolerance_at(ca, ma, la, cb, mb, lb, t, eps_rel, ulps), placed)
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
            if hi - lo < threshold or hi - lo <= TIME_ULPS * _ULP * hi:
                break
        if found:
            return HIT, hi, lo, first_contact, evals
    return NO_HIT, -1.0, -1.0, first_contact, evals


@njit(cache=True, nogil=True)
def exact_query(a, ea, ma, b, eb, mb, query, work):
    """Broad phase and :func:`exact_search` in one call (one dispatch from Python), with
    each body's :func:`polycontact._kernels.advance.edge_table` given and every buffer a
    view of ``work`` (at least :func:`work_floats` of both bodies' vertices; nothing is
    allocated).

    ``query`` is ``(t_max, inflate, time_tol, eps_rel, ulps, lam, max_iter, samples)``:
    the window [0, t_max], the broad phase's relative inflation of the radii, the time
    tolerance, the terms of the distance tolerance, the contact resolution and the
    iteration budget of the search, the samples of the sampled one (unused here).
    Returns ``(n, status, t_hi, t_lo, first_contact, iterations, t_reached)``, the n
    broad-phase intervals in ``work[:2 n]`` as (start, end) pairs."""
    n = query_intervals(a[2], ma, a[3], b[2], mb, b[3], query[0], query[1], work)
    return (n,) + query_search(a, ea, ma, b, eb, mb, n, query, work, False)


@njit(cache=True, nogil=True)
def query_intervals(ca, ma, la, cb, mb, lb, t_max, inflate, work):
    """The broad phase of :func:`exact_query`: the intervals of [0, ``t_max``] over
    which the bounding circles (centres ``ca``, ``cb`` at t = 0, radii ``la``, ``lb``)
    overlap, written into ``work[:2 n]`` as (start, end) pairs; returns n.

    >>> import numpy as np
    >>> still, work = np.zeros(6), np.empty(work_floats(8))
    >>> query_intervals(np.zeros(2), still, 1.0, np.array([1.5, 0.0]), still, 1.0, 2.0, 0.0,
    ...                 work), work[:2].tolist()
    (1, [0.0, 2.0])
    """
    iv, bw = _interval_views(work)
    return overlap_intervals_into(ca, ma, la, cb, mb, lb, t_max, inflate, iv, bw)


@njit(cache=True, nogil=True)
def query_search(a, ea, ma, b, eb, mb, n, query, work, apart_at_start):
    """The search of :func:`exact_query` over the n intervals that
    :func:`query_intervals` wrote into ``work``: ``(status, t_hi, t_lo, first_contact,
    iterations, t_reached)``. With ``apart_at_start`` the caller has classified the
    bodies at t = 0 (they do not penetrate there) and the search does not classify them
    there again."""
    _, _, time_tol, eps_rel, ulps, lam, max_iter, _ = query
    iv, _, placed, stepping = _work_views(work, a[0].shape[0], b[0].shape[0])
    return _exact_search(a, ea, ma, b, eb, mb, iv[:n], (time_tol, eps_rel, ulps, lam, max_iter),
                         placed, stepping, apart_at_start)


@njit(cache=True, nogil=True)
def pack_body(r, starts, centroid, radius, table):
    """One body's arguments of :func:`exact_query` in two arrays, for
    :func:`exact_call`: floats ``[cx, cy, radius, r (n, 2), circles (m, 4), r_len (n)]``
    and ints ``[n, len(starts), m, starts, nxt (n), links (m, 3)]`` (``table``: the
    body's :func:`polycontact._kernels.advance.edge_table`, m nodes). Passing two arrays
    instead of eight costs a call from Python less unboxing.

    >>> import numpy as np
    >>> sq = np.array([[-1.0, -1], [1, -1], [1, 1], [-1, 1]])
    >>> st = np.array([0, 4])
    >>> f, i = pack_body(sq, st, np.zeros(2), 1.5, edge_table(sq, st))
    >>> f.shape, i[:5].tolist()
    ((43,), [4, 2, 7, 0, 4])
    """
    nxt, links, circles, r_len = table
    n = r.shape[0]
    k = starts.shape[0]
    m = links.shape[0]
    f = np.empty(3 + 3 * n + 4 * m)
    f[0] = centroid[0]
    f[1] = centroid[1]
    f[2] = radius
    f[3:3 + 2 * n] = r.ravel()
    f[3 + 2 * n:3 + 2 * n + 4 * m] = circles.ravel()
    f[3 + 2 * n + 4 * m:] = r_len
    i = np.empty(3 + k + n + 3 * m, np.int64)
    i[0] = n
    i[1] = k
    i[2] = m
    i[3:3 + k] = starts
    i[3 + k:3 + k + n] = nxt
    i[3 + k + n:] = links.ravel()
    return f, i


@njit(cache=True, nogil=True, inline="always")
def unpack_body(f, i):
    """``(body, table)`` of a :func:`pack_body`, as views: ``body`` = ``(r, starts,
    centroid, radius)`` (see :func:`exact_search`), ``table`` its
    :func:`polycontact._kernels.advance.edge_table`."""
    n = i[0]
    k = i[1]
    m = i[2]
    table = (i[3 + k:3 + k + n], view(i, 3 + k + n, m, 3, np.int64),
             view(f, 3 + 2 * n, m, 4, np.float64), f[3 + 2 * n + 4 * m:3 + 3 * n + 4 * m])
    return (view(f, 3, n, 2, np.float64), i[3:3 + k], f[:2], f[2]), table


# The one kernel that takes its settings as plain numbers rather than as a record: it is
# the call from Python, where unboxing a nested tuple costs more than seven numbers.
@njit(cache=True, nogil=True)
def exact_call(fa, ia, ma, fb, ib, mb, t_max, inflate, time_tol, eps_rel, ulps, lam, max_iter,
               work):
    """:func:`exact_query` with each body given as its :func:`pack_body` (the call
    ``polycontact.time_of_impact`` makes) and the query's settings one by one (as in
    :func:`exact_query`'s record)."""
    a, ea = unpack_body(fa, ia)
    b, eb = unpack_body(fb, ib)
    return exact_query(a, ea, ma, b, eb, mb,
                       (t_max, inflate, time_tol, eps_rel, ulps, lam, max_iter, 0), work)


@njit(cache=True, nogil=True)
def sampled_query(a, ma, b, mb, query, work):
    """Broad phase and :func:`sampled_search` with ``samples`` points in one call (``a``,
    ``ma``, ``b``, ``mb``: as for :func:`exact_search`; ``query``: as for
    :func:`exact_query`, its ``max_iter`` the budget of classifications); returns
    what :func:`exact_query` does (``iterations``: the classifications;
    ``t_reached``: t_hi on a hit, the sample it stopped at when out of iterations, else
    t_max), with its buffers in ``work`` as there."""
    t_max, inflate, time_tol, eps_rel, ulps, _, max_iter, samples = query
    ra, _, ca, la = a
    rb, _, cb, lb = b
    iv, bw, placed, _ = _work_views(work, ra.shape[0], rb.shape[0])
    n = overlap_intervals_into(ca, ma, la, cb, mb, lb, t_max, inflate, iv, bw)
    code, hi, lo, contact, its = _sampled_search(a, ma, b, mb, iv[:n], time_tol, samples,
                                                 eps_rel, ulps, max_iter, placed)
    reached = hi if code == HIT else (lo if code == OUT_OF_ITERATIONS else t_max)
    return n, code, hi, lo, contact, its, reached
