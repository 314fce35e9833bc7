"""Kernels: a World's swept step — which pairs meet while every body moves, and where.

Each body of the World moves rigidly about its centroid (design.md §3) from its current
pose: ``x(t) = c(t) + R(θ(t)) r`` with ``r`` its rows relative to its centroid turned by
its current angle (``r = R(angle)(bxy − cen)``, so that ``pos + r`` are the stored rows:
to the bit for a body given a pose, within the rounding of its coordinates for one
added as it was). The candidate pairs come from the swept broad phase of
:func:`polycontact.first_impacts` (:mod:`polycontact._kernels.swept`), and each pair runs
the search of :mod:`polycontact._kernels.impact` as :func:`polycontact.time_of_impact`
does (``exact_query``, in its two steps :func:`~polycontact._kernels.impact.query_intervals`
and :func:`~polycontact._kernels.impact.query_search`).

The circle tree of each body's edges (:func:`polycontact._kernels.advance.edge_table`)
is built once, about the body's base rows (:func:`frame_tables`), and turned with the
body at each step, once per step for all the pairs it is in (:func:`turned_frames`): a
rigid turn moves the smallest circles with the points they hold (their radii keep
their relative margin of 1e-12 over the rounding of the turn). A pair whose bounding
circles overlap at the start is classified there once, as the bodies stand (the bodies
at t = 0 are their stored rows): if it penetrates it is reported as ``exact_query``
reports it, without turning anything; if not, the search starts from there without
classifying it again. A pair whose bodies the line of their centres at t = 0 keeps
apart over the whole step, each body's reach along it taken over its turn, beyond the
tolerance and the contact resolution (:func:`_axis_apart`), is not searched: the search
would report nothing.

At the first contact time of a pair (time 0 when it touches or penetrates at the
start), both bodies are placed and classified (a pair found penetrating at the start is
not classified again), and the contact's point and normal are those of
:func:`polycontact._kernels.contact_geometry.pair_geometry_into` in that state.
"""

from __future__ import annotations

import math

import numpy as np
from numba import prange

from .jit import njit
from .advance import edge_table_into, table_scratch
from .contact_geometry import geometry_buffers, geometry_into, grown_buffers
from .impact import HIT, INITIALLY_PENETRATING, LAM_PER_EPS, place, query_intervals, \
    query_search, state_at, tolerance_at, work_floats
from .packs import scratch_floats, state_scratch_views, vector, view
from .relation import PENETRATING, state_in
from .spread import SPREAD, block
from .world import body_view, circles_apart, circles_reach, rounding_allowance


@njit(cache=True, nogil=True, parallel=True)
def motion_maxima(motion, pos, rad, chunks):
    """Upper bounds, over the bodies, of each term of the sweep's motion bounds:
    ``(speed, acceleration, |ω|, |α|, radius, reach)``, from each body's kernel vector
    ``motion`` (rows ``vx, vy, ax, ay, ω, α``), centroid ``pos`` and bounding radius
    ``rad``. The speed and the acceleration are bounded by ``|x| + |y|`` of their
    vectors (never below their length, however a library rounds ``hypot``), the rest are
    the largest values; ``reach`` is the larger |coordinate| of the centroid plus the
    radius. In parallel chunks (``chunks`` = 1: serial).

    >>> motion_maxima(np.array([[3.0, 4, 0, 0, -2, 0], [1, 0, 0, 1, 0, 0.5]]),
    ...               np.array([[0.0, -7], [1, 1]]), np.array([1.0, 2.0]), 1).tolist()
    [7.0, 1.0, 2.0, 0.5, 2.0, 8.0]
    """
    n = motion.shape[0]
    part = np.zeros((chunks, 6))
    for c in prange(chunks):
        for k in range(n * c // chunks, n * (c + 1) // chunks):
            part[c, 0] = max(part[c, 0], abs(motion[k, 0]) + abs(motion[k, 1]))
            part[c, 1] = max(part[c, 1], abs(motion[k, 2]) + abs(motion[k, 3]))
            part[c, 2] = max(part[c, 2], abs(motion[k, 4]))
            part[c, 3] = max(part[c, 3], abs(motion[k, 5]))
            part[c, 4] = max(part[c, 4], rad[k])
            part[c, 5] = max(part[c, 5], max(abs(pos[k, 0]), abs(pos[k, 1])) + rad[k])
    out = np.zeros(6)
    for c in range(chunks):
        for q in range(6):
            out[q] = max(out[q], part[c, q])
    return out


@njit(cache=True, nogil=True)
def frame_tables(base, bodies, tables):
    """Build the circle tree of each body of ``bodies`` about its base rows (``base`` =
    ``(bxy, ls, lo, nl, cen)``: the rows as added, packed as the World's, and each
    body's centroid) into ``tables`` = ``(tint, tflt, tio, tfo)``: ``tint`` (``nxt``
    then ``links``) from ``tio[b]`` and ``tflt`` (``circles``) from ``tfo[b]``, offsets
    set by the caller (n vertices: n + 3 (2n − 1) ints, 4 (2n − 1) floats)."""
    bxy, ls, lo, nl, cen = base
    tint, tflt, tio, tfo = tables
    widest = 1
    loops = 1
    for k in range(bodies.shape[0]):
        b = bodies[k]
        widest = max(widest, ls[lo[b] + nl[b]] - ls[lo[b]])
        loops = max(loops, nl[b])
    r_buf = np.empty((widest, 2))
    st_buf = np.empty(loops + 1, np.int64)
    r_len = np.empty(widest)
    scratch = table_scratch(widest)
    for k in range(bodies.shape[0]):
        b = bodies[k]
        f = ls[lo[b]]
        n = ls[lo[b] + nl[b]] - f
        r = r_buf[:n]
        for i in range(n):
            r[i, 0] = bxy[f + i, 0] - cen[b, 0]
            r[i, 1] = bxy[f + i, 1] - cen[b, 1]
        for q in range(nl[b] + 1):
            st_buf[q] = ls[lo[b] + q] - f
        m = 2 * n - 1
        io = tio[b]
        table = (vector(tint, io, n, np.int64), view(tint, io + n, m, 3, np.int64),
                 view(tflt, tfo[b], m, 4, np.float64), r_len[:n])
        edge_table_into(r, st_buf[:nl[b] + 1], table, scratch)


@njit(cache=True, nogil=True)
def _turn_body(b, turn, base, tables, frames):
    """Body b's rows and circles turned by ``turn`` into ``frames`` (see
    :func:`turned_frames`)."""
    bxy, ls, lo, nl, cen = base
    tflt, tfo = tables[1], tables[3]
    rt, lt, ct = frames
    f = ls[lo[b]]
    n = ls[lo[b] + nl[b]] - f
    cs = math.cos(turn)
    sn = math.sin(turn)
    cx = cen[b, 0]
    cy = cen[b, 1]
    for i in range(f, f + n):
        dx = bxy[i, 0] - cx
        dy = bxy[i, 1] - cy
        x = dx * cs - dy * sn
        y = dx * sn + dy * cs
        rt[i, 0] = x
        rt[i, 1] = y
        lt[i] = np.sqrt(x * x + y * y)
    fo = tfo[b]
    for q in range(fo, fo + 4 * (2 * n - 1), 4):
        x = tflt[q]
        y = tflt[q + 1]
        u = x * cs - y * sn
        v = x * sn + y * cs
        ct[q] = u
        ct[q + 1] = v
        ct[q + 2] = tflt[q + 2]
        ct[q + 3] = np.sqrt(u * u + v * v)


@njit(cache=True, nogil=True, parallel=True)
def turned_frames(base, tables, bodies, ang, frames, chunks):
    """Every body of ``bodies`` turned by its angle ``ang[b]``, once for all the pairs it
    is in, written into ``frames`` = ``(rt, lt, ct)``: its rows about its centroid and
    their lengths (laid out as the base rows: at least as many) and its circles (as
    ``tables``' floats, from ``tfo[b]``: at least as many); other bodies' places are
    left as they are. ``base``, ``tables``: as for :func:`frame_tables`. In parallel
    chunks (``chunks`` = 1: serial)."""
    n = bodies.shape[0]
    for c in prange(chunks):
        for k in range(n * c // chunks, n * (c + 1) // chunks):
            _turn_body(bodies[k], ang[bodies[k]], base, tables, frames)


@njit(cache=True, nogil=True, inline="always")
def _turned(b, base, tables, frames, st):
    """Body b as turned by :func:`turned_frames`: ``(r, starts, table)``, its rows about
    its centroid, loop starts (written into ``st``) and
    :func:`polycontact._kernels.advance.edge_table`, as
    :func:`polycontact._kernels.impact.exact_query` takes them."""
    ls, lo, nl = base[1], base[2], base[3]
    tint, tio, tfo = tables[0], tables[2], tables[3]
    rt, lt, ct = frames
    f = ls[lo[b]]
    n = ls[lo[b] + nl[b]] - f
    m = 2 * n - 1
    for q in range(nl[b] + 1):
        st[q] = ls[lo[b] + q] - f
    io = tio[b]
    return rt[f:f + n], st[:nl[b] + 1], (tint[io:io + n], view(tint, io + n, m, 3, np.int64),
                                         view(ct, tfo[b], m, 4, np.float64), lt[f:f + n])


@njit(cache=True, nogil=True)
def _circles_apart(ca, ma, la, cb, mb, lb, t_max, inflate):
    """Whether the bounding circles provably stay apart over [0, t_max], with the margin
    the broad phase of ``exact_query`` gives them
    (:func:`polycontact._kernels.broad_phase.overlap_intervals_into`) and more: then that
    broad phase finds no interval, and the search reports nothing. The centres' distance
    is at least the distance of their straight paths (closest approach at the initial
    speeds) minus what the accelerations add, ``|Δa| t²/2``."""
    dx = cb[0] - ca[0]
    dy = cb[1] - ca[1]
    vx = mb[0] - ma[0]
    vy = mb[1] - ma[1]
    ax = mb[2] - ma[2]
    ay = mb[3] - ma[3]
    v2 = vx * vx + vy * vy
    t = 0.0
    if v2 > 0.0:
        t = min(max(-(dx * vx + dy * vy) / v2, 0.0), t_max)
    px = dx + vx * t
    py = dy + vy * t
    acc = 0.5 * math.sqrt(ax * ax + ay * ay) * t_max * t_max
    r = circles_reach(ca, la, cb, lb, math.sqrt(v2) * t_max + acc, inflate)
    return math.sqrt(px * px + py * py) - acc > r


@njit(cache=True, nogil=True)
def _circles_meet_at_start(ca, la, cb, lb, inflate):
    """Whether the bounding circles may overlap at t = 0, with the margin of
    :func:`_circles_apart`: where the first interval of ``exact_query``'s broad phase
    starts at 0, they do."""
    return not circles_apart(ca, la, cb, lb, 0.0, inflate)


@njit(cache=True, nogil=True)
def _turn_range(m, t_max):
    """The least and the greatest angle a body with motion row ``m`` (``[vx, vy, ax, ay,
    ω, α]``) has turned through over [0, ``t_max``]: of ``ω t + α t²/2``, 0 included."""
    w = m[4]
    al = m[5]
    end = (w + 0.5 * al * t_max) * t_max
    lo = min(0.0, end)
    hi = max(0.0, end)
    if (w < 0.0 < al or al < 0.0 < w) and abs(w) < abs(al) * t_max:  # it turns back
        top = -0.5 * w * (w / al)
        lo = min(lo, top)
        hi = max(hi, top)
    return lo, hi


@njit(cache=True, nogil=True)
def _turned_support(r, rl, ux, uy, m, t_max):
    """The greatest projection on (ux, uy) of the vertices ``r`` (about the centre they
    turn about; ``rl``: their lengths) as the body turns over [0, ``t_max``]: a vertex
    reaches its length where the turn takes it through the direction, else the larger
    projection of the turn's two ends."""
    lo, hi = _turn_range(m, t_max)
    full = hi - lo >= math.pi
    c = math.cos(lo)
    s = math.sin(lo)
    ax = c * ux + s * uy  # the direction as the body sees it at the turn's two ends
    ay = c * uy - s * ux
    c = math.cos(hi)
    s = math.sin(hi)
    bx = c * ux + s * uy
    by = c * uy - s * ux
    best = -np.inf
    for i in range(r.shape[0]):
        x = r[i, 0]
        y = r[i, 1]
        if full or (bx * y - by * x >= 0.0 and x * ay - y * ax >= 0.0):
            p = rl[i]
        else:
            p = max(x * ax + y * ay, x * bx + y * by)
        best = max(best, p)
    return best


@njit(cache=True, nogil=True)
def _axis_apart(a, ma, b, mb, t_max, margin):
    """Whether two bodies provably stay more than ``margin`` apart over [0, ``t_max``],
    beyond the rounding (:func:`polycontact._kernels.world.rounding_allowance`):
    along the line of their centres at t = 0, the centres' distance less what the
    motions take off it and the bodies' :func:`_turned_support` on either side. ``a``,
    ``b`` = ``(r, lengths, centre, radius)``; ``ma``, ``mb``: motion rows.

    >>> import numpy as np
    >>> sq = np.array([[-1.0, -1], [1, -1], [1, 1], [-1, 1]])
    >>> rl = np.full(4, np.sqrt(2.0))
    >>> spin = np.array([0.0, 0, 0, 0, 0.5, 0])
    >>> [bool(_axis_apart((sq, rl, np.zeros(2), 1.5), spin,
    ...                   (sq, rl, np.array([x, 0.0]), 1.5), spin, 1.0, 0.0)) for x in (2.5, 3.0)]
    [False, True]
    """
    ra, la, ca, rad_a = a
    rb, lb, cb, rad_b = b
    dx = cb[0] - ca[0]
    dy = cb[1] - ca[1]
    d = math.sqrt(dx * dx + dy * dy)
    if d == 0.0:
        return False
    ux = dx / d
    uy = dy / d
    vx = mb[0] - ma[0]
    vy = mb[1] - ma[1]
    ax = mb[2] - ma[2]
    ay = mb[3] - ma[3]
    gap = d + min(0.0, (vx * ux + vy * uy) * t_max) \
        + min(0.0, 0.5 * (ax * ux + ay * uy) * t_max * t_max)
    # what the motions add to the terms: the centres' paths and the vertices' arcs
    travel = (math.sqrt(vx * vx + vy * vy) + 0.5 * math.sqrt(ax * ax + ay * ay) * t_max
              + (abs(ma[4]) + 0.5 * abs(ma[5]) * t_max) * rad_a
              + (abs(mb[4]) + 0.5 * abs(mb[5]) * t_max) * rad_b) * t_max
    gap -= margin + rounding_allowance(ca, cb, rad_a + rad_b, travel)
    return gap > _turned_support(ra, la, ux, uy, ma, t_max) \
        + _turned_support(rb, lb, -ux, -uy, mb, t_max)


@njit(cache=True, nogil=True, inline="always")
def _search_buffers(vmax, lmax):
    """The scratch of :func:`_search_range` for bodies of up to ``vmax`` vertices and
    ``lmax`` loops: two bodies' loop starts, the search's ``work`` and the state kernel's
    scratch."""
    return (np.empty(lmax + 1, np.int64), np.empty(lmax + 1, np.int64),
            np.empty(work_floats(2 * vmax)),
            state_scratch_views(np.empty(scratch_floats(2 * vmax)), 2 * vmax))


# Compiled without Numba's reference counting (``_nrt=False``): each pair takes a dozen
# views of the World's arrays (its rows, its turned frames, the search's buffers), whose
# atomic reference counts cost a tenth of a pair's search. Nothing in it may allocate:
# the caller passes the buffers in, and what it calls that returns views is inlined.
@njit(cache=True, nogil=True, _nrt=False)
def _search_range(pi, pj, movers, world, settings, buffers, k0, k1, out):
    """:func:`sweep_search` for the pairs ``k0:k1``, into ``out`` (``buffers``:
    :func:`_search_buffers`)."""
    ids, pos, ang, rad, extent, motion = movers
    base, tables, frames, rows = world
    t_max, inflate, time_tol, rel, ulps, resolution, max_iter = settings
    code, t_hi, t_contact, state = out
    sa, sb, work, scratch = buffers
    for k in range(k0, k1):
        a = ids[pi[k]]
        b = ids[pj[k]]
        ma = motion[pi[k]]
        mb = motion[pj[k]]
        if _circles_apart(pos[a], ma, rad[a], pos[b], mb, rad[b], t_max, inflate):
            code[k] = 0
            t_hi[k] = -1.0
            t_contact[k] = -1.0
            state[k] = 0
            continue
        rel_k = rel * max(extent[a], extent[b])
        # exact_query's first step where the bounding circles overlap at the start: the
        # state at t = 0, of the bodies there, which are their stored rows (before its
        # broad phase: in a crowded step most such pairs penetrate, and need none)
        at_start = _circles_meet_at_start(pos[a], rad[a], pos[b], rad[b], inflate)
        if at_start:
            ya, s1 = body_view(rows[0], rows[1], rows[2], rows[3], a, sa)
            yb, s2 = body_view(rows[0], rows[1], rows[2], rows[3], b, sb)
            eps = tolerance_at(pos[a], ma, rad[a], pos[b], mb, rad[b], 0.0, rel_k, ulps)
            if state_in(ya, s1, 1.0, yb, s2, 1.0, eps, scratch) == PENETRATING:
                code[k] = INITIALLY_PENETRATING
                t_hi[k] = 0.0
                t_contact[k] = 0.0
                state[k] = 2
                continue
        r1, s1, e1 = _turned(a, base, tables, frames, sa)
        r2, s2, e2 = _turned(b, base, tables, frames, sb)
        # about half the pairs whose circles meet and whose bodies do not are kept apart
        # by the line of their centres: then the search, whose contacts come within the
        # tolerance and the contact resolution of the end, reports nothing
        lam = resolution * (rad[a] + rad[b])
        eps = tolerance_at(pos[a], ma, rad[a], pos[b], mb, rad[b], t_max, rel_k, ulps)
        if _axis_apart((r1, e1[3], pos[a], rad[a]), ma, (r2, e2[3], pos[b], rad[b]), mb,
                       t_max, lam + (1.0 + LAM_PER_EPS) * eps):
            code[k] = 0
            t_hi[k] = -1.0
            t_contact[k] = -1.0
            state[k] = 0
            continue
        n = query_intervals(pos[a], ma, rad[a], pos[b], mb, rad[b], t_max, inflate, work)
        query = (t_max, inflate, time_tol, rel_k, ulps, lam, max_iter, 0)
        got = query_search((r1, s1, pos[a], rad[a]), e1, ma, (r2, s2, pos[b], rad[b]), e2, mb,
                           n, query, work, at_start)
        c = got[0]
        code[k] = c
        t_hi[k] = got[1]
        t = got[3] if c != 2 else 0.0
        if c == 3 and t < 0.0:
            t = got[5]
        t_contact[k] = t
        state[k] = 0 if t < 0.0 else (2 if c == 1 or c == 2 else 1)


@njit(cache=True, nogil=True, parallel=True)
def sweep_search(pi, pj, movers, base, tables, frames, rows, settings, vmax, lmax, chunks):
    """The exact time-of-impact search of each candidate pair (``ids[pi[k]]``,
    ``ids[pj[k]]``) over [0, ``t_max``], in parallel chunks (``chunks`` = 1: serial).

    ``movers`` = ``(ids, pos, ang, rad, extent, motion)``: the World's ids of the
    moving bodies, and by id each body's position (its centroid), angle, bounding
    radius and box extent; ``motion`` holds the rows ``[vx, vy, ax, ay, ω, α]``,
    indexed like ``ids``. ``base``, ``tables``: as for :func:`frame_tables`;
    ``frames``: the bodies turned by :func:`turned_frames`; ``rows``: the World's stored
    rows ``(xy, ls, lo, nl)``. ``settings`` = ``(t_max, inflate, time_tol, rel,
    ulps, resolution, max_iter)``: those of
    :func:`polycontact._kernels.impact.exact_query`, with the relative terms of the
    distance tolerance and of the contact resolution (times each pair's larger extent,
    and its sum of radii). ``vmax``, ``lmax``: the most vertices and loops of a body.

    Returns ``(code, t_hi, t_contact, state)``: the search's status code and
    penetration time (as ``exact_query``), the first contact time (0 when penetrating
    at the start; the time reached by a search without a verdict; -1 when they never
    touch), and 2 when they penetrate within the step, 1 when they only touch, 0 when
    they never do."""
    n = pi.shape[0]
    out = (np.zeros(n, np.int8), np.empty(n), np.empty(n), np.zeros(n, np.int8))
    if chunks == 1:
        _search_range(pi, pj, movers, (base, tables, frames, rows), settings,
                      _search_buffers(vmax, lmax), 0, n, out)
        return out
    for c in prange(chunks):
        buffers = _search_buffers(vmax, lmax)
        for b in range(c, SPREAD * chunks, chunks):
            k0, k1 = block(n, chunks, b)
            _search_range(pi, pj, movers, (base, tables, frames, rows), settings, buffers,
                          k0, k1, out)
    return out


@njit(cache=True, nogil=True, parallel=True)
def sweep_events(order, pi, pj, ids, found, chunks):
    """A sweep's events, the candidate pairs ``order[k]`` in turn (bodies ``ids[pi[p]]``
    and ``ids[pj[p]]`` of pair p; ``found`` = ``(code, t_hit, t_contact, state)``, what
    :func:`sweep_search` found of each): ``(pairs, i, j, times, states, hit, codes,
    start)``, the bodies' ids as rows, their rows in ``ids``, the first contact's time,
    the state, the first penetration's time (0 at the start, NaN without one), the
    search's code, and whether it found the pair penetrating at the start. In parallel
    chunks (``chunks`` = 1: serial)."""
    code, t_hit, t_contact, state = found
    n = order.shape[0]
    pairs = np.empty((n, 2), np.int64)
    i = np.empty(n, np.int64)
    j = np.empty(n, np.int64)
    times = np.empty(n)
    states = np.empty(n, state.dtype)
    hit = np.empty(n)
    codes = np.empty(n, code.dtype)
    start = np.empty(n, np.bool_)
    for c in prange(chunks):
        for k in range(n * c // chunks, n * (c + 1) // chunks):
            p = order[k]
            i[k] = pi[p]
            j[k] = pj[p]
            pairs[k, 0] = ids[pi[p]]
            pairs[k, 1] = ids[pj[p]]
            times[k] = t_contact[p]
            states[k] = state[p]
            codes[k] = code[p]
            start[k] = code[p] == INITIALLY_PENETRATING
            hit[k] = 0.0 if start[k] else (t_hit[p] if code[p] == HIT else np.nan)
    return pairs, i, j, times, states, hit, codes, start


@njit(cache=True, nogil=True)
def _event_range(events, movers, world, vmax, lmax, ulps, c, chunks, point, normal):
    """:func:`event_geometry` for the events of chunk ``c`` of ``chunks`` (its blocks,
    :mod:`polycontact._kernels.spread`), into ``point`` and ``normal``, with one set of
    buffers.
    The two bodies of an event are placed side by side as the rows of a World of two
    (``rows``, one pair), for :func:`polycontact._kernels.contact_geometry.geometry_into`."""
    ei, ej, times, at_start = events
    ids, pos, ang, rad, extent, motion, rel = movers
    base, tables, frames = world
    fa = np.empty(lmax + 1, np.int64)
    fb = np.empty(lmax + 1, np.int64)
    xy = np.empty((2 * vmax, 2))
    ls = np.empty(2 * lmax + 1, np.int64)
    lo = np.zeros(2, np.int64)
    nl = np.empty(2, np.int64)
    rows = (xy, ls, lo, nl)
    pair = (np.zeros(1, np.int64), np.ones(1, np.int64), np.empty(1, np.int8), np.empty(1))
    scratch = state_scratch_views(np.empty(scratch_floats(2 * vmax)), 2 * vmax)
    buffers = geometry_buffers(vmax)
    ba = np.empty(lmax + 1, np.int64)
    bb = np.empty(lmax + 1, np.int64)
    dist = np.empty(1)
    rest = (np.empty(1), np.empty((1, 2)), np.empty(1, np.int8), np.empty(1, np.int64),
            np.empty(1, np.int64))
    for b in range(c, SPREAD * chunks, chunks):
        k0, k1 = block(ei.shape[0], chunks, b)
        for k in range(k0, k1):
            i = ei[k]
            j = ej[k]
            r1, s1, _ = _turned(ids[i], base, tables, frames, fa)
            r2, s2, _ = _turned(ids[j], base, tables, frames, fb)
            n1 = r1.shape[0]
            n2 = r2.shape[0]
            nl[0] = s1.shape[0] - 1
            nl[1] = s2.shape[0] - 1
            lo[1] = nl[0]
            ls[:nl[0] + 1] = s1
            ls[nl[0]:nl[0] + nl[1] + 1] = s2 + n1
            t = times[k]
            eps_rel = rel * max(extent[i], extent[j])
            eps = tolerance_at(pos[i], motion[i], rad[i], pos[j], motion[j], rad[j], t, eps_rel,
                               ulps)
            if at_start[k]:  # penetrating at t = 0, as the search classified the stored rows
                place(r1, pos[i], motion[i], t, xy[:n1])
                place(r2, pos[j], motion[j], t, xy[n1:n1 + n2])
                pair[2][0] = PENETRATING
            else:
                pair[2][0] = state_at((r1, s1, pos[i], rad[i]), motion[i],
                                      (r2, s2, pos[j], rad[j]), motion[j], t, eps,
                                      (xy[:n1], xy[n1:n1 + n2], scratch))
            pair[3][0] = eps
            out = (dist, normal[k:k + 1], point[k:k + 1]) + rest
            while True:
                done, status = geometry_into(rows, pair, 0, 1, out, buffers, ba, bb)
                if done == 1:
                    break
                buffers = grown_buffers(buffers, status, vmax)
            if not dist[0] == dist[0]:  # a depth left undecided: for the caller
                normal[k, 0] = np.nan
                normal[k, 1] = np.nan


@njit(cache=True, nogil=True, parallel=True)
def event_geometry(events, movers, base, tables, frames, vmax, lmax, ulps, chunks):
    """The contact point and normal of each event of ``events`` = ``(ei, ej, times,
    at_start)``: bodies ``ids[ei[k]]`` and ``ids[ej[k]]`` at ``times[k]``, of ``movers``
    = ``(ids, pos, ang, rad, extent, motion, rel)``, rows in the order of ``ids``: each
    body moving from its centroid ``pos`` and turn ``ang`` with its kernel vector
    ``motion``; classified there with the time-of-impact search's tolerance (``rel``
    times the larger ``extent`` of the two, bounding radii ``rad``, ``ulps``; a pair that
    ``at_start[k]`` says the search found penetrating at t = 0 is not classified again)
    and described by
    :func:`polycontact._kernels.contact_geometry.pair_geometry_into`; NaN normals where
    the depth is left undecided. ``base``, ``tables``, ``frames``: as for
    :func:`sweep_search`, the bodies turned by those turns. In parallel chunks."""
    n = events[0].shape[0]
    point = np.full((n, 2), np.nan)
    normal = np.full((n, 2), np.nan)
    if chunks == 1:
        _event_range(events, movers, (base, tables, frames), vmax, lmax, ulps, 0, 1, point,
                     normal)
        return point, normal
    for c in prange(chunks):
        _event_range(events, movers, (base, tables, frames), vmax, lmax, ulps, c, chunks,
                     point, normal)
    return point, normal
