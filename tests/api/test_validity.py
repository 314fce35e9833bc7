"""A polygon's validity is decided exactly, with no tolerance, wherever it lies.

Oracles: GEOS's ``is_valid``, and exact rational arithmetic
(:func:`exact_overlap.is_valid`) where GEOS's own arithmetic errs. Features of one body
closer than the tolerance are accepted and then decided as touching: classification,
no-fit polygons and times of impact of such bodies are checked against Shapely (within
the tolerance band: :func:`exact_overlap.widest_section`), the slab reference of
``nfp_reference`` and dense sampling.
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np
import pytest
import shapely
from catalogue import star_ring
from exact_overlap import is_valid, widest_section
from hypothesis import assume, example, given, note
from hypothesis import strategies as st
from nfp_reference import reference_region, same_region
from profiles import examples

import polycontact as pc
from polycontact import InvalidShapeError, Shape
from polycontact.limits import COORDINATE_LIMIT, EXTENT_FLOOR

#: The smallest case: vertex 3 is 5e-15 from edge 0 (the neck of a "W"), 4 float
#: spacings of the largest coordinate are 7.1e-15. GEOS calls it valid.
NECK = np.array([(0, 0), (10, 0), (10, 10), (5, 5e-15), (0, 10)], dtype=float)
SQUARE = np.array([(0, 0), (1, 0), (1, 1), (0, 1)], dtype=float)
_CODE = {pc.State.SEPARATE: 0, pc.State.CONTACT: 1, pc.State.PENETRATING: 2}


def _geos_state(a, b) -> int:
    m = shapely.relate(a, b)
    if m[0] != "F":
        return 2
    return 1 if any(m[k] != "F" for k in (1, 3, 4)) else 0


def _state_is_right(a, b, tolerance: float | None = None) -> bool:
    """Our state of shapely polygons a, b is GEOS's, or contact within the band: a gap
    up to the tolerance, or an overlap with no disc of radius above it (exactly: its
    longest vertical or horizontal section at most twice the tolerance)."""
    r = pc.classify(a, b, tolerance=tolerance)
    got, want, eps = _CODE[r.state], _geos_state(a, b), r.tolerance
    if got == want:
        return True
    if got == 1 and want == 2:
        return min(widest_section(a, b), widest_section(a, b, swap=True)) <= 2 * eps
    return got == 1 and want == 0 and shapely.distance(a, b) <= eps


def _accepted(rings) -> bool:
    try:
        Shape(rings[0], rings[1:])
    except InvalidShapeError:
        return False
    return True


# -- regressions -------------------------------------------------------------------


def test_a_vertex_a_few_float_spacings_from_an_edge_is_accepted():
    assert shapely.Polygon(NECK).is_valid
    s = Shape(NECK)
    assert s.n_vertices == 5 and s.area == pytest.approx(50.0) and s.repairs == ()
    assert Shape(NECK, repair=True).repairs == ()
    assert pc.classify(NECK, SQUARE + [4.5, -1.0]).state is pc.State.CONTACT


@pytest.mark.parametrize("offset", [(4.5, -1.0), (4.5, -1.0 + 1e-13), (4.5, 1e-14),
                                    (4.5, 0.5), (4.5, 4.9), (2.0, 2.0), (20.0, 0.0),
                                    (4.999, 5e-15), (4.5, -1.0 - 1e-11)])
def test_a_body_at_the_neck_gets_geos_state_within_the_tolerance(offset):
    # the neck is 5e-15 wide, far below the tolerance (1e-11): a square pressed into
    # it from below (overlap 1e-13 thick) is in contact; one in the notch above touches
    a, b = shapely.Polygon(NECK), shapely.Polygon(SQUARE + offset)
    assert _state_is_right(a, b) and _state_is_right(b, a)


def test_a_nearly_collinear_hole_is_accepted():
    # a hole 1e-14 high and 8 long: "zero area" at 4 float spacings of 10
    hole = [(1, 5), (9, 5), (5, 5 + 1e-14)]
    outer = [(0, 0), (10, 0), (10, 10), (0, 10)]
    assert shapely.Polygon(outer, [hole]).is_valid
    s = Shape(outer, [hole])
    assert s.area == pytest.approx(100.0) and len(s.holes) == 1


def test_edges_that_nearly_fold_are_accepted():
    # a spike 1e-14 wide at its base, 3 long: p -> q -> r with r 1e-14 from pq
    ring = [(0, 0), (4, 0), (4, 4), (1, 4), (4, 4 + 1e-14), (4, 5), (0, 5)]
    assert shapely.Polygon(ring).is_valid
    assert Shape(ring).n_vertices == 7
    folded = [(0, 0), (4, 0), (4, 4), (1, 4), (3, 4), (4, 4), (4, 5), (0, 5)]
    assert not shapely.Polygon(folded).is_valid
    with pytest.raises(InvalidShapeError, match="fold back"):
        Shape(folded)


def test_a_sliver_keeps_its_area_and_centroid():
    # a triangle whose third vertex is one float spacing off the middle of its long
    # edge: its area (about 1e-17) is below the rounding of the float sums; summed exactly
    a, b = (0.1, 0.2), (0.7, 0.9)
    c = (0.4, float(np.nextafter((0.2 + 0.9) / 2, 1.0)))
    s = Shape([a, b, c])
    (ax, ay), (bx, by), (cx, cy) = ((Fraction(x), Fraction(y)) for x, y in (a, b, c))
    area = abs((bx - ax) * (cy - ay) - (by - ay) * (cx - ax)) / 2
    assert 0 < area < Fraction(1, 10**16)
    assert s.area == pytest.approx(float(area), rel=1e-12)
    assert s.centroid.tolist() == pytest.approx([float((ax + bx + cx) / 3),
                                                 float((ay + by + cy) / 3)], rel=1e-15)


def test_the_empty_ring_of_a_shapely_polygon_is_left_out():
    poly = shapely.from_wkt("POLYGON ((0 0, 9 0, 9 9, 0 9, 0 0), EMPTY, (1 1, 2 1, 2 2, 1 1))")
    assert poly.is_valid
    s = Shape(poly)
    assert len(s.holes) == 1 and s.input_loop(1) == 2


# -- acceptance is validity, wherever the polygon lies -----------------------------


@st.composite
def polygons(draw):
    """Rings (with a hole, sometimes) full of near-degeneracies: a vertex on, or a few
    float spacings either side of, a non-adjacent edge; slits and spikes of a few
    spacings; random rings on a small grid (crossing, touching, folding, collinear);
    random stars."""
    kind = draw(st.sampled_from(["neck", "slit", "hole", "grid", "star"]))
    tiny = st.sampled_from([0.0, 1e-15, 5e-15, 1e-13, -1e-15, 2.0**-50, 1e-300])
    if kind == "neck":
        rings = [np.array([(0, 0), (10, 0), (10, 10), (5, draw(tiny)), (0, 10)], dtype=float)]
    elif kind == "slit":
        w = abs(draw(tiny))
        rings = [np.array([(0, 0), (1, 0), (1, 1), (0.5, 1), (0.5, 1 + w), (1, 1 + w),
                           (1, 2), (0, 2)], dtype=float)]
    elif kind == "hole":
        d = draw(tiny)
        rings = [np.array([(0, 0), (10, 0), (10, 10), (0, 10)], dtype=float),
                 np.array([(5, d), (7, 3), (3, 3)], dtype=float)]
    elif kind == "grid":
        n = draw(st.integers(3, 7))
        rings = [np.array(draw(st.lists(st.tuples(st.integers(0, 3), st.integers(0, 3)),
                                        min_size=n, max_size=n)), dtype=float)]
    else:
        rings = [star_ring(draw, 3, 12, 1.0, 9.0, False)]
    angle = draw(st.sampled_from([0.0, 0.5, 2.0]))
    c, s = np.cos(angle), np.sin(angle)
    scale = 10.0 ** draw(st.integers(-6, 6))
    return [r @ np.array([[c, s], [-s, c]]) * scale for r in rings]


def _in_range(rings) -> bool:
    """Within the range polycontact carries (refused there with its own message)."""
    xy = np.concatenate(rings)
    if not np.isfinite(xy).all() or np.abs(xy).max() > COORDINATE_LIMIT:
        return False
    extent = float(np.ptp(xy, axis=0).max())
    return extent == 0.0 or extent >= EXTENT_FLOOR


translations = st.tuples(*[st.floats(-1e100, 1e100, allow_nan=False)] * 2)


@given(polygons(), translations)
@examples(600)
@example([NECK], (1e6, 1e6))
@example([NECK], (0.0, 0.0))
def test_acceptance_is_the_validity_of_the_polygon_as_rounded(rings, t):
    """For any polygon P and any translation t float64 represents, ``Shape(fl(P + t))``
    is accepted exactly when the rounded polygon fl(P + t) is valid: GEOS's verdict,
    or exact arithmetic's where GEOS errs. Acceptance depends on the coordinates alone,
    never on where they lie (rounding may make the polygon valid or invalid: both
    sides see the same rounded coordinates)."""
    moved = [r + np.asarray(t) for r in rings]
    assume(_in_range(moved))
    poly = shapely.Polygon(moved[0], moved[1:])
    ours, geos = _accepted(moved), bool(poly.is_valid)
    note(f"accepted {ours}, GEOS {geos}")
    assert ours == geos or ours == is_valid(poly)


@given(polygons(), st.integers(-40, 40), st.integers(-2**20, 2**20), st.integers(-2**20, 2**20))
@examples(300)
def test_an_exact_translation_keeps_acceptance(rings, e, kx, ky):
    """Translated without rounding (P + t exact), a polygon is accepted at one
    position exactly when it is at the other: accepted ones stay accepted, refused ones
    refused."""
    t = np.array([kx, ky], dtype=float) * 2.0**e
    moved = [r + t for r in rings]
    tx, ty = Fraction(t[0]), Fraction(t[1])
    assume(all(Fraction(mx) == Fraction(rx) + tx and Fraction(my) == Fraction(ry) + ty
               for m, r in zip(moved, rings) for (mx, my), (rx, ry) in zip(m.tolist(), r.tolist())))
    assume(_in_range(rings) and _in_range(moved))
    assert _accepted(moved) == _accepted(rings)


# -- repairs -----------------------------------------------------------------------


@st.composite
def broken_rings(draw):
    """Random rings on a fine grid, scaled and moved: most cross or touch themselves."""
    n = draw(st.integers(4, 9))
    pts = draw(st.lists(st.tuples(st.integers(0, 8), st.integers(0, 8)), min_size=n, max_size=n))
    scale = 10.0 ** draw(st.integers(-4, 4))
    offset = draw(st.sampled_from([0.0, 1e3, 1e9]))
    return np.array(pts, dtype=float) * scale + offset


@given(broken_rings())
@examples(400)
@example(np.array([(0, 0), (4, 0), (4, 4), (2, 4), (2, 6), (2, 4), (0, 4)], dtype=float))
@example(np.array([(0, 0), (4, 0), (4, 4), (2, 4), (3, 2), (1, 2), (2, 4), (0, 4)], dtype=float))
@example(np.array([(1000.0, 1000.5), (1000.7, 1000.5), (1000.0, 1000.6), (1000.8, 1000.3),
                   (1000.6, 1000.7)]))  # far out, GEOS's overlay would move a node
def test_repaired_shapes_are_valid_and_within_the_tolerance(ring):
    """A repair gives a valid shape whose outline lies on the input's within the
    tolerance, and whose region is GEOS's reading of the input (``make_valid``)
    within the tolerance; or it refuses, saying why."""
    try:
        s = Shape(ring, repair=True)
    except InvalidShapeError as exc:
        assert "cannot repair" in str(exc) or "fewer than 3" in str(exc) or "zero area" in str(exc)
        return
    got = s.to_shapely()
    assert got.is_valid and is_valid(got)
    eps = pc.default_tolerance(ring)
    lines = shapely.LinearRing(ring)
    assert _farthest(got, lines) <= eps
    # the region: GEOS's reading of the ring moved to its corner (exactly, Sterbenz),
    # where GEOS's overlay keeps its nodes (far out, 1e3 away and more, its fallback can
    # move a crossing node along a line, and so misread the region), moved back by a
    # rounding per term. Compared by area: the two outlines follow the same lines, each
    # within its error (the tolerance; GEOS's, its distance to the lines), so they differ
    # by at most a band that wide along them (spikes and slivers of no width, kept by one
    # and not the other, weigh nothing)
    corner = ring.min(axis=0)
    reading = shapely.affinity.translate(
        shapely.make_valid(shapely.Polygon(ring - corner), method="structure",
                           keep_collapsed=False), *corner)
    error = eps + (0.0 if reading.is_empty else _farthest(reading, lines))
    assert (shapely.symmetric_difference(got, reading).area
            <= 2.0 * error * (got.length + reading.length))
    if s.repairs:
        assert "make_valid" in s.repairs[0]
    for k, loop in enumerate(s.loops):  # the caller's numbers, where there are some
        for i in range(len(loop)):
            v = s.input_vertex(k, i)
            assert v is None or np.abs(ring[v] - loop[i]).max() <= eps


#: A vertex exactly on a non-adjacent edge (3 on 0) that GEOS misses: GEOS calls the
#: ring valid; exactly, it pinches into two triangles.
GEOS_MISSES = np.array([
    [0.051214942789648, 0.37800719204204025], [7.971105113911915, 5.861975746864205],
    [2.48713655908975, 13.781865917986472], [2.031187485570215, 1.7489993307475815],
    [-5.432753612032517, 8.297897363164306]])


def test_a_vertex_exactly_on_an_edge_is_refused_where_geos_misses_it():
    poly = shapely.Polygon(GEOS_MISSES)
    assert poly.is_valid and not is_valid(poly)
    with pytest.raises(InvalidShapeError, match="self-intersection at .* between edge 0 and edge 3"):
        Shape(GEOS_MISSES)
    # repaired: GEOS's make_valid keeps it, snapping separates the two triangles
    with pytest.raises(InvalidShapeError, match="cannot repair: .* gives 2 polygons"):
        Shape(GEOS_MISSES, repair=True)


def _farthest(geom, lines) -> float:
    """The largest distance from a vertex of ``geom`` to ``lines``."""
    return float(shapely.distance(shapely.points(shapely.get_coordinates(geom)), lines).max())


def test_a_repair_stays_within_the_tolerance_where_make_valid_moves_the_outline():
    # GEOS's make_valid puts the crossing of edges 6 and 2 1.6e-9 off both (its
    # overlay falls back on snapping), 100 times the tolerance: read from GEOS's noding
    # instead, the repair is within a few float spacings of the loop
    ring = np.array([(1000.0, 1000.0), (1000.1, 1000.1), (1000.1, 1000.0), (1000.0, 1000.5),
                     (1000.5, 1000.2), (1000.3, 1000.4), (1000.6, 1000.1)])
    eps = pc.default_tolerance(ring)
    lines = shapely.LinearRing(ring)
    geos = shapely.make_valid(shapely.Polygon(ring), method="structure")
    assert _farthest(geos, lines) > 100 * eps
    s = Shape(ring, repair=True)
    assert _farthest(s.to_shapely(), lines) <= 1e-3 * eps
    assert "moved the outline by 1.64e-09" in s.repairs[0]
    assert shapely.hausdorff_distance(s.to_shapely(), geos) < 1e-8  # (GEOS's error)
    assert s.input_vertex(0, 0) == 2  # (1000.1, 1000) is the caller's vertex 2


def test_a_far_off_ring_geos_misreads_is_refused_not_repaired_wrongly():
    # 1e9 from the origin GEOS's make_valid reads this ring's crossings into a region of
    # area 0.0489, and the repair made 0.0518 of it; moved exactly to its corner GEOS
    # reads two polygons (one of them of 1e-3 the area): the repair refuses
    ring = np.array([(0.0, 0.0), (0.4, 0.6), (0.3, 0.5), (0.6, 0.8), (0.0, 0.0), (0.4, 0.7),
                     (0.1, 0.0)])
    # (also far out in x alone, y near the origin)
    for offset in ((1e9, 1e9), (1e9, 0.001)):
        with pytest.raises(InvalidShapeError,
                           match="cannot repair: .*moved exactly to their corner"):
            Shape(ring + offset, repair=True)


def test_a_repair_snaps_what_geos_leaves_meeting(monkeypatch):
    # GEOS's make_valid can return rings whose features still meet exactly (as above);
    # played here by a make_valid that returns its input, a ring touching itself at a
    # vertex: the repair snaps it onto a grid far below the tolerance, where GEOS's
    # noding turns the loop into a hole, and says so; the caller's numbers follow.
    ring = np.array([(0, 0), (4, 0), (4, 4), (2, 4), (3, 2), (1, 2), (2, 4), (0, 4)]) + 0.1
    monkeypatch.setattr(shapely, "make_valid", lambda geom, **kw: geom)
    s = Shape(ring, repair=True)
    assert "snapped onto a grid of" in s.repairs[0]
    got = s.to_shapely()
    assert got.is_valid and is_valid(got) and len(s.holes) == 1
    grid = pc.tolerances.snap_grid(pc.default_tolerance(ring))
    assert 0 < grid < pc.default_tolerance(ring) / 100
    assert shapely.hausdorff_distance(got, shapely.Polygon(ring[[0, 1, 2, 3, 6, 7]],
                                                            [ring[[3, 4, 5]]])) <= grid
    for k, loop in enumerate(s.loops):
        numbers = [s.input_vertex(k, i) for i in range(len(loop))]
        assert None not in numbers
        assert np.abs(ring[numbers] - loop).max() <= grid
    assert sorted(s.input_vertex(1, i) for i in range(3)) == [3, 4, 5]


# -- bodies with features closer than the tolerance --------------------------------


@st.composite
def near_the_neck(draw):
    """The neck polygon (its gap drawn from 0 to far below the tolerance, either side),
    scaled and moved, and a square or triangle placed at the neck within a few
    tolerances of touching, anywhere around it."""
    gap = draw(st.sampled_from([5e-15, 1e-13, 1e-12, 2e-12]))
    ring = np.array([(0, 0), (10, 0), (10, 10), (5, gap), (0, 10)], dtype=float)
    size = draw(st.sampled_from([0.1, 1.0, 4.0]))
    body = draw(st.sampled_from([SQUARE, np.array([(0, 0), (1, 0), (0.5, 1)])])) * size
    where = np.array([5 - draw(st.floats(0, 1)) * size,
                      draw(st.sampled_from([-size, 0.0, gap])) + draw(st.floats(-3e-11, 3e-11))])
    scale = 10.0 ** draw(st.integers(-3, 3))
    offset = draw(st.sampled_from([0.0, 1e3]))
    ring = ring * scale + offset
    assume(shapely.Polygon(ring).is_valid)  # (the offset's rounding may close the neck)
    return ring, (body + where) * scale + offset


@given(near_the_neck())
@examples(300)
def test_bodies_at_a_neck_thinner_than_the_tolerance_get_geos_state(pair):
    a, b = (shapely.Polygon(r) for r in pair)
    assert _state_is_right(a, b) and _state_is_right(b, a)


@pytest.mark.parametrize("gap", [5e-15, 1e-13, 0.5])
def test_the_no_fit_polygon_of_a_body_with_a_neck(gap):
    neck = Shape([(0, 0), (10, 0), (10, 10), (5, gap), (0, 10)])
    for orbiting, fixed in ((Shape(SQUARE), neck), (neck, Shape(SQUARE * 0.5))):
        nfp = pc.no_fit_polygon(orbiting, fixed)
        want = reference_region(orbiting.to_shapely(), fixed.to_shapely(), nfp.reference)
        assert same_region(nfp.region, want) is None


def test_a_body_falls_into_a_notch_and_slides_past_a_neck():
    neck = Shape(NECK)
    # a half square falling into the notch: first touches the notch's sides when its
    # lower corners meet them, 0.5 above the neck (y = 12 - t): t = 11.5
    hit = pc.time_of_impact(Shape(SQUARE * 0.5 + [4.75, 12.0]), pc.Motion(velocity=(0.0, -1.0)),
                            neck, pc.Motion(), t_max=20.0)
    assert hit.collides and hit.time == pytest.approx(11.5, abs=2e-4)
    # sliding along the bottom edge, under the neck (5e-15 above it): contact, never a
    # collision
    slide = pc.time_of_impact(Shape(SQUARE + [-2.0, -1.0]), pc.Motion(velocity=(1.0, 0.0)),
                              neck, pc.Motion(), t_max=11.0)
    assert not slide.collides and slide.first_contact == pytest.approx(1.0, abs=1e-4)
