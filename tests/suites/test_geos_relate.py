"""GEOS's own relate test cases, run as an external suite.

Each case of ``../shared/datasets/geos/*.xml`` gives two areal geometries and their
DE-9IM matrix, which maps to our three states: the interiors meet (entry II is not
``F``) -> penetrating; otherwise the boundaries meet (IB, BI or BB is not ``F``) ->
contact; otherwise separate. A MultiPolygon is classified part by part: its parts meet
only at points, so the interiors of the union overlap B's exactly when some part's do,
and the worst state over the part pairs is the state of the union. Every case is run in
both argument orders. Skipped in a clone without ``shared/`` beside it.

Our states are decided within a tolerance and GEOS's predicates are exact, so where
GEOS finds an overlap thinner than our tolerance (the width of its minimum rotated
rectangle; the "very skinny polygon" cases A/A-6-18 and 6-24) we expect ``contact``, and the test
checks that this is the only kind of disagreement.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
import shapely

import polycontact as pc

GEOS = Path(__file__).resolve().parents[3] / "shared" / "datasets" / "geos"
_CODE = {pc.State.SEPARATE: 0, pc.State.CONTACT: 1, pc.State.PENETRATING: 2}


def _cases() -> list:
    out = []
    for path in sorted(GEOS.glob("*.xml")):
        for case in ET.parse(path).getroot().iter("case"):
            desc = case.findtext("desc", "").split("[")[0].strip()
            for op in case.iter("op"):
                if op.get("name") == "relate" and op.text.strip() == "true":
                    a = shapely.from_wkt(case.findtext("a"))
                    b = shapely.from_wkt(case.findtext("b"))
                    out.append(pytest.param(a, b, op.get("arg3"), id=f"{path.stem}:{desc}"))
    return out


def _expected(matrix: str, a: shapely.Geometry, b: shapely.Geometry) -> int:
    if matrix[0] != "F":
        # the overlap's width: the shorter side of its minimum rotated rectangle
        box = shapely.get_coordinates(shapely.minimum_rotated_rectangle(
            shapely.intersection(a, b)))
        thickness = min(shapely.LineString(box[0:2]).length,
                        shapely.LineString(box[1:3]).length)
        eps = max(pc.classify(pa, pb).tolerance
                  for pa in shapely.get_parts(a) for pb in shapely.get_parts(b))
        return 1 if thickness < eps else 2
    return 1 if any(matrix[k] != "F" for k in (1, 3, 4)) else 0


def _state(a: shapely.Geometry, b: shapely.Geometry) -> int:
    return max(
        _CODE[pc.classify(pa, pb).state]
        for pa in shapely.get_parts(a)
        for pb in shapely.get_parts(b)
    )


CASES = _cases() if GEOS.is_dir() else []


@pytest.mark.skipif(not GEOS.is_dir(), reason="no ../shared/datasets/geos beside the clone")
def test_geos_suite_is_there():
    assert len(CASES) == 123
    thin = [p.id for p in CASES if p.values[2][0] != "F" and _expected(*p.values[2:], *p.values[:2]) == 1]
    assert sorted(thin) == ["validate_TestRelateAA-big:A/A-6-18: a polygon overlapping a very skinny polygon",
                            "validate_TestRelateAA-big:A/A-6-24: a polygon overlapping a very skinny polygon"]


@pytest.mark.parametrize(("a", "b", "matrix"), CASES)
def test_geos_relate_case(a, b, matrix):
    want = _expected(matrix, a, b)
    assert _state(a, b) == want
    assert _state(b, a) == want
