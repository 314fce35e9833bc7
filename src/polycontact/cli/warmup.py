"""``polycontact warmup``: compile every kernel now (first run only takes long)."""

from __future__ import annotations

import argparse
import sys
import time
from typing import Any


def add_parser(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "warmup",
        help="compile the kernels now (about a minute on a first run, then cached)",
        description="Compile (or load from the cache) every kernel, one family at a time, "
        "reporting each on stderr. Later runs of any command start at once. The cache "
        "lives in the per-user cache directory (NUMBA_CACHE_DIR overrides it).",
    )
    p.set_defaults(func=run, families=())


def progress_line(family: str, k: int, n: int, seconds: float | None) -> None:
    """One stderr line per stage of :func:`polycontact.compiling.warmup`."""
    if seconds is None:
        print(f"  [{k}/{n}] {family} ...", end="", file=sys.stderr, flush=True)
    else:
        print(f" {seconds:.1f} s", file=sys.stderr, flush=True)


def run(args: argparse.Namespace) -> int:
    from ..compiling import FAMILIES, cache_directory, warmup

    t0 = time.perf_counter()
    warmup(FAMILIES, progress=progress_line)
    print(f"kernels ready in {time.perf_counter() - t0:.1f} s (cache: {cache_directory()})")
    return 0
