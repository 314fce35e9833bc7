"""Independent reference for the no-fit polygon region (shares no code with polycontact).

Both shapes are cut into vertical slabs at every vertex x-coordinate; inside a slab the
solid is a set of trapezoids (convex). The entrance block is the union, over every pair
(trapezoid T of B, trapezoid S of A), of the convex hull of the vertex sums
``T + (a0 − S)``, taken with Shapely. Holes thinner than ``1e-9`` of the coordinates
(twice area over perimeter) are rounding seams, not holes.

Examples
--------
>>> import shapely
>>> sq = shapely.box(0, 0, 1, 1)
>>> reference_region(sq, sq, (0.0, 0.0)).area
4.0
"""

from __future__ import annotations

import numpy as np
import shapely


def trapezoids(poly: shapely.Geometry) -> list[np.ndarray]:
    """Convex pieces of a polygon: its parts within vertical slabs between vertices.

    (Pieces are convex because no vertex lies strictly inside a slab.) A sliver between
    two vertices less than 1e-12 of the width apart is left out (see below).
    """
    xs = np.unique(shapely.get_coordinates(poly)[:, 0])
    # Slabs thinner than 1e-12 of the width hold slivers that trip GEOS; they are left
    # out: the sums of a sliver lie within its width of its neighbours' sums, so the
    # region changes by less than 1e-12 of the size times the perimeter.
    keep = np.diff(xs) > 1e-12 * (xs[-1] - xs[0])
    _, y0, _, y1 = poly.bounds
    boxes = shapely.box(xs[:-1][keep], y0 - 1.0, xs[1:][keep], y1 + 1.0)
    out = []
    for piece in shapely.get_parts(shapely.intersection(poly, boxes)):
        for part in shapely.get_parts(piece):
            if part.geom_type == "Polygon" and part.area > 0.0:
                out.append(np.asarray(part.exterior.coords)[:-1])
    return out


def reference_region(a: shapely.Geometry, b: shapely.Geometry, a0) -> shapely.Geometry:
    """E(A, B) = {a0 + d : (A + d) ∩ B ≠ ∅} for shapely polygons A and B."""
    ta = trapezoids(a)
    tb = trapezoids(b)
    a0 = np.asarray(a0, dtype=float)
    coords = []
    ids = []
    k = 0
    for t in tb:
        for s in ta:
            pts = (t[:, None, :] + (a0 - s)[None, :, :]).reshape(-1, 2)
            coords.append(pts)
            ids.append(np.full(len(pts), k))
            k += 1
    points = shapely.multipoints(np.concatenate(coords), indices=np.concatenate(ids))
    hulls = shapely.convex_hull(points)
    scale = max(1.0, float(np.abs(shapely.get_coordinates(points)).max()))
    # Snap-rounded union: GEOS's floating union of hulls whose edges lie a few ulps
    # apart can drop whole pieces (test_nfp::test_reference_union_of_near_coincident_hulls
    # lost 0.875 of 15.7); on a grid of 1e-13 of the coordinates it is robust, and
    # moves the region by far less than the 1e-9 the comparison allows.
    region = shapely.union_all(hulls, grid_size=1e-13 * scale)
    return _without_seams(region, 1e-9 * scale)


def _without_seams(geom: shapely.Geometry, width: float) -> shapely.Geometry:
    parts = []
    for p in shapely.get_parts(geom):
        holes = [r for r in p.interiors if 2.0 * shapely.Polygon(r).area > width * r.length]
        parts.append(shapely.Polygon(p.exterior, holes))
    return parts[0] if len(parts) == 1 else shapely.MultiPolygon(parts)


def hole_count(geom: shapely.Geometry) -> int:
    """Number of holes over every polygon part."""
    return sum(len(p.interiors) for p in shapely.get_parts(geom))


def same_region(got: shapely.Geometry, want: shapely.Geometry, rel: float = 1e-9) -> str | None:
    """None when the regions agree (area of the symmetric difference and hole count)."""
    diff = shapely.symmetric_difference(got, want).area
    if diff > rel * max(want.area, 1e-300):
        return f"symmetric difference {diff:.3g} of area {want.area:.6g}"
    if hole_count(got) != hole_count(want):
        return f"{hole_count(got)} holes, reference has {hole_count(want)}"
    return None
