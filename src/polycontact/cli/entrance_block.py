"""``polycontact entrance-block A.json B.json``: the entrance block, summarised and drawn."""

from __future__ import annotations

import argparse
import json
import math
import sys
from typing import Any

from ._io import plotting, read_shape, save_figure
from ._progress import announced
from .classify import relation_text

_FAMILIES = (("A2-B0", "E(A(2), B(0))"), ("A0-B2", "E(A(0), B(2))"), ("A1-B1", "E(A(1), B(1))"))


def _point(text: str) -> tuple[float, float]:
    try:
        x, y = (float(v) for v in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected x,y (two numbers), got {text!r}") from None
    if not (math.isfinite(x) and math.isfinite(y)):
        raise argparse.ArgumentTypeError(f"expected two finite numbers, got {text!r}")
    return x, y


def add_parser(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "entrance-block",
        help="the entrance block of A to B: its components, area and a figure",
        description="Build the entrance block E(A, B) (the positions of A's reference "
        "point where A touches or overlaps B) from its finite cover, print a summary "
        "and optionally draw it like the paper's Fig. 5.",
    )
    p.add_argument("a", metavar="A.json", help="the moving body A")
    p.add_argument("b", metavar="B.json", help="the fixed body B")
    p.add_argument("--method", choices=("swept", "pairs"), default="swept",
                   help="E(A(1), B(1)) as one swept region per edge of B (default) or as "
                   "one parallelogram per pair of edges")
    p.add_argument("--reference", type=_point, default=None, metavar="X,Y",
                   help="reference point a0 of A (default: A's area centroid); write "
                   "--reference=-1,2 for a negative x")
    p.add_argument("--plot", metavar="OUT.png", help="draw the block (paper Fig. 5 style)")
    p.add_argument("--repair", action="store_true",
                   help="repair invalid polygons with shapely.make_valid and say so")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=run)


def _text(rep: dict[str, Any], a: str, b: str) -> str:
    x, y = rep["reference"]
    counts = rep["components"]
    lines = [
        f"entrance block of A ({a}) to B ({b}), method {rep['method']}",
        f"reference point a0: ({x:.12g}, {y:.12g})",
        "components: " + " + ".join(f"{counts[k]} {name}" for k, name in _FAMILIES)
        + f" = {sum(counts.values())} ({rep['zero_width_components']} of zero width)",
        f"area of E(A, B): {rep['area']:.12g}",
        "relation at a0:",
    ]
    lines += ["  " + line for line in relation_text(rep["relation"])]
    return "\n".join(lines)


def run(args: argparse.Namespace) -> int:
    from ..entrance import entrance_block

    if args.plot:
        plotting()
    a = read_shape(args.a, repair=args.repair)
    b = read_shape(args.b, repair=args.repair)
    for path, shape in ((args.a, a), (args.b, b)):
        for note in shape.repairs:
            print(f"polycontact entrance-block: repaired {path}: {note}", file=sys.stderr)
    with announced(f"building the entrance block of A {args.a} ({a.n_vertices} vertices) "
                   f"to B {args.b} ({b.n_vertices} vertices)"):
        block = entrance_block(a, b, args.reference, method=args.method)
        rep = block.to_dict()
    print(json.dumps(rep) if args.json else _text(rep, args.a, args.b))
    if args.plot:
        from ..plotting.entrance_block import plot_entrance_block

        save_figure(plot_entrance_block(block), args.plot, dpi=110)
    return 0
