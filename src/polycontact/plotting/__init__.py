"""Figures (matplotlib, imported only when a plot function is called).

- :func:`plot_entrance_block`: the two bodies, the three families of entrance-block
  components and the reference point (like the paper's Fig. 5).
- :func:`plot_impact`: both bodies at t = 0 and at the impact, centroid paths, contact.
- :func:`plot_nfp`: B, A at one placement, the no-fit polygon with holes and exact fits.
- :func:`plot_inner_fit`: the container, A at one placement, where A fits inside.
- :func:`plot_relation`: two bodies where they stand, the witness point and the normal.
- :func:`plot_contacts`: the bodies of a World, its contacts and penetrations.
- :func:`plot_world`: the bodies of a World where they stand, with their ids, and its
  container.
- :func:`plot_shape`: one shape, its holes, optionally its vertex numbers.

Every result draws itself too: ``.plot(ax=None)`` on :class:`~polycontact.Relation`,
:class:`~polycontact.Impact`, :class:`~polycontact.EntranceBlock`,
:class:`~polycontact.NoFitPolygon` and :class:`~polycontact.Contacts`, and on
:class:`~polycontact.Shape` and :class:`~polycontact.World`, returns the Axes. A figure
made here lays itself out so that ``ax.figure.savefig(...)`` keeps the titles, labels
and legend. Without matplotlib (the optional ``plot`` extra), drawing raises
``ImportError`` saying ``pip install 'polycontact[plot]'``.
"""

from __future__ import annotations

import importlib
from typing import Any

_LAZY = {
    "plot_entrance_block": "entrance_block",
    "plot_impact": "impact",
    "plot_nfp": "nfp",
    "plot_inner_fit": "nfp",
    "plot_shape": "shape",
    "plot_relation": "relation",
    "plot_contacts": "world",
    "plot_world": "world",
}
__all__ = list(_LAZY)


def __getattr__(name: str) -> Any:
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'polycontact.plotting' has no attribute {name!r}")
    return getattr(importlib.import_module(f".{module}", __name__), name)
