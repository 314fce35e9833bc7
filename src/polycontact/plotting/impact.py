"""Figure of a time-of-impact result (matplotlib imported inside the function)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from ..motion import Motion
from ..shape import ShapeLike, as_shape
from ._style import draw_shape, label_axes, legend_outside, new_axes, xy

if TYPE_CHECKING:  # (impact.py imports this module to plot: no cycle at run time)
    from matplotlib.axes import Axes

    from ..impact import Impact

__all__ = ["plot_impact"]


def _event_time(impact: Impact) -> float:
    for t in (impact.time, impact.first_contact):
        if t is not None:
            return t
    return impact.searched_to


def plot_impact(
    a: ShapeLike,
    motion_a: Motion,
    b: ShapeLike,
    motion_b: Motion,
    impact: Impact,
    *,
    names: tuple[str, str] = ("A", "B"),
    ax: Axes | None = None,
) -> Axes:
    """Draw both bodies at t = 0 (faint) and at the event, the centroid paths, the contact.

    The event is ``impact.time`` (collision), else ``impact.first_contact``, else the end
    of the search.

    Parameters
    ----------
    a, b : ShapeLike
        The bodies at t = 0, as given to :func:`polycontact.time_of_impact`.
    motion_a, motion_b : Motion
        Their motions.
    impact : Impact
        What :func:`polycontact.time_of_impact` answered for them.
    names : (str, str), default ("A", "B")
        The bodies' names in the legend.
    ax : matplotlib Axes, optional
        Drawn into a new figure when omitted.

    Returns
    -------
    matplotlib Axes

    Examples
    --------
    >>> from polycontact import Motion, Shape, time_of_impact
    >>> sq = Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
    >>> ma, mb = Motion(velocity=(1, 0)), Motion(angular_velocity=1.0)
    >>> hit = time_of_impact(sq, ma, sq.moved((3, 0)), mb, t_max=5)
    >>> ax = plot_impact(sq, ma, sq.moved((3, 0)), mb, hit)
    >>> labels = ax.get_legend_handles_labels()[1]
    >>> len(ax.patches), labels[0], labels[2], labels[-1]
    (4, 'A at t = 0', "A's centroid path", 'normal, A towards B')
    """
    a = as_shape(a, "a")
    b = as_shape(b, "b")
    if ax is None:
        ax = new_axes((11, 6))
    from matplotlib.lines import Line2D

    t_event = _event_time(impact)
    ts = np.linspace(0.0, t_event, 200)
    for shape, motion, color, name in ((a, motion_a, "tab:red", names[0]),
                                       (b, motion_b, "tab:blue", names[1])):
        draw_shape(ax, shape, color, 0.15, f"{name} at t = 0")
        draw_shape(ax, shape.at(motion, t_event), color, 0.5, f"{name} at t = {t_event:.6g}")
        path = np.array([shape.centroid + motion.pose(t)[0] for t in ts])
        ax.plot(path[:, 0], path[:, 1], "--", color=color, lw=1.0,
                label=f"{name}'s centroid path")
        ax.plot(*shape.centroid, "o", color=color, ms=3)
    if impact.point is not None:
        ax.plot(*impact.point, "*", color="gold", markeredgecolor="black", ms=13, zorder=5,
                label="contact point")
        if impact.normal is not None:
            # Long enough to clear the marker, drawn above it.
            size = 0.3 * max(a.bounding_radius, b.bounding_radius)
            ax.annotate("", xy=xy(impact.point + size * impact.normal), xytext=xy(impact.point),
                        arrowprops={"arrowstyle": "-|>", "color": "black", "lw": 1.8},
                        zorder=6)
            ax.add_line(Line2D([], [], color="black", lw=1.8, marker=">", markevery=[1],
                               label=f"normal, {names[0]} towards {names[1]}"))
    what = (f"collision at t = {impact.time:.6g}" if impact.collides
            else f"no collision ({impact.status.value})")
    ax.set_title(f"{what}, {impact.method} method")
    label_axes(ax)
    ax.autoscale_view()
    legend_outside(ax)
    return ax
