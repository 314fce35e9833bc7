"""Reading shapes for the command line: JSON body, GeoJSON, WKT or WKB files."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

from ..errors import InvalidShapeError
from ..shape import Shape, as_shape
from ._errors import CommandError
from ._progress import announced


#: The forms of a body file, as messages and help texts name them.
BODY_FILE_FORMS = ('JSON {"vertices": [[x, y], ...], "holes": [...]}, a JSON list '
                   "[[x, y], ...], GeoJSON, WKT or WKB")


def read_shape(path: str, *, repair: bool = False) -> Shape:
    """Read one shape from ``path``.

    Accepted: every text or binary form of a shape (:func:`polycontact.shape.as_shape`):
    a JSON mapping ``{"vertices": [[x, y], ...], "holes": [...]}``, a bare JSON list of vertices
    ``[[x, y], ...]``, a GeoJSON Polygon/Feature, WKT text (``POLYGON ((...))``) or WKB
    (binary or hex). Any problem is raised as a :class:`CommandError` whose message
    starts with the file name.
    """
    try:
        raw = Path(path).read_bytes()
    except OSError as exc:
        raise CommandError(f"{path}: cannot read ({exc.strerror})") from None
    if not raw.strip():
        raise CommandError(f"{path}: empty file (expected a body: {BODY_FILE_FORMS})")
    data: str | bytes = raw  # binary WKB starts with its byte-order byte, 0 or 1
    if raw[:1] not in (b"\x00", b"\x01"):
        try:
            data = raw.decode("utf-8")
        except UnicodeDecodeError:
            pass
    try:
        with announced(f"reading {path} ({len(raw):,} bytes)"):
            return as_shape(data, str(path), repair=repair)
    except (InvalidShapeError, TypeError) as exc:  # TypeError: coordinates not numbers
        raise CommandError(str(exc)) from None


#: What ``--plot`` says when matplotlib is missing (it is the ``plot`` extra).
NO_MATPLOTLIB = "--plot needs matplotlib: pip install 'polycontact[plot]'"


def plotting() -> None:
    """Make sure a ``--plot`` can be drawn, before anything is computed: matplotlib is
    there (else a :class:`CommandError` that says how to install it), with the
    non-interactive backend."""
    try:
        import matplotlib
    except ImportError:
        raise CommandError(NO_MATPLOTLIB) from None
    matplotlib.use("Agg")


def save_figure(figure: Any, path: str, dpi: int = 120) -> None:
    """Write a matplotlib ``figure`` to the image file ``path`` (the format from its
    extension) and close it; a :class:`CommandError` naming the file if it cannot be
    written."""
    import matplotlib.pyplot as plt

    try:
        figure.savefig(path, dpi=dpi, bbox_inches="tight")
    except OSError as exc:
        raise CommandError(f"{path}: cannot write the plot ({exc.strerror or exc})") from None
    except ValueError as exc:  # an image format matplotlib does not know
        raise CommandError(f"{path}: cannot write the plot ({exc})") from None
    finally:
        plt.close(figure)


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
