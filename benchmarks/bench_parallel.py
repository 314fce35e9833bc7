"""Scaling of the parallel paths: each at 1, 2, ... threads (and 1, 2, ... Dask workers),
with the speed-up, the measured serial fraction and Amdahl's prediction for 16 cores.

Paths (size, then the ``--quick`` size):

- ``contacts``: ``World.contacts()`` of concave 12-gons packed densely (bench_world's
  stars: each meets a few neighbours), 2·10⁵ bodies (2·10⁴);
- ``contacts_pile``: the same for a World as crowded as a pile at the bottom of a
  hopper: the first half of the bodies (in the order added) packed as there, the
  second half standing apart, so that all the work lies in the first half;
- ``set_poses``: ``World.set_poses`` of every body of that World (a small move each
  call, each body staying in or leaving its grid cell);
- ``geometry``: the contact geometry of that World's contacts (``Contacts.distances``:
  normals, points, overlaps of every pair in one compiled pass);
- ``sweep``: ``World.sweep`` of that World, every body moving a tenth of its size in the
  step and turning by up to 0.2 radian (bench_step's step): the pairs that meet, their
  times and states;
- ``classify_many``: 10⁶ pairs (10⁵) of such 12-gons as (P, N, 2) arrays, each ring
  against a copy moved by up to 0.8 (most pairs overlap);
- ``distances``: the signed distances of 10⁵ of those pairs (10⁴), given as Shapes;
- ``time_of_impact_many``: 4·10⁴ pairs (4·10³), bench_distributed's pairs (a square, an
  L and a U against each other and a square frame, random motions over [0, 3]);
  ``time_of_impact_many_rows``, the same with the motions given as the rows of arrays;
  and ``time_of_impact_many_arrays``, 4·10⁴ pairs (4·10³) in the packed form, no
  Python object per pair: 12-gons as (P, N, 2) arrays, each against a copy moved by up
  to 1.5, motions as rows (random velocities, spins and some accelerations, over [0,
  3]);
- ``first_impacts``: 2·10⁴ moving 12-gons (2·10³) on a jittered grid, random velocities
  and spins, over [0, 0.5];
- ``nfp_table``: the shipped jakobs1 (25 pieces) at 12 orientations, 90 000 entries
  (at 4 orientations, 10 000), reference at the origin, no cache, by its default choice
  (threads, for pieces without holes); ``nfp_table_workers``: the same table on 1, 2,
  ... local workers (``workers=w, threads=w``, as ``--workers``): at most ``w``
  processes, which the build starts only where they pay (work that holds the GIL), and
  otherwise ``w`` threads, as here (1 is the calling thread);
- ``dask ...`` (only when ``distributed`` is installed, else said and skipped):
  ``nfp_table``, ``classify_many`` and ``time_of_impact_many`` with ``client=`` on a
  ``LocalCluster`` of 1, 2, ... worker processes of one thread each, started and warmed
  before the timing.

For each thread count, ``numba.set_num_threads(t)`` and ``threads=t`` where the call
takes it; the time is the median of ``--repeat`` calls (the fastest and slowest in
brackets), and every answer is compared, entry by entry, with the one-thread answer
(``same``). The serial fraction is measured at one thread, the median of ``--repeat``
calls (the smallest and largest in brackets): the time outside the parallel regions
over the total, where the parallel regions are the calls of the
compiled parallel kernels and of the thread pool's chunk maps (timed by wrappers
installed for the measurement only); for the Dask rows, measured on one worker of one
thread, the parallel region is the time the worker computes tasks (Dask's task stream),
so that the calling process's preparation, the data's transfer and the waits between
tasks are the serial part. Amdahl's prediction for 16 cores is
``1 / (s + (1 - s) / 16)``. On a machine shared with other jobs the speed-ups are noisy;
the serial fractions much less.

Run: ``python benchmarks/bench_parallel.py [--quick] [--threads 1,2,4,8,16]
[--workers 1,2,4] [--repeat 5] [--paths contacts,nfp_table] [--json OUT]``.
With ``--json OUT`` every row is written to ``OUT`` as soon as it is measured (with
the machine, the date and the command), so a run cut short keeps what it measured.
Needs polycontact's own dependencies only (Dask optional).
"""

from __future__ import annotations

import argparse
import contextlib
import importlib
import json
import os
import platform
import statistics
import sys
import threading
import time
from collections.abc import Callable, Iterator
from typing import Any

import numba
import numpy as np

import polycontact as pc

#: The calls whose time counts as parallel work (module, name): the compiled parallel
#: kernels, the kernels that the thread pool shares among threads in chunks (timed when
#: the calling thread runs them itself), and the thread pool's chunk maps.
PARALLEL = [
    ("polycontact._kernels.world", "contact_pairs"),
    ("polycontact._kernels.world", "container_states"),
    ("polycontact._kernels.world", "regrid"),
    ("polycontact._kernels.packs", "unpack_shapes"),
    ("polycontact._kernels.poses", "pose_rows"),
    ("polycontact._kernels.poses", "pose_checks"),
    ("polycontact._kernels.contact_geometry", "pair_geometry"),
    ("polycontact._kernels.contact_geometry", "caller_features"),
    ("polycontact._kernels.world_sweep", "motion_maxima"),
    ("polycontact._kernels.world_sweep", "turned_frames"),
    ("polycontact._kernels.world_sweep", "sweep_search"),
    ("polycontact._kernels.world_sweep", "sweep_events"),
    ("polycontact._kernels.world_sweep", "event_geometry"),
    ("polycontact._kernels.contact_geometry", "boundary_gaps"),
    ("polycontact._kernels.relation_many", "many_distances"),
    ("polycontact._kernels.impact_batch", "body_tables"),
    ("polycontact._kernels.impact_batch", "suspect_bodies"),
    ("polycontact._kernels.impact_batch", "ring_bodies"),
    ("polycontact._kernels.impact_batch", "pack_rings"),
    ("polycontact._threads", "map_chunks"),
    ("polycontact._threads", "as_done"),
]

SIZES = {  # path: (full, quick)
    "contacts": (200_000, 20_000),
    "classify_many": (1_000_000, 100_000),
    "distances": (100_000, 10_000),
    "time_of_impact_many": (40_000, 4_000),
    "first_impacts": (20_000, 2_000),
    "nfp_table": (12, 4),  # orientations of jakobs1
}


# -- the parallel regions ------------------------------------------------------------------
class Regions:
    """Wrappers that add up the time spent in the parallel regions (in the main thread,
    outermost calls only); installed only inside :meth:`measuring`."""

    def __init__(self) -> None:
        self.seconds = 0.0
        self.depth = 0

    def _timed_call(self, fn: Callable[..., Any]) -> Callable[..., Any]:
        def call(*args: Any, **kwargs: Any) -> Any:
            if threading.current_thread() is not threading.main_thread() or self.depth:
                return fn(*args, **kwargs)
            self.depth += 1
            t0 = time.perf_counter()
            try:
                out = fn(*args, **kwargs)
            finally:
                self.seconds += time.perf_counter() - t0
                self.depth -= 1
            if hasattr(out, "__next__"):  # a generator: its work is done in next()
                return self._timed_generator(out)
            return out
        return call

    def _timed_generator(self, gen: Iterator[Any]) -> Iterator[Any]:
        while True:
            self.depth += 1
            t0 = time.perf_counter()
            try:
                item = next(gen)
            except StopIteration:
                return
            finally:
                self.seconds += time.perf_counter() - t0
                self.depth -= 1
            yield item

    @contextlib.contextmanager
    def measuring(self) -> Iterator[None]:
        """Every parallel region wrapped, in its module and wherever a module of
        polycontact imported it by name."""
        saved = []
        for module, name in PARALLEL:
            try:
                mod = importlib.import_module(module)
            except ImportError:
                continue
            fn = getattr(mod, name, None)
            if fn is None:
                continue
            timed = self._timed_call(fn)
            for other in list(sys.modules.values()):
                if (getattr(other, "__name__", "").startswith("polycontact")
                        and getattr(other, name, None) is fn):
                    saved.append((other, name, fn))
                    setattr(other, name, timed)
        try:
            yield
        finally:
            for mod, name, fn in saved:
                setattr(mod, name, fn)


# -- the workloads -------------------------------------------------------------------------
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_distributed import impact_pairs  # noqa: E402 - the benchmarks' own workloads
from bench_world import stars  # noqa: E402


class Path:
    """One path: ``run(threads)`` calls it once and returns its answer as arrays, after
    ``prepare()`` (not timed)."""

    name = ""
    size = ""

    def prepare(self) -> None:
        pass

    def run(self, threads: int) -> tuple[np.ndarray, ...]:
        raise NotImplementedError


class WorldPaths:
    """The World of the contacts, set_poses and geometry paths, built once."""

    def __init__(self, count: int) -> None:
        rng = np.random.default_rng(1)
        self.world = pc.World()
        self.ids = self.world.add_many(stars(rng, count))
        self.pos, self.ang = self.world.poses()
        self.step = 0


class WorldPath(Path):
    """A path on the World of :class:`WorldPaths`."""

    def __init__(self, w: WorldPaths) -> None:
        self.w = w
        self.size = f"{len(w.ids)} bodies"


class Contacts(WorldPath):
    name = "contacts"

    def run(self, threads: int) -> tuple[np.ndarray, ...]:
        c = self.w.world.contacts()
        return c.pairs, c.states


class ContactsPile(Path):
    """``World.contacts()`` of a World whose first half of bodies is packed as in
    :class:`WorldPaths` and whose second half stands apart (a pile: the work all in the
    first half of the bodies)."""

    name = "contacts_pile"

    def __init__(self, count: int) -> None:
        rings = stars(np.random.default_rng(1), count)
        apart = rings[count // 2:]
        apart += 2.0 * apart.mean(axis=1, keepdims=True) + 1e3  # centres spread 3 times
        self.world = pc.World()
        self.world.add_many(rings)
        self.size = f"{count} bodies, half of them apart"

    def run(self, threads: int) -> tuple[np.ndarray, ...]:
        c = self.world.contacts()
        return c.pairs, c.states


class SetPoses(WorldPath):
    name = "set_poses"

    def prepare(self) -> None:
        w = self.w
        w.step = (w.step + 1) % 4  # back and forth: the same poses at every thread count
        d = 0.01 * (w.step % 2)
        self.poses = (w.pos + d, w.ang + d)

    def run(self, threads: int) -> tuple[np.ndarray, ...]:
        w = self.w
        w.world.set_poses(w.ids, *self.poses)
        return w.world._xy, w.world._box  # (the World's own arrays: copied to compare)


class Geometry(WorldPath):
    name = "geometry"

    def prepare(self) -> None:
        self.contacts = self.w.world.contacts()  # (the contacts path's work)

    def run(self, threads: int) -> tuple[np.ndarray, ...]:
        c = self.contacts
        return c.distances, c.normals, c.points, c.overlap_areas


class Sweep(WorldPath):
    """``World.sweep`` of that World, each body moving a tenth of its size in the step
    (a random heading) and turning by up to 0.2 radian, as in bench_step."""

    name = "sweep"

    def __init__(self, w: WorldPaths) -> None:
        super().__init__(w)
        rng = np.random.default_rng(2)
        n = len(w.ids)
        self.dt = 0.01
        heading = rng.uniform(0.0, 2.0 * np.pi, n)
        self.vel = 0.12 / self.dt * np.c_[np.cos(heading), np.sin(heading)]
        self.spin = rng.uniform(-0.2, 0.2, n) / self.dt

    def run(self, threads: int) -> tuple[np.ndarray, ...]:
        ev = self.w.world.sweep(self.dt, self.vel, self.spin)
        return ev.pairs, ev.times, ev.states


class ClassifyMany(Path):
    """``classify_many`` of ring arrays (its states), or of Shapes (``distances``: the
    signed distances too)."""

    def __init__(self, count: int, distances: bool) -> None:
        rng = np.random.default_rng(2)
        a = stars(rng, count)
        b = a + rng.uniform(-0.8, 0.8, (count, 1, 2))
        self.distances = distances
        self.name = "distances" if distances else "classify_many"
        self.a: Any = [pc.Shape(x) for x in a] if distances else a
        self.b: Any = [pc.Shape(x) for x in b] if distances else b
        self.size = f"{count} pairs"

    def run(self, threads: int) -> tuple[np.ndarray, ...]:
        r = pc.classify_many(self.a, self.b, threads=threads)
        return r.states, (r.distances if self.distances else r.tolerances)


class Impacts(Path):
    """``time_of_impact_many`` of bench_distributed's pairs, the motions as Motions or
    (``rows``) as the rows of arrays."""

    def __init__(self, count: int, rows: bool) -> None:
        a, ma, b, mb = impact_pairs(count)
        if rows:
            ma, mb = (np.array([m.array for m in ms]) for ms in (ma, mb))
        self.pairs = (a, ma, b, mb)
        self.name = "time_of_impact_many" + (" (motions as rows)" if rows else "")
        self.size = f"{count} pairs"

    def run(self, threads: int) -> tuple[np.ndarray, ...]:
        b = pc.time_of_impact_many(*self.pairs, t_max=3, threads=threads)
        return b.statuses, b.times, b.first_contacts


class ImpactArrays(Path):
    """``time_of_impact_many`` in the packed form: ring arrays, motions as rows."""

    name = "time_of_impact_many_arrays"

    def __init__(self, count: int) -> None:
        rng = np.random.default_rng(5)
        a = stars(rng, count)
        b = a + rng.uniform(-1.5, 1.5, (count, 1, 2))
        ma = np.c_[rng.uniform(-2, 2, (count, 2)),
                   rng.uniform(-1, 1, (count, 2)) * (np.arange(count) % 4 == 0)[:, None],
                   rng.uniform(-1, 1, count), np.zeros(count)]
        mb = np.c_[rng.uniform(-1, 1, (count, 2)), np.zeros((count, 4))]
        self.pairs = (a, ma, b, mb)
        self.size = f"{count} pairs"

    def run(self, threads: int) -> tuple[np.ndarray, ...]:
        b = pc.time_of_impact_many(*self.pairs, t_max=3, threads=threads)
        return b.statuses, b.times, b.first_contacts


class FirstImpacts(Path):
    name = "first_impacts"

    def __init__(self, count: int) -> None:
        rng = np.random.default_rng(4)
        self.shapes = [pc.Shape(x) for x in stars(rng, count)]
        self.motions = [pc.Motion(velocity=rng.uniform(-1, 1, 2),
                                  angular_velocity=rng.uniform(-1, 1)) for _ in self.shapes]
        self.size = f"{count} bodies"

    def run(self, threads: int) -> tuple[np.ndarray, ...]:
        ev = pc.first_impacts(self.shapes, self.motions, t_max=0.5, threads=threads)
        return ev.pairs, ev.statuses, ev.times


def jakobs1(orientations: int) -> tuple[Any, list[float]]:
    from polycontact import datasets

    inst = datasets.instance("jakobs1")
    return inst, [360.0 * k / orientations for k in range(orientations)]


def table_arrays(t: Any) -> tuple[np.ndarray, ...]:
    """Every entry of an NFP table as arrays (regions' WKB lengths and a checksum of
    their bytes, fits, slides, tolerances), for comparing two builds entry by entry."""
    import hashlib

    import shapely

    digest = hashlib.blake2b()
    tols = []
    for key in t:
        e = t[key]
        digest.update(shapely.to_wkb(e.region))
        digest.update(e.exact_fits.tobytes())
        digest.update(e.slides.tobytes())
        tols.append(e.tolerance)
    return np.frombuffer(digest.digest(), np.uint8), np.array(tols)


class NfpTable(Path):
    name = "nfp_table"

    def __init__(self, orientations: int) -> None:
        self.inst, self.angles = jakobs1(orientations)
        n = sum(1 for _ in self.inst.pieces) * orientations
        self.size = f"jakobs1, {orientations} orientations, {n * n} entries"

    def run(self, threads: int) -> tuple[np.ndarray, ...]:
        t = pc.nfp_table(self.inst.pieces, self.angles, progress=False, threads=threads)
        self.last = t
        return (np.array([t.computed]),)


class NfpTableWorkers(NfpTable):
    """The table of :class:`NfpTable` on ``w`` local workers (the count given to ``run``):
    ``workers=w`` processes at most, and ``threads=w`` where processes do not pay."""

    name = "nfp_table_workers"
    unit = "workers"

    def run(self, threads: int) -> tuple[np.ndarray, ...]:
        t = pc.nfp_table(self.inst.pieces, self.angles, progress=False, workers=threads,
                         threads=threads)
        self.last = t
        return (np.array([t.computed]),)


# -- measuring -----------------------------------------------------------------------------
def same(x: tuple[np.ndarray, ...], y: tuple[np.ndarray, ...]) -> bool:
    return len(x) == len(y) and all(
        a.shape == b.shape and np.array_equal(a, b, equal_nan=a.dtype.kind == "f")
        for a, b in zip(x, y))


def copies(arrays: tuple[np.ndarray, ...]) -> tuple[np.ndarray, ...]:
    return tuple(np.array(a, copy=True) for a in arrays)


def measure(path: Path, threads: list[int], repeat: int) -> dict[str, Any]:
    """The path's row: seconds per thread (or process) count, speed-ups, the serial
    fraction (threads only)."""
    numba.set_num_threads(1)
    path.prepare()
    want = copies(path.run(1))  # (warm: the kernels loaded, the pools and buffers made)
    if isinstance(path, NfpTable):
        want = table_arrays(path.last)
    unit = getattr(path, "unit", "threads")
    row: dict[str, Any] = {"path": path.name, "size": path.size, "threads": {},
                           "serial_fraction": None, "amdahl16": None, "unit": unit}
    if unit == "threads":
        regions = Regions()
        serial = []
        with regions.measuring():
            for _ in range(repeat):
                path.prepare()
                regions.seconds = 0.0
                t0 = time.perf_counter()
                path.run(1)
                total = time.perf_counter() - t0
                serial.append((total - regions.seconds) / total)
        s = row["serial_fraction"] = statistics.median(serial)
        row["serial_spread"] = [min(serial), max(serial)]
        row["amdahl16"] = 1.0 / (s + (1.0 - s) / 16.0)
    for t in threads:
        numba.set_num_threads(t if unit == "threads" else 1)
        path.prepare()
        got = copies(path.run(t))
        if isinstance(path, NfpTable):
            got = table_arrays(path.last)
        times = []
        for _ in range(repeat):
            path.prepare()
            t0 = time.perf_counter()
            path.run(t)
            times.append(time.perf_counter() - t0)
        row["threads"][t] = {"median": statistics.median(times), "min": min(times),
                             "max": max(times), "same": same(want, got)}
    numba.set_num_threads(int(numba.config.NUMBA_NUM_THREADS))
    one = row["threads"][threads[0]]["median"] if threads[0] == 1 else None
    for t, r in row["threads"].items():
        r["speedup"] = None if one is None else one / r["median"]
    return row


def dask_rows(workers: list[int], quick: bool, repeat: int,
              report: Callable[[list[dict[str, Any]]], None]) -> list[dict[str, Any]]:
    """nfp_table, classify_many and time_of_impact_many with ``client=`` on clusters of
    1, 2, ... worker processes (one thread each); ``report(rows)`` after each cluster,
    with the rows measured so far."""
    try:
        from distributed import Client, LocalCluster, get_task_stream
    except ImportError:
        print("\nDask rows skipped: distributed is not installed (pip install "
              "'polycontact[dask]')")
        return []
    from polycontact.distributed import ensure_warm

    inst, angles = jakobs1(SIZES["nfp_table"][quick])
    rng = np.random.default_rng(2)
    n_pairs = SIZES["classify_many"][quick]
    a = stars(rng, n_pairs)
    b = a + rng.uniform(-0.8, 0.8, (n_pairs, 1, 2))
    pairs = impact_pairs(SIZES["time_of_impact_many"][quick])
    # each call, timed, then its answer as arrays (read after the timing: reading back
    # every entry of a table is the caller's work, not the cluster's)
    calls: dict[str, tuple[Callable[[Any], Any], Callable[[Any], Any]]] = {
        "dask nfp_table": (
            lambda c: pc.nfp_table(inst.pieces, angles, progress=False, client=c),
            table_arrays),
        "dask classify_many": (
            lambda c: pc.classify_many(a, b, client=c),
            lambda r: tuple(getattr(r, f) for f in ("states", "tolerances"))),
        "dask time_of_impact_many": (
            lambda c: pc.time_of_impact_many(*pairs, t_max=3, client=c),
            lambda r: tuple(getattr(r, f) for f in ("statuses", "times", "first_contacts"))),
    }
    rows = {name: {"path": name, "size": "", "threads": {}, "serial_fraction": None,
                   "amdahl16": None, "unit": "workers"} for name in calls}
    want: dict[str, Any] = {}
    def speedups() -> list[dict[str, Any]]:
        for row in rows.values():
            one = row["threads"].get(1, {}).get("median")
            for r in row["threads"].values():
                r["speedup"] = None if one is None else one / r["median"]
        return [row for row in rows.values() if row["threads"]]

    for w in workers:
        with LocalCluster(n_workers=w, threads_per_worker=1, processes=True,
                          dashboard_address=None) as cluster, Client(cluster) as client:
            ensure_warm(client, ["no-fit polygon", "classification", "many moving bodies"])
            for name, (call, answer) in calls.items():
                got = answer(call(client))
                want.setdefault(name, got)
                times = []
                serial = []
                for _ in range(repeat):
                    with get_task_stream(client) as stream:
                        t0 = time.perf_counter()
                        call(client)
                        total = time.perf_counter() - t0
                    times.append(total)
                    busy = sum(s["stop"] - s["start"] for task in stream.data
                               for s in task["startstops"] if s["action"] == "compute")
                    serial.append(max(0.0, total - busy) / total)
                rows[name]["threads"][w] = {"median": statistics.median(times),
                                            "min": min(times), "max": max(times),
                                            "same": same(want[name], got)}
                if w == 1:  # (one worker of one thread: its tasks never overlap)
                    s = rows[name]["serial_fraction"] = statistics.median(serial)
                    rows[name]["serial_spread"] = [min(serial), max(serial)]
                    rows[name]["amdahl16"] = 1.0 / (s + (1.0 - s) / 16.0)
        report(speedups())
    return speedups()


def show(row: dict[str, Any]) -> None:
    unit = row.get("unit", "threads")
    print(f"\n{row['path']} ({row['size']})" if row["size"] else f"\n{row['path']}")
    print(f"  {unit:>8} {'median s':>10} {'[fastest, slowest]':>22} {'speed-up':>9} {'same':>5}")
    for t, r in row["threads"].items():
        up = "" if r["speedup"] is None else f"{r['speedup']:.2f}×"
        print(f"  {t:>8} {r['median']:>10.4f} [{r['min']:.4f}, {r['max']:.4f}]".ljust(45)
              + f"{up:>9} {str(r['same']):>5}")
    if row["serial_fraction"] is not None:
        low, high = row["serial_spread"]
        print(f"  serial fraction at one {unit[:-1]}: {100 * row['serial_fraction']:.1f} % "
              f"[{100 * low:.1f}, {100 * high:.1f}]; Amdahl for 16 cores: "
              f"{row['amdahl16']:.1f}×")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="the smaller sizes")
    ap.add_argument("--threads", default=None,
                    help="thread counts, e.g. 1,2,4,8,16 (default 1, 2, 4, ... all)")
    ap.add_argument("--workers", default=None,
                    help="Dask worker counts (default: as the threads, at most 4 with "
                         "--quick)")
    ap.add_argument("--repeat", type=int, default=None, help="calls per figure (5; 3 quick)")
    ap.add_argument("--paths", default=None, help="comma-separated paths (default all): "
                    "contacts,contacts_pile,time_of_impact_many,time_of_impact_many_rows,"
                    "time_of_impact_many_arrays,nfp_table,"
                    "nfp_table_workers,classify_many,set_poses,first_impacts,distances,"
                    "geometry,sweep,dask")
    ap.add_argument("--json", metavar="OUT", help="write the figures to this file")
    args = ap.parse_args()
    most = int(numba.config.NUMBA_NUM_THREADS)
    if args.threads:
        threads = [int(t) for t in args.threads.split(",")]
    else:
        threads = sorted({1, *(2**k for k in range(1, 8) if 2**k < most), most})
    over = [t for t in threads if t > most]
    if over:
        print(f"threads {over} skipped: Numba has {most} (NUMBA_NUM_THREADS)")
        threads = [t for t in threads if t <= most]
    workers = ([int(w) for w in args.workers.split(",")] if args.workers
               else [t for t in threads if not args.quick or t <= 4])
    repeat = args.repeat or (3 if args.quick else 5)
    q = int(args.quick)
    chosen = (args.paths.split(",") if args.paths else
              ["contacts", "contacts_pile", "time_of_impact_many", "time_of_impact_many_rows",
               "time_of_impact_many_arrays", "nfp_table", "nfp_table_workers",
               "classify_many", "set_poses", "first_impacts",
               "distances", "geometry", "sweep", "dask"])
    head = {"date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
            "command": " ".join(["python", *sys.argv]), "machine": machine(),
            "cpus": os.cpu_count(), "numba_threads": most,
            "threading_layer": numba.config.THREADING_LAYER,
            "python": platform.python_version(), "numba": numba.__version__,
            "quick": args.quick, "repeat": repeat, "load_average": os.getloadavg()}
    print(f"{head['date']}, {head['machine']}: {os.cpu_count()} CPUs, Numba "
          f"{numba.__version__} ({most} threads, layer {head['threading_layer']}), Python "
          f"{platform.python_version()}, {'quick' if args.quick else 'full'} sizes, "
          f"{repeat} calls per figure, load average "
          f"{', '.join(f'{x:.2f}' for x in head['load_average'])}")
    pc.warmup()
    rows: list[dict[str, Any]] = []
    world = None
    for name in chosen:
        if name == "dask":
            continue
        if name in ("contacts", "set_poses", "geometry", "sweep"):
            world = world or WorldPaths(SIZES["contacts"][q])
            path: Path = {"contacts": Contacts, "set_poses": SetPoses,
                          "geometry": Geometry, "sweep": Sweep}[name](world)
        elif name == "contacts_pile":
            path = ContactsPile(SIZES["contacts"][q])
        elif name in ("classify_many", "distances"):
            path = ClassifyMany(SIZES[name][q], name == "distances")
        elif name in ("time_of_impact_many", "time_of_impact_many_rows"):
            path = Impacts(SIZES["time_of_impact_many"][q], name.endswith("rows"))
        elif name == "time_of_impact_many_arrays":
            path = ImpactArrays(SIZES["time_of_impact_many"][q])
        elif name == "first_impacts":
            path = FirstImpacts(SIZES[name][q])
        elif name == "nfp_table":
            path = NfpTable(SIZES[name][q])
        elif name == "nfp_table_workers":
            path = NfpTableWorkers(SIZES["nfp_table"][q])
        else:
            sys.exit(f"--paths: unknown path {name!r}")
        row = measure(path, workers if name == "nfp_table_workers" else threads, repeat)
        show(row)
        rows.append(row)
        save(args.json, head, rows)
    if "dask" in chosen:
        for row in dask_rows(workers, args.quick, repeat,
                             lambda partial: save(args.json, head, rows + partial)):
            show(row)
            rows.append(row)
        save(args.json, head, rows)


def machine() -> str:
    """The processor's name (Linux: /proc/cpuinfo; else the platform's)."""
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def save(out: str | None, head: dict[str, Any], rows: list[dict[str, Any]]) -> None:
    """Write the rows so far to ``out`` (if given), through a temporary file and a
    rename: a run cut short keeps the rows it measured, and the file is always whole."""
    if out:
        tmp = f"{out}.tmp"
        with open(tmp, "w") as f:
            json.dump({**head, "rows": rows}, f, indent=1)
        os.replace(tmp, out)


if __name__ == "__main__":
    main()
