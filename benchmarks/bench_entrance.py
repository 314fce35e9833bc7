"""Timings of ``entrance_block`` quoted in the README ("The entrance block").

Two random 100-vertex concave star polygons (the stars of ``bench_classify.py``), B
shifted by half a body so they overlap; for each method the time to build the block
and its union (``to_shapely()``), and for ``pairs`` the time of a plain union of every
component (one ``shapely.union_all`` on the same grid), to give the ratio the README
quotes. Medians over ``--pairs`` random pairs, after a warm-up on another pair (the
compiled kernels load from the cache, untimed).

Run: ``python benchmarks/bench_entrance.py [--pairs 5] [--n 100]``
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np
import shapely

sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_classify import star  # noqa: E402

import polycontact as pc  # noqa: E402
from polycontact.tolerances import snap_grid  # noqa: E402


def timed(fn) -> float:
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--pairs", type=int, default=5)
    ap.add_argument("--n", type=int, default=100)
    args = ap.parse_args()
    rng = np.random.default_rng(2026)

    def pair():
        return star(rng, args.n), star(rng, args.n) + np.array([0.5, 0.2])

    a, b = pair()
    pc.entrance_block(a, b, method="pairs").to_shapely()  # warm-up
    rows: dict[str, list[float]] = {"pairs": [], "swept": [], "pairs, plain union": []}
    for _ in range(args.pairs):
        a, b = pair()
        for method in ("pairs", "swept"):
            rows[method].append(timed(lambda: pc.entrance_block(a, b, method=method).to_shapely()))

        def plain():
            eb = pc.entrance_block(a, b, method="pairs")
            shapely.union_all([c.geometry for c in eb.components],
                              grid_size=snap_grid(eb.tolerance))

        rows["pairs, plain union"].append(timed(plain))
    print(f"entrance_block + to_shapely(), two {args.n}-vertex stars, median of {args.pairs}")
    for name, times in rows.items():
        print(f"  {name:20} {statistics.median(times):7.3f} s")
    ratio = [p / q for p, q in zip(rows["pairs, plain union"], rows["pairs"])]
    print(f"  plain union / pairs: {min(ratio):.1f}x to {max(ratio):.1f}x")


if __name__ == "__main__":
    main()
