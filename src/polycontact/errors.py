"""Exceptions raised by polycontact.

Every error the library raises on purpose derives from :class:`PolycontactError`.
Errors about bad input are also :class:`ValueError`, so ``except ValueError`` works.
"""

from __future__ import annotations

__all__ = ["PolycontactError", "InvalidShapeError", "InvalidSceneError"]


class PolycontactError(Exception):
    """Root of every error raised on purpose by polycontact."""


class InvalidShapeError(PolycontactError, ValueError):
    """A polygon cannot be used as given; the message says what is wrong and where."""


class InvalidSceneError(PolycontactError, ValueError):
    """A scene (bodies, motions, t_max) is malformed; the message names the key."""
