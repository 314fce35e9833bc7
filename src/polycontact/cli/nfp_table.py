"""``polycontact nfp-table INSTANCE.json --out DIR``: build or complete an NFP table."""

from __future__ import annotations

import argparse
import json
import math
import sys
from typing import Any

from .. import datasets
from ._errors import CommandError
from ._io import integer_at_least


def _angle(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected an angle in degrees, got {text!r}") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"expected a finite angle, got {text!r}")
    return value


def add_parser(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "nfp-table",
        help="the no-fit polygons of every pair of pieces of a nesting instance, cached",
        description="Build, or complete, the table of no-fit polygons of every ordered "
        "pair of pieces (a piece with itself included) at every allowed orientation of an "
        "ESICUP instance (JSON, jagua-rs form), reference at the origin. The table is "
        "cached in DIR: a rerun computes only the entries DIR lacks, and Ctrl-C never "
        "leaves a damaged cache. Prints a summary: entries, holes, exact fits, seconds.",
    )
    p.add_argument("instance", metavar="INSTANCE.json",
                   help="ESICUP instance file, or a shipped instance's name: "
                   + ", ".join(datasets.names("esicup")))
    p.add_argument("--out", required=True, metavar="DIR", help="cache directory")
    where = p.add_mutually_exclusive_group()
    where.add_argument("--workers", type=integer_at_least(1), default=None, metavar="N",
                       help="most local processes, started only where they pay "
                       "(work holding the GIL); otherwise threads (default: one per CPU)")
    where.add_argument("--scheduler", metavar="ADDRESS",
                       help="run on this Dask scheduler (needs polycontact[dask])")
    p.add_argument("--orientations", type=_angle, nargs="+", metavar="DEG",
                   help="allowed angles for every piece, instead of the instance's")
    p.add_argument("--chunk-size", type=integer_at_least(1), default=None, metavar="N",
                   help="entries per task and per cache file")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from ..esicup import read_esicup
    from ..nfp_tables import nfp_table

    instance = read_esicup(datasets.locate(args.instance, "esicup"))
    client: Any = None
    if args.scheduler is not None:
        try:
            import distributed
        except ImportError:
            raise CommandError("--scheduler needs Dask: pip install 'polycontact[dask]'"
                               ) from None
        try:
            client = getattr(distributed, "Client")(args.scheduler, timeout="20s")
        except OSError as exc:
            raise CommandError(f"--scheduler: cannot reach {args.scheduler}: {exc}") from None
        print(f"polycontact nfp-table: on {args.scheduler} "
              f"({len(client.nthreads())} workers; dashboard "
              f"{client.dashboard_link})", file=sys.stderr)
    try:
        table = nfp_table(instance, args.orientations, cache=args.out, client=client,
                          progress=not args.no_progress, workers=args.workers,
                          chunk_size=args.chunk_size)
    except KeyboardInterrupt:
        print("polycontact nfp-table: interrupted; the entries computed so far are in "
              f"{args.out}, a rerun completes the table", file=sys.stderr)
        return 130
    except OSError as exc:  # the cache cannot be written (a file, no permission, full)
        where = f" ({exc.filename})" if exc.filename else ""
        raise CommandError(f"--out {args.out}: cannot write the cache: "
                           f"{exc.strerror or exc}{where}") from None
    finally:
        if client is not None:
            client.close()
    s = table.summary()
    if args.json:
        print(json.dumps({"instance": instance.name, "out": args.out, **s}))
        return 0
    print(f"{instance.name}: {s['entries']} entries ({s['distinct']} distinct: "
          f"{s['computed']} computed, {s['loaded']} from the cache), {s['holes']} holes, "
          f"{s['exact_fits']} exact fits, {s['slides']} slides, {s['seconds']:.2f} s")
    return 0
