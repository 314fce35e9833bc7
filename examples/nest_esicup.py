"""Bottom-left fill of an ESICUP strip-packing instance with ``World.feasible_region``.

Run: ``python examples/nest_esicup.py [INSTANCE] [--plot out.png]`` (default jakobs1;
instances in ``../shared/datasets/esicup/``). Pieces go largest first; each goes, over
its allowed orientations, where its right end is leftmost (then lowest) among the
vertices of its feasible region: the container's inner-fit polygon minus the bodies'
no-fit polygons, exact fits and slides kept. Every placement is checked with the exact
``World.query`` before it is added, and at the end ``World.contacts`` confirms that no
two pieces penetrate and every piece is in the strip. Prints the strip length and the
density beside the best published layout of the instance
(``../shared/datasets/layouts/``).
"""

from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path

import numpy as np
import shapely

import polycontact as pc

DATASETS = next((p / "shared" / "datasets" for p in Path(__file__).resolve().parents[1:4]
                 if (p / "shared" / "datasets").is_dir()), None)


def candidates(region) -> np.ndarray:
    """Every vertex of a feasible region (a polygon's leftmost point is a vertex)."""
    pts = [np.asarray(g.coords) if g.geom_type in ("Point", "LineString") else
           np.concatenate([np.asarray(r.coords) for r in (g.exterior, *g.interiors)])
           for g in shapely.get_parts(region) if not g.is_empty]
    return np.concatenate(pts) if pts else np.empty((0, 2))


def nest(name: str) -> tuple[pc.World, float, float]:
    inst = json.loads((DATASETS / "esicup" / f"{name}.json").read_text())
    height = float(inst["strip_height"])
    pieces = []
    for it in inst["items"]:
        shape = pc.Shape(it["shape"]["data"])
        pieces += [(shape, [math.radians(a) for a in it["allowed_orientations"]])] * \
            int(it["demand"])
    pieces.sort(key=lambda p: -p[0].area)
    length = sum(float(np.ptp(s.exterior, axis=0).max()) for s, _ in pieces)
    world = pc.World(pc.Shape([(0, 0), (length, 0), (length, height), (0, height)]))
    for shape, angles in pieces:
        best = None
        for angle in angles:
            region = world.feasible_region(shape, angle)
            pts = candidates(region)
            if not len(pts):
                continue
            half = shape.moved((0, 0), angle).exterior[:, 0].max() - shape.centroid[0]
            for k in np.lexsort((pts[:, 1], pts[:, 0] + half))[:8]:
                key = (pts[k, 0] + half, pts[k, 1])
                if (best is None or key < best[0]) and world.query(shape, pts[k], angle).fits:
                    best = (key, pts[k], angle)
                    break
        if best is None:
            raise RuntimeError("a piece fits nowhere (the strip is too short?)")
        world.add(shape, best[1], best[2])
    used = max(float(b.shape.exterior[:, 0].max()) for b in world.bodies())
    area = sum(b.shape.area for b in world.bodies())
    return world, used, area / (used * height)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("instance", nargs="?", default="jakobs1")
    parser.add_argument("--plot", metavar="OUT.png")
    args = parser.parse_args()
    if DATASETS is None:
        raise SystemExit("../shared/datasets not found")
    t0 = time.perf_counter()
    world, length, density = nest(args.instance)
    took = time.perf_counter() - t0
    c = world.contacts()
    assert not (c.states == 2).any() and not (c.container_states == 2).any()
    best = json.loads((DATASETS / "layouts" / f"{args.instance}.json").read_text())
    ring = np.array(best["container"])
    b_len = float(np.ptp(ring[:, 0]))
    b_area = sum(pc.Shape(p["vertices"]).area for p in best["placed"])
    b_density = b_area / (b_len * float(np.ptp(ring[:, 1])))
    print(f"{args.instance}: {len(world)} pieces, bottom-left fill in {took:.1f} s")
    print(f"  strip length {length:.4f}, density {100 * density:.1f}%")
    print(f"  best published (sparrow): length {b_len:.4f}, density {100 * b_density:.1f}%")
    print(f"  pairs in contact {int((c.states == 1).sum())}, penetrating 0, "
          f"all pieces inside the strip")
    if args.plot:
        from polycontact.cli.contacts import save_plot

        height = float(np.ptp(world.container.exterior[:, 1]))
        strip = pc.World(pc.Shape([(0, 0), (length, 0), (length, height), (0, height)]))
        strip.add_many([b.shape for b in world.bodies()])
        save_plot(strip.contacts(), args.plot)


if __name__ == "__main__":
    main()
