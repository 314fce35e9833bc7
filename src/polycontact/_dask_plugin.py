"""The Dask worker plugin of :mod:`polycontact.distributed` (imports ``distributed``)."""

from __future__ import annotations

import asyncio
from collections.abc import Callable
from typing import Any

from distributed import WorkerPlugin

__all__ = ["WarmupPlugin"]


class WarmupPlugin(WorkerPlugin):
    """Runs ``warm()`` once per worker, when it starts or joins: a call that loads (or
    compiles) the kernels a batch uses, so that no task does.

    Registered by :func:`polycontact.distributed.ensure_warm` (``warm``: the warm-up of a
    kernel family) and by the batches (a first task of theirs). The call runs in a
    thread, so the worker keeps answering the scheduler while Numba compiles.

    Parameters
    ----------
    warm : callable
        Called without arguments; picklable (it is sent to the workers).
    """

    name = "polycontact-warmup"

    def __init__(self, warm: Callable[[], Any]) -> None:
        self.warm = warm

    async def setup(self, worker: Any) -> None:
        await asyncio.to_thread(self.warm)
