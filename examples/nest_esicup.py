"""Bottom-left fill of an ESICUP strip-packing instance with ``World.feasible_region``.

Run: ``python examples/nest_esicup.py [INSTANCE] [--plot OUT.png]``. INSTANCE is the
name of an instance shipped with polycontact (``polycontact.datasets``: jakobs1, the
default, or shapes0) or the path of an ESICUP instance file (JSON, jagua-rs form).

Pieces go largest first; each goes, over its allowed orientations, where its right end
is leftmost (then lowest) among the vertices of its feasible region: the container's
inner-fit polygon minus the bodies' no-fit polygons, exact fits and slides kept. Every
placement is checked with the exact ``World.query`` before it is added, and at the end
``World.contacts`` confirms that no two pieces penetrate and every piece is in the
strip. For a shipped instance it prints the best published layout's length and density
beside its own.
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np
import shapely

import polycontact as pc
from polycontact import datasets


def candidates(region: shapely.Geometry) -> np.ndarray:
    """Every vertex of a feasible region (a polygon's leftmost point is a vertex)."""
    pts = [np.asarray(g.coords) if g.geom_type in ("Point", "LineString") else
           np.concatenate([np.asarray(r.coords) for r in (g.exterior, *g.interiors)])
           for g in shapely.get_parts(region) if not g.is_empty]
    return np.concatenate(pts) if pts else np.empty((0, 2))


def nest(instance: pc.Instance) -> tuple[pc.World, float, float]:
    """The filled strip, its used length and the density of the pieces in it."""
    height = instance.strip_height
    pieces = []
    for shape, degrees, demand in zip(instance.pieces, instance.orientations,
                                      instance.demand):
        pieces += [(shape, [math.radians(a) for a in degrees])] * demand
    pieces.sort(key=lambda p: -p[0].area)
    length = sum(float(np.ptp(s.exterior, axis=0).max()) for s, _ in pieces)
    world = pc.World(pc.Shape([(0, 0), (length, 0), (length, height), (0, height)]))
    for shape, angles in pieces:
        best = None
        for angle in angles:
            pts = candidates(world.feasible_region(shape, angle))
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


def length_and_density(world: pc.World) -> tuple[float, float]:
    """The strip length and the density of a layout (a World whose container is a strip)."""
    lo, hi = world.container.exterior.min(axis=0), world.container.exterior.max(axis=0)
    length, height = hi - lo
    return float(length), sum(b.shape.area for b in world.bodies()) / float(length * height)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("instance", nargs="?", default="jakobs1",
                        help="a shipped instance's name (" +
                        ", ".join(datasets.names("esicup")) + ") or an ESICUP file")
    parser.add_argument("--plot", metavar="OUT.png", help="draw the filled strip")
    args = parser.parse_args()
    instance = pc.read_esicup(datasets.locate(args.instance, "esicup"))
    t0 = time.perf_counter()
    world, length, density = nest(instance)
    took = time.perf_counter() - t0
    c = world.contacts()
    assert not (c.states == 2).any() and not (c.container_states == 2).any()
    print(f"{instance.name}: {len(world)} pieces, bottom-left fill in {took:.1f} s")
    print(f"  strip length {length:.4f}, density {100 * density:.1f}%")
    if args.instance in datasets.names("layouts"):
        b_len, b_density = length_and_density(datasets.layout(args.instance))
        print(f"  best published (sparrow): length {b_len:.4f}, "
              f"density {100 * b_density:.1f}%")
    print(f"  pairs in contact {int((c.states == 1).sum())}, penetrating 0, "
          f"all pieces inside the strip")
    if args.plot:
        try:
            import matplotlib
        except ImportError:
            raise SystemExit("--plot needs matplotlib: pip install 'polycontact[plot]'") from None
        matplotlib.use("Agg")
        strip = pc.World(pc.Shape([(0, 0), (length, 0), (length, instance.strip_height),
                                   (0, instance.strip_height)]))
        strip.add_many([b.shape for b in world.bodies()])
        ax = strip.contacts().plot()
        ax.set_title(f"{instance.name}: bottom-left fill, length {length:.4g}")
        ax.figure.savefig(args.plot, dpi=110, bbox_inches="tight")


if __name__ == "__main__":
    main()
