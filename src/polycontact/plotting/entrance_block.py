"""Figure of an entrance block: the bodies, the three families of components, a0."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from ._style import LENGTH_LABEL, label_axes, legend_outside, plural, pyplot

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from ..entrance import EntranceBlock

__all__ = ["plot_entrance_block", "plot_union"]

#: Colour and title of each family (one term of paper Eq. 1).
FAMILY_STYLE = {
    "A2-B0": ("tab:blue", "E(A(2), B(0)): a vertex of B in A"),
    "A0-B2": ("tab:green", "E(A(0), B(2)): a vertex of A in B"),
    "A1-B1": ("tab:orange", "E(A(1), B(1)): an edge of A meets an edge of B"),
}


def plot_entrance_block(block: EntranceBlock, figure: Figure | None = None) -> Figure:
    """Draw an entrance block like the paper's Fig. 5, in four panels.

    One panel per family of components (each in its colour, translucent so overlaps
    show), then their union E(A, B) in red with its outline (the no-fit polygon) in
    black: a0 inside means penetrating, on the outline contact, outside separate. Every panel shows B (grey), A at its place (purple) and the
    reference point a0 (red dot); the relation at a0 is in the last panel's title.

    Parameters
    ----------
    block : EntranceBlock
    figure : matplotlib Figure, optional
        Drawn into a new figure, 12 inches wide, when omitted.

    Returns
    -------
    matplotlib Figure

    Examples
    --------
    >>> import polycontact as pc
    >>> from polycontact.plotting import plot_entrance_block
    >>> a = pc.Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
    >>> fig = plot_entrance_block(pc.entrance_block(a, a.moved((3, 0))))
    >>> for ax in fig.axes:
    ...     print(" | ".join(ax.get_title().splitlines()))
    E(A(2), B(0)): a vertex of B in A | 4 components
    E(A(0), B(2)): a vertex of A in B | 4 components
    E(A(1), B(1)): an edge of A meets an edge of B | 4 components, swept
    E(A, B), the union of the three; area 4 | A and B at a0: separate
    """
    if figure is None:
        import shapely

        x0, y0, x1, y1 = shapely.union_all(
            [block.to_shapely(), block.a.to_shapely(), block.b.to_shapely()]).bounds
        ratio = min(2.0, max(0.4, (y1 - y0) / max(x1 - x0, 1e-300)))
        figure = pyplot().figure(figsize=(12, 11 * ratio + 2.2), layout="constrained")
    axes = figure.subplots(2, 2, sharex=True, sharey=True).ravel()
    for ax, (family, (colour, text)) in zip(axes, FAMILY_STYLE.items()):
        _bodies(ax, block)
        _family(ax, block, family, colour)
        _reference(ax, block)
        n = len(block.of_family(family))
        how = f", {block.method}" if family == "A1-B1" else ""
        ax.set_title(f"{text}\n{plural(n, 'component')}{how}", fontsize=10)
    handles = _legend_handles(_union_panel(axes[3], block))
    figure.legend(handles=handles, loc="outside lower center", ncol=3, fontsize=9,
                  frameon=False)
    for ax in axes[2:]:
        ax.set_xlabel(f"x {LENGTH_LABEL}")
    for ax in axes[::2]:
        ax.set_ylabel(f"y {LENGTH_LABEL}")
    for ax in axes:
        ax.set_aspect("equal")
        ax.grid(True, linewidth=0.3, alpha=0.5)
        ax.autoscale_view()
    return figure


def plot_union(block: EntranceBlock, ax: Axes) -> Axes:
    """Draw the union panel alone into ``ax``: B, A, E(A, B) with its outline, a0.

    Returns ``ax`` (with axis labels and a legend outside).

    Examples
    --------
    >>> import matplotlib.pyplot as plt, polycontact as pc
    >>> a = pc.Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
    >>> ax = plot_union(pc.entrance_block(a, a.moved((3, 0))), plt.figure().gca())
    >>> ax.get_title().splitlines()[1]
    'A and B at a0: separate'
    """
    handles = _legend_handles(_union_panel(ax, block))[3:]  # no family in this panel
    label_axes(ax)
    ax.grid(True, linewidth=0.3, alpha=0.5)
    ax.autoscale_view()
    legend_outside(ax, handles)
    return ax


def _union_panel(ax: Any, block: Any) -> list[Any]:
    """The last panel: bodies, union and a0; returns the reference point's handles."""
    _bodies(ax, block)
    _union(ax, block)
    handles = _reference(ax, block)
    state = block.classify(block.reference).state.value
    ax.set_title(f"E(A, B), the union of the three; area {block.area:.6g}\n"
                 f"A and B at a0: {state}", fontsize=10)
    return handles


def _bodies(ax: Any, block: Any) -> None:
    from matplotlib.collections import PathCollection

    ax.add_collection(PathCollection(_paths(block.b.to_shapely()), facecolor="0.8",
                                     edgecolor="0.25", linewidth=1.0, hatch="//"))
    ax.add_collection(PathCollection(_paths(block.a.to_shapely()), facecolor="none",
                                     edgecolor="tab:purple", linewidth=1.6, zorder=4))


def _family(ax: Any, block: Any, family: str, colour: str) -> None:
    from matplotlib.collections import LineCollection, PathCollection

    paths: list[Any] = []
    lines: list[np.ndarray] = []
    for c in block.of_family(family):
        _collect(c.geometry, paths, lines)
    ax.add_collection(PathCollection(paths, facecolor=colour, edgecolor=colour, alpha=0.2,
                                     linewidth=0.6, zorder=2))
    if lines:
        ax.add_collection(LineCollection(lines, colors=colour, linewidths=1.0, alpha=0.8,
                                         zorder=2))


def _union(ax: Any, block: Any) -> None:
    from matplotlib.collections import LineCollection, PathCollection

    union = block.to_shapely()
    ax.add_collection(PathCollection(_paths(union), facecolor="tab:red", edgecolor="none",
                                     alpha=0.3, zorder=2))
    lines: list[np.ndarray] = []
    _collect(union.boundary, [], lines)
    ax.add_collection(LineCollection(lines, colors="black", linewidths=1.8, zorder=3))


def _reference(ax: Any, block: Any) -> list[Any]:
    x, y = block.reference
    handles: list[Any] = ax.plot([x], [y], marker="o", color="crimson", markeredgecolor="black",
                   markersize=7, linestyle="none", zorder=5,
                   label=f"reference point a0 ({x:.4g}, {y:.4g})")
    return handles


def _legend_handles(reference: list[Any]) -> list[Any]:
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    handles: list[Any] = [Patch(facecolor=c, edgecolor=c, alpha=0.4, label=t.split(":")[0])
                          for c, t in FAMILY_STYLE.values()]
    handles += [
        Patch(facecolor="tab:red", alpha=0.3, label="E(A, B)"),
        Line2D([], [], color="black", linewidth=1.8, label="outline of E(A, B) = no-fit polygon"),
        Patch(facecolor="0.8", edgecolor="0.25", hatch="//", label="B (fixed)"),
        Patch(facecolor="none", edgecolor="tab:purple", linewidth=1.6, label="A at its place"),
    ]
    return handles + reference


def _paths(geom: Any) -> list[Any]:
    paths: list[Any] = []
    _collect(geom, paths, [])
    return paths


def _collect(geom: Any, paths: list[Any], lines: list[np.ndarray]) -> None:
    """Append a matplotlib Path per polygon (holes cut out) and an array per line."""
    import shapely
    from matplotlib.path import Path

    for part in shapely.get_parts(geom):
        kind = part.geom_type
        if kind == "Polygon":
            rings = [np.asarray(part.exterior.coords)]
            rings += [np.asarray(r.coords) for r in part.interiors]
            paths.append(Path.make_compound_path(*[Path(r, closed=True) for r in rings]))
        elif kind in ("LineString", "LinearRing"):
            lines.append(np.asarray(part.coords))
        elif kind != "Point":
            _collect(part, paths, lines)
