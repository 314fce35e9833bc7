"""Kernels of a World's step: NumPy's summation order, the overlap of two regions
against Shapely's intersection, the closest features against Shapely's distance, the
depth's contact segment and its search given a known witness, and the state of a body
moved from its edge table."""

from __future__ import annotations

import math

import numpy as np
import shapely
from hypothesis import given
from hypothesis import strategies as st
from profiles import examples

import polycontact as pc
from polycontact._kernels import contact_geometry as kg
from polycontact._kernels.convolution import contact_depth_into, contact_depth_of, depth_buffers
from polycontact._kernels.depth import box_escape
from polycontact._kernels.overlap import overlap_moments, overlap_scratch, where
from polycontact._kernels.packs import scratch_floats
from polycontact._kernels.poses import centroids, pairwise_sum
from polycontact._kernels.primitives import edge_rows
from polycontact._kernels.relation import NO_WITNESS, moved_state, relate_state, witness_holds

SHAPES = [
    pc.Shape([(0, 0), (3, 0), (3, 1), (1, 1), (1, 3), (0, 3)]),
    pc.Shape([(0, 0), (3, 0), (3, 3), (2, 3), (2, 1), (1, 1), (1, 3), (0, 3)]),
    pc.Shape([(0, 0), (4, 0), (4, 4), (0, 4)], [[(1, 1), (3, 1), (3, 3), (1, 3)]]),
    pc.Shape([(0, 0), (1, 0), (1, 1), (0, 1)]),
    pc.Shape([(math.cos(t) * r, math.sin(t) * r) for t, r in
              zip(np.linspace(0, 2 * math.pi, 12, endpoint=False), [1.6, 0.6] * 6)]),
]


def offset(lo: float, hi: float) -> st.SearchStrategy[float]:
    """Floats in [lo, hi], those nearer 0 than 1e-9 made 0: no offset tiny against the
    bodies, where Shapely's overlay, the oracle, loses part of an intersection (an L
    turned a quarter and an L moved 1e-306 from it, at scale 1e-6)."""
    return st.floats(lo, hi).map(lambda v: v if abs(v) >= 1e-9 else 0.0)


placed = st.tuples(st.integers(0, len(SHAPES) - 1),
                   offset(-3.0, 3.0),
                   offset(-3.0, 3.0),
                   st.sampled_from([0.0, math.pi / 2, 0.3, -2.0]))
frames = st.tuples(st.sampled_from([1e-6, 1.0, 1e6]), st.sampled_from([0.0, 1e3]))


def make(spec, frame):
    t, x, y, a = spec
    scale, offset = frame
    s = SHAPES[t]
    s = pc.Shape(s.exterior * scale, [h * scale for h in s.holes])
    return s.moved((x * scale + offset * scale, y * scale + offset * scale), a)


def moments(a: pc.Shape, b: pc.Shape, eps: float):
    """The overlap kernel's answer, the point of the boundary it leaves (``acc``) and
    where it found each vertex of A and of B."""
    (xa, sa), (xb, sb) = a.packed, b.packed
    n = len(xa) + len(xb)
    scratch = overlap_scratch(len(xa), len(xb), n * n)
    got = overlap_moments(xa, sa, xb, sb, eps, scratch)
    return got, scratch[4], (scratch[7], scratch[8])


@examples(150)
@given(st.lists(st.floats(-1e6, 1e6), min_size=0, max_size=300))
def test_pairwise_sum_is_numpy_sum_to_the_bit(values):
    a = np.array(values, dtype=np.float64)
    assert float(pairwise_sum(a, 0, len(a))) == float(a.sum())


@examples(60)
@given(placed, frames)
def test_centroids_are_the_shape_centroid_to_the_bit(spec, frame):
    s = make(spec, frame)
    xy, st_ = s.packed
    cen, rad = np.empty((1, 2)), np.empty(1)
    centroids(xy, st_, np.array([0, len(st_)]), cen, rad)
    assert np.array_equal(cen[0], s.centroid)
    assert math.isclose(rad[0], s.bounding_radius, rel_tol=1e-12)


@examples(150)
@given(placed, placed, frames)
def test_overlap_area_and_centroid_equal_shapely_intersection(sa, sb, frame):
    a, b = make(sa, frame), make(sb, frame)
    eps = pc.default_tolerance(a.packed[0], b.packed[0])
    (area, cx, cy, nc), acc, _ = moments(a, b, eps)
    inter = a.to_shapely().intersection(b.to_shapely())
    size = max(np.ptp(a.packed[0], axis=0).max(), np.ptp(b.packed[0], axis=0).max())
    perimeter = a.to_shapely().length + b.to_shapely().length
    assert abs(area - inter.area) <= 1e-9 * size * size + 4 * eps * perimeter
    if inter.area > 1e-6 * size * size:
        c = inter.centroid
        assert math.hypot(cx - c.x, cy - c.y) <= 1e-6 * size
        boundary = shapely.union_all([g for g in shapely.get_parts(inter)
                                      if g.geom_type == "Polygon"]).boundary
        assert acc[3] == 1.0 and boundary.distance(shapely.Point(acc[4], acc[5])) <= 4 * eps
    if area == 0.0:
        assert math.isnan(cx) and math.isnan(cy)


@examples(100)
@given(placed, placed, frames)
def test_the_overlap_walk_knows_where_every_vertex_lies(sa, sb, frame):
    a, b = make(sa, frame), make(sb, frame)
    eps = pc.default_tolerance(a.packed[0], b.packed[0])
    places = moments(a, b, eps)[2]
    for own, other, got in ((a, b, places[0]), (b, a, places[1])):
        xo, so = other.packed
        want = [where(x, y, xo, so, eps) for x, y in own.packed[0]]
        assert got.tolist() == want


def test_overlap_of_shared_and_collinear_boundaries():
    sq = pc.Shape([(0, 0), (2, 0), (2, 2), (0, 2)])
    frame = pc.Shape([(0, 0), (4, 0), (4, 4), (0, 4)], [[(1, 1), (3, 1), (3, 3), (1, 3)]])
    cases = [(sq, sq), (sq, sq.moved((1, 0))), (sq, sq.moved((2, 0))), (sq, sq.moved((1, 2))),
             (frame, sq.moved((1, 1))), (frame, sq.moved((0.5, 0.5))), (frame, frame),
             (frame, frame.moved((1, 0))), (frame, frame.moved((2, 2))),
             (sq, pc.Shape([(0, 0), (4, 0), (0, 4)]))]
    for a, b in cases:
        want = a.to_shapely().intersection(b.to_shapely()).area
        for first, second in ((a, b), (b, a)):
            (area, *_), _, _ = moments(first, second, 1e-12)
            assert math.isclose(area, want, abs_tol=1e-9), (want, area)


@examples(100)
@given(placed, placed, frames)
def test_closest_features_give_the_gap_of_bodies_apart(sa, sb, frame):
    # apart: B moved past the widest reach of any turned shape (the L spans 3, the star 1.6)
    a, b = make(sa, frame), make((sb[0], sb[1] + 20.0, sb[2], sb[3]), frame)
    (xa, sta), (xb, stb) = a.packed, b.packed
    gap, ax, ay, bx, by, side, v, f = kg.closest_features(xa, sta, xb, stb)
    # bodies that touch (gap 0 for GEOS) may be a few float spacings apart here
    rounding = 8 * np.spacing(max(np.abs(xa).max(), np.abs(xb).max()))
    assert math.isclose(gap, a.to_shapely().distance(b.to_shapely()), rel_tol=1e-9,
                        abs_tol=rounding)
    assert math.isclose(math.hypot(bx - ax, by - ay), gap, rel_tol=1e-9, abs_tol=rounding)
    vertex = (ax, ay) if side == 0 else (bx, by)
    assert vertex == tuple((xa if side == 0 else xb)[v])


@examples(100)
@given(placed, placed, frames)
def test_the_depth_segment_takes_its_vertex_onto_its_edge(sa, sb, frame):
    a, b = make(sa, frame), make(sb, frame)
    r = pc.classify(a, b)
    if r.state is not pc.State.PENETRATING:
        return
    (xa, sta), (xb, stb) = a.packed, b.packed
    if len(xa) + len(xb) > 64:
        return
    got = contact_depth_into(xa, sta, xb, stb, *box_escape(xa, xb), r.tolerance, 0.0,
                             depth_buffers(len(xa), len(xb)))
    depth, dx, dy, ok, side, v, f = got
    if not ok:
        return
    assert abs(depth + r.distance) <= 4 * r.tolerance
    if side < 0:
        side, v, f = kg.carrier(xa, sta, xb, stb, dx, dy)
    if side == 0:
        p, (x, st_) = xa[v] + (dx, dy), (xb, stb)
    else:
        p, (x, st_) = xb[v] - (dx, dy), (xa, sta)
    loop = int(np.searchsorted(st_, f, side="right")) - 1
    g = f + 1 if f + 1 < st_[loop + 1] else st_[loop]
    assert shapely.LineString([x[f], x[g]]).distance(shapely.Point(p)) <= 8 * r.tolerance


def shrunk(shape: pc.Shape, f: float) -> pc.Shape:
    """The shape scaled by f about its centroid."""
    c = shape.centroid
    return pc.Shape(c + (shape.exterior - c) * f, [c + (h - c) * f for h in shape.holes])


def tables(shape: pc.Shape):
    """A body as the pair kernels take it: rows, loop starts, edge table, successors,
    box."""
    x, st_ = shape.packed
    e, nxt = np.empty((len(x), 7)), np.empty(len(x), np.int64)
    edge_rows(x, st_, e, nxt)
    return x, st_, e, nxt, (x[:, 0].min(), x[:, 0].max(), x[:, 1].min(), x[:, 1].max())


@examples(150)
@given(placed, placed, frames, st.floats(-1.0, 1.0), st.floats(-1.0, 1.0), st.booleans(),
       st.floats(0.0, 1.0), st.sampled_from([(1.0, 1.0), (0.1, 1.0), (1.0, 0.1)]))
def test_a_moved_body_gets_the_state_kernels_verdict_and_a_witness_that_holds(
        sa, sb, frame, fx, fy, onto, back, shrink):
    """The state of A moved, from its edge table, is the state kernel's on A's rows moved
    (touches, a vertex brought exactly onto an edge, included); a penetration's witness
    (two edges crossing, a vertex inside; one body shrunk, so that it may lie inside the
    other) holds there, and wherever it holds the state kernel finds a penetration."""
    a, b = (shrunk(make(spec, frame), f) for spec, f in ((sa, shrink[0]), (sb, shrink[1])))
    ta, tb = tables(a), tables(b)
    (xa, sta), (xb, stb) = a.packed, b.packed
    eps = pc.default_tolerance(xa, xb)
    if onto:  # A's vertex 0 onto the middle of B's edge 0
        d = 0.5 * (xb[0] + xb[1]) - xa[0]
    else:
        d = np.array([fx, fy]) * frame[0]
    moved = np.empty_like(xa)
    scratch = np.empty(scratch_floats(len(xa) + len(xb)))
    got, witness, i, j = moved_state(ta, tb, d[0], d[1], eps, moved, scratch)
    assert got == (relate_state(xa + d, sta, xb, stb, eps) == 2)
    if witness == NO_WITNESS:
        return
    touch = np.empty(len(xa) + len(xb), np.bool_)
    assert witness_holds(ta, tb, d[0], d[1], eps, witness, i, j, moved, touch)
    d2 = d * back
    if witness_holds(ta, tb, d2[0], d2[1], eps, witness, i, j, moved, touch):
        assert relate_state(xa + d2, sta, xb, stb, eps) == 2


@examples(150)
@given(placed, placed, frames, st.floats(0.0, 1.0), st.floats(0.0, 2 * math.pi))
def test_a_known_witness_leaves_the_depth_as_it_was(sa, sb, frame, reach, turn):
    """The depth's search given the witness of a penetration found at another
    translation (tried before the state kernel at each point) finds what it finds
    without: the same depth, escape, status and carrying features, to the bit."""
    a, b = make(sa, frame), make(sb, frame)
    (xa, sta), (xb, stb) = a.packed, b.packed
    if len(xa) + len(xb) > 64:
        return
    eps = pc.default_tolerance(xa, xb)
    ta, tb = tables(a), tables(b)
    bound, bdx, bdy = box_escape(xa, xb)
    d = reach * bound * np.array([math.cos(turn), math.sin(turn)])
    moved = np.empty_like(xa)
    scratch = np.empty(scratch_floats(len(xa) + len(xb)))
    got, witness, i, j = moved_state(ta, tb, d[0], d[1], eps, moved, scratch)
    if not got or relate_state(xa, sta, xb, stb, eps) != 2:
        return
    runs = [contact_depth_of(ta, tb, bound, bdx, bdy, eps, 0.0, known,
                             depth_buffers(len(xa), len(xb)))
            for known in ((NO_WITNESS, -1, -1), (witness, i, j))]
    assert runs[0] == runs[1] or (runs[0][1] != runs[0][1] and runs[0][3:] == runs[1][3:])
