"""Penetration depths of many pairs (``classify_many(...).distances``).

The batch computes each distinct body's convex pieces once and each distinct pair once,
in compiled code, and clips the sums' edges without the grid of cells when there are
few sums. The oracles: the pairwise :func:`polycontact.classify` (its depth is checked
against pyclipper's Minkowski sums in ``test_depth.py``), the same clipper oracle here,
and the grid path of the same kernel.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from profiles import examples
from .test_depth import _clipper_depth

import polycontact as pc
from polycontact import limits
from polycontact._kernels import depth as kd
from polycontact._pieces import pieces_packed
from polycontact.limits import MAX_SUM_VERTICES


def _ring(seed: int, n: int, centre, lo=0.5, hi=1.0, clockwise=False) -> np.ndarray:
    """A random star (n >= 4: every angular gap below pi, so the ring is simple)."""
    rng = np.random.default_rng(seed)
    t = 2.0 * np.pi * (np.arange(n) + rng.uniform(0.1, 0.9, n)) / n
    r = rng.uniform(lo, hi, n)
    ring = np.column_stack((centre[0] + r * np.cos(t), centre[1] + r * np.sin(t)))
    return np.ascontiguousarray(ring[::-1] if clockwise else ring)


@st.composite
def _batches(draw):
    """Star pairs near each other (many penetrating), some rings clockwise, some long
    (over the ear-clipping limit: decomposed by GEOS), bodies and pairs repeated."""
    count = draw(st.integers(1, 8))
    bodies = []
    for _ in range(count):
        na = draw(st.sampled_from([4, 5, 8, 12, 30, 80]))
        nb = draw(st.sampled_from([4, 6, 12, 40, 70]))
        c = (draw(st.floats(-1.2, 1.2)), draw(st.floats(-1.2, 1.2)))
        a = _ring(draw(st.integers(0, 10**6)), na, (0.0, 0.0), clockwise=draw(st.booleans()))
        b = _ring(draw(st.integers(0, 10**6)), nb, c, clockwise=draw(st.booleans()))
        bodies.append((a, b))
    picks = draw(st.lists(st.integers(0, count - 1), min_size=1, max_size=3 * count))
    # the same pair again, and A again against another B
    pairs = [bodies[i] for i in picks] + [(bodies[0][0], b) for _, b in bodies]
    return [p[0] for p in pairs], [p[1] for p in pairs]


@examples(40)
@given(_batches())
def test_batch_depths_equal_the_pairwise_depths(batch):
    shapes_a, shapes_b = batch
    got = pc.classify_many(shapes_a, shapes_b).distances
    want = [pc.classify(a, b).distance for a, b in zip(shapes_a, shapes_b)]
    pen = np.array([w < 0.0 for w in want])
    # the same computation: bit for bit
    assert got[pen].tolist() == np.array(want)[pen].tolist()


def test_batch_depths_equal_the_clipper_oracle():
    rng = np.random.default_rng(10)
    shapes_a, shapes_b = [], []
    for seed in range(40):
        shapes_a.append(_ring(seed, int(rng.integers(5, 40)), (0.0, 0.0)))
        shapes_b.append(_ring(1000 + seed, int(rng.integers(5, 40)),
                              tuple(rng.uniform(-0.6, 0.6, 2))))
    batch = pc.classify_many(shapes_a, shapes_b)
    pen = np.flatnonzero(batch.states == 2)
    assert len(pen) > 20
    for p in pen:
        want = _clipper_depth(shapes_a[p], shapes_b[p])
        assert -batch.distances[p] == pytest.approx(want, rel=1e-9, abs=1e-9)


def test_batch_depths_of_shapes_with_holes_and_raw_arrays():
    # holes: pieces by GEOS (the kernel does not decompose them); a (P, N, 2) array of
    # clockwise rings: pieces of the reversed rings
    frame = pc.Shape([(0, 0), (5, 0), (5, 5), (0, 5)], holes=[[(2, 2), (3, 2), (3, 3), (2, 3)]])
    sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    shapes_a = [sq + [2.3, 2.2], sq + [1.5, 1.5], frame]
    shapes_b = [frame, frame, sq + [4.5, 2.0]]
    got = pc.classify_many(shapes_a, shapes_b).distances
    want = [pc.classify(a, b).distance for a, b in zip(shapes_a, shapes_b)]
    assert got.tolist() == want
    cw = np.stack([sq[::-1], sq[::-1] + 0.25])
    ccw = np.stack([sq + 0.5, sq + [0.9, 0.0]])
    np.testing.assert_allclose(pc.classify_many(cw, ccw).distances, [-0.5, -0.35])


@examples(30)
@given(st.integers(0, 10**6), st.integers(4, 40), st.integers(4, 40),
       st.floats(-1.0, 1.0), st.floats(-1.0, 1.0))
def test_depth_without_the_grid_equals_the_depth_with_it(seed, na, nb, cx, cy):
    # the scan alone (few sums, grid_from above them) and the grid of cells (grid_from
    # 0) clip alike
    a = pc.Shape(_ring(seed, na, (0.0, 0.0)))
    b = pc.Shape(_ring(seed + 1, nb, (cx, cy)))
    rel = pc.classify(a, b)
    if rel.state is not pc.State.PENETRATING:
        return
    (xa, sa), (xb, sb) = a.packed, b.packed
    bxy, bst = pieces_packed(xb, sb)
    axy, ast = pieces_packed(xa, sa)
    args = ((xa, sa), (xb, sb), (bxy, bst), (-axy, ast), kd.box_escape(xa, xb), rel.tolerance,
            MAX_SUM_VERTICES)
    scan = kd.depth_from_pieces(*args, 10**9)
    grid = kd.depth_from_pieces(*args, 0)
    assert scan[0] == pytest.approx(grid[0], rel=1e-12, abs=rel.tolerance)
    assert pc.classify(xa + scan[1:], xb).state is not pc.State.PENETRATING
    assert pc.classify(xa + grid[1:], xb).state is not pc.State.PENETRATING


def _bodies_of_equal_key():
    """A packed batch of four squares: bodies 0 and 2 equal; body 1 with vertex 0 moved
    by (1.25, -1), which leaves the weighted sum of the coordinates that groups the
    bodies the same (weights 1 and 1.25 on vertex 0), exactly; body 3 that one reversed."""
    sq = np.array([[0.0, 0.0], [4.0, 0.0], [4.0, 4.0], [0.0, 4.0]])
    moved = sq.copy()
    moved[0] = [1.25, -1.0]
    x = np.concatenate([sq, moved, sq, moved[::-1]])
    ls = np.array([0, 4, 4, 8, 8, 12, 12, 16])
    bs = np.array([0, 2, 4, 6, 8])
    f = np.array([1.0, 1.0, 1.0, -1.0])
    return x, ls, bs, f


def test_distinct_bodies_tells_apart_bodies_of_equal_key():
    x, ls, bs, f = _bodies_of_equal_key()
    first, slot = kd.distinct_bodies(x, ls, bs, f, np.array([0, 1, 2, 3, 1]))
    assert first.tolist() == [0, 1, 3]
    assert slot.tolist() == [0, 1, 0, 2, 1]


def test_distinct_pairs_groups_equal_bodies_and_tolerances_only():
    # pairs k: (A, B) = (bodies p, p) of _bodies_of_equal_key with tolerances eps[k]
    x, ls, bs, f = _bodies_of_equal_key()
    batch = (x, ls, bs, f, x, ls, bs, f)
    pairs = np.array([0, 1, 2, 3, 2, 0])
    eps = np.array([1e-9, 1e-9, 1e-9, 1e-9, 1e-9, 2e-9])
    keys = kd.pair_keys(batch, pairs, eps)
    assert keys[1] == keys[0]  # (the case that needs the bodies compared)
    first, slot = kd.distinct_pairs(batch, pairs, eps, keys)
    assert first.tolist() == [0, 1, 3, 5]
    assert slot.tolist() == [0, 1, 0, 2, 0, 3]


@given(st.lists(st.integers(0, 3), min_size=1, max_size=60),
       st.lists(st.sampled_from([1e-9, 2e-9]), min_size=60, max_size=60))
@examples(30)
def test_distinct_pairs_equal_a_grouping_by_full_comparison(which, tolerances):
    # many repeats of four bodies (two of equal key, one with a -0.0 coordinate), in
    # any order: each pair joins the group of the first pair equal to it in full
    x, ls, bs, f = _bodies_of_equal_key()
    x = x.copy()
    x[8] = [-0.0, 0.0]  # (body 2: body 0 with a negative zero)
    batch = (x, ls, bs, f, x, ls, bs, f)
    pairs = np.array(which)
    eps = np.array(tolerances[: len(which)])
    first, slot = kd.distinct_pairs(batch, pairs, eps, kd.pair_keys(batch, pairs, eps))

    def same(p, q):
        return kd._samebody(x, ls, bs, f, pairs[p], pairs[q]) and eps[p] == eps[q]

    want = [next(q for q in range(k + 1) if same(q, k)) for k in range(len(pairs))]
    assert first.tolist() == sorted(set(want))
    assert [first[s] for s in slot.tolist()] == want


def test_batch_depth_beyond_its_memory_budget_is_refused(monkeypatch):
    monkeypatch.setattr(limits, "MAX_SUM_VERTICES", 3)
    # (40-gons: two small bodies take the contact segments, which build no sums)
    t = 2.0 * np.pi * np.arange(40) / 40
    disk = np.column_stack((np.cos(t), np.sin(t)))
    batch = pc.classify_many(np.stack([disk, disk]), np.stack([disk + 0.5, disk + 3.0]))
    with pytest.raises(pc.DepthTooLargeError, match="too large and interlocked"):
        batch.distances  # noqa: B018
