"""``polycontact classify A.json B.json``: separate, contact or penetrating."""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any

from ._io import BODY_FILE_FORMS, index_text, non_negative_number, read_shape
from ._progress import announced


def add_parser(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "classify",
        help="whether two bodies are separate, in contact or penetrating",
        description="Classify two bodies where they stand: separate, contact (touching, "
        "interiors disjoint) or penetrating (interiors overlap). Each file is a body: "
        f"{BODY_FILE_FORMS}. "
        "Vertex and edge numbers are 0-based, in the order of the vertices in the file "
        "(edge k joins vertex k and k + 1), whatever their orientation.",
    )
    p.add_argument("a", metavar="A.json", help="first body (A)")
    p.add_argument("b", metavar="B.json", help="second body (B)")
    p.add_argument("--tolerance", type=non_negative_number, default=None, metavar="T",
                   help="absolute distance that counts as touching "
                   "(default max(1e-12 × the larger body's extent, 64 float spacings of "
                   "the largest |coordinate|))")
    p.add_argument("--repair", action="store_true",
                   help="repair invalid polygons with shapely.make_valid and say so")
    p.add_argument("--state-only", action="store_true",
                   help="print the state alone (and the tolerance with --json): skips the "
                   "distance, the features, the point and the normal, which can take long "
                   "for large overlapping bodies")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=run)


def relation_text(rep: dict[str, Any]) -> list[str]:
    """The relation as lines of text (``rep`` is :meth:`Relation.to_dict`)."""
    lines = [f"state: {rep['state']}", f"distance: {rep['distance']:.12g}",
             "features:" if rep["features"] else "features: none"]
    for f in rep["features"]:
        other = "b" if f["body"] == "a" else "a"
        n = {k: index_text(f.get(k)) for k in ("vertex", "loop", "edge", "other_loop",
                                                 "own_edge")}
        if f["kind"] == "edges-cross":
            lines.append(f"  edge {n['own_edge']} (loop {n['loop']}) of {f['body']} crosses "
                         f"edge {n['edge']} (loop {n['other_loop']}) of {other}")
        else:
            where = "on" if f["kind"] == "vertex-on-edge" else "inside, nearest"
            lines.append(f"  vertex {n['vertex']} (loop {n['loop']}) of {f['body']} {where} "
                         f"edge {n['edge']} (loop {n['other_loop']}) of {other}")
    for key in ("point", "normal"):
        if rep[key] is not None:
            lines.append(f"{key}: ({rep[key][0]:.12g}, {rep[key][1]:.12g})")
    return lines


def run(args: argparse.Namespace) -> int:
    from ..relation import State, classify

    a = read_shape(args.a, repair=args.repair)
    b = read_shape(args.b, repair=args.repair)
    for path, shape in ((args.a, a), (args.b, b)):
        for note in shape.repairs:
            print(f"polycontact classify: repaired {path}: {note}", file=sys.stderr)
    bodies = f"{args.a} ({a.n_vertices} vertices) and {args.b} ({b.n_vertices} vertices)"
    with announced(f"classifying {bodies}"):
        relation = classify(a, b, tolerance=args.tolerance)
    if args.state_only:
        state = relation.state.value
        print(json.dumps({"state": state, "tolerance": relation.tolerance}) if args.json
              else f"state: {state}")
        return 0
    what = {State.SEPARATE: "the distance",
            State.CONTACT: "the features",
            State.PENETRATING: "the penetration depth and the features"}[relation.state]
    with announced(f"computing {what} of {bodies} (--state-only skips this)"):
        rep = relation.to_dict()
    print(json.dumps(rep) if args.json else "\n".join(relation_text(rep)))
    return 0
