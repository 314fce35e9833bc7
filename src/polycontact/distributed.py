"""Running polycontact's batches on a Dask cluster.

Dask is an optional extra (``pip install "polycontact[dask]"``): this module imports
``distributed`` only inside its functions, and nothing else in polycontact imports it.

:func:`polycontact.classify_many`, :func:`polycontact.time_of_impact_many` and
:func:`polycontact.nfp_table` take ``client=``: the same call, with the same checks in
the calling process, runs its work as tasks on the cluster, and the result is identical
to the local one. This module offers what they share (from
:mod:`polycontact._cluster`), for other batches:

- :func:`current_client` is the client a batch runs on: the one given, else the
  default client of this process when ``distributed`` is already imported and one is
  set (``Client(...)`` or ``with Client(...)``), never one inside a Dask task.
- ``WarmupPlugin`` (registered by :func:`ensure_warm`, and by the batches for the
  kernels they run) compiles or loads the kernels once per worker, when the worker
  starts or joins, not once per task.
- :func:`run_spans` cuts ``range(count)`` into tasks: a first task measures the work per
  item, the others get at least :data:`~polycontact.limits.TASK_SECONDS` of work each,
  at most four per worker thread, in whole rounds of one per worker thread
  (:func:`task_size`); what every task needs is sent to
  every worker once, and the results come back as they finish.
- :func:`map_batches` calls any function on aligned slices of sequences that way.

Examples
--------
Without a client everything runs locally:

>>> from polycontact import distributed
>>> distributed.map_batches(len, list(range(10)), chunk_size=4)
[4, 4, 2]
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Iterable, Iterator
from typing import Any

from ._cluster import (PROBE_ITEMS, check_chunk_size, current_client, plugin_name, run_spans,
                       task_size, warm, worker_plugins)

__all__ = [
    "WarmupPlugin",
    "current_client",
    "ensure_warm",
    "map_batches",
    "plugin_name",
    "run_spans",
    "task_size",
    "worker_plugins",
    "PROBE_ITEMS",
]


def __getattr__(name: str) -> Any:
    # WarmupPlugin subclasses distributed.WorkerPlugin: loaded (with Dask) on first use
    if name == "WarmupPlugin":
        from ._dask_plugin import WarmupPlugin

        return WarmupPlugin
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def ensure_warm(client: Any, families: Iterable[str] | None = None) -> None:
    """Have every worker of ``client`` compile or load the kernels of each family (all by
    default) when it starts or joins: one ``WarmupPlugin`` per family, named
    ``polycontact-warmup:FAMILY`` (:func:`plugin_name`), registered unless every worker
    has it, so a batch warms only the kernels it runs. Workers that join later get the
    plugins from the scheduler. Returns when the current workers have loaded the
    kernels."""
    from .compiling import FAMILIES, warmup

    for family in FAMILIES if families is None else families:
        if family not in FAMILIES:
            raise ValueError(f"families: expected names from {', '.join(FAMILIES)}, "
                             f"got {family!r}")
        warm(client, family, functools.partial(warmup, [family]))


def _call_on_slices(
    _: Any, task: tuple[Any, ...], fn: Callable[..., Any], kwargs: dict[str, Any]
) -> Any:
    return fn(*task, **kwargs)


def map_batches(
    fn: Callable[..., Any],
    *sequences: Any,
    client: Any = None,
    chunk_size: int | None = None,
    families: Iterable[str] | None = None,
    **kwargs: Any,
) -> list[Any]:
    """``[fn(*slices, **kwargs) for each slice]`` over aligned sequences, on Dask.

    The sequences (lists, arrays: anything sliceable, all of one length) are cut into
    consecutive slices; each call is one task (:func:`run_spans`). Without a client
    (see :func:`current_client`) the calls run here, one after the other.

    Parameters
    ----------
    fn : callable
        A module-level function (it is pickled to the workers).
    *sequences : sliceable
        Aligned inputs, e.g. shapes_a, shapes_b.
    client : dask.distributed.Client, optional
    chunk_size : int, optional
        Items per task; default sized by :func:`run_spans` from a first task (here,
        without a client: every item in one call).
    families : iterable of str, optional
        Kernel families the workers warm up (default all).
    **kwargs
        Passed to every call.

    Returns
    -------
    list
        The results of the calls, in the order of the slices.

    Examples
    --------
    >>> map_batches(sum, [1, 2, 3, 4, 5], chunk_size=2)
    [3, 7, 5]
    """
    if not sequences:
        raise ValueError("sequences: expected at least one sequence to split")
    count = len(sequences[0])
    for k, s in enumerate(sequences[1:], 1):
        if len(s) != count:
            raise ValueError(f"sequences: argument {k} has {len(s)} items, the first {count}")
    check_chunk_size(chunk_size)
    client = current_client(client)
    if client is None:
        size = chunk_size or max(count, 1)
        return [fn(*(s[p:p + size] for s in sequences), **kwargs)
                for p in range(0, count, size)]

    def tasks_of(spans: list[tuple[int, int]]) -> tuple[Any, list[Any]]:
        return None, [tuple(s[p0:p1] for s in sequences) for p0, p1 in spans]

    ensure_warm(client, families)
    parts: dict[int, Any] = {}
    with _closing(run_spans(client, _call_on_slices, count, tasks_of, fn, kwargs,
                            chunk_size=chunk_size)) as results:
        for p0, _, r in results:
            parts[p0] = r
    return [parts[p] for p in sorted(parts)]


def _closing(gen: Iterator[Any]) -> Any:
    from contextlib import closing

    return closing(gen)


