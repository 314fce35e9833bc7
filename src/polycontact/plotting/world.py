"""Figures of a World: its bodies and container (:func:`plot_world`), and its contacts
and penetrations (:func:`plot_contacts`)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from ._style import label_axes, legend_outside, new_axes, plural, shape_patch, xy

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from ..world import Contacts, World

__all__ = ["plot_contacts", "plot_world"]

#: A World drawn with more bodies than this shows no ids unless asked.
LABELLED_BODIES = 100

_COLOURS = {"penetrating": "#d62728", "outside the container": "#ff7f0e", "body": "#9ecae1"}


def plot_contacts(contacts: Contacts, ax: Axes | None = None) -> Axes:
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
    if ax is None:
        ax = new_axes((11, 7))
    pen = set(contacts.penetrating_pairs.ravel().tolist())
    out = set(contacts.container_ids[contacts.container_states == 2].tolist())
    if contacts.container is not None:
        ax.add_patch(shape_patch(contacts.container, facecolor="none", edgecolor="0.2", lw=1.5,
                            label="container"))
    labelled = set()
    for i in contacts.ids.tolist():
        kind = ("penetrating" if i in pen else
                "outside the container" if i in out else "body")
        ax.add_patch(shape_patch(contacts.shape(i), facecolor=_COLOURS[kind], edgecolor="0.3",
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
    ax.set_title(f"{_bodies(len(contacts.ids))}: {plural(len(touch), 'contact')}, "
                 f"{plural(len(deep), 'penetrating pair')}, "
                 f"{len(out)} outside the container")
    legend_outside(ax)
    return ax


def _bodies(n: int) -> str:
    return "1 body" if n == 1 else f"{n} bodies"


def plot_world(world: World, ax: Axes | None = None, *, labels: bool | None = None) -> Axes:
    """Draw the bodies of a World where they stand and its container (no contacts are
    computed: :meth:`World.contacts` and its ``plot`` draw those).

    Parameters
    ----------
    world : World
    ax : matplotlib Axes, optional
        Drawn into a new figure when omitted.
    labels : bool, optional
        Write each body's id (and name) at its centroid; by default when the world has
        at most :data:`LABELLED_BODIES` bodies.

    Returns
    -------
    matplotlib Axes

    Examples
    --------
    >>> import polycontact as pc
    >>> w = pc.World(container=[(0, 0), (4, 0), (4, 2), (0, 2)])
    >>> ids = [w.add([(0, 0), (1, 0), (1, 1), (0, 1)], (1, 1), name="a"),
    ...        w.add([(0, 0), (1, 0), (0, 1)], (3, 1))]
    >>> ax = plot_world(w)
    >>> ax.get_title(), [t.get_text() for t in ax.texts]
    ('2 bodies, in a container', ['0 (a)', '1'])
    """
    if ax is None:
        ax = new_axes((11, 7))
    bodies = world.bodies()
    if world.container is not None:
        ax.add_patch(shape_patch(world.container, facecolor="none", edgecolor="0.2", lw=1.5,
                                 label="container"))
    for k, body in enumerate(bodies):
        ax.add_patch(shape_patch(body.shape, facecolor=_COLOURS["body"], edgecolor="0.3",
                                 lw=0.5, alpha=0.6, label="bodies" if k == 0 else None))
    if labels or (labels is None and len(bodies) <= LABELLED_BODIES):
        for body in bodies:
            text = str(body.id) if body.name is None else f"{body.id} ({body.name})"
            ax.annotate(text, xy(body.shape.centroid), ha="center", va="center",
                        fontsize="small")
    ax.autoscale_view()
    label_axes(ax)
    inside = ", in a container" if world.container is not None else ""
    ax.set_title(f"{_bodies(len(bodies))}{inside}")
    if bodies or world.container is not None:
        legend_outside(ax)
    return ax
