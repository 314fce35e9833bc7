"""What every polycontact figure shares: counted nouns, axis labels, a legend outside.

>>> plural(1, "hole"), plural(2, "hole"), plural(0, "exact fit")
('1 hole', '2 holes', '0 exact fits')
"""

from __future__ import annotations

from typing import Any

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


def legend_outside(ax: Any) -> Any:
    """The legend to the right of the axes, where it hides no data."""
    return ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0,
                     fontsize="small", frameon=False)
