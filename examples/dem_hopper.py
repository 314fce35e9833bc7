"""A hopper discharge with the discrete element method (DEM), polycontact finding the contacts.

Run: ``python examples/dem_hopper.py [--bodies 2000] [--steps 1000] [--out hopper.png]
[--gif hopper.gif]``.

Concave polygons (stars, L-shapes, crosses, U-shapes, and square frames with a hole),
scattered at random in a hopper and the column above it, fall under gravity, pack in
the hopper and flow out through its outlet into a bin below. The walls are bodies of the
same World. Each step:

1. ``World.contacts()`` gives every pair in contact with its geometry as arrays: the
   penetration depth (``-distances``), the unit normal, the centroid of the overlap;
2. a linear spring-dashpot acts along the normal, Coulomb friction (regularised by a
   viscous term at low slip) across it, applied at the overlap's centroid;
3. velocities and positions are integrated explicitly (symplectic Euler) and
   ``World.set_poses`` puts every body where it now is, in one call.

Every ``--check-every`` steps, ``World.sweep`` follows the bodies through the step with
the velocities they are given (the integrator's straight motion over the step) and lists
every pair whose interiors come to overlap within it: such a pair found in contact
neither before nor after its step would have been skipped by the contact detection at
the steps (a collision missed between them); the run counts them.

The force model stays here: polycontact is the detection library, as parry is for
Rapier. The figure of the final state goes to ``--out``; ``--gif`` adds an animation.
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import numpy as np

import polycontact as pc

GRAVITY = np.array([0.0, -10.0])
DENSITY = 1.0
STIFFNESS = 5.0e3  # normal spring, per unit of depth
RESTITUTION = 0.3
FRICTION = 0.5  # Coulomb coefficient
SLIP = 1.0e-3  # below this slip speed, friction is viscous (the regularisation)


def templates() -> list[tuple[str, pc.Shape]]:
    """The bodies' shapes, about 1 across, centred on their centroids."""
    t = np.linspace(0.0, 2.0 * np.pi, 10, endpoint=False) + np.pi / 2
    r = np.where(np.arange(10) % 2 == 0, 0.6, 0.28)
    star = np.c_[r * np.cos(t), r * np.sin(t)]
    ell = [(0, 0), (1, 0), (1, 0.4), (0.4, 0.4), (0.4, 1), (0, 1)]
    cross = [(-0.5, -0.15), (-0.15, -0.15), (-0.15, -0.5), (0.15, -0.5), (0.15, -0.15),
             (0.5, -0.15), (0.5, 0.15), (0.15, 0.15), (0.15, 0.5), (-0.15, 0.5),
             (-0.15, 0.15), (-0.5, 0.15)]
    u = [(0, 0), (1, 0), (1, 0.9), (0.7, 0.9), (0.7, 0.3), (0.3, 0.3), (0.3, 0.9), (0, 0.9)]
    frame = ([(0, 0), (0.9, 0), (0.9, 0.9), (0, 0.9)],
             [[(0.25, 0.25), (0.25, 0.65), (0.65, 0.65), (0.65, 0.25)]])
    shapes = [("star", pc.Shape(star)), ("L", pc.Shape(ell)), ("cross", pc.Shape(cross)),
              ("U", pc.Shape(u)), ("frame", pc.Shape(*frame))]
    return [(name, s.moved(-s.centroid)) for name, s in shapes]


def polar_moment(shape: pc.Shape) -> float:
    """Second moment of area about the centroid (holes removed), per unit density."""
    total = 0.0
    for loop in shape.loops:
        x, y = (loop - shape.centroid).T
        xn, yn = np.roll(x, -1), np.roll(y, -1)
        cross = x * yn - xn * y
        total += float(np.sum(cross * (x * x + x * xn + xn * xn + y * y + y * yn + yn * yn)))
    return total / 12.0


def hopper() -> list[pc.Shape]:
    """The walls: a funnel at 45 degrees with a 6-wide outlet under a column, and a bin."""
    def wall(a, b, thick=1.0):  # (the inner face a -> b, the container on its right)
        a, b = np.asarray(a, float), np.asarray(b, float)
        n = np.array([a[1] - b[1], b[0] - a[0]]) / np.hypot(*(b - a)) * thick
        return pc.Shape([a, b, b + n, a + n])  # thick on the left of a -> b

    return [wall((-3.0, 0.0), (-33.0, 30.0)), wall((33.0, 30.0), (3.0, 0.0)),
            wall((-33.0, 30.0), (-33.0, 110.0)), wall((33.0, 110.0), (33.0, 30.0)),
            wall((36.0, -22.0), (-36.0, -22.0)), wall((-36.0, -22.0), (-36.0, -6.0)),
            wall((36.0, -6.0), (36.0, -22.0))]


def start_poses(shapes: list[pc.Shape], rng: np.random.Generator) -> tuple[np.ndarray, ...]:
    """A random loose packing of ``shapes`` in the funnel and the column above it: each
    body at a random pose where it touches nothing placed before it (``World.query``)."""
    world = pc.World()
    world.add_many(hopper())
    pos, ang = np.empty((len(shapes), 2)), np.empty(len(shapes))
    for k, shape in enumerate(shapes):
        while True:
            y = rng.uniform(1.0, 80.0)
            half = min(3.0 + y, 33.0) - 0.8
            p, a = (rng.uniform(-half, half), y), rng.uniform(0.0, 2.0 * np.pi)
            if not len(world.query(shape, p, a).ids):
                break
        world.add(shape, p, a)
        pos[k], ang[k] = p, a
    return pos, ang


class Hopper:
    """The bodies, their state and the World that finds their contacts."""

    def __init__(self, count: int, seed: int) -> None:
        rng = np.random.default_rng(seed)
        self.kinds = templates()
        kind = rng.integers(0, len(self.kinds), count)
        kind[rng.random(count) < 0.1] = len(self.kinds) - 1  # more frames: holes
        self.kind = kind
        shapes = [self.kinds[k][1] for k in kind]
        pos, ang = start_poses(shapes, rng)
        self.world = pc.World()
        self.ids = self.world.add_many(shapes, pos, ang)
        self.walls = self.world.add_many(hopper())
        area = np.array([s.area for _, s in self.kinds])[kind]
        self.mass = DENSITY * area
        self.inertia = DENSITY * np.array([polar_moment(s) for _, s in self.kinds])[kind]
        self.pos, self.ang = pos, ang
        self.vel = np.zeros((count, 2))
        self.spin = np.zeros(count)
        # index of each id among the moving bodies (walls: -1)
        self.row = np.full(int(self.walls.max()) + 1, -1)
        self.row[self.ids] = np.arange(count)
        m = float(self.mass.mean())
        self.dt = 0.05 * math.pi * math.sqrt(m / STIFFNESS)  # a 20th of a collision
        log_e = math.log(RESTITUTION)
        zeta = -log_e / math.sqrt(math.pi**2 + log_e**2)
        self.damping = 2.0 * zeta * math.sqrt(STIFFNESS * m / 2.0)

    def forces(self, contacts: pc.Contacts) -> tuple[np.ndarray, np.ndarray]:
        """Force and torque on every moving body from the contacts' arrays."""
        n = len(self.ids)
        force = np.zeros((n, 2))
        torque = np.zeros(n)
        pen = contacts.states == 2
        if not pen.any():
            return force, torque
        ia, ib = self.row[contacts.pairs[pen, 0]], self.row[contacts.pairs[pen, 1]]
        depth = -contacts.distances[pen]
        normal = contacts.normals[pen]
        point = contacts.overlap_centroids[pen]
        va, vb = self._point_velocity(ia, point), self._point_velocity(ib, point)
        rel = vb - va
        vn = np.einsum("ij,ij->i", rel, normal)
        fn = np.maximum(STIFFNESS * depth - self.damping * vn, 0.0)
        vt = rel - vn[:, None] * normal
        slip = np.hypot(vt[:, 0], vt[:, 1])
        ft = np.minimum(FRICTION * fn, FRICTION * fn * slip / SLIP)
        with np.errstate(invalid="ignore", divide="ignore"):
            tangent = np.where(slip[:, None] > 0.0, vt / slip[:, None], 0.0)
        f_b = fn[:, None] * normal - ft[:, None] * tangent  # on b; a gets the opposite
        for rows, sign in ((ia, -1.0), (ib, 1.0)):
            moving = rows >= 0
            r = rows[moving]
            f = sign * f_b[moving]
            arm = point[moving] - self.pos[r]
            np.add.at(force, r, f)
            np.add.at(torque, r, arm[:, 0] * f[:, 1] - arm[:, 1] * f[:, 0])
        return force, torque

    def _point_velocity(self, rows: np.ndarray, point: np.ndarray) -> np.ndarray:
        """Velocity of the material point at ``point`` of each body (walls: 0)."""
        out = np.zeros_like(point)
        moving = rows >= 0
        r = rows[moving]
        arm = point[moving] - self.pos[r]
        out[moving] = self.vel[r] + self.spin[r, None] * np.c_[-arm[:, 1], arm[:, 0]]
        return out

    def step(self, contacts: pc.Contacts, check: bool) -> tuple[int, set[tuple[int, int]]]:
        """One explicit step from ``contacts`` (those of the current poses); with
        ``check``, the pairs that touch within the step (by ``World.sweep``)."""
        force, torque = self.forces(contacts)
        self.vel += (force / self.mass[:, None] + GRAVITY) * self.dt
        self.spin += torque / self.inertia * self.dt
        met: set[tuple[int, int]] = set()
        if check:
            every = np.zeros((len(self.world), 2))
            spin = np.zeros(len(self.world))
            order = np.searchsorted(self.world.ids, self.ids)
            every[order] = self.vel
            spin[order] = self.spin
            sweep = self.world.sweep(self.dt, every, spin)
            # the pairs whose interiors come to overlap within the step (a graze within
            # the search's contact resolution, state 1, exerts no force)
            met = set(map(tuple, sweep.pairs[sweep.states == 2].tolist()))
        self.pos = self.pos + self.vel * self.dt
        self.ang = self.ang + self.spin * self.dt
        self.world.set_poses(self.ids, self.pos, self.ang)
        return len(met), met

    def run(self, steps: int, check_every: int, frames: int = 0) -> dict[str, object]:
        from tqdm import tqdm

        contacts = self.world.contacts()
        skipped = checked = met_total = 0
        snapshots = []
        keep = max(1, steps // frames) if frames else 0
        for k in tqdm(range(steps), desc="DEM steps", unit="step"):
            check = check_every > 0 and k % check_every == 0
            before = set(map(tuple, contacts.pairs.tolist())) if check else set()
            met, pairs = self.step(contacts, check)
            contacts = self.world.contacts()
            if check:
                after = set(map(tuple, contacts.pairs.tolist()))
                checked += 1
                met_total += met
                skipped += len(pairs - before - after)
            if keep and k % keep == 0:
                snapshots.append((self.pos.copy(), self.ang.copy()))
        return {"checked": checked, "met": met_total, "skipped": skipped,
                "snapshots": snapshots, "pairs": len(contacts)}

    def placed(self, pos: np.ndarray, ang: np.ndarray) -> list[list[np.ndarray]]:
        """Every moving body's loops at the given poses."""
        out = []
        for k, p, a in zip(self.kind, pos, ang):
            c, s = math.cos(a), math.sin(a)
            rot = np.array([[c, s], [-s, c]])
            out.append([loop @ rot + p for loop in self.kinds[k][1].loops])
        return out


def draw(sim: Hopper, pos: np.ndarray, ang: np.ndarray, ax, title: str) -> None:
    from matplotlib.collections import PathCollection
    from matplotlib.path import Path as MplPath

    def path(loops):
        verts = np.concatenate([np.vstack([lp, lp[:1]]) for lp in loops])
        codes = np.concatenate([[MplPath.MOVETO] + [MplPath.LINETO] * (len(lp) - 1)
                                + [MplPath.CLOSEPOLY] for lp in loops])
        return MplPath(verts, codes)

    colours = np.array(["#4c72b0", "#dd8452", "#55a868", "#c44e52", "#8172b3"])
    ax.clear()
    ax.add_collection(PathCollection([path(b.loops) for b in
                                      (sim.world.body(int(w)).shape for w in sim.walls)],
                                     facecolors="0.6", edgecolors="0.3", linewidths=0.5))
    ax.add_collection(PathCollection([path(lp) for lp in sim.placed(pos, ang)],
                                     facecolors=colours[sim.kind], edgecolors="0.15",
                                     linewidths=0.2))
    ax.set_xlim(-38, 38)
    ax.set_ylim(-24, max(32.0, float(pos[:, 1].max()) + 2.0))
    ax.set_aspect("equal")
    ax.set_title(title)
    ax.set_axis_off()


def main(argv: list[str] | None = None) -> dict[str, object]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--bodies", type=int, default=2000)
    parser.add_argument("--steps", type=int, default=1000)
    parser.add_argument("--check-every", type=int, default=10,
                        help="sweep every this many steps (0: never)")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--out", type=Path, default=Path("dem_hopper.png"),
                        help="figure of the final state ('-': none)")
    parser.add_argument("--gif", type=Path, default=None, help="also write an animation")
    args = parser.parse_args(argv)
    sim = Hopper(args.bodies, args.seed)
    t0 = time.perf_counter()
    got = sim.run(args.steps, args.check_every, frames=60 if args.gif else 0)
    seconds = time.perf_counter() - t0
    print(f"{args.bodies} bodies, {args.steps} steps of {sim.dt:.2e} in {seconds:.1f} s "
          f"({1e3 * seconds / max(args.steps, 1):.1f} ms per step); {got['pairs']} pairs in "
          "contact at the end")
    print(f"sweep checks: {got['checked']} steps, {got['met']} pairs penetrating within them, "
          f"{got['skipped']} of them in contact neither before nor after their step")
    if str(args.out) != "-" or args.gif:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(8, 8), layout="constrained")
        if str(args.out) != "-":
            draw(sim, sim.pos, sim.ang, ax, f"{args.bodies} concave bodies after "
                 f"{args.steps} steps ({args.steps * sim.dt:.2f} s)")
            fig.savefig(args.out, dpi=120)
        if args.gif:
            from matplotlib.animation import FuncAnimation, PillowWriter

            shots = got["snapshots"]
            anim = FuncAnimation(fig, lambda i: draw(sim, *shots[i], ax, f"frame {i}"),
                                 frames=len(shots))
            anim.save(args.gif, writer=PillowWriter(fps=15))
        plt.close(fig)
    return got


if __name__ == "__main__":
    main()
