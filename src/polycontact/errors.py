"""Exceptions raised by polycontact.

Every error the library raises on purpose derives from :class:`PolycontactError`.
Errors about bad input are also :class:`ValueError`, so ``except ValueError`` works.
"""

from __future__ import annotations

__all__ = ["PolycontactError", "InvalidShapeError", "InvalidSceneError", "WorkLimitError",
           "NfpTooLargeError", "DepthTooLargeError", "EntranceBlockTooLargeError"]


class PolycontactError(Exception):
    """Root of every error raised on purpose by polycontact."""


class InvalidShapeError(PolycontactError, ValueError):
    """A polygon cannot be used as given; the message says what is wrong and where."""


class InvalidSceneError(PolycontactError, ValueError):
    """A scene (bodies, motions, t_max) is malformed; the message names the key."""


class WorkLimitError(PolycontactError, MemoryError):
    """A call would take more memory or time than one of the limits of
    :mod:`polycontact.limits` allows. It is raised before the work starts, from an
    estimate; the message names the estimate, the limit and how to raise it."""


class NfpTooLargeError(WorkLimitError):
    """The no-fit polygon of these shapes would need more than allowed: more vertices of
    convex sums than ``polycontact.limits.MAX_SUM_VERTICES``, or more edge–sum tests
    to clip them than ``polycontact.limits.MAX_CLIP_TESTS``."""


class DepthTooLargeError(WorkLimitError):
    """The penetration depth of these bodies would need more memory than allowed
    (``polycontact.limits.MAX_SUM_VERTICES`` vertices of convex sums near the
    overlap)."""


class EntranceBlockTooLargeError(WorkLimitError):
    """An entrance block with one component per pair of edges would have more of them
    than ``polycontact.limits.MAX_EDGE_PAIRS``."""
