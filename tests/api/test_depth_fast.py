"""The depth's shortcuts (distances in the batch): the first escape along the
edge normals, its confirmation (and the box's escape when rounding leaves it short), the
stop when a sum holding the origin proves the bound, and the origin's foot on that sum's
outline when no other sum covers it.

Oracles: pyclipper's and Shapely's Minkowski sums (``test_depth.py``), and the same
search started from the box's escape alone (the path before the shortcuts).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from profiles import examples
from .test_depth import _clipper_depth, _convex_sum_depth

import polycontact as pc
from polycontact._kernels import depth as kd
from polycontact._pieces import pieces_packed
from polycontact.limits import MAX_SUM_VERTICES


def _star(rng: np.random.Generator, n: int, centre=(0.0, 0.0)) -> np.ndarray:
    """A random concave star of n vertices (radii 0.5..1, every angular gap below pi)."""
    t = 2.0 * np.pi * (np.arange(n) + rng.uniform(0.1, 0.9, n)) / n
    r = rng.uniform(0.5, 1.0, n)
    return np.column_stack((centre[0] + r * np.cos(t), centre[1] + r * np.sin(t)))


def _convex(rng: np.random.Generator, n: int, centre=(0.0, 0.0)) -> np.ndarray:
    """A random convex polygon (a regular n-gon, squashed and turned)."""
    t = 2.0 * np.pi * np.arange(n) / n + rng.uniform(0.0, 2.0 * np.pi)
    ring = np.column_stack((np.cos(t), rng.uniform(0.3, 1.0) * np.sin(t)))
    c, s = np.cos(rng.uniform(0, np.pi)), np.sin(rng.uniform(0, np.pi))
    return ring @ np.array([[c, s], [-s, c]]) * rng.uniform(0.3, 0.9) + centre


def _hole(rng: np.random.Generator, centre) -> np.ndarray:
    """A small clockwise triangle near the centre of a star (inside it)."""
    t = np.array([0.0, 2.1, 4.2]) + rng.uniform(0, 1)
    r = rng.uniform(0.15, 0.35)
    return np.column_stack((centre[0] + r * np.cos(-t), centre[1] + r * np.sin(-t)))


def _from_box(a: pc.Shape, b: pc.Shape, eps: float,
              escape: Callable[..., Any] = kd.box_escape) -> tuple[float, float, float]:
    """The depth searched over the convex sums from the ``escape`` (by default the box's
    escape only: the path before the shortcuts)."""
    (xa, sa), (xb, sb) = a.packed, b.packed
    bxy, bst = pieces_packed(xb, sb)
    axy, ast = pieces_packed(xa, sa)
    return kd.depth_from_pieces((xa, sa), (xb, sb), (bxy, bst), (-axy, ast), escape(xa, xb),
                                eps, MAX_SUM_VERTICES)


def _pairs(seed: int, count: int, holes: int):
    """``count`` pairs: two concave 12-gon stars (``holes`` 0), a convex A against a
    star B with a hole (1), or two stars with a hole each (2)."""
    rng = np.random.default_rng(seed)
    out = []
    while len(out) < count:
        c = tuple(rng.uniform(-0.9, 0.9, 2))
        a = _convex(rng, int(rng.integers(3, 13))) if holes == 1 else _star(rng, 12)
        b = _star(rng, 12, c)
        sa = pc.Shape(a, holes=[_hole(rng, (0.0, 0.0))] if holes == 2 else [])
        sb = pc.Shape(b, holes=[_hole(rng, c)] if holes else [])
        out.append((sa, sb))
    return out


def _transformed(shape: pc.Shape, scale: float, offset: np.ndarray) -> pc.Shape:
    return pc.Shape(shape.exterior * scale + offset,
                    holes=[h * scale + offset for h in shape.holes])


@examples(25)
@given(st.integers(0, 10**6), st.sampled_from([1e-9, 1e-3, 1.0, 1e3, 1e9]),
       st.sampled_from([0.0, 1.0, -1e6]), st.sampled_from([0, 1, 2]))
def test_batch_depths_of_concave_12_gons_equal_the_oracles(seed, scale, shift, holes):
    # Scales 1e-9..1e9, offsets up to 1e9 (shift x scale: at most 1e6 body sizes away,
    # where the coordinates still resolve the bodies). Two concave stars: pyclipper's
    # oracle; a convex A against B with a hole: Shapely's; both with holes: the
    # search from the box's escape alone. The oracles are taken on the bodies at scale
    # 1, unmoved.
    pairs = _pairs(seed, 12, holes)
    offset = np.array([shift * scale, -0.5 * shift * scale])
    moved = [(_transformed(a, scale, offset), _transformed(b, scale, offset)) for a, b in pairs]
    batch = pc.classify_many([m[0] for m in moved], [m[1] for m in moved])
    checked = 0
    for (a, b), (ma, mb), state, dist, tol in zip(pairs, moved, batch.states, batch.distances,
                                                  batch.tolerances):
        if state != 2 or pc.classify(a, b).state is not pc.State.PENETRATING:
            continue  # (a pair within the tolerance of touching once moved: not here)
        if holes < 2:
            want = (_convex_sum_depth(a.exterior, b.to_shapely()) if holes
                    else _clipper_depth(a.exterior, b.exterior))
            assert -dist == pytest.approx(want * scale, rel=1e-9, abs=4 * tol)
        # the search from the box's escape alone, on the moved bodies
        assert -dist == pytest.approx(_from_box(ma, mb, tol)[0], rel=1e-12, abs=2 * tol)
        # and the pairwise call, which takes the same shortcuts
        assert dist == pc.classify(ma, mb).distance
        checked += 1
    assert checked >= 1


@examples(40)
@given(st.integers(0, 10**6))
def test_first_escape_of_convex_pairs_is_their_depth(seed):
    # separating axes: for two convex bodies the best edge normal's escape is the depth
    # (the box's is longer unless the axes are normals); and the depth returned
    rng = np.random.default_rng(seed)
    a = _convex(rng, int(rng.integers(3, 13)))
    b = _convex(rng, int(rng.integers(3, 13)), tuple(rng.uniform(-0.5, 0.5, 2)))
    rel = pc.classify(a, b)
    if rel.state is not pc.State.PENETRATING:
        return
    want = _convex_sum_depth(a, b)
    (xa, _), (xb, _) = pc.Shape(a).packed, pc.Shape(b).packed
    got = kd.first_escape(xa, xb)
    assert got[0] == pytest.approx(want, rel=1e-9, abs=4 * rel.tolerance)
    assert np.hypot(got[1], got[2]) == pytest.approx(got[0], rel=1e-12)
    assert -rel.distance == pytest.approx(want, rel=1e-9, abs=4 * rel.tolerance)
    assert pc.classify(a + np.array(got[1:]), b).state is not pc.State.PENETRATING


def test_depth_of_convex_pairs_stops_at_the_first_escape_and_concave_ones_search_on():
    # Two squares: the sum holding the origin proves the normal's escape (the stop);
    # a square in the mouth of a U: the first escape (out sideways, 1.5) is beaten by
    # the slide into the slot (0.2), found by the search past the sum's bound.
    sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    rel = pc.classify(sq, sq + [0.75, 0.6])
    assert -rel.distance == pytest.approx(0.25, abs=2 * rel.tolerance)
    u = np.array([(0, 0), (3, 0), (3, 3), (2, 3), (2, 1), (1, 1), (1, 3), (0, 3)], float)
    moved = sq + [1.2, 1.5]
    assert kd.first_escape(moved, u)[0] > 1.0
    rel = pc.classify(moved, u)
    assert -rel.distance == pytest.approx(0.2, abs=2 * rel.tolerance)


def test_depth_from_a_first_escape_that_does_not_escape_falls_back_to_the_box():
    # A first escape that leaves the bodies penetrating (as rounding could, in a
    # normal's touching escape) is refused by the state kernel: the search is made again
    # from the box's escape, and finds the depth.
    sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    a, b = pc.Shape(sq), pc.Shape(sq + [0.5, 0.25])
    (xa, sa), (xb, sb) = a.packed, b.packed
    bxy, bst = pieces_packed(xb, sb)
    axy, ast = pieces_packed(xa, sa)
    got = kd.depth_from_pieces((xa, sa), (xb, sb), (bxy, bst), (-axy, ast), (0.1, 0.1, 0.0),
                               1e-12, MAX_SUM_VERTICES)
    assert got == pytest.approx((0.5, 0.0, -0.5) if got[2] else (0.5, -0.5, 0.0))
    assert pc.classify(sq + np.array(got[1:]), sq + [0.5, 0.25]).state is not \
        pc.State.PENETRATING


_L = np.array([(0, 0), (4, 0), (4, 1), (1, 1), (1, 4), (0, 4)], float)


def test_depth_at_the_foot_on_the_deepest_sum_and_past_it():
    # A unit square on the L's arm: the sum of the arm's piece holds the origin 0.3 inside
    # its top edge, and the foot there is covered by no other sum: the depth (the first
    # escape is 1.5, out of the box). In the L's corner, that foot is inside the other
    # arm's sum: the search goes on, to the corner (0.5, 0.5).
    sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    on_arm = sq + [2.5, 0.7]
    assert kd.first_escape(on_arm, _L)[0] == pytest.approx(1.5)
    rel = pc.classify(on_arm, _L)
    assert -rel.distance == pytest.approx(0.3, abs=2 * rel.tolerance)
    assert rel.escape == pytest.approx([0.0, 0.3], abs=2 * rel.tolerance)
    in_corner = sq + [0.5, 0.5]
    rel = pc.classify(in_corner, _L)
    assert -rel.distance == pytest.approx(np.sqrt(0.5), abs=2 * rel.tolerance)
    assert rel.escape == pytest.approx([0.5, 0.5], abs=2 * rel.tolerance)
    batch = pc.classify_many([on_arm, in_corner], [_L, _L])
    assert batch.distances == pytest.approx([-0.3, -np.sqrt(0.5)], abs=2 * batch.tolerances.max())
