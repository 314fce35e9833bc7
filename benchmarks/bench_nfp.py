"""No-fit polygons of the ESICUP nesting instances: polycontact vs pyclipper vs pysfcgal.

For each instance, every ordered pair (orbiting item, fixed item) of its items, the item
with itself included (nesting needs it when an item's demand is above one), at every
combination of the allowed orientations (rotations about the origin), with the
reference point at the origin (nesting convention: E = B ⊕ (−A)).

Timed, in the same run and on the same prepared inputs:
- ``polycontact.no_fit_polygon`` (region, exact fits and slides); "cold" clears the
  convex-decomposition cache before each NFP (every NFP decomposes both its pieces);
  "warm" clears it once at the start of each build of the instance, so each piece at
  each orientation is decomposed once and reused across its pairs, as a nesting code
  building all NFPs of an instance does (the decompositions are inside the timing).
  The result's Shapely ``region`` is built on first access, not by the call (the
  outline's coordinates are in the result: ``rings``), as pyclipper returns paths and
  no geometry; "pc+region" is warm with ``region`` accessed on every result, the
  time of a caller that wants the Shapely geometry of every NFP;
- ``pyclipper.MinkowskiSum2`` on integer coordinates scaled by a power of two so the
  largest reaches 2**50 (Clipper needs integers);
- ``pysfcgal`` ``Polygon.minkowski_sum`` (CGAL, exact arithmetic; ESICUP has no holes).

With ``--check`` every result is compared with the independent reference of
``tests/nfp_reference.py``: a region is wrong when the symmetric difference exceeds 1e-9
of the area or the number of holes differs (a false hole).

Times are for building all the NFPs of an instance once (medians over ``--repeat``
runs; an instance with fewer than 2000 NFPs is built several times per run and the
time divided), with Python's cyclic garbage collector run before and paused during each
timed run, as ``timeit`` does (the same for every tool). Run: ``python benchmarks/bench_nfp.py [--check] [--repeat 5] [instance ...]``
"""

from __future__ import annotations

import argparse
import gc
import json
import statistics
import sys
import time
import warnings
from pathlib import Path

import numpy as np
import shapely

import polycontact as pc
from polycontact._pieces import clear_cache as clear_pieces_cache

ROOT = Path(__file__).resolve().parents[1]
# the data sit in <checkout>/../shared (main checkout) or ../../shared (a worktree)
DATA = next((p / "shared" / "datasets" / "esicup" for p in ROOT.parents
             if (p / "shared" / "datasets" / "esicup").is_dir()), ROOT.parent / "shared")
sys.path.insert(0, str(ROOT / "tests"))


def rotated(ring: np.ndarray, degrees: float) -> np.ndarray:
    """Ring rotated about the origin; exact for multiples of 90 degrees."""
    t = np.radians(degrees)
    c, s = np.cos(t), np.sin(t)
    if degrees % 90 == 0:
        c, s = round(c), round(s)
    return ring @ np.array([[c, s], [-s, c]])


def load(path: Path) -> list[np.ndarray]:
    """Every (item, allowed orientation) of an instance as a CCW ring."""
    data = json.loads(path.read_text())
    out = []
    for item in data["items"]:
        ring = np.asarray(item["shape"]["data"], dtype=float)
        for deg in item["allowed_orientations"]:
            out.append(pc.Shape(rotated(ring, deg)).exterior)
    return out


def clipper_region(paths: list, scale: float) -> shapely.Geometry:
    import pyclipper

    outers = [shapely.Polygon(np.asarray(p) / scale) for p in paths if pyclipper.Orientation(p)]
    holes = [shapely.Polygon(np.asarray(p) / scale) for p in paths if not pyclipper.Orientation(p)]
    region = shapely.union_all(outers)
    if holes:
        # keep each hole as a hole (difference of the union), so false holes are counted
        region = shapely.Polygon(region.exterior, [h.exterior for h in holes]) if (
            region.geom_type == "Polygon") else region.difference(shapely.union_all(holes))
    return region


def run(path: Path, repeat: int, check: bool) -> dict:
    import pyclipper

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        import pysfcgal.geometry as sg
    rings = load(path)
    shapes = [pc.Shape._trusted([r]) for r in rings]
    scale = 2.0 ** (50 - int(np.ceil(np.log2(max(np.abs(r).max() for r in rings) * 2))))
    ints = [[tuple(v) for v in np.round(r * scale).astype(np.int64).tolist()] for r in rings]
    neg_ints = [[(-x, -y) for x, y in p] for p in ints]
    sf = [sg.Polygon([tuple(v) for v in r.tolist()]) for r in rings]
    sf_neg = [sg.Polygon([tuple(v) for v in (-r).tolist()]) for r in rings]
    pairs = [(i, j) for i in range(len(rings)) for j in range(len(rings))]

    def t_pc_warm():
        clear_pieces_cache()
        return [pc.no_fit_polygon(shapes[i], shapes[j], "origin") for i, j in pairs]

    def t_pc_cold():
        out = []
        for i, j in pairs:
            clear_pieces_cache()
            out.append(pc.no_fit_polygon(shapes[i], shapes[j], "origin"))
        return out

    def t_pc_region():
        clear_pieces_cache()
        return [pc.no_fit_polygon(shapes[i], shapes[j], "origin").region for i, j in pairs]

    def t_clipper():
        return [pyclipper.MinkowskiSum2(neg_ints[i], [ints[j]], True) for i, j in pairs]

    def t_sfcgal():
        return [sf[j].minkowski_sum(sf_neg[i]) for i, j in pairs]

    times: dict[str, list[float]] = {"pc_cold": [], "pc_warm": [], "pc_region": [],
                                     "pyclipper": [], "pysfcgal": []}
    results = {}
    # small instances are built several times per timed run (at least 2000 NFPs), so
    # that a run lasts long enough to be measured on a busy machine
    inner = max(1, -(-2000 // len(pairs)))
    for _ in range(repeat):
        for name, fn in (("pc_cold", t_pc_cold), ("pc_warm", t_pc_warm),
                         ("pc_region", t_pc_region), ("pyclipper", t_clipper),
                         ("pysfcgal", t_sfcgal)):
            # as timeit does: the previous results freed and the cyclic garbage
            # collector run before the clock starts, and kept from running while it runs
            results.pop(name, None)
            gc.collect()
            gc.disable()
            try:
                t0 = time.perf_counter()
                for _ in range(inner):
                    out = fn()
                times[name].append((time.perf_counter() - t0) / inner)
            finally:
                gc.enable()
            results[name] = out
    row = {"instance": path.stem, "pieces": len(rings), "nfps": len(pairs)}
    row.update({k: statistics.median(v) for k, v in times.items()})
    if check:
        from nfp_reference import hole_count, reference_region, same_region

        wrong = {"wrong_pc": 0, "wrong_clip": 0, "clip_false_holes": 0, "wrong_sfcgal": 0}
        exact = 0
        for k, (i, j) in enumerate(pairs):
            ref = reference_region(shapely.Polygon(rings[i]), shapely.Polygon(rings[j]), (0, 0))
            got = results["pc_warm"][k]
            exact += len(got.exact_fits) + len(got.slides)
            if same_region(got.region, ref):
                wrong["wrong_pc"] += 1
            clip = clipper_region(results["pyclipper"][k], scale)
            if same_region(clip, ref):
                wrong["wrong_clip"] += 1
            if hole_count(clip) > hole_count(ref):
                wrong["clip_false_holes"] += 1
            sfg = shapely.from_wkb(results["pysfcgal"][k].to_wkb(True))
            if same_region(sfg, ref):
                wrong["wrong_sfcgal"] += 1
        row.update(wrong)
        row["pc_exact_fits_and_slides"] = exact
    return row


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("instances", nargs="*", help="instance names (default: all)")
    parser.add_argument("--repeat", type=int, default=5, help="timed runs per tool (median)")
    parser.add_argument("--check", action="store_true", help="verify against the reference")
    args = parser.parse_args()
    paths = sorted(DATA.glob("*.json"))
    if args.instances:
        paths = [p for p in paths if p.stem in args.instances]
    # compile every kernel before timing (the slot gives a slide, the frame an exact fit)
    square = [(0, 0), (1, 0), (1, 1), (0, 1)]
    pc.no_fit_polygon(square, [(0, 0), (3, 0), (3, 3), (2, 3), (2, 1), (1, 1), (1, 3), (0, 3)])
    frame = pc.Shape([(0, 0), (4, 0), (4, 4), (0, 4)], [[(1, 1), (3, 1), (3, 3), (1, 3)]])
    pc.no_fit_polygon([(0, 0), (2, 0), (2, 2), (0, 2)], frame)
    head = (f"{'instance':10} {'NFPs':>6} {'pc cold s':>9} {'pc warm s':>9} {'pyclipper s':>11} "
            f"{'pysfcgal s':>10} {'clip/cold':>9} {'sfcgal/cold':>11} {'clip/warm':>9} "
            f"{'sfcgal/warm':>11} {'pc+region s':>11} {'clip/+reg':>9}")
    if args.check:
        head += (f" {'wrong pc':>8} {'wrong clip':>10} {'false holes clip':>16}"
                 f" {'wrong sfcgal':>12} {'fits+slides':>11}")
    print(head)
    total = {"pc_cold": 0.0, "pc_warm": 0.0, "pc_region": 0.0, "pyclipper": 0.0,
             "pysfcgal": 0.0, "nfps": 0}
    for path in paths:
        r = run(path, args.repeat, args.check)
        for key in total:
            total[key] += r[key]
        print(_line(r, args.check), flush=True)
    print(_line({"instance": "all", **total}, False))
    return 0


def _line(r: dict, check: bool) -> str:
    line = (f"{r['instance']:10} {r['nfps']:6d} {r['pc_cold']:9.3f} {r['pc_warm']:9.3f} "
            f"{r['pyclipper']:11.3f} {r['pysfcgal']:10.3f} "
            f"{r['pyclipper'] / r['pc_cold']:9.2f} {r['pysfcgal'] / r['pc_cold']:11.2f} "
            f"{r['pyclipper'] / r['pc_warm']:9.2f} {r['pysfcgal'] / r['pc_warm']:11.2f} "
            f"{r['pc_region']:11.3f} {r['pyclipper'] / r['pc_region']:9.2f}")
    if check:
        line += (f" {r['wrong_pc']:8d} {r['wrong_clip']:10d} {r['clip_false_holes']:16d}"
                 f" {r['wrong_sfcgal']:12d} {r['pc_exact_fits_and_slides']:11d}")
    return line


if __name__ == "__main__":
    sys.exit(main())
