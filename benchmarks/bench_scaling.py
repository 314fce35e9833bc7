"""How the penetration depth and the no-fit polygon scale with the number of vertices.

Rows at 10³, 10⁴ and 10⁵ vertices (the total of both bodies), each measured in a fresh
process (so the peak memory is that row's: ``ru_maxrss``, the resident set, which also
counts Numba's and GEOS's allocations that ``tracemalloc`` cannot see), after a warm-up
call on small bodies (compiled kernels loaded from the cache, not timed). Seconds: the
median of ``--repeat`` calls, each on fresh random bodies (another seed, so no
decomposition cache is reused), with the smallest and largest as the spread. Where
Shapely can build the same result (the no-fit polygon of a convex A: B triangulated by
GEOS, the convex hulls of each triangle summed with -A, one snap-rounded
``union_all``), that peer is timed the same way on the same bodies.

Cases (all bodies random but seeded):
- ``depth, square in star``: a unit square inside a star of n vertices around it
  (radii 1.5 to 3): the square must leave through the star's narrowest opening;
- ``depth, stars rim``: two stars of n/2 vertices each whose rims overlap (centres
  1.4 apart, radii 0.5 to 1): the common case, a shallow penetration;
- ``depth, stars deep``: two stars of n/2 vertices around nearly the same centre (the
  worst case: every spike of one crosses spikes of the other, so O(m n) sums of pieces
  lie within the depth; only 10³);
- ``nfp, star x square``: the no-fit polygon of a square orbiting a star of n vertices;
- ``nfp, circle x circle``: convex bodies of n/10 and 9n/10 vertices.

Run: ``python benchmarks/bench_scaling.py [--repeat 5] [--max 100000]``
"""

from __future__ import annotations

import argparse
import json
import resource
import subprocess
import sys
import time

import numpy as np

SIZES = (1000, 10000, 100000)


def star(rng: np.random.Generator, n: int, centre=(0.0, 0.0), lo=0.5, hi=1.0) -> np.ndarray:
    t = 2.0 * np.pi * (np.arange(n) + rng.uniform(0.1, 0.9, n)) / n
    r = rng.uniform(lo, hi, n)
    return np.column_stack((centre[0] + r * np.cos(t), centre[1] + r * np.sin(t)))


def circle(n: int, r: float, centre=(0.0, 0.0)) -> np.ndarray:
    t = 2.0 * np.pi * np.arange(n) / n
    return np.column_stack((centre[0] + r * np.cos(t), centre[1] + r * np.sin(t)))


SQUARE = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])


def bodies(case: str, n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    if case in ("depth, square in star", "nfp, star x square"):
        return SQUARE.copy(), star(rng, n - 4, (0.5, 0.5), 1.5, 3.0)
    if case == "depth, stars rim":
        return star(rng, n // 2), star(rng, n - n // 2, (1.4, 0.1))
    if case == "depth, stars deep":
        return star(rng, n // 2), star(rng, n - n // 2, (0.3, 0.1))
    return circle(n // 10, 1.0), circle(n - n // 10, 2.0, (0.1, 0.0))


def shapely_nfp(a: np.ndarray, b: np.ndarray):
    """The peer: E(A, B) for a convex A by Shapely (reference "origin")."""
    import shapely

    tris = shapely.get_parts(shapely.constrained_delaunay_triangles(shapely.Polygon(b)))
    coords = shapely.get_coordinates(tris).reshape(-1, 4, 2)[:, :3]
    sums = (coords[:, :, None, :] - a[None, None, :, :]).reshape(len(coords), -1, 2)
    hulls = shapely.convex_hull(shapely.multipoints(sums))
    return shapely.union_all(hulls, grid_size=2.0**-40)


def one_row(case: str, n: int, repeat: int) -> dict:
    """Measure one row in this process (called in a fresh process by :func:`main`)."""
    import polycontact as pc

    def call(a, b):
        if case.startswith("depth"):
            rel = pc.classify(a, b)
            assert rel.state is pc.State.PENETRATING, case
            return -rel.distance
        return pc.no_fit_polygon(a, b, reference="origin").region.area

    call(*bodies(case, 60, 99))  # warm-up: load the compiled kernels
    times = []
    peer = []
    value = peer_value = None
    for k in range(repeat):
        a, b = bodies(case, n, k)
        t0 = time.perf_counter()
        value = call(a, b)
        times.append(time.perf_counter() - t0)
        if case == "nfp, star x square":
            t0 = time.perf_counter()
            peer_value = shapely_nfp(a, b).area
            peer.append(time.perf_counter() - t0)
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0
    row = {"case": case, "n": n, "seconds": float(np.median(times)), "min": min(times),
           "max": max(times), "peak_mb": peak, "value": value}
    if peer:
        row.update(shapely=float(np.median(peer)), shapely_value=peer_value)
    return row


def row_in_fresh_process(cmd: list[str], timeout: float) -> dict | str:
    """Run ``cmd`` (a script's ``--row`` mode, which prints its row as JSON on its last
    line) in a fresh process: the row, or why there is none: ``"> N"`` past ``timeout``
    seconds, ``"killed (memory?)"`` or ``"failed (code)"``."""
    try:
        run = subprocess.run(cmd, capture_output=True, text=True, check=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return f"> {int(timeout)}"
    except subprocess.CalledProcessError as err:
        return "killed (memory?)" if err.returncode < 0 else f"failed ({err.returncode})"
    row: dict = json.loads(run.stdout.strip().splitlines()[-1])
    return row


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--max", type=int, default=SIZES[-1], help="largest size measured")
    ap.add_argument("--timeout", type=float, default=1800.0, help="seconds per row")
    ap.add_argument("--case", action="append", help="only this case (repeatable)")
    ap.add_argument("--row", nargs=2, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.row:
        print(json.dumps(one_row(args.row[0], int(args.row[1]), args.repeat)))
        return
    cases = ["depth, square in star", "depth, stars rim", "depth, stars deep",
             "nfp, star x square", "nfp, circle x circle"]
    print(f"{'case':24} {'vertices':>9} {'median s':>10} {'min..max s':>17} {'peak MB':>8}"
          f" {'shapely s':>10}")
    for case in args.case or cases:
        for n in SIZES:
            if n > args.max or (case == "depth, stars deep" and n > 1000):
                continue
            cmd = [sys.executable, __file__, "--repeat", str(args.repeat), "--row", case, str(n)]
            row = row_in_fresh_process(cmd, args.timeout)
            if isinstance(row, str):
                print(f"{case:24} {n:9d} {row:>10}", flush=True)
                continue
            spread = f"{row['min']:.3f}..{row['max']:.3f}"
            peer = f"{row['shapely']:10.3f}" if "shapely" in row else f"{'':>10}"
            print(f"{case:24} {n:9d} {row['seconds']:10.3f} {spread:>17} {row['peak_mb']:8.0f}"
                  f" {peer}", flush=True)


if __name__ == "__main__":
    main()
