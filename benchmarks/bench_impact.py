"""Time of impact: exact vs sampled on the paper's cases, exact vs Box2D's b2TimeOfImpact.

Run: ``python benchmarks/bench_impact.py [--pairs N] [--repeat R]``. Needs the ``bench``
extra (``box2d``). Prints, in one run:

1. both paper cases, exact vs sampled at the same time tolerance (1e-4 s): time per
   query (full API call and kernel only; the methods take turns in rounds of 100
   calls, 4R + 1 rounds) and whether the answer is the first penetration found by an
   independent Shapely oracle; then the smallest number of samples per round with
   which the sampled method finds it;
2. pairs of random convex octagons with constant velocity and angular velocity over one
   step [0, 1]: time per query of ``time_of_impact`` (API, kernel through the Numba
   dispatcher, compiled kernel called directly) and of Box2D's ``b2TimeOfImpact``
   (through pybox2d), taking turns, with the ratios API / kernel and API / Box2D and
   their targets (<= 1.3, <= 2.5), and how often each gets the wrong answer,
   judged by the Shapely oracle (dense sampling + bisection). Half the pairs spin
   slowly (|ω| <= 3 rad per step), half fast (|ω| up to 40 rad per step).

Timings are medians over repeats; the machine is shared, so compare ratios measured in
the same run rather than absolute figures.
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import numpy as np
import shapely

import polycontact as pc
from polycontact import Motion, Shape
from polycontact._kernels import impact as ki
from polycontact._dispatch import entry_point
from polycontact.impact import body_frame
from polycontact.limits import BROAD_PHASE_INFLATION, CONTACT_RESOLUTION, RELATIVE_TOLERANCE
from polycontact.tolerances import ROUNDING_FACTOR

ROOT = Path(__file__).resolve().parent.parent
TOL = 1e-4


# -- an independent oracle -------------------------------------------------------------
def place(shape: Shape, motion: Motion, t: float) -> shapely.Polygon:
    c = shape.centroid
    th = motion.angular_velocity * t + 0.5 * motion.angular_acceleration * t * t
    rot = np.array([[math.cos(th), -math.sin(th)], [math.sin(th), math.cos(th)]])
    shift = np.asarray(motion.velocity) * t + 0.5 * np.asarray(motion.acceleration) * t * t
    loops = [(loop - c) @ rot.T + c + shift for loop in shape.loops]
    return shapely.Polygon(loops[0], loops[1:])


def penetrates(a, ma, b, mb, t) -> bool:
    return bool(shapely.relate_pattern(place(a, ma, t), place(b, mb, t), "2********"))


def oracle(a, ma, b, mb, t_max, n) -> float | None:
    ts = np.linspace(0.0, t_max, n)
    prev = 0.0
    for t in ts:
        if penetrates(a, ma, b, mb, t):
            lo, hi = prev, t
            while hi - lo > 1e-8:
                mid = 0.5 * (lo + hi)
                lo, hi = (lo, mid) if penetrates(a, ma, b, mb, mid) else (mid, hi)
            return hi
        prev = t
    return None


def truth(a, ma, b, mb, t_max, n, exact: pc.Impact) -> tuple[float | None, bool]:
    """First penetration: the oracle's, or an earlier one that Shapely confirms.

    A very short clip can fall between the oracle's samples; when the exact method
    reports an earlier time, Shapely checks it (penetrating at ``time``, not at the
    bracket's start) and the second value says the oracle alone had missed it.
    """
    first = oracle(a, ma, b, mb, t_max, n)
    if exact.collides and (first is None or exact.time < first - TOL):
        lo, hi = exact.time_bracket
        if penetrates(a, ma, b, mb, hi) and not penetrates(a, ma, b, mb, lo):
            return hi, True
    return first, False


def median_time(fn, repeat: int) -> float:
    fn()
    ts = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t0)
    return float(np.median(ts))


def kernel_query(a, ma, b, mb, t_max, method="exact", samples=10, compiled=False):
    """What a query costs without building the result: broad phase + search, the one
    kernel call ``time_of_impact`` makes (``_kernels.impact.exact_call`` on each body's
    packed frame, or ``sampled_query``), with a scratch buffer made once. The
    body-frame tables are built once per shape (as ``time_of_impact`` does) before
    timing, like ``Shape.packed``. ``compiled``: call the compiled code directly (as
    ``time_of_impact`` does, see ``polycontact._dispatch``) rather than through the
    Numba dispatcher."""
    ra, _, _, pa = body_frame(a)
    rb, _, _, pb = body_frame(b)
    va, vb = ma.array, mb.array
    lam = CONTACT_RESOLUTION * (a.bounding_radius + b.bounding_radius)
    eps_rel = RELATIVE_TOLERANCE * max(a._extent, b._extent)
    la, lb = a.bounding_radius, b.bounding_radius
    work = np.empty(ki.work_floats(len(ra) + len(rb)))  # (the API's is kept per thread)

    if method == "exact":
        kernel = ki.exact_call
        args = (*pa, va, *pb, vb, t_max, BROAD_PHASE_INFLATION, TOL, eps_rel, ROUNDING_FACTOR,
                lam, 1_000_000, work)
    else:
        kernel = ki.sampled_query
        args = ((ra, a.packed[1], a.centroid, la), va, (rb, b.packed[1], b.centroid, lb), vb,
                (t_max, BROAD_PHASE_INFLATION, TOL, eps_rel, ROUNDING_FACTOR, 0.0, 1_000_000,
                 samples),
                work)
    if compiled:
        kernel = entry_point(kernel, args)
    return lambda: kernel(*args)


# -- 1. the paper's cases ----------------------------------------------------------------
def interleaved_times(fns: dict, repeat: int, batch: int = 100) -> tuple[dict, dict]:
    """Per-call times of several functions measured in turn, ``repeat`` rounds of
    ``batch`` calls each (so that a burst of load on the machine hits all of them):
    ``(medians, ratios)`` with each one's median and, for each, the median over rounds
    of its time divided by the first function's in the same round."""
    for fn in fns.values():
        fn()
    rounds = {name: [] for name in fns}
    for _ in range(repeat):
        for name, fn in fns.items():
            t0 = time.perf_counter()
            for _ in range(batch):
                fn()
            rounds[name].append((time.perf_counter() - t0) / batch)
    first = np.array(next(iter(rounds.values())))
    return ({name: float(np.median(ts)) for name, ts in rounds.items()},
            {name: float(np.median(np.array(ts) / first)) for name, ts in rounds.items()})


def paper_cases(repeat: int) -> None:
    print("== Paper cases: exact vs sampled (n = 10), time tolerance 1e-4 s ==")
    print(f"(medians of {4 * repeat + 1} rounds of 100 calls, the methods taking turns; "
          "ratios are medians of the per-round ratios)")
    print(f"{'case':>4} {'method':>8} {'time (s)':>11} {'right':>6} {'API us':>8} "
          f"{'kernel us':>10} {'steps/samples':>14}")
    for k in (1, 2):
        scene = pc.load_scene(ROOT / f"examples/paper-case-{k}.json", repair=True)
        (A, B) = scene.bodies
        a, ma, b, mb = A.shape, A.motion, B.shape, B.motion
        exact = pc.time_of_impact(a, ma, b, mb, t_max=scene.t_max)
        first, _ = truth(a, ma, b, mb, scene.t_max, 8000, exact)
        hits = {m: pc.time_of_impact(a, ma, b, mb, t_max=scene.t_max, method=m)
                for m in ("exact", "sampled")}
        api, api_ratio = interleaved_times(
            {m: (lambda m=m: pc.time_of_impact(a, ma, b, mb, t_max=scene.t_max, method=m))
             for m in ("exact", "sampled")}, 4 * repeat + 1)
        kern, kern_ratio = interleaved_times(
            {m: kernel_query(a, ma, b, mb, scene.t_max, m) for m in ("exact", "sampled")},
            4 * repeat + 1)
        for method, hit in hits.items():
            right = hit.collides and abs(hit.time - first) <= TOL
            print(f"{k:>4} {method:>8} {hit.time:>11.5f} {str(right):>6} "
                  f"{api[method] * 1e6:>8.1f} {kern[method] * 1e6:>10.1f} {hit.iterations:>14}")
        print(f"     oracle first penetration {first:.5f} s; exact/sampled time ratio: "
              f"API {1 / api_ratio['sampled']:.2f}, kernel {1 / kern_ratio['sampled']:.2f}")
        for n in (10, 20, 50, 100, 200, 500, 1000, 2000):
            hit = pc.time_of_impact(a, ma, b, mb, t_max=scene.t_max, method="sampled",
                                    samples=n)
            if hit.collides and abs(hit.time - first) <= TOL:
                times, ratio = interleaved_times(
                    {"exact": kernel_query(a, ma, b, mb, scene.t_max, "exact"),
                     "sampled": kernel_query(a, ma, b, mb, scene.t_max, "sampled", n)},
                    4 * repeat + 1)
                print(f"     sampled finds it from n = {n} samples per round "
                      f"(kernel {times['sampled'] * 1e6:.1f} us, {ratio['sampled']:.2f} x exact)")
                break
        else:
            print("     sampled does not find it with up to 2000 samples per round")


# -- 2. Box2D --------------------------------------------------------------------------
def octagon(rng: np.random.Generator) -> np.ndarray:
    ang = np.arange(8) * math.pi / 4
    pts = np.column_stack([np.cos(ang) * rng.uniform(0.3, 0.7),
                           np.sin(ang) * rng.uniform(0.3, 0.7)])
    rot = rng.uniform(0, 2 * math.pi)
    r = np.array([[math.cos(rot), -math.sin(rot)], [math.sin(rot), math.cos(rot)]])
    return pts @ r.T


def box2d_query(a: Shape, ma: Motion, b: Shape, mb: Motion):
    import Box2D

    def shape(s: Shape):
        return Box2D.b2PolygonShape(vertices=[tuple(p) for p in s.exterior - s.centroid])

    def sweep(s: Shape, m: Motion):
        sw = Box2D.b2Sweep()
        sw.localCenter = (0.0, 0.0)
        sw.c0 = tuple(s.centroid)
        sw.c = tuple(s.centroid + np.asarray(m.velocity))
        sw.a0 = 0.0
        sw.a = m.angular_velocity
        sw.alpha0 = 0.0
        return sw

    pa, pb, sa, sb = shape(a), shape(b), sweep(a, ma), sweep(b, mb)
    return lambda: Box2D.b2TimeOfImpact(shapeA=pa, shapeB=pb, sweepA=sa, sweepB=sb, tMax=1.0)


def box2d_vs_exact(pairs: int, repeat: int) -> None:
    import Box2D

    touching = Box2D.b2TOIOutput.e_touching
    # Box2D stops when the core polygons are within its target distance (a fraction of
    # b2_linearSlop = 0.005 around the polygon skin of 0.01); anything within 0.025 of
    # touching at its reported time counts as a right answer for it.
    skin = 0.025
    rng = np.random.default_rng(20260521)
    rows = []
    for i in range(pairs):
        fast = i % 2 == 1
        wmax = 40.0 if fast else 3.0
        a = Shape(octagon(rng))
        b = Shape(octagon(rng)).moved((rng.uniform(1.6, 2.6), rng.uniform(-0.7, 0.7)))
        ma = Motion(velocity=(rng.uniform(0.5, 2.0), rng.normal(0, 0.3)),
                    angular_velocity=rng.uniform(-wmax, wmax))
        mb = Motion(velocity=(-rng.uniform(0.0, 1.5), rng.normal(0, 0.3)),
                    angular_velocity=rng.uniform(-wmax, wmax))
        exact = pc.time_of_impact(a, ma, b, mb, t_max=1.0)
        first, oracle_missed = truth(a, ma, b, mb, 1.0, 4000, exact)
        if penetrates(a, ma, b, mb, 0.0):
            continue
        ours_right = (exact.collides == (first is not None)) and (
            first is None or abs(exact.time - first) <= TOL)
        b2 = box2d_query(a, ma, b, mb)
        state, t_b2 = b2()
        if state == touching and t_b2 < 1.0:
            gap = shapely.distance(place(a, ma, t_b2), place(b, mb, t_b2))
            early_ok = first is None or t_b2 <= first + TOL
            b2_right = early_ok and gap <= skin
        else:
            b2_right = first is None
        times, ratios = interleaved_times({
            "api": lambda: pc.time_of_impact(a, ma, b, mb, t_max=1.0),
            "kernel": kernel_query(a, ma, b, mb, 1.0),
            "compiled": kernel_query(a, ma, b, mb, 1.0, compiled=True),
            "b2": b2,
        }, repeat, batch=20)
        rows.append({
            "fast": fast, "hit": first is not None, "ours": ours_right, "b2": b2_right,
            "oracle_missed": oracle_missed,
            **{f"t_{k}": v for k, v in times.items()},
            # per-round ratios against the API call, inverted: API / kernel, API / Box2D
            **{f"api_over_{k}": 1.0 / v for k, v in ratios.items()},
        })
    print(f"\n== Convex octagons, one step [0, 1], constant v and ω: exact vs Box2D "
          f"b2TimeOfImpact ({len(rows)} pairs) ==")
    print(f"(per pair: medians of {repeat} rounds of 20 calls each, the four taking turns; "
          "table: median over the pairs, ratios are medians of the per-pair ratios with "
          "their 10th-90th percentile; 'kernel' goes through the Numba dispatcher, "
          "'compiled' calls the compiled code as time_of_impact does)")
    print(f"{'spin':>6} {'pairs':>5} {'hits':>5} {'ours wrong':>10} {'Box2D wrong':>11} "
          f"{'API us':>7} {'kernel us':>9} {'compiled us':>11} {'Box2D us':>8} "
          f"{'API/kernel':>17} {'API/compiled':>17} {'API/Box2D':>17}")

    def pct(rs, key):
        v = np.array([r[key] for r in rs])
        return f"{np.median(v):5.2f} ({np.percentile(v, 10):.2f}-{np.percentile(v, 90):.2f})"

    for label, sel in (("slow", False), ("fast", True), ("all", None)):
        rs = [r for r in rows if sel is None or r["fast"] == sel]
        med = {k: np.median([r[f"t_{k}"] for r in rs]) * 1e6
               for k in ("api", "kernel", "compiled", "b2")}
        print(f"{label:>6} {len(rs):>5} {sum(r['hit'] for r in rs):>5} "
              f"{sum(not r['ours'] for r in rs):>10} {sum(not r['b2'] for r in rs):>11} "
              f"{med['api']:>7.1f} {med['kernel']:>9.1f} {med['compiled']:>11.1f} "
              f"{med['b2']:>8.1f} {pct(rs, 'api_over_kernel'):>17} "
              f"{pct(rs, 'api_over_compiled'):>17} {pct(rs, 'api_over_b2'):>17}")
    for key, target, what in (("api_over_kernel", 1.3, "API <= 1.3 x kernel"),
                              ("api_over_compiled", 1.3, "API <= 1.3 x compiled kernel"),
                              ("api_over_b2", 2.5, "API <= 2.5 x Box2D")):
        v = np.array([r[key] for r in rows])
        verdict = ("met for every pair" if v.max() <= target else
                   "met at the median only" if np.median(v) <= target else "not met")
        print(f"target {what}: median {np.median(v):.2f}, worst pair {v.max():.2f}: {verdict}")
    print(f"target 0 misses: ours wrong on {sum(not r['ours'] for r in rows)} pairs")
    missed = sum(r["oracle_missed"] for r in rows)
    print(f"(the 4000-sample oracle alone missed {missed} short clips that the exact method "
          "found and Shapely confirmed)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pairs", type=int, default=200)
    parser.add_argument("--repeat", type=int, default=7)
    parser.add_argument("--box2d-only", action="store_true",
                        help="only the octagon set against Box2D (part 2)")
    args = parser.parse_args()
    # Compile (or load) the kernels the way the README tells users to, first. The code
    # Numba caches depends on the order: the sampled search measures 10-15% faster when
    # it is compiled into an empty cache before the classifier than after it (as
    # warmup(), the test suite or any classify call leaves it); the exact search does
    # not change. Starting from warmup() makes the figures independent of what ran
    # before; the README gives both.
    pc.warmup()
    if not args.box2d_only:
        paper_cases(args.repeat)
    box2d_vs_exact(args.pairs, args.repeat)


if __name__ == "__main__":
    main()
