"""Reading shapes for the command line: JSON body, GeoJSON or WKT files."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

from ..errors import InvalidShapeError, PolycontactError
from ..shape import Shape


class CommandError(PolycontactError):
    """A problem with what the user gave the command (file, option); exit status 2."""


def read_shape(path: str, *, repair: bool = False) -> Shape:
    """Read one shape from ``path``.

    Accepted: a JSON body ``{"vertices": [[x, y], ...], "holes": [...]}``, a GeoJSON
    Polygon/Feature, or WKT text (``POLYGON ((...))``). Any problem is raised as a
    :class:`CommandError` whose message starts with the file name.
    """
    try:
        text = Path(path).read_text()
    except OSError as exc:
        raise CommandError(f"{path}: cannot read ({exc.strerror})") from None
    try:
        stripped = text.lstrip()
        if stripped.startswith("{"):
            try:
                data = json.loads(text)
            except json.JSONDecodeError as exc:
                raise CommandError(f"{path}: not valid JSON ({exc})") from None
            if "vertices" in data:
                unknown = set(data) - {"vertices", "holes", "name"}
                if unknown:
                    raise CommandError(f"{path}: unknown key {sorted(unknown)[0]!r}")
                return Shape(data["vertices"], data.get("holes", ()), repair=repair)
            if "type" in data:
                return Shape.from_geojson(data, repair=repair)
            raise CommandError(
                f"{path}: expected a body with 'vertices' or a GeoJSON Polygon"
            )
        return Shape.from_wkt(text, repair=repair)
    except (InvalidShapeError, TypeError) as exc:  # TypeError: coordinates not numbers
        raise CommandError(f"{path}: {exc}") from None


def integer_at_least(minimum: int) -> Callable[[str], int]:
    """An argparse ``type`` for an integer option >= ``minimum``."""

    def parse(text: str) -> int:
        import argparse

        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected an integer, got {text!r}") from None
        if value < minimum:
            raise argparse.ArgumentTypeError(f"expected an integer >= {minimum}, got {value}")
        return value

    return parse


def _number_option(text: str, *, zero_allowed: bool) -> float:
    import argparse
    import math

    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not math.isfinite(value) or value < 0 or (value == 0 and not zero_allowed):
        bound = ">= 0" if zero_allowed else "> 0"
        raise argparse.ArgumentTypeError(f"expected a number {bound}, got {text!r}")
    return value


def positive_number(text: str) -> float:
    """argparse type: a finite number > 0 (a time tolerance, a length tolerance)."""
    return _number_option(text, zero_allowed=False)


def non_negative_number(text: str) -> float:
    """argparse type: a finite number >= 0."""
    return _number_option(text, zero_allowed=True)


def index_text(index: int | None) -> str:
    """A vertex, edge or loop number as printed: the file's number, or a note for one
    that ``--repair`` created (it has none in the file).

    >>> index_text(3), index_text(None)
    ('3', '(new, made by --repair)')
    """
    return "(new, made by --repair)" if index is None else str(index)
