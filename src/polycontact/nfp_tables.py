"""NFP tables of nesting instances, with a resumable on-disk cache.

:func:`nfp_table` builds the no-fit polygon of every ordered pair of pieces (a piece
with itself included) at every allowed orientation of each: ``table[i, ai, j, aj]`` is
the :class:`~polycontact.NoFitPolygon` of piece ``i`` turned by ``ai`` degrees orbiting
piece ``j`` turned by ``aj`` degrees, a piece being turned about the origin of its own
coordinates, as ESICUP defines it (:func:`polycontact.esicup.turned`).

**Cache.** With ``cache=DIR`` the table is read from and written to a directory:

- ``DIR/table.json``: the last build's pieces, orientations and reference (so
  :meth:`NfpTable.load` needs nothing else), with a checksum of them;
- ``DIR/shards/NAME.wkb``: the regions of a batch of entries, as ISO WKB
  (little-endian, float64: exact), one after the other;
- ``DIR/shards/NAME.json``: that batch's index: for each entry its key, the byte range
  of its region in the ``.wkb`` file, the reference point, the tolerance, the exact fits
  and the slides (JSON numbers, which round-trip float64 exactly), and one BLAKE2
  checksum of the ``.wkb`` file and of every value of the index: every byte that
  decides an answer is checked.

An entry's key is a hash of the two turned pieces' coordinates, the reference, this
format's version and polycontact's version, so the cache is shared by every table
whose pieces are the same, a changed piece or a new orientation recomputes only its
own entries, and entries of another polycontact version are never reused. Every file
is written to a temporary name and renamed (atomic on POSIX and Windows); a shard's
``.json`` is written after its ``.wkb`` and is what makes the shard exist, so a build
interrupted at any point (Ctrl-C, a killed process or worker) leaves only complete
shards, and the next build computes only the entries the cache lacks. A shard that
cannot be read or does not match its checksum is ignored with a warning and its entries
are recomputed.

**Parallel runs.** With ``client=`` (a ``dask.distributed.Client``), or when called where
a Dask client is the default, the missing entries are split into tasks of
``chunk_size`` pairs run on the cluster (:mod:`polycontact.distributed`); the client
writes the shards as results arrive. Without Dask, large builds run on a pool of
``workers`` processes (default: one per CPU): the NFP build spends most of its time in
Python and GEOS calls that hold the GIL, so threads do not help (measured: two threads
are twice as slow as one on jakobs1). Processes start in about a second each, so builds
under :data:`PROCESS_POOL_MIN_ENTRIES` missing entries run in the calling process.
Scripts that build large tables locally must guard their entry point with
``if __name__ == "__main__":`` (processes are spawned, as on macOS and Windows).

Examples
--------
>>> import polycontact as pc
>>> ell = pc.Shape([(0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)])
>>> table = pc.nfp_table([ell], [[0, 90]], progress=False)
>>> len(table), table[0, 90, 0, 0].region.area
(4, 14.0)
"""

from __future__ import annotations

import hashlib
import json
import math
import multiprocessing
import multiprocessing.connection
import operator
import os
import signal
import sys
import threading
import time
import uuid
import warnings
from collections.abc import Callable, Generator, Iterator, Sequence
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from contextlib import closing
from dataclasses import dataclass
from os import PathLike
from pathlib import Path
from typing import Any

import numpy as np
import shapely

from . import __version__
from ._json import load_json
from .esicup import Instance, turned
from .nfp import NoFitPolygon, no_fit_polygon
from .shape import Shape, as_shape

__all__ = ["NfpTable", "nfp_table", "CacheWarning", "PROCESS_POOL_MIN_ENTRIES"]

#: Name and version of the on-disk format.
FORMAT = "polycontact-nfp-table"
FORMAT_VERSION = 2
MANIFEST = "table.json"
SHARDS = "shards"

#: Below this many missing entries a local build runs in the calling process: starting
#: a process (import, load the compiled kernels) costs about a second, the time of some
#: 30 000 NFPs of the ESICUP instances.
PROCESS_POOL_MIN_ENTRIES = 50_000

#: Angles closer than this (degrees) name the same orientation in ``table[i, a, j, b]``.
ANGLE_MATCH = 1e-9

Progress = bool | Callable[[int, int], None]

#: A task's result: the regions' WKB and their ends, exact fits and their ends, slides
#: and their ends, references, tolerances (see :func:`_compute_chunk`).
Packed = tuple[bytes, np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray,
               np.ndarray, np.ndarray]


class CacheWarning(UserWarning):
    """A cache file is damaged or unreadable; its entries are recomputed."""


@dataclass(frozen=True)
class _Record:
    """One computed entry, in the form it is stored."""

    wkb: bytes
    exact_fits: np.ndarray
    slides: np.ndarray
    reference: np.ndarray
    tolerance: float

    def __post_init__(self) -> None:
        # the arrays go out as they are in each NoFitPolygon of the table: read-only
        for array in (self.exact_fits, self.slides, self.reference):
            array.flags.writeable = False


class NfpTable:
    """The no-fit polygons of every ordered pair of pieces at every orientation.

    Built by :func:`nfp_table` or read by :meth:`load`; ``table[i, ai, j, aj]`` (piece
    indices, angles in degrees) is the :class:`~polycontact.NoFitPolygon` of piece
    ``i`` at ``ai`` orbiting piece ``j`` at ``aj``.

    Attributes
    ----------
    pieces : tuple of Shape
        The pieces at orientation 0.
    orientations : tuple of tuple of float
        The angles (degrees) of each piece.
    reference : str
        ``"origin"`` or ``"centroid"`` (of the turned orbiting piece).
    computed, loaded : int
        Distinct entries computed by this build, and read from the cache.
    seconds : float
        Wall time of the build.
    """

    def __init__(
        self,
        pieces: tuple[Shape, ...],
        orientations: tuple[tuple[float, ...], ...],
        reference: str,
        shapes: dict[tuple[int, int], Shape],
        keys: dict[tuple[int, int], bytes],
        records: dict[str, _Record],
    ) -> None:
        self.pieces = pieces
        self.orientations = orientations
        self.reference = reference
        self._shapes = shapes
        self._digests = keys
        self._records = records
        self._regions: dict[str, Any] = {}
        self.computed = 0
        self.loaded = 0
        self.seconds = 0.0

    # -- access ---------------------------------------------------------------------
    def __len__(self) -> int:
        n = sum(len(o) for o in self.orientations)
        return n * n

    def __iter__(self) -> Iterator[tuple[int, float, int, float]]:
        """The indices ``(i, ai, j, aj)`` of every entry."""
        slots = [(i, a) for i, angles in enumerate(self.orientations) for a in angles]
        for i, ai in slots:
            for j, aj in slots:
                yield i, ai, j, aj

    def __getitem__(self, index: tuple[int, float, int, float]) -> NoFitPolygon:
        if not (isinstance(index, tuple) and len(index) == 4):
            raise KeyError(f"expected table[i, ai, j, aj] (pieces, angles in degrees), "
                           f"got {index!r}")
        i, ai, j, aj = index
        sa = self._slot(i, ai, "i")
        sb = self._slot(j, aj, "j")
        key = _pair_key(self._digests[sa], self._digests[sb])
        rec = self._records.get(key)
        if rec is None:
            raise KeyError(f"entry {index!r} is not in the table (a load of an incomplete "
                           "cache); build it with nfp_table(..., cache=DIR)")
        region = self._regions.get(key)
        if region is None:
            region = self._regions[key] = shapely.from_wkb(rec.wkb)
        return NoFitPolygon(region, rec.exact_fits, rec.slides, rec.reference,
                            self._shapes[sa], self._shapes[sb], rec.tolerance)

    def _slot(self, piece: Any, angle: Any, what: str) -> tuple[int, int]:
        try:
            k = operator.index(piece)
        except TypeError:
            raise KeyError(f"{what}: expected a piece index, got {piece!r}") from None
        if isinstance(piece, bool):
            raise KeyError(f"{what}: expected a piece index, got {piece!r}")
        if not 0 <= k < len(self.pieces):
            raise KeyError(f"{what}: piece {k} out of range (the table has "
                           f"{len(self.pieces)} pieces)")
        if not _is_number(angle):  # (a string is not parsed, a bool is no angle)
            raise KeyError(f"angle of piece {k}: expected degrees, got {angle!r}")
        deg = float(angle)
        for n, a in enumerate(self.orientations[k]):
            if abs(math.remainder(deg - a, 360.0)) <= ANGLE_MATCH:
                return k, n
        raise KeyError(f"angle of piece {k}: {angle!r} degrees is not one of its "
                       f"orientations {list(self.orientations[k])}")

    # -- figures --------------------------------------------------------------------
    def summary(self) -> dict[str, Any]:
        """Counts over every entry: ``entries``, ``distinct`` (entries with different
        pieces' coordinates), ``holes``, ``exact_fits``, ``slides``, and the build's
        ``computed``, ``loaded`` and ``seconds``.

        Examples
        --------
        >>> import polycontact as pc
        >>> sq = pc.Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
        >>> s = pc.nfp_table([sq], progress=False).summary()
        >>> s["entries"], s["holes"], s["exact_fits"]
        (1, 0, 0)
        """
        holes = fits = slides = 0
        counted: dict[str, tuple[int, int, int]] = {}
        for key in self._entry_keys():
            c = counted.get(key)
            if c is None:
                rec = self._records[key]
                region = self._regions.get(key)
                if region is None:
                    region = self._regions[key] = shapely.from_wkb(rec.wkb)
                n_holes = sum(len(p.interiors) for p in shapely.get_parts(region))
                c = counted[key] = (n_holes, len(rec.exact_fits), len(rec.slides))
            holes += c[0]
            fits += c[1]
            slides += c[2]
        return {"entries": len(self), "distinct": len(counted), "holes": holes,
                "exact_fits": fits, "slides": slides, "computed": self.computed,
                "loaded": self.loaded, "seconds": self.seconds}

    def _entry_keys(self) -> Iterator[str]:
        slots = list(self._digests)
        for sa in slots:
            for sb in slots:
                yield _pair_key(self._digests[sa], self._digests[sb])

    # -- files ----------------------------------------------------------------------
    def save(self, directory: str | PathLike[str]) -> None:
        """Write the table into ``directory`` (the ``cache=`` format; entries already
        there are not written again)."""
        cache = Path(directory)
        have = _read_cache(cache)
        _write_manifest(cache, self.pieces, self.orientations, self.reference)
        todo = [(k, r) for k, r in self._records.items() if k not in have]
        if todo:
            _write_shard(cache, todo)

    @classmethod
    def load(cls, directory: str | PathLike[str]) -> NfpTable:
        """Read the table last built into ``directory`` (its ``table.json``).

        Entries the cache lacks (an interrupted build) raise KeyError on access;
        ``summary()`` needs them all.
        """
        cache = Path(directory)
        try:
            doc = load_json((cache / MANIFEST).read_bytes())
            if not isinstance(doc, dict) or _checksum(doc) != doc.get("blake2b"):
                raise ValueError("it does not match its checksum")
            pieces = tuple(Shape(p["vertices"], p["holes"]) for p in doc["pieces"])
            orientations = tuple(tuple(float(a) for a in o) for o in doc["orientations"])
            reference = doc["reference"]
        except (OSError, ValueError, KeyError, TypeError) as exc:
            raise ValueError(f"directory: {cache} holds no readable {MANIFEST}: {exc}") from None
        table = _prepare(pieces, orientations, reference)
        records = _read_cache(cache)
        wanted = set(table._entry_keys())
        table._records.update({k: r for k, r in records.items() if k in wanted})
        table.loaded = len(table._records)
        return table


def nfp_table(
    pieces: Any,
    orientations: Any = None,
    *,
    reference: str = "origin",
    cache: str | PathLike[str] | None = None,
    client: Any = None,
    progress: Progress = True,
    workers: int | None = None,
    chunk_size: int | None = None,
) -> NfpTable:
    """The no-fit polygon of every ordered pair of pieces at every orientation.

    Parameters
    ----------
    pieces : Instance or sequence of bodies
        The pieces (Shape, shapely Polygon or (N, 2) array each), or an
        :class:`~polycontact.esicup.Instance` (its orientations are then the default).
    orientations : sequence, optional
        The allowed angles in degrees: one list per piece, or one list for every
        piece. Default: the instance's, else 0 only.
    reference : {"origin", "centroid"}
        The orbiting piece's reference point: the origin of its coordinates (nesting
        convention), or the area centroid of the turned piece.
    cache : str or path-like, optional
        A directory to read entries from and write new ones to (created if needed).
    client : dask.distributed.Client, optional
        Run on this Dask cluster; by default the current Dask client if there is one.
    progress : bool or callable
        Show a progress bar (tqdm on stderr), or call ``progress(done, total)`` after
        each batch of entries.
    workers : int, optional
        Local processes when there is no Dask client (default: one per CPU, used only
        for at least :data:`PROCESS_POOL_MIN_ENTRIES` missing entries; 1: in this
        process).
    chunk_size : int, optional
        Entries per task (and per cache shard); default about a quarter of each
        worker's share, between 64 and 1024.

    Returns
    -------
    NfpTable

    Examples
    --------
    >>> import polycontact as pc
    >>> sq = pc.Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
    >>> t = pc.nfp_table([sq, sq], [[0], [0, 45]], progress=False)
    >>> len(t), round(t[0, 0, 1, 45].region.area, 6), t.summary()["distinct"]
    (9, 4.828427, 4)
    """
    start = time.perf_counter()
    if reference not in ("origin", "centroid"):
        raise ValueError(f"reference: expected 'origin' or 'centroid', got {reference!r}")
    shapes, angles = _pieces_and_orientations(pieces, orientations)
    for name, value in (("workers", workers), ("chunk_size", chunk_size)):
        if value is not None and (isinstance(value, bool) or not isinstance(value, int)
                                  or value < 1):
            raise ValueError(f"{name}: expected a positive integer, got {value!r}")
    table = _prepare(shapes, angles, reference)
    have: dict[str, _Record] = {}
    cache_dir = None if cache is None else Path(cache)
    if cache_dir is not None:
        have = _read_cache(cache_dir)
        _write_manifest(cache_dir, shapes, angles, reference)
    # the distinct missing entries, as pairs of slots
    todo: dict[str, tuple[tuple[int, int], tuple[int, int]]] = {}
    for sa in table._digests:
        for sb in table._digests:
            key = _pair_key(table._digests[sa], table._digests[sb])
            if key in have:
                table._records[key] = have[key]
            elif key not in todo:
                todo[key] = (sa, sb)
    table.loaded = len(table._records)
    if todo:
        _compute_missing(table, todo, cache_dir, client, progress, workers, chunk_size)
    table.seconds = time.perf_counter() - start
    return table


# -- building ----------------------------------------------------------------------------


def _pieces_and_orientations(
    pieces: Any, orientations: Any
) -> tuple[tuple[Shape, ...], tuple[tuple[float, ...], ...]]:
    if isinstance(pieces, Instance):
        if orientations is None:
            orientations = pieces.orientations
        pieces = pieces.pieces
    if isinstance(pieces, str | bytes) or not isinstance(pieces, Sequence | np.ndarray):
        raise ValueError(f"pieces: expected a sequence of bodies or an Instance, got "
                         f"{type(pieces).__name__}")
    shapes = tuple(as_shape(p, f"pieces[{k}]") for k, p in enumerate(pieces))
    if not shapes:
        raise ValueError("pieces: expected at least one piece, got none")
    if orientations is None:
        return shapes, tuple((0.0,) for _ in shapes)
    if isinstance(orientations, str | bytes) or not isinstance(orientations, Sequence
                                                                | np.ndarray):
        raise ValueError(f"orientations: expected a list of angles in degrees or one list "
                         f"per piece, got {type(orientations).__name__}")
    items = list(orientations)
    if items and all(_is_number(a) for a in items):
        items = [items] * len(shapes)
    if len(items) != len(shapes):
        raise ValueError(f"orientations: expected one list of angles per piece "
                         f"({len(shapes)}), got {len(items)}")
    out = []
    for k, angles in enumerate(items):
        if isinstance(angles, str | bytes) or not isinstance(angles, Sequence | np.ndarray) \
                or not len(angles) or not all(_is_number(a) for a in angles):
            raise ValueError(f"orientations[{k}]: expected a non-empty list of finite "
                             f"angles in degrees, got {angles!r}")
        vals = tuple(float(a) for a in angles)
        for m, a in enumerate(vals):
            if any(abs(math.remainder(a - b, 360.0)) <= ANGLE_MATCH for b in vals[:m]):
                raise ValueError(f"orientations[{k}]: angle {a} is repeated (modulo 360)")
        out.append(vals)
    return shapes, tuple(out)


def _is_number(a: Any) -> bool:
    if isinstance(a, bool) or not isinstance(a, int | float | np.integer | np.floating):
        return False
    try:
        return math.isfinite(float(a))
    except OverflowError:  # an integer beyond float64
        return False


def _prepare(pieces: tuple[Shape, ...], orientations: tuple[tuple[float, ...], ...],
             reference: str) -> NfpTable:
    """A table without entries: the turned pieces and their digests."""
    shapes: dict[tuple[int, int], Shape] = {}
    digests: dict[tuple[int, int], bytes] = {}
    prefix = f"{FORMAT}/{FORMAT_VERSION}/{__version__}/{reference}/".encode()
    for i, (piece, angles) in enumerate(zip(pieces, orientations)):
        for k, a in enumerate(angles):
            s = turned(piece, a)
            xy, starts = s.packed
            h = hashlib.blake2b(prefix, digest_size=16)
            h.update(np.ascontiguousarray(xy, dtype="<f8").tobytes())
            h.update(np.ascontiguousarray(starts, dtype="<i8").tobytes())
            shapes[i, k] = s
            digests[i, k] = h.digest()
    return NfpTable(pieces, orientations, reference, shapes, digests, {})


def _pair_key(da: bytes, db: bytes) -> str:
    return hashlib.blake2b(da + db, digest_size=16).hexdigest()


def _compute_chunk(shapes: Sequence[Shape], pairs: np.ndarray, reference: str) -> Packed:
    """Compute the NFPs of ``pairs`` (rows of indices into ``shapes``), packed in a few
    flat arrays (a task's result crosses the network quicker so than as many small
    objects): the regions' WKB one after the other, their ends, the exact fits and
    slides with their ends per entry, the references and the tolerances."""
    wkbs, fits, slides, refs, tols = [], [], [], [], []
    for ia, ib in pairs.tolist():
        nfp = no_fit_polygon(shapes[ia], shapes[ib], reference)
        wkbs.append(shapely.to_wkb(nfp.region, byte_order=1, include_srid=False))
        fits.append(nfp.exact_fits.reshape(-1, 2))
        slides.append(nfp.slides.reshape(-1, 2, 2))
        refs.append(nfp.reference)
        tols.append(float(nfp.tolerance))
    return (b"".join(wkbs), np.cumsum([len(w) for w in wkbs], dtype=np.int64),
            np.concatenate(fits), np.cumsum([len(f) for f in fits], dtype=np.int64),
            np.concatenate(slides), np.cumsum([len(x) for x in slides], dtype=np.int64),
            np.array(refs, dtype=np.float64).reshape(-1, 2), np.array(tols, dtype=np.float64))


def _unpack_chunk(packed: Packed) -> list[_Record]:
    """The records of a result of :func:`_compute_chunk`."""
    blob, wkb_ends, fits, fit_ends, slides, slide_ends, refs, tols = packed
    out = []
    w0 = f0 = s0 = 0
    for k in range(len(tols)):
        w1, f1, s1 = int(wkb_ends[k]), int(fit_ends[k]), int(slide_ends[k])
        out.append(_Record(blob[w0:w1], fits[f0:f1].copy(), slides[s0:s1].copy(),
                           refs[k].copy(), float(tols[k])))
        w0, f0, s0 = w1, f1, s1
    return out


def _chunks(count: int, workers: int, chunk_size: int | None) -> list[tuple[int, int]]:
    if chunk_size is None:
        chunk_size = min(1024, max(64, math.ceil(count / (4 * workers))))
    return [(p, min(count, p + chunk_size)) for p in range(0, count, chunk_size)]


def _compute_missing(
    table: NfpTable, todo: dict[str, tuple[tuple[int, int], tuple[int, int]]],
    cache_dir: Path | None, client: Any, progress: Progress,
    workers: int | None, chunk_size: int | None,
) -> None:
    from .distributed import current_client

    client = current_client(client)
    # the distinct shapes the missing entries need, and the pairs as indices into them
    index: dict[tuple[int, int], int] = {}
    for sa, sb in todo.values():
        index.setdefault(sa, len(index))
        index.setdefault(sb, len(index))
    shapes = [table._shapes[slot] for slot in index]  # numbered in insertion order
    keys = list(todo)
    pairs = np.array([(index[sa], index[sb]) for sa, sb in todo.values()], dtype=np.int64)
    if client is not None:
        n_workers = max(1, sum(client.nthreads().values()))  # every thread of every worker
    else:
        n_workers = workers or os.cpu_count() or 1
        if workers is None and len(keys) < PROCESS_POOL_MIN_ENTRIES:
            n_workers = 1
    spans = _chunks(len(keys), n_workers, chunk_size)
    tasks = [pairs[p0:p1] for p0, p1 in spans]
    results: Generator[tuple[int, Packed], None, None]
    if client is not None:
        from .distributed import run_tasks

        results = run_tasks(client, _compute_chunk, shapes, tasks, table.reference,
                            families=["no-fit polygon"])
    elif n_workers > 1:
        results = _run_processes(n_workers, shapes, tasks, table.reference)
    else:
        results = ((k, _compute_chunk(shapes, t, table.reference)) for k, t in enumerate(tasks))
    bar = _progress_bar(progress, len(keys))
    done = 0
    try:
        with closing(results):
            for k, packed in results:
                p0, p1 = spans[k]
                recs = list(zip(keys[p0:p1], _unpack_chunk(packed)))
                if cache_dir is not None:
                    _write_shard(cache_dir, recs)
                table._records.update(recs)
                table.computed += len(recs)
                done += p1 - p0
                if callable(progress):
                    progress(done, len(keys))
                elif bar is not None:
                    bar.update(p1 - p0)
    finally:
        if bar is not None:
            bar.close()


def _progress_bar(progress: Progress, total: int) -> Any:
    if progress is not True:
        return None
    from tqdm.auto import tqdm

    return tqdm(total=total, unit="NFP", desc="NFP table", file=sys.stderr, smoothing=0.1)


_WORKER_SHAPES: list[Shape] = []


def _init_process(shapes: list[Shape]) -> None:
    """A local worker process: Ctrl-C is the parent's to handle; it ends when its parent
    does (:func:`_exit_with_parent`); kernels loaded once."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    parent = multiprocessing.parent_process()
    if parent is not None:
        threading.Thread(target=_exit_with_parent, args=(parent.sentinel,), daemon=True,
                         name="polycontact-parent-watch").start()
    from .compiling import warmup

    warmup(["no-fit polygon"])
    _WORKER_SHAPES[:] = shapes


def _exit_with_parent(sentinel: int) -> None:
    """Wait until the parent process is gone, then end this worker at once.

    A worker blocked on its task queue never learns that the parent was killed (the
    queue's pipe stays open: the worker holds both of its ends), and neither does the
    resource tracker the workers keep alive; the parent's sentinel, which the spawned
    process holds, becomes ready when the parent dies however it dies (SIGKILL
    included)."""
    multiprocessing.connection.wait([sentinel])
    os._exit(1)


def _process_task(pairs: np.ndarray, reference: str) -> Packed:
    return _compute_chunk(_WORKER_SHAPES, pairs, reference)


def _run_processes(
    n: int, shapes: list[Shape], tasks: list[np.ndarray], reference: str
) -> Generator[tuple[int, Packed], None, None]:
    """Run the tasks on ``n`` spawned processes; yield (task index, result) as they end."""
    pool = ProcessPoolExecutor(n, mp_context=multiprocessing.get_context("spawn"),
                               initializer=_init_process, initargs=(shapes,))
    try:
        futures = {pool.submit(_process_task, t, reference): k for k, t in enumerate(tasks)}
        pending = set(futures)
        while pending:
            finished, pending = wait(pending, return_when=FIRST_COMPLETED)
            for f in finished:
                try:
                    result = f.result()
                except BrokenProcessPool:
                    raise RuntimeError(
                        "the local worker processes of nfp_table stopped: a script that "
                        "builds a large table must guard its entry point with "
                        "`if __name__ == '__main__':` (processes are spawned), or pass "
                        "workers=1") from None
                yield futures[f], result
    finally:
        pool.shutdown(wait=False, cancel_futures=True)


# -- the cache files ---------------------------------------------------------------------


def _atomic_write(path: Path, data: bytes) -> None:
    """Write ``data`` to ``path`` through a temporary file and a rename."""
    tmp = path.with_name(f".{path.name}.{uuid.uuid4().hex}.tmp")
    try:
        with open(tmp, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()


def _manifest(pieces: tuple[Shape, ...], orientations: tuple[tuple[float, ...], ...],
              reference: str) -> bytes:
    """The bytes of ``table.json``: the build's pieces, orientations and reference, and a
    checksum of them (:func:`_checksum`)."""
    doc: dict[str, Any] = {
        "format": FORMAT, "format_version": FORMAT_VERSION, "polycontact": __version__,
        "reference": reference,
        "pieces": [{"vertices": p.exterior.tolist(), "holes": [h.tolist() for h in p.holes]}
                   for p in pieces],
        "orientations": [list(o) for o in orientations]}
    doc["blake2b"] = _checksum(doc)
    return json.dumps(doc).encode()


def _write_manifest(cache: Path, pieces: tuple[Shape, ...],
                    orientations: tuple[tuple[float, ...], ...], reference: str) -> None:
    """Write ``table.json`` (and make the folders), unless it holds these bytes already:
    a build that finds every entry in a read-only cache writes nothing."""
    if cache.exists() and not cache.is_dir():
        raise ValueError(f"cache: {cache} is not a directory")
    data = _manifest(pieces, orientations, reference)
    try:
        if (cache / MANIFEST).read_bytes() == data and (cache / SHARDS).is_dir():
            return
    except OSError:
        pass
    (cache / SHARDS).mkdir(parents=True, exist_ok=True)
    _atomic_write(cache / MANIFEST, data)


def _checksum(doc: dict[str, Any], blob: bytes = b"") -> str:
    """BLAKE2 of ``blob`` and of ``doc``'s JSON without its ``blake2b`` key, keys sorted:
    every value of the document (numbers round-trip exactly), so that a changed byte of
    either, a swapped byte range or an edited number included, is a mismatch."""
    h = hashlib.blake2b(blob)
    h.update(json.dumps({k: v for k, v in doc.items() if k != "blake2b"},
                        sort_keys=True).encode())
    return h.hexdigest()


def _write_shard(cache: Path, records: list[tuple[str, _Record]]) -> None:
    """Write one shard: its ``.wkb``, then its ``.json`` index (which commits it)."""
    folder = cache / SHARDS
    folder.mkdir(parents=True, exist_ok=True)
    stem = f"{time.time_ns():x}-{os.getpid()}-{uuid.uuid4().hex[:8]}"
    blob = b"".join(r.wkb for _, r in records)
    entries = []
    offset = 0
    for key, r in records:
        entries.append({"key": key, "offset": offset, "length": len(r.wkb),
                        "reference": r.reference.tolist(), "tolerance": r.tolerance,
                        "exact_fits": r.exact_fits.tolist(), "slides": r.slides.tolist()})
        offset += len(r.wkb)
    index: dict[str, Any] = {"format": FORMAT, "format_version": FORMAT_VERSION,
                             "wkb": f"{stem}.wkb", "wkb_bytes": len(blob), "entries": entries}
    index["blake2b"] = _checksum(index, blob)
    _atomic_write(folder / f"{stem}.wkb", blob)
    _atomic_write(folder / f"{stem}.json", json.dumps(index).encode())


def _read_cache(cache: Path) -> dict[str, _Record]:
    """Every entry of the committed shards of ``cache`` (empty if there is none). A
    shard that cannot be read, or whose index or regions do not match its checksum, is
    skipped with a :class:`CacheWarning` (its entries are recomputed)."""
    folder = cache / SHARDS
    if not folder.is_dir():
        return {}
    out: dict[str, _Record] = {}
    for index_path in sorted(folder.glob("[!.]*.json")):
        try:
            out.update(_read_shard(folder, index_path))
        except Exception as exc:  # noqa: BLE001 - whatever is wrong, the shard is damaged
            warnings.warn(f"NFP cache: ignoring shard {index_path} ({exc}); its entries are "
                          "recomputed", CacheWarning, stacklevel=3)
    return out


def _read_shard(folder: Path, index_path: Path) -> list[tuple[str, _Record]]:
    """The entries of one shard; a ValueError (or OSError) saying why it is refused.
    Another format's shard (not ours to read) has none."""
    index = load_json(index_path.read_bytes())
    if not isinstance(index, dict):
        raise ValueError("the index is not a JSON object")
    if index.get("format") != FORMAT or index.get("format_version") != FORMAT_VERSION:
        return []
    name = index.get("wkb")
    if not isinstance(name, str) or Path(name).name != name or not name.endswith(".wkb"):
        raise ValueError(f"the index names no .wkb file of this folder ({name!r})")
    blob = (folder / name).read_bytes()
    if index.get("wkb_bytes") != len(blob) or _checksum(index, blob) != index.get("blake2b"):
        raise ValueError("the shard does not match its checksum")
    entries = index.get("entries")
    if not isinstance(entries, list):
        raise ValueError("'entries' is not a list")
    return [_entry(e, blob) for e in entries]


def _entry(e: Any, blob: bytes) -> tuple[str, _Record]:
    """One entry of a shard's index (checked: the checksum passed, but nothing of it may
    crash a build), as ``(key, record)``."""
    if not isinstance(e, dict):
        raise ValueError("an entry is not a JSON object")
    key, offset, length = e.get("key"), e.get("offset"), e.get("length")
    if not (isinstance(key, str) and isinstance(offset, int) and isinstance(length, int)
            and 0 <= offset <= offset + length <= len(blob)):
        raise ValueError(f"entry {key!r}: bad key or byte range")
    fits = np.array(e.get("exact_fits"), dtype=np.float64).reshape(-1, 2)
    slides = np.array(e.get("slides"), dtype=np.float64).reshape(-1, 2, 2)
    reference = np.array(e.get("reference"), dtype=np.float64)
    tolerance = float(e["tolerance"])
    if reference.shape != (2,) or not (np.isfinite(reference).all() and tolerance > 0.0):
        raise ValueError(f"entry {key!r}: bad reference or tolerance")
    return key, _Record(blob[offset:offset + length], fits, slides, reference, tolerance)
