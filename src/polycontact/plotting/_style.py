"""What every polycontact figure shares: matplotlib imported on demand, a figure that
keeps its labels and legend inside when saved, counted nouns, axis labels, a legend
outside the data.

>>> plural(1, "hole"), plural(2, "hole"), plural(0, "exact fit")
('1 hole', '2 holes', '0 exact fits')
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from ..shape import Shape

#: Coordinates are in whatever length unit the caller used (consistent throughout).
LENGTH_LABEL = "(length units)"


#: The error when matplotlib is missing: one line, saying how to install it.
NO_MATPLOTLIB = ("drawing needs matplotlib, which is not installed: "
                 "pip install 'polycontact[plot]'")


def pyplot() -> Any:
    """``matplotlib.pyplot``, imported now; ``ImportError`` (:data:`NO_MATPLOTLIB`) when
    matplotlib is not installed (it is the optional ``plot`` extra)."""
    try:
        import matplotlib.pyplot as plt
    except ImportError:
        raise ImportError(NO_MATPLOTLIB) from None
    return plt


def new_axes(figsize: tuple[float, float]) -> Axes:
    """Axes of a new figure of ``figsize`` inches whose layout makes room for the titles,
    the axis labels and a legend outside the axes (``layout="constrained"``), so that
    ``ax.figure.savefig(...)`` clips none of them."""
    ax: Axes = pyplot().subplots(figsize=figsize, layout="constrained")[1]
    return ax


def shape_patch(shape: Any, **style: Any) -> Any:
    """A matplotlib ``PathPatch`` of a :class:`~polycontact.Shape`, holes left open;
    ``style`` goes to the patch (``facecolor``, ``alpha``, ``label``...)."""
    from matplotlib.patches import PathPatch
    from matplotlib.path import Path

    verts: list[Any] = []
    codes: list[Any] = []
    for loop in shape.loops:
        verts += [*loop.tolist(), loop[0].tolist()]
        codes += [Path.MOVETO] + [Path.LINETO] * (len(loop) - 1) + [Path.CLOSEPOLY]
    return PathPatch(Path(verts, codes), **style)


def xy(p: Any) -> tuple[float, float]:
    """A point (an array of two numbers) as the ``(x, y)`` tuple matplotlib's
    ``annotate`` takes."""
    return float(p[0]), float(p[1])


def plural(n: int, noun: str) -> str:
    """``"1 hole"``, ``"2 holes"``: the count with its noun in the right number."""
    return f"{n} {noun}" if n == 1 else f"{n} {noun}s"


def label_axes(ax: Any) -> None:
    """x and y axis labels with the (caller's) length unit, equal aspect."""
    ax.set_xlabel(f"x {LENGTH_LABEL}")
    ax.set_ylabel(f"y {LENGTH_LABEL}")
    ax.set_aspect("equal")


def draw_shape(ax: Any, shape: Shape, color: str, alpha: float, label: str | None) -> None:
    """Fill every loop of ``shape`` (holes left open) in ``color`` on ``ax``."""
    ax.add_patch(shape_patch(shape, facecolor=color, edgecolor=color, alpha=alpha, lw=1.0,
                             label=label))


def legend_outside(ax: Any, handles: Any = None) -> Any:
    """The legend to the right of the axes, where it hides no data, when the figure's
    layout makes room for it (the figures :func:`new_axes` makes); inside the axes, where
    it hides the least, in a figure without a layout engine (Axes the caller made with
    ``plt.subplots()``), whose edge would cut a legend outside. ``handles``: the
    entries, when not the labelled artists of ``ax``."""
    more = {} if handles is None else {"handles": handles}
    if ax.figure.get_layout_engine() is None:
        return ax.legend(loc="best", fontsize="small", framealpha=0.8, **more)
    return ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0,
                     fontsize="small", frameon=False, **more)
