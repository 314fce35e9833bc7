"""Batches on a Dask cluster, for :func:`polycontact.classify_many`,
:func:`polycontact.time_of_impact_many` and :func:`polycontact.nfp_table` (and the
public :mod:`polycontact.distributed`): the client a batch runs on, the tasks' sizes,
and their run. Nothing here imports Dask before a client is used.

>>> task_size(1_000_000, 1e-6, 4), current_client() is None
(62500, True)
"""

from __future__ import annotations

import functools
import math
import sys
from collections.abc import Callable, Generator
from typing import Any

__all__ = ["PLUGIN_NAME", "PROBE_ITEMS", "check_chunk_size", "current_client",
           "plugin_name", "run_spans", "task_size", "warm", "worker_plugins"]

#: Prefix of the names under which the warm-up plugins are registered (one per family).
PLUGIN_NAME = "polycontact-warmup"

#: Items of the first task of :func:`run_spans`, which measures the work per item.
PROBE_ITEMS = 256

#: Times :func:`run_spans` runs a task again when the scheduler has forgotten it (a
#: worker that died took what it needed) before the batch fails.
RESUBMITS = 3

Tasks = Callable[[list[tuple[int, int]]], tuple[Any, list[Any]]]


def current_client(client: Any = None) -> Any:
    """The Dask client a batch should run on, or None to run locally.

    ``client`` if given; else, when ``distributed`` is already imported (this never
    imports it), the default client, except inside a Dask task (a batch called from
    a task runs in that task rather than submitting more).
    """
    if client is not None:
        return client
    dist = sys.modules.get("distributed")
    if dist is None:
        return None
    try:
        dist.get_worker()
        return None  # inside a task
    except ValueError:
        pass
    try:
        return dist.default_client()
    except ValueError:
        return None


def warm(client: Any, family: str, call: Callable[[], Any]) -> None:
    """Have every worker of ``client`` run ``call()`` once, when it starts or joins (a
    :class:`polycontact._dask_plugin.WarmupPlugin` named after ``family``, registered
    unless every worker has it): the kernels it runs are loaded (or compiled) then, not
    in a task. Returns when the current workers have run it."""
    have = client.run(worker_plugins)
    name = plugin_name(family)
    if have and all(name in names for names in have.values()):
        return
    from ._dask_plugin import WarmupPlugin

    client.register_plugin(WarmupPlugin(call), name=name)


def plugin_name(family: str) -> str:
    """The name of the warm-up plugin of one kernel family."""
    return f"{PLUGIN_NAME}:{family}"


def worker_plugins(dask_worker: Any) -> list[str]:
    """The names of a worker's plugins (run on the worker by ``client.run``)."""
    return sorted(dask_worker.plugins)


def task_size(count: int, per_item: float, workers: int) -> int:
    """Items per task for ``count`` items of ``per_item`` seconds each on ``workers``
    worker threads: as many tasks as the work holds
    :data:`~polycontact.limits.TASK_SECONDS`, at most four per worker thread, and, where
    there are more tasks than worker threads, whole rounds of one per worker thread (so
    that no thread is left with a last task while the others wait).

    >>> task_size(100_000, 1e-6, 4), task_size(1000, 1e-6, 4), task_size(10**8, 1e-6, 4)
    (50000, 1000, 6250000)
    """
    from .limits import TASK_SECONDS

    tasks = max(1, min(4 * workers, math.floor(count * per_item / TASK_SECONDS + 1e-9)))
    if tasks > workers:
        tasks -= tasks % workers
    return max(1, math.ceil(count / tasks))


def _timed(fn: Callable[..., Any], shared: Any, task: Any, *args: Any) -> tuple[Any, float]:
    """``fn(shared, task, *args)`` and the seconds it took (on the worker)."""
    import time

    t0 = time.perf_counter()
    out = fn(shared, task, *args)
    return out, time.perf_counter() - t0


def run_spans(
    client: Any, fn: Callable[..., Any], count: int, tasks_of: Tasks, *args: Any,
    chunk_size: int | None = None, family: str | None = None,
) -> Generator[tuple[int, int, Any], None, None]:
    """Run ``fn(shared, task, *args)`` over spans of ``range(count)`` as tasks on the
    cluster; yield ``(p0, p1, result)`` for each span as its task finishes.

    ``tasks_of(spans)`` gives ``(shared, tasks)``: what every task of those spans needs
    (sent to every worker once) and each span's own task (sent to one worker, straight
    from here rather than through the scheduler, then the task that reads it submitted:
    the first tasks run while the next ones' data is sent). With ``chunk_size`` the spans
    have that many items; else a first task of :data:`PROBE_ITEMS` items measures the
    work per item and :func:`task_size` sizes the others. With a ``family`` (a name),
    every worker runs that first task once when it starts or joins (:func:`warm`), so
    that it loads the kernels the tasks use before any is timed. A task the scheduler
    cancels (a dead worker held what it needed) is run again, at most
    :data:`RESUBMITS` times. Closing the generator early (an error, or Ctrl-C in the
    caller) cancels the tasks not yet finished.
    """
    from concurrent.futures import CancelledError

    import distributed

    if not count:
        return
    as_completed: Any = distributed.as_completed
    start = min(count, chunk_size or PROBE_ITEMS)
    first_shared, [first] = tasks_of([(0, start)])
    if family is not None:
        warm(client, family, functools.partial(fn, first_shared, first, *args))
    futures: list[Any] = []
    try:
        size = chunk_size or 0
        if not size:
            probe = client.submit(_timed, fn, first_shared, first, *args, pure=False)
            futures.append(probe)
            result, seconds = probe.result()
            yield 0, start, result
            workers = max(1, sum(client.nthreads().values()))
            size = task_size(count - start, seconds / start, workers)
        else:
            start = 0
        spans = [(p, min(count, p + size)) for p in range(start, count, size)]
        if not spans:
            return
        shared, tasks = tasks_of(spans)
        [shared_future] = client.scatter([shared], broadcast=True, hash=False)
        futures.append(shared_future)

        def submit(k: int) -> Any:
            [data] = client.scatter([tasks[k]], hash=False)
            task = client.submit(fn, shared_future, data, *args, pure=False)
            futures.extend((data, task))
            index[task.key] = k, data
            return task

        index: dict[Any, tuple[int, Any]] = {}
        tries = [0] * len(tasks)
        done = as_completed([submit(k) for k in range(len(tasks))])
        for f in done:
            k, data = index.pop(f.key)
            try:
                result = f.result()
            except CancelledError:  # (distributed's FutureCancelledError is one)
                # The scheduler forgot the task: a worker that died took with it what
                # the task needed. Run it again, its data and the shared data sent again.
                tries[k] += 1
                if tries[k] > RESUBMITS:
                    raise
                [shared_future] = client.scatter([shared], broadcast=True, hash=False)
                futures.append(shared_future)
                done.add(submit(k))
                continue
            f.release()
            data.release()
            yield *spans[k], result
    finally:
        client.cancel(futures)


def check_chunk_size(chunk_size: Any) -> None:
    """Refuse a ``chunk_size`` that is not None or a positive integer."""
    if chunk_size is not None and (isinstance(chunk_size, bool) or not isinstance(
            chunk_size, int) or chunk_size < 1):
        raise ValueError(f"chunk_size: expected a positive integer, got {chunk_size!r}")


