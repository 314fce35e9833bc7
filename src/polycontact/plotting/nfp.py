"""Figure of a no-fit polygon: B, A at one placement, the region, its holes and exact fits."""

from __future__ import annotations

from typing import Any

import numpy as np

from ._style import label_axes, legend_outside, plural

__all__ = ["plot_nfp"]


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


def plot_nfp(nfp: Any, placement: Any = None, ax: Any = None) -> Any:
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
    import matplotlib.pyplot as plt
    import shapely
    import shapely.affinity

    if ax is None:
        _, ax = plt.subplots(figsize=(9, 6.5), layout="constrained")
    region = nfp.region
    if placement is None:
        if len(nfp.exact_fits):
            placement = nfp.exact_fits[0]
        elif not region.is_empty:
            placement = shapely.get_coordinates(region)[0]
        else:
            placement = nfp.reference
    p = np.asarray(placement, dtype=float)
    holes = sum(len(g.interiors) for g in shapely.get_parts(region))
    if not region.is_empty:
        ax.add_patch(_patch(region, facecolor="tab:red", alpha=0.25, edgecolor="none",
                            label="E(A, B): A touches or overlaps B"))
        for k, ring in enumerate(shapely.get_parts(shapely.get_rings(region))):
            xy = np.asarray(ring.coords)
            ax.plot(xy[:, 0], xy[:, 1], color="black", linewidth=1.2,
                    label="outline (NFP) and holes" if k == 0 else None)
    ax.add_patch(_patch(nfp.b.to_shapely(), facecolor="0.6", alpha=0.8, edgecolor="0.3",
                        label="B (fixed)"))
    placed = shapely.affinity.translate(nfp.a.to_shapely(), *(p - nfp.reference))
    ax.add_patch(_patch(placed, facecolor="tab:purple", alpha=0.45, edgecolor="indigo",
                        label="A at the reference point"))
    for k, s in enumerate(nfp.slides):
        ax.plot(s[:, 0], s[:, 1], color="black", linewidth=3,
                label="slides" if k == 0 else None)
    if len(nfp.exact_fits):
        ax.plot(nfp.exact_fits[:, 0], nfp.exact_fits[:, 1], "*", color="black",
                markersize=12, label="exact fits")
    ax.plot([p[0]], [p[1]], "o", color="red", label="A's reference point")
    label_axes(ax)
    ax.autoscale_view()
    legend_outside(ax)
    ax.set_title(f"no-fit polygon: area {region.area:.6g}, {plural(holes, 'hole')}, "
                 f"{plural(len(nfp.exact_fits), 'exact fit')}, "
                 f"{plural(len(nfp.slides), 'slide')}")
    return ax
