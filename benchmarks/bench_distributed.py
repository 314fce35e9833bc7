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
Run: ``python benchmarks/bench_distributed.py [--repeat 3] [--data DIR] [instance ...]``.
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
    from polycontact import nfp

    nfp._PIECES_CACHE.clear()


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


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("instances", nargs="*", default=["jakobs1", "jakobs2"])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--data", type=Path, default=DATA,
                        help=f"directory of the ESICUP files (default {DATA})")
    args = parser.parse_args()
    from distributed import Client, LocalCluster

    pc.warmup(["no-fit polygon"])
    instances = {name: pc.read_esicup(args.data / f"{name}.json") for name in args.instances}
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

            ensure_warm(client, ["no-fit polygon"])
            for name, inst in instances.items():
                rows[name][f"dask {n}"] = timed(
                    lambda: pc.nfp_table(inst, progress=False, client=client),
                    args.repeat, client)
    print(f"{os.cpu_count()} CPUs; medians of {args.repeat} runs, seconds\n")
    print("| instance | entries | distinct | local | dask 1 | dask 2 | efficiency | cold | cached |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    for name, r in rows.items():
        eff = r["dask 1"] / (2 * r["dask 2"])
        print(f"| {name} | {r['entries']} | {r['distinct']} | {r['local']:.3f} | "
              f"{r['dask 1']:.3f} | {r['dask 2']:.3f} | {eff:.2f} | {r['cold']:.3f} | "
              f"{r['cached']:.3f} |")


if __name__ == "__main__":
    main()
