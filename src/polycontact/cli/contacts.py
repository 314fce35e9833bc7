"""``polycontact contacts LAYOUT.json``: every contact and penetration of a set of bodies."""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

from ..errors import InvalidShapeError
from ._io import CommandError, non_negative_number

_STATE = {1: "contact", 2: "penetrating"}
_CONTAINER_STATE = {1: "touches the boundary", 2: "outside"}


def add_parser(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "contacts",
        help="every pair of bodies in contact or penetrating in a layout",
        description="List every pair of bodies of a layout that touch or penetrate, and "
        "the bodies that touch or leave the container. LAYOUT.json is a nesting layout "
        '{"container": [[x, y], ...], "placed": [{"item": k, "vertices": [[x, y], ...]}]} '
        "(the form of the published layouts; the container is optional), or "
        '{"container": ..., "bodies": [{"name": ..., "vertices": ..., "holes": ...}]}.',
    )
    p.add_argument("layout", metavar="LAYOUT.json", help="the bodies (and container)")
    p.add_argument("--tolerance", type=non_negative_number, default=None, metavar="T",
                   help="absolute distance that counts as touching (default: per pair, "
                   "from the bodies' size and coordinates, as classify)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--plot", metavar="OUT.png",
                   help="draw the bodies with the contacts and penetrations marked")
    p.set_defaults(func=run)


def read_layout(path: str) -> tuple[Any, list, list[str]]:
    """(container Shape or None, bodies, names) of a layout file; errors name the file
    and the entry."""
    from ..bodies import as_shape

    try:
        data = json.loads(Path(path).read_text())
    except OSError as exc:
        raise CommandError(f"{path}: cannot read ({exc.strerror})") from None
    except json.JSONDecodeError as exc:
        raise CommandError(f"{path}: not valid JSON ({exc})") from None
    if not isinstance(data, dict) or not ("placed" in data or "bodies" in data):
        raise CommandError(f"{path}: expected an object with 'placed' or 'bodies'")
    entries = data.get("placed", data.get("bodies"))
    if not isinstance(entries, list):
        raise CommandError(f"{path}: 'placed'/'bodies' must be a list")
    container = None
    try:
        if data.get("container") is not None:
            container = as_shape(data["container"], f"{path}: container")
    except (InvalidShapeError, TypeError) as exc:
        raise CommandError(str(exc)) from None
    bodies, names = [], []
    for k, e in enumerate(entries):
        where = f"{path}: body {k}"
        if not isinstance(e, dict) or "vertices" not in e:
            raise CommandError(f"{where}: expected an object with 'vertices'")
        try:
            bodies.append(as_shape({"vertices": e["vertices"], "holes": e.get("holes", [])},
                                   where))
        except (InvalidShapeError, TypeError) as exc:
            raise CommandError(str(exc)) from None
        label = e.get("name", e.get("item"))
        names.append(f"{k}" if label is None else f"{k} ({label})")
    return container, bodies, names


def report(world: Any, contacts: Any, names: list[str]) -> dict:
    """The contacts as a JSON-ready dict (the object printed by ``--json``)."""
    pairs = []
    for k, (i, j) in enumerate(contacts.pairs.tolist()):
        point = contacts.relation(k).point
        pairs.append({"a": i, "b": j, "names": [names[i], names[j]],
                      "state": _STATE[int(contacts.states[k])],
                      "point": None if point is None else [float(v) for v in point]})
    container = [{"body": int(i), "name": names[int(i)],
                  "state": "contact" if s == 1 else "outside"}
                 for i, s in zip(contacts.container_ids.tolist(),
                                 contacts.container_states.tolist())]
    return {"bodies": len(world), "container": world.container is not None,
            "contacts": pairs, "container_contacts": container}


def text(rep: dict) -> list[str]:
    pen = sum(p["state"] == "penetrating" for p in rep["contacts"])
    lines = [f"bodies: {rep['bodies']}" + (", in a container" if rep["container"] else ""),
             f"pairs: {len(rep['contacts'])} ({len(rep['contacts']) - pen} in contact, "
             f"{pen} penetrating)"]
    for p in rep["contacts"]:
        at = "" if p["point"] is None else f" at ({p['point'][0]:.9g}, {p['point'][1]:.9g})"
        lines.append(f"  {p['names'][0]} and {p['names'][1]}: {p['state']}{at}")
    if rep["container"]:
        out = sum(c["state"] == "outside" for c in rep["container_contacts"])
        lines.append(f"container: {out} outside or crossing its boundary, "
                     f"{len(rep['container_contacts']) - out} touching it")
        for c in rep["container_contacts"]:
            lines.append(f"  {c['name']}: "
                         f"{'outside' if c['state'] == 'outside' else 'touches the boundary'}")
    return lines


def plot(world: Any, rep: dict, path: str) -> None:
    """Draw the bodies, penetrating bodies filled, contact points and penetrations marked."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import PathPatch
    from matplotlib.path import Path as MPath

    from ..plotting._style import label_axes, legend_outside, plural

    def patch(shape: Any, **kw: Any) -> PathPatch:
        verts, codes = [], []
        for loop in shape.loops:
            verts += [*loop.tolist(), loop[0].tolist()]
            codes += [MPath.MOVETO] + [MPath.LINETO] * (len(loop) - 1) + [MPath.CLOSEPOLY]
        return PathPatch(MPath(verts, codes), **kw)

    pen = {i for p in rep["contacts"] if p["state"] == "penetrating" for i in (p["a"], p["b"])}
    out = {c["body"] for c in rep["container_contacts"] if c["state"] == "outside"}
    fig, ax = plt.subplots(figsize=(11, 7))
    if world.container is not None:
        ax.add_patch(patch(world.container, facecolor="none", edgecolor="0.2", lw=1.5,
                           label="container"))
    labelled = set()
    for body in world.bodies():
        kind = ("penetrating" if body.id in pen else
                "outside the container" if body.id in out else "body")
        color = {"penetrating": "#d62728", "outside the container": "#ff7f0e",
                 "body": "#9ecae1"}[kind]
        ax.add_patch(patch(body.shape, facecolor=color, edgecolor="0.3", lw=0.5, alpha=0.6,
                           label=None if kind in labelled else f"{kind}"))
        labelled.add(kind)
    touch = [p["point"] for p in rep["contacts"] if p["state"] == "contact" and p["point"]]
    deep = [p["point"] for p in rep["contacts"] if p["state"] == "penetrating" and p["point"]]
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
    bodies = "1 body" if rep["bodies"] == 1 else f"{rep['bodies']} bodies"
    ax.set_title(f"{bodies}: {plural(len(touch), 'contact')}, "
                 f"{plural(len(deep), 'penetrating pair')}, "
                 f"{len(out)} outside the container")
    legend_outside(ax)
    fig.tight_layout()
    try:
        fig.savefig(path, dpi=110)
    except (OSError, ValueError) as exc:
        raise CommandError(f"{path}: cannot write the plot ({exc})") from None
    finally:
        plt.close(fig)


def run(args: argparse.Namespace) -> int:
    from ..world import World

    container, bodies, names = read_layout(args.layout)
    world = World(container)
    world.add_many(bodies, names=names)
    try:
        contacts = world.contacts(args.tolerance)
    except ValueError as exc:
        raise CommandError(str(exc)) from None
    rep = report(world, contacts, names)
    print(json.dumps(rep) if args.json else "\n".join(text(rep)))
    if args.plot:
        plot(world, rep, args.plot)
    return 0
