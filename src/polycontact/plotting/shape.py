"""Figure of one shape: its solid, its loops, optionally its vertex numbers."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from ._style import label_axes, legend_outside, new_axes, plural, shape_patch

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from ..shape import Shape

__all__ = ["plot_shape"]


def plot_shape(shape: Shape, ax: Axes | None = None, *, numbers: bool = False,
               **style: Any) -> Axes:
    """Draw a shape: its solid filled, holes left open, every loop outlined.

    Parameters
    ----------
    shape : Shape
    ax : matplotlib Axes, optional
        Drawn into a new figure when omitted.
    numbers : bool, default False
        Write each vertex's number next to it, in the caller's numbering (the one
        features and the command line report): ``i`` for vertex ``i`` of the outer loop,
        ``k:i`` for vertex ``i`` of loop ``k`` (hole ``k - 1``); ``new`` for a vertex that
        ``repair=True`` made.
    **style
        Passed to the matplotlib ``PathPatch``, over the defaults (``facecolor``,
        ``edgecolor``, ``alpha``, ``linewidth``); a ``label`` adds a legend.

    Returns
    -------
    matplotlib Axes

    Examples
    --------
    >>> import polycontact as pc
    >>> from polycontact.plotting import plot_shape
    >>> frame = pc.Shape([(0, 0), (4, 0), (4, 4), (0, 4)], [[(1, 1), (1, 2), (2, 1)]])
    >>> ax = plot_shape(frame, numbers=True)
    >>> ax.get_title(), [t.get_text() for t in ax.texts][:5]
    ('4 vertices, 1 hole, area 15.5', ['0', '1', '2', '3', '1:0'])
    """
    if ax is None:
        ax = new_axes((7, 6))
    look = {"facecolor": "tab:blue", "edgecolor": "navy", "alpha": 0.45, "linewidth": 1.2}
    ax.add_patch(shape_patch(shape, **{**look, **style}))
    if numbers:
        for k, loop in enumerate(shape.loops):
            kk = shape.input_loop(k)
            for i, (x, y) in enumerate(loop.tolist()):
                v = shape.input_vertex(k, i)
                text = "new" if v is None or kk is None else (
                    str(v) if kk == 0 else f"{kk}:{v}")
                ax.annotate(text, (x, y), xytext=(3, 3), textcoords="offset points",
                            fontsize="small")
    label_axes(ax)
    ax.autoscale_view()
    ax.set_title(f"{len(shape.exterior)} vertices, {plural(len(shape.holes), 'hole')}, "
                 f"area {shape.area:.6g}")
    if style.get("label"):
        legend_outside(ax)
    return ax
