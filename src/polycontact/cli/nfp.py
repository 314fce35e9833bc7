"""``polycontact nfp A B``: the no-fit polygon of A orbiting the fixed B."""

from __future__ import annotations

import argparse
import json
import math
from typing import Any

from ._io import CommandError, plotting, positive_number, read_shape


def _reference(text: str) -> Any:
    if text in ("origin", "centroid"):
        return text
    parts = text.split(",")
    try:
        x, y = (float(v) for v in parts)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected origin, centroid or x,y, got {text!r}") from None
    if not (math.isfinite(x) and math.isfinite(y)):
        raise argparse.ArgumentTypeError(f"expected finite numbers, got {text!r}")
    return (x, y)


def add_parser(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "nfp",
        help="no-fit polygon of A orbiting B (or A's inner-fit polygon in B)",
        description="No-fit polygon: the positions of A's reference point where A "
        "touches or overlaps the fixed B, with its holes, exact fits (points) and "
        "slides (segments) where A touches B without overlapping. Each file is a JSON "
        'body {"vertices": [[x, y], ...], "holes": [...]}, a GeoJSON Polygon or WKT.',
    )
    p.add_argument("a", metavar="A", help="orbiting body")
    p.add_argument("b", metavar="B", help="fixed body (the container with --inner)")
    p.add_argument("--reference", type=_reference, default="centroid",
                   metavar="origin|centroid|x,y",
                   help="A's reference point (default: its area centroid; origin: plain "
                   "translations of A's coordinates, as nesting codes use)")
    p.add_argument("--inner", action="store_true",
                   help="the inner-fit polygon instead: where A lies inside B")
    p.add_argument("--tolerance", type=positive_number, default=None, metavar="T",
                   help="absolute distance tolerance (default max(1e-12 × the extent, "
                   "64 float spacings of the largest |coordinate|) of the sums)")
    p.add_argument("--repair", action="store_true",
                   help="repair invalid polygons with shapely.make_valid and say so")
    out = p.add_mutually_exclusive_group()
    out.add_argument("--wkt", action="store_true",
                     help="print WKT: the region, then a MULTIPOINT of the exact fits and a "
                     "MULTILINESTRING of the slides when there are any")
    out.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--plot", metavar="OUT.png", help="draw the figure into this file")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    import shapely

    import polycontact as pc

    if args.plot:
        if args.inner:
            raise CommandError("--plot draws no-fit polygons only, not with --inner")
        plotting()
    a = read_shape(args.a, repair=args.repair)
    b = read_shape(args.b, repair=args.repair)
    if args.inner:
        geom = pc.inner_fit_polygon(a, b, args.reference, tolerance=args.tolerance)
        if args.json:
            print(json.dumps({"inner_fit": json.loads(shapely.to_geojson(geom))}))
        else:
            print(geom.wkt)
        return 0
    nfp = pc.no_fit_polygon(a, b, args.reference, tolerance=args.tolerance)
    rep = nfp.to_dict()
    fits, slides, holes = rep["exact_fits"], rep["slides"], rep["holes"]
    if args.json:
        print(json.dumps(rep))
    elif args.wkt:
        print(nfp.region.wkt)
        if fits:
            print(shapely.MultiPoint(fits).wkt)
        if slides:
            print(shapely.MultiLineString(slides).wkt)
    else:
        x, y = nfp.reference
        parts = len(shapely.get_parts(nfp.region))
        print(f"reference point of A: ({x:.12g}, {y:.12g})")
        print(f"region: {parts} polygon(s), area {nfp.region.area:.12g}, {holes} hole(s)")
        print(f"exact fits: {len(fits)}")
        for fx, fy in fits:
            print(f"  ({fx:.12g}, {fy:.12g})")
        print(f"slides: {len(slides)}")
        for (x0, y0), (x1, y1) in slides:
            print(f"  ({x0:.12g}, {y0:.12g}) to ({x1:.12g}, {y1:.12g})")
    if args.plot:
        ax = nfp.plot()
        try:
            ax.figure.savefig(args.plot, dpi=120)
        except (OSError, ValueError) as exc:
            raise CommandError(f"{args.plot}: cannot write the plot ({exc})") from None
    return 0
