"""First impacts among many moving bodies: ``first_impacts`` against the all-pairs loop
of ``time_of_impact``.

Run: ``python benchmarks/bench_first_impacts.py [--bodies N] [--repeat R] [--seed S]``.

The scene: N random concave 12-gons (star-shaped, radius up to 1; every fourth one
with a square hole) on a jittered grid of pitch 3, none touching at t = 0, each with a
random velocity (up to 1.5 per axis), spin (up to 2 rad/s), and for half of them an
acceleration (up to 1 per axis), over one step [0, 1]: neighbours collide, graze or
pass. Printed, in one run:

- ``first_impacts`` (swept bounds + exact search on threads), its candidate pairs and
  the events found;
- ``Scene(...).first_impact()``, which goes through the same World, and the
  all-pairs baseline: a plain double loop of ``time_of_impact`` whose events must equal
  those of ``first_impacts`` (same pairs, equal ``Impact`` objects);
- medians over R rounds (each: ``first_impacts`` and ``first_impact``, median of 5
  calls, then one run of each loop) and the median of the per-round ratios, with their
  spread (fastest and slowest call of ``first_impacts``, range of the ratios and of the
  loops over the rounds);
- ``time_of_impact_many`` on one thread and on all CPUs against a loop of
  ``time_of_impact``, on two pair lists: the candidate pairs (short searches) and pairs
  of fast-spinning neighbours (long searches).

Timings are wall-clock medians; the machine may be shared, so compare the ratio
measured in one run rather than absolute figures.
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

import polycontact as pc
from polycontact import Motion, Shape


def star(rng: np.random.Generator, k: int = 12) -> np.ndarray:
    """A concave star-shaped k-gon of radius at most 1 about the origin."""
    ang = 2 * np.pi * (np.arange(k) + rng.uniform(-0.3, 0.3, k)) / k
    rad = np.where(np.arange(k) % 2 == 0, rng.uniform(0.75, 1.0, k), rng.uniform(0.35, 0.6, k))
    return np.c_[rad * np.cos(ang), rad * np.sin(ang)]


def scene(n: int, seed: int) -> tuple[list[Shape], list[Motion]]:
    rng = np.random.default_rng(seed)
    side = int(np.ceil(np.sqrt(n)))
    shapes, motions = [], []
    for k in range(n):
        centre = 3.0 * np.array([k % side, k // side]) + rng.uniform(-0.4, 0.4, 2)
        ring = star(rng) + centre
        holes = [centre + 0.12 * np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]])] \
            if k % 4 == 0 else []
        shapes.append(Shape(ring, holes))
        acc = rng.uniform(-1, 1, 2) if k % 2 else (0.0, 0.0)
        motions.append(Motion(velocity=rng.uniform(-1.5, 1.5, 2), acceleration=acc,
                              angular_velocity=rng.uniform(-2, 2)))
    return shapes, motions


def spinning_pairs(n: int, seed: int) -> tuple[list, list, list, list]:
    """n pairs of 12-gons side by side, spinning at up to 20 rad/s, one drifting."""
    rng = np.random.default_rng(seed)
    sa, ma, sb, mb = [], [], [], []
    for _ in range(n):
        sa.append(Shape(star(rng)))
        sb.append(Shape(star(rng) + [rng.uniform(1.9, 2.6), 0.0]))
        ma.append(Motion(velocity=(rng.uniform(0, 0.3), 0), angular_velocity=rng.uniform(-20, 20)))
        mb.append(Motion(angular_velocity=rng.uniform(-20, 20)))
    return sa, ma, sb, mb


def timings(fn, repeat: int) -> tuple[list[float], object]:
    """Wall-clock seconds of ``repeat`` calls, and the last result."""
    times, out = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return times, out


def median_time(fn, repeat: int) -> tuple[float, object]:
    times, out = timings(fn, repeat)
    return float(np.median(times)), out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bodies", type=int, default=1000)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()
    shapes, motions = scene(args.bodies, args.seed)
    t_max = 1.0
    n = len(shapes)
    pairs = n * (n - 1) // 2
    scene_obj = pc.Scene(tuple(pc.SceneBody(f"b{k}", s, m) for k, s, m in
                               zip(range(n), shapes, motions)), t_max)
    from polycontact.impacts import candidate_pairs

    pc.first_impacts(shapes[:3], motions[:3], t_max=t_max)  # compile / load the kernels
    print(f"== first impacts of {n} moving concave 12-gons over [0, {t_max:g}] "
          f"({pairs} pairs, {os.cpu_count()} CPUs) ==")
    t_cand, cand = median_time(lambda: candidate_pairs(shapes, motions, t_max=t_max), 5)

    def brute():
        out = []
        for i in range(n):
            for j in range(i + 1, n):
                imp = pc.time_of_impact(shapes[i], motions[i], shapes[j], motions[j],
                                        t_max=t_max)
                if imp.state is not None or imp.status is pc.ImpactStatus.OUT_OF_ITERATIONS:
                    out.append((i, j, imp))
        return out

    # rounds: first_impacts (median of 5 calls) right before each all-pairs loop, so
    # that the ratio of a round compares runs under the same load of the machine
    rounds, fast_calls = [], []
    for _ in range(args.repeat):
        calls, events = timings(lambda: pc.first_impacts(shapes, motions, t_max=t_max), 5)
        fast_calls += calls
        t_fast = float(np.median(calls))
        t_one, first = median_time(lambda: pc.first_impact(shapes, motions, t_max=t_max), 5)
        t_scene, (si, sj, imp) = median_time(lambda: scene_obj.first_impact(), 1)
        t_brute, slow = median_time(brute, 1)
        rounds.append((t_fast, t_one, t_scene, t_brute))
    t_fast, t_one, t_scene, t_brute = np.median(rounds, axis=0)
    ratios_scene = [r[2] / r[0] for r in rounds]
    ratios_brute = [r[3] / r[0] for r in rounds]
    r_scene, r_brute = np.median(ratios_scene), np.median(ratios_brute)
    hits = int((events.statuses == 1).sum())
    print(f"first_impacts: {1e3 * t_fast:9.1f} ms  (swept bounds alone {1e3 * t_cand:.1f} ms: "
          f"{len(cand)} candidate pairs; {len(events)} pairs meet, {hits} collide)")
    print(f"first_impact:  {1e3 * t_one:9.1f} ms  -> bodies {first.i}, {first.j} at "
          f"t = {first.impact.time:.6f} ({first.impact.status.value})")
    print(f"Scene.first_impact (World): {t_scene:7.2f} s  -> {scene_obj.bodies[si].name}, "
          f"{scene_obj.bodies[sj].name} at "
          f"t = {imp.time:.6f}")
    same = {(i, j): imp for i, j, imp in slow} == {(e.i, e.j): e.impact for e in events}
    print(f"double loop of time_of_impact:  {t_brute:7.2f} s  -> {len(slow)} pairs meet; "
          f"first_impacts gives the same pairs and Impacts: {same}")
    agree = (first.i, first.j) == (si, sj) and first.impact == imp
    print(f"first_impact agrees with Scene.first_impact: {agree}")
    print(f"speed-up (medians over {args.repeat} rounds of the per-round ratios): "
          f"first_impacts vs Scene.first_impact {r_scene:.0f}x, vs the double loop "
          f"{r_brute:.0f}x (target >= 50x)")
    print(f"spread: first_impacts {1e3 * min(fast_calls):.1f}-{1e3 * max(fast_calls):.1f} ms over "
          f"{len(fast_calls)} calls; per-round ratios {min(ratios_scene):.0f}-"
          f"{max(ratios_scene):.0f}x (Scene), {min(ratios_brute):.0f}-{max(ratios_brute):.0f}x "
          f"(double loop); all-pairs loops {min(r[2] for r in rounds):.2f}-"
          f"{max(r[2] for r in rounds):.2f} s (Scene), {min(r[3] for r in rounds):.2f}-"
          f"{max(r[3] for r in rounds):.2f} s (double loop)")

    # pair lists of a user's own: those candidate pairs, and pairs of fast-spinning
    # neighbours (long searches: there the threads pay)
    ia, ib = cand[:, 0].tolist(), cand[:, 1].tolist()
    lists = [(f"the {len(cand)} candidate pairs over [0, {t_max:g}]",
              [shapes[i] for i in ia], [motions[i] for i in ia],
              [shapes[j] for j in ib], [motions[j] for j in ib], t_max),
             ("300 pairs of spinning neighbours over [0, 3]", *spinning_pairs(300, args.seed),
              3.0)]
    for what, sa, ma, sb, mb, window in lists:
        print(f"== time_of_impact_many on {what} ==")
        t_loop, loop = median_time(lambda: [pc.time_of_impact(a, m1, b, m2, t_max=window)
                                            for a, m1, b, m2 in zip(sa, ma, sb, mb)], 5)
        print(f"loop of time_of_impact:        {1e3 * t_loop:8.1f} ms "
              f"({sum(i.collides for i in loop)} hits)")
        for threads in sorted({1, os.cpu_count() or 1}):
            t_many, batch = median_time(lambda: pc.time_of_impact_many(
                sa, ma, sb, mb, t_max=window, threads=threads), 5)
            print(f"time_of_impact_many, {threads} thread{'s' if threads > 1 else ' '}: "
                  f"{1e3 * t_many:8.1f} ms ({t_loop / t_many:.1f}x the loop; equal answers: "
                  f"{list(batch) == loop})")

if __name__ == "__main__":
    main()
