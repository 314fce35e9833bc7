"""Scale and offset: the same answers at every scale 1e-9 .. 1e9 and offset up to 1e9.

The default tolerance follows the size of the bodies and the float spacing of their
coordinates (:func:`polycontact.default_tolerance`), so scaling a placement by 10**k and
moving it far from the origin changes nothing, **wherever float64 still separates the
features**: a case is skipped at a scale and offset where the smallest positive
distance between a vertex and an edge (:func:`catalogue.feature_separation`, times the
scale) is below ``SEPARATION_MARGIN`` times the tolerance there. Below that, rounding
the scaled and offset coordinates may honestly move a feature across the tolerance.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import shapely
from catalogue import CASES, feature_separation, pairs, shapely_state
from hypothesis import given, note
from hypothesis import strategies as st

import polycontact as pc
from polycontact import InvalidShapeError, Shape, State, classify, classify_many
from polycontact.tolerances import tolerance_for

#: A case is compared at a scale and offset only if its features stay this many
#: tolerances apart there.
SEPARATION_MARGIN = 4.0

SCALES = [10.0**k for k in range(-9, 10)]
OFFSETS = [0.0, 1e3, -1e6, 1e9]
SQ = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])


def _placed(s: Shape, scale: float, offset: np.ndarray) -> Shape:
    return Shape(s.exterior * scale + offset, [h * scale + offset for h in s.holes])


def _separable(a: Shape, b: Shape, scale: float, offset: float) -> bool:
    extent = max(np.ptp(a.exterior, axis=0).max(), np.ptp(b.exterior, axis=0).max())
    reach = max(np.abs(a.exterior).max(), np.abs(b.exterior).max())
    tol = tolerance_for(extent * scale, abs(offset) + reach * scale)
    return feature_separation(a, b) * scale > SEPARATION_MARGIN * tol


@pytest.mark.parametrize("case", CASES, ids=lambda c: c.name)
def test_catalogue_at_every_scale_and_offset(case):
    checked = 0
    for scale in SCALES:
        for offset in OFFSETS:
            if not _separable(case.a, case.b, scale, offset):
                continue
            off = np.array([offset, -0.5 * offset])
            a, b = _placed(case.a, scale, off), _placed(case.b, scale, off)
            for x, y in ((a, b), (b, a)):
                assert classify(x, y).state.value == case.state, (scale, offset)
                if not x.holes and not y.holes:
                    assert classify(x.exterior, y.exterior).state.value == case.state
            checked += 1
    if feature_separation(case.a, case.b) > 1e-9:
        assert checked >= 20  # compared over most of the range (thinner ones: less)


@given(pairs(grid=True, holes=None), st.integers(-9, 9),
       st.sampled_from([0.0, 1.0, 1e3, 1e6, 1e9]), st.floats(-1.0, 1.0))
def test_random_pairs_at_every_scale_and_offset(pair, k, offset, turn):
    # Random concave pairs, with holes or not, on the integer grid (Shapely decides them
    # exactly at scale 1), then scaled by 10**k and moved up to 1e9 away.
    a, b, _ = pair
    scale = 10.0**k
    direction = np.array([np.cos(turn * np.pi), np.sin(turn * np.pi)])
    if not _separable(a, b, scale, offset):
        return
    note(f"scale {scale:g}, offset {offset * direction}")
    want = shapely_state(a, b)
    xa, xb = _placed(a, scale, offset * direction), _placed(b, scale, offset * direction)
    assert classify(xa, xb).state.value == want
    assert classify(xb, xa).state.value == want
    if not a.holes and not b.holes:
        assert classify(xa.exterior, xb.exterior).state.value == want
        assert classify_many([xa.exterior], [xb.exterior]).state(0).value == want


def test_the_tolerance_follows_the_bodies():
    for scale in SCALES:
        for offset in OFFSETS:
            if scale < 1e3 * 2.0**-52 * abs(offset):
                continue  # a square 1e3 float spacings wide at least
            a = SQ * scale + offset
            r = classify(a, a + [scale, 0.0])
            magnitude = max(abs(offset), abs(offset + 2 * scale))
            want = max(1e-12 * scale, 64 * 2.0**-52 * magnitude)
            assert r.tolerance == pytest.approx(want, rel=1e-12)
            assert r.tolerance == classify(Shape(a), Shape(a + [scale, 0.0])).tolerance


def test_tiny_huge_and_far_shapes_are_accepted():
    # Refused before: "zero area" for a micrometre square, a self-intersection that
    # does not exist at offset 1e9, "all vertices on one line" for GEOS's skinny case.
    for scale in SCALES:
        for offset in (0.0, 1e9):
            if scale < 1e3 * 2.0**-52 * offset:
                continue  # a square 1e3 float spacings wide at least
            s = Shape(SQ * scale + offset)
            # (the side is rounded to the float spacing at the offset: <= 1e-3 of it)
            assert s.area == pytest.approx(scale * scale, rel=3e-3)
    assert Shape(SQ * 1e-6).area == pytest.approx(1e-12)
    slit = np.array([(0, 0), (1, 0), (1, 1), (0.5, 1), (0.5, 1 + 1e-4), (1, 1 + 1e-4),
                     (1, 2), (0, 2)]) + 1e9
    assert shapely.Polygon(slit).is_valid
    assert Shape(slit).n_vertices == 8
    skinny = shapely.from_wkt("POLYGON ((100 100, 1e15 110, 1e15 100, 100 100))")
    assert skinny.is_valid
    assert Shape.from_shapely(skinny).area == pytest.approx(5e15)
    for wkt in ("POLYGON ((100 100, 100 200, 200 200, 200 100, 100 100))",
                "POLYGON ((120 100, 120 200, 200 200, 200 100, 120 100))"):
        # Their overlap is a sliver 1e-12 thick, far below the float spacing at 1e15
        # (and the tolerance there): contact, never refused, never separate.
        assert classify(shapely.from_wkt(wkt), skinny).state is State.CONTACT


def test_out_of_range_is_refused_clearly():
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no overflow warning on the way
        for scale, message in ((1e200, "beyond"), (1e-300, "below 1e-100")):
            with pytest.raises(InvalidShapeError, match=message):
                Shape(SQ * scale)
            with pytest.raises(InvalidShapeError, match=f"^a: outer loop: .*{message}"):
                classify(SQ * scale, SQ)
            with pytest.raises(InvalidShapeError, match=f"^shapes_b\\[0\\]: .*{message}"):
                classify_many((SQ)[None], (SQ * scale)[None])
        with pytest.raises(InvalidShapeError, match="beyond"):
            Shape(SQ + [0.0, 2e100])
        with pytest.raises(InvalidShapeError, match="beyond"):
            Shape(SQ).moved((1e101, 0.0))


def test_features_closer_than_the_float_spacing_are_accepted_as_geos_accepts_them():
    # At 1e9 the float spacing is 1.2e-7: a slit one or two spacings wide is a valid
    # polygon (GEOS says so), decided exactly; closed to zero width it is a fold.
    for width in (2.0**-22, 2.0**-23):  # 2 and 1 float spacings at 1e9
        slit = np.array([(0, 0), (1, 0), (1, 1), (0.5, 1), (0.5, 1 + width),
                         (1, 1 + width), (1, 2), (0, 2)]) + 1e9
        assert slit[4, 1] - slit[3, 1] == width
        assert shapely.Polygon(slit).is_valid
        assert Shape(slit).n_vertices == 8
    slit[4:6, 1] = slit[3, 1]
    assert not shapely.Polygon(slit).is_valid
    with pytest.raises(InvalidShapeError, match="edges 2 and 3 fold back on each other"):
        Shape(slit)


def test_shape_caches_what_the_tolerance_needs():
    s = Shape(SQ * 3 + [-7.0, 2.0])
    assert (s._extent, s._magnitude) == (3.0, 7.0)
    assert classify(s, s).tolerance == pc.default_tolerance(s.packed[0])
    moved = s.moved((100.0, 0.0))
    assert (moved._extent, moved._magnitude) == (3.0, 96.0)
