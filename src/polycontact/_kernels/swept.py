"""Kernels: many moving bodies at once — swept bounds and batched time of impact.

Swept bounds (design.md §3 for every body at once). A body moving with constant
acceleration and spin stays within its bounding circle (radius ``L``) about its
centroid, and its centroid follows ``c(t) = c0 + v t + a t²/2``. Over a time slice
``[t0, t1]`` each coordinate of that path is a parabola, so its range is spanned by the
slice's ends and the apex ``t* = −v/a`` when it falls inside; the box of that range
grown by ``L`` (widened as the pairwise broad phase widens the radii, see
:func:`boxes_into`) holds the body for the whole slice, whatever its spin. Each body
gets enough slices that its centroid moves at most about ``L`` per slice (at most
``max_slices``), so the boxes hug the path. Two bodies can touch at
time t only if the boxes of the slices holding t overlap in x, in y and in time:
a sort-and-sweep over the space–time boxes (on the axis where the boxes spread most)
lists every such pair once.

Batched search. :func:`impacts_chunk` runs, for a list of pairs, exactly what
``polycontact.time_of_impact`` runs for one (``_kernels.impact.exact_query`` or
``sampled_query``) on the bodies' tables packed one after another, without the GIL.
"""

from __future__ import annotations

import numpy as np

from .jit import njit
from .impact import exact_query, sampled_query, unpack_body, work_floats


@njit(cache=True, nogil=True)
def _coordinate_range(c, v, a, t0, t1):
    """Range of ``c + v t + a t²/2`` over ``[t0, t1]``: the ends and, inside, the apex."""
    x0 = c + v * t0 + 0.5 * a * t0 * t0
    x1 = c + v * t1 + 0.5 * a * t1 * t1
    lo = min(x0, x1)
    hi = max(x0, x1)
    if a != 0.0:
        ts = -v / a
        if t0 < ts < t1:
            xs = c + v * ts + 0.5 * a * ts * ts
            lo = min(lo, xs)
            hi = max(hi, xs)
    return lo, hi


@njit(cache=True, nogil=True)
def slice_starts(m, radius, t_max, max_slices):
    """Where each body's space–time boxes start among all (N + 1,), from its motion
    vector ``m[i]`` = ``[vx, vy, ax, ay, ω, α]`` and bounding radius ``radius[i]``: body
    i gets ``k_i = clamp(ceil(travel_i / radius_i), 1, max_slices)`` slices of ``[0,
    t_max]`` (``travel_i = |v| t_max + |a| t_max²/2`` bounds its centroid's path
    length), its boxes ``first[i]:first[i + 1]`` (:func:`boxes_into`).

    >>> slice_starts(np.array([[0.0] * 6, [3.0, 4, 0, 0, 0, 0]]), np.array([1.0, 1.0]),
    ...              1.0, 16).tolist()
    [0, 1, 6]
    """
    n = m.shape[0]
    first = np.empty(n + 1, np.int64)
    first[0] = 0
    for i in range(n):
        travel = np.sqrt(m[i, 0] ** 2 + m[i, 1] ** 2) * t_max + \
            0.5 * np.sqrt(m[i, 2] ** 2 + m[i, 3] ** 2) * t_max * t_max
        k = 1
        if radius[i] > 0.0 and travel > radius[i]:
            k = int(min(float(max_slices), np.ceil(travel / radius[i])))
        first[i + 1] = first[i] + max(1, min(k, max_slices))
    return first


@njit(cache=True, nogil=True)
def boxes_into(c, m, radius, t_max, first, inflate, ulps, i0, i1, boxes, owner):
    """Space–time boxes bounding bodies ``i0`` to ``i1 - 1`` over ``[0, t_max]``, written
    into ``boxes`` and ``owner`` from ``first[i]`` (:func:`slice_starts`, whose slices
    they are): ``boxes[k] = (x_lo, x_hi, y_lo, y_hi, t_lo, t_hi)`` and the body it
    bounds; the caller may split the bodies among threads.

    ``c`` (N, 2) centroids at t = 0, ``m`` (N, 6) motion vectors ``[vx, vy, ax, ay, ω,
    α]``, ``radius`` (N,) bounding radii. Each box is grown by the radius times ``1 +
    inflate`` and by ``ulps`` times the body's reach ``radius + Σ_x,y (|c0| + |v| t_max
    + |a| t_max²/2)``: the terms whose sum over both bodies, times 16 units of 2**-52,
    the pairwise broad phase adds to the sum of the radii
    (:func:`polycontact._kernels.broad_phase.rounding_allowance`); ``ulps`` above that
    covers the rounding of the centre distance there and of the boxes here. Two bodies
    whose inflated circles the pairwise broad phase sees meeting at some t thus have
    boxes that meet in x, y and time (slice ends are computed one way for every body,
    so the slices tile ``[0, t_max]``)."""
    for i in range(i0, i1):
        k = first[i + 1] - first[i]
        b = first[i]
        vx, vy, ax, ay = m[i, 0], m[i, 1], m[i, 2], m[i, 3]
        reach = radius[i] + abs(c[i, 0]) + abs(c[i, 1]) + \
            (abs(vx) + abs(vy)) * t_max + 0.5 * (abs(ax) + abs(ay)) * t_max * t_max
        grow = radius[i] * (1.0 + inflate) + ulps * reach
        for s in range(k):
            t0 = t_max * s / k
            t1 = t_max if s == k - 1 else t_max * (s + 1) / k
            xlo, xhi = _coordinate_range(c[i, 0], vx, ax, t0, t1)
            ylo, yhi = _coordinate_range(c[i, 1], vy, ay, t0, t1)
            boxes[b, 0] = xlo - grow
            boxes[b, 1] = xhi + grow
            boxes[b, 2] = ylo - grow
            boxes[b, 3] = yhi + grow
            if not (boxes[b, 0] <= boxes[b, 1] and boxes[b, 2] <= boxes[b, 3]):
                # the path overflowed float64 (inf − inf): the box is the whole plane,
                # so that the pair goes on to the search, which says what it can
                boxes[b, 0] = -np.inf
                boxes[b, 1] = np.inf
                boxes[b, 2] = -np.inf
                boxes[b, 3] = np.inf
            boxes[b, 4] = t0
            boxes[b, 5] = t1
            owner[b] = i
            b += 1


@njit(cache=True, nogil=True)
def _strip_axis(boxes):
    """The sweep axis ``ax`` (0: x, 2: y: the axis along which the boxes' centres spread
    most), the other axis ``ox`` and its strips: ``(ax, ox, lo, width, strips)``, the
    strips as high as a box on average, at most one per box; one strip when a box
    reaches infinity."""
    nb = boxes.shape[0]
    mx = 0.0
    my = 0.0
    for k in range(nb):
        mx += boxes[k, 0] + boxes[k, 1]
        my += boxes[k, 2] + boxes[k, 3]
    mx /= 2.0 * nb
    my /= 2.0 * nb
    vx = 0.0
    vy = 0.0
    for k in range(nb):
        vx += (0.5 * (boxes[k, 0] + boxes[k, 1]) - mx) ** 2
        vy += (0.5 * (boxes[k, 2] + boxes[k, 3]) - my) ** 2
    ax = 0 if vx >= vy else 2
    ox = 2 - ax
    lo = np.inf
    hi = -np.inf
    tall = 0.0
    for k in range(nb):
        lo = min(lo, boxes[k, ox])
        hi = max(hi, boxes[k, ox + 1])
        tall += boxes[k, ox + 1] - boxes[k, ox]
    strips = 1
    width = 1.0
    if hi > lo and np.isfinite(hi - lo) and np.isfinite(tall):
        width = max(tall / nb, (hi - lo) / nb)
        strips = min(nb, int((hi - lo) / width) + 1)
        width = (hi - lo) / strips
    return ax, ox, lo, width, strips


@njit(cache=True, nogil=True)
def box_strips(boxes):
    """The strips of a sort and sweep of ``boxes`` (rows ``x0, x1, y0, y1, t0, t1``):
    ``(ax, ox, first, start, members)``, the sweep axis ``ax`` (0: x, 2: y: the axis
    along which the boxes' centres spread most) and the other axis ``ox``, across which
    the strips lie, as high as a box on average, at most one per box (one when a box
    reaches infinity); each box's first strip, and strip q's boxes
    ``members[start[q]:start[q + 1]]`` (a box in every strip its extent on axis ``ox``
    meets; the strip of a coordinate grows with it)."""
    ax, ox, lo, width, strips = _strip_axis(boxes)
    nb = boxes.shape[0]
    first = np.empty(nb, np.int64)
    last = np.empty(nb, np.int64)
    start = np.zeros(strips + 1, np.int64)
    for k in range(nb):
        s0 = 0
        s1 = strips - 1
        if strips > 1:
            s0 = min(strips - 1, max(0, int((boxes[k, ox] - lo) / width)))
            s1 = min(strips - 1, max(s0, int((boxes[k, ox + 1] - lo) / width)))
        first[k] = s0
        last[k] = s1
        for q in range(s0, s1 + 1):
            start[q + 1] += 1
    for q in range(strips):
        start[q + 1] += start[q]
    members = np.empty(start[strips], np.int64)
    fill = start[:strips].copy()
    for k in range(nb):
        for q in range(first[k], last[k] + 1):
            members[fill[q]] = k
            fill[q] += 1
    return ax, ox, first, start, members


@njit(cache=True, nogil=True)
def sweep_strips(boxes, owner, ax, ox, first, start, members, q0, q1, at, pi, pj):
    """Sweep strips ``q0`` to ``q1 - 1``: the overlapping boxes of different bodies,
    each pair of boxes in the first strip they share only. With ``at`` empty: sort each
    strip's members along ``ax`` (in place) and count strip q's pairs into
    ``pi[q + 1]``; else write them (lower body first) to ``pi`` and ``pj`` from
    ``at[q]``."""
    count = at.shape[0] == 0
    for q in range(q0, q1):
        group = members[start[q]:start[q + 1]]
        if count:
            group[:] = group[np.argsort(boxes[group, ax], kind="mergesort")]
        k = 0 if count else at[q]
        for p in range(group.shape[0]):
            a = group[p]
            top = boxes[a, ax + 1]
            ia = owner[a]
            for r in range(p + 1, group.shape[0]):
                b = group[r]
                if boxes[b, ax] > top:
                    break
                ib = owner[b]
                if ia == ib or max(first[a], first[b]) != q:
                    continue
                if boxes[b, ox] > boxes[a, ox + 1] or boxes[a, ox] > boxes[b, ox + 1]:
                    continue
                if boxes[b, 4] > boxes[a, 5] or boxes[a, 4] > boxes[b, 5]:
                    continue
                if not count:
                    pi[k] = min(ia, ib)
                    pj[k] = max(ia, ib)
                k += 1
        if count:
            pi[q + 1] = k


@njit(cache=True, nogil=True)
def partners_of(pi, pj, n_bodies):
    """The pairs ``(pi[k], pj[k])`` grouped by their first body: ``(start, bucket,
    kept)``, body i's partners ``bucket[start[i]:start[i + 1]]`` in the order given,
    ``kept`` zeros for their distinct counts."""
    start = np.zeros(n_bodies + 1, np.int64)
    for k in range(pi.shape[0]):
        start[pi[k] + 1] += 1
    for i in range(n_bodies):
        start[i + 1] += start[i]
    bucket = np.empty(pi.shape[0], np.int64)
    fill = start[:n_bodies].copy()
    for k in range(pi.shape[0]):
        bucket[fill[pi[k]]] = pj[k]
        fill[pi[k]] += 1
    return start, bucket, np.zeros(n_bodies + 1, np.int64)


@njit(cache=True, nogil=True)
def distinct_partners(bucket, start, i0, i1, kept):
    """Sort each body i's partners ``bucket[start[i]:start[i + 1]]`` (i from ``i0`` to
    ``i1 - 1``), keep each once at the front, their count in ``kept[i + 1]``."""
    for i in range(i0, i1):
        seg = bucket[start[i]:start[i + 1]]
        m = 0
        if seg.shape[0] > 32:
            seg[:] = np.sort(seg)
            for r in range(seg.shape[0]):
                if m == 0 or seg[r] != seg[m - 1]:
                    seg[m] = seg[r]
                    m += 1
        else:  # (a few partners, as most bodies have: each inserted unless kept)
            for r in range(seg.shape[0]):
                v = seg[r]
                q = m
                while q > 0 and seg[q - 1] > v:
                    q -= 1
                if q > 0 and seg[q - 1] == v:
                    continue
                for t in range(m, q, -1):
                    seg[t] = seg[t - 1]
                seg[q] = v
                m += 1
        kept[i + 1] = m


@njit(cache=True, nogil=True)
def write_pairs(bucket, start, kept, i0, i1, out):
    """Body i's distinct partners (i from ``i0`` to ``i1 - 1``) as rows ``(i, j)`` of
    ``out`` from ``kept[i]``."""
    for i in range(i0, i1):
        for r in range(kept[i + 1] - kept[i]):
            out[kept[i] + r, 0] = i
            out[kept[i] + r, 1] = bucket[start[i] + r]


@njit(cache=True, nogil=True)
def impacts_chunk(todo, pairs, shapes, settings, out):
    """Time of impact of the pairs ``todo`` (indices into the pair arrays), results
    written in place at those indices.

    ``pairs`` is ``(sa, sb, ma, mb, ka, kb, eps_rel)``: pair p is shape ``sa[p]`` moving
    with ``ma[ka[p]]`` against shape ``sb[p]`` moving with ``mb[kb[p]]``, the size term of its
    distance tolerance ``eps_rel[p]`` (the kernels add ``ulps`` times the largest
    |coordinate| at each time they examine). ``shapes`` is ``(floats, f_off, ints,
    i_off, widest)``: shape s is ``floats[f_off[s]:f_off[s + 1]]`` and
    ``ints[i_off[s]:i_off[s + 1]]``, its :func:`polycontact._kernels.impact.pack_body`
    (vertices about its centroid, loop starts, centroid, bounding radius, circle tree),
    and no shape has more than ``widest`` vertices (the work buffers' size).
    ``settings`` is ``(t_max, inflate, time_tol, ulps, contact_resolution, max_iter,
    exact, samples)``. Each pair runs ``exact_query`` (``exact``) or ``sampled_query``
    with the same arguments as ``polycontact.time_of_impact`` (contact resolution
    ``contact_resolution`` times the sum of the radii); its outputs go to ``out`` =
    ``(code, t_hi, t_lo, contact, iters, reached, n_iv, iv)``, its broad-phase intervals
    to ``iv[p, :n_iv[p]]``.
    """
    # every pair's buffers, reused
    _impacts_into(todo, pairs, shapes, settings, out, np.empty(work_floats(2 * shapes[4])))


# Compiled without Numba's reference counting (``_nrt=False``): each pair takes a dozen
# views of the packed shapes and of the search's buffers, whose atomic reference counts
# cost about a tenth of a pair's search. Nothing in it may allocate (the caller passes
# ``work``), and what it calls that returns views is inlined.
@njit(cache=True, nogil=True, _nrt=False)
def _impacts_into(todo, pairs, shapes, settings, out, work):
    """:func:`impacts_chunk` with its buffer passed in (``work``: at least
    :func:`polycontact._kernels.impact.work_floats` of twice the widest shape)."""
    sa, sb, ma, mb, ka, kb, eps_rel = pairs
    floats, f_off, ints, i_off, _ = shapes
    t_max, inflate, time_tol, ulps, contact_resolution, max_iter, exact, samples = settings
    code, t_hi, t_lo, contact, iters, reached, n_iv, iv = out
    for k in range(todo.shape[0]):
        p = todo[k]
        a, ea = unpack_body(floats[f_off[sa[p]]:f_off[sa[p] + 1]],
                            ints[i_off[sa[p]]:i_off[sa[p] + 1]])
        b, eb = unpack_body(floats[f_off[sb[p]]:f_off[sb[p] + 1]],
                            ints[i_off[sb[p]]:i_off[sb[p] + 1]])
        query = (t_max, inflate, time_tol, eps_rel[p], ulps, contact_resolution * (a[3] + b[3]),
                 max_iter, samples)
        if exact:
            res = exact_query(a, ea, ma[ka[p]], b, eb, mb[kb[p]], query, work)
        else:
            res = sampled_query(a, ma[ka[p]], b, mb[kb[p]], query, work)
        n, c, hi, lo, ct, its, got = res
        code[p] = c
        t_hi[p] = hi
        t_lo[p] = lo
        contact[p] = ct
        iters[p] = its
        reached[p] = got
        n_iv[p] = n                             # (at most MAX_INTERVALS, iv's width)
        for q in range(n):
            iv[p, q, 0] = work[2 * q]
            iv[p, q, 1] = work[2 * q + 1]
