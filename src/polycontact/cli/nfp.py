"""``polycontact nfp A B``: the no-fit polygon of A orbiting the fixed B."""

from __future__ import annotations

import argparse
import json
import math
from typing import Any

from ._io import BODY_FILE_FORMS, plotting, positive_number, read_shape, save_figure
from ._progress import announced


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
        "slides (segments) where A touches B without overlapping. Each file is a body: "
        f"{BODY_FILE_FORMS}.",
    )
    p.add_argument("a", metavar="A", help="orbiting body")
    p.add_argument("b", metavar="B", help="fixed body (the container with --inner)")
    p.add_argument("--reference", type=_reference, default="centroid",
                   metavar="origin|centroid|x,y",
                   help="A's reference point (default: its area centroid; origin: plain "
                   "translations of A's coordinates, as nesting codes use)")
    p.add_argument("--inner", action="store_true",
                   help="the inner-fit polygon instead: where A lies inside B (B the "
                   "container); the same summary, --wkt prints its geometry")
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
    p.add_argument("--plot", metavar="OUT.png",
                   help="draw the figure into this file (with --inner: the container, "
                   "where A fits, A at one of those places)")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    import polycontact as pc

    if args.plot:
        plotting()
    a = read_shape(args.a, repair=args.repair)
    b = read_shape(args.b, repair=args.repair)
    bodies = f"A {args.a} ({a.n_vertices} vertices) and B {args.b} ({b.n_vertices} vertices)"
    if args.inner:
        with announced(f"computing the inner-fit polygon of {bodies}"):
            geom = pc.inner_fit_polygon(a, b, args.reference, tolerance=args.tolerance)
        a0 = _reference_point(a, args.reference)
        _print_inner_fit(geom, a0, args)
        if args.plot:
            from ..plotting.nfp import plot_inner_fit

            save_figure(plot_inner_fit(a, b, geom, a0).figure, args.plot)
        return 0
    with announced(f"computing the no-fit polygon of {bodies}"):
        nfp = pc.no_fit_polygon(a, b, args.reference, tolerance=args.tolerance)
    rep = nfp.to_dict()
    if args.json:
        print(json.dumps(rep))
    elif args.wkt:
        _print_wkt(nfp.region, rep["exact_fits"], rep["slides"])
    else:
        print("\n".join(_summary(nfp.reference, "region", nfp.region, rep["exact_fits"],
                                 rep["slides"])))
    if args.plot:
        save_figure(nfp.plot().figure, args.plot)
    return 0


def _reference_point(a: Any, reference: Any) -> tuple[float, float]:
    """A's reference point as ``--reference`` names it (see :func:`_reference`)."""
    if reference == "centroid":
        x, y = a.centroid.tolist()
        return x, y
    return (0.0, 0.0) if reference == "origin" else reference


def _print_inner_fit(geom: Any, a0: tuple[float, float], args: argparse.Namespace) -> None:
    """The inner-fit polygon as ``--json``, ``--wkt`` or the text summary ask."""
    import shapely

    from ..plotting.nfp import fit_parts

    region, fits, slides = fit_parts(geom)
    if args.wkt:
        print(geom.wkt)
        return
    if args.json:
        print(json.dumps({
            "reference": list(a0),
            "inner_fit": json.loads(shapely.to_geojson(geom)),
            "area": float(region.area),
            "holes": _holes(region),
            "exact_fits": fits.tolist(),
            "slides": slides.tolist(),
        }))
        return
    lines = _summary(a0, "inner-fit region", region, fits.tolist(), slides.tolist())
    if geom.is_empty:
        lines.append("A does not fit inside B")
    print("\n".join(lines))


def _holes(region: Any) -> int:
    import shapely

    return sum(len(g.interiors) for g in shapely.get_parts(region))


def _summary(a0: Any, what: str, region: Any, fits: list[Any], slides: list[Any]) -> list[str]:
    """The text summary of a no-fit or inner-fit polygon: reference point, region,
    exact fits and slides."""
    import shapely

    x, y = a0
    polygons = 0 if region.is_empty else len(shapely.get_parts(region))
    lines = [f"reference point of A: ({x:.12g}, {y:.12g})",
             f"{what}: {polygons} polygon(s), area "
             f"{region.area:.12g}, {_holes(region)} hole(s)",
             f"exact fits: {len(fits)}"]
    lines += [f"  ({fx:.12g}, {fy:.12g})" for fx, fy in fits]
    lines.append(f"slides: {len(slides)}")
    lines += [f"  ({x0:.12g}, {y0:.12g}) to ({x1:.12g}, {y1:.12g})"
              for (x0, y0), (x1, y1) in slides]
    return lines


def _print_wkt(region: Any, fits: list[Any], slides: list[Any]) -> None:
    import shapely

    print(region.wkt)
    if fits:
        print(shapely.MultiPoint(fits).wkt)
    if slides:
        print(shapely.MultiLineString(slides).wkt)
