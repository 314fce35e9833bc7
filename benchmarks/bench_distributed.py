"""NFP tables of jakobs1 and jakobs2 on Dask: 1 and 2 local workers, and the cache.

For each instance (every ordered pair of pieces at 0/90/180/270 degrees, reference at
the origin; 10 000 entries, fewer distinct ones since some pieces are equal):

- ``local``: :func:`polycontact.nfp_table` in this process (``workers=1``);
- ``dask 1`` / ``dask 2``: on a ``LocalCluster`` of 1 or 2 worker processes (one
  thread each); the cluster is started and its kernels warmed before the timing, which
  covers the tasks, the transfers and assembling the table;
- efficiency: ``dask 1 / (2 * dask 2)``, 1.0 being a perfect halving;
- ``cold`` / ``cached``: a build into an empty cache directory (computing and writing
  every entry), then the same call again (reading every entry, computing none).

Times are medians of ``--repeat`` runs (seconds); each run clears the convex
decomposition cache of every process first, so no run reuses another's work.

Then :func:`polycontact.time_of_impact_many` on ``--impacts`` pairs (default 10 000): a
square, an L and a U, each pair one of them at a random place and turn against another
(every fifth one a square frame with a square hole), random velocities (up to 2 per
axis), spins (up to 1 rad/s), accelerations for a quarter, over [0, 3]; each pair has
its own shape objects except one side of every other pair, which shares one of the
three. ``local 1`` is the local call on one thread, ``local N`` on every CPU, ``dask
1`` / ``dask 2`` the same call with ``client=`` on the clusters
above (default chunk size), whose first run is checked equal to ``local 1``. Each run
gets new shape objects (the search keeps its tables with a shape). Printed with the
fastest and slowest run.

Run: ``python benchmarks/bench_distributed.py [--repeat 3] [--data DIR] [--impacts N]
[--no-nfp] [instance ...]``.
"""

from __future__ import annotations

import argparse
import os
import statistics
import tempfile
import time
from pathlib import Path

import polycontact as pc

DATA = Path(__file__).resolve().parents[2] / "shared" / "datasets" / "esicup"


def _clear() -> None:
    from polycontact import _pieces

    _pieces.clear_cache()


def timed(fn, repeat: int, client=None) -> float:
    times = []
    for _ in range(repeat):
        _clear()
        if client is not None:
            client.run(_clear)
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def impact_pairs(count: int, seed: int = 1) -> tuple[list, list, list, list]:
    """The pairs of the ``time_of_impact_many`` row (see the module's docstring)."""
    import numpy as np

    rng = np.random.default_rng(seed)
    pieces = [pc.Shape([(0, 0), (1, 0), (1, 1), (0, 1)]),
              pc.Shape([(0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)]),
              pc.Shape([(0, 0), (3, 0), (3, 3), (2, 3), (2, 1), (1, 1), (1, 3), (0, 3)])]
    frame = pc.Shape([(0, 0), (6, 0), (6, 6), (0, 6)], [[(2, 2), (4, 2), (4, 4), (2, 4)]])
    out: list[list] = [[], [], [], []]
    for k in range(count):
        a = pieces[k % 3] if k % 2 else pieces[k % 3].moved(rng.uniform(-3, 3, 2))
        b = frame if k % 5 == 0 else pieces[(k // 3) % 3].moved(rng.uniform(-3, 3, 2),
                                                                rng.uniform(0, 6.3))
        ma = pc.Motion(velocity=rng.uniform(-2, 2, 2), angular_velocity=rng.uniform(-1, 1),
                       acceleration=rng.uniform(-1, 1, 2) if k % 4 == 0 else (0, 0))
        mb = pc.Motion() if k % 2 else pc.Motion(velocity=rng.uniform(-1, 1, 2))
        for lst, x in zip(out, (a, ma, b, mb)):
            lst.append(x)
    return out[0], out[1], out[2], out[3]


def spread(fn, count: int, repeat: int) -> tuple[float, float, float]:
    """Median, fastest and slowest of ``repeat`` calls ``fn(pairs)`` (seconds), each on
    new shape objects (the search keeps tables with each shape: a second call on the
    same objects would skip building them)."""
    times = []
    for _ in range(repeat):
        pairs = impact_pairs(count)
        t0 = time.perf_counter()
        fn(pairs)
        times.append(time.perf_counter() - t0)
    return statistics.median(times), min(times), max(times)


def same(x, y) -> bool:
    import numpy as np

    return (np.array_equal(x.statuses, y.statuses)
            and np.array_equal(x.times, y.times, equal_nan=True)
            and np.array_equal(x.first_contacts, y.first_contacts, equal_nan=True))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("instances", nargs="*", default=["jakobs1", "jakobs2"])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--data", type=Path, default=DATA,
                        help=f"directory of the ESICUP files (default {DATA})")
    parser.add_argument("--impacts", type=int, default=10_000,
                        help="pairs of the time_of_impact_many row (0: none)")
    parser.add_argument("--no-nfp", action="store_true", help="only the time_of_impact_many row")
    args = parser.parse_args()
    from distributed import Client, LocalCluster


    pc.warmup(["no-fit polygon", "many moving bodies"])
    instances = {} if args.no_nfp else {
        name: pc.read_esicup(args.data / f"{name}.json") for name in args.instances}
    toi: dict[str, tuple[float, float, float]] = {}
    if args.impacts:
        want = pc.time_of_impact_many(*impact_pairs(args.impacts), t_max=3, threads=1)
        toi["local 1"] = spread(lambda p: pc.time_of_impact_many(*p, t_max=3, threads=1),
                                args.impacts, args.repeat)
        toi[f"local {os.cpu_count()}"] = spread(
            lambda p: pc.time_of_impact_many(*p, t_max=3), args.impacts, args.repeat)
    rows = {name: {} for name in instances}
    for name, inst in instances.items():
        rows[name]["local"] = timed(lambda: pc.nfp_table(inst, progress=False, workers=1),
                                    args.repeat)
        cold, cached = [], []
        for _ in range(args.repeat):
            _clear()
            with tempfile.TemporaryDirectory() as d:
                t0 = time.perf_counter()
                pc.nfp_table(inst, cache=d, progress=False, workers=1)
                cold.append(time.perf_counter() - t0)
                t0 = time.perf_counter()
                t = pc.nfp_table(inst, cache=d, progress=False, workers=1)
                cached.append(time.perf_counter() - t0)
                assert t.computed == 0
        rows[name]["cold"] = statistics.median(cold)
        rows[name]["cached"] = statistics.median(cached)
        s = t.summary()
        rows[name]["entries"] = s["entries"]
        rows[name]["distinct"] = s["distinct"]
    for n in (1, 2):
        with LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                          dashboard_address=None) as cluster, Client(cluster) as client:
            from polycontact.distributed import ensure_warm

            ensure_warm(client, ["no-fit polygon", "many moving bodies"])
            for name, inst in instances.items():
                rows[name][f"dask {n}"] = timed(
                    lambda: pc.nfp_table(inst, progress=False, client=client),
                    args.repeat, client)
            if args.impacts:
                got = pc.time_of_impact_many(*impact_pairs(args.impacts), t_max=3, client=client)
                assert same(got, want)
                toi[f"dask {n}"] = spread(
                    lambda p: pc.time_of_impact_many(*p, t_max=3, client=client), args.impacts,
                    args.repeat)
    print(f"{os.cpu_count()} CPUs; medians of {args.repeat} runs, seconds\n")
    if toi:
        print(f"time_of_impact_many, {args.impacts} pairs (median [fastest, slowest])\n")
        print("| " + " | ".join(toi) + " |")
        print("|" + "---:|" * len(toi))
        print("| " + " | ".join(f"{m:.3f} [{lo:.3f}, {hi:.3f}]" for m, lo, hi in toi.values())
              + " |\n")
    if not instances:
        return
    print("| instance | entries | distinct | local | dask 1 | dask 2 | efficiency | cold | cached |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    for name, r in rows.items():
        eff = r["dask 1"] / (2 * r["dask 2"])
        print(f"| {name} | {r['entries']} | {r['distinct']} | {r['local']:.3f} | "
              f"{r['dask 1']:.3f} | {r['dask 2']:.3f} | {eff:.2f} | {r['cold']:.3f} | "
              f"{r['cached']:.3f} |")


if __name__ == "__main__":
    main()
