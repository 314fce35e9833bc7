"""Repairs of invalid polygons (``Shape(..., repair=True)``).

GEOS's ``make_valid(method="structure")`` reads the loops' linework as a polygon. Its
result is kept only when it is one polygon, valid exactly (the caller's check) and
within the tolerance of the input's linework. Where it is not:

- GEOS's floating overlay can fall back on snapping when its arithmetic fails, and
  then moves nodes by about 1e-12 of the coordinates, beyond the tolerance: the loops
  are then read as ``make_valid`` reads them from GEOS's noding (``shapely.node``, whose
  nodes are within a few float spacings) and ``shapely.build_area``, holes cut on the
  grid of :func:`polycontact.tolerances.snap_grid` (a power of two below 1/256 of the
  tolerance), where GEOS's overlay is exact;
- GEOS's result can still meet itself exactly where GEOS's arithmetic does not see it
  (a vertex exactly on an edge that GEOS finds a float spacing away): it is then
  snap-rounded onto that grid, which moves each vertex by less than a grid step.

Every vertex of a repaired shape lies within the tolerance of the input's linework.
Far from the origin (1e3 and more, features a thousand times smaller) GEOS's overlay can
misread the loops' crossings into another region: a repair whose region differs from
GEOS's reading of the loops moved exactly to their corner is refused.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

from .errors import InvalidShapeError
from .tolerances import default_tolerance, snap_grid


def repaired(rings: Sequence[np.ndarray], why: str,
             check: Callable[[Any], None]) -> tuple[Any, float, str]:
    """``(polygon, grid, note)``: the repair of the loops ``rings`` (float64 (N, 2)
    arrays, outer loop first) refused because ``why``.

    ``check`` raises :class:`InvalidShapeError` for a shapely polygon that is not valid
    exactly. ``grid`` is the step the result was snapped onto (0.0 if it was not);
    ``note`` says what was done and why. Raises :class:`InvalidShapeError` ("cannot
    repair: ...") when the repair is not one polygon, or not within the tolerance.
    """
    import shapely

    try:
        raw = shapely.Polygon(rings[0], rings[1:])
    except shapely.errors.ShapelyError as exc:  # rings shapely cannot even build
        raise InvalidShapeError(f"cannot repair: {why} ({exc})") from None
    eps = default_tolerance(*rings)
    grid = snap_grid(eps) if eps > 0.0 else 0.0  # (0: a ring of one point at the origin)
    lines = shapely.multilinestrings([np.vstack([r, r[:1]]) for r in rings if len(r)])
    poly = _one_polygon(shapely.make_valid(raw, method="structure", keep_collapsed=False),
                        why, "shapely.make_valid")
    note = f"made valid with shapely.make_valid(method='structure') because {why}"
    snapped = False
    off = _farthest(poly, lines)
    if off > eps - grid:
        poly, snapped = _structure(rings, grid, why)
        note = (f"made valid as shapely.make_valid(method='structure') does, from GEOS's "
                f"noding of the loops (shapely.node, shapely.build_area), because {why} "
                f"(shapely.make_valid itself moved the outline by {off:.3g}, beyond the "
                f"tolerance {eps:.3g})")
    try:
        check(poly)
    except InvalidShapeError as exc:
        poly = _one_polygon(_snap(poly, grid, why), why, f"snapping onto a grid of {grid:.3g}")
        note += (f"; then snapped onto a grid of {grid:.3g} (each vertex moved by at most "
                 f"{grid * 0.5**0.5:.3g}, far below the tolerance) because {exc}")
        snapped = True
        try:
            check(poly)
        except InvalidShapeError as err:
            raise InvalidShapeError(f"cannot repair: {why}; snapped: {err}") from None
    off = _farthest(poly, lines)
    if off > eps:
        raise InvalidShapeError(f"cannot repair: {why}; the repair moves the outline by "
                                f"{off:.3g}, beyond the tolerance {eps:.3g}")
    near = _read_about_corner(rings)
    if near is not None and (shapely.symmetric_difference(poly, near).area
                             > 2.0 * eps * (poly.length + near.length)):
        raise InvalidShapeError(f"cannot repair: {why}; GEOS reads another region from the "
                                "loops moved exactly to their corner (far from the origin its "
                                "overlay can misread their crossings)")
    return poly, grid if snapped else 0.0, note


def _read_about_corner(rings: Sequence[np.ndarray]) -> Any:
    """``make_valid(method="structure")`` of the loops moved to the lower corner of their
    box and moved back, or None when that moves nothing. Each coordinate moves only
    where the move is exact for every vertex (Sterbenz: within a factor 2 of the
    corner's; checked), so the loops read are the caller's. About the corner GEOS's
    overlay reads the crossings of far-off loops (1e3 from the origin and more, features
    a thousand times smaller) as they are: a repair whose region differs from that
    reading by more than a band of the tolerance along both outlines is refused."""
    import shapely

    pts = [r for r in rings if len(r)]
    if not pts:
        return None
    corner = np.min([r.min(axis=0) for r in pts], axis=0)
    for c in range(2):  # (a coordinate whose move would round stays where it is)
        if not all(np.array_equal((r[:, c] - corner[c]) + corner[c], r[:, c]) for r in pts):
            corner[c] = 0.0
    if not corner.any():
        return None
    local = [r - corner for r in rings]
    read = shapely.make_valid(shapely.Polygon(local[0], local[1:]), method="structure",
                              keep_collapsed=False)
    return shapely.affinity.translate(read, *corner)


def _structure(rings: Sequence[np.ndarray], grid: float, why: str) -> tuple[Any, bool]:
    """``(polygon, snapped)``: the loops read as ``make_valid(method="structure")`` reads
    them (each loop's area by the even-odd rule of its noded linework; the holes' union
    cut from the outer loop's), from GEOS's noding, which computes its nodes to a few
    float spacings. The cut is snap-rounded onto the grid (``snapped``), where GEOS's
    overlay is exact."""
    import shapely

    try:
        areas = [shapely.build_area(shapely.node(shapely.linearrings(r))) for r in rings]
        if len(areas) == 1:
            return _one_polygon(areas[0], why, "the even-odd area of the loop"), False
        cut = shapely.difference(areas[0], shapely.union_all(areas[1:], grid_size=grid),
                                 grid_size=grid)
    except shapely.errors.ShapelyError as exc:
        raise InvalidShapeError(f"cannot repair: {why} ({exc})") from None
    return _one_polygon(cut, why, "the outer loop's area less the holes'"), True


def _one_polygon(geom: Any, why: str, how: str) -> Any:
    """The one polygon of positive area in a repair's result ``geom`` (made by
    ``how``); refuses others."""
    import shapely

    polys = [g for g in shapely.get_parts(geom) if g.geom_type == "Polygon" and g.area > 0]
    if len(polys) != 1:
        raise InvalidShapeError(f"cannot repair: {why}; {how} gives {len(polys)} polygons, "
                                "not one")
    return polys[0]


def _snap(geom: Any, grid: float, why: str) -> Any:
    """``geom`` snap-rounded onto a grid of step ``grid``, valid for GEOS."""
    import shapely

    try:
        return shapely.set_precision(geom, grid)
    except shapely.errors.GEOSException as exc:
        raise InvalidShapeError(f"cannot repair: {why}; snapping onto a grid of {grid:.3g}, "
                                f"GEOS fails: {exc}") from None


def _farthest(poly: Any, lines: Any) -> float:
    """The largest distance from a vertex of ``poly`` to the input's linework."""
    import shapely

    return float(shapely.distance(shapely.points(shapely.get_coordinates(poly)), lines).max())
