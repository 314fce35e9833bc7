"""The penetration depth of small bodies from their vertex-edge contact segments
(:mod:`polycontact._kernels.convolution`).

Oracles: the search over the convex sums of the pieces (the path before it, and its
fallback), pyclipper's and Shapely's Minkowski sums (``test_depth.py``), and the state
kernel (the escape returned escapes).
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from profiles import examples
from .test_depth import _clipper_depth, _convex_sum_depth
from .test_depth_fast import _from_box, _pairs, _star, _transformed

import polycontact as pc
from polycontact._kernels import convolution as kc
from polycontact._kernels import depth as kd


def _search(a: pc.Shape, b: pc.Shape, eps: float) -> tuple[float, float, float]:
    """The search over the convex sums from the first escape."""
    return _from_box(a, b, eps, kd.first_escape)


def _contact(a: pc.Shape, b: pc.Shape, eps: float,
             bound: tuple[float, float, float] | None = None) -> tuple[float, ...]:
    (xa, sa), (xb, sb) = a.packed, b.packed
    return kc.contact_depth(xa, sa, xb, sb, *(bound or kd.first_escape(xa, xb)), eps)


def _check(a: pc.Shape, b: pc.Shape, got: tuple[float, ...], tol: float) -> None:
    """The escape returned has the length returned and ends the overlap."""
    assert np.hypot(got[1], got[2]) == pytest.approx(got[0], rel=1e-12, abs=tol)
    assert pc.classify(a.moved((got[1], got[2])), b, tolerance=tol).state is not \
        pc.State.PENETRATING


@examples(30)
@given(st.integers(0, 10**6), st.sampled_from([1e-9, 1e-3, 1.0, 1e3, 1e9]),
       st.sampled_from([0.0, 1.0, -1e6]), st.sampled_from([0, 1, 2]))
def test_contact_depth_of_concave_12_gons_equals_the_search_and_the_oracles(seed, scale,
                                                                            shift, holes):
    # Two concave stars (pyclipper's oracle), a convex A against a star B with a hole
    # (Shapely's), two stars with a hole each (the search only); scales 1e-9..1e9,
    # offsets up to 1e6 body sizes. From the first escape and from the box's (more
    # segments, deeper inside the sums), both equal to the search.
    pairs = _pairs(seed, 10, holes)
    offset = np.array([shift * scale, -0.5 * shift * scale])
    checked = 0
    for a, b in pairs:
        ma, mb = _transformed(a, scale, offset), _transformed(b, scale, offset)
        rel = pc.classify(ma, mb)
        if rel.state is not pc.State.PENETRATING or \
                pc.classify(a, b).state is not pc.State.PENETRATING:
            continue
        tol = rel.tolerance
        want = _search(ma, mb, tol)
        (xa, _), (xb, _) = ma.packed, mb.packed
        for start in (kd.first_escape(xa, xb), kd.box_escape(xa, xb)):
            got = _contact(ma, mb, tol, start)
            assert got[3]  # (random stars: no segments run together)
            assert got[0] == pytest.approx(want[0], rel=1e-12, abs=2 * tol)
            _check(ma, mb, got, tol)
        if holes < 2:
            oracle = (_convex_sum_depth(a.exterior, b.to_shapely()) if holes
                      else _clipper_depth(a.exterior, b.exterior))
            assert got[0] == pytest.approx(oracle * scale, rel=1e-9, abs=4 * tol)
        assert -rel.distance == pytest.approx(got[0], rel=1e-12)  # the pairwise call
        checked += 1
    assert checked >= 1


@pytest.mark.parametrize("seed", range(4))
def test_contact_depth_of_stars_of_up_to_32_vertices(seed):
    # more vertices (64 in all, the most this kernel takes), deeper overlaps
    rng = np.random.default_rng(seed)
    for _ in range(10):
        a = pc.Shape(_star(rng, 32))
        b = pc.Shape(_star(rng, 32, tuple(rng.uniform(-0.6, 0.6, 2))))
        rel = pc.classify(a, b)
        if rel.state is not pc.State.PENETRATING:
            continue
        got = _contact(a, b, rel.tolerance)
        assert got[3]
        assert got[0] == pytest.approx(_search(a, b, rel.tolerance)[0], rel=1e-12,
                                       abs=2 * rel.tolerance)
        assert got[0] == pytest.approx(_clipper_depth(a.exterior, b.exterior), rel=1e-9,
                                       abs=4 * rel.tolerance)
        _check(a, b, got, rel.tolerance)


_SQ = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])


def test_contact_depth_refuses_segments_that_run_together_and_the_search_answers():
    # Two squares: the sides of B ⊕ (−A) are each made of two collinear segments that
    # overlap (a slide: where their contacts part is known only to the rounding). The
    # nearest segment's foot is tried first: it escapes, so it is the depth, with no
    # split. A square in an L's corner: the nearest foot does not escape, and splitting
    # the collinear segments is refused; the depth is then the search's, by the
    # pairwise and the batch calls alike.
    a, b = pc.Shape(_SQ), pc.Shape(_SQ + [0.75, 0.6])
    got = _contact(a, b, 1e-12, (3.0, 3.0, 0.0))
    assert got[3] and got[0] == pytest.approx(0.25, abs=1e-12)
    ell = np.array([(0, 0), (3, 0), (3, 1), (1, 1), (1, 3), (0, 3)], float) - [1.0, 0.75]
    assert not _contact(a, pc.Shape(ell), 1e-12, (3.0, 3.0, 0.0))[3]
    for b_ring, depth in ((_SQ + [0.75, 0.6], 0.25), (ell, 0.25)):
        rel = pc.classify(a, b_ring)
        assert -rel.distance == pytest.approx(depth, abs=2 * rel.tolerance)
    batch = pc.classify_many([_SQ, _SQ, _SQ], [_SQ + [0.75, 0.6], _SQ + [0.5, 0.1], ell])
    assert batch.distances == pytest.approx([-0.25, -0.5, -0.25],
                                            abs=2 * batch.tolerances.max())


def test_contact_depth_refuses_a_first_escape_that_does_not_escape():
    # nothing nearer than a "first escape" that leaves the bodies penetrating: refused
    a, b = pc.Shape(_SQ), pc.Shape(_SQ + [0.5, 0.25])
    got = _contact(a, b, 1e-12, (0.1, 0.1, 0.0))
    assert not got[3]
    assert -pc.classify(a, b).distance == pytest.approx(0.5)


def test_contact_depth_of_bodies_with_more_than_64_vertices_is_left_to_the_search():
    t = 2.0 * np.pi * np.arange(40) / 40
    disk = pc.Shape(np.column_stack((np.cos(t), np.sin(t))))
    assert not _contact(disk, disk.moved((0.5, 0.0)), 1e-12)[3]
    rel = pc.classify(disk, disk.moved((0.5, 0.0)))
    assert -rel.distance == _search(disk, disk.moved((0.5, 0.0)), rel.tolerance)[0]


def test_contact_depth_at_a_crossing_of_two_segments():
    # A triangle in the corner of an L: the depth (0.3, 0.5) puts one vertex on each
    # arm's inner edge, where their two contact segments cross; the nearest points of
    # both segments (and their ends) overlap: only the split at the crossing finds it.
    ell = pc.Shape(np.array([(0, 0), (4, 0), (4, 1), (1, 1), (1, 4), (0, 4)], float))
    tri = pc.Shape(np.array([(1.2, 0.5), (1.7, 1.5), (0.7, 1.0)]))
    for start in ((1.5, 0.0, -1.5), (3.0, 3.0, 0.0)):  # (the first escape, and farther)
        got = _contact(tri, ell, 1e-12, start)
        assert got[3]
        assert got[0] == pytest.approx(np.hypot(0.3, 0.5))
        assert got[1:3] == pytest.approx((0.3, 0.5))
    assert -pc.classify(tri, ell).distance == pytest.approx(np.hypot(0.3, 0.5))


@pytest.mark.parametrize("scale, offset", [(1.0, 0.0), (1e-9, 0.0), (1e9, 0.0), (1.0, 1e6)])
def test_contact_depth_of_a_triangle_held_by_three_spikes(scale, offset):
    # The hole's three inward corners (blunt spikes of B) touch the triangle's three
    # vertices tip to tip: there A can go nowhere (a single escape, no parallel sides,
    # every contact vertex-vertex, so every segment through it ends there). Moved off it
    # by d, the depth is |d|, found at the ends of the segments.
    ang = np.deg2rad([90, 150, 210, 270, 330, 30])
    hole = np.column_stack((np.cos(ang), np.sin(ang))) * np.array([3.0, 1.0] * 3)[:, None]
    tri = np.column_stack((np.cos(ang[[5, 1, 3]]), np.sin(ang[[5, 1, 3]])))
    frame = np.array([(-5, -5), (5, -5), (5, 5), (-5, 5)], float)
    rng = np.random.default_rng(3)
    for _ in range(6):
        d = rng.normal(size=2) * rng.choice([1e-3, 0.05])
        a = pc.Shape((tri + d) * scale + offset)
        b = pc.Shape(frame * scale + offset, [hole[::-1] * scale + offset])
        rel = pc.classify(a, b)
        assert rel.state is pc.State.PENETRATING
        got = _contact(a, b, rel.tolerance, kd.box_escape(*(a.packed[0], b.packed[0])))
        assert got[3]
        assert got[0] == pytest.approx(np.hypot(*d) * scale, abs=2 * rel.tolerance)
        assert -rel.distance == got[0]
