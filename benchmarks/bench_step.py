"""Benchmark: one step of a simulation loop on a World, against pymunk's ``Space.step``.

Run: ``python benchmarks/bench_step.py`` (``--quick``: 10³ and 10⁴ bodies only;
``--threads 1``: the parallel kernels on one thread; ``--cpu``: the CPU time of the
process, all its threads, instead of the wall time: on a machine shared with other
jobs it does not count the time spent waiting for a core; ``--repeat N``: N calls per
figure instead of 5; ``--fastest``: the figures and ratios from each call's fastest
repeat instead of the median, the steadier figure on a machine shared with other jobs).
Medians of 5 repeats, with the spread (smallest and largest); the calls take turns, one
of each per round, so that a slow spell of the machine falls on all of them, and the
peer is measured in the same run.

Scene: N concave 12-gon stars on a jittered unit grid (``bench_world.stars``: radius
about 0.6, each body meeting a few neighbours), N = 10³, 10⁴, 10⁵. One step:

- ``set_poses``: every body moved by a small random translation and turn (a few
  hundredths of its size), in one call;
- ``contacts()``: the pairs and states only; then ``contacts()`` with its geometry
  arrays read (distances, normals, points, overlap areas and centroids, carrying
  vertices and edges); the ratio is the cost of the geometry;
- the detection step: ``set_poses`` + ``contacts()`` + geometry, per body too;
- ``sweep(dt)`` apart, the bodies moving a tenth of their size in the step (a random
  direction) and turning by up to 0.2 radian, against ``contacts()``: the pairs that
  meet and their times, then with the points and normals read too.

Peer: pymunk's ``Space.step`` (detection and solver) on the same scene, each star as a
body of its 6 convex kites (pymunk takes convex shapes only), measured on successive
steps after a first one. pymunk is in the ``bench`` extra.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

import polycontact as pc

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_world import stars  # noqa: E402

REPEATS = 5
#: The clock of :func:`rounds`: wall time, or the process's CPU time (``--cpu``).
CLOCK = time.perf_counter
#: The figure each call is given by: the median of its repeats, or the fastest
#: (``--fastest``).
FIGURE = statistics.median
#: The pymunk spaces, kept to the end: freeing one of 10⁵ bodies takes minutes, so the
#: run ends without freeing them (see main).
SPACES: list[object] = []


def rounds(calls: dict[str, Callable[[], object]],
           repeats: int) -> dict[str, tuple[float, float, float, object]]:
    """``repeats`` rounds of every call in ``calls``, one after another in each round:
    for each, its figure (:data:`FIGURE` of its times, :data:`CLOCK`), its smallest and
    largest time, and its last result."""
    times: dict[str, list[float]] = {name: [] for name in calls}
    out: dict[str, object] = {}
    for _ in range(repeats):
        for name, fn in calls.items():
            t0 = CLOCK()
            out[name] = fn()
            times[name].append(CLOCK() - t0)
    return {name: (FIGURE(ts), min(ts), max(ts), out[name]) for name, ts in times.items()}


def pymunk_space(rings: np.ndarray):
    """A pymunk Space holding each star as one body of its 6 convex kites (centre,
    notch, tip, notch)."""
    import pymunk

    space = pymunk.Space()
    for ring in rings:
        c = ring.mean(axis=0)
        body = pymunk.Body(1.0, 1.0)
        body.position = (float(c[0]), float(c[1]))
        loc = ring - c
        kites = [pymunk.Poly(body, [(0.0, 0.0), tuple(loc[2 * k - 1]), tuple(loc[2 * k]),
                                    tuple(loc[(2 * k + 1) % 12])]) for k in range(6)]
        space.add(body, *kites)
    return space


def fmt(t: tuple[float, float, float, object], scale: float = 1e3, unit: str = "ms") -> str:
    return f"{scale * t[0]:8.2f} {unit} ({scale * t[1]:.2f}-{scale * t[2]:.2f})"


def bench(n: int, rng: np.random.Generator, repeats: int) -> dict[str, float]:
    rings = stars(rng, n)
    world = pc.World()
    ids = world.add_many(rings)
    pos, ang = world.poses()
    world.contacts().distances  # noqa: B018 - compile / warm
    moves = iter([(pos + rng.normal(0.0, 0.01, pos.shape), ang + rng.normal(0.0, 0.02, n))
                  for _ in range(2 * repeats)])

    def step():
        p, a = next(moves)
        world.set_poses(ids, p, a)
        return world.contacts().overlap_areas

    dt = 0.01
    heading = rng.uniform(0.0, 2.0 * np.pi, n)
    vel = 0.12 / dt * np.c_[np.cos(heading), np.sin(heading)]  # a tenth of the size (1.24)
    spin = rng.uniform(-0.2, 0.2, n) / dt
    world.sweep(dt, vel, spin).normals  # compile / warm
    space = pymunk_space(rings)
    SPACES.append(space)
    space.step(1e-3)
    # (in a loop's order: set_poses after the contacts' geometry was read)
    got = rounds({"pymunk": lambda: space.step(1e-3),
                  "sweep": lambda: world.sweep(dt, vel, spin),
                  "sweep_geometry": lambda: world.sweep(dt, vel, spin).normals,
                  "plain": world.contacts,
                  "geometry": lambda: world.contacts().overlap_areas,
                  "set_poses": lambda: world.set_poses(ids, *next(moves)),
                  "step": step}, repeats)
    t_set, t_plain, t_geom, t_step = (got[k] for k in ("set_poses", "plain", "geometry",
                                                          "step"))
    t_sweep, t_sweep_geom, t_pm = got["sweep"], got["sweep_geometry"], got["pymunk"]
    pairs = len(world.contacts())
    found = len(t_sweep[3])
    print(f"N = {n}: {pairs} contact pairs; sweep: {found} pairs meet in the step")
    print(f"  set_poses                 {fmt(t_set)}  = {1e9 * t_set[0] / n:6.0f} ns per body")
    print(f"  contacts() (pairs only)   {fmt(t_plain)}")
    print(f"  contacts() with geometry  {fmt(t_geom)}  = {t_geom[0] / t_plain[0]:.2f}x "
          "contacts()")
    print(f"  sweep(dt)                 {fmt(t_sweep)}  = {t_sweep[0] / t_plain[0]:.2f}x "
          "contacts()")
    print(f"  sweep(dt), points read    {fmt(t_sweep_geom)}  = "
          f"{t_sweep_geom[0] / t_plain[0]:.2f}x contacts()")
    print(f"  detection step            {fmt(t_step)}  = {1e6 * t_step[0] / n:.2f} us per body")
    print(f"  pymunk Space.step         {fmt(t_pm)}  -> the step is {t_pm[0] / t_step[0]:.2f}x "
          "faster than pymunk")
    return {"step_per_body": t_step[0] / n}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="10³ and 10⁴ bodies only")
    parser.add_argument("--threads", type=int, default=0,
                        help="Numba threads for the parallel kernels (default: all)")
    parser.add_argument("--cpu", action="store_true",
                        help="time the process's CPU time (all threads), not the wall time")
    parser.add_argument("--repeat", type=int, default=REPEATS,
                        help=f"calls per figure (default {REPEATS})")
    parser.add_argument("--fastest", action="store_true",
                        help="figures and ratios from the fastest call, not the median")
    args = parser.parse_args()
    if args.repeat < 1:
        parser.error("--repeat: expected at least 1 call per figure")
    global CLOCK, FIGURE
    if args.cpu:
        CLOCK = time.process_time
    if args.fastest:
        FIGURE = min
    import numba
    import pymunk

    if args.threads:
        numba.set_num_threads(args.threads)
    print(f"threads: {numba.get_num_threads()}, load average {os.getloadavg()[0]:.1f} on "
          f"{os.cpu_count()} cores; pymunk {pymunk.version}; "
          f"{'CPU time of the process' if args.cpu else 'wall time'}, "
          f"{'fastest' if args.fastest else 'median'} of {args.repeat} calls")
    rng = np.random.default_rng(1)
    sizes = [1_000, 10_000] if args.quick else [1_000, 10_000, 100_000]
    per_body = [bench(n, rng, args.repeat)["step_per_body"] for n in sizes]
    print(f"detection step per body, largest / smallest over N = "
          f"{', '.join(str(n) for n in sizes)}: {max(per_body) / min(per_body):.2f}")
    sys.stdout.flush()
    os._exit(0)  # without freeing the pymunk spaces (minutes for the largest)


if __name__ == "__main__":
    main()
