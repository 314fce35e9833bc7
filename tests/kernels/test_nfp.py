"""NFP kernels against plain Shapely references (also run with NUMBA_DISABLE_JIT=1).

Inputs stay small so that the pure-Python run is quick.
"""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from catalogue import SMALL_FAR_RING
from hypothesis import example, given
from hypothesis import strategies as st
from profiles import examples

from polycontact._kernels import decompose
from polycontact._kernels import fits as kfit
from polycontact._kernels import minkowski as kmink
from polycontact._kernels import outline as kout


def _packed(polys):
    xy = np.concatenate(polys).astype(float)
    starts = np.r_[0, np.cumsum([len(p) for p in polys])].astype(np.int64)
    return xy, starts


def _split(xy, starts):
    return [xy[starts[k]:starts[k + 1]] for k in range(len(starts) - 1)]


@st.composite
def convex_polys(draw, grid=4):
    """Convex hull of a few lattice points (collinear edges and shared lines are common)."""
    pts = draw(st.lists(st.tuples(st.integers(0, grid), st.integers(0, grid)), min_size=3,
                        max_size=7, unique=True))
    hull = shapely.convex_hull(shapely.MultiPoint(pts))
    if hull.geom_type != "Polygon":
        hull = shapely.box(pts[0][0], pts[0][1], pts[0][0] + 1, pts[0][1] + 1)
    hull = shapely.orient_polygons(hull)  # CCW exterior
    return np.asarray(hull.exterior.coords)[:-1].astype(float)


@examples(100)
@given(convex_polys(), convex_polys())
def test_convex_sums_match_the_hull_of_vertex_sums(p, q):
    xy, starts, _ = kmink.convex_sums(*_packed([p]), *_packed([q]))
    got = shapely.Polygon(xy)
    want = shapely.convex_hull(shapely.MultiPoint((p[:, None, :] + q[None, :, :]).reshape(-1, 2)))
    assert got.is_valid
    assert shapely.symmetric_difference(got, want).area < 1e-12
    assert kout.ring_stats(xy, starts)[0][0] > 0  # counter-clockwise


@examples(60)
@given(st.lists(convex_polys(), min_size=2, max_size=4))
def test_outline_rings_are_the_union(polys):
    xy, starts = _packed(polys)
    bb = kmink.boxes(xy, starts)
    fr = kmink.frames(xy, starts)
    outline, loose = kout.edge_cover(xy, starts, bb, fr, 1e-12)
    ok, rxy, rst = kout.assemble_rings(outline, 4e-12)
    assert ok
    area, _ = kout.ring_stats(rxy, rst)
    want = shapely.union_all([shapely.Polygon(p) for p in polys])
    assert abs(area.sum() - want.area) < 1e-9
    shells = [shapely.Polygon(r) for r, a in zip(_split(rxy, rst), area) if a > 0]
    holes = [shapely.Polygon(r) for r, a in zip(_split(rxy, rst), area) if a < 0]
    got = shapely.union_all(shells).difference(shapely.union_all(holes)) if holes else (
        shapely.union_all(shells))
    assert shapely.symmetric_difference(got, want).area < 1e-9


def test_two_squares_sharing_an_edge_have_one_outline_and_a_seam():
    left = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
    xy, starts = _packed([left, left + [1, 0]])
    bb = kmink.boxes(xy, starts)
    fr = kmink.frames(xy, starts)
    outline, loose = kout.edge_cover(xy, starts, bb, fr, 1e-12)
    ok, rxy, rst = kout.assemble_rings(outline, 4e-12)
    assert ok and len(rst) == 2
    assert kout.ring_stats(rxy, rst)[0][0] == 2.0
    # the shared edge x = 1 is loose (no open square covers it) and surrounded
    pts, segs = kfit.degenerate_contacts(xy, starts, bb, fr, loose, 1e-12, 1e-9)
    assert len(pts) == 0
    assert {tuple(sorted([tuple(s[:2]), tuple(s[2:])])) for s in segs} == {((1, 0), (1, 1))}


def test_surrounded_on_an_l_of_three_squares():
    sq = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
    xy, starts = _packed([sq, sq + [1, 0], sq + [0, 1]])
    bb = kmink.boxes(xy, starts)
    fr = kmink.frames(xy, starts)
    assert not kfit.surrounded(1.0, 1.0, starts, bb, fr, 1e-12, 1e-9)  # reflex corner
    assert kfit.surrounded(0.5, 1.0, starts, bb, fr, 1e-12, 1e-9)  # shared edge
    assert kfit.surrounded(1.0, 0.5, starts, bb, fr, 1e-12, 1e-9)
    assert not kfit.surrounded(0.0, 0.5, starts, bb, fr, 1e-12, 1e-9)  # outline


def test_surrounded_at_a_shared_corner_of_four_squares():
    sq = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
    xy, starts = _packed([sq, sq + [1, 0], sq + [0, 1], sq + [1, 1]])
    bb = kmink.boxes(xy, starts)
    fr = kmink.frames(xy, starts)
    assert kfit.surrounded(1.0, 1.0, starts, bb, fr, 1e-12, 1e-9)
    assert not kfit.surrounded(2.0, 1.0, starts, bb, fr, 1e-12, 1e-9)


@st.composite
def lattice_polygons(draw):
    cells = draw(st.lists(st.tuples(st.integers(0, 3), st.integers(0, 3)), min_size=1,
                          max_size=10, unique=True))
    geom = shapely.union_all([shapely.box(x, y, x + 1, y + 1) for x, y in cells])
    return max(shapely.get_parts(geom), key=lambda g: g.area)


@examples(60)
@given(lattice_polygons())
@example(shapely.Polygon([(0, 0), (4, 0), (4, 4), (0, 4)], [[(1, 1), (3, 1), (3, 3), (1, 3)]]))
def test_convex_pieces_tile_the_polygon(poly):
    tris = shapely.get_parts(shapely.constrained_delaunay_triangles(poly))
    coords = shapely.get_coordinates(tris).reshape(-1, 4, 2)[:, :3, :]
    vxy, idx = np.unique(coords.reshape(-1, 2), axis=0, return_inverse=True)
    xy, starts = decompose.convex_pieces(vxy, idx.reshape(-1, 3), 1e-12, 64.0)
    pieces = [shapely.Polygon(p) for p in _split(xy, starts)]
    assert len(pieces) <= len(tris)
    for p, ring in zip(pieces, _split(xy, starts)):
        assert p.is_valid and decompose.is_convex(ring)
        assert shapely.convex_hull(p).area - p.area < 1e-12
    assert abs(sum(p.area for p in pieces) - poly.area) < 1e-9  # interiors disjoint
    assert shapely.symmetric_difference(shapely.union_all(pieces), poly).area < 1e-9


def test_is_convex():
    assert decompose.is_convex(np.array([[0, 0], [1, 0], [2, 0], [1, 1]], float))
    assert not decompose.is_convex(np.array([[0, 0], [2, 0], [1, 0.5], [1, 2]], float))


@examples(80)
@given(lattice_polygons())
@example(shapely.Polygon([(0, 0), (2, 0), (4, 0), (4, 1), (2, 1), (2, 3), (0, 3), (0, 1)]))
def test_ear_triangles_tile_a_simple_polygon(poly):
    poly = shapely.Polygon(shapely.orient_polygons(poly).exterior)  # holes dropped
    ring = np.asarray(poly.exterior.coords)[:-1]
    ok, tri = decompose.ear_triangles(np.ascontiguousarray(ring))
    assert ok
    tris = [shapely.Polygon(ring[t]) for t in tri]
    assert all(t.area > 0 for t in tris)
    assert abs(sum(t.area for t in tris) - poly.area) < 1e-9  # no overlaps
    assert shapely.symmetric_difference(shapely.union_all(tris), poly).area < 1e-9
    xy, starts = decompose.convex_pieces(ring, tri, 1e-12, 64.0)
    pieces = [shapely.Polygon(p) for p in _split(xy, starts)]
    assert all(decompose.is_convex(p) for p in _split(xy, starts))
    assert abs(sum(p.area for p in pieces) - poly.area) < 1e-9


def test_snap_to_vertices_and_crossings():
    # sums: a unit square and a square shifted right by 1 and up by 0.5
    sq = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
    xy, starts = _packed([sq, sq + [1, 0.5]])
    e = 1e-13
    pts = np.array([[1 + e, 1 - e],      # near a vertex
                    [1 + e, 0.5 + e],    # near (1, 0.5): a vertex of the second square
                    [0.5, 1 + e],        # on the top edge, sliding along x: no crossing
                    [1 + e, 0.25],       # on x = 1, sliding along y: no crossing near
                    [5.0, 5.0]])         # far from everything: unchanged
    along = np.array([[0, 0], [0, 0], [1, 0], [0, 1], [0, 0]], float)
    out = kfit.snap(pts, along, xy, starts, 1e-10)
    assert out[0].tolist() == [1.0, 1.0]
    assert out[1].tolist() == [1.0, 0.5]
    assert out[2].tolist() == pts[2].tolist() and out[3].tolist() == pts[3].tolist()
    assert out[4].tolist() == [5.0, 5.0]
    # a slide's end near the crossing of x = 0.5 + t with the square's top edge y = 1
    cross = kfit.snap(np.array([[0.7, 1 + e]]), np.array([[1.0, 2.0]]), xy, starts, 1e-10)
    assert cross[0, 1] == 1.0 and abs(cross[0, 0] - 0.7) < 1e-12


def test_merge_collinear():
    segs = np.array([
        [0, 0, 1, 0], [2, 0, 1, 0],       # meet end to end (one reversed)
        [1.5, 0, 3, 0],                   # overlaps
        [0, 1, 0, 2], [0, 3, 0, 4],       # same line, apart: stay two
        [5, 5, 5, 5 + 1e-13],             # shorter than tol: dropped
        [0, 0, 1, 1],                     # meets the first at an angle: stays
    ], float)
    out = kfit.merge_collinear(segs, 1e-10)
    out = out[np.lexsort(out.T[::-1])]
    assert out.tolist() == [[0, 0, 1, 1], [0, 0, 3, 0], [0, 1, 0, 2], [0, 3, 0, 4]]


def test_ring_pieces_convex_small_and_too_big():
    sq = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
    ok, xy, starts = decompose.ring_pieces(sq, 1e-12, 64.0, 64)
    assert ok and xy.tolist() == sq.tolist() and starts.tolist() == [0, 4]
    ell = np.array([[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]], float)
    ok, xy, starts = decompose.ring_pieces(ell, 1e-12, 64.0, 64)
    assert ok and len(starts) == 3
    assert sum(shapely.Polygon(p).area for p in _split(xy, starts)) == 3.0
    ok, _, _ = decompose.ring_pieces(ell, 1e-12, 64.0, 5)  # too many vertices for ear clipping
    assert not ok


def test_ring_stats_small_ring_far_from_the_origin():
    xy = np.ascontiguousarray(SMALL_FAR_RING)
    area, length = kout.ring_stats(xy, np.array([0, len(xy)]))
    assert area[0] == pytest.approx(shapely.Polygon(xy).area, rel=1e-12)
    assert length[0] == pytest.approx(shapely.LinearRing(xy).length, rel=1e-12)
