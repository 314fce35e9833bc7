"""time_of_impact against an independent Shapely oracle and hand-solvable scenes.

The oracle places the bodies with its own rotation formula, asks Shapely whether the
interiors overlap (``relate_pattern(a, b, "2********")``) on a dense time grid, and
bisects the first penetrating sample against the one before it. It shares no code with
the library's kernels.
"""

from __future__ import annotations

import math
import pickle
from typing import Any

import numpy as np
import pytest
import shapely
from hypothesis import example, given
from hypothesis import strategies as st
from profiles import examples

import polycontact as pc
from polycontact import ImpactStatus, Motion, Shape, State, time_of_impact
from polycontact import impact as impact_module
from polycontact.broad_phase import intervals_array

TOL = 1e-4


# -- the oracle ---------------------------------------------------------------------
def _place(shape: Shape, motion: Motion, t: float) -> shapely.Polygon:
    c = shape.centroid
    vx, vy = motion.velocity
    ax, ay = motion.acceleration
    th = motion.angular_velocity * t + 0.5 * motion.angular_acceleration * t * t
    rot = np.array([[math.cos(th), -math.sin(th)], [math.sin(th), math.cos(th)]])
    shift = np.array([vx * t + 0.5 * ax * t * t, vy * t + 0.5 * ay * t * t])
    loops = [(loop - c) @ rot.T + c + shift for loop in shape.loops]
    return shapely.Polygon(loops[0], loops[1:])


def oracle_penetrates(a, ma, b, mb, t) -> bool:
    return bool(shapely.relate_pattern(_place(a, ma, t), _place(b, mb, t), "2********"))


def oracle_penetrates_beyond(a, ma, b, mb, t, depth) -> bool:
    """Whether the interiors overlap by more than a sliver ``depth`` thick: A shrunk by
    ``depth`` still overlaps B."""
    return bool(shapely.relate_pattern(_place(a, ma, t).buffer(-depth), _place(b, mb, t),
                                       "2********"))


def oracle_first_penetration(a, ma, b, mb, t0, t1, n, tol=1e-7, depth=0.0):
    """(t_prev, t_first) of the first penetrating sample of n in [t0, t1], bisected
    (penetrating by more than ``depth``, when given)."""
    def penetrates(t):
        return oracle_penetrates_beyond(a, ma, b, mb, t, depth) if depth > 0.0 \
            else oracle_penetrates(a, ma, b, mb, t)

    ts = np.linspace(t0, t1, n)
    prev = ts[0]
    for t in ts:
        if penetrates(t):
            lo, hi = prev, t
            while hi - lo > tol:
                mid = 0.5 * (lo + hi)
                if penetrates(mid):
                    hi = mid
                else:
                    lo = mid
            return hi
        prev = t
    return None


def check_against_oracle(a, ma, b, mb, t_max, n=1500):
    hit = time_of_impact(a, ma, b, mb, t_max=t_max, time_tolerance=TOL)
    assert hit.status in (ImpactStatus.HIT, ImpactStatus.NO_HIT)
    first = oracle_first_penetration(a, ma, b, mb, 0.0, t_max, n)
    if first is not None:
        # never later than a penetration the oracle sees
        assert hit.collides, f"missed the penetration at {first}"
        assert hit.time <= first + TOL
    if hit.collides:
        lo, hi = hit.time_bracket
        assert hi == hit.time and 0 <= hi - lo <= TOL
        assert oracle_penetrates(a, ma, b, mb, hit.time)
        # at the bracket's start the bodies may overlap within the distance tolerance
        # (1e-12 of their size, more for coordinates far from the origin), not beyond
        # ten times it
        size = max(max(np.ptp(loop, axis=0)) for s in (a, b) for loop in s.loops)
        far = max(abs(v) for s in (a, b) for loop in s.loops for v in loop.ravel())
        slack = 10.0 * max(1e-12 * size, 64 * 2.0**-52 * (far + 10.0 * size))
        assert not oracle_penetrates_beyond(a, ma, b, mb, lo, slack)
        # no oracle sample before the bracket penetrates beyond it either
        before = oracle_first_penetration(a, ma, b, mb, 0.0, lo, max(3, int(n * lo / t_max)),
                                          depth=slack)
        assert before is None
        assert hit.state is State.PENETRATING
        assert hit.first_contact is not None and hit.first_contact <= hit.time
    return hit, first


# -- random concave bodies (like the paper's: random radii at increasing angles) ----
def star_polygon(rng: np.random.Generator, n: int, scale: float) -> np.ndarray:
    # one vertex per sector of 360/n degrees, so no gap reaches 180° (a simple polygon)
    angles = (np.arange(n) + rng.uniform(0.05, 0.95, size=n)) * 2 * math.pi / n
    radii = rng.uniform(0.25, 1.0, size=n) * scale
    return np.column_stack([radii * np.cos(angles), radii * np.sin(angles)])


def random_motion(rng: np.random.Generator, toward: np.ndarray) -> Motion:
    return Motion(
        velocity=tuple(toward * rng.uniform(0.5, 1.5) + rng.normal(0, 0.3, 2)),
        acceleration=tuple(rng.normal(0, 0.3, 2)),
        angular_velocity=float(rng.normal(0, 2.0)),
        angular_acceleration=float(rng.normal(0, 1.0)),
    )


@examples(25)
@given(st.integers(0, 2**32 - 1))
@example(396)  # the bracket starts on a sliver of overlap within the distance tolerance
def test_random_concave_pairs_match_oracle(seed):
    rng = np.random.default_rng(seed)
    a = Shape(star_polygon(rng, int(rng.integers(5, 14)), 1.0))
    b = Shape(star_polygon(rng, int(rng.integers(5, 14)), 1.0)).moved((4.0, rng.normal(0, 0.8)))
    direction = np.array([1.0, 0.0])
    ma = random_motion(rng, direction)
    mb = random_motion(rng, -direction)
    check_against_oracle(a, ma, b, mb, t_max=3.0)


# -- hand-made scenes -------------------------------------------------------------------
SQ = Shape([(0, 0), (1, 0), (1, 1), (0, 1)])


def test_flush_approach_is_a_collision_when_edges_meet():
    # paper Fig. 17: two squares head-on, edges parallel
    b = SQ.moved((3, 0))
    for method in ("exact", "sampled"):
        hit = time_of_impact(SQ, Motion(velocity=(1, 0)), b, Motion(velocity=(-0.5, 0)),
                             t_max=5, method=method)
        assert hit.collides and hit.status is ImpactStatus.HIT
        assert abs(hit.time - 2 / 1.5) <= TOL
    assert np.allclose(hit.normal, [1, 0])


def test_exact_flush_features_are_the_touching_vertices():
    hit = time_of_impact(SQ, Motion(velocity=(1, 0)), SQ.moved((3, 0)), Motion(), t_max=5)
    touching = {(f.body, f.vertex) for f in hit.features}
    assert {("a", 1), ("a", 2), ("b", 0), ("b", 3)} <= touching
    assert np.allclose(hit.normal, [1, 0])
    assert hit.point[0] == pytest.approx(3.0)


def test_sliding_along_is_contact_not_collision():
    # paper Fig. 16: A's top edge slides along B's bottom edge
    b = SQ.moved((3, 1))
    hit = time_of_impact(SQ, Motion(velocity=(1, 0)), b, Motion(), t_max=2.1)
    assert not hit.collides and hit.time is None
    assert hit.status is ImpactStatus.NO_HIT
    assert hit.first_contact == pytest.approx(2.0, abs=TOL)
    assert hit.state is State.CONTACT
    assert hit.features and hit.normal is not None


def test_slide_then_hit_a_step():
    # A slides under B's overhang, then hits B's leg at x = 3.3. No line separates the
    # bodies (the leg reaches below A's top), but the touching pairs keep to their
    # edges' lines, so the slide takes a few steps, not probes
    b = Shape([(3.0, 1.0), (3.3, 1.0), (3.3, 0.0), (3.6, 0.0), (3.6, 2.0), (3.0, 2.0)])
    hit = time_of_impact(SQ, Motion(velocity=(1, 0)), b, Motion(), t_max=3)
    assert hit.first_contact == pytest.approx(2.0, abs=TOL)
    assert hit.collides and hit.time == pytest.approx(2.3, abs=TOL)
    assert ("a", 1) in {(f.body, f.vertex) for f in hit.features}
    assert hit.iterations < 50


def test_accelerating_slide_ends_with_a_verdict():
    # A slides along the floor towards B's leg, slowing down (acceleration along the
    # edge), and has not reached it by t_max: contact throughout, no collision. Only the
    # acceleration across the edge's line may end such a step, and there is none
    floor = Shape([(-3, -1), (2.3, -1), (2.3, 1.5), (2.0, 1.5), (2.0, 0), (-3, 0)])
    a = SQ.moved((-1.9, 0.0))
    ma = Motion(velocity=(1.05, 0.0), acceleration=(-0.1, 0.0))
    mb = Motion(velocity=(-0.01, 0.0))
    hit = time_of_impact(a, ma, floor, mb, t_max=2)
    assert hit.status is ImpactStatus.NO_HIT and hit.first_contact == 0.0
    assert hit.iterations < 100
    assert oracle_first_penetration(a, ma, floor, mb, 0, 2, 2001) is None


def test_contact_that_lasts_while_the_bodies_turn_runs_out_of_iterations_with_a_status():
    # a square spinning in a square hole it fits exactly, the holed body spinning a hair
    # faster about the same centre: touching throughout, turning apart by far less than
    # the tolerance, but the bounds see each body's own spin, so the touch is probed; a
    # small budget ends the search with a status, not a hang and not a guess
    sq = Shape([(-1, -1), (1, -1), (1, 1), (-1, 1)])
    b = Shape([(-3, -3), (3, -3), (3, 3), (-3, 3)], [[(-1, -1), (-1, 1), (1, 1), (1, -1)]])
    hit = time_of_impact(sq, Motion(angular_velocity=1.0), b,
                         Motion(angular_velocity=1.0 + 1e-13), t_max=5, max_iterations=1000)
    assert hit.status is ImpactStatus.OUT_OF_ITERATIONS
    assert not hit.collides and hit.first_contact == 0.0 and hit.searched_to < 5


def _disc_in_its_frame(n):
    t = 2.0 * np.pi * np.arange(n) / n
    disc = np.column_stack((np.cos(t), np.sin(t)))
    return Shape(disc), Shape([(-2, -2), (2, -2), (2, 2), (-2, 2)], [disc[::-1]])


@pytest.mark.parametrize("n", [64, 512])
def test_bodies_without_relative_motion_are_answered_from_the_start(n):
    # a disc spinning with its exact-fit frame at the same rate (about one centre) keeps
    # its pose in the frame's: the contact at t = 0 holds, however long the window
    disc, frame = _disc_in_its_frame(n)
    spin = Motion(velocity=(3.0, -1.0), acceleration=(0.5, 0.0), angular_velocity=20.0,
                  angular_acceleration=1.0)
    hit = time_of_impact(disc, spin, frame, spin, t_max=1000.0)
    assert hit.status is ImpactStatus.NO_HIT and not hit.collides
    assert hit.first_contact == 0.0 and hit.state is State.CONTACT and hit.iterations <= 2
    # a common translation keeps apart bodies apart, and overlapping ones overlapping
    drift = Motion(velocity=(1.0, 2.0), acceleration=(0.0, -3.0))
    apart = time_of_impact(disc, drift, disc.moved((5.0, 0.0)), drift, t_max=1000.0)
    assert apart.status is ImpactStatus.NO_HIT and apart.first_contact is None
    assert apart.iterations <= 2
    inside = time_of_impact(disc, spin, disc.moved((0.5, 0.0)), spin, t_max=1000.0)
    assert inside.status is ImpactStatus.PENETRATING_AT_START


def test_a_common_spin_about_two_centres_is_relative_motion():
    # equal motions but different centroids: in A's frame B circles A's centroid without
    # turning, so its corner meets A's near an eighth of a turn
    a = Shape([(-1, -1), (1, -1), (1, 1), (-1, 1)])
    spin = Motion(angular_velocity=1.0)
    hit = time_of_impact(a, spin, a.moved((2.5, 0.0)), spin, t_max=10.0)
    assert hit.collides and 0.0 < hit.time < np.pi / 4


def test_sampled_search_refuses_more_samples_per_round_than_its_budget():
    b = SQ.moved((3, 0))
    with pytest.raises(ValueError, match=r"samples: .*1000000000.* max_iterations = 1000000"):
        time_of_impact(SQ, Motion(velocity=(1, 0)), b, Motion(), t_max=5, method="sampled",
                       samples=10**9)
    # within the budget it answers; a search that spends it ends with a status
    hit = time_of_impact(SQ, Motion(velocity=(1, 0)), b, Motion(), t_max=5, method="sampled",
                         samples=1000)
    assert hit.status is ImpactStatus.HIT and abs(hit.time - 2.0) <= 0.01
    out = time_of_impact(SQ, Motion(velocity=(1, 0)), b, Motion(), t_max=5, method="sampled",
                         samples=100, max_iterations=100)
    assert out.status is ImpactStatus.OUT_OF_ITERATIONS and not out.collides
    assert out.iterations <= 101 and 0.0 < out.searched_to < 5.0


def _no_overlap(a, ma, b, mb, ts, area=0.0):
    return all(_place(a, ma, t).intersection(_place(b, mb, t)).area <= area for t in ts)


def test_long_slide_ends_with_a_verdict():
    # paper Fig. 16 over twenty body sizes: A slides under a long bar from t = 1 to 22
    # and leaves it. Contact, not collision, found in a few steps: a line through the
    # touching edges separates the bodies for the whole slide
    bar = Shape([(2, 1), (22, 1), (22, 1.5), (2, 1.5)])
    ma = Motion(velocity=(1, 0))
    hit = time_of_impact(SQ, ma, bar, Motion(), t_max=30)
    assert hit.status is ImpactStatus.NO_HIT and not hit.collides
    assert hit.first_contact == pytest.approx(1.0, abs=TOL)
    assert hit.state is State.CONTACT and hit.iterations < 100
    ts = np.linspace(0, 30, 3001)
    assert oracle_first_penetration(SQ, ma, bar, Motion(), 0, 30, 3001) is None
    assert shapely.distance(_place(SQ, ma, 10.0), _place(bar, Motion(), 10.0)) == 0.0
    assert _no_overlap(SQ, ma, bar, Motion(), ts)


def test_tilted_slide_along_a_moving_bar():
    # the same slide turned by 0.3 rad (no coordinate exact) with both bodies moving:
    # A at (1, 0.05), the bar at (0, 0.05) in the turned frame
    c, s = math.cos(0.3), math.sin(0.3)
    rot = np.array([[c, -s], [s, c]])
    a = Shape(SQ.exterior @ rot.T)
    bar = Shape(np.array([(2.0, 1), (22, 1), (22, 1.5), (2, 1.5)]) @ rot.T)
    ma = Motion(velocity=tuple(rot @ (1.0, 0.05)))
    mb = Motion(velocity=tuple(rot @ (0.0, 0.05)))
    hit = time_of_impact(a, ma, bar, mb, t_max=30)
    assert hit.status is ImpactStatus.NO_HIT and not hit.collides
    assert hit.first_contact == pytest.approx(1.0, abs=TOL) and hit.iterations < 1000
    # the oracle: touching during the slide, never overlapping beyond rounding
    assert shapely.distance(_place(a, ma, 10.0), _place(bar, mb, 10.0)) < 1e-9
    assert _no_overlap(a, ma, bar, mb, np.linspace(0, 30, 3001), area=1e-9)


def test_corner_graze_is_contact():
    # B's corner touches A's top edge while A passes underneath, rising then falling
    b = Shape([(2.5, 1.5), (3.0, 1.0), (3.5, 1.5)])
    ma = Motion(velocity=(1, 0.5), acceleration=(0, -1))   # y(t) = 0.5 t - t²/2, max at t=0.5
    # A's top edge starts at y = 0.875 and reaches y = 1 exactly at t = 0.5
    hit = time_of_impact(SQ.moved((2, -0.125)), ma, b, Motion(), t_max=1)
    assert not hit.collides and hit.status is ImpactStatus.NO_HIT
    # "touching" is within the contact resolution lam = 1e-6 (L_A + L_B): the gap
    # (t - 0.5)²/2 is below lam from t = 0.5 - sqrt(2 lam) on
    lam = pc.impact.CONTACT_RESOLUTION * (SQ.bounding_radius + b.bounding_radius)
    assert hit.first_contact == pytest.approx(0.5 - math.sqrt(2 * lam), abs=1e-4)


def test_start_inside_a_hole_collides_only_at_the_hole_boundary():
    ring = Shape([(-5, -5), (5, -5), (5, 5), (-5, 5)], [[(-3, -3), (3, -3), (3, 3), (-3, 3)]])
    small = Shape([(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)])
    hit = time_of_impact(small, Motion(velocity=(2, 0)), ring, Motion(), t_max=5)
    assert hit.collides and hit.time == pytest.approx(1.25, abs=TOL)
    assert {(f.body, f.other_loop) for f in hit.features} == {("a", 1)}
    check_against_oracle(small, Motion(velocity=(2, 0.3), angular_velocity=3.0), ring,
                         Motion(angular_velocity=-0.5), t_max=5)


def test_entering_a_concavity_is_not_a_hit_at_the_hull():
    c_shape = Shape([(0, 0), (4, 0), (4, 1), (1, 1), (1, 3), (4, 3), (4, 4), (0, 4)])
    peg = Shape([(6, 1.5), (7, 1.5), (7, 2.5), (6, 2.5)])
    hit = time_of_impact(peg, Motion(velocity=(-1, 0)), c_shape, Motion(), t_max=10)
    hull = time_of_impact(peg, Motion(velocity=(-1, 0)), c_shape.to_shapely().convex_hull,
                          Motion(), t_max=10)
    assert hull.time == pytest.approx(2.0, abs=TOL)
    assert hit.time == pytest.approx(5.0, abs=TOL)      # reaches the inner wall x = 1


def test_already_penetrating_is_reported_not_an_impact_at_zero():
    for method in ("exact", "sampled"):
        hit = time_of_impact(SQ, Motion(velocity=(1, 0)), SQ.moved((0.5, 0)), Motion(),
                             t_max=1, method=method)
        assert hit.status is ImpactStatus.PENETRATING_AT_START
        assert not hit.collides and hit.time is None and hit.state is State.PENETRATING


def test_touching_at_start_then_separating():
    hit = time_of_impact(SQ, Motion(velocity=(-1, 0)), SQ.moved((1, 0)), Motion(), t_max=1)
    assert not hit.collides and hit.first_contact == 0.0


def test_no_broad_phase_overlap_means_no_search():
    hit = time_of_impact(SQ, Motion(velocity=(0, 1)), SQ.moved((10, 0)), Motion(), t_max=1)
    assert hit.broad_phase == () and hit.status is ImpactStatus.NO_HIT
    assert hit.iterations == 0 and hit.first_contact is None and hit.state is None


# -- tunnelling: a thin bar spinning fast clips a small body for 3.7 ms -------------------
BAR = Shape([(-1, -0.01), (1, -0.01), (1, 0.01), (-1, 0.01)])
DOT = Shape([(-0.025, 0.945), (0.025, 0.945), (0.025, 0.995), (-0.025, 0.995)])


def test_spinning_bar_sampled_tunnels_exact_does_not():
    spin = Motion(angular_velocity=20.0)
    first = oracle_first_penetration(BAR, spin, DOT, Motion(), 0.0, 0.2, 4001)
    assert first is not None and 0.07 < first < 0.08
    # it is a clip: free again 5 ms later
    assert not oracle_penetrates(BAR, spin, DOT, Motion(), first + 0.005)
    sampled = time_of_impact(BAR, spin, DOT, Motion(), t_max=0.2, method="sampled")
    assert not sampled.collides
    exact = time_of_impact(BAR, spin, DOT, Motion(), t_max=0.2)
    assert exact.collides and abs(exact.time - first) <= TOL


def test_spinning_bar_many_turns_inside_the_interval():
    spin = Motion(angular_velocity=200.0)             # 32 turns per second
    dot = DOT.moved((0, 0.25))
    come = Motion(velocity=(0, -0.02))
    # the dot's nearest point is beyond the bar's reach (1.00005) until t = 9.75
    first = oracle_first_penetration(BAR, spin, dot, come, 9.7, 9.9, 20001)
    assert first is not None
    exact = time_of_impact(BAR, spin, dot, come, t_max=10)
    (start, end), = exact.broad_phase
    assert 200.0 * (first - start) / (2 * math.pi) > 10     # turns inside the interval
    assert exact.collides and 9.7 < exact.time <= first + TOL
    assert oracle_penetrates(BAR, spin, dot, come, exact.time)
    assert not oracle_penetrates(BAR, spin, dot, come, exact.time_bracket[0])


# -- the paper's cases ---------------------------------------------------------------------
@pytest.mark.parametrize("case", [1, 2])
def test_paper_cases_match_oracle(case):
    scene = pc.load_scene(f"examples/paper-case-{case}.json", repair=True)
    a, b = scene.bodies
    hit, first = check_against_oracle(a.shape, a.motion, b.shape, b.motion, scene.t_max,
                                      n=4000)
    assert first is not None


@pytest.mark.parametrize("case, touching", [(1, ("b", 2, 0)), (2, ("a", 17, 30))])
def test_paper_case_features_are_read_where_the_bodies_touch(case, touching):
    """The search brackets the hit only to the tolerance (here 1e-4 s, during which the
    bodies move by up to 0.07 m); the features come from the bracket narrowed to the
    contact resolution, so they name only the vertex that touches; Shapely finds it on
    that edge, moved in by less than the bracket allows, at the bracket's end."""
    scene = pc.load_scene(f"examples/paper-case-{case}.json", repair=True)
    a, b = scene.bodies
    hit = time_of_impact(a.shape, a.motion, b.shape, b.motion, t_max=scene.t_max)
    assert [(f.body, f.vertex, f.edge) for f in hit.features] == [touching]
    lo, hi = hit.time_bracket
    assert hi - lo <= TOL
    body, vertex, edge = touching
    pv, pe = (a, b) if body == "a" else (b, a)
    moved = pv.shape.at(pv.motion, hi)
    other = pe.shape.at(pe.motion, hi)
    ring = other.exterior
    # the features are in the file's numbering: find the stored rows
    vertex = [moved.input_vertex(0, i) for i in range(len(moved.exterior))].index(vertex)
    edge = [other.input_edge(0, i) for i in range(len(ring))].index(edge)
    seg = shapely.LineString([ring[edge], ring[(edge + 1) % len(ring)]])
    assert shapely.distance(shapely.Point(moved.exterior[vertex]), seg) < 0.07
    assert shapely.contains(shapely.Polygon(ring), shapely.Point(moved.exterior[vertex]))


def test_features_name_the_first_tooth_not_one_a_tolerance_later():
    """Two teeth land 5e-5 s apart, inside the 1e-4 s bracket the search stops with: the
    features come from the bracket narrowed to the contact resolution, so only the
    first tooth is named (read over the coarse bracket, both would be)."""
    comb = Shape([(0, 1), (0, 0), (0.2, 0.5), (1, 0.5), (1.2, 5e-5), (1.4, 1)])
    floor = Shape([(-1, -2), (3, -2), (3, -1), (-1, -1)])
    hit = time_of_impact(comb, Motion(velocity=(0, -1)), floor, Motion(), t_max=3)
    assert hit.time == pytest.approx(1.0, abs=TOL)
    assert [(f.body, f.vertex, f.edge) for f in hit.features] == [("a", 1, 2)]


def test_paper_case_1_sampled_misses_the_first_penetration():
    scene = pc.load_scene("examples/paper-case-1.json")
    a, b = scene.bodies
    exact = time_of_impact(a.shape, a.motion, b.shape, b.motion, t_max=scene.t_max)
    sampled = time_of_impact(a.shape, a.motion, b.shape, b.motion, t_max=scene.t_max,
                             method="sampled")
    assert exact.time == pytest.approx(7.98475, abs=TOL)
    # the paper's answer, 9.6965 s, is the start of a second penetration
    assert sampled.time == pytest.approx(9.6965, abs=TOL)
    assert oracle_penetrates(a.shape, a.motion, b.shape, b.motion, 8.05)
    assert not oracle_penetrates(a.shape, a.motion, b.shape, b.motion, 9.0)
    assert ("a", 2) in {(f.body, f.vertex) for f in sampled.features}   # red vertex 3


# -- arguments ---------------------------------------------------------------------------
@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"method": "fast"}, "method: expected one of exact, sampled"),
        ({"samples": 1}, "samples"),
        ({"time_tolerance": 0}, "time_tolerance"),
        ({"time_tolerance": float("nan")}, "time_tolerance"),
        ({"t_max": -1}, "t_max"),
        ({"max_iterations": 0}, "max_iterations"),
    ],
)
def test_bad_arguments(kwargs, message):
    args = {"t_max": 1.0, **kwargs}
    with pytest.raises(ValueError, match=message):
        time_of_impact(SQ, Motion(), SQ.moved((3, 0)), Motion(), **args)


def test_motion_must_be_a_motion():
    with pytest.raises(TypeError, match="motion_b"):
        time_of_impact(SQ, Motion(), SQ, (1, 0), t_max=1)


def test_impact_result_sets_every_field():
    # time_of_impact builds its Impact field by field (not through __init__, for speed):
    # every dataclass field must be there, for every status and both methods, and the
    # fast path (Shapes and Motions: compiled code called directly) must agree with
    # the dispatcher's (a Shape subclass)
    import dataclasses

    class Sub(Shape):
        __slots__ = ()

    sq = Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
    sub = Sub.__new__(Sub)
    sub._set([np.array(sq.exterior) + [3.0, 0.0]], ())
    sub._input = sq._input
    fields = {f.name for f in dataclasses.fields(pc.Impact)}
    for b, mb, t_max in ((sq.moved((3, 0)), Motion(), 5.0), (sq.moved((3, 0)), Motion(), 1.0),
                         (sq.moved((0.5, 0)), Motion(), 1.0), (sub, Motion(), 5.0)):
        for method in ("exact", "sampled"):
            for _ in range(2):
                hit = time_of_impact(sq, Motion(velocity=(1, 0)), b, mb, t_max=t_max,
                                     method=method)
                # set at once; the others filled in together on first access
                eager = {"collides", "time", "status"}
                assert eager <= set(vars(hit)), eager - set(vars(hit))
                assert fields - eager - {"_bodies"} == set(impact_module._LAZY)
                # (pickled before the lazy fields are read; a local class cannot be)
                copy = hit if b is sub else pickle.loads(pickle.dumps(hit))
                hit.method  # (one lazy field read fills in all of them)
                assert fields <= set(vars(hit)), fields - set(vars(hit))
                built = pc.Impact(**{f: getattr(hit, f) for f in fields})
                assert hit == built == copy
                assert hit.broad_phase == tuple(map(tuple, intervals_array(
                    sq, Motion(velocity=(1, 0)), b, mb, t_max).tolist()))
                t = hit.time if hit.time is not None else hit.searched_to
                assert hit.time_tolerance == max(1e-4, 4 * 2.0**-52 * abs(t))
            if b is sub:
                ref = time_of_impact(sq, Motion(velocity=(1, 0)), sq.moved((3, 0)), mb,
                                     t_max=t_max, method=method)
                assert (hit.time, hit.status, hit.iterations) == (
                    ref.time, ref.status, ref.iterations)


@examples(150)
@given(st.sampled_from([1e-9, 1.0, 1e14, 1e15, 2e15, 1e30]),
       st.lists(st.sampled_from([0.0, 1.0, 1e14, 1e15, 1.0000001e15, 1e20, 1e40, 1e60, 2e100]),
                min_size=4, max_size=4),
       st.sampled_from([0.0, 1.0, 1e15, 1.5e15, 1e30, 1e50]), st.booleans())
def test_time_of_impact_refuses_exactly_the_motions_that_check_reach_refuses(
        size, norms, t_max, second):
    # time_of_impact skips the reach check when every input is below a bound that
    # keeps the products far from overflow (_SAFE_SCALE): it must still refuse every
    # motion check_reach refuses, naming it, and accept the others
    from polycontact.broad_phase import check_reach

    v, acc, w, alpha = norms
    moving = Motion(velocity=(v, 0.0), acceleration=(0.0, acc), angular_velocity=w,
                    angular_acceleration=alpha)
    a = Shape(np.array([(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]) * size)
    b = a.moved((-3.0 * size, 0.0))
    ma, mb = (Motion(), moving) if second else (moving, Motion())
    name = "motion_b" if second else "motion_a"
    try:
        check_reach(b if second else a, moving, t_max, name)
    except ValueError as err:
        with pytest.raises(ValueError, match=f"^{name}: ") as got:
            time_of_impact(a, ma, b, mb, t_max=t_max, max_iterations=20)
        assert str(got.value) == str(err)
    else:
        time_of_impact(a, ma, b, mb, t_max=t_max, max_iterations=20)


def test_queries_reuse_one_scratch_per_thread_without_carrying_anything_over():
    # time_of_impact hands the kernel this thread's scratch buffer (grown for larger
    # bodies): a query's answer must not depend on the queries before it, and threads
    # must not share a buffer. Reference: each query alone in a fresh thread.
    import threading

    rng = np.random.default_rng(7)

    def star(n: int) -> Shape:
        t = np.sort(rng.uniform(0, 2 * np.pi, n))
        r = rng.uniform(0.5, 1.0, n)
        return Shape(np.c_[r * np.cos(t), r * np.sin(t)])

    cases = []
    for n in (3, 8, 40, 200, 5, 700, 12):  # the buffer grows twice on the way
        a, b = star(n), star(max(3, n // 2)).moved((2.5, 0.3))
        cases.append((a, Motion(velocity=(1.5, 0.0), angular_velocity=2.0), b,
                      Motion(angular_velocity=-1.0)))

    def answer(case: tuple[Any, ...], method: str) -> tuple[Any, ...]:
        hit = time_of_impact(*case, t_max=2.0, method=method)
        return hit.status, hit.time, hit.first_contact, hit.iterations, hit.broad_phase

    def fresh(case: tuple[Any, ...], method: str) -> tuple[Any, ...]:
        out: list[Any] = []
        worker = threading.Thread(target=lambda: out.append(answer(case, method)))
        worker.start()
        worker.join()
        return out[0]

    for method in ("exact", "sampled"):
        alone = [fresh(c, method) for c in cases]
        assert [answer(c, method) for c in cases] == alone
        got: dict[int, list[Any]] = {}

        def run(k: int) -> None:
            got[k] = [answer(c, method) for c in cases[k:] + cases[:k]]

        threads = [threading.Thread(target=run, args=(k,)) for k in range(4)]
        for th in threads:
            th.start()
        for th in threads:
            th.join()
        for k in range(4):
            assert got[k] == alone[k:] + alone[:k]


def test_a_query_kernel_refuses_a_scratch_buffer_too_short_for_its_bodies():
    # the kernels take every buffer from one scratch array and never write past it
    from polycontact._kernels import impact as ki
    from polycontact.impact import body_frame

    sq = Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
    (r, tab, *_) = body_frame(sq)
    m = np.zeros(6)
    body = (r, sq.packed[1], sq.centroid, 1.0)
    args = (body, tab, m, body, tab, m, (1.0, 1e-6, 1e-4, 1e-12, 1e-14, 0.01, 100, 10))
    need = ki.work_floats(8)
    assert ki.exact_query(*args, np.empty(need))[1] == ki.INITIALLY_PENETRATING
    with pytest.raises(ValueError, match="scratch buffer is too short"):
        ki.exact_query(*args, np.empty(need - 1))


def test_the_body_frame_cached_on_a_shape_is_read_only():
    # time_of_impact keeps each shape's body frame (vertices about the centroid, circle
    # tree, the packed arrays the exact kernel takes) on the shape: none of it may be
    # changed afterwards, or later queries would read a stale body
    from polycontact.impact import body_frame

    s = Shape([(0, 0), (2, 0), (2, 2), (0, 2)], [[(0.5, 0.5), (1, 0.5), (1, 1)]])
    time_of_impact(s, Motion(velocity=(1, 0)), s.moved((5, 0)), Motion(), t_max=1.0)
    r, tables, _, packed = body_frame(s)
    assert s._frame is not None and s._frame[3] is packed
    for arr in (r, *tables, *packed):
        assert not arr.flags.writeable
        with pytest.raises(ValueError):
            arr[0] = 0
