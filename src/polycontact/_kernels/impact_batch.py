"""Kernels: the bodies of many time-of-impact pairs prepared at once, without the GIL
(the caller splits the bodies over threads).

:func:`body_tables` builds every distinct body's arguments of the exact search (its
vertices about its centroid, circle tree and lengths: what
:func:`polycontact._kernels.impact.pack_body` packs for one body, the same arrays bit
for bit) into two flat arrays, each body at offsets known beforehand;
:func:`suspect_bodies` marks the bodies whose coordinates or motion may be beyond the
range the kernels take, for the caller to check exactly and refuse; :func:`pair_bodies`
gives the shapes and tolerances of many body pairs; :func:`ring_bodies` and
:func:`pack_rings` make bodies of raw outer rings, without a Shape.

Bodies are packed as ``xy`` (V, 2) float64, every body's loops one after another,
``rows`` (U + 1,) the first row of each body, and ``starts`` with ``st_off`` (U + 1,):
body u's loop starts (0 first, its vertex count last) are
``starts[st_off[u]:st_off[u + 1]]``.
"""

from __future__ import annotations

import math

import numpy as np

from .jit import njit
from .advance import edge_table_into, table_scratch
from .packs import vector, view
from .rings import raw_ring


@njit(cache=True, nogil=True)
def table_sizes(rows, st_off, wanted):
    """Offsets of each body's floats and ints in :func:`body_tables`' arrays, and the
    most vertices of a body with a table: ``(f_off, i_off, widest)``. A body of n
    vertices and k loop starts takes ``11 n - 1`` floats and ``7 n + k`` ints (those of
    ``pack_body`` with its tree of ``2 n - 1`` nodes); a body not ``wanted`` (bool,
    (U,)) takes none, and gets no table."""
    u_count = rows.shape[0] - 1
    f_off = np.zeros(u_count + 1, np.int64)
    i_off = np.zeros(u_count + 1, np.int64)
    widest = 0
    for u in range(u_count):
        if not wanted[u]:
            f_off[u + 1] = f_off[u]
            i_off[u + 1] = i_off[u]
            continue
        n = rows[u + 1] - rows[u]
        widest = max(widest, n)
        f_off[u + 1] = f_off[u] + 11 * n - 1
        i_off[u + 1] = i_off[u] + 7 * n + st_off[u + 1] - st_off[u]
    return f_off, i_off, widest


@njit(cache=True, nogil=True, _nrt=False)
def _body_into(xy, rows, starts, st_off, centroids, radii, u, f_out, fo, i_out, io, scratch):
    """Body u's ``pack_body`` arrays, written into ``f_out`` from ``fo`` and ``i_out``
    from ``io`` (the tables built in place, no allocation; ``scratch``:
    :func:`polycontact._kernels.advance.table_scratch` of at least its vertices)."""
    r0 = rows[u]
    n = rows[u + 1] - r0
    s0 = st_off[u]
    k = st_off[u + 1] - s0
    m = 2 * n - 1
    f_out[fo] = centroids[u, 0]
    f_out[fo + 1] = centroids[u, 1]
    f_out[fo + 2] = radii[u]
    r = view(f_out, fo + 3, n, 2, np.float64)
    for i in range(n):
        r[i, 0] = xy[r0 + i, 0] - centroids[u, 0]
        r[i, 1] = xy[r0 + i, 1] - centroids[u, 1]
    i_out[io] = n
    i_out[io + 1] = k
    i_out[io + 2] = m
    for q in range(k):
        i_out[io + 3 + q] = starts[s0 + q]
    table = (vector(i_out, io + 3 + k, n, np.int64),
             view(i_out, io + 3 + k + n, m, 3, np.int64),
             view(f_out, fo + 3 + 2 * n, m, 4, np.float64),
             vector(f_out, fo + 3 + 2 * n + 4 * m, n, np.float64))
    edge_table_into(r, vector(i_out, io + 3, k, np.int64), table, scratch)


@njit(cache=True, nogil=True)
def body_tables(xy, rows, starts, st_off, centroids, radii, f_off, i_off, u0, u1, floats,
                ints):
    """The :func:`polycontact._kernels.impact.pack_body` arrays of bodies ``u0`` to
    ``u1 - 1``, written into ``floats`` and ``ints`` (body u's at ``floats[f_off[u]:f_off[u
    + 1]]`` and ``ints[i_off[u]:i_off[u + 1]]``, the offsets of :func:`table_sizes`), as
    ``impacts_chunk`` reads them; the caller splits the bodies over threads.
    ``centroids`` (U, 2) and ``radii`` (U,): each body's area centroid and bounding
    radius. Bodies given no room (not wanted by :func:`table_sizes`) are skipped."""
    widest = 1
    for u in range(u0, u1):
        widest = max(widest, rows[u + 1] - rows[u])
    scratch = table_scratch(widest)
    for u in range(u0, u1):
        if f_off[u + 1] == f_off[u]:
            continue
        _body_into(xy, rows, starts, st_off, centroids, radii, u, floats, f_off[u], ints,
                   i_off[u], scratch)


@njit(cache=True, nogil=True)
def _suspect(xy, rows, centroids, radii, motions, owner, t_max, limit, floor, k):
    """Whether body k (shape ``owner[k]`` moving with ``motions[k]``) may be refused:
    see :func:`suspect_bodies`."""
    u = owner[k]
    x0 = math.inf
    x1 = -math.inf
    y0 = math.inf
    y1 = -math.inf
    for i in range(rows[u], rows[u + 1]):
        x0 = min(x0, xy[i, 0])
        x1 = max(x1, xy[i, 0])
        y0 = min(y0, xy[i, 1])
        y1 = max(y1, xy[i, 1])
    extent = max(x1 - x0, y1 - y0)
    margin = 1.0 - 1e-9  # (the exact check rounds differently: a margin, then that check)
    if not max(-x0, x1, -y0, y1) <= limit * margin or (0.0 < extent < floor / margin):
        return True
    m = motions[k]
    v = math.hypot(m[0], m[1])
    a = math.hypot(m[2], m[3])
    w = abs(m[4])
    alpha = abs(m[5])
    radius = radii[u]
    base = max(abs(centroids[u, 0]), abs(centroids[u, 1])) + radius
    w_max = w + alpha * t_max
    reach = base + v * t_max + 0.5 * a * t_max * t_max
    speed = v + a * t_max + w_max * radius
    accel = a + (alpha + w_max * w_max) * radius
    bound = limit * margin
    return not (reach <= bound and speed <= bound and accel <= bound and w_max <= bound)


@njit(cache=True, nogil=True)
def suspect_bodies(xy, rows, centroids, radii, motions, owner, t_max, limit, floor, k0, k1,
                   out):
    """For each body k from ``k0`` to ``k1 - 1`` (shape ``owner[k]`` of the packing,
    moving with the kernel vector ``motions[k]``), ``out[k]``: True when its coordinates
    may lie beyond ``limit`` or its extent below ``floor``, or when within ``[0, t_max]``
    its coordinates, its points' speeds or accelerations or its angular speed may exceed
    ``limit`` (the bounds of ``polycontact.broad_phase.reach_excess``, with a margin of
    1e-9 of the limit for the rounding); the caller splits the bodies over
    threads."""
    for k in range(k0, k1):
        out[k] = _suspect(xy, rows, centroids, radii, motions, owner, t_max, limit, floor, k)


@njit(cache=True, nogil=True)
def pair_bodies(pairs, owner, extents, rel):
    """What the search of the body pairs ``pairs`` (K, 2) needs, in one pass (a gather:
    a few nanoseconds a pair): ``(i, j, oi, oj, eps_rel, wanted)``, the two bodies of
    each pair, their shapes ``owner[i]`` and ``owner[j]``, the size term of the pair's
    distance tolerance ``rel * max(extents[oi], extents[oj])``, and for each of the U =
    ``extents.shape[0]`` shapes whether a pair has it."""
    n = pairs.shape[0]
    i = np.empty(n, np.int64)
    j = np.empty(n, np.int64)
    oi = np.empty(n, np.int64)
    oj = np.empty(n, np.int64)
    eps_rel = np.empty(n)
    wanted = np.zeros(extents.shape[0], np.bool_)
    for k in range(n):
        a = pairs[k, 0]
        b = pairs[k, 1]
        i[k] = a
        j[k] = b
        ua = owner[a]
        ub = owner[b]
        oi[k] = ua
        oj[k] = ub
        eps_rel[k] = rel * max(extents[ua], extents[ub])
        wanted[ua] = True
        wanted[ub] = True
    return i, j, oi, oj, eps_rel, wanted


@njit(cache=True, nogil=True)
def _ring_vertex(ring, n, sign, i):
    """Vertex i of the first ``n`` of ``ring`` turned counter-clockwise as
    :class:`polycontact.Shape` turns a clockwise outer loop (``ring[:n][::-1]``)."""
    return ring[i] if sign > 0 else ring[n - 1 - i]


@njit(cache=True, nogil=True)
def ring_bodies(rings, rel, ulps, limit, floor, p0, p1, used, sign, centroids, radii,
                extents):
    """Rings ``p0`` to ``p1 - 1`` of ``rings`` (P, N, 2) as bodies, written into
    ``used`` (int64), ``sign`` (int8), ``centroids`` (P, 2), ``radii`` and ``extents``;
    the caller splits the rings over threads.

    ``used[p]``: the vertices ring p keeps (a repeated closing point dropped), or -1
    when the caller must let :class:`polycontact.Shape` decide: the ring is not
    certified a valid simple polygon within ``limit`` and ``floor`` as given
    (:func:`polycontact._kernels.rings.raw_ring`, with ``rel`` and ``ulps``), or twice
    its area summed in floats is not clear of its rounding (a sliver, which ``Shape``
    sums exactly). ``sign[p]``: 1 counter-clockwise, -1 clockwise. The area centroid,
    bounding radius and extent of ring p are computed as ``Shape`` computes them (the
    ring turned counter-clockwise, coordinates taken relative to its first vertex; the
    sums in another order, so they may differ in the last bits)."""
    for p in range(p0, p1):
        ring = rings[p]
        n, s, _, box = raw_ring(ring, rel, ulps, limit, floor)
        used[p] = n
        sign[p] = 1 if s > 0 else -1
        if n < 0:
            continue
        o = _ring_vertex(ring, n, s, 0)
        a2 = 0.0
        sx = 0.0
        sy = 0.0
        mags = 0.0
        for i in range(n):
            u = _ring_vertex(ring, n, s, i)
            v = _ring_vertex(ring, n, s, (i + 1) % n)
            x = u[0] - o[0]
            y = u[1] - o[1]
            xn = v[0] - o[0]
            yn = v[1] - o[1]
            c = x * yn - xn * y
            a2 += c
            sx += (x + xn) * c
            sy += (y + yn) * c
            mags += abs(x * yn) + abs(xn * y)
        # (the rule of Shape's _area_clear: (n + 8) ulps of the products' magnitudes)
        if not a2 > (n + 8) * 2.0**-52 * mags or mags < 2.0**-1000:
            used[p] = -1
            continue
        cx = o[0] + sx / (3.0 * a2)
        cy = o[1] + sy / (3.0 * a2)
        radius = 0.0
        for i in range(n):
            radius = max(radius, math.hypot(ring[i, 0] - cx, ring[i, 1] - cy))
        centroids[p, 0] = cx
        centroids[p, 1] = cy
        radii[p] = radius
        extents[p] = max(box[1] - box[0], box[3] - box[2])


@njit(cache=True, nogil=True)
def pack_rings(rings, used, sign, rows, p0, p1, xy):
    """The kept vertices of rings ``p0`` to ``p1 - 1`` (:func:`ring_bodies`' ``used``
    and ``sign``), counter-clockwise, written into ``xy[rows[p]:rows[p] + used[p]]``;
    the caller splits the rings over threads."""
    for p in range(p0, p1):
        n = used[p]
        for i in range(n):
            v = _ring_vertex(rings[p], n, sign[p], i)
            xy[rows[p] + i, 0] = v[0]
            xy[rows[p] + i, 1] = v[1]
