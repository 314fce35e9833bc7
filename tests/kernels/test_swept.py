"""Kernels of the swept broad phase, on their own and through the sort and sweep that
shares them among threads (also run as plain Python in CI)."""

from __future__ import annotations

import numpy as np
from hypothesis import given
from hypothesis import strategies as st
from profiles import examples

from polycontact._kernels.swept import boxes_into, slice_starts
from polycontact.impacts import box_pairs


def swept_boxes(c, m, radius, t_max, max_slices, inflate, ulps):
    """Every body's boxes, in one range: ``(boxes, owner)``."""
    first = slice_starts(m, radius, t_max, max_slices)
    boxes, owner = np.empty((first[-1], 6)), np.empty(first[-1], np.int64)
    boxes_into(c, m, radius, t_max, first, inflate, ulps, 0, len(c), boxes, owner)
    return boxes, owner


def test_swept_boxes_of_a_parabola_hold_its_apex():
    # x(t) = 0 + 2 t − t²: rises to 1 at t = 1, back to 0 at t = 2; radius 0.5, one slice
    c = np.array([[0.0, 0.0]])
    m = np.array([[2.0, 0.0, -2.0, 0.0, 7.0, 0.0]])      # the spin plays no part
    boxes, owner = swept_boxes(c, m, np.array([0.5]), 2.0, 1, 0.0, 0.0)
    assert owner.tolist() == [0]
    assert boxes.tolist() == [[-0.5, 1.5, -0.5, 0.5, 0.0, 2.0]]
    # path length bound 4 + 4 = 8 radii of 0.5 -> 16 slices (the cap)
    boxes, owner = swept_boxes(c, m, np.array([0.5]), 2.0, 16, 0.0, 0.0)
    assert len(boxes) == 16 and boxes[0, 4] == 0.0 and boxes[-1, 5] == 2.0
    assert np.array_equal(boxes[1:, 4], boxes[:-1, 5])      # slices tile [0, t_max]



def test_swept_boxes_are_grown_as_the_pairwise_broad_phase_grows_the_radii():
    # radius 0.5 inflated by 1e-3; reach 0.5 + 3 + 4 + 2 t_max + t_max² (t_max = 1)
    c = np.array([[3.0, -4.0]])
    m = np.array([[0.0, 2.0, 0.0, 2.0, 0.0, 0.0]])
    (box,), _ = swept_boxes(c, m, np.array([0.5]), 1.0, 1, 1e-3, 1e-2)
    grow = 0.5 * 1.001 + 1e-2 * (0.5 + 3.0 + 4.0 + 2.0 + 1.0)
    assert np.allclose(box, [3.0 - grow, 3.0 + grow, -4.0 - grow, -1.0 + grow, 0.0, 1.0])


def test_swept_boxes_of_a_path_that_overflows_are_the_whole_plane():
    # v t and a t²/2 overflow to +inf and -inf: their sum is NaN; the box must not drop
    # the body (the public functions refuse such motions before, see check_reach)
    c = np.array([[0.0, 0.0]])
    m = np.array([[1e300, 0.0, -1e300, 0.0, 0.0, 0.0]])
    with np.errstate(all="ignore"):
        boxes, _ = swept_boxes(c, m, np.array([1.0]), 1e10, 1, 0.0, 0.0)
    assert boxes[0, :4].tolist() == [-np.inf, np.inf, -np.inf, np.inf]


def test_boxes_written_by_ranges_of_bodies_are_those_of_one_range():
    rng = np.random.default_rng(3)
    c = rng.uniform(-5, 5, (30, 2))
    m = np.c_[rng.normal(0, 3, (30, 4)), np.zeros((30, 2))]
    radius = rng.uniform(0.1, 1.0, 30)
    first = slice_starts(m, radius, 1.5, 16)
    whole = swept_boxes(c, m, radius, 1.5, 16, 1e-3, 1e-12)
    boxes, owner = np.full((first[-1], 6), np.nan), np.full(first[-1], -1, np.int64)
    for i0, i1 in ((17, 30), (0, 5), (5, 17)):
        boxes_into(c, m, radius, 1.5, first, 1e-3, 1e-12, i0, i1, boxes, owner)
    assert np.array_equal(boxes, whole[0]) and np.array_equal(owner, whole[1])


def _all_pairs(boxes: np.ndarray, owner: np.ndarray) -> list[list[int]]:
    """The oracle of ``box_pairs``: every pair of owners (lower first) with boxes that
    overlap or touch, by testing every pair of boxes."""
    want = set()
    for a in range(len(boxes)):
        for b in range(len(boxes)):
            lo_a, hi_a = boxes[a, 0::2], boxes[a, 1::2]
            lo_b, hi_b = boxes[b, 0::2], boxes[b, 1::2]
            if owner[a] < owner[b] and np.all(lo_a <= hi_b) and np.all(lo_b <= hi_a):
                want.add((int(owner[a]), int(owner[b])))
    return sorted(map(list, want))


@examples(200)
@given(st.integers(1, 40), st.integers(1, 12), st.integers(0, 2**32 - 1))
def test_box_pairs_equal_all_pairs_of_overlapping_boxes(n_boxes, n_bodies, seed):
    rng = np.random.default_rng(seed)
    lo = rng.integers(0, 10, (n_boxes, 3)).astype(float)   # integers: touching boxes too
    size = rng.integers(0, 4, (n_boxes, 3)).astype(float)
    boxes = np.empty((n_boxes, 6))
    boxes[:, 0::2] = lo
    boxes[:, 1::2] = lo + size
    owner = rng.integers(0, n_bodies, n_boxes).astype(np.int64)
    want = _all_pairs(boxes, owner)
    got = box_pairs(boxes, owner, n_bodies)
    assert got.tolist() == want


@examples(150)
@given(st.integers(1, 60), st.integers(1, 12), st.integers(0, 2**32 - 1))
def test_box_pairs_of_boxes_of_every_size_equal_all_pairs(n_boxes, n_bodies, seed):
    """Boxes from a thousandth to a thousand times the crowd's spacing, and some that
    reach infinity, swept in strips: every pair, once."""
    rng = np.random.default_rng(seed)
    lo = rng.uniform(0.0, 20.0, (n_boxes, 3))
    size = 10.0 ** rng.uniform(-3.0, 3.0, (n_boxes, 3))
    size[rng.random(n_boxes) < 0.05, rng.integers(0, 2)] = np.inf
    boxes = np.empty((n_boxes, 6))
    boxes[:, 0::2] = lo
    boxes[:, 1::2] = lo + size
    boxes[rng.random(n_boxes) < 0.05, 2] = -np.inf
    owner = rng.integers(0, n_bodies, n_boxes).astype(np.int64)
    want = _all_pairs(boxes, owner)
    with np.errstate(invalid="ignore"):  # (infinite boxes' centres, run as Python)
        got = box_pairs(boxes, owner, n_bodies)
    assert got.tolist() == want


def _overlapping_pairs(boxes: np.ndarray, owner: np.ndarray) -> list[list[int]]:
    """:func:`_all_pairs` for thousands of boxes: every pair of boxes tested, a block
    of rows at a time in NumPy."""
    lo, hi = boxes[:, 0::2], boxes[:, 1::2]
    want = set()
    for a0 in range(0, len(boxes), 256):
        a = slice(a0, a0 + 256)
        meet = np.all((lo[a, None, :] <= hi[None, :, :]) & (lo[None, :, :] <= hi[a, None, :]),
                      axis=2)
        meet &= owner[a, None] < owner[None, :]
        ka, kb = np.nonzero(meet)
        want.update(zip(owner[a][ka].tolist(), owner[kb].tolist()))
    return sorted(map(list, want))


def test_box_pairs_of_a_crowd_are_the_same_on_every_number_of_threads(monkeypatch):
    """A crowd swept in many chunks on two threads (its work per strip and per pair set
    high, so that it is shared whatever the machine's speed; bodies of several boxes,
    boxes touching and spanning several strips): every pair once, as on one thread."""
    from polycontact import impacts

    rng = np.random.default_rng(7)
    n_boxes = 8500
    lo = rng.integers(0, 400, (n_boxes, 3)).astype(float)
    lo[:, 2] = rng.integers(0, 4, n_boxes)
    size = rng.integers(0, 5, (n_boxes, 3)).astype(float)
    size[rng.random(n_boxes) < 0.01, 1] = 60.0        # tall boxes: in many strips
    boxes = np.empty((n_boxes, 6))
    boxes[:, 0::2] = lo
    boxes[:, 1::2] = lo + size
    owner = rng.integers(0, n_boxes // 2, n_boxes).astype(np.int64)
    want = _overlapping_pairs(boxes, owner)
    monkeypatch.setattr(impacts, "STRIP_MEMBER_SECONDS", 1.0)
    monkeypatch.setattr(impacts, "PARTNER_SECONDS", 1.0)
    got = [box_pairs(boxes, owner, n_boxes // 2, threads=t).tolist() for t in (1, 2)]
    assert len(want) > 1000
    assert all(g == want for g in got)
