"""Small inputs shipped with polycontact, to try every job on real data from any install.

Three kinds, one folder each beside this module (where each file comes from, and its
licence, is in the ``README.md`` there):

``esicup``
    Nesting instances of the EURO Special Interest Group on Cutting and Packing
    (``jakobs1``, ``shapes0``), in the JSON form :func:`polycontact.read_esicup` reads.
``layouts``
    The best published layouts of those instances, found by the sparrow solver, in the
    form ``polycontact contacts`` reads.
``scenes``
    A time-of-impact scene (:func:`polycontact.load_scene`): ``paper-case-1``, case 1
    of the paper polycontact implements.

The command line takes these names wherever it takes such a file:
``polycontact nfp-table jakobs1 --out DIR``, ``polycontact contacts jakobs1``,
``polycontact collide paper-case-1``.

Examples
--------
>>> from polycontact import datasets
>>> datasets.names("esicup")
('jakobs1', 'shapes0')
>>> datasets.path("scenes", "paper-case-1").name
'paper-case-1.json'
>>> inst = datasets.instance("jakobs1")
>>> len(inst.pieces), sum(inst.demand), inst.strip_height
(25, 25, 40.004)
>>> world = datasets.layout("jakobs1")
>>> len(world), int((world.contacts().states == 2).sum())
(25, 0)
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from ..esicup import Instance
    from ..scene import Scene
    from ..world import World

__all__ = ["KINDS", "names", "path", "locate", "instance", "layout", "scene"]

#: The kinds of shipped data, each a folder of JSON files beside this module.
KINDS = ("esicup", "layouts", "scenes")

_HERE = Path(__file__).resolve().parent


def _kind(kind: str) -> Path:
    if kind not in KINDS:
        raise ValueError(f"kind: expected one of {', '.join(KINDS)}, got {kind!r}")
    return _HERE / kind


def names(kind: str) -> tuple[str, ...]:
    """The names of the shipped datasets of one kind, sorted.

    Parameters
    ----------
    kind : {"esicup", "layouts", "scenes"}

    Returns
    -------
    tuple of str

    Examples
    --------
    >>> names("scenes")
    ('paper-case-1',)
    """
    return tuple(sorted(p.stem for p in _kind(kind).glob("*.json")))


def path(kind: str, name: str) -> Path:
    """The file of a shipped dataset.

    Parameters
    ----------
    kind : {"esicup", "layouts", "scenes"}
    name : str
        One of :func:`names` ``(kind)``.

    Returns
    -------
    pathlib.Path

    Raises
    ------
    ValueError
        An unknown kind or name; the message lists the shipped ones.

    Examples
    --------
    >>> path("layouts", "shapes0").name
    'shapes0.json'
    >>> path("esicup", "swim")
    Traceback (most recent call last):
    ...
    ValueError: name: no shipped esicup dataset 'swim' (shipped: jakobs1, shapes0)
    """
    shipped = names(kind)
    if name not in shipped:
        raise ValueError(f"name: no shipped {kind} dataset {name!r} "
                         f"(shipped: {', '.join(shipped)})")
    return _kind(kind) / f"{name}.json"


def locate(argument: str, kind: str) -> str:
    """The file a command-line argument names: the argument itself when it is an
    existing file or no shipped name, else the shipped dataset of that kind and name.

    Parameters
    ----------
    argument : str
        A path, or the name of a shipped dataset (``jakobs1``).
    kind : {"esicup", "layouts", "scenes"}

    Returns
    -------
    str

    Examples
    --------
    >>> Path(locate("jakobs1", "esicup")).name
    'jakobs1.json'
    >>> locate("my-instance.json", "esicup")
    'my-instance.json'
    """
    if Path(argument).is_file() or argument not in names(kind):
        return argument
    return str(path(kind, argument))


def instance(name: str) -> Instance:
    """A shipped ESICUP nesting instance, read by :func:`polycontact.read_esicup`.

    Parameters
    ----------
    name : str
        One of :func:`names` ``("esicup")``.

    Returns
    -------
    polycontact.esicup.Instance

    Examples
    --------
    >>> inst = instance("shapes0")
    >>> len(inst.pieces), inst.demand, inst.orientations[0]
    (4, (15, 7, 9, 12), (0.0,))
    """
    from ..esicup import read_esicup

    return read_esicup(path("esicup", name))


def layout(name: str) -> World:
    """A shipped published layout as a :class:`polycontact.World`: its strip as the
    container and every placed piece as a body, named ``item K`` after its piece.

    Parameters
    ----------
    name : str
        One of :func:`names` ``("layouts")``.

    Returns
    -------
    polycontact.World

    Examples
    --------
    >>> world = layout("shapes0")
    >>> len(world), world.body(0).name
    (43, 'item 0')
    """
    import json

    from ..shape import Shape
    from ..world import World

    data = json.loads(path("layouts", name).read_text())
    world = World(Shape(data["container"]))
    world.add_many([p["vertices"] for p in data["placed"]],
                   names=[f"item {p['item']}" for p in data["placed"]])
    return world


def scene(name: str) -> Scene:
    """A shipped time-of-impact scene, read by :func:`polycontact.load_scene`.

    Parameters
    ----------
    name : str
        One of :func:`names` ``("scenes")``.

    Returns
    -------
    polycontact.Scene

    Examples
    --------
    >>> [b.name for b in scene("paper-case-1").bodies]
    ['red', 'blue']
    """
    from ..scene import load_scene

    return load_scene(path("scenes", name))
