"""Figure of a relation: both bodies, the witness point, the normal (matplotlib inside)."""

from __future__ import annotations

from typing import TYPE_CHECKING

from ._style import draw_shape, label_axes, legend_outside, new_axes, xy

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from ..relation import Relation

__all__ = ["plot_relation"]


def plot_relation(relation: Relation, ax: Axes | None = None) -> Axes:
    """Draw A (red) and B (blue) where they stand, the witness point and the normal.

    Parameters
    ----------
    relation : Relation
    ax : matplotlib Axes, optional
        Drawn into a new figure when omitted.

    Returns
    -------
    matplotlib Axes

    Examples
    --------
    >>> import polycontact as pc
    >>> from polycontact.plotting import plot_relation
    >>> sq = [(0, 0), (2, 0), (2, 2), (0, 2)]
    >>> ax = plot_relation(pc.classify(sq, [(1, 1), (3, 1), (3, 3), (1, 3)]))
    >>> ax.get_title(), ax.get_legend_handles_labels()[1]
    ('penetrating, distance -1', ['A', 'B', 'witness point', 'normal, A towards B'])
    """
    if ax is None:
        ax = new_axes((8, 6))
    from matplotlib.lines import Line2D

    a, b = relation.shapes
    draw_shape(ax, a, "tab:red", 0.45, "A")
    draw_shape(ax, b, "tab:blue", 0.45, "B")
    point, normal = relation.point, relation.normal
    if point is not None:
        ax.plot(*point, "*", color="gold", markeredgecolor="black", ms=13, zorder=5,
                label="witness point")
        if normal is not None:
            size = 0.3 * max(a.bounding_radius, b.bounding_radius)
            ax.annotate("", xy=xy(point + size * normal), xytext=xy(point), zorder=6,
                        arrowprops={"arrowstyle": "-|>", "color": "black", "lw": 1.8})
            ax.add_line(Line2D([], [], color="black", lw=1.8, marker=">", markevery=[1],
                               label="normal, A towards B"))
    ax.set_title(f"{relation.state.value}, distance {relation.distance:.6g}")
    label_axes(ax)
    ax.autoscale_view()
    legend_outside(ax)
    return ax
