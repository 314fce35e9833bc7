"""EntranceBlock.classify: the relation at a reference-point position, against Shapely."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from hypothesis import assume, given
from hypothesis import strategies as st
from profiles import examples
from .test_entrance_block import FRAME, NOTCHED_HOLE, SQUARE, bodies, note_bodies

import polycontact as pc


def _shapely_state(a: pc.Shape, b: pc.Shape) -> str:
    pa, pb = a.to_shapely(), b.to_shapely()
    if shapely.relate_pattern(pa, pb, "2********"):
        return "penetrating"
    return "contact" if pa.intersects(pb) else "separate"


@examples(80)
@given(bodies(max_vertices=8), bodies(max_vertices=8), st.data())
def test_classify_agrees_with_shapely_away_from_the_boundary(a, b, data):
    note_bodies(a, b)
    eb = pc.entrance_block(a, b)
    union = eb.to_shapely()
    lo, hi = np.array(union.bounds).reshape(2, 2)
    scale = max(1.0, float(np.abs(union.bounds).max()))
    for _ in range(10):
        p = lo + (hi - lo) * np.array([data.draw(st.floats(-0.2, 1.2)) for _ in range(2)])
        if union.boundary.distance(shapely.Point(p)) < 1e-8 * scale:
            continue  # decided by the tolerance, checked below
        state = eb.classify(p).state.value
        assert state == _shapely_state(a.moved(p - eb.reference), b)
        assert state == ("penetrating" if union.contains(shapely.Point(p)) else "separate")


def _nearly_parallel(a: pc.Shape, b: pc.Shape) -> bool:
    """Whether an edge of A and one of B are between 1e-12 and 1e-2 rad from parallel."""
    def dirs(s):
        return np.concatenate([np.roll(r, -1, axis=0) - r for r in s.loops])

    da, db = dirs(a), dirs(b)
    cross = da[:, None, 0] * db[None, :, 1] - da[:, None, 1] * db[None, :, 0]
    ang = np.abs(np.arctan2(cross, da @ db.T))
    ang = np.minimum(ang, np.pi - ang)
    return bool(np.any((ang > 1e-12) & (ang < 1e-2)))


@examples(60)
@given(bodies(max_vertices=8), bodies(max_vertices=8))
def test_classify_is_contact_on_the_boundary_of_the_block(a, b):
    note_bodies(a, b)
    # The outline's vertices are computed (rounded): moved a rounding error across an
    # edge nearly parallel to the other body's edge, A overlaps B by a sliver much
    # deeper than the shift, which Shapely would also call overlap. Edge pairs are
    # either parallel (to rounding) or at least 0.01 rad apart here, so the sliver
    # stays within the tolerance.
    assume(not _nearly_parallel(a, b))
    eb = pc.entrance_block(a, b, method="pairs")
    union = eb.to_shapely()
    rings = [union.exterior, *union.interiors]
    points = np.concatenate([np.asarray(r.coords)[:-1] for r in rings])
    mids = np.concatenate(
        [0.5 * (np.asarray(r.coords)[:-1] + np.asarray(r.coords)[1:]) for r in rings]
    )
    for p in np.concatenate([points, mids]):
        relation = eb.classify(p)
        if relation.state == pc.State.CONTACT:
            assert relation.distance == 0.0
        else:  # the rounded outline point can overlap B by a sliver within the tolerance
            assert relation.state == pc.State.PENETRATING, p
            assert -relation.distance <= relation.tolerance, p


def test_the_verdict_is_the_classifier_s_also_where_the_block_closes_a_crack():
    # A 1 × 1 square sliding in a slot exactly 1 wide: every position along the slot is
    # an exact fit, so contact, though the union of the components (a closed polygon)
    # has the slot's centre line in its interior.
    slot = pc.Shape([(0, 0), (5, 0), (5, 3), (0, 3), (0, 2), (4, 2), (4, 1), (0, 1)])
    a = pc.Shape(SQUARE)
    eb = pc.entrance_block(a, slot)
    for x in (0.0, 1.0, 2.7, 3.5):
        p = np.array([x, 1.5])
        assert eb.classify(p).state == pc.State.CONTACT
        assert _shapely_state(a.moved(p - eb.reference), slot) == "contact"
    assert eb.classify((2.0, 1.6)).state == pc.State.PENETRATING
    assert eb.classify((-0.6, 1.5)).state == pc.State.SEPARATE
    # the paper's reading of the cover: on boundaries only, in no interior
    at = eb.components_at((2.0, 1.5))
    assert at.interior == () and len(at.boundary) > 0


def test_classify_matches_classify_of_the_moved_shape():
    a = pc.Shape([(0, 0), (3, 0), (3, 1), (1, 1), (1, 3), (0, 3)])
    b = pc.Shape(FRAME, [NOTCHED_HOLE]).moved((5.0, 1.0))
    eb = pc.entrance_block(a, b, reference=(0.0, 0.0))
    for p in [(5.5, 1.5), (6.0, 2.0), (4.0, 2.0), (6.5, 2.5), (2.0, 2.0)]:
        mine, theirs = eb.classify(p), pc.classify(a.moved(p), b)
        assert mine.state == theirs.state
        assert mine.distance == pytest.approx(theirs.distance)
        assert mine.features == theirs.features


def test_classify_refuses_a_bad_point():
    eb = pc.entrance_block(pc.Shape(SQUARE), pc.Shape(SQUARE))
    with pytest.raises(ValueError, match="point: expected two"):
        eb.classify((1.0,))
    with pytest.raises(ValueError, match="point: expected two finite numbers"):
        eb.components_at((np.inf, 0.0))
