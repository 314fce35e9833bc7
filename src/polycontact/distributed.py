"""Running polycontact's batches on a Dask cluster.

Dask is an optional extra (``pip install "polycontact[dask]"``): this module imports
``distributed`` only inside its functions, and nothing else in polycontact imports this
module unless a Dask client is given or is already the default.

- :func:`current_client` is the client a batch runs on: the one given, else the
  default client of this process when ``distributed`` is already imported and one is
  set (``Client(...)`` or ``with Client(...)``), never one inside a Dask task.
- ``WarmupPlugin`` (registered by :func:`ensure_warm`) compiles or loads the
  kernels once per worker, when the worker starts or joins, not once per task.
- :func:`map_batches` splits aligned sequences into slices, calls a function on each
  slice as one task, and returns the results in order; :func:`classify_many` is
  :func:`polycontact.classify_many` split this way, with results identical to the
  local run. :func:`polycontact.nfp_table` with ``client=`` runs its tasks through
  :func:`run_tasks`.
- :func:`time_of_impact_many` is :func:`polycontact.time_of_impact_many` on slices of
  pairs: the arguments are checked here first, shapes used by several tasks are sent
  to every worker once, and the result equals the local call's
  :class:`~polycontact.ImpactBatch`.

Examples
--------
Without a client everything runs locally:

>>> import numpy as np
>>> from polycontact import distributed
>>> sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
>>> distributed.classify_many(np.stack([sq, sq]), np.stack([sq + 2, sq + 1])).states.tolist()
[0, 1]
>>> distributed.map_batches(len, list(range(10)), chunk_size=4)
[4, 4, 2]
"""

from __future__ import annotations

import math
import sys
from collections.abc import Callable, Generator, Iterable, Iterator, Sequence
from typing import Any

import numpy as np

from .limits import (DEFAULT_BATCH, DEFAULT_IMPACT_BATCH, MAX_ITERATIONS, SAMPLES,
                     TIME_TOLERANCE)

__all__ = [
    "WarmupPlugin",
    "classify_many",
    "current_client",
    "ensure_warm",
    "map_batches",
    "run_tasks",
    "time_of_impact_many",
    "DEFAULT_BATCH",
    "DEFAULT_IMPACT_BATCH",
]

#: Prefix of the names under which ``WarmupPlugin`` is registered (one per family).
PLUGIN_NAME = "polycontact-warmup"


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


def run_tasks(
    client: Any, fn: Callable[..., Any], shared: Any, tasks: Sequence[Any], *args: Any,
    families: Iterable[str] | None = None,
) -> Generator[tuple[int, Any], None, None]:
    """Run ``fn(shared, task, *args)`` for each task on the cluster; yield
    ``(task index, result)`` as tasks finish.

    ``shared`` is sent once to every worker. Closing the generator early (an error, or
    Ctrl-C in the caller) cancels the tasks not yet finished.
    """
    import distributed

    as_completed: Any = distributed.as_completed
    ensure_warm(client, families)
    [shared_future] = client.scatter([shared], broadcast=True, hash=False)
    futures = [client.submit(fn, shared_future, t, *args, pure=False) for t in tasks]
    index = {f.key: k for k, f in enumerate(futures)}
    try:
        for f in as_completed(futures):
            result = f.result()
            k = index[f.key]
            f.release()
            yield k, result
    finally:
        client.cancel(futures)
        client.cancel([shared_future])


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
    consecutive slices of ``chunk_size`` items; each call is one task. Without a client
    (see :func:`current_client`) the calls run here, one after the other.

    Parameters
    ----------
    fn : callable
        A module-level function (it is pickled to the workers).
    *sequences : sliceable
        Aligned inputs, e.g. shapes_a, shapes_b.
    client : dask.distributed.Client, optional
    chunk_size : int, optional
        Items per task; default :data:`~polycontact.limits.DEFAULT_BATCH`, fewer if
        that would give less than four tasks per worker thread.
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
    _check_chunk_size(chunk_size)
    client = current_client(client)
    if chunk_size is None:
        chunk_size = _default_chunk(client, count, DEFAULT_BATCH)
    spans = [(p, min(count, p + chunk_size)) for p in range(0, count, chunk_size)]
    if client is None:
        return [fn(*(s[p0:p1] for s in sequences), **kwargs) for p0, p1 in spans]
    tasks = [tuple(s[p0:p1] for s in sequences) for p0, p1 in spans]
    out: list[Any] = [None] * len(tasks)
    with _closing(run_tasks(client, _call_on_slices, None, tasks, fn, kwargs,
                            families=families)) as results:
        for k, r in results:
            out[k] = r
    return out


def _check_chunk_size(chunk_size: Any) -> None:
    if chunk_size is not None and (isinstance(chunk_size, bool) or not isinstance(
            chunk_size, int) or chunk_size < 1):
        raise ValueError(f"chunk_size: expected a positive integer, got {chunk_size!r}")


def _default_chunk(client: Any, count: int, largest: int) -> int:
    """``largest`` items per task, fewer if that gives less than four tasks per thread."""
    n_workers = 1 if client is None else max(1, sum(client.nthreads().values()))
    return max(1, min(largest, math.ceil(count / (4 * n_workers))))


def _closing(gen: Iterator[Any]) -> Any:
    from contextlib import closing

    return closing(gen)


def classify_many(
    shapes_a: Any,
    shapes_b: Any,
    *,
    tolerance: float | None = None,
    client: Any = None,
    chunk_size: int | None = None,
) -> Any:
    """:func:`polycontact.classify_many` split into tasks on a Dask cluster.

    Same arguments and result (a :class:`~polycontact.RelationBatch`, identical to the
    local call: each pair's tolerance depends on that pair only), plus ``client`` and
    ``chunk_size`` as in :func:`map_batches`. Without a client it is the local call.
    ``distances``, on first access, are computed locally.

    Examples
    --------
    See the module's example.
    """
    from .relation import RelationBatch, pack_bodies
    from .relation import classify_many as local

    client = current_client(client)
    if client is None:
        return local(shapes_a, shapes_b, tolerance=tolerance)
    if len(shapes_a) != len(shapes_b):
        raise ValueError(
            f"shapes_a and shapes_b differ in length ({len(shapes_a)} and {len(shapes_b)})")
    # packed now (a copy): the distances, computed locally on first access, are those of
    # the bodies as they were at the call, whatever the caller does with its arrays since
    packed = (*pack_bodies(shapes_a, "shapes_a"), *pack_bodies(shapes_b, "shapes_b"))
    parts = map_batches(_states, shapes_a, shapes_b, client=client, chunk_size=chunk_size,
                        families=["classification"], tolerance=tolerance)
    states = np.concatenate([p[0] for p in parts]) if parts else np.empty(0, np.int8)
    tols = np.concatenate([p[1] for p in parts]) if parts else np.empty(0)
    return RelationBatch(states, tols, lambda: packed)


def _states(a: Any, b: Any, tolerance: float | None) -> tuple[np.ndarray, np.ndarray]:
    from .relation import classify_many as local

    batch = local(a, b, tolerance=tolerance)
    return batch.states, batch.tolerances


def time_of_impact_many(
    shapes_a: Any,
    motions_a: Any,
    shapes_b: Any,
    motions_b: Any,
    t_max: float,
    *,
    method: str = "exact",
    time_tolerance: float = TIME_TOLERANCE,
    samples: int = SAMPLES,
    max_iterations: int = MAX_ITERATIONS,
    threads: int | None = None,
    client: Any = None,
    chunk_size: int | None = None,
) -> Any:
    """:func:`polycontact.time_of_impact_many` split into tasks on a Dask cluster.

    Same arguments and result (an :class:`~polycontact.ImpactBatch` equal to the local
    call's: ``status``, ``collides``, ``times``, ``first_contacts`` and every
    ``impact(k)``; each pair's answer depends on that pair only), plus ``client`` and
    ``chunk_size`` as in :func:`map_batches`. Without a client it is the local call.

    Every shape and motion is checked here, before any task is sent, so errors name
    the argument and index in the caller's numbering, as the local call does. The
    shapes that pairs of more than one task use are sent to every worker once; the
    others go with their task. Each task runs the local search on its slice of pairs
    and returns its result arrays; the :class:`~polycontact.Impact` objects are built
    here, on demand, from the caller's own shapes and motions.

    Parameters
    ----------
    shapes_a, motions_a, shapes_b, motions_b, t_max
        As for :func:`polycontact.time_of_impact_many` (``t_max`` may be positional).
    method, time_tolerance, samples, max_iterations
        As there.
    threads : int, optional
        Threads of each task (default 1 on a cluster: the worker threads already run
        tasks side by side); without a client, as for the local call.
    client : dask.distributed.Client, optional
    chunk_size : int, optional
        Pairs per task; default :data:`~polycontact.limits.DEFAULT_IMPACT_BATCH`, fewer
        if that would give less than four tasks per worker thread.

    Returns
    -------
    ImpactBatch

    Examples
    --------
    Without a client this is the local call:

    >>> from polycontact import Motion, Shape
    >>> sq = Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
    >>> batch = time_of_impact_many([sq, sq], [Motion(velocity=(1, 0))] * 2,
    ...                             [sq.moved((3, 0)), sq.moved((0, 5))], [Motion()] * 2, 5)
    >>> batch.statuses.tolist(), batch.times.round(3).tolist()
    ([1, 0], [2.0, nan])
    """
    from . import impacts

    options: dict[str, Any] = dict(t_max=t_max, method=method, time_tolerance=time_tolerance,
                                   samples=samples, max_iterations=max_iterations)
    _check_chunk_size(chunk_size)
    client = current_client(client)
    if client is None:
        return impacts.time_of_impact_many(shapes_a, motions_a, shapes_b, motions_b,
                                           threads=threads, **options)
    # the local call's checks, in its order, before anything is sent
    a = impacts.check_shapes(shapes_a, "shapes_a")
    b = impacts.check_shapes(shapes_b, "shapes_b")
    if len(a) != len(b):
        raise ValueError(f"shapes_a and shapes_b differ in length ({len(a)} and {len(b)})")
    ma = impacts.check_motions(motions_a, "motions_a", len(a), "shapes_a")
    mb = impacts.check_motions(motions_b, "motions_b", len(b), "shapes_b")
    t_max, tol, samples, max_iterations, threads = impacts.check_many_options(
        t_max, method, time_tolerance, samples, max_iterations,
        1 if threads is None else threads)
    uniq, sa, sb, rows_a, rows_b, eps_rel = impacts.prepare_pairs(a, b, ma, mb, t_max)
    count = len(a)
    if count == 0:
        return impacts.time_of_impact_many([], [], [], [], threads=threads, **options)
    if chunk_size is None:
        chunk_size = _default_chunk(client, count, DEFAULT_IMPACT_BATCH)
    spans = [(p, min(count, p + chunk_size)) for p in range(0, count, chunk_size)]
    shared, tasks = _impact_tasks(uniq, sa, sb, rows_a, rows_b, eps_rel, spans)
    parts: list[Any] = [None] * len(tasks)
    with _closing(run_tasks(client, _impact_slice, shared, tasks, t_max, method, tol, samples,
                            max_iterations, threads,
                            families=["many moving bodies"])) as results:
        for k, r in results:
            parts[k] = r
    raw = tuple(np.concatenate(field) for field in zip(*parts))
    return impacts.impact_batch(a, b, ma, mb, raw, eps_rel, t_max, method, tol)


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
                  tol: float, samples: int, max_iterations: int,
                  threads: int) -> tuple[Any, ...]:
    """One task of :func:`time_of_impact_many`: the local search on a slice of pairs
    (only the shapes it uses are packed for the kernel); the raw result arrays."""
    from .impacts import search_pairs

    sa, sb, own, rows_a, rows_b, eps_rel = task
    common, mine = shared.shapes(), own.shapes()
    used, inverse = np.unique(np.concatenate([sa, sb]), return_inverse=True)
    shapes = [common[u] if u < len(common) else mine[u - len(common)] for u in used]
    n = len(sa)
    return search_pairs(shapes, inverse[:n], inverse[n:], rows_a, rows_b, eps_rel, t_max,
                        method, tol, samples, max_iterations, threads)


class _ShapePack:
    """Shapes sent to Dask workers as five flat arrays, unpacked there on first use.

    A list of :class:`~polycontact.Shape` pickles as a dozen small NumPy buffers per
    shape, which Dask sends one by one (10 000 pairs of small polygons took 12-16 s to
    send against 1 s of work); here every vertex of every shape is one array. The
    receiving process unpacks them once into :class:`_PackedShape` (what the search
    reads of a shape: its packed loops, centroid and bounding radius, as sent, not
    recomputed) and keeps them, with the tables the search builds on them, for every
    later task.

    Examples
    --------
    >>> import pickle
    >>> from polycontact import Shape
    >>> frame = Shape([(0, 0), (6, 0), (6, 6), (0, 6)], [[(2, 2), (4, 2), (4, 4), (2, 4)]])
    >>> back = pickle.loads(pickle.dumps(_ShapePack([frame, frame.moved((1, 0))]))).shapes()
    >>> back[1].centroid.tolist(), back[1].bounding_radius == frame.bounding_radius
    ([4.0, 3.0], True)
    >>> [b.tolist() for b in back[0].packed] == [b.tolist() for b in frame.packed]
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
    """What the time-of-impact search reads of a :class:`~polycontact.Shape`
    (``packed``, ``centroid``, ``bounding_radius``, and the body-frame tables it keeps
    in ``_frame``), on a worker. Read-only arrays, as a Shape's: the kernels are
    compiled (and cached) for those types."""

    __slots__ = ("packed", "centroid", "bounding_radius", "_frame")

    def __init__(self, xy: np.ndarray, starts: np.ndarray, centroid: np.ndarray,
                 radius: float) -> None:
        for array in (xy, starts, centroid):
            array.flags.writeable = False
        self.packed = (xy, starts)
        self.centroid = centroid
        self.bounding_radius = radius
        self._frame: Any = None
