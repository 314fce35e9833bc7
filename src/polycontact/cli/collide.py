"""``polycontact collide SCENE.json``: first impact among the bodies of a scene."""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any

from .. import datasets
from ..limits import SAMPLES, TIME_TOLERANCE
from ._io import CommandError, index_text, integer_at_least, positive_number


def add_parser(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "collide",
        help="first time of impact among the bodies of a scene",
        description="Find when and where the bodies of a scene first penetrate "
        "(the first impact among all pairs). Vertex and edge numbers are 0-based, in "
        "the order of each body's vertices in the file (edge k joins vertex k and k + 1).",
    )
    p.add_argument("scene", metavar="SCENE.json",
                   help="scene file, or a shipped scene's name: "
                   + ", ".join(datasets.names("scenes")))
    p.add_argument("--method", choices=("exact", "sampled"), default="exact",
                   help="exact: continuous, never tunnels (default); sampled: the paper's")
    p.add_argument("--samples", type=integer_at_least(2), default=SAMPLES,
                   help=f"time points per round of the sampled method (default {SAMPLES})")
    p.add_argument("--time-tolerance", type=positive_number, default=None,
                   help=f"accuracy of the time (default: the scene's, else {TIME_TOLERANCE:g})")
    p.add_argument("--repair", action="store_true",
                   help="repair invalid polygons with shapely.make_valid and say so")
    p.add_argument("--all", action="store_true",
                   help="list every pair that meets within t_max, by time (not only the "
                   "first impact)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--plot", metavar="OUT.png",
                   help="draw the bodies, paths and contact (with --all: the earliest event)")
    p.set_defaults(func=run)


def _text(rep: dict[str, Any]) -> str:
    a, b = rep["pair"]
    lines = [f"pair: {a} and {b} ({rep['method']} method)"]
    lines.append("broad phase: " + (", ".join(f"[{s:.6g}, {e:.6g}]" for s, e in
                                              rep["broad_phase"]) or "none"))
    if rep["status"] == "penetrating-at-start":
        lines.append("already penetrating at t = 0")
    elif rep["collides"]:
        lines.append(f"collision at t = {rep['time']:.6f}")
    else:
        lines.append(f"no collision ({rep['status']})")
    if rep["first_contact"] is not None:
        lines.append(f"first contact at t = {rep['first_contact']:.6f}")
    for f in rep["features"]:
        n = {k: index_text(f.get(k)) for k in ("vertex", "loop", "edge", "other_loop",
                                                 "own_edge")}
        if f["kind"] == "edges-cross":
            lines.append(f"  edge {n['own_edge']} of {f['body']} crosses edge {n['edge']} "
                         f"of {f['other_body']}")
        else:
            lines.append(f"  vertex {n['vertex']} (loop {n['loop']}) of {f['body']} meets "
                         f"edge {n['edge']} (loop {n['other_loop']}) of {f['other_body']}")
    if rep["point"] is not None:
        lines.append(f"point: ({rep['point'][0]:.6g}, {rep['point'][1]:.6g})")
    if rep["normal"] is not None:
        lines.append(f"normal: ({rep['normal'][0]:.6g}, {rep['normal'][1]:.6g})")
    return "\n".join(lines)


def run(args: argparse.Namespace) -> int:
    from ..scene import load_scene

    scene = load_scene(datasets.locate(args.scene, "scenes"), repair=args.repair)
    for body in scene.bodies:
        for note in body.shape.repairs:
            print(f"polycontact collide: repaired {body.name}: {note}",
                  file=sys.stderr)
    options = {"method": args.method, "time_tolerance": args.time_tolerance,
               "samples": args.samples}
    if args.all:
        events = scene.impacts(**options)
        reps = [imp.to_dict((a.name, b.name)) for a, b, imp in events]
        if args.json:
            print(json.dumps({"events": reps}))
        else:
            print(f"{len(reps)} pair(s) meet within t_max = {scene.t_max:g}" +
                  "".join("\n\n" + _text(r) for r in reps))
        if not events:
            if args.plot:
                raise CommandError("--plot: no pair meets, nothing to draw")
            return 0
        body_a, body_b, impact = events[0]
    else:
        body_a, body_b, impact = scene.first_impact(**options)
        rep = impact.to_dict((body_a.name, body_b.name))
        print(json.dumps(rep) if args.json else _text(rep))
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        ax = impact.plot(names=(body_a.name, body_b.name))
        try:
            ax.figure.savefig(args.plot, dpi=120, bbox_inches="tight")
        except OSError as exc:
            raise CommandError(f"{args.plot}: cannot write ({exc.strerror})") from None
        except ValueError as exc:  # an image format matplotlib does not know
            raise CommandError(f"{args.plot}: cannot write the plot ({exc})") from None
    return 0
