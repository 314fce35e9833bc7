"""``polycontact collide SCENE.json``: first impact among the bodies of a scene."""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any

from ._io import CommandError, index_text, integer_at_least, positive_number


def add_parser(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "collide",
        help="first time of impact among the bodies of a scene",
        description="Find when and where the bodies of a scene first penetrate "
        "(the first impact among all pairs). Vertex and edge numbers are 0-based, in "
        "the order of each body's vertices in the file (edge k joins vertex k and k + 1).",
    )
    p.add_argument("scene", metavar="SCENE.json", help="scene file (see the README)")
    p.add_argument("--method", choices=("exact", "sampled"), default="exact",
                   help="exact: continuous, never tunnels (default); sampled: the paper's")
    p.add_argument("--samples", type=integer_at_least(2), default=10,
                   help="time points per round of the sampled method (default 10)")
    p.add_argument("--time-tolerance", type=positive_number, default=None,
                   help="accuracy of the time (default: the scene's, else 1e-4)")
    p.add_argument("--repair", action="store_true",
                   help="repair invalid polygons with shapely.make_valid and say so")
    p.add_argument("--all", action="store_true",
                   help="list every pair that meets within t_max, by time (not only the "
                   "first impact)")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--plot", metavar="OUT.png",
                   help="draw the bodies, paths and contact (with --all: the earliest event)")
    p.set_defaults(func=run)


def _features(impact: Any, name_a: str, name_b: str) -> list[dict]:
    names = {"a": (name_a, name_b), "b": (name_b, name_a)}
    out = []
    for f in impact.features:
        body, other = names[f.body]
        item = {"body": body, "vertex": f.vertex, "loop": f.loop, "other_body": other,
                "edge": f.edge, "other_loop": f.other_loop, "kind": f.kind}
        if f.own_edge is not None:
            item["own_edge"] = f.own_edge
        out.append(item)
    return out


def _as_list(x: Any) -> list[float] | None:
    return None if x is None else [float(v) for v in x]


def report(body_a: Any, body_b: Any, impact: Any) -> dict:
    """The JSON object printed by ``--json``."""
    return {
        "collides": impact.collides,
        "time": impact.time,
        "first_contact": impact.first_contact,
        "state": None if impact.state is None else impact.state.value,
        "features": _features(impact, body_a.name, body_b.name),
        "point": _as_list(impact.point),
        "normal": _as_list(impact.normal),
        "method": impact.method,
        "broad_phase": [list(iv) for iv in impact.broad_phase],
        "status": impact.status.value,
        "pair": [body_a.name, body_b.name],
        "time_bracket": None if impact.time_bracket is None else list(impact.time_bracket),
        "time_tolerance": impact.time_tolerance,
        "iterations": impact.iterations,
    }


def _text(rep: dict) -> str:
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

    scene = load_scene(args.scene, repair=args.repair)
    for body in scene.bodies:
        for note in body.shape.repairs:
            print(f"polycontact collide: repaired {body.name}: {note}",
                  file=sys.stderr)
    options = {"method": args.method, "time_tolerance": args.time_tolerance,
               "samples": args.samples}
    if args.all:
        events = scene.impacts(**options)
        reps = [report(a, b, imp) for a, b, imp in events]
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
        rep = report(body_a, body_b, impact)
        print(json.dumps(rep) if args.json else _text(rep))
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        from ..plotting.impact import plot_impact

        ax = plot_impact(body_a.shape, body_a.motion, body_b.shape, body_b.motion, impact,
                         names=(body_a.name, body_b.name))
        try:
            ax.figure.savefig(args.plot, dpi=120, bbox_inches="tight")
        except OSError as exc:
            raise CommandError(f"{args.plot}: cannot write ({exc.strerror})") from None
    return 0
