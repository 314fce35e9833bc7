"""Shape: normalisation, measurements against Shapely, interchange and bad input."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest
import shapely
from catalogue import SMALL_FAR_RING
from hypothesis import example, given
from hypothesis import strategies as st

from polycontact import InvalidShapeError, Shape
from polycontact.tolerances import default_tolerance

SQUARE = [(0.0, 0.0), (4.0, 0.0), (4.0, 4.0), (0.0, 4.0)]
HOLE = [(1.0, 1.0), (1.0, 3.0), (3.0, 3.0), (3.0, 1.0)]


@st.composite
def star_polygons(draw, max_vertices=30):
    """Random star-shaped (generally concave) simple polygons about a random centre."""
    n = draw(st.integers(3, max_vertices))
    angles = np.sort(
        np.array(draw(st.lists(st.floats(0, 2 * np.pi, exclude_max=True), min_size=n,
                               max_size=n, unique=True)))
    )
    if np.min(np.diff(np.r_[angles, angles[0] + 2 * np.pi])) < 1e-3 or np.max(
        np.diff(np.r_[angles, angles[0] + 2 * np.pi])
    ) >= np.pi:
        angles = np.linspace(0, 2 * np.pi, n, endpoint=False)
    radii = np.array(draw(st.lists(st.floats(0.2, 1.0), min_size=n, max_size=n)))
    cx, cy = draw(st.floats(-100, 100)), draw(st.floats(-100, 100))
    scale = draw(st.floats(0.01, 100))
    return np.c_[cx + scale * radii * np.cos(angles), cy + scale * radii * np.sin(angles)]


def test_orientation_is_normalised_and_indices_follow_it():
    s = Shape(SQUARE[::-1], [HOLE[::-1]])
    assert s.exterior.tolist() == [[0, 0], [4, 0], [4, 4], [0, 4]]
    assert shapely.LinearRing(s.exterior).is_ccw
    assert not shapely.LinearRing(s.holes[0]).is_ccw
    assert np.array_equal(s.loops[0], s.exterior)
    assert np.array_equal(s.loops[1], s.holes[0])


def test_closed_rings_and_repeated_vertices_are_dropped():
    s = Shape(SQUARE + [SQUARE[0]])
    assert len(s.exterior) == 4
    s = Shape([(0, 0), (0, 0), (4, 0), (4, 0), (4, 4), (0, 4), (0, 0)])
    assert len(s.exterior) == 4


def test_arrays_are_read_only_and_input_untouched():
    given_ = np.array(SQUARE[::-1])
    before = given_.copy()
    s = Shape(given_)
    assert np.array_equal(given_, before)
    with pytest.raises(ValueError):
        s.exterior[0, 0] = 1.0
    with pytest.raises(ValueError):
        s.centroid[0] = 1.0




@given(star_polygons())
@example(SMALL_FAR_RING)
def test_area_centroid_radius_match_shapely(ring):
    s = Shape(ring)
    p = shapely.Polygon(ring)
    assert s.area == pytest.approx(p.area, rel=1e-9)
    c = p.centroid
    scale = max(1.0, np.abs(ring).max())
    assert np.allclose(s.centroid, (c.x, c.y), atol=1e-9 * scale)
    assert s.bounding_radius == pytest.approx(np.hypot(*(ring - s.centroid).T).max())


def test_centroid_with_hole_matches_shapely():
    hole = [(0.5, 0.5), (0.5, 1.5), (2.5, 1.5), (2.5, 0.5)]
    s = Shape(SQUARE, [hole])
    p = shapely.Polygon(SQUARE, [hole])
    assert s.area == pytest.approx(p.area)
    assert np.allclose(s.centroid, (p.centroid.x, p.centroid.y))


# The shipped scenes hold the paper's Tables A1-A2 as printed (shared/paper/cases.json),
# so these tests run in any checkout, not only one with shared/ beside it.
EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def _scene_bodies(name: str) -> list[dict]:
    return json.loads((EXAMPLES / name).read_text())["bodies"]


CASES_JSON = Path(__file__).resolve().parents[3] / "shared" / "paper" / "cases.json"


@pytest.mark.skipif(not CASES_JSON.is_file(), reason="shared/paper/cases.json not beside")
def test_shipped_paper_scenes_hold_the_printed_tables():
    cases = json.loads(CASES_JSON.read_text())
    for k in (1, 2):
        printed = [b["vertices"] for b in cases[f"case{k}"]["bodies"]]
        assert [b["vertices"] for b in _scene_bodies(f"paper-case-{k}.json")] == printed


def test_paper_case_1_centroids_as_reported():
    reported = [(0.32, -4.75), (312.54, 20.12)]  # cases.json: case1.paper_reports.centroids
    for body, c in zip(_scene_bodies("paper-case-1.json"), reported):
        assert np.allclose(Shape(body["vertices"]).centroid, c, atol=0.005)


@pytest.mark.parametrize(
    ("vertices", "holes", "message"),
    [
        ([(0, 0), (1, 0)], (), "fewer than 3 distinct vertices"),
        ([(0, 0), (1, 0), (0, 0), (1, 0)], (), "fewer than 3 distinct vertices"),
        ([(0, 0), (1, 0), (np.nan, 1)], (), "vertex 2 has a non-finite coordinate"),
        ([(0, 0), (1, 0), (np.inf, 1)], (), "vertex 2 has a non-finite coordinate"),
        ([(0, 0), (1, 1), (2, 2)], (), "zero area"),
        ([(0, 0), (2, 2), (2, 0), (0, 2)], (), "self-intersection at (1, 1) between edge 0 and edge 2"),
        ([(0, 0), (4, 0), (4, 4), (2, 0), (0, 4)], (), "self-intersection at (2, 0)"),
        ([(0, 0), (2, 0), (1, 0), (1, 1)], (), "fold back"),
        (SQUARE, [[(5, 5), (6, 5), (6, 6)]], "hole 0 lies outside the outer loop"),
        (SQUARE, [[(1, 1), (5, 1), (5, 2)]], "hole 0 crosses the outer loop"),
        (SQUARE, [HOLE, [(2, 2), (3.5, 2), (3.5, 3.5)]], "hole 1 crosses hole 0"),
        (SQUARE, [HOLE, [(1.5, 1.5), (2.5, 1.5), (2.5, 2.5)]], "hole 0 and hole 1 overlap"),
        (SQUARE, [[(0, 0), (1, 0), (1, 1)]], "crosses the outer loop"),
        ([[0, 0, 0], [1, 0, 0], [0, 1, 0]], (), "expected an array of shape (N, 2)"),
    ],
)
def test_bad_input_is_refused_with_what_and_where(vertices, holes, message):
    with pytest.raises(InvalidShapeError) as info:
        Shape(vertices, holes)
    assert message in str(info.value)
    assert isinstance(info.value, ValueError)


def test_hole_touching_outer_loop_at_a_point_is_valid():
    s = Shape(SQUARE, [[(0, 2), (2, 3), (2, 1)]])
    assert shapely.is_valid(s.to_shapely())


def test_repair_refuses_when_the_result_is_not_one_polygon():
    with pytest.raises(InvalidShapeError, match="gives 2 polygons, not one"):
        Shape([(0, 0), (2, 2), (2, 0), (0, 2)], repair=True)


def test_paper_case_2_red_needs_repair():
    red = _scene_bodies("paper-case-2.json")[0]["vertices"]
    with pytest.raises(InvalidShapeError, match=r"self-intersection at \(10\.207"):
        Shape(red)
    fixed = Shape(red, repair=True)
    assert fixed.repairs
    assert fixed.area == pytest.approx(shapely.make_valid(shapely.Polygon(red)).area, rel=1e-5)


def test_interchange_round_trips():
    s = Shape(SQUARE, [HOLE])
    for t in (
        Shape.from_shapely(s.to_shapely()),
        Shape.from_wkt(s.to_wkt()),
        Shape.from_geojson(s.to_geojson()),
        Shape.from_geojson(json.dumps({"type": "Feature", "geometry": s.__geo_interface__})),
    ):
        assert np.array_equal(t.exterior, s.exterior)
        assert np.array_equal(t.holes[0], s.holes[0])
    assert shapely.geometry.shape(s).equals(s.to_shapely())


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda: Shape.from_wkt("POLYGON ((0 0, 1 0"), "not valid WKT"),
        (lambda: Shape.from_wkt("LINESTRING (0 0, 1 0)"), "expected one Polygon"),
        (lambda: Shape.from_geojson({"type": "Point", "coordinates": [0, 0]}), "expected a Polygon"),
        (lambda: Shape.from_geojson("{"), "not valid JSON"),
        (lambda: Shape.from_shapely(shapely.MultiPolygon([shapely.box(0, 0, 1, 1),
                                                           shapely.box(2, 0, 3, 1)])),
         "expected one Polygon"),
    ],
)
def test_interchange_errors(call, message):
    with pytest.raises(InvalidShapeError, match=message):
        call()


def test_moved_rotates_about_centroid():
    s = Shape(SQUARE)
    r = s.moved((1.0, 0.0), np.pi / 2)
    assert np.allclose(r.centroid, s.centroid + (1, 0))
    assert r.area == pytest.approx(s.area)
    expected = shapely.Polygon(np.array(SQUARE) + (1, 0)).normalize()
    assert shapely.equals_exact(shapely.Polygon(r.exterior).normalize(), expected, 1e-12)


@given(
    st.lists(st.tuples(st.integers(0, 6), st.integers(0, 6)), min_size=3, max_size=9),
)
def test_accepts_exactly_the_rings_shapely_calls_valid(points):
    """On an integer grid degeneracies are exact: touching, collinear, repeated points."""
    ring = np.array(points, dtype=float)
    keep = np.r_[True, np.any(ring[1:] != ring[:-1], axis=1)]
    cleaned = ring[keep]
    while len(cleaned) > 1 and np.all(cleaned[-1] == cleaned[0]):
        cleaned = cleaned[:-1]
    valid = len(np.unique(cleaned, axis=0)) >= 3 and shapely.is_valid(shapely.Polygon(cleaned))
    try:
        Shape(ring)
        accepted = True
    except InvalidShapeError:
        accepted = False
    assert accepted == valid, shapely.is_valid_reason(shapely.Polygon(cleaned))


@given(
    st.lists(st.tuples(st.integers(0, 8), st.integers(0, 8)), min_size=3, max_size=6),
    st.lists(st.tuples(st.integers(0, 8), st.integers(0, 8)), min_size=3, max_size=6),
)
def test_accepts_exactly_the_holes_shapely_calls_valid(hole_a, hole_b):
    outer = [(0, 0), (8, 0), (8, 8), (0, 8)]
    holes = [np.array(hole_a, float), np.array(hole_b, float)]
    for h in holes:
        if len(np.unique(h, axis=0)) < 3 or not shapely.is_valid(shapely.Polygon(h)):
            return  # rings that are invalid on their own are covered above
    valid = shapely.is_valid(shapely.Polygon(outer, holes))
    try:
        Shape(outer, holes)
        accepted = True
    except InvalidShapeError:
        accepted = False
    assert accepted == valid, shapely.is_valid_reason(shapely.Polygon(outer, holes))


def test_a_shape_is_immutable():
    s = Shape([(0, 0), (2, 0), (2, 2), (0, 2)], [[(0.5, 0.5), (1, 0.5), (1, 1)]])
    for arr in (s.exterior, *s.holes, s.centroid, *s.packed):
        assert not arr.flags.writeable
        with pytest.raises(ValueError):
            arr[0] = 0
    assert type(s._kernel) is bytes  # the kernel pack: immutable by its type
    for name in ("repairs", "_xy", "_loops", "_area", "_centroid", "_extent", "_magnitude",
                 "_tolerance", "_starts", "_radius", "_kernel"):
        with pytest.raises(AttributeError, match="immutable"):
            setattr(s, name, getattr(s, name))
        with pytest.raises(AttributeError, match="immutable"):
            delattr(s, name)
    for name in ("area", "centroid", "exterior", "holes", "loops"):
        with pytest.raises(AttributeError):
            setattr(s, name, None)
    with pytest.raises(AttributeError):
        s.anything = 1  # __slots__: no new attributes either
    assert s.area == 3.875 and s.moved((1, 0)).area == 3.875


@pytest.mark.parametrize("scale, offset", [(1.0, 0.0), (1e-9, 0.0), (1e9, 0.0), (1.0, 1e9),
                                           (1e-6, -3e5)])
def test_cached_tolerance_is_the_default_tolerance_of_the_shape(scale, offset):
    # classify() reads the tolerance cached on each shape; it must be what
    # default_tolerance computes from the coordinates, for the shape and every shape
    # made from it (moved, rotated, with holes)
    s = Shape(np.array([(0, 0), (4, 0), (4, 3), (0, 3)]) * scale + offset,
              [np.array([(1, 1), (2, 1), (2, 2)]) * scale + offset])
    for shape in (s, s.moved((5 * scale, -7 * scale), 0.3), s.moved((1e3 * scale, 0))):
        assert shape._tolerance == default_tolerance(shape.packed[0])
        assert shape._tolerance == default_tolerance(*shape.loops)


@pytest.mark.parametrize(
    "vertices, vertex, given",
    [
        ([("a", 0), (1, 0), (0, 1)], 0, "'a' (str)"),
        ([(0, 0), ("1", "0"), ("0", "1")], 1, "'1' (str)"),
        (np.array([(0, 0), (1, 0), (0, 1)]) + 0j, 0, "0j (complex128)"),
        (np.array([(0, 0), (1, 0), (0, 1)]) > 0, 0, "False (bool)"),
        ([(0, 0), (1, 0), (0, None)], 2, "None (NoneType)"),
        ([(0, 0), (1, 0), (0, True)], 2, "True (bool)"),
    ],
)
def test_coordinates_that_are_not_real_numbers_are_refused_naming_the_vertex(vertices, vertex,
                                                                             given):
    with pytest.raises(TypeError, match=f"^outer loop: vertex {vertex}: expected real "
                       f"numbers, got {re.escape(given)}$"):
        Shape(vertices)


def test_a_coordinate_that_is_not_a_number_in_a_hole_names_the_hole_and_the_vertex():
    with pytest.raises(TypeError, match=r"^hole 1: vertex 2: expected real numbers, got 'x'"):
        Shape([(0, 0), (9, 0), (9, 9), (0, 9)],
              [[(1, 1), (2, 1), (2, 2)], [(3, 3), (4, 3), (4, "x")]])


def test_integer_and_decimal_coordinates_are_accepted():
    from decimal import Decimal
    from fractions import Fraction

    assert Shape(np.array([(0, 0), (2, 0), (0, 2)], dtype=np.int16)).area == 2.0
    assert Shape([(Decimal(0), 0), (Fraction(2), 0), (0, 2)]).area == 2.0


def test_a_python_geo_interface_mapping_of_tuples_is_read():
    """``shapely.geometry.mapping`` (and the geo interface of other libraries) gives
    tuples, not lists."""
    polygon = shapely.Polygon(SQUARE, [HOLE])
    mapping = shapely.geometry.mapping(polygon)
    assert isinstance(mapping["coordinates"], tuple)
    for got in (Shape.from_geojson(mapping), Shape(mapping)):
        assert got.to_shapely().equals(polygon)


def test_an_empty_interior_ring_is_left_out_in_every_form():
    polygon = shapely.Polygon(SQUARE, [[], HOLE])
    expected = Shape(SQUARE, [HOLE])
    for got in (Shape.from_shapely(polygon), Shape.from_wkt(polygon.wkt),
                Shape.from_geojson(shapely.geometry.mapping(polygon)),
                Shape.from_geojson(json.dumps(shapely.geometry.mapping(polygon)))):
        assert len(got.holes) == 1
        assert np.array_equal(got.holes[0], expected.holes[0])
        assert got.input_loop(1) == 2
