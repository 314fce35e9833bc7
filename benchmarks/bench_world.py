"""Benchmark: a World of many bodies against Shapely 2 (STRtree + relate).

Run: ``python benchmarks/bench_world.py`` (``--quick``: 10³ and 10⁴ bodies only, fewer
repeats; ``--threads 1``: the parallel kernels on one thread). Medians of several
repeats; the peers are measured in the same run.

1. All contacts of N random concave 12-gons packed densely (N = 10³, 10⁴, 10⁵): stars
   of radius about 0.6 on a jittered unit grid, so each body meets a few neighbours
   (both touching-free overlaps and near misses). Timed:
   - ``world.contacts()`` on a World already holding the bodies (its broad phase is kept
     up to date by ``add``/``move``/``remove``, as in a block system stepping on);
   - building that World (``add_many``: validation of every ring and the broad phase),
     reported apart;
   - Shapely: ``STRtree(polys)``, ``tree.query(polys, predicate="intersects")`` and
     ``shapely.relate`` on the candidate pairs (i < j), polygons prebuilt, vectorised.
2. Placement queries in the protocol of jagua-rs's benchmark: the published swim layout
   (``../shared/datasets/layouts/swim.json``) with 5 items removed; 1 000 random
   placements of each removed item (centroid uniform in the container's box, rotation
   drawn from the item's allowed orientations); ``world.query_many`` (one call per
   item) in ns per placement, against Shapely vectorised: the placed polygons built by
   ``shapely.polygons``, ``covers(container, polys)`` and ``STRtree.query(polys,
   predicate="intersects")`` with ``relate`` on the candidates.
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
from pathlib import Path

import numpy as np
import shapely
from numba import njit

import polycontact as pc

DATASETS = next((p / "shared" / "datasets" for p in Path(__file__).resolve().parents[1:4]
                 if (p / "shared" / "datasets").is_dir()), None)


def stars(rng: np.random.Generator, count: int, n: int = 12) -> np.ndarray:
    """``count`` random concave n-gons on a jittered unit grid, (count, n, 2)."""
    side = int(np.ceil(np.sqrt(count)))
    k = np.arange(count)
    centres = np.c_[k % side, k // side] + rng.uniform(-0.1, 0.1, (count, 2))
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)[None, :] + rng.uniform(0, 2 * np.pi,
                                                                               (count, 1))
    r = np.where(np.arange(n) % 2 == 0, 0.62, 0.38)[None, :] * rng.uniform(0.9, 1.1,
                                                                             (count, n))
    xy = np.stack([np.cos(t) * r, np.sin(t) * r], axis=2) + centres[:, None, :]
    return np.ascontiguousarray(xy)


@njit(cache=True)
def sweep_and_prune(box: np.ndarray) -> int:
    """Candidate pairs by sorting boxes on x0 and sweeping (the alternative broad phase
    measured against the World's grid); returns their count."""
    order = np.argsort(box[:, 0])
    n = 0
    for a in range(order.shape[0]):
        i = order[a]
        for b in range(a + 1, order.shape[0]):
            j = order[b]
            if box[j, 0] > box[i, 1]:
                break
            if box[j, 2] <= box[i, 3] and box[j, 3] >= box[i, 2]:
                n += 1
    return n


CPU = {}  # fn name -> median process time (all threads) of the last timed() call


def timed(fn, repeats: int, name: str = "") -> tuple[float, object]:
    """Median wall time and the last result; the median process time goes to CPU[name]
    (on a loaded machine it is the fairer measure: waiting for a core is not counted)."""
    times, cpu = [], []
    out = None
    for _ in range(repeats):
        t0, c0 = time.perf_counter(), time.process_time()
        out = fn()
        times.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
    CPU[name] = statistics.median(cpu)
    return statistics.median(times), out


def shapely_contacts(polys: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    tree = shapely.STRtree(polys)
    i, j = tree.query(polys, predicate="intersects")
    keep = i < j
    i, j = i[keep], j[keep]
    m = shapely.relate(polys[i], polys[j])
    pen = np.array([s[0] != "F" for s in m], dtype=bool)
    return np.c_[i, j], np.where(pen, 2, 1).astype(np.int8)


def bench_contacts(sizes: list[int], repeats: int) -> None:
    print("All contacts of N random concave 12-gons, packed densely (median seconds)")
    print(f"{'N':>7} {'pairs':>7} {'world.contacts':>15} {'per body':>10} {'CPU/body':>9} "
          f"{'Shapely':>10} {'ratio':>7} {'CPU ratio':>10} {'build World':>12} "
          f"{'same answer':>12}")
    rng = np.random.default_rng(1)
    pc.World().add_many(stars(rng, 10))  # compile / warm
    for n in sizes:
        rings = stars(rng, n)
        world = pc.World()
        t0 = time.perf_counter()
        world.add_many(rings)
        build = time.perf_counter() - t0
        world.contacts()  # compile / warm
        reps = repeats if n < 100_000 else max(3, repeats // 2)
        tw, got = timed(world.contacts, reps, "ours")
        polys = shapely.polygons(rings)
        ts, (sp, ss) = timed(lambda: shapely_contacts(polys), reps, "shapely")
        order = np.lexsort((sp[:, 1], sp[:, 0]))
        same = got.pairs.tolist() == sp[order].tolist() and got.states.tolist() == \
            ss[order].tolist()
        print(f"{n:>7} {len(got):>7} {tw:>15.4f} {1e6 * tw / n:>8.2f}µs "
              f"{1e6 * CPU['ours'] / n:>7.2f}µs {ts:>10.4f} "
              f"{ts / tw:>6.1f}× {CPU['shapely'] / CPU['ours']:>9.1f}× {build:>11.3f}s "
              f"{str(same):>12}")


def bench_broad_phase(sizes: list[int], repeats: int) -> None:
    """The World's loose grid against sweep and prune, candidate pairs only."""
    from polycontact._kernels import world as kw

    print()
    print("Broad phase alone (candidate pairs of the same bodies; median µs per body)")
    print(f"{'N':>7} {'candidates':>11} {'grid':>8} {'sweep and prune':>16}")
    rng = np.random.default_rng(1)
    for n in sizes:
        w = pc.World()
        w.add_many(stars(rng, n))
        alive = np.sort(w._alive())
        grid = w._grid()

        def ours():
            return kw.candidate_pairs(grid, w._box, w._eps, -1.0, alive, w._next, 0.0)

        box = np.ascontiguousarray(w._box[alive])
        ours()
        sweep_and_prune(box)
        tg, (pi, _) = timed(ours, repeats)
        tp, count = timed(lambda: sweep_and_prune(box), repeats)
        print(f"{n:>7} {len(pi):>11} {1e6 * tg / n:>8.2f} {1e6 * tp / n:>16.2f}"
              f"   (sweep finds {count} box pairs)")


def bench_placements(repeats: int) -> None:
    if DATASETS is None:
        print("placement queries: ../shared/datasets absent, skipped")
        return
    layout = json.loads((DATASETS / "layouts" / "swim.json").read_text())
    inst = json.loads((DATASETS / "esicup" / "swim.json").read_text())
    allowed = {str(it["id"]): it["allowed_orientations"] for it in inst["items"]}
    rng = np.random.default_rng(5)
    placed = layout["placed"]
    removed = set(rng.choice(len(placed), 5, replace=False).tolist())
    container = pc.Shape(layout["container"])
    world = pc.World(container)
    kept = []
    for k, it in enumerate(placed):
        if k not in removed:
            world.add(pc.Shape(it["vertices"]))
            kept.append(shapely.Polygon(it["vertices"]))
    tree = shapely.STRtree(kept)
    c_poly = container.to_shapely()
    lo, hi = container.exterior.min(axis=0), container.exterior.max(axis=0)
    jobs = []
    for k in sorted(removed):
        item = pc.Shape(layout["items"][str(placed[k]["item"])])
        pos = rng.uniform(lo, hi, (1000, 2))
        ang = np.radians(rng.choice(allowed[str(placed[k]["item"])], 1000))
        jobs.append((item, pos, ang))
    for item, pos, ang in jobs:
        world.query_many(item, pos[:10], ang[:10])  # compile / warm

    def ours():
        return [world.query_many(item, pos, ang) for item, pos, ang in jobs]

    def theirs():
        out = []
        for item, pos, ang in jobs:
            c = item.centroid
            xy = item.exterior - c
            cs, sn = np.cos(ang)[:, None], np.sin(ang)[:, None]
            rings = np.stack([xy[:, 0] * cs - xy[:, 1] * sn + pos[:, :1],
                              xy[:, 0] * sn + xy[:, 1] * cs + pos[:, 1:]], axis=2)
            polys = shapely.polygons(rings)
            worst = np.where(shapely.covers(c_poly, polys), 0, 2).astype(np.int8)
            i, j = tree.query(polys, predicate="intersects")
            m = shapely.relate(polys[i], np.asarray(kept)[j])
            st = np.array([2 if s[0] != "F" else 1 for s in m], dtype=np.int8)
            np.maximum.at(worst, i, st)
            out.append(worst)
        return out

    tw, got = timed(ours, repeats, "ours")
    ts, ref = timed(theirs, repeats, "shapely")
    count = sum(len(p) for _, p, _ in jobs)
    agree = np.mean(np.concatenate(got) == np.concatenate(ref))
    fits = np.mean(np.concatenate(got) < 2)
    print()
    print("Placement queries, jagua-rs protocol: swim layout, 5 items removed, 1000 random "
          "placements each")
    print(f"  bodies {len(world)}, placements {count}, fitting {100 * fits:.1f}%")
    print(f"  query_many  {1e9 * tw / count:9.0f} ns/placement   CPU "
          f"{1e9 * CPU['ours'] / count:6.0f} ns/placement")
    print(f"  Shapely     {1e9 * ts / count:9.0f} ns/placement   CPU "
          f"{1e9 * CPU['shapely'] / count:6.0f} ns/placement   ratio {ts / tw:.1f}× (CPU "
          f"{CPU['shapely'] / CPU['ours']:.1f}×)")
    print(f"  same worst state as Shapely (touching aside): {100 * agree:.2f}% of placements")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="10³ and 10⁴ only, 3 repeats")
    parser.add_argument("--threads", type=int, default=0,
                        help="Numba threads for the parallel kernels (default: all)")
    args = parser.parse_args()
    import numba

    if args.threads:
        numba.set_num_threads(args.threads)

    import os

    print(f"threads: {numba.get_num_threads()}, load average {os.getloadavg()[0]:.1f} on "
          f"{os.cpu_count()} cores")
    sizes = [1_000, 10_000] if args.quick else [1_000, 10_000, 100_000]
    repeats = 3 if args.quick else 7
    bench_contacts(sizes, repeats)
    bench_broad_phase(sizes, repeats)
    bench_placements(repeats)


if __name__ == "__main__":
    main()
