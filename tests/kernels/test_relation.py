"""The relation kernels against plain NumPy / Shapely references, on small inputs.

Also run as plain Python (NUMBA_DISABLE_JIT=1) by the CI script.
"""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from catalogue import CASES, SMALL_FAR_RING, boundary_gap, pairs, shapely_state
from hypothesis import example, given
from hypothesis import strategies as st

from polycontact import Shape
from polycontact._depth import penetration
from polycontact._kernels import distance as kdist
from polycontact._kernels import features as kfeat
from polycontact._kernels import relation as kr
from polycontact._kernels import relation_many as km
from polycontact._kernels import rings as kring
from polycontact._kernels import sweep as ksweep
from polycontact.errors import InvalidShapeError
from polycontact.tolerances import (
    COORDINATE_LIMIT,
    EXTENT_FLOOR,
    RELATIVE_TOLERANCE,
    ROUNDING_ULPS,
    default_tolerance,
)

STATE_NAMES = ("separate", "contact", "penetrating")
#: The default-tolerance rule and the coordinate range, as the ring kernels take them.
RING = (RELATIVE_TOLERANCE, ROUNDING_ULPS, COORDINATE_LIMIT, EXTENT_FLOOR)


def _eps(a: Shape, b: Shape) -> float:
    return default_tolerance(a.packed[0], b.packed[0])


def _raw_states(xa: np.ndarray, xb: np.ndarray) -> tuple[np.ndarray, ...]:
    """:func:`km.raw_states` of rings ``xa`` against ``xb`` with the default tolerance."""
    return km.raw_states(xa, xb, -1.0, *RING, km.raw_states_outputs(xa.shape[0]))


@pytest.mark.parametrize("case", CASES, ids=lambda c: c.name)
def test_relate_state_catalogue(case):
    a, b = case.a, case.b
    assert STATE_NAMES[kr.relate_state(*a.packed, *b.packed, _eps(a, b))] == case.state


@given(pairs(grid=True))
def test_relate_state_matches_shapely_on_grid(pair):
    a, b, _ = pair
    eps = _eps(a, b)
    assert STATE_NAMES[kr.relate_state(*a.packed, *b.packed, eps)] == shapely_state(a, b)
    assert kr.relate_state(*b.packed, *a.packed, eps) == kr.relate_state(*a.packed, *b.packed, eps)


@given(pairs())
def test_boundary_distance_and_closest_pair(pair):
    a, b, _ = pair
    want = boundary_gap(a, b)
    assert kdist.boundary_distance(*a.packed, *b.packed) == pytest.approx(want, rel=1e-9,
                                                                          abs=1e-12)
    d, xa, ya, xb, yb = kdist.closest_pair(*a.packed, *b.packed)
    assert np.hypot(xa - xb, ya - yb) == pytest.approx(d, rel=1e-9, abs=1e-12)
    on_a = shapely.distance(shapely.Point(xa, ya), a.to_shapely().boundary)
    on_b = shapely.distance(shapely.Point(xb, yb), b.to_shapely().boundary)
    assert on_a <= 1e-9 and on_b <= 1e-9


@given(
    st.lists(st.integers(-5, 5), min_size=4, max_size=4),
    st.lists(st.integers(1, 4), min_size=4, max_size=4),
)
def test_penetration_of_boxes_is_the_smallest_overlap(corner, size):
    ax, ay, bx, by = corner
    wa, ha, wb, hb = size
    a = Shape(shapely.box(ax, ay, ax + wa, ay + ha).exterior.coords[:-1])
    b = Shape(shapely.box(bx, by, bx + wb, by + hb).exterior.coords[:-1])
    ox = min(ax + wa, bx + wb) - max(ax, bx)
    oy = min(ay + ha, by + hb) - max(ay, by)
    if ox <= 0 or oy <= 0:
        return
    # leave along x: right (bx + wb - ax) or left (ax + wa - bx); same along y
    want = min(bx + wb - ax, ax + wa - bx, by + hb - ay, ay + ha - by)
    depth, dx, dy = penetration(*a.packed, *b.packed, _eps(a, b))
    assert depth == pytest.approx(want)
    assert np.hypot(dx, dy) == pytest.approx(depth)
    moved = a.packed[0] + np.array([dx, dy])
    assert kr.relate_state(moved, a.packed[1], *b.packed, _eps(a, b)) != kr.PENETRATING


@given(pairs(n_max=7))
def test_penetration_escape_ends_the_overlap(pair):
    a, b, _ = pair
    eps = _eps(a, b)
    if kr.relate_state(*a.packed, *b.packed, eps) != kr.PENETRATING:
        return
    depth, dx, dy = penetration(*a.packed, *b.packed, eps)
    moved = a.packed[0] + np.array([dx, dy])
    assert kr.relate_state(moved, a.packed[1], *b.packed, eps) != kr.PENETRATING
    # the escape is no longer than leaving B's bounding box along an axis
    (ax0, ay0), (ax1, ay1) = a.packed[0].min(0), a.packed[0].max(0)
    (bx0, by0), (bx1, by1) = b.packed[0].min(0), b.packed[0].max(0)
    assert depth <= min(bx1 - ax0, ax1 - bx0, by1 - ay0, ay1 - by0) + 1e-12


def _reference_touches(xv: np.ndarray, other: Shape, eps: float) -> set[tuple[int, int]]:
    """Vertex-on-edge pairs by plain NumPy: every vertex against every edge."""
    xo, so = other.packed
    nxt = np.concatenate([np.roll(np.arange(so[k], so[k + 1]), -1) for k in range(len(so) - 1)])
    p, q = xo, xo[nxt]
    u = q - p
    out = set()
    for i, v in enumerate(xv):
        t = np.clip(np.einsum("ij,ij->i", v - p, u) / np.einsum("ij,ij->i", u, u), 0, 1)
        d = np.hypot(*(p + t[:, None] * u - v).T)
        out |= {(i, int(e)) for e in np.flatnonzero(d <= eps)}
    return out


@given(pairs())
def test_features_kernel_against_numpy(pair):
    a, b, _ = pair
    eps = _eps(a, b)
    a_on, b_on, a_in, b_in, cross = kfeat.features(*a.packed, *b.packed, eps)
    assert {(v, e) for v, e, _ in a_on} == _reference_touches(a.packed[0], b, eps)
    assert {(v, e) for v, e, _ in b_on} == _reference_touches(b.packed[0], a, eps)
    pb, pa = b.to_shapely(), a.to_shapely()
    for rows, xv, poly in ((a_in, a.packed[0], pb), (b_in, b.packed[0], pa)):
        inside = {i for i, v in enumerate(xv) if poly.contains(shapely.Point(v))}
        on = {v for v, _, _ in (a_on if poly is pb else b_on)}
        assert {v for v, _, _ in rows} == inside - on
    for e, f, x, y in cross:
        assert shapely.distance(shapely.Point(x, y), pa.boundary) <= 1e-9
        assert shapely.distance(shapely.Point(x, y), pb.boundary) <= 1e-9


@given(st.lists(st.floats(-100, 100), min_size=0, max_size=60))
@example(list(range(32, 0, -1)))                 # reversed: the heap-sort fallback
@example([1.0] * 20 + [0.0] * 20 + [0.5] * 20)   # bunched keys, bucket pass then fallback
def test_sort_into_orders_rows_by_xmin(keys):
    box = np.zeros((len(keys), 4))
    box[:, 0] = keys
    order = np.empty(len(keys), np.int64)
    ksweep.sort_into(box, len(keys), order, np.empty(len(keys) + 1, np.int64))
    assert sorted(order.tolist()) == list(range(len(keys)))
    assert np.all(np.diff(box[order, 0]) >= 0)


@given(
    st.lists(st.integers(1, 6), min_size=25, max_size=48),
    st.integers(0, 3),
    st.tuples(st.integers(0, 47), st.integers(0, 47)),
)
def test_long_ring_sweep_agrees_with_all_pairs(radii, snap, swap):
    # Star rings on a coarse grid, some with two vertices swapped: many touch or cross
    # themselves (and bunched keys exercise the sort's fallback); the sweep must agree
    # with the all-pairs check.
    t = np.linspace(0.0, 2.0 * np.pi, len(radii), endpoint=False)
    ring = np.c_[np.cos(t), np.sin(t)] * np.array(radii, dtype=float)[:, None]
    if snap:
        ring = np.round(ring * snap) / snap
    i, j = swap[0] % len(ring), swap[1] % len(ring)
    ring[[i, j]] = ring[[j, i]]
    n = len(ring)
    eps = default_tolerance(ring)
    folds = any(
        kring._folds(*ring[i - 1], *ring[i], *ring[(i + 1) % n], eps) for i in range(n)
    )
    expected = not folds and kring._small_ring_is_simple(ring, n, eps)
    assert kring._ring_is_simple(ring, n, eps) == expected
    rows = ksweep.sorted_edge_boxes(ring, n)
    assert sorted(rows[:, 4].astype(int).tolist()) == list(range(n))
    assert np.all(np.diff(rows[:, 0]) >= 0)


def _full_ring_check(ring, eps):
    n = len(ring)
    folds = any(kring._folds(*ring[i - 1], *ring[i], *ring[(i + 1) % n], eps) for i in range(n))
    return not folds and kring._small_ring_is_simple(ring, n, eps)


@given(
    st.lists(st.tuples(st.floats(1e-3, 1.0), st.sampled_from([1.0, 0.5, 1e-9, 1e-12, 1e-14])),
             min_size=3, max_size=14),
    st.sampled_from([1, 2, 3]),
    st.floats(-1.0, 1.0),
    st.sampled_from([1.0, 1e6]),
    st.booleans(),
)
def test_star_certificate_is_never_wrong(steps, turns, shift, scale, clockwise):
    # Rings whose vertices step round a point (some once, some two or three times
    # round, like a pentagram), with angular steps down to 1e-14 and radii
    # far apart, at two scales and both orientations: whenever the O(n) star test
    # certifies a ring, the all-pairs check must call it simple.
    gaps = np.array([g * w for g, w in steps])
    ang = np.cumsum(gaps) / gaps.sum() * 2.0 * np.pi * turns
    rad = np.array([0.2 + g for g, _ in steps])
    ring = np.c_[np.cos(ang) * rad + shift, np.sin(ang) * rad] * scale
    if clockwise:
        ring = ring[::-1].copy()
    eps = default_tolerance(ring)
    if kring._star_ring_is_simple(ring, len(ring), eps):
        assert _full_ring_check(ring, eps)
        assert shapely.Polygon(ring).is_valid


def test_star_certificate_fires_on_convex_and_star_rings():
    t = np.linspace(0.0, 2.0 * np.pi, 12, endpoint=False)
    convex = np.c_[np.cos(t), np.sin(t)] * 3.0 + 100.0
    star = np.c_[np.cos(t), np.sin(t)] * np.where(np.arange(12) % 2, 1.0, 0.4)[:, None]
    k = np.arange(5) * 4.0 * np.pi / 5.0
    pentagram = np.c_[np.cos(k), np.sin(k)]
    comb = np.array([[0, 0], [3, 0], [3, 1], [2, 1], [2, 0.2], [1, 0.2], [1, 1], [0, 1.0]])
    for ring, certified in ((convex, True), (star, True), (convex[::-1], True),
                            (pentagram, False), (comb, False)):
        eps = default_tolerance(ring)
        assert kring._star_ring_is_simple(ring, len(ring), eps) == certified
        assert kring._ring_is_simple(ring, len(ring), eps) == _full_ring_check(ring, eps)


@given(st.lists(st.tuples(st.integers(-4, 4), st.integers(-4, 4)), min_size=3, max_size=9))
def test_raw_ring_agrees_with_shape(points):
    ring = np.array(points, dtype=float)
    n, sign, eps, box = kring.raw_ring(ring, *RING)
    try:
        shape = Shape(ring)
    except InvalidShapeError:
        assert n == -1
        return
    distinct = np.any(ring != np.roll(ring, 1, axis=0), axis=1).all()
    if distinct:  # repeated vertices are left to Shape, which drops them
        assert n == len(ring)
        assert sign == (1.0 if np.array_equal(shape.exterior, ring) else -1.0)
        assert eps == default_tolerance(ring)
        assert box == (ring[:, 0].min(), ring[:, 0].max(), ring[:, 1].min(), ring[:, 1].max())


def test_classify_raw_orientation_and_codes():
    sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    bow = np.array([[0.0, 0.0], [1.0, 1.0], [1.0, 0.0], [0.0, 1.0]])
    assert kring.classify_raw(sq, sq[::-1] + 1.0, -1.0, *RING)[0] == kr.CONTACT
    assert kring.classify_raw(sq, sq[::-1] + 0.5, -1.0, *RING)[0] == kr.PENETRATING
    assert kring.classify_raw(bow, sq, -1.0, *RING)[0] == -1
    assert kring.classify_raw(sq, bow, -1.0, *RING)[0] == -2
    closed = np.vstack([sq, sq[:1]])
    code, eps, na, fa, nb, fb = kring.classify_raw(closed, sq[::-1] + 3.0, 0.5, *RING)
    assert (code, eps, na, fa, nb, fb) == (kr.SEPARATE, 0.5, 4, 1.0, 4, -1.0)


@given(st.lists(pairs(n_max=6), min_size=1, max_size=5))
def test_many_kernels_match_single(many):
    def pack(shapes):
        xy = np.concatenate([s.packed[0] for s in shapes])
        ls, bs, row = [], [0], 0
        for s in shapes:
            ls += (s.packed[1] + row).tolist()
            row += len(s.packed[0])
            bs.append(len(ls))
        return xy, np.array(ls), np.array(bs), np.ones(len(shapes))

    sa = [p[0] for p in many]
    sb = [p[1] for p in many]
    pa, pb = pack(sa), pack(sb)
    states, eps = km.many_states(*pa, *pb, -1.0, RELATIVE_TOLERANCE, ROUNDING_ULPS)
    want = [kr.relate_state(*a.packed, *b.packed, _eps(a, b)) for a, b in zip(sa, sb)]
    assert states.tolist() == want
    dist = km.many_distances(*pa, *pb, states, eps)
    for d, s, a, b in zip(dist, states, sa, sb):
        if s == kr.SEPARATE:
            assert d == pytest.approx(kdist.boundary_distance(*a.packed, *b.packed))
        elif s == kr.CONTACT:
            assert d == 0.0
        else:
            assert np.isnan(d)  # the depth is the caller's (RelationBatch.distances)


@given(st.lists(pairs(n_max=6, holes=False), min_size=1, max_size=5), st.booleans())
def test_raw_states_matches_single_pairs(many, closed):
    """The fused validate-and-classify kernel of (P, N, 2) arrays against classify_raw:
    each pair in both orientations of A and of B (closed rings repeat their first
    vertex at the end, which the kernel drops)."""
    for a, b, _ in many:
        def rows(shape):
            ring = np.vstack([shape.exterior, shape.exterior[:1]]) if closed else shape.exterior
            return [ring, np.ascontiguousarray(ring[::-1])]

        ra, rb = rows(a), rows(b)
        xa = np.stack([ra[0], ra[1], ra[0], ra[1]])
        xb = np.stack([rb[0], rb[0], rb[1], rb[1]])
        got = _raw_states(xa, xb)
        for p in range(4):
            want = kring.classify_raw(xa[p], xb[p], -1.0, *RING)
            assert tuple(g[p] for g in got) == want


def test_raw_states_flags_invalid_rings():
    sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    bow = np.array([[0.0, 0.0], [1.0, 1.0], [1.0, 0.0], [0.0, 1.0]])
    states, _, used_a, _, used_b, _ = _raw_states(np.stack([sq, bow, sq]),
                                                  np.stack([sq + 0.5, sq, bow]))
    assert states.tolist() == [2, -1, -1]
    assert used_a.tolist() == [4, -1, 4] and used_b.tolist() == [4, 4, -1]
    # a lopsided bow-tie (nonzero signed area, clockwise by it): invalid, with the sign
    # _raw_ring gives an invalid ring, whichever way its area turns
    lop = np.array([[0.0, 0.0], [2.0, 2.0], [2.0, 0.0], [0.0, 1.0]])
    _, _, used_a, sign_a, _, _ = _raw_states(lop[None], sq[None])
    assert used_a[0] == -1 and sign_a[0] == kring.raw_ring(lop, *RING)[1] == 1.0


def _comb(teeth: int) -> np.ndarray:
    """A comb of 4·teeth + 2 vertices: simple, and not star-shaped about any point."""
    top = [(x + dx, y) for x in range(teeth)
           for dx, y in ((0.0, 1.0), (0.5, 1.0), (0.5, 0.3), (1.0, 0.3))]
    return np.array([(0.0, -1.0), *top, (teeth, -1.0)])


def test_raw_states_long_rings_that_need_the_sweep():
    # Rings of more than 24 vertices that the O(n) certificate cannot pass are left to
    # the sorted sweep after the pass: valid ones are classified, a crossing one flagged.
    comb = _comb(8)
    crossed = comb.copy()
    crossed[[5, 9]] = crossed[[9, 5]]
    t = np.linspace(0.0, 2.0 * np.pi, len(comb), endpoint=False)
    star = np.c_[np.cos(t), np.sin(t)] * np.where(np.arange(len(t)) % 2, 3.0, 2.0)[:, None]
    xa = np.stack([comb, comb, star, crossed, star])
    xb = np.stack([comb + [0.25, 0.5], star + [12.0, 0.0], comb, star, crossed])
    states, eps, used_a, sign_a, used_b, sign_b = _raw_states(xa, xb)
    assert states.tolist()[3:] == [-1, -1]
    assert used_a.tolist()[3] == -1 and used_b.tolist()[4] == -1
    assert sign_a[3] == kring.raw_ring(crossed, *RING)[1] == sign_b[4]
    for p in range(3):
        want = kring.classify_raw(xa[p], xb[p], -1.0, *RING)
        assert (states[p], eps[p], used_a[p], sign_a[p], used_b[p], sign_b[p]) == want
    assert states.tolist()[:3] == [2, 0, 2]


def test_raw_ring_small_ring_far_from_the_origin():
    # area 2e-4 at (82, 70): valid, counter-clockwise, its box exact
    n, sign, eps, box = kring.raw_ring(SMALL_FAR_RING, *RING)
    assert (n, sign) == (len(SMALL_FAR_RING), 1.0)
    assert box[1] == SMALL_FAR_RING[:, 0].max() and eps == default_tolerance(SMALL_FAR_RING)


@given(st.floats(0.0, 1e100), st.floats(0.0, 1e100))
def test_kernel_tolerance_is_the_python_formula(extent, magnitude):
    from polycontact._kernels import tolerance as kt
    from polycontact.tolerances import tolerance_for

    got = kt.tolerance_for(extent, magnitude, RELATIVE_TOLERANCE, ROUNDING_ULPS)
    assert got == tolerance_for(extent, magnitude)  # bit for bit


@given(pairs(holes=False))
def test_pair_tolerance_is_default_tolerance(pair):
    a, b, _ = pair
    na, _, _, ba = kring.raw_ring(a.exterior, *RING)
    nb, _, _, bb = kring.raw_ring(b.exterior, *RING)
    assert na > 0 and nb > 0
    want = default_tolerance(a.exterior, b.exterior)
    assert kring.pair_tolerance(ba, bb, RELATIVE_TOLERANCE, ROUNDING_ULPS) == want
    assert kring.classify_raw(a.exterior, b.exterior, -1.0, *RING)[1] == want


def test_raw_ring_refuses_out_of_range_without_overflow():
    sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    # (as plain Python, CI's NUMBA_DISABLE_JIT run: the star-shaped check squared cross
    # products of coordinates, which overflowed at 1e90 and underflowed at 1e-90)
    with np.errstate(all="raise"):
        for ring in (sq * 1e200, sq * 1e-300, sq + [np.nan, 0.0], sq + [0.0, np.inf]):
            assert kring.raw_ring(ring, *RING)[0] == -1
        assert kring.raw_ring(sq * 1e-90, *RING)[0] == 4
        assert kring.raw_ring(sq * 1e90, *RING)[0] == 4
