"""The ``polycontact`` command.

Each subcommand lives in its own module of this package and provides
``add_parser(subparsers)``, which registers the subcommand and sets ``func`` to a
function taking the parsed arguments and returning an exit status. Errors about the
user's input are raised as :class:`CommandError` (or a :class:`PolycontactError`, or
the ``ValueError`` or ``TypeError`` with which the library refuses an argument: every
argument comes from the user's files and options) and printed as one line on stderr
with exit status 2, never as a traceback.

A command compiles only the kernels its job calls, on their first call (a first run),
and the library's compile notice says so once on stderr, never stdout, so ``--json``
output stays parseable (see :mod:`polycontact.compiling`).
"""

from __future__ import annotations

import argparse
import importlib
import sys

from .. import __version__
from ..errors import PolycontactError
from ._errors import CommandError

_SUBCOMMANDS = ("classify", "entrance_block", "collide", "nfp", "nfp_table", "contacts",
                "warmup")



def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="polycontact",
        description="Contact, time of impact and no-fit polygons of 2D polygons.",
    )
    parser.add_argument("--version", action="version", version=f"polycontact {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name in _SUBCOMMANDS:
        importlib.import_module(f".{name}", __name__).add_parser(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except (CommandError, PolycontactError, ValueError, TypeError) as exc:
        message = " ".join(str(exc).split())  # one line
        print(f"polycontact {args.command}: error: {message}", file=sys.stderr)
        return 2
    except BrokenPipeError:
        return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
