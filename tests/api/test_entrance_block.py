"""Entrance block: the components of the finite cover, their union, the two methods."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from hypothesis import given, note
from hypothesis import strategies as st
from profiles import examples

import polycontact as pc
from polycontact.entrance import Element

SQUARE = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
ELL = [(0.0, 0.0), (3.0, 0.0), (3.0, 1.0), (1.0, 1.0), (1.0, 3.0), (0.0, 3.0)]
FRAME = [(0.0, 0.0), (4.0, 0.0), (4.0, 4.0), (0.0, 4.0)]
NOTCHED_HOLE = [(1.0, 1.0), (3.0, 1.0), (3.0, 2.0), (2.0, 2.0), (2.0, 3.0), (1.0, 3.0)]


def _star(draw, n, r_lo, r_hi, centre):
    """A star-shaped ring about ``centre`` with angular gaps well under pi."""
    jitter = np.array(draw(st.lists(st.floats(-0.3, 0.3), min_size=n, max_size=n)))
    angles = (np.arange(n) + jitter) * 2 * np.pi / n + draw(st.floats(0, 2 * np.pi))
    radii = np.array(draw(st.lists(st.floats(r_lo, r_hi), min_size=n, max_size=n)))
    return centre + np.c_[radii * np.cos(angles), radii * np.sin(angles)]


@st.composite
def bodies(draw, max_vertices=10, holes=True):
    """Random star-shaped (mostly concave) bodies, some with a star-shaped hole."""
    centre = np.array([draw(st.floats(-5, 5)), draw(st.floats(-5, 5))])
    outer = _star(draw, draw(st.integers(3, max_vertices)), 0.4, 2.0, centre)
    loops = []
    room = shapely.Polygon(outer).exterior.distance(shapely.Point(centre))
    if holes and room > 0.05 and shapely.Polygon(outer).contains(shapely.Point(centre)) \
            and draw(st.booleans()):
        loops.append(_star(draw, draw(st.integers(3, 6)), 0.2 * room, 0.8 * room, centre))
    return pc.Shape(outer, loops)


def _minkowski_reference(a: pc.Shape, b: pc.Shape, a0) -> shapely.Geometry:
    """B ⊕ (a0 − A) by triangles: the convex hulls of the sums of triangle pairs."""
    reflected = shapely.Polygon(a0 - a.exterior, [a0 - h for h in a.holes])
    ta = shapely.get_parts(shapely.constrained_delaunay_triangles(reflected))
    tb = shapely.get_parts(shapely.constrained_delaunay_triangles(b.to_shapely()))
    pa = shapely.get_coordinates(ta).reshape(len(ta), 4, 2)[:, :3]
    pb = shapely.get_coordinates(tb).reshape(len(tb), 4, 2)[:, :3]
    sums = (pa[:, None, :, None] + pb[None, :, None, :]).reshape(-1, 9, 2)
    return shapely.union_all(shapely.convex_hull(shapely.multipoints(sums)))


def note_bodies(*shapes: pc.Shape) -> None:
    """Print the coordinates of a failing example (a Shape's repr omits them)."""
    for s in shapes:
        note(repr([loop.tolist() for loop in s.loops]))


def _same_region(g1, g2, rel=1e-9, grid=0.0):
    """g1 and g2 are one region up to slivers along their boundaries: their symmetric
    difference is within ``rel`` of their area, or within a band along their outlines
    as wide as the rounding of their coordinates (16 float spacings of the largest
    |coordinate|) plus the ``grid`` a union was snapped to."""
    bounds = [v for g in (g1, g2) if not g.is_empty for v in g.bounds]
    width = grid + 16.0 * float(np.spacing(max([abs(v) for v in bounds] + [1e-300])))
    allowed = max(rel * max(g1.area, g2.area), width * (g1.length + g2.length), 1e-300)
    assert g1.symmetric_difference(g2).area <= allowed


# -- hand cases ------------------------------------------------------------------------
def test_two_squares_side_by_side():
    a = pc.Shape(SQUARE)
    eb = pc.entrance_block(a, a.moved((3.0, 0.0)), method="pairs")
    assert [len(eb.of_family(f)) for f in ("A2-B0", "A0-B2", "A1-B1")] == [4, 4, 16]
    assert np.array_equal(eb.reference, [0.5, 0.5])
    assert eb.to_shapely().equals(shapely.box(2.5, -0.5, 4.5, 1.5))
    # B's vertex 0 at (3, 0) is in A when a0 is in (3, 0) + a0 − A
    first = eb.components[0]
    assert first.kind == "A2-B0" and first.features == (Element("b", "vertex", 0, 0),)
    assert first.geometry.equals(shapely.box(2.5, -0.5, 3.5, 0.5))
    assert first.label == "E(A(2), B(0))[B vertex 0]"
    # A's vertex 2 at (1, 1) is in B when a0 is in B + a0 − (1, 1)
    third_of_a = eb.of_family("A0-B2")[2]
    assert third_of_a.features == (Element("a", "vertex", 0, 2),)
    assert third_of_a.geometry.equals(shapely.box(2.5, -0.5, 3.5, 0.5))


def test_edge_pair_parallelogram_and_parallel_pairs_are_segments():
    a = pc.Shape(SQUARE)
    eb = pc.entrance_block(a, a.moved((3.0, 0.0)), method="pairs")
    pairs = {(c.features[0].index, c.features[1].index): c for c in eb.of_family("A1-B1")}
    # edge 0 of A: (0,0)->(1,0); edge 1 of B: (4,0)->(4,1): f ⊕ (a0 − e)
    expected = shapely.Polygon([(4.5, 0.5), (4.5, 1.5), (3.5, 1.5), (3.5, 0.5)])
    assert pairs[0, 1].geometry.equals(expected)
    assert pairs[0, 1].label == "E(A(1), B(1))[A edge 0, B edge 1]"
    # edges 0 of A and 2 of B are parallel: a segment, kept, inside the union
    flat = pairs[0, 2]
    assert flat.is_degenerate and flat.geometry.geom_type == "LineString"
    assert flat.geometry.equals(shapely.LineString([(2.5, 1.5), (4.5, 1.5)]))
    degenerate = [c for c in eb.components if c.is_degenerate]
    assert len(degenerate) == 8  # 2 horizontal × 2 horizontal + 2 vertical × 2 vertical
    union = eb.to_shapely()
    assert all(union.covers(c.geometry) for c in degenerate)


def test_holes_contribute_vertices_and_edges():
    a = pc.Shape(ELL)
    b = pc.Shape(FRAME, [NOTCHED_HOLE])
    for method, n_edge in (("pairs", 6 * 10), ("swept", 10)):
        eb = pc.entrance_block(a, b, method=method)
        kinds = [c.kind for c in eb.components]
        assert kinds.count("A2-B0") == 10 and kinds.count("A0-B2") == 6
        assert len(eb.of_family("A1-B1")) == n_edge
        # B loop 1 (the hole, given counter-clockwise, stored reversed): stored vertex 2
        # is vertex 3 as given
        hole_vertex = eb.components[4 + 2]
        assert hole_vertex.features == (Element("b", "vertex", 1, 3),)
        assert str(hole_vertex.features[0]) == "B vertex 3 of hole 0"
    # A with a hole: E(A(2), B(0)_i) is A reflected, hole included
    eb = pc.entrance_block(b, a, reference=(0.0, 0.0))
    first = eb.components[0].geometry
    assert len(first.interiors) == 1
    assert first.area == pytest.approx(b.area)
    assert first.equals(shapely.Polygon(-b.exterior, [-b.holes[0]]))


def test_l_fits_in_notched_hole_the_block_has_a_hole():
    a = pc.Shape([(0.0, 0.0), (0.5, 0.0), (0.5, 0.5), (0.0, 0.5)])
    b = pc.Shape(FRAME, [NOTCHED_HOLE])
    for method in ("pairs", "swept"):
        union = pc.entrance_block(a, b, method=method).to_shapely()
        assert union.geom_type == "Polygon" and len(union.interiors) == 1
        _same_region(union, _minkowski_reference(a, b, a.centroid))


def test_reference_point_moves_the_block():
    a, b = pc.Shape(ELL), pc.Shape(FRAME, [NOTCHED_HOLE]).moved((6.0, 1.0))
    at_centroid = pc.entrance_block(a, b).to_shapely()
    shifted = pc.entrance_block(a, b, reference=(-2.0, 7.5)).to_shapely()
    d = np.array([-2.0, 7.5]) - a.centroid
    _same_region(shifted, shapely.affinity.translate(at_centroid, *d))


def test_swept_uses_the_splice_and_the_edge_union_alike():
    # a convex loop (spliced) and a concave one (edge by edge) along the same edge
    from polycontact.entrance import _splice, _swept_loop

    v = np.array([0.7, 0.2])
    square = np.array(SQUARE)
    ell = np.array(ELL)
    assert _splice(square, v) is not None
    assert _splice(ell, np.array([1.0, 1.0])) is not None  # monotone across (1, 1)
    assert _splice(ell, np.array([1.0, -1.0])) is None  # a line along (1, -1) meets it twice
    for loop, step in ((square, v), (ell, v), (ell, np.array([3.0, 0.0])), (ell, np.array([1.0, -1.0]))):
        edges = [shapely.Polygon([p, q, q + step, p + step])
                 for p, q in zip(loop, np.roll(loop, -1, axis=0))]
        area, lines = _swept_loop(loop, step, 1e-12)
        _same_region(area, shapely.union_all(edges))
        assert len(lines) == (3 if step[1] == 0.0 and loop is ell else 0)  # 3 edges along x


def test_curve_sweep_is_not_the_filled_sweep():
    # a long square sliding a little: the boundary sweeps two thin strips, not the square
    big = np.array([(0.0, 0.0), (10.0, 0.0), (10.0, 10.0), (0.0, 10.0)])
    from polycontact.entrance import _swept_loop

    area, lines = _swept_loop(big, np.array([1.0, 0.0]), 1e-12)
    _same_region(area, shapely.box(0, 0, 1, 10).union(shapely.box(10, 0, 11, 10)))
    # the edges along the motion sweep segments, kept apart
    assert shapely.union_all(lines).equals(
        shapely.MultiLineString([[(0, 0), (11, 0)], [(11, 10), (0, 10)]]))


def test_no_pinhole_where_many_components_meet():
    # Regression: the snapped union of A with itself had a hole 1.4e-14 wide where
    # several components meet; its corners, taken as outline points, lie 0.21 inside E.
    a = pc.Shape([(0.03807015713455442, 2.000049816043191),
                  (0.29077141391611083, 3.6706055138781286),
                  (-1.2566393287113387, 2.892965327746735),
                  (-1.2488407611933097, 1.5389124590139875),
                  (-0.5230174431123771, 1.610559239058842)])
    union = pc.entrance_block(a, a, method="pairs").to_shapely()
    assert union.geom_type == "Polygon" and len(union.interiors) == 0
    _same_region(union, _minkowski_reference(a, a, a.centroid))


def test_bad_input_is_refused():
    a = pc.Shape(SQUARE)
    with pytest.raises(ValueError, match="method must be one of 'swept', 'pairs', got 'fast'"):
        pc.entrance_block(a, a, method="fast")
    with pytest.raises(ValueError, match="reference: expected two finite numbers"):
        pc.entrance_block(a, a, reference=(1.0, np.nan))
    with pytest.raises(ValueError, match="reference: expected two"):
        pc.entrance_block(a, a, reference=(1.0, 2.0, 3.0))
    with pytest.raises(pc.InvalidShapeError, match="b: outer loop: fewer than 3"):
        pc.entrance_block(a, [(0, 0), (1, 1)])
    with pytest.raises(ValueError, match="family must be one of"):
        pc.entrance_block(a, a).of_family("A1e-B1f")


def test_inputs_untouched_and_result_read_only():
    ref = np.array([0.25, 0.25])
    ring = np.array(ELL)
    eb = pc.entrance_block(ring, pc.Shape(FRAME), reference=ref)
    assert np.array_equal(ring, ELL) and np.array_equal(ref, [0.25, 0.25])
    ref[0] = 9.0
    assert eb.reference[0] == 0.25
    with pytest.raises(ValueError):
        eb.reference[0] = 1.0


# -- random bodies -----------------------------------------------------------------------
@given(bodies(), bodies())
def test_the_two_methods_give_the_same_region(a, b):
    note_bodies(a, b)
    pairs = pc.entrance_block(a, b, method="pairs")
    swept = pc.entrance_block(a, b, method="swept")
    # B ⊕ (a0 − A) is connected, and so is the union of the components
    assert pairs.to_shapely().geom_type == swept.to_shapely().geom_type == "Polygon"
    _same_region(pairs.to_shapely(), swept.to_shapely())
    assert pairs.area == pytest.approx(swept.area, rel=1e-9)


@examples(60)
@given(bodies(max_vertices=8), bodies(max_vertices=8))
def test_union_is_the_minkowski_sum(a, b):
    note_bodies(a, b)
    _same_region(pc.entrance_block(a, b).to_shapely(), _minkowski_reference(a, b, a.centroid))


@examples(60)
@given(bodies(max_vertices=8), bodies(max_vertices=8))
def test_each_swept_region_is_the_union_of_its_edge_pairs(a, b):
    note_bodies(a, b)
    pairs = pc.entrance_block(a, b, method="pairs")
    swept = pc.entrance_block(a, b, method="swept")
    n_b = b.n_vertices
    scale = max(1.0, float(np.abs(swept.to_shapely().bounds).max()))
    for f, comp in enumerate(swept.of_family("A1-B1")):
        mine = pairs.of_family("A1-B1")[f::n_b]
        assert {c.features[1] for c in mine} == set(comp.features)
        # on a fine grid: GEOS's floating union of pieces whose edges lie ulps apart can
        # drop area (test_nfp::test_reference_union_of_near_coincident_hulls)
        union = shapely.union_all([c.geometry for c in mine], grid_size=1e-13 * scale)
        _same_region(union.buffer(0), comp.geometry.buffer(0), grid=1e-13 * scale)
        # equal as closed sets, segments included: each within 1e-9 of the other
        assert union.buffer(1e-9 * scale).covers(comp.geometry)
        assert comp.geometry.buffer(1e-9 * scale).covers(union)


@examples(60)
@given(bodies(max_vertices=7), bodies(max_vertices=7), st.data())
def test_components_mean_what_their_features_say(a, b, data):
    note_bodies(a, b)
    """a0 in a component iff its features meet when A is moved there (closed sets)."""
    for method in ("pairs", "swept"):
        eb = pc.entrance_block(a, b, method=method)
        lo, hi = np.array(eb.to_shapely().bounds).reshape(2, 2)
        for _ in range(5):
            p = lo + (hi - lo) * np.array([data.draw(st.floats(-0.1, 1.1)) for _ in range(2)])
            moved = a.moved(p - eb.reference)
            point = shapely.Point(p)
            for c in eb.components:
                if _outline(c.geometry).distance(point) < 1e-9:
                    continue  # too close to call in floating point
                feat = c.features
                if c.kind == "A2-B0":
                    meets = moved.to_shapely().intersects(shapely.Point(_vertex(b, feat[0])))
                elif c.kind == "A0-B2":
                    meets = b.to_shapely().intersects(
                        shapely.Point(_vertex(moved, feat[0])))
                elif c.kind == "A1e-B1f":
                    meets = _edge(moved, feat[0]).intersects(_edge(b, feat[1]))
                else:
                    meets = moved.to_shapely().boundary.intersects(_edge(b, feat[0]))
                assert bool(c.geometry.intersects(point)) == bool(meets), (c.label, p)


def _outline(geom: shapely.Geometry) -> shapely.Geometry:
    """Rings of the areas and the zero-width segments of a component."""
    parts = shapely.get_parts(shapely.get_parts(geom))
    return shapely.union_all([p.boundary if p.geom_type == "Polygon" else p for p in parts])


def _stored(s: pc.Shape, el: Element) -> int:
    """The stored index of an element given in the caller's numbering."""
    index = s.input_vertex if el.kind == "vertex" else s.input_edge
    found = [i for i in range(len(s.loops[el.loop])) if index(el.loop, i) == el.index]
    assert len(found) == 1, el
    return found[0]


def _vertex(s: pc.Shape, el: Element) -> np.ndarray:
    return s.loops[el.loop][_stored(s, el)]


def _edge(s: pc.Shape, el: Element) -> shapely.LineString:
    loop = s.loops[el.loop]
    i = _stored(s, el)
    return shapely.LineString([loop[i], loop[(i + 1) % len(loop)]])


@pytest.mark.parametrize("side", [1e105, 1e154])
def test_entrance_block_of_huge_squares_says_why(side):
    # Before: a bare "ValueError: max() arg is an empty sequence".
    import warnings

    sq = np.array([(0, 0), (1, 0), (1, 1), (0, 1)], dtype=float) * side
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # Shape's own overflow, if any
        with pytest.raises(pc.InvalidShapeError, match="overflow float64"):
            pc.entrance_block(sq, sq)


def test_union_of_components_a_hole_snaps_onto_its_shell():
    # GEOS's snap-rounded union refused these components ("side location conflict":
    # snapping made one invalid), so .area raised for two valid bodies (CI seed).
    from nfp_reference import reference_region, same_region

    a = pc.Shape(
        [[0.3958310055569007, 3.9279007059405204], [-0.0015716512765144755, 4.402340680364698],
         [-0.402291098272617, 3.993491128002938], [0.0237765475853263, 3.598359403260844]],
        [[[0.03924935039413392, 3.9148615774538986], [-0.027557328357078945, 3.9565765988148796],
          [-0.05056356214843421, 4.03673657826828], [0.01348515707822336, 4.171345166735382],
          [0.0625, 4.0]]])
    b = pc.Shape(
        [[0.3958310055569007, 4.92790070594052], [-0.0019531200329500277, 5.499996185307585],
         [-0.499996185307585, 4.99804687996705], [0.0237765475853263, 4.598359403260844]],
        [[[0.03924935039413392, 4.914861577453899], [-0.04592498523364826, 4.966633545129737],
          [-0.10112712429686842, 5.073473156536559], [0.03862712429686843, 5.118882064536894],
          [0.125, 5.0]]])
    for method in ("swept", "pairs"):
        eb = pc.entrance_block(a, b, method=method)
        want = reference_region(a.to_shapely(), b.to_shapely(), eb.reference)
        assert same_region(eb.to_shapely(), want, rel=1e-6) is None


def test_edge_pairs_beyond_their_limit_are_refused_before_any_is_built(monkeypatch):
    a = pc.Shape(SQUARE)
    b = a.moved((3.0, 0.0))
    monkeypatch.setattr(pc.limits, "MAX_EDGE_PAIRS", 15)
    with pytest.raises(pc.EntranceBlockTooLargeError,
                       match=r"16 edge-pair components .*MAX_EDGE_PAIRS = 15"):
        pc.entrance_block(a, b, method="pairs")
    assert len(pc.entrance_block(a, b).components) == 12  # (swept: one per edge of B)
    monkeypatch.setattr(pc.limits, "MAX_EDGE_PAIRS", 16)
    assert len(pc.entrance_block(a, b, method="pairs").of_family("A1-B1")) == 16
    assert issubclass(pc.EntranceBlockTooLargeError, (pc.WorkLimitError, MemoryError))
