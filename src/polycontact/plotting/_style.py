"""What every polycontact figure shares: counted nouns, axis labels, a legend outside.

>>> plural(1, "hole"), plural(2, "hole"), plural(0, "exact fit")
('1 hole', '2 holes', '0 exact fits')
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from ..shape import Shape

#: Coordinates are in whatever length unit the caller used (consistent throughout).
LENGTH_LABEL = "(length units)"


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
    from matplotlib.patches import PathPatch
    from matplotlib.path import Path

    verts, codes = [], []
    for loop in shape.loops:
        verts += [*loop.tolist(), loop[0].tolist()]
        codes += [Path.MOVETO] + [Path.LINETO] * (len(loop) - 1) + [Path.CLOSEPOLY]
    ax.add_patch(PathPatch(Path(verts, codes), facecolor=color, edgecolor=color,
                           alpha=alpha, lw=1.0, label=label))


def legend_outside(ax: Any) -> Any:
    """The legend to the right of the axes, where it hides no data."""
    return ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0,
                     fontsize="small", frameon=False)
