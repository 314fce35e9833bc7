"""``polycontact collide SCENE.json``: first impact among the bodies of a scene."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

from .. import datasets
from .._json import load_json
from ..errors import InvalidSceneError
from ..limits import SAMPLES, TIME_TOLERANCE
from ._errors import CommandError
from ._io import index_text, integer_at_least, plotting, positive_number, save_figure
from ._progress import announced

#: What a scene is, in one line (for the message about a body file given instead).
SCENE_IN_A_LINE = ('a JSON object {"t_max": ..., "bodies": [...]}: two or more bodies, '
                   "each with its vertices and motion; see polycontact collide --help")

#: The scene format, as ``polycontact collide --help`` shows it.
SCENE_FORMAT = """\
scene format (JSON; lengths in any unit, times in any unit, used consistently):
  {"t_max": 20,                   end of the time window searched, from t = 0
   "time_tolerance": 1e-4,        optional: accuracy of the time (default %g)
   "description": "...",          optional
   "bodies": [                    two or more, each moving rigidly about its
                                  area centroid:
     {"name": "red",              optional (default body0, body1, ...)
      "vertices": [[x, y], ...],  outer loop at t = 0, either orientation
      "holes": [[[x, y], ...]],   optional
      "velocity": [vx, vy],       optional: length per time (default [0, 0])
      "acceleration": [ax, ay],   optional: length per time squared
      "angular_velocity": w,      optional: radians per time, counter-clockwise
      "angular_acceleration": al  optional: radians per time squared
     }, ...]}
  "angular_velocity_deg" and "angular_acceleration_deg" take degrees instead.
  Unknown keys are refused. Vertex and edge numbers are 0-based, in the order of each
  body's vertices in the file (edge k joins vertex k and k + 1).

example:
  {"t_max": 5, "bodies": [
    {"name": "a", "vertices": [[0, 0], [1, 0], [1, 1], [0, 1]], "velocity": [1, 0]},
    {"name": "b", "vertices": [[3, 0], [4, 0], [4, 1], [3, 1]], "velocity": [-1, 0]}]}
  answers "collision at t = 1.00..." (each closes half the gap of 2 at speed 1). The
  paper's case 1 ships as the scene named paper-case-1 (examples/paper-case-1.json).
""" % TIME_TOLERANCE


def add_parser(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "collide",
        help="first time of impact among the bodies of a scene",
        description="Find when and where the bodies of a scene first penetrate (the first\n"
        "impact among all pairs), each body moving with constant linear and angular\n"
        "acceleration. The scene file's format follows the options.",
        epilog=SCENE_FORMAT,
        formatter_class=argparse.RawDescriptionHelpFormatter,
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

    if args.plot:
        plotting()
    path = datasets.locate(args.scene, "scenes")
    try:
        with announced(f"reading {path}"):
            scene = load_scene(path, repair=args.repair)
    except InvalidSceneError:
        if _holds_a_body(path):
            raise CommandError(f"{path}: this is a body file, not a scene: collide takes "
                               f"a scene ({SCENE_IN_A_LINE})") from None
        raise
    for body in scene.bodies:
        for note in body.shape.repairs:
            print(f"polycontact collide: repaired {body.name}: {note}",
                  file=sys.stderr)
    options = {"method": args.method, "time_tolerance": args.time_tolerance,
               "samples": args.samples}
    bodies = f"{len(scene.bodies)} bodies ({sum(b.shape.n_vertices for b in scene.bodies)} " \
        f"vertices) over [0, {scene.t_max:g}]"
    names = [b.name for b in scene.bodies]
    if args.all:
        with announced(f"searching every impact of {bodies}"):
            events = scene.impacts(**options)
        reps = [imp.to_dict((names[i], names[j])) for i, j, imp in events]
        if args.json:
            print(json.dumps({"events": reps}))
        else:
            print(f"{len(reps)} pair(s) meet within t_max = {scene.t_max:g}" +
                  "".join("\n\n" + _text(r) for r in reps))
        if not events:
            if args.plot:
                raise CommandError("--plot: no pair meets, nothing to draw")
            return 0
        i, j, impact = events[0]
    else:
        with announced(f"searching the first impact of {bodies}"):
            i, j, impact = scene.first_impact(**options)
        rep = impact.to_dict((names[i], names[j]))
        print(json.dumps(rep) if args.json else _text(rep))
    if args.plot:
        save_figure(impact.plot(names=(names[i], names[j])).figure, args.plot)
    return 0


def _holds_a_body(path: str) -> bool:
    """Whether the file ``path`` (not a valid scene) holds one body instead: a body
    mapping, GeoJSON, a list of vertices, WKT or WKB."""
    try:
        raw = Path(path).read_bytes()
    except OSError:
        return False
    if raw[:1] in (b"\x00", b"\x01"):  # binary WKB
        return True
    text = raw.decode("utf-8", errors="replace").strip()
    if text.upper().startswith(("POLYGON", "MULTIPOLYGON")):
        return True
    try:
        data = load_json(text)
    except ValueError:
        return False
    if isinstance(data, list):
        return True
    return isinstance(data, dict) and "bodies" not in data and (
        "vertices" in data or data.get("type") in ("Polygon", "MultiPolygon", "Feature"))
