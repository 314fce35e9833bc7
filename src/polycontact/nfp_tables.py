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

**Parallel runs.** The no-fit polygon of two pieces without holes is computed, with its
region's WKB, exact fits and slides, in compiled code that releases the GIL
(:mod:`polycontact._kernels.nfp_batch`): a local build shares the missing entries among
threads (``threads=``, by the threading policy of :doc:`conventions`), in chunks of
``chunk_size`` entries. The entries it leaves to :func:`polycontact.no_fit_polygon`
(pieces with holes, rings too large for ear clipping) hold the GIL; only when they are
most of the work measured on a first chunk, and each process's share of that work
outweighs its start (:data:`PROCESS_START`), does the build use a pool of processes
instead: at most ``workers`` of them (by default ``threads``), as many as have that
much work each. ``workers`` is a bound, not a command: a build that processes would not
speed up runs on threads whatever ``workers`` says, so ``workers=16`` on pieces without
holes scales as 16 threads do, and ``workers=1`` keeps the build in this process (on
its threads). The pool is started once, after the kernels are compiled here, so the
processes load them and never compile. This process works alongside the pool, from the
other end of the tasks, and computes the tasks of processes that are slow to start (or
stop) itself, so that processes never make a build much slower than this process
alone. The processes are spawned (as on macOS and Windows), and a spawned process runs
the main script's top-level code again: a build called from there, outside an ``if
__name__ == "__main__":`` block, runs on threads instead (with a warning when it was
given ``workers`` and would have started processes), since each process would
otherwise start the build again. With ``client=`` (a ``dask.distributed.Client``), or
when called where a Dask client is the default, the missing entries run as tasks on the
cluster (:mod:`polycontact.distributed`), each of at least
:data:`~polycontact.limits.TASK_SECONDS` of work as measured on a first task, up to
four per worker thread in whole rounds, the pieces sent to every worker once; the
client writes the shards as results arrive.

Examples
--------
>>> import polycontact as pc
>>> ell = pc.Shape([(0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)])
>>> table = pc.nfp_table([ell], [[0, 90]], progress=False)
>>> len(table), table[0, 90, 0, 0].region.area
(4, 14.0)
"""

from __future__ import annotations

import ast
import bisect
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
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from contextlib import closing
from dataclasses import dataclass
from os import PathLike
from pathlib import Path
from types import FrameType
from typing import Any

import numpy as np
import shapely

from . import __version__
from ._json import load_json
from .esicup import Instance, turned, turned_loops
from .nfp import NoFitPolygon, no_fit_polygon
from .shape import Shape, as_shape
from ._threads import requested

__all__ = ["NfpTable", "nfp_table", "CacheWarning", "PROCESS_START"]

#: Name and version of the on-disk format.
FORMAT = "polycontact-nfp-table"
FORMAT_VERSION = 2
MANIFEST = "table.json"
SHARDS = "shards"

#: What starting one local worker process costs (seconds: the interpreter, the imports
#: and loading the compiled kernels from the cache): a build uses processes only where
#: each has more work than this.
PROCESS_START = 1.0

#: Entries of the first chunk, computed in the calling process (or as the first Dask
#: task) to measure the work per entry before the others are sized.
PROBE_ENTRIES = 256

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
        packed: dict[tuple[int, int], tuple[np.ndarray, np.ndarray]],
        shapes: dict[tuple[int, int], Shape],
        digests: dict[tuple[int, int], bytes],
    ) -> None:
        self.pieces = pieces
        self.orientations = orientations
        self.reference = reference
        self._packed = packed  # each slot's turned piece, as Shape.packed
        self._shapes = shapes  # the turned pieces made Shapes so far
        self._digests = digests
        # An entry is a pair of distinct turned pieces (digests): its code is
        # ``ia * D + ib``, ia and ib the digests' numbers, D how many there are.
        numbers: dict[bytes, int] = {}
        self._number: dict[tuple[int, int], int] = {}
        self._first: list[tuple[int, int]] = []  # a slot of each digest
        for slot, d in digests.items():
            if d not in numbers:
                numbers[d] = len(numbers)
                self._first.append(slot)
            self._number[slot] = numbers[d]
        self._distinct = list(numbers)  # each digest once, in the order of their numbers
        n = len(self._distinct)
        self._records: dict[int, _Record] = {}
        # entries of this build, unpacked on first use: their number in the build (-1:
        # none), and the computed chunks with the number of their first entry
        self._where = np.full(n * n, -1, np.int64)
        self._chunks: list[_Stored] = []
        self._chunk_starts: list[int] = []
        self._regions: dict[int, Any] = {}
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
        code = self._number[sa] * len(self._distinct) + self._number[sb]
        rec = self._record(code)
        if rec is None:
            raise KeyError(f"entry {index!r} is not in the table (a load of an incomplete "
                           "cache); build it with nfp_table(..., cache=DIR)")
        region = self._regions.get(code)
        if region is None:
            region = self._regions[code] = shapely.from_wkb(rec.wkb)
        return NoFitPolygon(region, rec.exact_fits, rec.slides, rec.reference,
                            self._shape(sa), self._shape(sb), rec.tolerance)

    def _shape(self, slot: tuple[int, int]) -> Shape:
        """The turned piece of ``slot`` (piece, orientation number), made on first use."""
        shape = self._shapes.get(slot)
        if shape is None:
            i, k = slot
            shape = self._shapes[slot] = turned(self.pieces[i], self.orientations[i][k])
        return shape

    def _key(self, code: int) -> str:
        """The cache key of entry ``code``."""
        n = len(self._distinct)
        return _pair_key(self._distinct[code // n], self._distinct[code % n])

    def _record(self, code: int) -> _Record | None:
        """The stored entry ``code`` (None if the table lacks it); an entry computed by
        this build is unpacked from its chunk's arrays on first use."""
        rec = self._records.get(code)
        if rec is None and self._where[code] >= 0:
            k = int(self._where[code])
            c = bisect.bisect_right(self._chunk_starts, k) - 1
            rec = self._records[code] = self._chunks[c].record(k - self._chunk_starts[c])
        return rec

    def _store(self, codes: np.ndarray, chunk: _Stored) -> None:
        """Take the computed entries ``codes``, in the order of ``chunk``."""
        start = self._chunk_starts[-1] + len(self._chunks[-1]) if self._chunks else 0
        self._chunks.append(chunk)
        self._chunk_starts.append(start)
        self._where[codes] = np.arange(start, start + len(codes))
        self.computed += len(codes)

    def _known(self) -> list[int]:
        """The codes of the entries the table holds."""
        return sorted({*self._records, *np.flatnonzero(self._where >= 0).tolist()})

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
        counted: dict[int, tuple[int, int, int]] = {}
        n = len(self._distinct)
        numbers = list(self._number.values())
        for code in (a * n + b for a in numbers for b in numbers):
            c = counted.get(code)
            if c is None:
                rec = self._record(code)
                assert rec is not None
                region = self._regions.get(code)
                if region is None:
                    region = self._regions[code] = shapely.from_wkb(rec.wkb)
                n_holes = sum(len(p.interiors) for p in shapely.get_parts(region))
                c = counted[code] = (n_holes, len(rec.exact_fits), len(rec.slides))
            holes += c[0]
            fits += c[1]
            slides += c[2]
        return {"entries": len(self), "distinct": len(counted), "holes": holes,
                "exact_fits": fits, "slides": slides, "computed": self.computed,
                "loaded": self.loaded, "seconds": self.seconds}

    # -- files ----------------------------------------------------------------------
    def save(self, directory: str | PathLike[str]) -> None:
        """Write the table into ``directory`` (the ``cache=`` format; entries already
        there are not written again)."""
        cache = Path(directory)
        have = _read_cache(cache)
        _write_manifest(cache, self.pieces, self.orientations, self.reference)
        todo = [(key, r) for code in self._known() for key in [self._key(code)]
                if key not in have for r in [self._record(code)] if r is not None]
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
        table._take_cached(_read_cache(cache))
        return table

    def _take_cached(self, records: dict[str, _Record]) -> np.ndarray:
        """Take this table's entries among ``records`` (cache keys to records); the
        codes of the entries they lack."""
        missing = []
        for code in range(len(self._where)):
            rec = records.get(self._key(code))
            if rec is None:
                missing.append(code)
            else:
                self._records[code] = rec
        self.loaded = len(self._records)
        return np.array(missing, np.int64)


def nfp_table(
    pieces: Any,
    orientations: Any = None,
    *,
    reference: str = "origin",
    cache: str | PathLike[str] | None = None,
    client: Any = None,
    progress: Progress = True,
    workers: int | None = None,
    threads: int | None = None,
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
        The most local processes when there is no Dask client (besides this process,
        which works alongside them; default: ``threads``). Processes are started only
        where they pay: most of the work, measured on a first chunk, holds the GIL
        (pieces with holes, large rings) and each process has more of it than its start
        costs (:data:`PROCESS_START`); otherwise the build runs on threads (``threads``),
        so no value makes it slower than this process alone. 1: in this process only.
    threads : int, optional
        Threads of a local build (default and meaning: the threading policy of
        :doc:`conventions`: at most ``numba.get_num_threads()``, and no more than the
        work can use).
    chunk_size : int, optional
        Entries per task (and per cache shard); default about a quarter of each
        thread's or process's share, between 64 and 1024, and on a cluster at least
        :data:`~polycontact.limits.TASK_SECONDS` of work.

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
    n_threads = requested(threads)
    for name, value in (("workers", workers), ("chunk_size", chunk_size)):
        if value is not None and (isinstance(value, bool) or not isinstance(value, int)
                                  or value < 1):
            raise ValueError(f"{name}: expected a positive integer, got {value!r}")
    table = _prepare(shapes, angles, reference)
    cache_dir = None if cache is None else Path(cache)
    if cache_dir is not None:
        todo = table._take_cached(_read_cache(cache_dir))
        _write_manifest(cache_dir, shapes, angles, reference)
    else:
        todo = np.arange(len(table._where), dtype=np.int64)
    if len(todo):
        _compute_missing(table, todo, cache_dir, client, progress, workers, n_threads,
                         chunk_size)
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
    """A table without entries: the turned pieces, packed, and their digests.

    The turned pieces of one loop are checked together in one compiled call
    (:func:`polycontact._kernels.relation_many.check_rings`); one it takes as given
    (counter-clockwise, no vertex dropped) is what :func:`~polycontact.esicup.turned`
    would store, and its Shape is made only when asked for. Any other turned piece is
    made a Shape here, checked (or refused) as ``turned`` does."""
    from ._kernels.relation_many import check_rings
    from .limits import COORDINATE_LIMIT, EXTENT_FLOOR, RELATIVE_TOLERANCE, ROUNDING_ULPS

    packed: dict[tuple[int, int], tuple[np.ndarray, np.ndarray]] = {}
    shapes: dict[tuple[int, int], Shape] = {}
    rings: dict[tuple[int, int], np.ndarray] = {}
    for i, (piece, angles) in enumerate(zip(pieces, orientations)):
        for k, a in enumerate(angles):
            loops = turned_loops(piece, a)
            if loops is not None and len(loops) == 1:
                rings[i, k] = loops[0]
            else:
                shapes[i, k] = piece if loops is None else Shape(loops[0], loops[1:])
    if rings:
        n = np.array([len(r) for r in rings.values()], np.int64)
        used, sign = check_rings(np.concatenate(list(rings.values())),
                                 np.cumsum(n) - n, n, RELATIVE_TOLERANCE, ROUNDING_ULPS,
                                 COORDINATE_LIMIT, EXTENT_FLOOR)
        for (slot, ring), u, m, sg in zip(rings.items(), used.tolist(), n.tolist(),
                                          sign.tolist()):
            if u == m and sg > 0.0:
                starts = np.array([0, m], np.int64)
                packed[slot] = (ring, starts)
            else:
                i, k = slot
                shapes[slot] = turned(pieces[i], orientations[i][k])
    packed.update({slot: shape.packed for slot, shape in shapes.items()})
    digests: dict[tuple[int, int], bytes] = {}
    prefix = f"{FORMAT}/{FORMAT_VERSION}/{__version__}/{reference}/".encode()
    for i, angles in enumerate(orientations):
        for k in range(len(angles)):
            xy, starts = packed[i, k]
            h = hashlib.blake2b(prefix, digest_size=16)
            h.update(np.ascontiguousarray(xy, dtype="<f8").tobytes())
            h.update(np.ascontiguousarray(starts, dtype="<i8").tobytes())
            digests[i, k] = h.digest()
    return NfpTable(pieces, orientations, reference, packed, shapes, digests)


def _pair_key(da: bytes, db: bytes) -> str:
    return hashlib.blake2b(da + db, digest_size=16).hexdigest()


class _Pieces:
    """The distinct turned pieces of a build, packed as
    :func:`polycontact._kernels.nfp_batch.nfp_pairs` reads them (made once per build,
    sent once to every worker), with what the kernel needs of each: its largest
    |coordinate| and the larger side of its box (computed as :class:`~polycontact.Shape`
    computes them), and the reference points (``centroids``: the pieces' area
    centroids, or None for the origin)."""

    def __init__(self, packs: Sequence[tuple[np.ndarray, np.ndarray]],
                 centroids: np.ndarray | None) -> None:
        rows = np.array([0, *np.cumsum([len(xy) for xy, _ in packs])], np.int64)
        self.xy = (np.ascontiguousarray(np.concatenate([xy for xy, _ in packs]))
                   if packs else np.empty((0, 2)))
        self.ls = np.concatenate([st + rows[k] for k, (_, st) in enumerate(packs)]
                                 + [np.empty(0, np.int64)])
        self.nl = np.array([len(st) - 1 for _, st in packs], np.int64)
        self.lo = np.concatenate([[0], np.cumsum(self.nl + 1)]).astype(np.int64)
        first = rows[:-1]
        lo = np.minimum.reduceat(self.xy, first) if packs else np.empty((0, 2))
        hi = np.maximum.reduceat(self.xy, first) if packs else np.empty((0, 2))
        self.extent = np.maximum(hi[:, 0] - lo[:, 0], hi[:, 1] - lo[:, 1])
        self.magnitude = np.maximum(-lo.min(axis=1, initial=np.inf),
                                    hi.max(axis=1, initial=-np.inf))
        self.centroids = centroids

    def shape(self, k: int) -> Shape:
        """Piece ``k`` as a Shape (its loops as packed: checked already)."""
        st = self.ls[self.lo[k]:self.lo[k + 1]]
        return Shape._trusted([self.xy[st[q]:st[q + 1]] for q in range(len(st) - 1)])


def _compute_chunk(pieces: _Pieces, pairs: np.ndarray, reference: str) -> Packed:
    """:func:`_compute`'s entries."""
    return _compute(pieces, pairs, reference)[0]


def _compute(pieces: _Pieces, pairs: np.ndarray, reference: str) -> tuple[Packed, float]:
    """Compute the NFPs of ``pairs`` (rows of indices into the pieces), packed in a few
    flat arrays (a task's result crosses the network quicker so than as many small
    objects): the regions' WKB one after the other, their ends, the exact fits and
    slides with their ends per entry, the references and the tolerances.

    The compiled batch (:func:`polycontact._kernels.nfp_batch.nfp_pairs`, without the
    GIL) computes what it can; the entries it leaves go through
    :func:`polycontact.no_fit_polygon`, which gives the same answers. Returns the
    packed entries and the seconds spent on those (holding the GIL)."""
    from ._kernels.nfp_batch import nfp_pairs
    from . import limits
    from .limits import (ANGLE_TOLERANCE, EAR_CLIPPING_MAX, HOLE_WIDTH_FACTOR,
                         RELATIVE_TOLERANCE, ROUNDING_ULPS, SNAP_FACTOR)

    pairs = np.ascontiguousarray(pairs, dtype=np.int64)
    if pieces.centroids is None:
        refs = np.zeros((len(pairs), 2))
    else:
        refs = np.ascontiguousarray(pieces.centroids[pairs[:, 0]])
    settings = (RELATIVE_TOLERANCE, ROUNDING_ULPS, ANGLE_TOLERANCE, SNAP_FACTOR,
                HOLE_WIDTH_FACTOR, EAR_CLIPPING_MAX, limits.MAX_SUM_VERTICES, limits.MAX_CLIP_TESTS,
                reference == "origin")
    blob, wkb_ends, fits, fit_ends, slides, slide_ends, tols, flagged = nfp_pairs(
        (pieces.xy, pieces.ls, pieces.lo, pieces.nl, pieces.magnitude, pieces.extent),
        pairs, refs, settings)
    data: list[np.ndarray] = [blob, fits, slides]
    ends = [wkb_ends, fit_ends, slide_ends]
    t0 = time.perf_counter()
    if len(flagged):
        made = [no_fit_polygon(pieces.shape(ia), pieces.shape(ib), reference)
                for ia, ib in pairs[flagged].tolist()]
        parts = ([np.frombuffer(shapely.to_wkb(n.region, byte_order=1, include_srid=False),
                                np.uint8) for n in made],
                 [n.exact_fits.reshape(-1, 2) for n in made],
                 [n.slides.reshape(-1, 2, 2) for n in made])
        for f, got in enumerate(parts):
            data[f], ends[f] = _splice(data[f], ends[f], flagged, got)
        tols[flagged] = [n.tolerance for n in made]
        refs[flagged] = [n.reference for n in made]
    return ((data[0].tobytes(), ends[0], data[1], ends[1], data[2], ends[2], refs, tols),
            time.perf_counter() - t0 if len(flagged) else 0.0)


def _splice(data: np.ndarray, ends: np.ndarray, at: np.ndarray,
            parts: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """Entries ``at`` (empty in ``data``, whose entry k ends at ``ends[k]``) replaced by
    ``parts``; the new data and ends.

    >>> d, e = _splice(np.array([1, 2, 3]), np.array([2, 2, 3]), np.array([1]),
    ...                [np.array([7, 7])])
    >>> d.tolist(), e.tolist()
    ([1, 2, 7, 7, 3], [2, 4, 5])
    """
    lengths = np.diff(ends, prepend=0)
    lengths[at] = [len(p) for p in parts]
    ours = np.ones(len(ends), bool)
    ours[at] = False
    mask = np.repeat(ours, lengths)
    out = np.empty((len(mask), *data.shape[1:]), data.dtype)
    out[mask] = data
    out[~mask] = np.concatenate(parts)
    return out, np.cumsum(lengths)


class _Stored:
    """The entries of one computed chunk (a :data:`Packed`), unpacked into records one
    by one on first use (a table of many entries never makes the records it is not
    asked for)."""

    def __init__(self, packed: Packed) -> None:
        self.packed = packed

    def __len__(self) -> int:
        return len(self.packed[7])

    def record(self, k: int) -> _Record:
        """The record of entry ``k``."""
        blob, wkb_ends, fits, fit_ends, slides, slide_ends, refs, tols = self.packed
        w0, f0, s0 = ((0, 0, 0) if k == 0 else
                      (int(wkb_ends[k - 1]), int(fit_ends[k - 1]), int(slide_ends[k - 1])))
        return _Record(blob[w0:int(wkb_ends[k])], fits[f0:int(fit_ends[k])].copy(),
                       slides[s0:int(slide_ends[k])].copy(), refs[k].copy(), float(tols[k]))


def _spans(start: int, count: int, size: int) -> list[tuple[int, int]]:
    return [(p, min(count, p + size)) for p in range(start, count, size)]


def _compute_missing(
    table: NfpTable, todo: np.ndarray, cache_dir: Path | None, client: Any,
    progress: Progress, workers: int | None, threads: int, chunk_size: int | None,
) -> None:
    """Compute the entries ``todo`` (codes) of ``table``, writing the cache's shards as
    they come."""
    from ._cluster import current_client

    client = current_client(client)
    # the distinct turned pieces the missing entries need, and the pairs of them
    n = len(table._distinct)
    ia, ib = todo // n, todo % n
    used = np.unique(np.concatenate([ia, ib]))
    local = np.full(n, -1, np.int64)
    local[used] = np.arange(len(used))
    slots = [table._first[d] for d in used.tolist()]
    pieces = _Pieces([table._packed[slot] for slot in slots], None if table.reference ==
                     "origin" else np.array([table._shape(slot).centroid for slot in slots]))
    pairs = np.stack([local[ia], local[ib]], axis=1)
    count = len(todo)
    bar = _progress_bar(progress, count)
    done = 0

    def take(p0: int, p1: int, packed: Packed) -> None:
        nonlocal done
        stored = _Stored(packed)
        if cache_dir is not None:
            _write_shard(cache_dir, [(table._key(code), stored.record(k))
                                     for k, code in enumerate(todo[p0:p1].tolist())])
        table._store(todo[p0:p1], stored)
        done += p1 - p0
        if callable(progress):
            progress(done, count)
        elif bar is not None:
            bar.update(p1 - p0)

    results: Generator[tuple[int, int, Packed], None, None]
    try:
        if client is not None:
            from ._cluster import run_spans

            def tasks_of(spans: list[tuple[int, int]]) -> tuple[_Pieces, list[np.ndarray]]:
                return pieces, [pairs[p0:p1] for p0, p1 in spans]

            results = run_spans(client, _compute_chunk, count, tasks_of, table.reference,
                                chunk_size=chunk_size, family="no-fit polygon table")
        else:
            results = _local(pieces, pairs, table.reference, workers, threads, chunk_size)
        with closing(results):
            for p0, p1, packed in results:
                take(p0, p1, packed)
    finally:
        if bar is not None:
            bar.close()


def _local(pieces: _Pieces, pairs: np.ndarray, reference: str, workers: int | None,
           threads: int, chunk_size: int | None) -> Generator[tuple[int, int, Packed], None, None]:
    """The entries of ``pairs`` computed here, as ``(p0, p1, packed)`` spans as they
    finish: a first chunk here (which compiles the kernels before any process starts)
    measures the work and how much of it holds the GIL, which decides between threads
    and processes, at most ``workers`` of them (by default ``threads``), by
    :func:`_processes_that_pay` (see the module's docstring)."""
    from ._threads import as_done, useful

    count = len(pairs)
    first = min(count, chunk_size or PROBE_ENTRIES)
    _compute(pieces, pairs[:0], reference)  # loads the kernels: the probe times the work
    t0 = time.perf_counter()
    packed, gil_seconds = _compute(pieces, pairs[:first], reference)
    seconds = time.perf_counter() - t0
    yield 0, first, packed
    rest = count - first
    n_proc = _processes_that_pay(threads if workers is None else workers,
                                 gil_seconds / seconds if seconds > 0.0 else 0.0,
                                 gil_seconds / first * rest)
    if n_proc > 1 and _spawn_reruns_caller():
        if workers is not None:
            warnings.warn(
                f"nfp_table: workers={workers} runs on threads: it is called from a "
                "script's top-level code, which spawned processes would run again (put "
                "the call under `if __name__ == '__main__':` to use processes)",
                RuntimeWarning, stacklevel=4)
        n_proc = 1
    n_threads = 1 if n_proc > 1 else useful(threads, seconds / first * rest)
    size = chunk_size or min(1024, max(64, math.ceil(rest / (4 * max(n_proc, n_threads)))))
    spans = _spans(first, count, size)
    tasks = [pairs[p0:p1] for p0, p1 in spans]
    results: Iterator[tuple[int, Packed]]
    if n_proc > 1:
        results = _run_processes(n_proc, pieces, tasks, reference)
    else:
        results = as_done(lambda t: _compute_chunk(pieces, t, reference), tasks, n_threads)
    with closing(results):  # type: ignore[type-var]
        for k, got in results:
            yield *spans[k], got


def _processes_that_pay(most: int, gil_share: float, gil_work: float) -> int:
    """The processes (at most ``most``) that a build's remaining entries are worth: more
    than one only where most of the work holds the GIL (``gil_share`` of the first
    chunk's time: threads cannot share that part) and each process's share of it
    (``gil_work`` seconds in all, estimated from the first chunk) outweighs its start
    (:data:`PROCESS_START`); else 1, and the build runs on threads.

    >>> _processes_that_pay(16, 0.1, 100.0), _processes_that_pay(16, 0.9, 100.0)
    (1, 16)
    >>> _processes_that_pay(16, 0.9, 2.5), _processes_that_pay(16, 0.9, 1.5)
    (2, 1)
    """
    if gil_share <= 0.5:
        return 1
    return max(1, min(most, int(gil_work / PROCESS_START)))


def _spawn_reruns_caller() -> bool:
    """Whether a spawned process would run this call again: the call comes (through any
    number of functions) from the top-level code of the ``__main__`` module outside an
    ``if __name__ == "__main__":`` block, and ``multiprocessing`` runs that module again
    in a spawned process (a script run by path or ``python -m module``; not a package's
    ``__main__.py``, nor the interactive interpreter)."""
    main = sys.modules.get("__main__")
    path = getattr(main, "__file__", None)
    name = getattr(getattr(main, "__spec__", None), "name", None)
    if main is None or path is None or name == "__main__" or (
            name is not None and name.endswith(".__main__")) or (
            name is None and os.path.splitext(os.path.basename(path))[0] == "ipython"):
        return False
    frame: FrameType | None = sys._getframe(1)
    while frame is not None and not (frame.f_globals is vars(main)
                                     and frame.f_code.co_name == "<module>"):
        frame = frame.f_back
    if frame is None:
        return False  # not called from the main module's top-level code
    line = frame.f_lineno
    try:
        with open(path, "rb") as f:
            tree = ast.parse(f.read())
    except (OSError, SyntaxError, ValueError):
        return True  # (the source cannot be read: taken as unguarded)
    for statement in tree.body:
        if statement.lineno <= line <= (statement.end_lineno or statement.lineno):
            return not (isinstance(statement, ast.If) and _is_main_test(statement.test)
                        and any(s.lineno <= line <= (s.end_lineno or s.lineno)
                                for s in statement.body))
    return True


def _is_main_test(test: ast.expr) -> bool:
    """Whether ``test`` is ``__name__ == "__main__"`` (either way round)."""
    if (not isinstance(test, ast.Compare) or len(test.ops) != 1
            or not isinstance(test.ops[0], ast.Eq)):
        return False
    sides = (test.left, test.comparators[0])
    return (any(isinstance(x, ast.Name) and x.id == "__name__" for x in sides)
            and any(isinstance(x, ast.Constant) and x.value == "__main__" for x in sides))


def _progress_bar(progress: Progress, total: int) -> Any:
    if progress is not True:
        return None
    from tqdm.auto import tqdm

    return tqdm(total=total, unit="NFP", desc="NFP table", file=sys.stderr, smoothing=0.1)


_WORKER_PIECES: list[_Pieces] = []


def _init_process(pieces: _Pieces, reference: str) -> None:
    """A local worker process: Ctrl-C is the parent's to handle; it ends when its parent
    does (:func:`_exit_with_parent`); the kernels loaded once, by a first entry (from
    the cache: the parent compiled them before starting the pool)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    parent = multiprocessing.parent_process()
    if parent is not None:
        threading.Thread(target=_exit_with_parent, args=(parent.sentinel,), daemon=True,
                         name="polycontact-parent-watch").start()
    _compute_chunk(pieces, np.zeros((1, 2), np.int64), reference)
    _WORKER_PIECES[:] = [pieces]


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
    return _compute_chunk(_WORKER_PIECES[0], pairs, reference)


def _run_processes(
    n: int, pieces: _Pieces, tasks: list[np.ndarray], reference: str
) -> Generator[tuple[int, Packed], None, None]:
    """Run the tasks on ``n`` spawned processes (one pool for the build) and in this
    process; yield (task index, result) as they end, each task once.

    The pool takes tasks from the front, ``n + 1`` at a time, and this process from the
    back, so it works while the processes start: when the processes are slow to start
    (or stop), this process computes the tasks it handed them too (the first result
    wins; both are the same), and the build takes no longer than here alone."""
    pool = ProcessPoolExecutor(n, mp_context=multiprocessing.get_context("spawn"),
                               initializer=_init_process, initargs=(pieces, reference))
    owner: dict[Future[Packed], int] = {}
    done = np.zeros(len(tasks), bool)
    front, back = 0, len(tasks)  # tasks[front:back]: handed to nobody yet
    answered = broken = False

    def finished(timeout: float | None) -> list[tuple[int, Packed]]:
        nonlocal answered, broken
        ended, _ = wait(list(owner), timeout=timeout, return_when=FIRST_COMPLETED)
        out = []
        for f in ended:
            k = owner.pop(f)
            try:
                result = f.result()
            except BrokenProcessPool:
                if not broken:
                    warnings.warn("nfp_table: the local worker processes stopped; the "
                                  "build goes on in this process", RuntimeWarning,
                                  stacklevel=5)
                broken = True
                continue
            answered = True
            if not done[k]:
                done[k] = True
                out.append((k, result))
        return out

    try:
        while not done.all():
            for item in finished(0):
                yield item
            while not broken and front < back and len(owner) < n + 1:
                owner[pool.submit(_process_task, tasks[front], reference)] = front
                front += 1
            if front < back:
                back -= 1
                k = back
            else:  # every task handed out: compute the pool's, unless it is at work
                left = [] if answered and not broken and owner else [
                    k for k in range(front - 1, -1, -1) if not done[k]]
                if not left:
                    for item in finished(None):
                        yield item
                    continue
                k = left[0]
            result = _compute_chunk(pieces, tasks[k], reference)
            if not done[k]:
                done[k] = True
                yield k, result
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
