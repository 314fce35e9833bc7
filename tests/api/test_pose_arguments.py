"""Every public call that takes a pose, a motion or a position refuses a value that is
not one: non-finite, complex, a string, a boolean, a set, or out of the range of
coordinates (±1e100). It raises ``TypeError`` or ``ValueError`` naming the argument;
it never returns a result built from such a value (a NaN shape that classifies as
separate at distance inf, a unit square turned by 1j into a shape of area 2.38, a
velocity "12" read as (1, 2)).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from profiles import examples

import polycontact as pc
from polycontact.esicup import turned

SQ = pc.Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
BIN = pc.Shape([(-5, -5), (5, -5), (5, 5), (-5, 5)])

#: Values that are not one real number within range.
BAD_NUMBERS = [math.nan, math.inf, -math.inf, 1j, complex(1, 0), np.complex128(2), "1", "0",
               b"1", True, False, np.bool_(True), [1.0], {1.0}, 1e200, -1e300,
               10**400]
#: Values that are not one point (x, y) within range.
BAD_POINTS = [(math.nan, 0), (0, math.inf), (1j, 0), (complex(1, 0), 0), ("1", "2"), "12",
              "1,2", (1, True), (True, False), np.array([True, False]), {1, 2}, {"x": 1},
              (1e200, 0), (0, -1e101), (10**400, 0), (1,), (1, 2, 3), np.array([1j, 0]),
              np.array(["1", "2"]), [(0, 0)], 3.0]

# finite floats beyond the range of coordinates: an angle may be one (it has no range)
OUT_OF_RANGE = {1e200, -1e300}


def _world() -> tuple[pc.World, int]:
    w = pc.World(BIN)
    return w, w.add(SQ, (0, 0))


def _pair_world() -> tuple[pc.World, np.ndarray]:
    """A World of two squares added as arrays (the simulation loop's calls)."""
    w = pc.World()
    return w, w.add_many([SQ, SQ], [(0, 0), (3, 0)])


def _moving(**motion):
    """time_of_impact of a square given this motion: a Motion refuses what is not a
    finite real number, the query a motion its products would overflow with."""
    pc.time_of_impact(SQ, pc.Motion(**motion), SQ.moved((3, 0)), pc.Motion(), t_max=5)


def _tmax(bad):
    pc.time_of_impact(SQ, pc.Motion(velocity=(1, 0)), SQ.moved((3, 0)), pc.Motion(), t_max=bad)


#: (argument name, call with one number argument set to ``bad``, whether the number has
#: a range (every value beyond ±1e100 refused) or may be any finite number)
NUMBER_CALLS = {
    "Shape.moved angle": ("angle", lambda bad: SQ.moved((0, 0), bad), False),
    "Shape.at t": ("t", lambda bad: SQ.at(pc.Motion(velocity=(1, 0)), bad), True),
    # (a motion beyond the range is refused by the query that would use it, naming it)
    "Motion angular_velocity": ("angular_velocity|motion_a", lambda bad: _moving(
        angular_velocity=bad), True),
    "Motion angular_acceleration": ("angular_acceleration|motion_a", lambda bad: _moving(
        angular_acceleration=bad), True),
    "Motion.pose t": ("t", lambda bad: pc.Motion(velocity=(1, 0)).pose(bad), True),
    "World.add angle": ("angle", lambda bad: _world()[0].add(SQ, (1, 1), bad), False),
    "World.move angle": ("angle", lambda bad: (lambda w, i: w.move(i, (0, 0), bad))(*_world()),
                         False),
    "World.add_many angles": ("angles", lambda bad: pc.World().add_many([SQ], [(0, 0)],
                                                                         [bad]), False),
    "World.set_poses angles": ("angles", lambda bad: (lambda w, ids: w.set_poses(
        ids, [(0, 0), (3, 0)], [bad, 0.0]))(*_pair_world()), False),
    "World.sweep dt": ("dt", lambda bad: _pair_world()[0].sweep(bad, [(1, 0), (0, 0)]), True),
    "World.sweep angular_velocities": ("angular_velocities", lambda bad: _pair_world()[0].sweep(
        0.1, [(1, 0), (0, 0)], [bad, 0.0]), True),
    "World.query angle": ("angle", lambda bad: _world()[0].query(SQ, (2, 2), bad), False),
    "World.query_many angles": ("angle", lambda bad: _world()[0].query_many(SQ, [(2, 2), (3, 3)],
                                                                          bad),
                                False),
    "World.feasible_region angle": ("angle", lambda bad: _world()[0].feasible_region(SQ, bad),
                                    False),
    "turned degrees": ("degrees", lambda bad: turned(SQ, bad), False),
    "nfp_table orientations": ("orientations", lambda bad: pc.nfp_table(
        [SQ], [[bad]], progress=False), False),
    "time_of_impact t_max": ("t_max", _tmax, True),
    "broad_phase_intervals t_max": ("t_max", lambda bad: pc.broad_phase_intervals(
        SQ, pc.Motion(velocity=(1, 0)), SQ.moved((3, 0)), pc.Motion(), t_max=bad), True),
    "first_impacts t_max": ("t_max", lambda bad: pc.first_impacts(
        [SQ, SQ.moved((3, 0))], [pc.Motion(velocity=(1, 0)), pc.Motion()], t_max=bad), True),
}

#: (argument name, call with one point argument set to ``bad``)
POINT_CALLS = {
    "Shape.moved translation": ("translation", lambda bad: SQ.moved(bad)),
    "Motion velocity": ("velocity|motion_a", lambda bad: _moving(velocity=bad)),
    "Motion acceleration": ("acceleration|motion_a", lambda bad: _moving(acceleration=bad)),
    "World.add position": ("position", lambda bad: _world()[0].add(SQ, bad)),
    "World.move position": ("position", lambda bad: (lambda w, i: w.move(i, bad))(*_world())),
    "World.query position": ("position", lambda bad: _world()[0].query(SQ, bad)),
    "World.add_many positions": ("positions", lambda bad: pc.World().add_many([SQ], [bad])),
    "World.set_poses positions": ("positions", lambda bad: (lambda w, ids: w.set_poses(
        ids, [bad, (3, 0)]))(*_pair_world())),
    "World.sweep velocities": ("velocities", lambda bad: _pair_world()[0].sweep(
        0.1, [bad, (0, 0)])),
    "World.sweep accelerations": ("accelerations", lambda bad: _pair_world()[0].sweep(
        0.1, [(1, 0), (0, 0)], accelerations=[bad, (0, 0)])),
    "World.query_many positions": ("positions", lambda bad: _world()[0].query_many(SQ, [bad])),
    "no_fit_polygon reference": ("reference", lambda bad: pc.no_fit_polygon(SQ, SQ, bad)),
    "inner_fit_polygon reference": ("reference", lambda bad: pc.inner_fit_polygon(SQ, BIN, bad)),
    "entrance_block reference": ("reference", lambda bad: pc.entrance_block(SQ, SQ, bad)),
    "NoFitPolygon.contains point": ("point",
                                    lambda bad: pc.no_fit_polygon(SQ, SQ).contains(bad)),
    "EntranceBlock.classify point": ("point",
                                     lambda bad: pc.entrance_block(SQ, SQ).classify(bad)),
    "EntranceBlock.components_at point": (
        "point", lambda bad: pc.entrance_block(SQ, SQ).components_at(bad)),
}

#: (argument name, call with one motion argument set to ``bad``)
MOTION_CALLS = {
    "time_of_impact motion_a": ("motion_a", lambda bad: pc.time_of_impact(
        SQ, bad, SQ.moved((3, 0)), pc.Motion(), t_max=5)),
    "broad_phase_intervals motion_b": ("motion_b", lambda bad: pc.broad_phase_intervals(
        SQ, pc.Motion(), SQ.moved((3, 0)), bad, t_max=5)),
    "time_of_impact_many motions_a": ("motions_a", lambda bad: pc.time_of_impact_many(
        [SQ], [bad], [SQ.moved((3, 0))], [pc.Motion()], t_max=5.0)),
    "first_impacts motions": ("motions", lambda bad: pc.first_impacts(
        [SQ, SQ.moved((3, 0))], [pc.Motion(), bad], t_max=5.0)),
    "World.add motion": ("motion", lambda bad: pc.World().add(SQ, motion=bad)),
    "Shape.at motion": ("motion", lambda bad: SQ.at(bad, 1.0)),
}


def _refused(call, bad, name: str) -> None:
    """``call(bad)`` raises TypeError or ValueError naming ``name`` (or one of the names
    it lists, separated by "|")."""
    with pytest.raises((TypeError, ValueError)) as got:
        call(bad)
    assert any(n in str(got.value) for n in name.split("|")), (name, bad, got.value)


@examples(300)
@given(st.sampled_from(sorted(NUMBER_CALLS)), st.sampled_from(BAD_NUMBERS))
def test_every_number_of_a_pose_or_motion_is_checked(which, bad):
    name, call, ranged = NUMBER_CALLS[which]
    if not ranged and isinstance(bad, float) and bad in OUT_OF_RANGE:
        call(bad)  # any finite angle is one (the sine and cosine are exact enough)
        return
    _refused(call, bad, name)


@examples(300)
@given(st.sampled_from(sorted(POINT_CALLS)), st.sampled_from(range(len(BAD_POINTS))))
def test_every_point_of_a_pose_or_position_is_checked(which, k):
    name, call = POINT_CALLS[which]
    _refused(call, BAD_POINTS[k], name)


@examples(100)
@given(st.sampled_from(sorted(MOTION_CALLS)),
       st.sampled_from([(1, 0), "velocity", 3.0, {"velocity": (1, 0)}]))
def test_every_motion_argument_is_a_motion(which, bad):
    name, call = MOTION_CALLS[which]
    _refused(call, bad, name)


def test_non_finite_and_complex_poses_are_refused():
    # the shapes these built: area NaN (classified separate at distance inf), area 2.38
    with pytest.raises(ValueError, match="translation"):
        SQ.moved((math.nan, 0))
    with pytest.raises(TypeError, match="angle"):
        SQ.moved((0, 0), 1j)
    with pytest.raises(ValueError, match="position"):
        pc.World().add(SQ, (math.nan, 0))


def test_lenient_values_are_refused_with_the_argument_named():
    for bad in ("12", {1, 2}, ("1", True)):
        with pytest.raises(TypeError, match="velocity"):
            pc.Motion(velocity=bad)
    with pytest.raises(TypeError, match="translation"):
        SQ.moved(("1", "2"))
    w, _ = _world()
    with pytest.raises(TypeError, match="positions"):
        w.query_many(SQ, [("1", "2")])
    with pytest.raises(TypeError, match="positions"):
        w.query_many(SQ, [(True, 0)])
    with pytest.raises(TypeError, match="positions"):
        w.query_many(SQ, np.array([(1 + 1j, 0)]))
    with pytest.raises(ValueError, match="positions"):
        w.query_many(SQ, [(1e200, 0)])
    with pytest.raises(TypeError, match="names"):
        pc.World().add_many([SQ, SQ.moved((3, 0))], names="ab")


def test_result_arrays_are_read_only():
    sq = [(0, 0), (1, 0), (1, 1), (0, 1)]
    r = pc.classify(sq, np.array(sq) + [0.5, 0.5])
    hit = pc.time_of_impact(SQ, pc.Motion(velocity=(1, 0)), SQ.moved((3, 0)), pc.Motion(),
                            t_max=5)
    nfp = pc.no_fit_polygon(SQ, pc.Shape([(0, 0), (3, 0), (3, 3), (2, 3), (2, 1), (1, 1),
                                          (1, 3), (0, 3)]), reference="origin")
    batch = pc.classify_many(np.stack([np.array(sq, float)] * 2),
                             np.stack([np.array(sq, float) + 0.5] * 2))
    impacts = pc.time_of_impact_many([SQ], [pc.Motion(velocity=(1, 0))], [SQ.moved((3, 0))],
                                     [pc.Motion()], t_max=5.0)
    w, i = _world()
    w.add(SQ, (0.5, 0))
    contacts = w.contacts()
    arrays = {"Relation.point": r.point, "Relation.normal": r.normal,
              "Relation.escape": r.escape, "Impact.point": hit.point,
              "Impact.normal": hit.normal, "NoFitPolygon.reference": nfp.reference,
              "NoFitPolygon.exact_fits": nfp.exact_fits, "NoFitPolygon.slides": nfp.slides,
              "RelationBatch.states": batch.states, "RelationBatch.distances": batch.distances,
              "ImpactBatch.times": impacts.times, "Contacts.pairs": contacts.pairs,
              "Contacts.states": contacts.states, "WorldBody.position": w.body(i).position,
              "Query.ids": w.query(SQ, (0, 0)).ids}
    before = r.to_dict()
    for name, arr in arrays.items():
        assert isinstance(arr, np.ndarray) and not arr.flags.writeable, name
        with pytest.raises(ValueError):
            arr[...] = 99
    assert r.to_dict() == before


def test_a_sweep_refusal_names_the_argument_that_carries_the_overflow():
    w, _ = _pair_world()
    with pytest.raises(ValueError, match=r"^angular_velocities\[0\]"):
        w.sweep(0.1, [(1, 0), (0, 0)], [1e200, 0.0])
    with pytest.raises(ValueError, match=r"^accelerations\[1\]"):
        w.sweep(0.1, [(1, 0), (0, 0)], accelerations=[(0, 0), (1e200, 0)])
    with pytest.raises(ValueError, match=r"^velocities\[0\]"):
        w.sweep(0.1, [(1e200, 0), (0, 0)])


def test_a_sweep_takes_motions_whose_bounds_hold_body_by_body():
    # one body far out, the other travelling far: together their largest terms pass
    # the limit, each body's own bound does not, so nothing is refused
    limit = pc.limits.COORDINATE_LIMIT
    w = pc.World()
    w.add_many([SQ, SQ], [(0.6 * limit, 0.0), (0.0, 0.0)])
    s = w.sweep(10.0, [(0.0, 0.0), (0.0, 0.06 * limit)])
    assert len(s) == 0
    with pytest.raises(ValueError, match=r"^velocities\[1\]"):
        w.sweep(10.0, [(0.0, 0.0), (0.0, 0.2 * limit)])


def test_booleans_among_real_numbers_are_refused():
    w, ids = _pair_world()
    with pytest.raises(TypeError, match="angles"):
        w.set_poses(ids, [(0, 0), (3, 0)], [True, 0.5])
    with pytest.raises(TypeError, match="positions"):
        w.set_poses(ids, [np.array([True, False]), (3, 0)])
    assert w.poses()[0].tolist() == [[0.0, 0.0], [3.0, 0.0]]


def test_ragged_angles_are_refused_with_their_name():
    w, ids = _pair_world()
    with pytest.raises(ValueError, match="angles"):
        w.set_poses(ids, [(0, 0), (3, 0)], [[1.0], 0.0])
