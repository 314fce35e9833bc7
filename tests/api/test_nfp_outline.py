"""The no-fit polygon's outline as reported: no vertex that changes nothing, and no
coordinate a rounding away from the input coordinate it stands for.

Every vertex of the outline is a vertex of some convex sum ``b + a0 − a`` or a crossing
of two sums' edges; a crossing on an axis-aligned edge lies exactly on that edge's
coordinate, which is a sum vertex's. So for shapes whose coordinates are multiples of a
power of two, every reported coordinate is such a multiple, exactly. Dropping vertices
that lie within the tolerance of their neighbours' segment moves the outline by at most
the tolerance: the region stays the independent reference's (``nfp_reference``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import shapely
from hypothesis import given
from hypothesis import strategies as st
from nfp_reference import reference_region, same_region
from profiles import examples
from .test_nfp import grid_shapes, star_shapes

import polycontact as pc
from polycontact.cli import main

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def _vertex_on_its_neighbours_segment(ring: np.ndarray, eps: float) -> list[int]:
    """The vertices of a closed ring (first point repeated last) that lie within ``eps``
    of the segment joining the vertices before and after them."""
    pts = ring[:-1]
    n = len(pts)
    out = []
    for k in range(n):
        p, a, b = pts[k], pts[k - 1], pts[(k + 1) % n]
        seg = shapely.LineString([a, b])
        if shapely.distance(seg, shapely.Point(p)) <= eps:
            out.append(k)
    return out


def test_the_outline_carries_no_vertex_that_changes_nothing(capsys):
    square, slot = EXAMPLES / "nfp-square.json", EXAMPLES / "nfp-slot.json"
    assert main(["nfp", str(square), str(slot), "--reference", "0,0", "--wkt"]) == 0
    region = capsys.readouterr().out.splitlines()[0]
    assert region == "POLYGON ((4.5 -1.5, 4.5 4, -1.5 4, -1.5 -1.5, 4.5 -1.5))"
    # a square donut made by Shapely, the unit square orbiting it (centroid reference)
    donut = pc.Shape.from_shapely(shapely.box(0, 0, 4, 4).difference(shapely.box(1, 1, 3, 3)))
    nfp = pc.no_fit_polygon(pc.Shape([(0, 0), (1, 0), (1, 1), (0, 1)]), donut)
    values = {float(v) for ring in nfp.rings for v in ring.ravel()}
    assert values <= {-0.5, 0.5, 1.5, 2.5, 3.5, 4.5}, sorted(values)
    assert shapely.normalize(nfp.region).equals_exact(shapely.normalize(shapely.Polygon(
        [(-0.5, -0.5), (4.5, -0.5), (4.5, 4.5), (-0.5, 4.5)],
        [[(1.5, 1.5), (2.5, 1.5), (2.5, 2.5), (1.5, 2.5)]])), 0.0)


@st.composite
def dyadic(draw, shapes):
    """A shape of ``shapes`` scaled by a power of two and moved by a multiple of it."""
    s = draw(shapes)
    unit = 2.0 ** draw(st.integers(-6, 6))
    dx, dy = (draw(st.integers(-40, 40)) * unit for _ in range(2))
    loops = [ring * unit + (dx, dy) for ring in s.loops]
    return pc.Shape(loops[0], loops[1:]), unit


@examples(150)
@given(dyadic(grid_shapes()), dyadic(grid_shapes()))
def test_outline_coordinates_are_the_input_coordinates_they_stand_for(a, b):
    (a, ua), (b, ub) = a, b
    unit = min(ua, ub)
    nfp = pc.no_fit_polygon(a, b, reference="origin")
    for ring in nfp.rings:
        # on the dyadic grid of the inputs, exactly: no -2e-16 for 0, no 0.4999999999999999
        assert np.all(ring / unit == np.round(ring / unit)), ring
        assert _vertex_on_its_neighbours_segment(ring, nfp.tolerance) == [], ring
    for p in nfp.exact_fits:
        assert np.all(p / unit == np.round(p / unit))
    ref = reference_region(a.to_shapely(), b.to_shapely(), (0.0, 0.0))
    assert same_region(nfp.region, ref) is None


@examples(150)
@given(star_shapes(), star_shapes())
def test_tidying_the_outline_moves_it_within_the_tolerance(a, b):
    nfp = pc.no_fit_polygon(a, b)
    for ring in nfp.rings:
        assert _vertex_on_its_neighbours_segment(ring, nfp.tolerance) == [], ring
    ref = reference_region(a.to_shapely(), b.to_shapely(), nfp.reference)
    assert same_region(nfp.region, ref) is None
    # every point of the reference's outline is within the tolerance (and the rounding
    # of the reference's own union) of the reported outline, and back
    gap = shapely.hausdorff_distance(nfp.region.boundary, ref.boundary)
    assert gap <= nfp.tolerance + 1e-9 * max(1.0, abs(np.asarray(ref.bounds)).max()), gap
