"""The Dask worker plugin of :mod:`polycontact.distributed` (imports ``distributed``)."""

from __future__ import annotations

import asyncio
from collections.abc import Iterable
from typing import Any

from distributed import WorkerPlugin

from .compiling import FAMILIES, warmup

__all__ = ["WarmupPlugin"]


class WarmupPlugin(WorkerPlugin):
    """Loads (or compiles) polycontact's kernels once per worker, when it starts or joins.

    Registered by :func:`polycontact.distributed.ensure_warm`. The warm-up runs in a
    thread, so the worker keeps answering the scheduler while Numba compiles.

    Parameters
    ----------
    families : iterable of str, optional
        Kernel families (keys of :data:`polycontact.compiling.FAMILIES`); default all.
    """

    name = "polycontact-warmup"

    def __init__(self, families: Iterable[str] | None = None) -> None:
        self.families = tuple(FAMILIES if families is None else families)
        unknown = [f for f in self.families if f not in FAMILIES]
        if unknown:
            raise ValueError(f"families: expected names from {', '.join(FAMILIES)}, "
                             f"got {unknown[0]!r}")

    async def setup(self, worker: Any) -> None:
        await asyncio.to_thread(warmup, self.families)
