"""Kernels of :class:`polycontact.World`: placing shapes, the broad phase, and the
classification of candidate pairs with the pairwise state kernel.

Bodies are stored packed: ``xy`` (V, 2) float64 holds every body's loops; body ``b``
has ``nl[b]`` loops whose start rows are ``ls[lo[b]:lo[b] + nl[b]]`` and whose end row
is ``ls[lo[b] + nl[b]]`` (loops oriented interior-left, as in ``Shape.packed``).
``box`` (B, 4) holds each body's bounding box ``x0, x1, y0, y1`` and ``eps`` (B,) its
own default tolerance; the tolerance of a pair is the larger of the two, which is
:func:`polycontact.default_tolerance` of both bodies (a maximum of per-body terms).

The broad phase is a loose hierarchical grid kept in one open-addressing hash table.
A body of box side ``s`` lives on level ``L`` (cells of side ``2**L >= s``) in the one
cell that holds its box centre, so its box lies within that cell widened by half a cell;
adding, moving or removing a body touches one cell list (doubly linked through ``nxt``
and ``prv``). A box query visits, on every non-empty level, the cells whose widened
bounds meet the box. Cell indices are clamped to ±2**25 about ``origin``: far cells
merge (more candidates), never lose one.

:func:`contact_pairs` lists and classifies the pairs in one parallel pass over the live
bodies (the broad phase's queries and the state kernel, chunk by chunk), then sorts them
in parallel buckets (:func:`sorted_pairs`).

The kernels take the store as records: ``bodies`` = ``(xy, ls, lo, nl, box, eps)``, and
the broad phase's ``grid`` = ``(keys, heads, nxt, level, lvl_count, levels, origin)``
(``levels``: the level indices in use).
"""

from __future__ import annotations

import math

import numpy as np
from numba import prange

from .jit import njit
from .packs import state_scratch
from .primitives import bbox
from .relation import state_in
from .spread import SPREAD, block


#: Levels L = idx - 512, idx in [0, 1024): cells from 2**-512 to 2**511.
_LEVEL_OFFSET = 512
_CELL_LIMIT = 33554432.0  # 2**25


@njit(cache=True, nogil=True)
def place(xy, cx, cy, px, py, angle, out):
    """Rotate ``xy`` by ``angle`` about (cx, cy), then move (cx, cy) to (px, py), into
    ``out``. Element by element (no matrix product), so every caller gets the same bits.
    """
    cs = math.cos(angle)
    sn = math.sin(angle)
    for k in range(xy.shape[0]):
        dx = xy[k, 0] - cx
        dy = xy[k, 1] - cy
        out[k, 0] = px + (dx * cs - dy * sn)
        out[k, 1] = py + (dx * sn + dy * cs)


@njit(cache=True, nogil=True)
def _level(x0, x1, y0, y1):
    """Level index of a box: the smallest L with 2**L >= its larger side."""
    s = max(x1 - x0, y1 - y0)
    if not s > 0.0:
        return 0
    m, e = math.frexp(s)
    lev = e - 1 if m == 0.5 else e
    return min(max(lev, -_LEVEL_OFFSET), _LEVEL_OFFSET - 1) + _LEVEL_OFFSET


@njit(cache=True, nogil=True)
def _cell(v, c):
    """The cell of side c holding coordinate v, clamped to ±2**25."""
    f = math.floor(v / c)
    return int(min(max(f, -_CELL_LIMIT), _CELL_LIMIT - 1.0))


@njit(cache=True, nogil=True)
def _key(idx, ix, iy):
    """The hash key of cell (ix, iy) of level index ``idx``."""
    return (idx << 52) | ((ix + 33554432) << 26) | (iy + 33554432)


@njit(cache=True, nogil=True)
def _slot(keys, key):
    """The slot holding ``key``, or the empty slot where it goes (linear probing)."""
    mask = keys.shape[0] - 1
    h = int(key) * 6364136223846793005  # wraps in int64 when compiled
    h = (h ^ (h >> 29)) & mask
    while keys[h] != key and keys[h] != -1:
        h = (h + 1) & mask
    return h


@njit(cache=True, nogil=True, inline="always")
def cell_key(box, b, origin):
    """The level index of body ``b``'s box and the hash key of the cell that holds it."""
    idx = _level(box[b, 0], box[b, 1], box[b, 2], box[b, 3])
    c = math.ldexp(1.0, int(idx) - _LEVEL_OFFSET)
    ix = _cell(0.5 * (box[b, 0] + box[b, 1]) - origin[0], c)
    iy = _cell(0.5 * (box[b, 2] + box[b, 3]) - origin[1], c)
    return idx, _key(idx, ix, iy)


@njit(cache=True, nogil=True)
def grid_insert(keys, heads, nxt, prv, slot, level, lvl_count, box, origin, b):
    """Put body ``b`` (its box set) in its cell; returns 1 if a new cell was made."""
    idx, key = cell_key(box, b, origin)
    h = _slot(keys, key)
    made = 0
    if keys[h] == -1:
        keys[h] = key
        heads[h] = -1
        made = 1
    _link(heads, nxt, prv, h, b)
    slot[b] = h
    level[b] = idx
    lvl_count[idx] += 1
    return made


@njit(cache=True, nogil=True)
def _link(heads, nxt, prv, h, b):
    """Put body ``b`` at the head of the cell list of slot ``h``."""
    nxt[b] = heads[h]
    prv[b] = -1
    if heads[h] >= 0:
        prv[heads[h]] = b
    heads[h] = b


@njit(cache=True, nogil=True)
def _unlink(heads, nxt, prv, h, b):
    """Take body ``b`` out of the cell list of slot ``h``."""
    if prv[b] >= 0:
        nxt[prv[b]] = nxt[b]
    else:
        heads[h] = nxt[b]
    if nxt[b] >= 0:
        prv[nxt[b]] = prv[b]


@njit(cache=True, nogil=True)
def grid_remove(heads, nxt, prv, slot, level, lvl_count, b):
    """Take body ``b`` out of its cell list."""
    _unlink(heads, nxt, prv, slot[b], b)
    slot[b] = -1
    lvl_count[level[b]] -= 1
    level[b] = -1


@njit(cache=True, nogil=True)
def grid_insert_many(keys, heads, nxt, prv, slot, level, lvl_count, box, origin, bodies,
                     filled):
    """:func:`grid_insert` of each body in ``bodies`` into a table holding ``filled``
    cells; stops before it would be more than half full and returns (cells made,
    bodies inserted)."""
    made = 0
    limit = keys.shape[0] // 2
    for k in range(bodies.shape[0]):
        if filled + made + 1 > limit:
            return made, k
        made += grid_insert(keys, heads, nxt, prv, slot, level, lvl_count, box, origin,
                            bodies[k])
    return made, bodies.shape[0]


@njit(cache=True, nogil=True)
def grid_rebuild(keys, heads, nxt, prv, slot, level, lvl_count, box, origin, alive):
    """Fill an emptied table (``keys`` all -1) with the bodies in ``alive``."""
    lvl_count[:] = 0
    made = 0
    for k in range(alive.shape[0]):
        made += grid_insert(keys, heads, nxt, prv, slot, level, lvl_count, box, origin,
                            alive[k])
    return made


@njit(cache=True, nogil=True)
def _regrid_probe(ids, keys, slot, level, box, origin, k0, k1, moves):
    """For each body of ``ids[k0:k1]``: its old slot and level, the level and cell key of
    its box, and the slot of that key (or the empty slot where it would go), into the
    rows of ``moves`` (see :func:`regrid`)."""
    for k in range(k0, k1):
        b = ids[k]
        idx, key = cell_key(box, b, origin)
        moves[k, 0] = slot[b]
        moves[k, 1] = level[b]
        moves[k, 2] = idx
        moves[k, 3] = key
        moves[k, 4] = _slot(keys, key)


@njit(cache=True, nogil=True)
def _regrid_lists(ids, moves, heads, nxt, prv, slot, level, c, chunks, insert):
    """Take out of their old cell lists (``insert`` False), or put at the head of their
    new ones, the bodies of ``ids`` whose slot (old or new) is ``c`` modulo
    ``chunks``, in the order of ``ids``."""
    for k in range(ids.shape[0]):
        h = moves[k, 4] if insert else moves[k, 0]
        if h < 0 or h % chunks != c:
            continue
        b = ids[k]
        if insert:
            _link(heads, nxt, prv, h, b)
            slot[b] = h
            level[b] = moves[k, 2]
        else:
            _unlink(heads, nxt, prv, h, b)


@njit(cache=True, nogil=True, parallel=True)
def regrid(ids, keys, heads, nxt, prv, slot, level, lvl_count, box, origin, filled, chunks):
    """Move each body of ``ids`` (boxes already set, and each out of its cell: see
    :func:`polycontact._kernels.poses.pose_rows`) to the cell of its box, in a table
    holding ``filled`` cells; stops before it would be more than half full. Returns
    (cells made, bodies done).

    The same table and lists as :func:`grid_remove` then :func:`grid_insert` of each
    body in turn, in ``chunks`` parallel chunks: the cells' keys and slots are looked up
    in parallel, the missing cells made in the order of ``ids``, then each chunk takes
    the bodies out of, and then puts them into, the cell lists of its own slots (a
    list's order depends only on the order of its insertions)."""
    n = ids.shape[0]
    moves = np.empty((n, 5), np.int64)  # old slot, old level, level, key, slot
    if chunks == 1:
        _regrid_probe(ids, keys, slot, level, box, origin, 0, n, moves)
    else:
        for c in prange(chunks):
            _regrid_probe(ids, keys, slot, level, box, origin, n * c // chunks,
                          n * (c + 1) // chunks, moves)
    made = 0
    limit = keys.shape[0] // 2
    for k in range(n):
        if filled + made + 1 > limit:
            return made, k
        key = moves[k, 3]
        if keys[moves[k, 4]] != key:  # (the cell was missing when looked up)
            h = _slot(keys, key)
            if keys[h] == -1:
                keys[h] = key
                heads[h] = -1
                made += 1
            moves[k, 4] = h
        if moves[k, 0] >= 0:
            lvl_count[moves[k, 1]] -= 1
        lvl_count[moves[k, 2]] += 1
    if chunks == 1:
        _regrid_lists(ids, moves, heads, nxt, prv, slot, level, 0, 1, False)
        _regrid_lists(ids, moves, heads, nxt, prv, slot, level, 0, 1, True)
        return made, n
    for c in prange(chunks):
        _regrid_lists(ids, moves, heads, nxt, prv, slot, level, c, chunks, False)
    for c in prange(chunks):
        _regrid_lists(ids, moves, heads, nxt, prv, slot, level, c, chunks, True)
    return made, n


@njit(cache=True, nogil=True)
def _gather(grid, q0, q1, q2, q3, low, n_ids, cand):
    """Bodies whose cell in ``grid`` may hold a box meeting [q0, q1] x [q2, q3], on levels
    >= ``low``, written into ``cand``; returns how many. A level whose cell range is
    larger than its population is scanned body by body instead."""
    keys, heads, nxt, level, lvl_count, levels, origin = grid
    n = 0
    for li in range(levels.shape[0]):
        idx = levels[li]
        if idx < low:
            continue
        c = math.ldexp(1.0, int(idx) - _LEVEL_OFFSET)
        # A body of this level has its box centre in its cell and a half side <= c / 2,
        # so it can meet [q0, q1] only if its centre lies in [q0 - c/2, q1 + c/2]
        # (0.01 c spare for the rounding of the origin's subtraction).
        ix0 = _cell(q0 - origin[0] - 0.51 * c, c)
        ix1 = _cell(q1 - origin[0] + 0.51 * c, c)
        iy0 = _cell(q2 - origin[1] - 0.51 * c, c)
        iy1 = _cell(q3 - origin[1] + 0.51 * c, c)
        if (ix1 - ix0 + 1) * (iy1 - iy0 + 1) > 2 * lvl_count[idx] + 16:
            for b in range(n_ids):
                if level[b] == idx:
                    cand[n] = b
                    n += 1
            continue
        for ix in range(ix0, ix1 + 1):
            for iy in range(iy0, iy1 + 1):
                key = _key(idx, ix, iy)
                h = _slot(keys, key)
                if keys[h] != key:
                    continue
                b = heads[h]
                while b >= 0:
                    cand[n] = b
                    n += 1
                    b = nxt[b]
    return n


@njit(cache=True, nogil=True)
def _meet(box, b, q0, q1, q2, q3):
    """Whether body b's box meets [q0, q1] x [q2, q3]."""
    return not (box[b, 0] > q1 or box[b, 1] < q0 or box[b, 2] > q3 or box[b, 3] < q2)


@njit(cache=True, nogil=True, inline="always")
def body_view(xy, ls, lo, nl, b, buf):
    """Rows of body ``b`` and its loop starts relative to them (written into ``buf``)."""
    first = ls[lo[b]]
    m = nl[b]
    for k in range(m + 1):
        buf[k] = ls[lo[b] + k] - first
    return xy[first : ls[lo[b] + m]], buf[: m + 1]


#: Units of 2**-52 of the terms of a bounding-circle test (the centres' coordinates and
#: paths, the radii) allowed for its rounding: a body's stored rows lie within its
#: bounding radius of its centre up to the rounding of their placing (a few units of
#: those terms), and the test's few operations round by a few units each.
APART_ULPS = 64.0


@njit(cache=True, nogil=True)
def rounding_allowance(ca, cb, reach, travel):
    """What the rounding may take off a test that two bodies about the centres ``ca``
    and ``cb`` stay apart: :data:`APART_ULPS` of the terms the test adds up, the
    centres' coordinates, ``travel`` (what motions add to them) and ``reach`` (the
    bodies' extent along the test, such as the sum of their radii).

    >>> import numpy as np
    >>> float(rounding_allowance(np.zeros(2), np.array([3.0, 0.0]), 2.0, 0.0)) / 2.0**-52
    320.0
    """
    terms = abs(ca[0]) + abs(ca[1]) + abs(cb[0]) + abs(cb[1]) + travel + reach
    return APART_ULPS * 2.0**-52 * terms


@njit(cache=True, nogil=True)
def circles_reach(ca, la, cb, lb, travel, inflate):
    """The distance of the centres ``ca`` and ``cb`` beyond which the bounding circles
    of radii ``la`` and ``lb`` are provably apart: their sum inflated by twice the
    relative ``inflate``, and the :func:`rounding_allowance` of the centres' paths
    (``travel``: what motions add to them).

    >>> import numpy as np
    >>> float(circles_reach(np.zeros(2), 1.0, np.array([3.0, 0.0]), 1.0, 0.0, 0.0)) > 2.0
    True
    """
    big = la + lb
    return big * (1.0 + 2.0 * inflate) + rounding_allowance(ca, cb, big, travel)


@njit(cache=True, nogil=True)
def circles_apart(ca, la, cb, lb, gap, inflate):
    """Whether the bounding circles of radii ``la`` and ``lb`` about ``ca`` and ``cb``
    (inflated by the relative ``inflate``) lie provably more than ``gap`` apart, beyond
    the rounding (:func:`circles_reach` of motionless centres).

    >>> import numpy as np
    >>> bool(circles_apart(np.zeros(2), 1.0, np.array([3.0, 0.0]), 1.0, 0.5, 0.0))
    True
    """
    dx = cb[0] - ca[0]
    dy = cb[1] - ca[1]
    return math.sqrt(dx * dx + dy * dy) > circles_reach(ca, la, cb, lb, 0.0, inflate) + gap


#: What :func:`contact_pairs` returns: the pairs in contact or penetrating, or every
#: candidate pair classified.
TOUCHING = 1
CLASSIFIED = 2


# Compiled without Numba's reference counting (``_nrt=False``): per pair it makes four
# views and passes a dozen arrays to the state kernel, whose atomic reference-count
# updates would cost a large part of a pair's classification. Nothing in it may
# allocate: the buffers are passed in.
@njit(cache=True, nogil=True, _nrt=False)
def _pairs_into(grid, bodies, circles, settings, alive, k0, k1, out, cap, buffers):
    """The pairs that the live bodies ``alive[k0:k1]`` find in the broad phase, with
    their states and tolerances, into ``out`` = ``(pi, pj, states, used)`` up to ``cap``
    of them; returns how many there are (those beyond ``cap`` counted, not written).

    ``circles`` = ``(centres, radii)``: each body's bounding circle (every stored row
    within its radius of its centre, up to the rounding of the placing); ``settings`` =
    ``(tol, emax, margin, n_ids, mode)`` (see :func:`contact_pairs`); ``buffers`` =
    ``(cand, scratch, ba, bb)``: the grid's candidates, the state kernel's scratch and
    the loop starts of the two bodies. Body i finds j when their boxes come within the
    pair's tolerance plus ``margin``, j on a higher level than i's or on the same level
    with j > i (so each pair once); the pair is ``(min, max)``. A pair whose bounding
    circles lie farther apart than its tolerance plus ``margin`` (beyond the rounding,
    :func:`circles_reach`) is passed over unclassified: it is separate, with a gap over
    ``margin``, and neither mode lists it.
    """
    xy, ls, lo, nl, box, eps = bodies
    cen, rad = circles
    tol, emax, margin, n_ids, mode = settings
    level = grid[3]
    oi, oj, ost, oe = out
    cand, scratch, ba, bb = buffers
    n = 0
    for k in range(k0, k1):
        i = alive[k]
        ei = (tol if tol >= 0.0 else eps[i]) + margin
        d = ei + emax
        m = _gather(grid, box[i, 0] - d, box[i, 1] + d, box[i, 2] - d, box[i, 3] + d,
                    level[i], n_ids, cand)
        for t in range(m):
            j = cand[t]
            if j == i or (level[j] == level[i] and j < i):
                continue
            dj = ei + (tol if tol >= 0.0 else eps[j])
            if not _meet(box, j, box[i, 0] - dj, box[i, 1] + dj, box[i, 2] - dj,
                         box[i, 3] + dj):
                continue
            a = min(i, j)
            b = max(i, j)
            e = tol if tol >= 0.0 else max(eps[a], eps[b])
            if circles_apart(cen[a], rad[a], cen[b], rad[b], e + margin, 0.0):
                continue
            ya, sa = body_view(xy, ls, lo, nl, a, ba)
            yb, sb = body_view(xy, ls, lo, nl, b, bb)
            state = state_in(ya, sa, 1.0, yb, sb, 1.0, e, scratch)
            if mode == TOUCHING and state == 0:
                continue
            if n < cap:
                oi[n] = a
                oj[n] = b
                ost[n] = state
                oe[n] = e
            n += 1
    return n


@njit(cache=True, nogil=True)
def _chunk_pairs(grid, bodies, circles, settings, alive, c, chunks, out, cap, vmax, lmax):
    """:func:`_pairs_into` of chunk ``c`` of ``chunks`` with its buffers, for bodies of
    up to ``vmax`` vertices and ``lmax`` loops: its blocks of ``alive``
    (:mod:`polycontact._kernels.spread`), their pairs one after another."""
    buffers = (np.empty(settings[3], np.int64), state_scratch(2 * vmax),
               np.empty(lmax + 1, np.int64), np.empty(lmax + 1, np.int64))
    n = alive.shape[0]
    if chunks == 1:
        return _pairs_into(grid, bodies, circles, settings, alive, 0, n, out, cap, buffers)
    oi, oj, ost, oe = out
    m = 0
    for b in range(c, SPREAD * chunks, chunks):
        k0, k1 = block(n, chunks, b)
        w = min(m, cap)
        m += _pairs_into(grid, bodies, circles, settings, alive, k0, k1,
                         (oi[w:], oj[w:], ost[w:], oe[w:]), cap - w, buffers)
    return m


@njit(cache=True, nogil=True, parallel=True)
def contact_pairs(grid, bodies, circles, tol, alive, n_ids, margin, mode, vmax, lmax, chunks):
    """The pairs of live bodies whose boxes come within their tolerance plus
    ``margin``, classified by the state kernel, in parallel chunks of ``alive``
    (``chunks`` = 1: serial, no thread start): ``(pairs (P, 2), states (P,) int8,
    tolerances (P,))``, the pairs ``(i, j)`` with i < j, sorted. ``mode``:
    :data:`TOUCHING` (those in contact or penetrating) or :data:`CLASSIFIED` (every
    such pair, but those whose bounding circles are farther apart than their tolerance
    plus ``margin``: separate, by more than ``margin``). ``tol`` < 0: each pair's
    default tolerance, the larger of its bodies' ``eps``. ``grid`` and ``bodies`` are
    the World's records (see the module's docstring), ``circles`` = ``(centres,
    radii)`` the bodies' bounding circles; ``n_ids`` bounds the ids.

    Each chunk writes its pairs into a buffer of its own, sized for four per body (a
    chunk that finds more is run again into the output once the counts are known);
    the counts give each chunk its place in the output, and the pairs are sorted by
    :func:`sorted_pairs`: the answer does not depend on the chunks.
    """
    eps = bodies[5]
    n = alive.shape[0]
    emax = tol
    if tol < 0.0 and chunks == 1:
        emax = _largest(eps, alive, 0, n)
    elif tol < 0.0:
        part = np.empty(chunks)
        for c in prange(chunks):
            part[c] = _largest(eps, alive, n * c // chunks, n * (c + 1) // chunks)
        emax = part.max()
    settings = (tol, emax, margin, n_ids, mode)
    cap = 4 * ((n + chunks - 1) // chunks) + 16
    bi = np.empty((chunks, cap), np.int64)
    bj = np.empty((chunks, cap), np.int64)
    bs = np.empty((chunks, cap), np.int8)
    be = np.empty((chunks, cap))
    count = np.zeros(chunks, np.int64)
    if chunks == 1:
        m = _chunk_pairs(grid, bodies, circles, settings, alive, 0, 1,
                         (bi[0], bj[0], bs[0], be[0]), cap, vmax, lmax)
        if m <= cap:
            return sorted_pairs(bi[0, :m], bj[0, :m], bs[0, :m], be[0, :m], n_ids, 1)
        out = (np.empty(m, np.int64), np.empty(m, np.int64), np.empty(m, np.int8),
               np.empty(m))
        _chunk_pairs(grid, bodies, circles, settings, alive, 0, 1, out, m, vmax, lmax)
        return sorted_pairs(out[0], out[1], out[2], out[3], n_ids, 1)
    for c in prange(chunks):
        count[c] = _chunk_pairs(grid, bodies, circles, settings, alive, c, chunks,
                                (bi[c], bj[c], bs[c], be[c]), cap, vmax, lmax)
    start = np.zeros(chunks + 1, np.int64)
    for c in range(chunks):
        start[c + 1] = start[c] + count[c]
    total = start[chunks]
    pi = np.empty(total, np.int64)
    pj = np.empty(total, np.int64)
    states = np.empty(total, np.int8)
    used = np.empty(total)
    for c in prange(chunks):
        s0 = start[c]
        s1 = start[c + 1]
        if s1 - s0 <= cap:
            pi[s0:s1] = bi[c, : s1 - s0]
            pj[s0:s1] = bj[c, : s1 - s0]
            states[s0:s1] = bs[c, : s1 - s0]
            used[s0:s1] = be[c, : s1 - s0]
        else:
            _chunk_pairs(grid, bodies, circles, settings, alive, c, chunks,
                         (pi[s0:s1], pj[s0:s1], states[s0:s1], used[s0:s1]), s1 - s0,
                         vmax, lmax)
    return sorted_pairs(pi, pj, states, used, n_ids, chunks)


@njit(cache=True, nogil=True)
def _largest(eps, alive, k0, k1):
    """The largest ``eps`` of the bodies ``alive[k0:k1]`` (0 for none)."""
    m = 0.0
    for k in range(k0, k1):
        m = max(m, eps[alive[k]])
    return m


@njit(cache=True, nogil=True)
def _order(pi, pj, n_ids):
    """The order that sorts the distinct pairs ``(pi[k], pj[k])`` (ids below
    ``n_ids``): by one key where ``pi * n_ids + pj`` fits int64, else by pj then
    (stably) pi."""
    if n_ids < 3037000499:  # (n_ids**2 < 2**63)
        return np.argsort(pi * n_ids + pj)
    first = np.argsort(pj, kind="mergesort")
    return first[np.argsort(pi[first], kind="mergesort")]


@njit(cache=True, nogil=True, parallel=True)
def sorted_pairs(pi, pj, states, used, n_ids, chunks):
    """The distinct pairs ``(pi[k], pj[k])`` (ids below ``n_ids``) sorted, as ``(pairs
    (P, 2), states, used)``, their ``states`` and ``used`` in the same order; in
    ``chunks`` parallel chunks: the pairs go to ``chunks`` buckets of ``pi`` (counted,
    then placed, chunk by chunk), and each bucket is sorted apart. The pairs being
    distinct, the order does not depend on the chunks."""
    p_count = pi.shape[0]
    pairs = np.empty((p_count, 2), np.int64)
    st = np.empty(p_count, np.int8)
    us = np.empty(p_count)
    if chunks == 1:
        order = _order(pi, pj, n_ids)
        for t in range(p_count):
            k = order[t]
            pairs[t, 0] = pi[k]
            pairs[t, 1] = pj[k]
            st[t] = states[k]
            us[t] = used[k]
        return pairs, st, us
    # bucket b holds the pairs whose pi is in [n_ids * b / chunks, n_ids * (b + 1) / chunks)
    count = np.zeros((chunks, chunks), np.int64)
    for c in prange(chunks):
        for k in range(p_count * c // chunks, p_count * (c + 1) // chunks):
            count[c, pi[k] * chunks // n_ids] += 1
    place = np.empty((chunks, chunks), np.int64)
    edge = np.empty(chunks + 1, np.int64)
    w = 0
    for b in range(chunks):
        edge[b] = w
        for c in range(chunks):
            place[c, b] = w
            w += count[c, b]
    edge[chunks] = w
    src = np.empty(p_count, np.int64)
    for c in prange(chunks):
        at = place[c].copy()
        for k in range(p_count * c // chunks, p_count * (c + 1) // chunks):
            b = pi[k] * chunks // n_ids
            src[at[b]] = k
            at[b] += 1
    for b in prange(chunks):
        part = src[edge[b] : edge[b + 1]]
        order = _order(pi[part], pj[part], n_ids)
        for t in range(part.shape[0]):
            k = part[order[t]]
            pairs[edge[b] + t, 0] = pi[k]
            pairs[edge[b] + t, 1] = pj[k]
            st[edge[b] + t] = states[k]
            us[edge[b] + t] = used[k]
    return pairs, st, us


@njit(cache=True, nogil=True)
def _container_state(ya, sa, qbox, e, hazards, hbuf, scratch):
    """0 inside, 1 touching the boundary, 2 outside or crossing: A (box ``qbox``, as
    ``(x0, x1, y0, y1)``) against the hazards (the frame around the container's outer
    loop, and its holes)."""
    if _off_box(qbox, e, hazards[4]):
        return 2
    return _hazard_state(ya, sa, e, hazards, hbuf, scratch)


@njit(cache=True, nogil=True)
def _off_box(qbox, e, cbox):
    """Does the box ``qbox`` leave the container's box by more than ``e``?"""
    bx0, bx1, by0, by1 = qbox
    return bx0 < cbox[0] - e or bx1 > cbox[1] + e or by0 < cbox[2] - e or by1 > cbox[3] + e


@njit(cache=True, nogil=True)
def _hazard_state(ya, sa, e, hazards, hbuf, scratch):
    """Worst state of A against the container's hazards (its box not left: see
    :func:`_off_box`)."""
    hxy, hls, hlo, hnl, _, _ = hazards
    worst = 0
    for h in range(hnl.shape[0]):
        yh, sh = body_view(hxy, hls, hlo, hnl, h, hbuf)
        s = state_in(ya, sa, 1.0, yh, sh, 1.0, e, scratch)
        if s > worst:
            worst = s
            if worst == 2:
                break
    return worst


@njit(cache=True, nogil=True, parallel=True)
def container_states(bodies, tol, alive, hazards, vmax, lmax, hmax, chunks):
    """Container state (0, 1, 2) of every live body, in parallel chunks."""
    xy, ls, lo, nl, box, eps = bodies
    hnl, ceps = hazards[3], hazards[5]
    n = alive.shape[0]
    out = np.empty(n, np.int8)
    for c in prange(chunks):  # few bodies: chunks = 1, one thread
        scratch = state_scratch(vmax + hmax)
        ba = np.empty(lmax + 1, np.int64)
        hb = np.empty(hnl.max() + 1, np.int64)
        for q in range(c, SPREAD * chunks, chunks):
            k0, k1 = block(n, chunks, q)
            for k in range(k0, k1):
                b = alive[k]
                ya, sa = body_view(xy, ls, lo, nl, b, ba)
                e = tol if tol >= 0.0 else max(eps[b], ceps)
                out[k] = _container_state(ya, sa, (box[b, 0], box[b, 1], box[b, 2],
                                                   box[b, 3]), e, hazards, hb, scratch)
    return out


@njit(cache=True, nogil=True, inline="always")
def _state_against(qxy, qs, qbox, qeps, j, bodies, tol, buf, scratch):
    """State of the placed shape ``(qxy, qs)`` (box ``qbox``, tolerance term ``qeps``)
    against body j; 0 when their boxes are farther apart than the pair's tolerance."""
    xy, ls, lo, nl, box, eps = bodies
    x0, x1, y0, y1 = qbox
    e = tol if tol >= 0.0 else max(qeps, eps[j])
    if not _meet(box, j, x0 - e, x1 + e, y0 - e, y1 + e):
        return 0
    yb, sb = body_view(xy, ls, lo, nl, j, buf)
    return state_in(qxy, qs, 1.0, yb, sb, 1.0, e, scratch)


@njit(cache=True, nogil=True)
def query_states(query, grid, bodies, tol, emax, n_ids, vmax, lmax):
    """Ids and states of the bodies the placed shape ``query`` = ``(qxy, qs, qeps)``
    (its packed loops and its default-tolerance term) touches or penetrates."""
    qxy, qs, qeps = query
    n = qs[qs.shape[0] - 1]
    qbox = bbox(qxy, n)
    x0, x1, y0, y1 = qbox
    cand = np.empty(n_ids, np.int64)
    e0 = tol if tol >= 0.0 else qeps
    d = e0 + (tol if tol >= 0.0 else emax)
    m = _gather(grid, x0 - d, x1 + d, y0 - d, y1 + d, 0, n_ids, cand)
    scratch = state_scratch(n + vmax)
    buf = np.empty(lmax + 1, np.int64)
    out_ids = np.empty(m, np.int64)
    out_st = np.empty(m, np.int8)
    k = 0
    for t in range(m):
        s = _state_against(qxy, qs, qbox, qeps, cand[t], bodies, tol, buf, scratch)
        if s > 0:
            out_ids[k] = cand[t]
            out_st[k] = s
            k += 1
    order = np.argsort(out_ids[:k])
    return out_ids[:k][order], out_st[:k][order]


@njit(cache=True, nogil=True)
def query_container(query, tol, hazards):
    """Container state of one placed shape ``query`` = ``(qxy, qs, qeps)`` (see
    :func:`_container_state`)."""
    qxy, qs, qeps = query
    _, hls, hlo, hnl, _, ceps = hazards
    n = qs[qs.shape[0] - 1]
    hmax = 0
    for h in range(hnl.shape[0]):
        hmax = max(hmax, hls[hlo[h] + hnl[h]] - hls[hlo[h]])
    scratch = state_scratch(n + hmax)
    hb = np.empty(hnl.max() + 1, np.int64)
    e = tol if tol >= 0.0 else max(qeps, ceps)
    return _container_state(qxy, qs, bbox(qxy, n), e, hazards, hb, scratch)


@njit(cache=True, nogil=True)
def _query_range(shape, poses, grid, bodies, hazards, settings, scan, c, chunks, out):
    """:func:`query_many` for the poses of chunk ``c`` of ``chunks`` (its blocks,
    :mod:`polycontact._kernels.spread`), into ``out``: the buffers, then
    :func:`_query_into` for each block."""
    ss = shape[1]
    n_ids, vmax, lmax, hmax = settings[4], settings[5], settings[6], settings[8]
    hnl = hazards[3]
    n = ss[ss.shape[0] - 1]
    buffers = (np.empty((n, 2)), np.empty(n_ids, np.int64), state_scratch(n + max(vmax, hmax)),
               np.empty(lmax + 1, np.int64),
               np.empty(hnl.max() + 1 if hnl.shape[0] else 1, np.int64))
    for b in range(c, SPREAD * chunks, chunks):
        p0, p1 = block(poses[0].shape[0], chunks, b)
        _query_into(shape, poses, grid, bodies, hazards, settings, scan, p0, p1, out, buffers)


# Compiled without Numba's reference counting (``_nrt=False``): per placement and
# candidate body it reads the records' arrays and makes views of the body, and their
# atomic reference counts cost as much as the test of a separate pair. Nothing in it may
# allocate: the buffers are passed in.
@njit(cache=True, nogil=True, _nrt=False)
def _query_into(shape, poses, grid, bodies, hazards, settings, scan, p0, p1, out, buffers):
    """The loop of :func:`_query_range` with its ``buffers``: ``(qxy, cand, scratch, buf,
    hbuf)``, the placed shape, the grid's candidates, the state kernel's scratch and the
    loop starts of a body and of a hazard."""
    sxy, ss, cx, cy = shape
    px, py, angles = poses
    rel, ulp_factor, tol, emax, n_ids, _, _, has_container, _ = settings
    cbox, ceps = hazards[4], hazards[5]
    qxy, cand, scratch, buf, hb = buffers
    n = ss[ss.shape[0] - 1]
    for p in range(p0, p1):
        place(sxy, cx, cy, px[p], py[p], angles[p], qxy)
        qbox = bbox(qxy, n)
        x0, x1, y0, y1 = qbox
        mag = max(max(-x0, x1), max(-y0, y1))
        qeps = max(rel * max(x1 - x0, y1 - y0), ulp_factor * mag)
        worst = 0
        ec = tol if tol >= 0.0 else max(qeps, ceps)
        if has_container and _off_box(qbox, ec, cbox):
            worst = 2
        # The bodies before the container's hazards: in a dense layout most placements
        # penetrate a body, and then the hazards (a state kernel call) are not needed.
        if worst < 2:
            e0 = tol if tol >= 0.0 else qeps
            d = e0 + (tol if tol >= 0.0 else emax)
            if scan.shape[0]:
                m = scan.shape[0]
                src = scan
            else:
                m = _gather(grid, x0 - d, x1 + d, y0 - d, y1 + d, 0, n_ids, cand)
                src = cand
            for t in range(m):
                s = _state_against(qxy, ss, qbox, qeps, src[t], bodies, tol, buf, scratch)
                if s > worst:
                    worst = s
                    if worst == 2:
                        break
        if has_container and worst < 2:
            worst = max(worst, _hazard_state(qxy, ss, ec, hazards, hb, scratch))
        out[p] = worst


@njit(cache=True, nogil=True, parallel=True)
def query_many(shape, poses, grid, bodies, hazards, settings, scan, chunks):
    """Worst state (int8) of ``shape`` = ``(sxy, ss, cx, cy)`` (its packed loops and the
    point it turns about) placed at each of ``poses`` = ``(px, py, angles)`` over every
    body and the container (outside counts as 2); ``chunks`` = 1: serial.

    ``settings`` = ``(rel, ulp_factor, tol, emax, n_ids, vmax, lmax, has_container,
    hmax)``: the default-tolerance rule (its relative and float-spacing factors), the
    tolerance (< 0: each pair's default), the largest body term, the store's sizes
    (ids, most vertices, most loops of a body), whether ``hazards`` is a container, and
    the most vertices of a hazard. ``scan``: the live bodies, to be tested box by box
    instead of through the grid (a few bodies), or empty (use the grid)."""
    p_count = poses[0].shape[0]
    out = np.empty(p_count, np.int8)
    if chunks == 1:
        _query_range(shape, poses, grid, bodies, hazards, settings, scan, 0, 1, out)
        return out
    for c in prange(chunks):
        _query_range(shape, poses, grid, bodies, hazards, settings, scan, c, chunks, out)
    return out
