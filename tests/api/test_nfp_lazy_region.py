"""The no-fit polygon's region is built on first access, from the kernel's rings.

- The lazily built region is, bit for bit, the region the eager code built: the rings
  of the cached-pieces kernel (``entrance_region``) made into a geometry by
  ``_polygon_from_rings`` (catalogue cases, random shapes with holes, ESICUP pairs).
- The cached region cannot go stale: the result is frozen, ``rings`` are read-only, the
  same geometry is returned on every access, pickles and copies carry the geometry.
"""

from __future__ import annotations

import copy
import dataclasses
import json
import pickle

import numpy as np
import pytest
import shapely
from hypothesis import given
from profiles import examples
from .test_nfp import CATALOGUE, ESICUP, _rotated, shape, star_shapes

import polycontact as pc
from polycontact import nfp as nfp_module
from polycontact._kernels import nfp as kn
from polycontact.limits import MAX_CLIP_TESTS
from polycontact.tolerances import RELATIVE_TOLERANCE, ROUNDING_ULPS


def eager_region(a: pc.Shape, b: pc.Shape, a0: np.ndarray) -> shapely.Geometry:
    """The region as built before it was lazy: entrance_region's rings, then
    _polygon_from_rings (the general path, one ring or many)."""
    bxy, bst = nfp_module._convex_pieces(b)
    axy, ast = nfp_module._convex_pieces(a)
    ring_xy, ring_starts, stats, _, meta = kn.entrance_region(
        bxy, bst, a0 - axy, ast, -1.0, RELATIVE_TOLERANCE, ROUNDING_ULPS,
        nfp_module.ANGLE_TOLERANCE, MAX_CLIP_TESTS)
    assert meta[1] == 1.0
    width = nfp_module.HOLE_WIDTH_FACTOR * meta[0]
    return nfp_module._polygon_from_rings(ring_xy, ring_starts, stats, width)


def assert_lazy_is_eager(a: pc.Shape, b: pc.Shape, reference=None) -> pc.NoFitPolygon:
    nfp = pc.no_fit_polygon(a, b, reference)
    assert "region" not in nfp.__dict__  # not built by the call
    want = eager_region(a, b, nfp.reference)
    assert shapely.to_wkb(nfp.region) == shapely.to_wkb(want)
    # rings: the region's coordinates, ring by ring
    got = nfp.rings
    rings = [r for part in shapely.get_parts(shapely.orient_polygons(want))
             if not part.is_empty for r in (part.exterior, *part.interiors)]
    assert len(got) == len(rings)
    for g, r in zip(got, rings):
        np.testing.assert_array_equal(g, shapely.get_coordinates(r))
        assert not g.flags.writeable
    return nfp


@pytest.mark.parametrize("name,a,b,holes,fits,slides", CATALOGUE, ids=[c[0] for c in CATALOGUE])
def test_lazy_region_is_the_eager_one_catalogue(name, a, b, holes, fits, slides):
    assert_lazy_is_eager(shape(a), shape(b), "origin")


@examples(30)
@given(star_shapes(), star_shapes())
def test_lazy_region_is_the_eager_one_random(a, b):
    assert_lazy_is_eager(a, b)


@pytest.mark.skipif(not ESICUP.is_dir(), reason="ESICUP instances not available")
@pytest.mark.parametrize("instance", ["fu", "shapes0", "shapes1"])
def test_lazy_region_is_the_eager_one_esicup(instance):
    data = json.loads((ESICUP / f"{instance}.json").read_text())
    pieces = [pc.Shape(_rotated(it["shape"]["data"], deg))
              for it in data["items"] for deg in it["allowed_orientations"]]
    for a in pieces:
        for b in pieces:
            assert_lazy_is_eager(a, b, "origin")


def test_one_ring_rings_are_given_without_building_the_region():
    sq = pc.Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
    nfp = pc.no_fit_polygon(sq, sq.moved((0.5, 0.2)), "origin")
    (ring,) = nfp.rings
    assert "region" not in nfp.__dict__
    assert not ring.flags.writeable
    with pytest.raises(ValueError):
        ring[0, 0] = 7.0
    assert shapely.to_wkb(nfp.region) == shapely.to_wkb(shapely.Polygon(ring))


def test_cached_region_cannot_go_stale():
    sq = pc.Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
    frame = pc.Shape([(0, 0), (4, 0), (4, 4), (0, 4)], [[(1, 1), (3, 1), (3, 3), (1, 3)]])
    nfp = pc.no_fit_polygon(sq, frame, "origin")
    nfp.rings  # noqa: B018 (the private rings are read-only from here on)
    region = nfp.region
    assert nfp.region is region  # built once, cached
    with pytest.raises(dataclasses.FrozenInstanceError):
        nfp.region = shapely.Point(0, 0)  # type: ignore[misc]
    with pytest.raises(dataclasses.FrozenInstanceError):
        del nfp.region
    assert all(not r.flags.writeable for r in nfp.rings)
    assert not nfp.reference.flags.writeable  # "origin": one array shared by results
    with pytest.raises(AttributeError):
        nfp.no_such_attribute  # noqa: B018
    assert not hasattr(nfp, "no_such_attribute")


@pytest.mark.parametrize("built", [False, True])
def test_pickle_and_copy_carry_the_region(built):
    a = pc.Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
    b = pc.Shape([(0, 0), (3, 0), (3, 3), (2, 3), (2, 1), (1, 1), (1, 3), (0, 3)])
    nfp = pc.no_fit_polygon(a, b, "origin")
    if built:
        nfp.region  # noqa: B018
    want = shapely.to_wkb(eager_region(a, b, nfp.reference))
    for other in (pickle.loads(pickle.dumps(nfp)), copy.copy(nfp), copy.deepcopy(nfp)):
        assert "_rings" not in other.__dict__
        assert shapely.to_wkb(other.region) == want
        assert [r.tolist() for r in other.rings] == [r.tolist() for r in nfp.rings]
        np.testing.assert_array_equal(other.slides, nfp.slides)
        assert other.tolerance == nfp.tolerance


def test_fields_repr_and_the_public_constructor():
    sq = pc.Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
    nfp = pc.no_fit_polygon(sq, sq, "origin")
    assert [f.name for f in dataclasses.fields(nfp)] == [
        "region", "exact_fits", "slides", "reference", "a", "b", "tolerance"]
    assert repr(nfp).startswith("NoFitPolygon(region=<POLYGON ((-1 -1, 1 -1")
    made = pc.NoFitPolygon(nfp.region, nfp.exact_fits, nfp.slides, nfp.reference, sq, sq,
                           nfp.tolerance)
    assert made.region is nfp.region
    assert [r.tolist() for r in made.rings] == [r.tolist() for r in nfp.rings]
    assert made.to_dict() == nfp.to_dict()
    assert made != nfp and nfp == nfp  # eq=False: identity


def _packed_rings(*rings):
    """The kernel's packed rings (see entrance_packed): coordinates, starts, stats."""
    rings = [np.asarray(r, dtype=float) for r in rings]
    starts = np.cumsum([0] + [len(r) for r in rings])
    stats = [(shapely.LinearRing(r).is_ccw * 2 - 1) * shapely.Polygon(r).area for r in rings]
    lengths = [shapely.LinearRing(r).length for r in rings]
    buf = np.concatenate([np.concatenate(rings).ravel(), starts,
                          np.column_stack((stats, lengths)).ravel()])
    return buf, float(len(rings)), float(starts[-1])


SHELL = [(0, 0), (4, 0), (4, 4), (0, 4), (0, 0)]
THIN_HOLE = [(1, 1), (1, 1 + 1e-9), (3, 1 + 1e-9), (3, 1), (1, 1)]  # clockwise
HOLE = [(1, 2), (1, 3), (3, 3), (3, 2), (1, 2)]


@pytest.mark.parametrize("rings,width,wkt", [
    ((SHELL,), 1e-6, "POLYGON ((0 0, 4 0, 4 4, 0 4, 0 0))"),
    ((THIN_HOLE[::-1],), 1e-6, "POLYGON EMPTY"),  # one shell thinner than the width
    ((SHELL, THIN_HOLE, HOLE), 1e-6,
     "POLYGON ((0 0, 4 0, 4 4, 0 4, 0 0), (1 2, 1 3, 3 3, 3 2, 1 2))"),
    ((SHELL, THIN_HOLE), 1e-12, None),  # the hole is wider than this width: kept
])
def test_region_of_drops_rings_thinner_than_the_width(rings, width, wkt):
    region = nfp_module._region_of(*_packed_rings(*rings), width)
    if wkt is None:
        assert len(region.interiors) == 1
    else:
        assert region.wkt == wkt
