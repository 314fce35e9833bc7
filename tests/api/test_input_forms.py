"""One way in: every accepted form of a body gives the same answer at every
public entry point, and every bad argument the right exception naming the argument."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest
import shapely

import polycontact as pc
from polycontact.shape import as_shape

# A 10 x 10 square with a hole; B a 3 x 3 square with a hole, touching A's right side.
A_OUTER = [(0.0, 0.0), (10.0, 0.0), (10.0, 10.0), (0.0, 10.0)]
A_HOLES = [[(2.0, 2.0), (2.0, 4.0), (4.0, 4.0), (4.0, 2.0)]]
B_OUTER = [(10.0, 2.0), (13.0, 2.0), (13.0, 5.0), (10.0, 5.0)]
B_HOLES = [[(11.0, 3.0), (11.0, 4.0), (12.0, 4.0), (12.0, 3.0)]]


class GeoThing:
    """A foreign geometry object: only ``__geo_interface__``."""

    def __init__(self, mapping: dict) -> None:
        self.__geo_interface__ = mapping


def forms(outer: list, holes: list) -> dict:
    """Every accepted form of one body, by name."""
    poly = shapely.Polygon(outer, holes)
    geojson = json.loads(shapely.to_geojson(poly))
    body = {"vertices": [list(p) for p in outer], "holes": [[list(p) for p in h] for h in holes]}
    out = {
        "Shape": pc.Shape(outer, holes),
        "shapely": poly,
        "shapely-multi": shapely.MultiPolygon([poly]),
        "geo_interface": GeoThing(geojson),
        "geojson": geojson,
        "geojson-feature": {"type": "Feature", "properties": {}, "geometry": geojson},
        "body-dict": body,
        "body-dict-named": {**body, "name": "x"},
        "wkt": poly.wkt,
        "json-body": json.dumps(body),
        "json-geojson": json.dumps(geojson),
        "wkb": poly.wkb,
        "wkb-hex": poly.wkb_hex,
    }
    if not holes:
        out |= {"list": [list(p) for p in outer], "tuple": tuple(outer),
                "ndarray": np.array(outer), "closed": np.array([*outer, outer[0]])}
    return out


PAIRS = {"holes": ((A_OUTER, A_HOLES), (B_OUTER, B_HOLES)),
         "plain": ((A_OUTER, []), (B_OUTER, []))}
CASES = [(pair, name) for pair, (a, _) in PAIRS.items() for name in forms(*a)]


def _relation(r: pc.Relation) -> tuple:
    return (r.state, r.tolerance, r.distance, r.features, _pt(r.point), _pt(r.normal))


def _pt(p: np.ndarray | None) -> list | None:
    return None if p is None else p.tolist()


def _answers(a: object, b: object) -> dict:
    """Everything each entry point answers for the bodies ``a`` and ``b``."""
    out: dict = {"classify": _relation(pc.classify(a, b))}
    batch = pc.classify_many([a, b], [b, a])
    out["classify_many"] = (batch.states.tolist(), batch.tolerances.tolist(),
                            batch.distances.tolist())
    imp = pc.time_of_impact(a, pc.Motion(velocity=(-1.0, 0.0)), b,
                            pc.Motion(velocity=(-2.0, 0.0)), t_max=3.0)
    out["time_of_impact"] = (imp.status, imp.time, imp.first_contact, imp.features,
                             _pt(imp.point), _pt(imp.normal))
    block = pc.entrance_block(a, b)
    out["entrance_block"] = (block.area, block.reference.tolist(),
                             block.to_shapely().normalize().wkb)
    nfp = pc.no_fit_polygon(a, b)
    out["no_fit_polygon"] = (nfp.region.normalize().wkb, nfp.exact_fits.tolist(),
                             nfp.slides.tolist(), nfp.reference.tolist())
    out["inner_fit_polygon"] = pc.inner_fit_polygon(b, a).normalize().wkb
    world = pc.World(container=a)
    world.add(b)
    world.add(b, position=(11.5, 6.5))
    q = world.query(b, position=(11.5, 6.5))
    c = world.contacts()
    out["world"] = (world.container.loops[0].tolist(), c.pairs.tolist(), c.states.tolist(),
                    c.container_ids.tolist(), c.container_states.tolist(), q.ids.tolist(),
                    q.states.tolist(), q.container_state)
    return out


_REFERENCE: dict = {}


def _reference(pair: str) -> dict:
    if pair not in _REFERENCE:
        (a, ha), (b, hb) = PAIRS[pair]
        _REFERENCE[pair] = _answers(pc.Shape(a, ha), pc.Shape(b, hb))
    return _REFERENCE[pair]


def test_reference_answers_are_not_trivial():
    ref = _reference("holes")
    assert ref["classify"][0] is pc.State.CONTACT and ref["classify"][3]
    assert ref["time_of_impact"][0] is pc.ImpactStatus.HIT
    assert ref["classify_many"][0] == [1, 1]
    assert ref["world"][1] == [[0, 1]] and ref["world"][5] == [0, 1]


@pytest.mark.parametrize(("pair", "form"), CASES)
def test_every_form_gives_the_same_answers(pair, form):
    (a, ha), (b, hb) = PAIRS[pair]
    fa, fb = forms(a, ha)[form], forms(b, hb)[form]
    got = _answers(fa, fb)
    ref = _reference(pair)
    for entry in ref:
        assert got[entry] == ref[entry], entry


@pytest.mark.parametrize("form", list(forms(A_OUTER, A_HOLES)))
def test_as_shape_gives_the_same_shape(form):
    shape = as_shape(forms(A_OUTER, A_HOLES)[form], "a")
    ref = pc.Shape(A_OUTER, A_HOLES)
    assert [x.tolist() for x in shape.loops] == [x.tolist() for x in ref.loops]


def test_load_scene_takes_a_mapping_and_a_path(tmp_path):
    data = {"t_max": 3, "bodies": [{"name": "a", "vertices": A_OUTER, "holes": A_HOLES},
                                   {"name": "b", "vertices": B_OUTER, "holes": B_HOLES,
                                    "velocity": [1, 0]}]}
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(data))
    for src in (data, path, str(path)):
        scene = pc.load_scene(src)
        assert [len(b.shape.loops) for b in scene.bodies] == [2, 2]
    with pytest.raises(TypeError, match="^path: "):
        pc.load_scene(3)


SQ = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
M0 = pc.Motion()

# Each public entry point, called with one bad body in the named argument.
ENTRIES = {
    "classify-a": ("a", lambda x: pc.classify(x, SQ)),
    "classify-b": ("b", lambda x: pc.classify(SQ, x)),
    "classify_many-a": (r"shapes_a\[1\]", lambda x: pc.classify_many([SQ, x], [SQ, SQ])),
    "classify_many-b": (r"shapes_b\[0\]", lambda x: pc.classify_many([SQ], [x])),
    "time_of_impact-a": ("a", lambda x: pc.time_of_impact(x, M0, SQ, M0, t_max=1.0)),
    "time_of_impact-b": ("b", lambda x: pc.time_of_impact(SQ, M0, x, M0, t_max=1.0)),
    "entrance_block-a": ("a", lambda x: pc.entrance_block(x, SQ)),
    "entrance_block-b": ("b", lambda x: pc.entrance_block(SQ, x)),
    "no_fit_polygon-a": ("a", lambda x: pc.no_fit_polygon(x, SQ)),
    "no_fit_polygon-b": ("b", lambda x: pc.no_fit_polygon(SQ, x)),
    "inner_fit_polygon-a": ("a", lambda x: pc.inner_fit_polygon(x, SQ)),
    "inner_fit_polygon-container": ("container", lambda x: pc.inner_fit_polygon(SQ, x)),
    "World-container": ("container", lambda x: pc.World(container=x)),
    "World.add": ("shape", lambda x: pc.World().add(x)),
    "World.query": ("shape", lambda x: pc.World().query(x)),
    "World.query_many": ("shape", lambda x: pc.World().query_many(x, [(0.0, 0.0)])),
    "World.feasible_region": ("shape", lambda x: pc.World(SQ).feasible_region(x)),
}

WRONG_TYPES = {"int": 3, "None": None, "set": {1, 2}, "object": object()}
WRONG_VALUES = {
    "two vertices": [(0, 0), (1, 1)],
    "bowtie": [(0, 0), (1, 1), (1, 0), (0, 1)],
    "body-dict unknown key": {"vertices": SQ, "colour": "red"},
    "mapping without type": {"coordinates": []},
    "geojson point": {"type": "Point", "coordinates": [0, 0]},
    "shapely point": shapely.Point(0, 0),
    "bad wkt": "POLYGON ((0 0, 1",
    "bad json": '{"vertices": [',
    "bad wkb": b"\x01\x03garbage",
    "non-finite": [(0, 0), (1, 0), (float("nan"), 1)],
}


@pytest.mark.parametrize("entry", list(ENTRIES))
@pytest.mark.parametrize("kind", list(WRONG_TYPES))
def test_wrong_type_is_type_error_naming_the_argument(entry, kind):
    what, call = ENTRIES[entry]
    if kind == "None" and entry == "World-container":
        # not a wrong type there: container=None is a world without a container
        assert pc.World(container=None).container is None
        return
    with pytest.raises(TypeError, match=f"^{what}: "):
        call(WRONG_TYPES[kind])


@pytest.mark.parametrize("entry", list(ENTRIES))
@pytest.mark.parametrize("kind", list(WRONG_VALUES))
def test_wrong_value_is_value_error_naming_the_argument(entry, kind):
    what, call = ENTRIES[entry]
    with pytest.raises(ValueError, match=f"^{what}: ") as err:
        call(WRONG_VALUES[kind])
    assert not isinstance(err.value, TypeError)


@pytest.mark.parametrize("form", list(forms(A_OUTER, A_HOLES)))
def test_shape_constructor_takes_every_form(form):
    shape = pc.Shape(forms(A_OUTER, A_HOLES)[form])
    ref = pc.Shape(A_OUTER, A_HOLES)
    assert [x.tolist() for x in shape.loops] == [x.tolist() for x in ref.loops]
    assert shape.input_vertex(1, 0) == ref.input_vertex(1, 0)


@pytest.mark.parametrize("form", ["shapely", "geojson", "body-dict", "wkt", "wkb", "Shape"])
def test_shape_constructor_refuses_holes_beside_a_body_that_carries_its_own(form):
    with pytest.raises(TypeError, match="^holes: .*carries its own holes"):
        pc.Shape(forms(B_OUTER, [])[form], B_HOLES)


def test_shape_constructor_names_the_argument_of_an_invalid_body_form():
    with pytest.raises(pc.InvalidShapeError, match="^vertices: outer loop: self-intersection"):
        pc.Shape("POLYGON ((0 0, 1 1, 1 0, 0 1, 0 0))")
    with pytest.raises(pc.InvalidShapeError, match="^vertices: not valid WKT"):
        pc.Shape("0 0, 1 0, 0 1")
    assert pc.Shape("POLYGON ((0 0, 2 0, 2 2, 1 2, 1 3, 1 2, 0 2, 0 0))", repair=True).repairs


@pytest.mark.parametrize(
    ("text", "message"),
    [("", "empty text"), ("  \n\t", "empty text"), (b"", "empty WKB"),
     ("[[0, 0], [1, 0", "not valid JSON"), ('"a string"', "not valid WKT"),
     ("[]", "outer loop: expected an array of shape (N, 2)")],
)
def test_text_with_no_body_says_what_it_is(text, message):
    with pytest.raises(pc.InvalidShapeError, match=f"^a: {re.escape(message)}"):
        as_shape(text, "a")


def test_json_text_of_a_list_of_vertices_is_a_body():
    shape = as_shape("[[0, 0], [2, 0], [2, 1]]", "a")
    assert shape.area == 1.0 and pc.Shape(" [[0, 0], [2, 0], [2, 1]]\n").area == 1.0
