"""``polycontact contacts LAYOUT.json``: every contact and penetration of a set of bodies."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

from .. import datasets
from .._json import load_json
from ..errors import InvalidShapeError
from ._errors import CommandError
from ._io import non_negative_number, plotting, save_figure
from ._progress import announced


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
    p.add_argument("layout", metavar="LAYOUT.json",
                   help="the bodies (and container), or a shipped published layout's name: "
                   + ", ".join(datasets.names("layouts")))
    p.add_argument("--tolerance", type=non_negative_number, default=None, metavar="T",
                   help="absolute distance that counts as touching (default: per pair, "
                   "from the bodies' size and coordinates, as classify)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--no-progress", action="store_true",
                   help="no progress bar while a long layout is read (shown only on a "
                   "terminal, from 10 000 bodies)")
    p.add_argument("--plot", metavar="OUT.png",
                   help="draw the bodies with the contacts and penetrations marked")
    p.set_defaults(func=run)


#: Layouts with at least this many bodies show a progress bar while they are read:
#: reading and validating the bodies takes longer than finding their contacts, long
#: enough at this size to be worth showing.
PROGRESS_MIN_BODIES = 10_000


def _progress(entries: list[Any], progress: bool) -> Any:
    """``entries``, wrapped in a tqdm bar on stderr for a long layout read from a
    terminal (tqdm's ``disable=None``: no bar when stderr is not a terminal)."""
    if not progress or len(entries) < PROGRESS_MIN_BODIES:
        return entries
    from tqdm.auto import tqdm

    return tqdm(entries, desc="reading bodies", unit="body", file=sys.stderr, disable=None,
                leave=False)


def read_layout(path: str, progress: bool = False) -> tuple[Any, list[Any], list[str]]:
    """(container Shape or None, bodies, names) of a layout file; errors name the file
    and the entry. ``progress``: a bar on stderr while a long layout is read."""
    from ..shape import as_shape

    try:
        data = load_json(Path(path).read_bytes())
    except OSError as exc:
        raise CommandError(f"{path}: cannot read ({exc.strerror})") from None
    except ValueError as exc:
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
    for k, e in enumerate(_progress(entries, progress)):
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


def text(rep: dict[str, Any]) -> list[str]:
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


def run(args: argparse.Namespace) -> int:
    from ..world import World

    if args.plot:
        plotting()
    container, bodies, names = read_layout(datasets.locate(args.layout, "layouts"),
                                           progress=not args.no_progress)
    world = World(container)
    with announced(f"finding the contacts of {len(bodies)} bodies"):
        world.add_many(bodies, names=names)
        try:
            contacts = world.contacts(tolerance=args.tolerance)
        except ValueError as exc:
            raise CommandError(str(exc)) from None
        rep = contacts.to_dict(names)
    print(json.dumps(rep) if args.json else "\n".join(text(rep)))
    if args.plot:
        save_figure(contacts.plot().figure, args.plot, dpi=110)
    return 0
