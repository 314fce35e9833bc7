"""``polycontact warmup``: compile every kernel now (first run only takes long)."""

from __future__ import annotations

import argparse
import time
from typing import Any

from ._progress import progress_line


def add_parser(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "warmup",
        help="compile the kernels now (about a minute on a first run, then cached)",
        description="Compile (or load from the cache) every kernel, one family at a time, "
        "reporting each on stderr. Later runs of any command start at once. The cache "
        "lives in the per-user cache directory (NUMBA_CACHE_DIR overrides it).",
    )
    p.set_defaults(func=run, families=())


def run(args: argparse.Namespace) -> int:
    from ..compiling import FAMILIES, cache_directory, warmup

    t0 = time.perf_counter()
    warmup(FAMILIES, progress=progress_line)
    print(f"kernels ready in {time.perf_counter() - t0:.1f} s (cache: {cache_directory()})")
    return 0
