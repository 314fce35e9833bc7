"""Running polycontact's batches on a Dask cluster.

Dask is an optional extra (``pip install "polycontact[dask]"``): this module imports
``distributed`` only inside its functions, and nothing else in polycontact imports this
module unless a Dask client is given or is already the default.

:func:`polycontact.classify_many`, :func:`polycontact.time_of_impact_many` and
:func:`polycontact.nfp_table` take ``client=``: the same call, with the same checks in
the calling process, runs its work here as tasks, and the result is identical to the
local one. This module holds what they share:

- :func:`current_client` is the client a batch runs on: the one given, else the
  default client of this process when ``distributed`` is already imported and one is
  set (``Client(...)`` or ``with Client(...)``), never one inside a Dask task.
- ``WarmupPlugin`` (registered by :func:`ensure_warm`) compiles or loads the
  kernels once per worker, when the worker starts or joins, not once per task.
- :func:`run_spans` cuts ``range(count)`` into tasks: a first task measures the work per
  item, the others get at least :data:`~polycontact.limits.TASK_SECONDS` of work each
  and four per worker thread where there is enough; what every task needs is sent to
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

import math
import sys
from collections.abc import Callable, Generator, Iterable, Iterator, Sequence
from typing import Any

import numpy as np

__all__ = [
    "WarmupPlugin",
    "current_client",
    "ensure_warm",
    "map_batches",
    "run_spans",
    "task_size",
    "PROBE_ITEMS",
]

#: Prefix of the names under which ``WarmupPlugin`` is registered (one per family).
PLUGIN_NAME = "polycontact-warmup"

#: Items of the first task of :func:`run_spans`, which measures the work per item.
PROBE_ITEMS = 256


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


def __getattr__(name: str) -> Any:
    # WarmupPlugin subclasses distributed.WorkerPlugin: loaded (with Dask) on first use
    if name == "WarmupPlugin":
        from ._dask_plugin import WarmupPlugin

        return WarmupPlugin
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def ensure_warm(client: Any, families: Iterable[str] | None = None) -> None:
    """Register a ``WarmupPlugin`` with ``client`` for each kernel family (all by
    default) that some worker lacks.

    One plugin per family, named ``polycontact-warmup:FAMILY``, so a batch warms only
    the kernels it runs. Workers that join later get the plugins from the scheduler.
    Returns when the current workers have loaded the kernels.
    """
    from .compiling import FAMILIES

    wanted = list(FAMILIES if families is None else families)
    have = client.run(_plugins)
    missing = [f for f in wanted
               if not have or not all(plugin_name(f) in names for names in have.values())]
    if not missing:
        return
    from ._dask_plugin import WarmupPlugin

    for family in missing:
        client.register_plugin(WarmupPlugin([family]), name=plugin_name(family))


def plugin_name(family: str) -> str:
    """The name of the warm-up plugin of one kernel family."""
    return f"{PLUGIN_NAME}:{family}"


def _plugins(dask_worker: Any) -> list[str]:
    return sorted(dask_worker.plugins)


Tasks = Callable[[list[tuple[int, int]]], tuple[Any, list[Any]]]


def task_size(count: int, per_item: float, workers: int) -> int:
    """Items per task for ``count`` items of ``per_item`` seconds each on ``workers``
    worker threads: at least :data:`~polycontact.limits.TASK_SECONDS` of work, and as
    many more as keeps four tasks per worker thread.

    >>> task_size(1_000_000, 1e-6, 4), task_size(1000, 1e-6, 4)
    (200000, 1000)
    """
    from .limits import TASK_SECONDS

    by_time = math.ceil(TASK_SECONDS / max(per_item, 1e-12) * (1.0 - 1e-12))  # (no 1 ulp up)
    return max(1, min(count, max(by_time, math.ceil(count / (4 * workers)))))


def _timed(fn: Callable[..., Any], shared: Any, task: Any, *args: Any) -> tuple[Any, float]:
    """``fn(shared, task, *args)`` and the seconds it took (on the worker)."""
    import time

    t0 = time.perf_counter()
    out = fn(shared, task, *args)
    return out, time.perf_counter() - t0


def run_spans(
    client: Any, fn: Callable[..., Any], count: int, tasks_of: Tasks, *args: Any,
    chunk_size: int | None = None, families: Iterable[str] | None = None,
) -> Generator[tuple[int, int, Any], None, None]:
    """Run ``fn(shared, task, *args)`` over spans of ``range(count)`` as tasks on the
    cluster; yield ``(p0, p1, result)`` for each span as its task finishes.

    ``tasks_of(spans)`` gives ``(shared, tasks)``: what every task of those spans needs
    (sent to every worker once) and each span's own task. With ``chunk_size`` the spans
    have that many items; else a first task of :data:`PROBE_ITEMS` items measures the
    work per item and :func:`task_size` sizes the others. Closing the generator early
    (an error, or Ctrl-C in the caller) cancels the tasks not yet finished.
    """
    import distributed

    if not count:
        return
    as_completed: Any = distributed.as_completed
    ensure_warm(client, families)
    futures: list[Any] = []
    try:
        start = 0
        size = chunk_size or 0
        if not size:
            start = min(count, PROBE_ITEMS)
            shared, [task] = tasks_of([(0, start)])
            probe = client.submit(_timed, fn, shared, task, *args, pure=False)
            futures.append(probe)
            result, seconds = probe.result()
            yield 0, start, result
            workers = max(1, sum(client.nthreads().values()))
            size = task_size(count - start, seconds / start, workers)
        spans = [(p, min(count, p + size)) for p in range(start, count, size)]
        if not spans:
            return
        shared, tasks = tasks_of(spans)
        [shared_future] = client.scatter([shared], broadcast=True, hash=False)
        futures.append(shared_future)
        submitted = [client.submit(fn, shared_future, t, *args, pure=False) for t in tasks]
        futures.extend(submitted)
        index = {f.key: k for k, f in enumerate(submitted)}
        for f in as_completed(submitted):
            result = f.result()
            k = index[f.key]
            f.release()
            yield *spans[k], result
    finally:
        client.cancel(futures)


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

    parts: dict[int, Any] = {}
    with _closing(run_spans(client, _call_on_slices, count, tasks_of, fn, kwargs,
                            chunk_size=chunk_size, families=families)) as results:
        for p0, _, r in results:
            parts[p0] = r
    return [parts[p] for p in sorted(parts)]


def check_chunk_size(chunk_size: Any) -> None:
    """Refuse a ``chunk_size`` that is not None or a positive integer."""
    if chunk_size is not None and (isinstance(chunk_size, bool) or not isinstance(
            chunk_size, int) or chunk_size < 1):
        raise ValueError(f"chunk_size: expected a positive integer, got {chunk_size!r}")


def _closing(gen: Iterator[Any]) -> Any:
    from contextlib import closing

    return closing(gen)


# -- classify_many and time_of_impact_many on the cluster --------------------------------
def classify_states(client: Any, packs: tuple[Any, ...], tol: float,
                    chunk_size: int | None) -> tuple[np.ndarray, np.ndarray]:
    """The states and tolerances of the packed pairs ``packs`` (both sides'
    ``pack_bodies``) as :func:`polycontact.classify_many` computes them, in tasks (each
    with the slices of the packed arrays its pairs need)."""
    count = len(packs[3])
    states = np.empty(count, np.int8)
    tols = np.empty(count)

    def tasks_of(spans: list[tuple[int, int]]) -> tuple[Any, list[Any]]:
        return None, [(_pack_slice(packs[:4], p0, p1), _pack_slice(packs[4:], p0, p1))
                      for p0, p1 in spans]

    with _closing(run_spans(client, _states, count, tasks_of, tol, chunk_size=chunk_size,
                            families=["classification"])) as results:
        for p0, p1, (st, e) in results:
            states[p0:p1] = st
            tols[p0:p1] = e
    return states, tols


def _pack_slice(pack: tuple[Any, ...], p0: int, p1: int) -> tuple[Any, ...]:
    """The bodies ``p0:p1`` of a ``pack_bodies`` result ``(xy, ls, bs, sign)``, packed
    alone (their rows, loop starts and body starts renumbered from 0)."""
    xy, ls, bs, sign = pack
    b0, b1 = int(bs[p0]), int(bs[p1])
    r0 = int(ls[b0]) if b1 > b0 else 0
    r1 = int(ls[b1 - 1]) if b1 > b0 else 0
    return (xy[r0:r1], ls[b0:b1] - r0, bs[p0:p1 + 1] - b0, sign[p0:p1])


def _states(_: Any, task: tuple[Any, ...], tol: float) -> tuple[np.ndarray, np.ndarray]:
    from .relation import pack_states

    (xa, lsa, bsa, fa), (xb, lsb, bsb, fb) = task
    return pack_states(xa, lsa, bsa, fa, xb, lsb, bsb, fb, tol, 1)


def impact_search(client: Any, prepared: tuple[Any, ...], options: tuple[Any, ...],
                  chunk_size: int | None) -> tuple[Any, ...]:
    """The raw result arrays of :func:`polycontact.impacts.search_pairs` for the
    prepared pairs (``prepare_pairs``'s answer), in tasks; ``options`` = ``(t_max,
    method, tol, samples, max_iterations)``."""
    from .impacts import empty_result

    uniq, _, sa, sb, rows_a, rows_b, eps_rel = prepared
    count = len(sa)
    raw = empty_result(count)

    def tasks_of(spans: list[tuple[int, int]]) -> tuple[Any, list[Any]]:
        return _impact_tasks(uniq, sa, sb, rows_a, rows_b, eps_rel, spans)

    with _closing(run_spans(client, _impact_slice, count, tasks_of, *options,
                            chunk_size=chunk_size,
                            families=["many moving bodies"])) as results:
        for p0, p1, part in results:
            for whole, got in zip(raw, part):
                whole[p0:p1] = got
    return raw


def _impact_tasks(uniq: list[Any], sa: np.ndarray, sb: np.ndarray, rows_a: np.ndarray,
                  rows_b: np.ndarray, eps_rel: np.ndarray,
                  spans: list[tuple[int, int]]) -> tuple[_ShapePack, list[tuple[Any, ...]]]:
    """The shapes several tasks use (sent once to every worker) and the tasks: each its
    slice of pairs, with its own shapes, the pairs' shape indices numbering the shared
    shapes first, then the task's own."""
    task = np.empty(len(sa), np.int64)
    for k, (p0, p1) in enumerate(spans):
        task[p0:p1] = k
    first = np.full(len(uniq), len(spans), np.int64)
    last = np.full(len(uniq), -1, np.int64)
    for s in (sa, sb):
        np.minimum.at(first, s, task)
        np.maximum.at(last, s, task)
    shared_ids = np.flatnonzero(first < last)
    number = np.full(len(uniq), -1, np.int64)
    number[shared_ids] = np.arange(len(shared_ids))
    tasks = []
    for p0, p1 in spans:
        ta, tb = sa[p0:p1], sb[p0:p1]
        own = np.unique(np.concatenate([ta, tb]))
        own = own[number[own] < 0]
        number[own] = len(shared_ids) + np.arange(len(own))
        tasks.append((number[ta], number[tb], _ShapePack([uniq[u] for u in own]),
                      rows_a[p0:p1], rows_b[p0:p1], eps_rel[p0:p1]))
        number[own] = -1
    return _ShapePack([uniq[u] for u in shared_ids]), tasks


def _impact_slice(shared: _ShapePack, task: tuple[Any, ...], t_max: float, method: str,
                  tol: float, samples: int, max_iterations: int) -> tuple[Any, ...]:
    """One task of :func:`time_of_impact_many`: the local search on a slice of pairs
    (only the shapes it uses are packed for the kernel); the raw result arrays."""
    from .impacts import pack_shapes, search_pairs

    sa, sb, own, rows_a, rows_b, eps_rel = task
    common, mine = shared.shapes(), own.shapes()
    used, inverse = np.unique(np.concatenate([sa, sb]), return_inverse=True)
    shapes = [common[u] if u < len(common) else mine[u - len(common)] for u in used]
    n = len(sa)
    return search_pairs(pack_shapes(shapes), inverse[:n], inverse[n:], rows_a, rows_b,
                        eps_rel, t_max, method, tol, samples, max_iterations, 1)


class _ShapePack:
    """Shapes sent to Dask workers as five flat arrays, unpacked there on first use.

    A list of :class:`~polycontact.Shape` pickles as a dozen small NumPy buffers per
    shape, which Dask sends one by one (10 000 pairs of small polygons took 12-16 s to
    send against 1 s of work); here every vertex of every shape is one array. The
    receiving process unpacks them once into :class:`_PackedShape` (what the search
    reads of a shape: its packed loops, centroid and bounding radius, as sent, not
    recomputed) and keeps them for every later task.

    Examples
    --------
    >>> import pickle
    >>> from polycontact import Shape
    >>> frame = Shape([(0, 0), (6, 0), (6, 6), (0, 6)], [[(2, 2), (4, 2), (4, 4), (2, 4)]])
    >>> back = pickle.loads(pickle.dumps(_ShapePack([frame, frame.moved((1, 0))]))).shapes()
    >>> back[1]._centroid.tolist(), back[1]._radius == frame.bounding_radius
    ([4.0, 3.0], True)
    >>> back[0]._xy.tolist() == frame.packed[0].tolist()
    True
    """

    def __init__(self, shapes: Sequence[Any]) -> None:
        n = len(shapes)
        self.arrays: tuple[np.ndarray, ...] = (
            np.concatenate([s.packed[0] for s in shapes]) if n else np.empty((0, 2)),
            np.concatenate([np.diff(s.packed[1]) for s in shapes]) if n
            else np.empty(0, np.int64),
            np.array([len(s.packed[1]) - 1 for s in shapes], dtype=np.int64),
            np.array([s.centroid for s in shapes], dtype=np.float64).reshape(n, 2),
            np.array([s.bounding_radius for s in shapes], dtype=np.float64),
        )
        self._shapes: list[Any] | None = list(shapes)

    def __getstate__(self) -> tuple[np.ndarray, ...]:
        return self.arrays

    def __setstate__(self, arrays: tuple[np.ndarray, ...]) -> None:
        self.arrays = arrays
        self._shapes = None

    def shapes(self) -> list[Any]:
        """The shapes: those given, or, in a process that received them, unpacked."""
        if self._shapes is None:
            xy, loop_len, n_loops, cent, rad = self.arrays
            loop_end = np.concatenate([[0], np.cumsum(loop_len)])
            first = np.concatenate([[0], np.cumsum(n_loops)])
            shapes = []
            for k in range(len(rad)):
                ends = loop_end[first[k]:first[k + 1] + 1]
                shapes.append(_PackedShape(xy[ends[0]:ends[-1]], ends - ends[0],
                                           cent[k].copy(), float(rad[k])))
            self._shapes = shapes
        return self._shapes


class _PackedShape:
    """What the time-of-impact search reads of a :class:`~polycontact.Shape` (its stored
    coordinates, loop starts, centroid and bounding radius, under a Shape's names), on
    a worker."""

    __slots__ = ("_xy", "_starts", "_centroid", "_radius")

    def __init__(self, xy: np.ndarray, starts: np.ndarray, centroid: np.ndarray,
                 radius: float) -> None:
        self._xy = xy
        self._starts = starts
        self._centroid = centroid
        self._radius = radius
