"""Bounded time: calls whose work could explode, each answered or refused within a bound.

One row per case, each measured in a fresh process with a time limit (a case that
overruns shows as ``> limit``, not as a stuck run), after a warm-up call on small bodies
in that process (compiled kernels loaded from the cache, not timed). The bodies are
built before the clock starts (a Shape checks its rings once); each repetition calls on
fresh copies of the arrays, so no decomposition cache is reused. Printed: the bound, the
median of ``--repeat`` calls with the smallest and largest, the median CPU time of the
process (all its threads: on a loaded machine it shows the work apart from the waiting),
and the outcome: the answer's gist, or the error's class when the call refuses (a
refusal names its estimate and the limit it passes, see :mod:`polycontact.limits`).

Cases:

- ``nfp combs 400``: the no-fit polygon of two interlocking regular combs of 400
  vertices (100 unit teeth each, each tooth as wide as the other's gaps: a slide for
  every way in); 10 s.
- ``nfp wavy 60000``: a convex 600-gon of radius 0.3 against a disc of radius 1 whose
  60 000-vertex outline waves (50 waves of amplitude 0.002: nearly convex, with
  thousands of reflex vertices); 15 s.
- ``toi spin 64`` / ``toi spin 512``: a regular 64- (512-) gon spinning (20 rad per time
  unit) in the square frame whose hole it fills exactly, the frame spinning with it
  about the same centre, over 1000 time units: no relative motion, so no collision; 2 s.
- ``toi sampled 1e9``: ``method="sampled"`` with ``samples=10**9`` (two unit squares
  closing at unit speed): refused (more samples than ``max_iterations``) or bounded; 2 s.
- ``depth stars 1e5``: ``classify(a, b).distance`` of two overlapping smooth stars of
  10⁵ vertices each (offset by half their radius): refused before decomposing; 5 s.
- ``pairs stars 1000``: ``entrance_block(a, b, method="pairs")`` of two overlapping
  1 000-vertex stars (10⁶ edge pairs): answered or refused; 30 s.
- ``ring 2e6 state`` / ``ring 2e6 depth``: ``classify(ring, square)`` of a 2·10⁶-vertex
  circle (raw arrays, as the command line reads them) against a square across its rim,
  then the same with its ``distance`` (the penetration depth, classification included);
  a few seconds each.

Run: ``python benchmarks/bench_bounds.py [--repeat 3] [--case NAME ...]``
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path
from typing import Any, Callable

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / "tests"))
from bench_scaling import row_in_fresh_process  # noqa: E402
from catalogue import interlocking_combs  # noqa: E402

#: case name -> bound in seconds
BOUNDS = {
    "nfp combs 400": 10.0,
    "nfp wavy 60000": 15.0,
    "toi spin 64": 2.0,
    "toi spin 512": 2.0,
    "toi sampled 1e9": 2.0,
    "depth stars 1e5": 5.0,
    "pairs stars 1000": 30.0,
    "ring 2e6 state": 5.0,
    "ring 2e6 depth": 5.0,
}


def circle(n: int, r: float = 1.0) -> np.ndarray:
    t = 2.0 * np.pi * np.arange(n) / n
    return np.column_stack((r * np.cos(t), r * np.sin(t)))


def wavy(n: int, waves: int = 50, amplitude: float = 0.002) -> np.ndarray:
    t = 2.0 * np.pi * np.arange(n) / n
    r = 1.0 + amplitude * np.sin(waves * t)
    return np.column_stack((r * np.cos(t), r * np.sin(t)))


def star(rng: np.random.Generator, n: int) -> np.ndarray:
    """The smooth concave stars of ``bench_classify.py``: radius 1 + 0.3 sin(k t + phase)
    with a jitter of half a vertex spacing."""
    t = np.linspace(0, 2 * np.pi, n, endpoint=False) + rng.uniform(0, 2 * np.pi)
    k = rng.integers(2, 6)
    r = 1 + 0.3 * np.sin(k * t + rng.uniform(0, 2 * np.pi))
    r += 0.5 * (2 * np.pi / n) * rng.uniform(-1, 1, n)
    return np.ascontiguousarray(np.c_[np.cos(t) * r, np.sin(t) * r])


def setup(case: str) -> tuple[Callable[[], Any], Callable[[], Any]]:
    """``(warm, call)`` for a case: a small call of the same kind, and the case itself
    (each call on fresh bodies' copies)."""
    import polycontact as pc

    if case.startswith("nfp"):
        if case == "nfp combs 400":
            a, b = interlocking_combs(99)
        else:
            a, b = circle(600, 0.3), wavy(60000)
        sa, sb = pc.Shape(a), pc.Shape(b)
        # (rings past ear clipping, and sums enough for the grids: the same kernels)
        small = pc.Shape(interlocking_combs(20)[0]), pc.Shape(interlocking_combs(20)[1])

        def nfp(x: Any, y: Any) -> Any:
            got = pc.no_fit_polygon(x, y, reference="origin")
            return f"{len(got.rings)} ring(s), {sum(len(r) for r in got.rings)} vertices, " \
                   f"{len(got.slides)} slides"

        return (lambda: nfp(*small)), (lambda: nfp(pc.Shape(sa.packed[0].copy()),
                                                   pc.Shape(sb.packed[0].copy())))
    if case.startswith("toi spin"):
        n = int(case.split()[-1])
        disc = circle(n)
        frame = [(-2, -2), (2, -2), (2, 2), (-2, 2)]
        a, b = pc.Shape(disc), pc.Shape(frame, [disc[::-1]])
        spin = pc.Motion(angular_velocity=20.0)

        def toi(x: Any, y: Any) -> Any:
            hit = pc.time_of_impact(x, spin, y, spin, t_max=1000.0)
            return f"{hit.status.value}, state {hit.state.value if hit.state else None}"

        small = pc.Shape(circle(8)), pc.Shape(frame, [circle(8)[::-1]])
        return (lambda: toi(*small)), (lambda: toi(a, b))
    if case == "toi sampled 1e9":
        sq = pc.Shape([(0, 0), (1, 0), (1, 1), (0, 1)])

        def sampled(samples: int) -> Any:
            hit = pc.time_of_impact(sq, pc.Motion(velocity=(1, 0)), sq.moved((3, 0)),
                                    pc.Motion(), t_max=5.0, method="sampled",
                                    samples=samples)
            return f"{hit.status.value} at {hit.time}"

        return (lambda: sampled(10)), (lambda: sampled(10**9))
    if case == "depth stars 1e5":
        rng = np.random.default_rng(0)
        a, b = star(rng, 100_000), star(rng, 100_000) + [0.5, 0.1]
        sa, sb = pc.Shape(a), pc.Shape(b)
        small = pc.Shape(star(rng, 200)), pc.Shape(star(rng, 200) + [0.5, 0.1])

        def depth(x: Any, y: Any) -> Any:
            return f"depth {-pc.classify(x, y).distance:.6g}"

        return (lambda: depth(*small)), (lambda: depth(pc.Shape(sa.packed[0].copy()),
                                                       pc.Shape(sb.packed[0].copy())))
    if case == "pairs stars 1000":
        rng = np.random.default_rng(1)
        a, b = pc.Shape(star(rng, 1000)), pc.Shape(star(rng, 1000) + [0.5, 0.2])

        def pairs(x: Any, y: Any) -> Any:
            return f"{len(pc.entrance_block(x, y, method='pairs').components)} components"

        small = pc.Shape(star(rng, 20)), pc.Shape(star(rng, 20) + [0.5, 0.2])
        return (lambda: pairs(*small)), (lambda: pairs(a, b))
    ring = circle(2_000_000)
    square = np.array([[0.9, -0.1], [1.2, -0.1], [1.2, 0.1], [0.9, 0.1]])
    small = circle(1000)

    if case == "ring 2e6 state":
        return ((lambda: pc.classify(small, square).state.value),
                (lambda: pc.classify(ring.copy(), square.copy()).state.value))

    def depth_of(r: np.ndarray) -> Any:
        return f"distance {pc.classify(r, square.copy()).distance:.6g}"

    return (lambda: depth_of(small)), (lambda: depth_of(ring.copy()))


def one_row(case: str, repeat: int) -> dict[str, Any]:
    """Measure one case in this process (called in a fresh process by :func:`main`)."""
    warm, call = setup(case)
    warm()
    times = []
    cpu = []
    outcome = ""
    for _ in range(repeat):
        t0, c0 = time.perf_counter(), time.process_time()
        try:
            outcome = str(call())
        except Exception as err:  # noqa: BLE001 - a refusal is an outcome
            outcome = f"refused: {type(err).__name__}"
        times.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
    return {"case": case, "median": float(np.median(times)), "min": min(times),
            "max": max(times), "cpu": float(np.median(cpu)), "outcome": outcome}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--case", action="append", choices=list(BOUNDS),
                    help="only this case (repeatable)")
    ap.add_argument("--row", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.row:
        print(json.dumps(one_row(args.row, args.repeat)))
        return
    print(f"{'case':18} {'bound s':>8} {'median s':>9} {'min..max s':>15} {'CPU s':>8}  outcome")
    for case in args.case or list(BOUNDS):
        bound = BOUNDS[case]
        # the limit: each repetition within three times its bound, plus the set-up
        limit = 120.0 + 3.0 * bound * args.repeat
        cmd = [sys.executable, __file__, "--repeat", str(args.repeat), "--row", case]
        row = row_in_fresh_process(cmd, limit)
        if isinstance(row, str):
            print(f"{case:18} {bound:8.0f} {row:>9}", flush=True)
            continue
        spread = f"{row['min']:.3f}..{row['max']:.3f}"
        print(f"{case:18} {bound:8.0f} {row['median']:9.3f} {spread:>15} {row['cpu']:8.3f}  "
              f"{row['outcome']}", flush=True)


if __name__ == "__main__":
    main()
