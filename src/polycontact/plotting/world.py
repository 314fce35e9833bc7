"""Figure of a World's contacts: the bodies, the container, contacts and penetrations."""

from __future__ import annotations

from typing import Any

from ._style import label_axes, legend_outside, plural

__all__ = ["plot_contacts"]

_COLOURS = {"penetrating": "#d62728", "outside the container": "#ff7f0e", "body": "#9ecae1"}


def _patch(shape: Any, **style: Any) -> Any:
    from matplotlib.patches import PathPatch
    from matplotlib.path import Path

    verts: list[Any] = []
    codes: list[Any] = []
    for loop in shape.loops:
        verts += [*loop.tolist(), loop[0].tolist()]
        codes += [Path.MOVETO] + [Path.LINETO] * (len(loop) - 1) + [Path.CLOSEPOLY]
    return PathPatch(Path(verts, codes), **style)


def plot_contacts(contacts: Any, ax: Any = None) -> Any:
    """Draw the bodies (penetrating ones red, those leaving the container orange), the
    container, contact points (green circles) and penetrations (black crosses).

    Parameters
    ----------
    contacts : Contacts
        As :meth:`polycontact.World.contacts` returns it.
    ax : matplotlib Axes, optional
        Drawn into a new figure when omitted.

    Returns
    -------
    matplotlib Axes

    Examples
    --------
    >>> import polycontact as pc
    >>> w = pc.World()
    >>> sq = [(0, 0), (1, 0), (1, 1), (0, 1)]
    >>> ids = [w.add(sq), w.add(sq, position=(1.5, 0.5))]
    >>> ax = w.contacts().plot()
    >>> ax.get_title()
    '2 bodies: 1 contact, 0 penetrating pairs, 0 outside the container'
    """
    import matplotlib.pyplot as plt

    if ax is None:
        _, ax = plt.subplots(figsize=(11, 7), layout="constrained")
    pen = set(contacts.penetrating.ravel().tolist())
    out = set(contacts.container_ids[contacts.container_states == 2].tolist())
    if contacts.container is not None:
        ax.add_patch(_patch(contacts.container, facecolor="none", edgecolor="0.2", lw=1.5,
                            label="container"))
    labelled = set()
    for i in contacts.ids.tolist():
        kind = ("penetrating" if i in pen else
                "outside the container" if i in out else "body")
        ax.add_patch(_patch(contacts.shape(i), facecolor=_COLOURS[kind], edgecolor="0.3",
                            lw=0.5, alpha=0.6, label=None if kind in labelled else kind))
        labelled.add(kind)
    touch: list[Any] = []
    deep: list[Any] = []
    for k, state in enumerate(contacts.states.tolist()):
        point = contacts.relation(k).point if state else None  # (0: a pair near, apart)
        if point is not None:
            (touch if state == 1 else deep).append(point)
    if touch:
        xs, ys = zip(*touch)
        ax.plot(xs, ys, "o", ms=9, mfc="none", mec="#2ca02c", mew=2, zorder=5,
                label=plural(len(touch), "contact"))
    if deep:
        xs, ys = zip(*deep)
        ax.plot(xs, ys, "x", ms=9, mew=2, color="k", zorder=5,
                label=plural(len(deep), "penetration"))
    ax.autoscale_view()
    label_axes(ax)
    n = len(contacts.ids)
    bodies = "1 body" if n == 1 else f"{n} bodies"
    ax.set_title(f"{bodies}: {plural(len(touch), 'contact')}, "
                 f"{plural(len(deep), 'penetrating pair')}, "
                 f"{len(out)} outside the container")
    legend_outside(ax)
    return ax
