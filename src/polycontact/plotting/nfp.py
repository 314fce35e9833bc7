"""Figures of a no-fit polygon (B, A at one placement, the region, its holes, exact fits
and slides) and of an inner-fit polygon (the container, A at one placement, the
positions where A fits)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from ._style import label_axes, legend_outside, new_axes, plural

if TYPE_CHECKING:
    import numpy.typing as npt
    from matplotlib.axes import Axes
    from shapely.geometry.base import BaseGeometry

    from ..nfp import NoFitPolygon
    from ..shape import Shape

__all__ = ["fit_parts", "plot_inner_fit", "plot_nfp"]


def _patch(geom: Any, **style: Any) -> Any:
    """A matplotlib patch for a shapely (Multi)Polygon, holes left open."""
    import shapely
    import shapely.affinity
    from matplotlib.patches import PathPatch
    from matplotlib.path import Path

    verts: list[np.ndarray] = []
    codes: list[int] = []
    for poly in shapely.get_parts(shapely.orient_polygons(geom)):
        for ring in (poly.exterior, *poly.interiors):
            xy = np.asarray(ring.coords)[:, :2]
            verts.extend(xy)
            codes.extend(int(c) for c in [Path.MOVETO, *[Path.LINETO] * (len(xy) - 2), Path.CLOSEPOLY])
    return PathPatch(Path(np.asarray(verts), codes), **style)


def plot_nfp(nfp: NoFitPolygon, placement: npt.ArrayLike | None = None,
             ax: Axes | None = None) -> Axes:
    """Draw a no-fit polygon like the paper's Fig. 18.

    B in grey; the region E(A, B) in red, its outline (the NFP) in black, its holes
    left white; exact fits as black stars and slides as thick black segments; A (purple)
    drawn with its reference point (red dot) at ``placement``.

    Parameters
    ----------
    nfp : NoFitPolygon
    placement : array_like of shape (2,), optional
        Where to draw A's reference point; default: the first exact fit if any, else
        the first vertex of the outline (A touching B).
    ax : matplotlib Axes, optional
        Drawn into a new figure when omitted.

    Returns
    -------
    matplotlib Axes

    Examples
    --------
    >>> import polycontact as pc
    >>> from polycontact.plotting import plot_nfp
    >>> sq = pc.Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
    >>> ax = plot_nfp(pc.no_fit_polygon(sq, sq.moved((3, 0))))
    >>> ax.get_title()
    'no-fit polygon: area 4, 0 holes, 0 exact fits, 0 slides'
    >>> ax.get_xlabel()
    'x (length units)'
    """
    if ax is None:
        ax = new_axes((9, 6.5))
    region = nfp.region
    holes = _draw_fit(ax, region, nfp.exact_fits, nfp.slides, nfp.b, nfp.a, nfp.reference,
                      placement, inner=False)
    ax.set_title(f"no-fit polygon: area {region.area:.6g}, {plural(holes, 'hole')}, "
                 f"{plural(len(nfp.exact_fits), 'exact fit')}, "
                 f"{plural(len(nfp.slides), 'slide')}")
    return ax


def fit_parts(geometry: Any) -> tuple[Any, np.ndarray, np.ndarray]:
    """``(region, exact_fits, slides)`` of an inner-fit polygon
    (:func:`polycontact.inner_fit_polygon`'s geometry): its areas as one (Multi)Polygon
    (empty if none), its isolated points as an (F, 2) array and its segments as an
    (S, 2, 2) array (a path of several segments gives each).

    Examples
    --------
    >>> import shapely
    >>> g = shapely.GeometryCollection([shapely.box(0, 0, 1, 1), shapely.Point(3, 0),
    ...                                 shapely.LineString([(5, 0), (6, 0), (6, 1)])])
    >>> region, fits, slides = fit_parts(g)
    >>> region.area, fits.tolist(), slides.tolist()
    (1.0, [[3.0, 0.0]], [[[5.0, 0.0], [6.0, 0.0]], [[6.0, 0.0], [6.0, 1.0]]])
    """
    import shapely

    parts = shapely.get_parts(geometry)
    while any(g.geom_type.startswith(("Multi", "GeometryCollection")) for g in parts):
        parts = shapely.get_parts(parts)
    polygons = [g for g in parts if g.geom_type == "Polygon" and not g.is_empty]
    fits = [g.coords[0] for g in parts if g.geom_type == "Point" and not g.is_empty]
    slides = [seg for g in parts if g.geom_type == "LineString"
              for seg in zip(g.coords[:-1], g.coords[1:])]
    region = shapely.union_all(polygons) if polygons else shapely.Polygon()
    return (region, np.array(fits, dtype=np.float64).reshape(-1, 2),
            np.array(slides, dtype=np.float64).reshape(-1, 2, 2))


def plot_inner_fit(a: Shape, container: Shape, geometry: BaseGeometry,
                   reference: npt.ArrayLike, placement: npt.ArrayLike | None = None,
                   ax: Axes | None = None) -> Axes:
    """Draw an inner-fit polygon: the container in grey, the positions of A's reference
    point where A lies inside it in green (with its outline), exact fits as black stars
    and slides as thick black segments, and A (purple) with its reference point (red
    dot) at ``placement``.

    Parameters
    ----------
    a, container : Shape
        The body placed and the container (as given to
        :func:`polycontact.inner_fit_polygon`).
    geometry : shapely geometry
        What :func:`polycontact.inner_fit_polygon` returned.
    reference : array_like of shape (2,)
        A's reference point (where A is as given).
    placement : array_like of shape (2,), optional
        Where to draw A's reference point; default: the first exact fit if any, else
        the first vertex of the region's outline (A touching the container), else the
        first slide's start.
    ax : matplotlib Axes, optional
        Drawn into a new figure when omitted.

    Returns
    -------
    matplotlib Axes

    Examples
    --------
    >>> import polycontact as pc
    >>> from polycontact.plotting import plot_inner_fit
    >>> bin_, a = pc.Shape([(0, 0), (4, 0), (4, 2), (0, 2)]), pc.Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
    >>> ax = plot_inner_fit(a, bin_, pc.inner_fit_polygon(a, bin_, "origin"), (0, 0))
    >>> ax.get_title()
    'inner-fit polygon: area 3, 0 exact fits, 0 slides'
    """
    if ax is None:
        ax = new_axes((9, 6.5))
    region, fits, slides = fit_parts(geometry)
    reference = np.asarray(reference, dtype=np.float64)
    _draw_fit(ax, region, fits, slides, container, a, reference, placement, inner=True)
    if geometry.is_empty:
        ax.set_title("inner-fit polygon: empty, A does not fit in the container")
    else:
        ax.set_title(f"inner-fit polygon: area {region.area:.6g}, "
                     f"{plural(len(fits), 'exact fit')}, {plural(len(slides), 'slide')}")
    return ax


def _draw_fit(ax: Any, region: Any, fits: np.ndarray, slides: np.ndarray, fixed: Any,
              a: Any, reference: np.ndarray, placement: Any, *, inner: bool) -> int:
    """Draw a no-fit (``inner`` False) or inner-fit polygon into ``ax``: the fixed body
    or container, the region with its outline, exact fits, slides, A placed at
    ``placement`` (default: see :func:`plot_nfp` and :func:`plot_inner_fit`) and its
    reference point; returns the number of holes of the region."""
    import shapely
    import shapely.affinity

    if placement is None:
        if len(fits):
            placement = fits[0]
        elif not region.is_empty:
            placement = shapely.get_coordinates(region)[0]
        elif len(slides):
            placement = slides[0, 0]
        else:
            placement = reference
    p = np.asarray(placement, dtype=float)
    holes = sum(len(g.interiors) for g in shapely.get_parts(region))
    fixed_style = {"facecolor": "0.6", "alpha": 0.8, "edgecolor": "0.3",
                   "label": "container" if inner else "B (fixed)"}
    if inner:
        ax.add_patch(_patch(fixed.to_shapely(), **{**fixed_style, "alpha": 0.35}))
    if not region.is_empty:
        ax.add_patch(_patch(region, facecolor="tab:green" if inner else "tab:red",
                            alpha=0.35 if inner else 0.25, edgecolor="none",
                            label="where A fits inside" if inner
                            else "E(A, B): A touches or overlaps B"))
        for k, ring in enumerate(shapely.get_rings(shapely.get_parts(region))):
            xy = np.asarray(ring.coords)
            ax.plot(xy[:, 0], xy[:, 1], color="black", linewidth=1.2,
                    label=("outline" if inner else "outline (NFP) and holes") if k == 0
                    else None)
    if not inner:
        ax.add_patch(_patch(fixed.to_shapely(), **fixed_style))
    placed = shapely.affinity.translate(a.to_shapely(), *(p - reference))
    ax.add_patch(_patch(placed, facecolor="tab:purple", alpha=0.45, edgecolor="indigo",
                        label="A at the reference point"))
    for k, s in enumerate(slides):
        ax.plot(s[:, 0], s[:, 1], color="black", linewidth=3,
                label="slides" if k == 0 else None)
    if len(fits):
        ax.plot(fits[:, 0], fits[:, 1], "*", color="black", markersize=12,
                label="exact fits")
    ax.plot([p[0]], [p[1]], "o", color="red", label="A's reference point")
    label_axes(ax)
    ax.autoscale_view()
    legend_outside(ax)
    return holes
