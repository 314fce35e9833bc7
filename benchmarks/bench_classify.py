"""Benchmark: polycontact.classify against Shapely, and import time.

Run: ``python benchmarks/bench_classify.py`` (add ``--quick`` for fewer repeats).

What is timed (medians of several repeats, peers measured in the same run):
- one pair at a time, from raw (N, 2) float64 arrays: ``classify(a, b)`` (which
  validates both rings and classifies them) against ``shapely.Polygon(a)``,
  ``shapely.Polygon(b)`` then ``.intersects`` / ``.relate`` (Shapely does not check
  validity on construction);
- 100 000 pairs of 12-gons in one call: ``classify_many`` on a (P, N, 2) array against
  ``shapely.relate`` / ``shapely.intersects`` vectorised on prebuilt polygon arrays (and
  with their construction by ``shapely.polygons`` counted);
- prebuilt :class:`polycontact.Shape` pairs against prebuilt Shapely polygons with
  ``shapely.relate`` (a simulation's loop), each called directly (no wrapper function on
  either side: each returns its result object), taking turns every 50 pairs, with the
  target ratio, and under it the same call with a state kernel that does nothing (the
  most any kernel could reach through this call);
- signed distances of the 100 000 pairs (``classify_many(...).distances``) against the
  states alone (also with every pair made distinct: the pairs repeat 3000, and each
  distinct pair's depth is computed once), and for the separate pairs against
  ``shapely.distance`` (targets printed);
- growth from 8 to 1024 vertices;
- ``python -X importtime -c "import polycontact"``.

The bodies are random concave star polygons: a radius of 1 + 0.3 sin(k t + phase) with
k in 2..5, plus a jitter of half the vertex spacing. The pairs are a third separate (B
placed near A without touching), a third contact (A moved out of a random overlap along
a random direction, by bisection, until the boundaries touch within the tolerance) and a
third penetrating. Star-shaped rings pass validation in O(n) (a certificate); a last
table repeats the single-pair timing on random combs, which are not star-shaped and take
the general check.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import time

import numpy as np
import shapely

import polycontact as pc


def star(rng: np.random.Generator, n: int) -> np.ndarray:
    """A random concave star polygon with n vertices, counter-clockwise."""
    t = np.linspace(0, 2 * np.pi, n, endpoint=False) + rng.uniform(0, 2 * np.pi)
    k = rng.integers(2, 6)
    r = 1 + 0.3 * np.sin(k * t + rng.uniform(0, 2 * np.pi))
    r += 0.5 * (2 * np.pi / n) * rng.uniform(-1, 1, n)
    return np.ascontiguousarray(np.c_[np.cos(t) * r, np.sin(t) * r])


def comb(rng: np.random.Generator, n: int) -> np.ndarray:
    """A random comb with n vertices (n divisible by 4, at least 8), counter-clockwise:
    teeth of random depths on a base, scaled to about the size of :func:`star`; not
    star-shaped about any point once it has a few deep teeth."""
    teeth = (n - 4) // 4 + 1
    xs = np.linspace(-1.0, 1.0, 2 * teeth)
    tips = rng.uniform(0.4, 1.0, teeth)
    roots = tips - rng.uniform(0.3, 0.9, teeth)
    ring = [(-1.0, -1.0), (1.0, -1.0)]
    for k in range(teeth - 1, -1, -1):
        ring += [(xs[2 * k + 1], tips[k]), (xs[2 * k], tips[k])]
        if k > 0:
            ring += [(xs[2 * k] - 0.25 * (xs[1] - xs[0]), roots[k]),
                     (xs[2 * k - 1] + 0.25 * (xs[1] - xs[0]), roots[k])]
    return np.ascontiguousarray(np.array(ring[: n]) * 1.3)


def touching(a: np.ndarray, b: np.ndarray, rng: np.random.Generator) -> np.ndarray | None:
    """A moved along a random direction until it just touches B (bisection on the state)."""
    u = rng.normal(size=2)
    u /= np.hypot(*u)
    lo, hi = 0.0, 8.0  # A + lo u overlaps B, A + hi u is clear of it
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        state = pc.classify(a + mid * u, b).state
        if state is pc.State.CONTACT:
            return np.ascontiguousarray(a + mid * u)
        if state is pc.State.PENETRATING:
            lo = mid
        else:
            hi = mid
    return None


def make_pairs(rng: np.random.Generator, n: int, count: int,
               body=star) -> list[tuple[np.ndarray, np.ndarray]]:
    """``count`` pairs of n-gons made by ``body``: separate, contact and penetrating in
    equal parts."""
    out: list[tuple[np.ndarray, np.ndarray]] = []
    want = ["separate", "contact", "penetrating"]
    while len(out) < count:
        kind = want[len(out) % 3]
        a = body(rng, n)
        b = body(rng, n) + rng.uniform(-2.6, 2.6, 2)
        state = pc.classify(a, b).state
        if kind == "separate" and state is pc.State.SEPARATE:
            out.append((a, b))
        elif kind == "penetrating" and state is pc.State.PENETRATING:
            out.append((a, b))
        elif kind == "contact" and state is pc.State.PENETRATING:
            moved = touching(a, b, rng)
            if moved is not None:
                out.append((moved, b))
    return out


def per_call(fn, pairs, repeats: int) -> float:
    """Median over repeats of the mean time per pair, in microseconds."""
    fn(*pairs[0])
    runs = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        for a, b in pairs:
            fn(a, b)
        runs.append((time.perf_counter() - t0) / len(pairs) * 1e6)
    return statistics.median(runs)


def ours(a, b):
    return pc.classify(a, b).state


def rounds(fns: dict, pairs: dict, repeats: int, chunk: int = 50) -> tuple[dict, dict]:
    """Per-pair times (us) of two or more functions, taking turns chunk by chunk
    (``chunk`` pairs each), ``repeats`` times over all pairs, so that a burst of load on
    the shared machine hits all of them alike. Returns ``({name: [time per pair of
    each repeat]}, {name: [time per pair in each chunk]})``; chunk i of every function
    was measured next to chunk i of the others."""
    for name, fn in fns.items():
        fn(*pairs[name][0])
    count = len(next(iter(pairs.values())))
    per_repeat: dict = {name: [] for name in fns}
    per_chunk: dict = {name: [] for name in fns}
    for _ in range(repeats):
        total = dict.fromkeys(fns, 0.0)
        for c0 in range(0, count, chunk):
            for name, fn in fns.items():
                part = pairs[name][c0 : c0 + chunk]
                t0 = time.perf_counter()
                for a, b in part:
                    fn(a, b)
                dt = time.perf_counter() - t0
                total[name] += dt
                per_chunk[name].append(dt / len(part) * 1e6)
        for name in fns:
            per_repeat[name].append(total[name] / count * 1e6)
    return per_repeat, per_chunk


def ratio_text(num: list, den: list, target: float, at_most: bool = False,
               quantiles: bool = False) -> str:
    """``median (spread) x, target: met / met at the median only / not met`` of the
    ratios num / den (per run, or per chunk); the spread is min-max, or the 10th-90th
    percentile with ``quantiles`` (many chunks: the extremes are single load bursts).
    The target is ``>= target`` (``<=`` if ``at_most``); "met" when the whole spread
    meets it."""
    r = np.array(num) / np.array(den)
    med = float(np.median(r))
    lo, hi = (np.percentile(r, 10), np.percentile(r, 90)) if quantiles else (r.min(), r.max())
    ok = (lambda x: x <= target) if at_most else (lambda x: x >= target)
    verdict = ("met" if ok(hi if at_most else lo) else
               "met at the median only" if ok(med) else "not met")
    sign = "<=" if at_most else ">="
    return f"{med:5.2f}x ({lo:.2f}-{hi:.2f})  target {sign} {target:g}x: {verdict}"


def spread(ts: list) -> str:
    return f"{np.median(ts):7.2f} ({min(ts):.2f}-{max(ts):.2f})"


def shapely_intersects(a, b):
    return shapely.Polygon(a).intersects(shapely.Polygon(b))


def shapely_relate(a, b):
    return shapely.Polygon(a).relate(shapely.Polygon(b))


def median_time(fn, repeats: int) -> float:
    fn()
    runs = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        runs.append(time.perf_counter() - t0)
    return statistics.median(runs)


def import_time() -> float:
    """Cumulative import time of polycontact (seconds), from ``-X importtime``."""
    runs = []
    for _ in range(5):
        res = subprocess.run(
            [sys.executable, "-X", "importtime", "-c", "import polycontact"],
            capture_output=True, text=True, check=True,
        )
        line = [ln for ln in res.stderr.splitlines() if ln.rstrip().endswith("| polycontact")]
        runs.append(int(line[-1].split("|")[1]) / 1e6)
    return statistics.median(runs)


def distance_rows(arr_a: np.ndarray, arr_b: np.ndarray, repeats: int) -> None:
    """The signed-distance rows: ``classify_many(...).distances`` of the pairs against
    the states alone, the same with every pair distinct, and the separate pairs
    against ``shapely.distance`` (prebuilt)."""
    print("\nsigned distances of the same 100 000 pairs (seconds, median (min-max) of "
          f"{repeats} runs, each from a fresh classify_many)")
    states_t, dist_t = [], []
    for _ in range(repeats):
        t0 = time.perf_counter()
        batch = pc.classify_many(arr_a, arr_b)
        t1 = time.perf_counter()
        batch.distances  # noqa: B018 - computed on first access
        states_t.append(t1 - t0)
        dist_t.append(time.perf_counter() - t1)
    print(f"  states                                  {spread(states_t)}")
    print(f"  distances (on first access)             {spread(dist_t)}")
    print(f"  distances / states (per run):          {ratio_text(dist_t, states_t, 3.0, True)}")
    # The 100 000 pairs repeat 3000 pairs: the depth is computed once per distinct pair
    # (and the pieces once per distinct body). The same pairs made all distinct (A and B
    # shifted alike by p 2^-20 along x) show the cost of one depth per pair.
    shift = np.zeros((len(arr_a), 1, 2))
    shift[:, 0, 0] = np.arange(len(arr_a)) * 2.0**-20
    uni_a, uni_b = arr_a + shift, arr_b + shift
    uni_states, uni_dist = [], []
    for _ in range(max(3, repeats // 2)):
        t0 = time.perf_counter()
        b_uni = pc.classify_many(uni_a, uni_b)
        t1 = time.perf_counter()
        b_uni.distances  # noqa: B018
        uni_states.append(t1 - t0)
        uni_dist.append(time.perf_counter() - t1)
    print(f"  all pairs distinct ({np.bincount(b_uni.states, minlength=3).tolist()} "
          f"separate/contact/penetrating): states {spread(uni_states)}, distances "
          f"{spread(uni_dist)}")
    print(f"    distances / states (per run):        "
          f"{ratio_text(uni_dist, uni_states, 3.0, True)}")
    n_pen = int(np.sum(b_uni.states == 2))
    print(f"    distances per penetrating pair (wall time on all threads; the depths "
          f"dominate): {1e6 * statistics.median(uni_dist) / max(n_pen, 1):.1f} us")
    sep = batch.states == 0
    sep_a, sep_b = np.ascontiguousarray(arr_a[sep]), np.ascontiguousarray(arr_b[sep])
    poly_sa, poly_sb = shapely.polygons(sep_a), shapely.polygons(sep_b)
    ours_sep, ours_sep_total, geos_sep = [], [], []
    for _ in range(repeats):  # interleaved, fresh batch each time
        t0 = time.perf_counter()
        b_sep = pc.classify_many(sep_a, sep_b)
        t1 = time.perf_counter()
        b_sep.distances  # noqa: B018
        t2 = time.perf_counter()
        shapely.distance(poly_sa, poly_sb)
        t3 = time.perf_counter()
        ours_sep.append(t2 - t1)
        ours_sep_total.append(t2 - t0)
        geos_sep.append(t3 - t2)
    print(f"  the {int(sep.sum())} separate pairs: distances {spread(ours_sep)}, with their "
          f"states {spread(ours_sep_total)}, shapely.distance (prebuilt) {spread(geos_sep)}")
    print(f"    shapely.distance / distances:          {ratio_text(geos_sep, ours_sep, 5.0)}")
    print(f"    shapely.distance / (states+distances): {ratio_text(geos_sep, ours_sep_total, 5.0)}")
    np.testing.assert_allclose(b_sep.distances, shapely.distance(poly_sa, poly_sb),
                               rtol=1e-9, atol=1e-12)


def prebuilt_rows(rng: np.random.Generator, repeats: int, rows) -> None:
    """classify on prebuilt Shapes against shapely.relate on prebuilt polygons, one row
    per (vertices, target ratio)."""
    print("\nclassify on prebuilt Shapes vs shapely.relate on prebuilt polygons (us per "
          f"pair, median (min-max) of {2 * repeats + 1} passes over the pairs, the two "
          "taking turns every 50 pairs; ratio = relate / classify per chunk of 50, median "
          "(10th-90th percentile))")
    print(f"{'vertices':>8} {'classify(Shape, Shape)':>24} {'shapely.relate':>22}  ratio")
    for n, target in rows:
        pairs = make_pairs(rng, n, 600 if n < 1000 else 100)
        shapes = [(pc.Shape(a), pc.Shape(b)) for a, b in pairs]
        geoms = [(shapely.Polygon(a), shapely.Polygon(b)) for a, b in pairs]
        t, chunks = rounds({"ours": pc.classify, "relate": shapely.relate},
                           {"ours": shapes, "relate": geoms}, 2 * repeats + 1,
                           50 if n < 1000 else 10)
        print(f"{n:>8} {spread(t['ours']):>24} {spread(t['relate']):>22}  "
              f"{ratio_text(chunks['relate'], chunks['ours'], target, quantiles=True)}")
        t, chunks = call_floor(shapes, geoms, 2 * repeats + 1, 50 if n < 1000 else 10)
        r = np.array(chunks["relate"]) / np.array(chunks["ours"])
        print(f"{'':>8} {spread(t['ours']):>24} {spread(t['relate']):>22}   "
              f"{np.median(r):.2f}x ({np.percentile(r, 10):.2f}-{np.percentile(r, 90):.2f})"
              "  the call alone, its state kernel doing nothing: the ceiling of the ratio")


def call_floor(shapes: list, geoms: list, repeats: int, chunk: int) -> tuple[dict, dict]:
    """:func:`rounds` of classify on prebuilt Shapes with its state kernel swapped for
    one that reads a number from each shape and returns, against shapely.relate: what
    the call costs around the geometry (checks, unboxing, the Relation, caches emptied by
    GEOS), so ``relate / this`` is the most any state kernel could reach in this call."""
    from numba import njit

    from polycontact import relation
    from polycontact._dispatch import entry_point

    @njit(nogil=True, _nrt=False)
    def nothing(pa, pb, eps):  # (an answer that depends on both shapes)
        return 1 if pa[1] < pb[3] else 0

    real = relation._state_into
    relation._state_into = entry_point(
        nothing, (shapes[0][0]._kernel, shapes[0][1]._kernel, 1.0))
    try:
        return rounds({"ours": pc.classify, "relate": shapely.relate},
                      {"ours": shapes, "relate": geoms}, repeats, chunk)
    finally:
        relation._state_into = real


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer pairs and repeats")
    parser.add_argument("--prebuilt", action="store_true",
                        help="only the prebuilt-Shape rows (12 and 96 vertices)")
    args = parser.parse_args()
    repeats = 3 if args.quick else 7
    rng = np.random.default_rng(20261122)
    pc.warmup()
    if args.prebuilt:
        print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
        prebuilt_rows(rng, repeats, ((12, 5.0), (96, 3.0)))
        return

    print("classify from raw arrays vs Shapely construction + predicate (us per pair)")
    print(f"{'vertices':>8} {'classify':>10} {'intersects':>11} {'relate':>10} "
          f"{'x intersects':>13} {'x relate':>9}")
    for n in (12, 96, 1024):
        count = 600 if n < 1000 else 90
        pairs = make_pairs(rng, n, count)
        t_ours = per_call(ours, pairs, repeats)
        t_int = per_call(shapely_intersects, pairs, repeats)
        t_rel = per_call(shapely_relate, pairs, repeats)
        print(f"{n:>8} {t_ours:>10.2f} {t_int:>11.2f} {t_rel:>10.2f} "
              f"{t_int / t_ours:>13.1f} {t_rel / t_ours:>9.1f}")

    prebuilt_rows(rng, repeats, ((12, 5.0), (96, 3.0), (1024, 1.0)))

    print("\nclassify_many: 100 000 pairs of 12-gons (seconds)")
    base = make_pairs(rng, 12, 3000)
    idx = rng.integers(0, len(base), 100_000)
    arr_a = np.stack([base[i][0] for i in idx])
    arr_b = np.stack([base[i][1] for i in idx])
    poly_a = shapely.polygons(arr_a)
    poly_b = shapely.polygons(arr_b)
    t_many = median_time(lambda: pc.classify_many(arr_a, arr_b).states, repeats)
    t_rel = median_time(lambda: shapely.relate(poly_a, poly_b), repeats)
    t_int = median_time(lambda: shapely.intersects(poly_a, poly_b), repeats)
    t_build = median_time(lambda: (shapely.polygons(arr_a), shapely.polygons(arr_b)), repeats)
    t_dist = median_time(lambda: pc.classify_many(arr_a, arr_b).distances, max(3, repeats // 2))
    print(f"  classify_many (validate + states)      {t_many:8.3f}")
    print(f"  classify_many + signed distances       {t_dist:8.3f}")
    print(f"  shapely.relate (prebuilt)              {t_rel:8.3f}   ratio {t_rel / t_many:6.1f}x")
    print(f"  shapely.intersects (prebuilt)          {t_int:8.3f}   ratio {t_int / t_many:6.1f}x")
    print(f"  shapely.polygons x2 + relate           {t_build + t_rel:8.3f}   "
          f"ratio {(t_build + t_rel) / t_many:6.1f}x")
    distance_rows(arr_a, arr_b, repeats)
    many = pc.classify_many(arr_a, arr_b).states[:3000]
    rel = shapely.relate(poly_a[:3000], poly_b[:3000])
    inter = shapely.intersects(poly_a[:3000], poly_b[:3000])
    oracle = np.where([m[0] == "2" for m in rel], 2, np.where(inter, 1, 0))
    print(f"  states equal to Shapely's (first 3000 pairs): {np.mean(many == oracle):.4f}"
          " (contact pairs are touching only within the tolerance)")

    print("\ngrowth: classify vs Shapely construction + relate (us per pair)")
    print(f"{'vertices':>8} {'classify':>10} {'relate':>10} {'ratio':>7} {'classify/n':>11}")
    for n in (8, 16, 32, 64, 128, 256, 512, 1024):
        pairs = make_pairs(rng, n, 150 if n <= 256 else 60)
        t_ours = per_call(ours, pairs, repeats)
        t_rel = per_call(shapely_relate, pairs, repeats)
        print(f"{n:>8} {t_ours:>10.2f} {t_rel:>10.2f} {t_rel / t_ours:>7.1f} "
              f"{1000 * t_ours / n:>9.1f}ns")

    print("\nclassify on random combs (not star-shaped: the general ring check) vs Shapely "
          "construction + predicate (us per pair)")
    print(f"{'vertices':>8} {'classify':>10} {'intersects':>11} {'relate':>10} "
          f"{'x intersects':>13} {'x relate':>9}")
    for n in (12, 96, 1024):
        pairs = make_pairs(rng, n, 300 if n < 1000 else 60, body=comb)
        t_ours = per_call(ours, pairs, repeats)
        t_int = per_call(shapely_intersects, pairs, repeats)
        t_rel = per_call(shapely_relate, pairs, repeats)
        print(f"{n:>8} {t_ours:>10.2f} {t_int:>11.2f} {t_rel:>10.2f} "
              f"{t_int / t_ours:>13.1f} {t_rel / t_ours:>9.1f}")

    print(f"\nimport polycontact: {import_time():.3f} s (cumulative, -X importtime, median of 5)")


if __name__ == "__main__":
    main()
