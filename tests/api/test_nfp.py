"""No-fit polygon: a catalogue of hard cases, random shapes and ESICUP pieces, all
checked against the independent reference in ``nfp_reference.py``; exact fits and
slides checked by brute force on integer lattices with the classifier."""

from __future__ import annotations

import json
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest
import shapely
from catalogue import interlocking_combs
from hypothesis import assume, given
from hypothesis import strategies as st
from profiles import examples
from nfp_reference import hole_count, reference_region, same_region

import polycontact as pc
from polycontact import State
from polycontact import nfp as nfp_module


@pytest.fixture(autouse=True, scope="module")
def no_geos_fallback():
    """Every region of this module (catalogue, random shapes, ESICUP) is assembled by
    polycontact's own kernel: the GEOS fallback, which would hide an assembly failure
    behind a right answer, is never taken."""
    before = nfp_module.fallback_count()
    yield
    assert nfp_module.fallback_count() == before, "the GEOS fallback built some region"

SQ = [(0, 0), (1, 0), (1, 1), (0, 1)]
H = 1e-7  # "a hair" in the narrow-entry cases
U_SLOT = [(0, 0), (3, 0), (3, 3), (2, 3), (2, 1), (1, 1), (1, 3), (0, 3)]
FRAME = ([(0, 0), (4, 0), (4, 4), (0, 4)], [[(1, 1), (3, 1), (3, 3), (1, 3)]])
DOVETAIL_A = [(0, 2), (1.7, 2), (1.4, 1), (2.6, 1), (2.3, 2), (4, 2), (4, 3), (0, 3)]
DOVETAIL_B = [(0, 0), (4, 0), (4, 2), (2.3, 2), (2.6, 1), (1.4, 1), (1.7, 2), (0, 2)]
C_CAVITY = [(0, 0), (5, 0), (5, 5), (3, 5), (3, 4), (4, 4), (4, 1), (1, 1), (1, 4), (2, 4),
            (2, 5), (0, 5)]
COMB_A = [(0, 0), (5, 0), (5, 1), (4, 1), (4, 2), (3, 2), (3, 1), (2, 1), (2, 2), (1, 2),
          (1, 1), (0, 1)]


def shape(spec):
    return pc.Shape(*spec) if isinstance(spec, tuple) else pc.Shape(spec)


# name, A, B, holes, exact fits, slides (reference at the origin)
CATALOGUE = [
    ("jigsaw dovetail: isolated exact fit", DOVETAIL_A, DOVETAIL_B, 0, [(0, 0)], []),
    ("square in a square hole of B", [(0, 0), (2, 0), (2, 2), (0, 2)], FRAME, 0, [(1, 1)], []),
    ("square hole of A around B exactly", FRAME, [(0, 0), (2, 0), (2, 2), (0, 2)], 0,
     [(-1, -1)], []),
    ("small square in a hole of B", SQ, FRAME, 1, [], []),
    ("B in a hole of A", FRAME, SQ, 1, [], []),
    ("slot exactly as wide", SQ, U_SLOT, 0, [], [((1, 1), (1, 3))]),
    ("slot a hair wider", SQ, [(0, 0), (3, 0), (3, 3), (2 + H, 3), (2 + H, 1), (1, 1), (1, 3),
                               (0, 3)], 0, [], []),
    ("slot a hair narrower", SQ, [(0, 0), (3, 0), (3, 3), (2 - H, 3), (2 - H, 1), (1, 1),
                                  (1, 3), (0, 3)], 0, [], []),
    ("slot with a shorter right wall", SQ, [(0, 0), (3, 0), (3, 2), (2, 2), (2, 1), (1, 1),
                                            (1, 3), (0, 3)], 0, [], [((1, 1), (1, 2))]),
    ("closed channel exactly as wide", SQ, ([(0, 0), (5, 0), (5, 3), (0, 3)],
                                           [[(1, 1), (4, 1), (4, 2), (1, 2)]]), 0, [],
     [((1, 1), (3, 1))]),
    ("closed channel a hair wider", SQ, ([(0, 0), (5, 0), (5, 3), (0, 3)],
                                        [[(1, 1), (4, 1), (4, 2 + H), (1, 2 + H)]]), 1, [], []),
    ("cavity with a narrow mouth", [(0, 0), (1.5, 0), (1.5, 1.5), (0, 1.5)], C_CAVITY, 1, [],
     []),
    ("interlocking combs", COMB_A, [(0, 0), (5, 0), (5, 2), (4, 2), (4, 1), (3, 1), (3, 2),
                                    (2, 2), (2, 1), (1, 1), (1, 2), (0, 2)], 0, [], []),
    ("collinear vertices and sliding edges", [(0, 0), (0.5, 0), (1, 0), (1, 1), (0, 1)],
     [(0, 0), (1, 0), (2, 0), (2, 1), (1, 1), (0, 1)], 0, [], []),
    ("hole touching the outer loop", SQ, ([(0, 0), (4, 0), (4, 4), (0, 4)],
                                         [[(2, 0), (3, 1), (1, 1)]]), 0, [], []),
    ("holes in both: B in the hole of A", FRAME, (SQ, [[(0.25, 0.25), (0.75, 0.25),
                                                      (0.75, 0.75), (0.25, 0.75)]]), 1, [], []),
    ("holes in both: thick frames", FRAME, ([(0, 0), (6, 0), (6, 6), (0, 6)],
                                          [[(2, 2), (4, 2), (4, 4), (2, 4)]]), 0, [], []),
]


@pytest.mark.parametrize("name,a,b,holes,fits,slides", CATALOGUE, ids=[c[0] for c in CATALOGUE])
def test_catalogue(name, a, b, holes, fits, slides):
    a, b = shape(a), shape(b)
    nfp = pc.no_fit_polygon(a, b, reference="origin")
    ref = reference_region(a.to_shapely(), b.to_shapely(), (0.0, 0.0))
    assert same_region(nfp.region, ref) is None
    assert hole_count(nfp.region) == holes
    assert nfp.exact_fits.tolist() == [list(map(float, p)) for p in fits]
    assert nfp.slides.tolist() == [[list(map(float, p)), list(map(float, q))] for p, q in slides]
    for p in nfp.exact_fits:
        assert nfp.contains(p) is State.CONTACT
        assert shapely.contains_xy(nfp.region, *p)  # inside the area, not on its outline
        for d in [(1e-6, 0), (-1e-6, 0), (0, 1e-6), (0, -1e-6)]:
            assert nfp.contains(p + np.array(d)) is State.PENETRATING
    for s in nfp.slides:
        for t in (0.25, 0.5, 0.75):
            assert nfp.contains(s[0] + t * (s[1] - s[0])) is State.CONTACT


def test_hair_wider_channel_hole_is_as_thin_as_the_clearance():
    b = shape(CATALOGUE[10][2])
    nfp = pc.no_fit_polygon(SQ, b, reference="origin")
    hole = shapely.Polygon(nfp.region.interiors[0])
    assert hole.area == pytest.approx(2 * H, rel=1e-6)


def test_contains_agrees_with_classify():
    a, b = shape(DOVETAIL_A), shape(C_CAVITY)
    nfp = pc.no_fit_polygon(a, b)
    rng = np.random.default_rng(7)
    x0, y0, x1, y1 = nfp.region.bounds
    pts = rng.uniform((x0 - 1, y0 - 1), (x1 + 1, y1 + 1), size=(200, 2))
    pts = np.vstack([pts, shapely.get_coordinates(nfp.region)[:40]])
    for p in pts:
        want = pc.classify(a.moved(p - nfp.reference), b).state
        assert nfp.contains(p) is want
        if want is State.PENETRATING:
            assert shapely.contains_xy(nfp.region, *p)
        if want is State.SEPARATE:
            assert not shapely.intersects_xy(nfp.region, *p)


def test_reference_point_translates_the_region():
    a, b = shape(COMB_A), shape(C_CAVITY)
    base = pc.no_fit_polygon(a, b, reference="origin")
    for ref, a0 in [(None, a.centroid), ("centroid", a.centroid), ((2.5, -1.0), (2.5, -1.0)),
                    ("origin", (0.0, 0.0))]:
        nfp = pc.no_fit_polygon(a, b, reference=ref)
        assert np.allclose(nfp.reference, a0)
        moved = shapely.affinity.translate(base.region, *a0)
        assert shapely.symmetric_difference(nfp.region, moved).area < 1e-9 * moved.area


def test_region_is_valid_and_closed_under_swapping():
    # E(B, A) is E(A, B) reflected through the origin (reference at the origin)
    a, b = shape(FRAME), shape(C_CAVITY)
    ab = pc.no_fit_polygon(a, b, reference="origin").region
    ba = pc.no_fit_polygon(b, a, reference="origin").region
    assert ab.is_valid and ba.is_valid
    flipped = shapely.affinity.scale(ba, -1, -1, origin=(0, 0))
    assert shapely.symmetric_difference(ab, flipped).area < 1e-9 * ab.area


@pytest.mark.parametrize(
    "reference,message",
    [("middle", "reference"), ((1, 2, 3), "reference"), ((np.nan, 0), "reference"),
     ([["x", 1]], "reference")],
)
def test_bad_reference(reference, message):
    # a bad reference point is a bad argument, not an invalid shape
    with pytest.raises((ValueError, TypeError), match=message) as err:
        pc.no_fit_polygon(SQ, SQ, reference=reference)
    assert not isinstance(err.value, pc.InvalidShapeError)


def test_bad_shapes_and_tolerance():
    with pytest.raises(pc.InvalidShapeError, match="self-intersection"):
        pc.no_fit_polygon([(0, 0), (1, 1), (1, 0), (0, 1)], SQ)
    with pytest.raises(pc.InvalidShapeError, match="fewer than 3"):
        pc.no_fit_polygon(SQ, [(0, 0), (1, 1)])
    with pytest.raises(ValueError, match="^tolerance"):
        pc.no_fit_polygon(SQ, SQ, tolerance=-1.0)
    with pytest.raises(ValueError, match="^point"):
        pc.no_fit_polygon(SQ, SQ).contains((0, np.inf))


def test_inputs_are_not_modified():
    a = np.array(COMB_A, dtype=float)
    b = np.array(C_CAVITY, dtype=float)
    a0, b0 = a.copy(), b.copy()
    pc.no_fit_polygon(a, b)
    pc.inner_fit_polygon(a, b)
    assert np.array_equal(a, a0) and np.array_equal(b, b0)


def test_degenerate_inputs_give_the_same_region():
    # repeated vertices (zero-length edges) and collinear vertices change nothing
    a = [(0, 0), (1.5, 0), (1.5, 1.5), (0, 1.5)]
    plain = pc.no_fit_polygon(a, C_CAVITY, reference="origin").region
    noisy_a = [a[0], a[0], (0.75, 0), a[1], (1.5, 0.5), (1.5, 1.0), *a[2:], a[-1]]
    noisy_b = [C_CAVITY[0], (2.5, 0), *C_CAVITY[1:], (0, 2.5)]
    noisy = pc.no_fit_polygon(noisy_a, noisy_b, reference="origin").region
    assert shapely.symmetric_difference(plain, noisy).area < 1e-12 * plain.area
    assert hole_count(plain) == hole_count(noisy) == 1


def _force_geos_fallback(monkeypatch):
    """Make the outline assembly report failure, so that GEOS unions the sums."""
    from polycontact._kernels import nfp as kn

    real = kn.entrance_packed
    real_rings = kn.ring_entrance

    def unlinked(answer):
        (ok, eps, _, *rest), buf = answer
        return (ok, eps, 0.0, *rest), buf  # status 0: the parts did not link

    monkeypatch.setattr(kn, "entrance_packed", lambda *args: unlinked(real(*args)))
    monkeypatch.setattr(kn, "ring_entrance", lambda *args: unlinked(real_rings(*args)))
    # (this deliberate fallback is not counted against the module: restored at teardown)
    monkeypatch.setattr(nfp_module, "_FALLBACKS", nfp_module.fallback_count())


def test_geos_fallback_gives_the_same_region(monkeypatch):
    # If the outline parts ever failed to link into rings, GEOS unions the sums.
    a, b = shape(FRAME), shape(C_CAVITY)
    want = pc.no_fit_polygon(a, b).region
    _force_geos_fallback(monkeypatch)
    before = nfp_module.fallback_count()
    got = pc.no_fit_polygon(a, b).region
    assert nfp_module.fallback_count() == before + 1
    assert shapely.symmetric_difference(got, want).area < 1e-12 * want.area
    assert hole_count(got) == hole_count(want)


# -- random shapes ----------------------------------------------------------------------


@st.composite
def star_shapes(draw, holes=True):
    """Star-shaped polygon (concave in general), maybe with a star-shaped hole."""
    n = draw(st.integers(3, 12))
    radii = draw(st.lists(st.floats(0.6, 3.0), min_size=n, max_size=n))
    phase = draw(st.floats(0, 1))
    ang = 2 * np.pi * (np.arange(n) + phase) / n
    cx, cy = draw(st.floats(-5, 5)), draw(st.floats(-5, 5))
    ring = np.c_[cx + np.array(radii) * np.cos(ang), cy + np.array(radii) * np.sin(ang)]
    hole_rings = []
    if holes and draw(st.booleans()):
        m = draw(st.integers(3, 6))
        # inside the circle inscribed in the star's kernel around the centre
        r = draw(st.floats(0.1, 0.9)) * min(radii) * np.cos(np.pi / n) ** 2 / 2
        t = 2 * np.pi * np.arange(m) / m
        hole_rings.append(np.c_[cx + r * np.cos(t), cy + r * np.sin(t)])
    return pc.Shape(ring, hole_rings)


@st.composite
def grid_shapes(draw, size=4):
    """Unit cells of a small integer grid (some drawn, or all but a few for holes):
    collinear edges, exact fits, slides, holes touching at corners."""
    cell = st.tuples(st.integers(0, size - 1), st.integers(0, size - 1))
    if draw(st.booleans()):
        cells = draw(st.lists(cell, min_size=1, max_size=size * size, unique=True))
    else:
        gone = set(draw(st.lists(cell, max_size=size, unique=True)))
        cells = [(x, y) for x in range(size) for y in range(size) if (x, y) not in gone]
    geom = shapely.union_all([shapely.box(x, y, x + 1, y + 1) for x, y in cells])
    part = max(shapely.get_parts(geom), key=lambda g: g.area)
    try:
        return pc.Shape.from_shapely(part)
    except pc.InvalidShapeError:
        assume(False)


@examples(150)
@given(star_shapes(), star_shapes())
def test_random_concave_with_holes_against_reference(a, b):
    nfp = pc.no_fit_polygon(a, b)
    ref = reference_region(a.to_shapely(), b.to_shapely(), nfp.reference)
    assert same_region(nfp.region, ref) is None


NEAR_COINCIDENT = (
    "POLYGON ((0.9616839614202389 0.2741604609477383, -0.3084305185662055 "
    "1.0818944565977688, -2.885051884260717 -0.8224813828432158, 0.5483209218954771 "
    "-1.9233679228404779, 0.9616839614202389 0.2741604609477383))",
    "POLYGON ((1.6536898730240086 1, 0.6536898730240085 1.75, -0.3463101269759915 "
    "1.0000000000000002, 0.6536898730240083 0, 1.6536898730240086 1))",
)


def test_reference_union_of_near_coincident_hulls():
    # B's two vertices 2e-16 apart in x split it into triangles whose sums with A have
    # edges a few ulps apart; GEOS's floating union_all of those hulls lost 0.875 of the
    # area (CI seed of ce6b02e). The oracle now unions on a fine grid; the region is the
    # convex hull of the vertex differences (both shapes are convex).
    a, b = (shapely.from_wkt(w) for w in NEAR_COINCIDENT)
    nfp = pc.no_fit_polygon(a, b)
    pa = np.asarray(a.exterior.coords)[:-1]
    pb = np.asarray(b.exterior.coords)[:-1]
    hull = shapely.MultiPoint((pb[:, None] - pa[None] + nfp.reference).reshape(-1, 2))
    assert same_region(nfp.region, hull.convex_hull) is None
    assert same_region(nfp.region, reference_region(a, b, nfp.reference)) is None


def test_geos_fallback_unions_near_coincident_hulls_on_a_grid(monkeypatch):
    # The fallback's floating union_all lost 0.875 of the area 15.7 on this pair (see
    # test_reference_union_of_near_coincident_hulls); on a snap-rounding grid it is right.
    a, b = (shapely.from_wkt(w) for w in NEAR_COINCIDENT)
    _force_geos_fallback(monkeypatch)
    before = nfp_module.fallback_count()
    nfp = pc.no_fit_polygon(a, b)
    assert nfp_module.fallback_count() == before + 1
    pa = np.asarray(a.exterior.coords)[:-1]
    pb = np.asarray(b.exterior.coords)[:-1]
    hull = shapely.MultiPoint((pb[:, None] - pa[None] + nfp.reference).reshape(-1, 2))
    assert same_region(nfp.region, hull.convex_hull) is None


def test_geos_fallback_union_does_not_drop_near_coincident_hulls():
    # The hulls of the reference's pieces of the pair above (its slabs, A's centroid as
    # reference) whose floating union_all GEOS cut to 15.74 of 16.62; the fallback's union
    # is snap-rounded and keeps them whole.
    from nfp_reference import trapezoids

    a, b = (shapely.from_wkt(w) for w in NEAR_COINCIDENT)
    a0 = np.array([-0.5611591731704021, -0.46326479604606213])
    hulls = [shapely.MultiPoint((t[:, None] + (a0 - s)[None]).reshape(-1, 2)).convex_hull
             for t in trapezoids(b) for s in trapezoids(a)]
    assert shapely.union_all(hulls).area < 15.75  # GEOS's floating union loses a piece
    pa = np.asarray(a.exterior.coords)[:-1]
    pb = np.asarray(b.exterior.coords)[:-1]
    want = shapely.MultiPoint((pb[:, None] - pa[None] + a0).reshape(-1, 2)).convex_hull
    got = nfp_module._union_of_sums(hulls, 1e-12 * 4.0)
    assert same_region(got, want) is None


@examples(200)
@given(grid_shapes(), grid_shapes())
def test_grid_shapes_against_reference_and_lattice(a, b):
    nfp = pc.no_fit_polygon(a, b, reference="origin")
    ref = reference_region(a.to_shapely(), b.to_shapely(), (0.0, 0.0))
    assert same_region(nfp.region, ref) is None
    # Exact fits and slides of integer shapes lie on the integer lines: every lattice
    # point (and mid-point of a lattice edge) inside the region's area where A only
    # touches B is an exact fit or on a slide, and nothing else is reported.
    x0, y0, x1, y1 = (int(v) for v in nfp.region.bounds)
    boundary = nfp.region.boundary
    slides = shapely.linestrings(nfp.slides) if len(nfp.slides) else None
    fits = {tuple(p) for p in nfp.exact_fits.tolist()}
    for x2 in range(2 * x0, 2 * x1 + 1):
        for y2 in range(2 * y0, 2 * y1 + 1):
            if x2 % 2 and y2 % 2:
                continue
            p = shapely.Point(x2 / 2, y2 / 2)
            if shapely.distance(boundary, p) < 1e-9 or not shapely.contains(nfp.region, p):
                continue
            touching = pc.classify(a.moved((p.x, p.y)), b).state is State.CONTACT
            on_slide = slides is not None and shapely.distance(slides, p).min() < 1e-9
            listed = on_slide or (p.x, p.y) in fits
            assert touching == listed, (p, touching, on_slide)
    for x, y in fits:
        assert float(x).is_integer() and float(y).is_integer()


# -- ESICUP pieces ----------------------------------------------------------------------

# <checkout>/../shared (the main checkout) or further up (a worktree)
ESICUP = next((p / "shared" / "datasets" / "esicup" for p in Path(__file__).resolve().parents
               if (p / "shared" / "datasets" / "esicup").is_dir()), Path("/nonexistent"))


def _rotated(ring, degrees):
    t = np.radians(degrees)
    c, s = (round(np.cos(t)), round(np.sin(t))) if degrees % 90 == 0 else (np.cos(t), np.sin(t))
    return np.asarray(ring, dtype=float) @ np.array([[c, s], [-s, c]])


@pytest.mark.skipif(not ESICUP.is_dir(), reason="ESICUP instances not available")
@pytest.mark.parametrize("instance", ["shapes0", "shapes1", "blaz1", "shirts"])
def test_esicup_every_pair_against_reference(instance):
    data = json.loads((ESICUP / f"{instance}.json").read_text())
    pieces = [pc.Shape(_rotated(it["shape"]["data"], deg))
              for it in data["items"] for deg in it["allowed_orientations"]]
    wrong = []
    for i, a in enumerate(pieces):
        for j, b in enumerate(pieces):
            nfp = pc.no_fit_polygon(a, b, reference="origin")
            why = same_region(nfp.region, reference_region(a.to_shapely(), b.to_shapely(),
                                                           (0.0, 0.0)))
            if why:
                wrong.append((i, j, why))
    assert wrong == []


# -- inner-fit polygon --------------------------------------------------------------------


def test_inner_fit_rectangle_in_bin():
    bin_ = [(0, 0), (10, 0), (10, 4), (0, 4)]
    ifp = pc.inner_fit_polygon([(0, 0), (2, 0), (2, 1), (0, 1)], bin_, reference="origin")
    assert shapely.equals(ifp, shapely.box(0, 0, 8, 3))
    exact = pc.inner_fit_polygon([(0, 0), (2, 0), (2, 4), (0, 4)], bin_, reference="origin")
    assert exact.geom_type == "LineString" and shapely.equals(
        exact, shapely.LineString([(0, 0), (8, 0)]))
    both = pc.inner_fit_polygon([(0, 0), (10, 0), (10, 4), (0, 4)], bin_, reference="origin")
    assert both.geom_type == "Point" and (both.x, both.y) == (0.0, 0.0)
    assert pc.inner_fit_polygon([(0, 0), (11, 0), (11, 1)], bin_).is_empty


@examples(80)
@given(grid_shapes(size=3), grid_shapes(size=5))
def test_inner_fit_against_brute_force(a, container):
    ifp = pc.inner_fit_polygon(a, container, reference="origin")
    c = container.to_shapely()
    ap = a.to_shapely()
    for x in np.arange(-4, 6, 0.5):
        for y in np.arange(-4, 6, 0.5):
            placed = shapely.affinity.translate(ap, x, y)
            inside = placed.difference(c).area < 1e-12
            assert inside == shapely.intersects_xy(ifp, x, y), (x, y)


# Grid shapes whose straight sides hold several vertices: the sums along one line mix
# edges on and off the reduced convolution; the outline there is kept once, by the kernel.
GRID_INNER_FITS = [
    ([(0, 0), (1, 0), (2, 0), (2, 1), (1, 1), (0, 1)],
     [(1, 1), (2, 1), (2, 0), (3, 0), (3, 1), (4, 1), (4, 0), (5, 0), (5, 1), (5, 2), (5, 3),
      (5, 4), (5, 5), (4, 5), (3, 5), (2, 5), (1, 5), (0, 5), (0, 4), (0, 3), (0, 2), (1, 2)],
     shapely.Polygon([(0, 4), (3, 4), (3, 1), (1, 1), (1, 2), (0, 2)])),
    ([(0, 1), (0, 0), (1, 0), (2, 0), (3, 0), (3, 1), (3, 2), (3, 3), (2, 3), (1, 3), (0, 3),
      (0, 2)],
     [(0, 2), (0, 1), (0, 0), (1, 0), (2, 0), (3, 0), (4, 0), (4, 1), (5, 1), (5, 2), (4, 2),
      (4, 3), (5, 3), (5, 4), (4, 4), (3, 4), (2, 4), (2, 5), (1, 5), (0, 5), (0, 4), (0, 3)],
     shapely.box(0, 0, 1, 1)),
]


@pytest.mark.parametrize("a, container, want", GRID_INNER_FITS)
def test_inner_fit_of_grid_shapes_is_assembled_by_the_kernel(a, container, want):
    before = nfp_module.fallback_count()
    ifp = pc.inner_fit_polygon(a, container, reference="origin")
    assert nfp_module.fallback_count() == before
    assert shapely.equals(ifp, want), ifp.wkt
    # no vertex that changes nothing (none on the segment of its neighbours)
    ring = np.asarray(ifp.exterior.coords)[:-1]
    u = ring - np.roll(ring, 1, axis=0)
    v = np.roll(ring, -1, axis=0) - ring
    turn = u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]
    assert np.all(turn != 0), ifp.wkt
    c = shapely.Polygon(container)
    ap = shapely.Polygon(a)
    for x in np.arange(-1, 5, 0.25):
        for y in np.arange(-1, 5, 0.25):
            inside = shapely.affinity.translate(ap, x, y).difference(c).area < 1e-12
            assert inside == shapely.intersects_xy(ifp, x, y), (x, y)


# -- no crash at any finite input --------------------------------------------------------

HUGE = [1e105, 1e120, 1e140, 1e154]


@pytest.mark.parametrize("side", HUGE)
def test_huge_squares_are_refused_not_a_segfault(side):
    # Before: the centroid overflowed to inf, the sums to NaN, and the sum kernel's
    # merge never advanced: out-of-bounds writes, a segmentation fault.
    sq = np.array(SQ, dtype=float) * side
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # Shape's own overflow, if any
        with pytest.raises(pc.InvalidShapeError, match="overflow float64"):
            pc.no_fit_polygon(sq, sq)
        with pytest.raises(pc.InvalidShapeError, match="overflow float64"):
            pc.inner_fit_polygon(sq, 3 * sq)


@pytest.mark.parametrize("side", [1e105, 1e154])
def test_huge_squares_time_of_impact_is_refused_not_no_hit(side):
    # Before: "no hit" where there is one (the same squares as the NFP crash above).
    sq = np.array(SQ, dtype=float) * side
    with pytest.raises(pc.InvalidShapeError, match="overflow float64"):
        pc.time_of_impact(sq, pc.Motion(velocity=(side, 0.0)), sq + [3.0 * side, 0.0],
                          pc.Motion(), t_max=5.0)


def test_nfp_beyond_its_memory_budget_is_refused_not_killed(monkeypatch):
    # Two large concave bodies make a sum per pair of pieces (1000 x 100 000 vertices:
    # hundreds of millions of vertices); past its budget the NFP raises a clear error.
    # The budget is lowered here to reach it with small shapes.
    monkeypatch.setattr(pc.limits, "MAX_SUM_VERTICES", 20)
    comb = [(0, 0), (4, 0), (4, 3), (3, 1), (2, 3), (1, 1), (0, 3)]
    with pytest.raises(nfp_module.NfpTooLargeError, match="memory"):
        pc.no_fit_polygon(comb, comb)
    assert issubclass(nfp_module.NfpTooLargeError, (pc.PolycontactError, MemoryError))


def _regular_combs(teeth):
    return tuple(pc.Shape(x) for x in interlocking_combs(teeth))


def test_interlocking_combs_match_the_reference():
    # their sums overlap by the dozen wherever teeth meet gaps: every exact fit found is
    # a point where A touches B, every slide a segment, and the region is the reference
    a, b = _regular_combs(20)
    nfp = pc.no_fit_polygon(a, b, reference="origin")
    ref = reference_region(a.to_shapely(), b.to_shapely(), (0.0, 0.0))
    assert same_region(nfp.region, ref) is None
    # a slide for each way the teeth can enter: 2 x 20 - 1 shifts
    assert len(nfp.slides) == 39 and len(nfp.exact_fits) == 0
    for s in nfp.slides:
        for p in (s[0], s[1], 0.5 * (s[0] + s[1])):
            assert nfp.contains(p) is State.CONTACT


def test_nfp_beyond_its_clipping_limit_is_refused_naming_the_estimate(monkeypatch):
    # the edge-sum tests are counted once the sums are built, before any clipping (420
    # sums: enough for the grid that lists them)
    a, b = _regular_combs(20)
    monkeypatch.setattr(pc.limits, "MAX_CLIP_TESTS", 1000)
    with pytest.raises(pc.NfpTooLargeError, match=r"about [0-9.e+]+ edge–sum tests "
                                                  r".*MAX_CLIP_TESTS = 1e\+03 \(time\)"):
        pc.no_fit_polygon(a, b, reference="origin")
    monkeypatch.undo()
    assert pc.no_fit_polygon(a, b, reference="origin").region.area > 0


@pytest.mark.parametrize("far", [1e150, 1e100, 1e17])
def test_reference_too_far_for_the_region_is_refused(far):
    # Before: an empty region (the unit squares' sums vanish in the rounding at 1e17 and
    # beyond), silently wrong.
    with pytest.raises(ValueError, match="reference"):
        pc.no_fit_polygon(SQ, SQ, reference=(far, 0.0))
    with pytest.raises(ValueError, match="reference"):
        pc.inner_fit_polygon(SQ, np.array(SQ) * 3, reference=(0.0, -far))


def test_far_reference_that_float64_resolves_is_answered():
    # at 1e9 the rounding (1.4e-5) is far below the unit bodies: the region is exact
    nfp = pc.no_fit_polygon(SQ, SQ, reference=(1e9, 0.0))
    assert nfp.region.area == pytest.approx(4.0, rel=1e-4)


def test_nfp_kernel_reports_non_finite_sums_instead_of_crashing():
    # The kernel itself is safe: run apart, so that a crash fails this test only.
    code = (
        "import numpy as np\n"
        "from polycontact._kernels import minkowski as kmink\n"
        "from polycontact._kernels import nfp as kn\n"
        "sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])\n"
        "st = np.array([0, 4])\n"
        "r = np.full((4, 2), np.inf)\n"
        "print(kn.entrance_region(sq, st, r, st, -1.0, 1e-12, 64.0, 1e-9, 1e8)[4][1])\n"
        "print(len(kmink.convex_sums(sq, st, r, st)[0]) <= 8)\n"
    )
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=900)
    assert run.returncode == 0, run.stderr[-2000:]
    assert run.stdout.split() == ["-1.0", "True"]
