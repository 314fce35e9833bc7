"""The command line's own error: what the user gave a command (a file, an option, an
environment variable) is wrong.

>>> str(CommandError("a.json: empty file"))
'a.json: empty file'
"""

from __future__ import annotations

from ..errors import PolycontactError

__all__ = ["CommandError"]


class CommandError(PolycontactError):
    """A problem with what the user gave the command (file, option); exit status 2."""
