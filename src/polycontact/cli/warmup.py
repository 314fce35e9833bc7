"""``polycontact warmup``: compile every kernel now (first run only takes long)."""

from __future__ import annotations

import argparse
import logging
import os
import time
from typing import Any

from ._io import integer_at_least
from ._progress import progress_line


def add_parser(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "warmup",
        help="compile the kernels now (a minute or two on a first run, then cached)",
        description="Compile (or load from the cache) every kernel, one family at a time "
        "in each of several processes, reporting each family on stderr as it ends. Later "
        "runs of any command start at once. The cache lives in the per-user cache "
        "directory (NUMBA_CACHE_DIR overrides it).",
    )
    p.add_argument("--processes", type=integer_at_least(1), default=os.cpu_count() or 1,
                   metavar="N", help="compile in N processes at once (default: one per "
                   "CPU; 1: in this one)")
    p.set_defaults(func=run, families=())


def run(args: argparse.Namespace) -> int:
    from ..compiling import FAMILIES, cache_directory, warmup

    logging.getLogger("polycontact").setLevel(logging.ERROR)  # (the lines below report)
    t0 = time.perf_counter()
    warmup(FAMILIES, progress=progress_line, processes=args.processes)
    print(f"kernels ready in {time.perf_counter() - t0:.1f} s (cache: {cache_directory()})")
    return 0
