"""Exceptions raised by polycontact.

Every error the library raises on purpose derives from :class:`PolycontactError`.
Errors about bad input are also :class:`ValueError`, so ``except ValueError`` works.
"""

from __future__ import annotations

__all__ = ["PolycontactError", "InvalidShapeError", "InvalidSceneError", "NfpTooLargeError",
           "DepthTooLargeError"]


class PolycontactError(Exception):
    """Root of every error raised on purpose by polycontact."""


class InvalidShapeError(PolycontactError, ValueError):
    """A polygon cannot be used as given; the message says what is wrong and where."""


class InvalidSceneError(PolycontactError, ValueError):
    """A scene (bodies, motions, t_max) is malformed; the message names the key."""


class NfpTooLargeError(PolycontactError, MemoryError):
    """The no-fit polygon of these shapes would need more memory than allowed
    (``polycontact.limits.MAX_SUM_VERTICES`` vertices of convex sums)."""


class DepthTooLargeError(PolycontactError, MemoryError):
    """The penetration depth of these bodies would need more memory than allowed
    (``polycontact.limits.MAX_SUM_VERTICES`` vertices of convex sums)."""
