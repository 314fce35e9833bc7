"""The ``polycontact`` command.

Each subcommand lives in its own module of this package and provides
``add_parser(subparsers)``, which registers the subcommand and sets ``func`` to a
function taking the parsed arguments and returning an exit status. Errors about the
user's input are raised as :class:`CommandError` (or a :class:`PolycontactError`) and
printed as one line on stderr with exit status 2, never as a traceback.
"""

from __future__ import annotations

import argparse
import importlib
import sys

from ..errors import PolycontactError
from ._io import CommandError

_SUBCOMMANDS = ("classify", "entrance_block", "collide", "nfp")


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="polycontact",
        description="Contact, time of impact and no-fit polygons of 2D polygons.",
    )
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    for name in _SUBCOMMANDS:
        importlib.import_module(f".{name}", __name__).add_parser(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except (CommandError, PolycontactError) as exc:
        print(f"polycontact {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except BrokenPipeError:
        return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
