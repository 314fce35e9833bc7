"""The threading policy of every parallel call (stated for users in :doc:`conventions`).

- **How many threads.** A call that takes ``threads=`` uses at most that many; without
  it (or with ``threads=None``) at most ``numba.get_num_threads()``, which
  ``NUMBA_NUM_THREADS`` sets at start-up and ``numba.set_num_threads`` at any time (for
  the calling thread). The compiled parallel loops run on Numba's own threads, so they
  never use more than ``NUMBA_NUM_THREADS``.
- **No more threads than the work can use.** A call estimates its work and takes one
  thread per :data:`~polycontact.limits.THREAD_WORK` seconds of it, at most the number
  above; work below that runs on the calling thread and starts no thread.
- **Idle threads sleep.** ``import polycontact`` sets ``OMP_WAIT_POLICY=PASSIVE``
  unless the environment sets it, so that Numba's OpenMP threads do not spin between
  parallel calls, taking the cores the calling thread needs on a busy machine.
- **Where the threads come from.** The compiled loops use Numba's pool; the calls that
  share kernels releasing the GIL among Python threads (:func:`map_chunks`) use one pool
  per process, started on first use and grown when a call asks for more threads, whose
  threads take the chunks as they go (a slow chunk does not hold the others back).
  Every chunk's result goes to its own place, so the answer never depends on the number
  of threads.

Examples
--------
>>> requested(2), useful(8, 0.0), useful(8, 1.0) >= 1
(2, 1, True)
>>> map_chunks(lambda p0, p1: p1 - p0, 10, threads=2, chunks=3)
[3, 3, 4]
"""

from __future__ import annotations

import queue
import threading
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import ThreadPoolExecutor, wait
from contextlib import contextmanager
from typing import Any, TypeVar

import numpy as np

from .limits import THREAD_WORK

__all__ = ["requested", "useful", "chunks", "numba_threads", "map_chunks", "map_work",
           "as_done", "PAIR_SECONDS"]

_T = TypeVar("_T")

#: The time of one pair's classification (two 12-gons, seconds): the unit of work of the
#: World's compiled passes (:func:`chunks`).
PAIR_SECONDS = 0.5e-6


def requested(threads: Any) -> int:
    """The most threads a call may use: ``threads`` checked (an integer >= 1), or
    ``numba.get_num_threads()`` for None."""
    if threads is None:
        import numba

        return int(numba.get_num_threads())
    if isinstance(threads, bool) or not isinstance(threads, (int, np.integer)) or threads < 1:
        raise ValueError(f"threads: expected an integer >= 1 or None, got {threads!r}")
    return int(threads)


def useful(threads: int, seconds: float) -> int:
    """Threads worth starting for ``seconds`` of work: one per
    :data:`~polycontact.limits.THREAD_WORK` seconds, between 1 and ``threads``."""
    return max(1, min(threads, int(seconds / THREAD_WORK)))


def chunks(count: int, work: float = 1.0) -> int:
    """Chunks of a compiled parallel pass over ``count`` items of ``work`` pair
    classifications each (:data:`PAIR_SECONDS`): 1 (serial, no thread start) when the
    work needs one thread, else four per useful thread, each taking its blocks spread
    over the items (:mod:`polycontact._kernels.spread`)."""
    seconds = count * work * PAIR_SECONDS
    if seconds < 2.0 * THREAD_WORK:  # (one thread, however many there are)
        return 1
    n = useful(requested(None), seconds)
    return 1 if n == 1 else 4 * n


@contextmanager
def numba_threads(threads: int) -> Iterator[int]:
    """Run the compiled parallel loops of the block on at most ``threads`` of Numba's
    threads (at most ``NUMBA_NUM_THREADS``); yields that number."""
    import numba

    before = numba.get_num_threads()
    n = max(1, min(int(threads), int(getattr(numba.config, "NUMBA_NUM_THREADS"))))
    numba.set_num_threads(n)
    try:
        yield n
    finally:
        numba.set_num_threads(before)


class _Pool:
    """The process's pool of Python threads for :func:`map_chunks`."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._executor: ThreadPoolExecutor | None = None
        self._size = 0
        self.inside = threading.local()

    def executor(self, size: int) -> ThreadPoolExecutor:
        """A pool of at least ``size`` threads (a larger one replaces a smaller)."""
        with self._lock:
            if self._executor is None or self._size < size:
                old = self._executor
                self._executor = ThreadPoolExecutor(size, thread_name_prefix="polycontact",
                                                    initializer=self._mark)
                self._size = size
                if old is not None:
                    old.shutdown(wait=False)
            return self._executor

    def _mark(self) -> None:
        self.inside.flag = True


_POOL = _Pool()


def map_chunks(fn: Callable[[int, int], _T], count: int, threads: int,
               chunks: int | None = None) -> list[_T]:
    """``[fn(p0, p1) for each chunk]`` over ``chunks`` consecutive chunks of
    ``range(count)`` (default: four per thread), on at most ``threads`` threads of the
    process's pool (``fn`` must release the GIL to gain anything); the results in the
    order of the chunks. One thread (or a call from a pool thread): here, in order."""
    n_chunks = max(1, min(count, 4 * threads if chunks is None else chunks))
    bounds = [count * c // n_chunks for c in range(n_chunks + 1)]
    workers = min(threads, n_chunks)
    if workers <= 1 or getattr(_POOL.inside, "flag", False):
        return [fn(bounds[c], bounds[c + 1]) for c in range(n_chunks)]
    out: list[Any] = [None] * n_chunks
    todo = iter(range(n_chunks))
    lock = threading.Lock()

    def work() -> None:
        while True:
            with lock:
                c = next(todo, None)
            if c is None:
                return
            out[c] = fn(bounds[c], bounds[c + 1])

    futures = [_POOL.executor(workers).submit(work) for _ in range(workers)]
    wait(futures)
    for f in futures:
        f.result()  # (the first error, once every thread has stopped)
    return out


def map_work(fn: Callable[[int, int], _T], count: int, seconds: float,
             threads: int | None = None) -> list[_T]:
    """:func:`map_chunks` of ``count`` items of ``seconds`` of work each, on the threads
    that work can use (:func:`useful`, at most :func:`requested` ``(threads)``): in
    one chunk, here, when one thread is enough."""
    n = useful(requested(threads), count * seconds)
    return map_chunks(fn, count, n, chunks=1 if n == 1 else None)


def as_done(fn: Callable[[Any], _T], tasks: Sequence[Any],
            threads: int) -> Iterator[tuple[int, _T]]:
    """``(k, fn(tasks[k]))`` for every task, in the order they finish, computed on at
    most ``threads`` threads of the process's pool (here, in order, for one thread or
    from a pool thread). Closing the generator early stops the threads taking tasks;
    an error in a task is raised here once its thread has stopped."""
    workers = min(threads, len(tasks))
    if workers <= 1 or getattr(_POOL.inside, "flag", False):
        for k, task in enumerate(tasks):
            yield k, fn(task)
        return
    todo = iter(range(len(tasks)))
    lock = threading.Lock()
    done: queue.SimpleQueue[tuple[int, Any, BaseException | None]] = queue.SimpleQueue()
    stop = threading.Event()

    def work() -> None:
        while not stop.is_set():
            with lock:
                k = next(todo, None)
            if k is None:
                return
            try:
                done.put((k, fn(tasks[k]), None))
            except BaseException as exc:  # noqa: BLE001 - handed to the caller
                done.put((k, None, exc))
                return

    futures = [_POOL.executor(workers).submit(work) for _ in range(workers)]
    try:
        for _ in range(len(tasks)):
            k, result, error = done.get()
            if error is not None:
                raise error
            yield k, result
    finally:
        stop.set()
        wait(futures)
