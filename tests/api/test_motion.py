"""Motion: pose formula, Shape.at, validation."""

import dataclasses
import math

import numpy as np
import pytest

from polycontact import Motion, Shape


def test_pose_is_constant_acceleration_about_the_centroid():
    m = Motion(velocity=(1, 2), acceleration=(-2, 4), angular_velocity=0.5,
               angular_acceleration=-1.0)
    translation, angle = m.pose(3.0)
    assert translation.tolist() == [1 * 3 - 0.5 * 2 * 9, 2 * 3 + 0.5 * 4 * 9]
    assert angle == pytest.approx(0.5 * 3 - 0.5 * 9)


def test_shape_at_rotates_about_the_area_centroid():
    tri = Shape([(0, 0), (3, 0), (0, 3)])          # centroid (1, 1)
    placed = tri.at(Motion(angular_velocity=math.pi / 2), 1.0)
    assert np.allclose(placed.centroid, tri.centroid)
    # vertex (3, 0) is (2, -1) from the centroid; a quarter turn gives (1, 2)
    assert np.allclose(placed.exterior[1], [1 + 1, 1 + 2])


def test_zero_time_is_the_identity():
    sq = Shape([(0, 0), (2, 0), (2, 1), (0, 1)])
    m = Motion(velocity=(5, 5), acceleration=(1, 1), angular_velocity=3,
               angular_acceleration=2)
    assert np.allclose(sq.at(m, 0.0).exterior, sq.exterior)


def test_array_is_the_kernel_vector():
    m = Motion((1, 2), (3, 4), 5, 6)
    assert m.array.tolist() == [1, 2, 3, 4, 5, 6]
    assert m.array.dtype == np.float64


def test_cached_kernel_vector_cannot_go_stale():
    # the vector is built once per motion (time_of_impact passes it as it is): it is
    # read-only, and the motion cannot be rebound, so it always says what the fields say
    m = Motion((1, 2), (3, 4), 5, 6)
    assert m.array is m.array
    assert not m.array.flags.writeable
    with pytest.raises(ValueError):
        m.array[0] = 9.0
    assert m._norms == (math.hypot(1, 2), math.hypot(3, 4), 5.0, 6.0)
    assert Motion(angular_velocity=-2, angular_acceleration=-3)._norms == (0.0, 0.0, 2.0, 3.0)
    for name in ("velocity", "angular_velocity", "_array", "_norms"):
        with pytest.raises(AttributeError):
            setattr(m, name, getattr(m, name))
    moved = dataclasses.replace(m, velocity=(7, 8))
    assert moved.array.tolist() == [7, 8, 3, 4, 5, 6] and m.array.tolist()[:2] == [1, 2]
    assert moved._norms[0] == math.hypot(7, 8)
    assert m == Motion((1, 2), (3, 4), 5, 6) and hash(m) == hash(Motion((1, 2), (3, 4), 5, 6))


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"velocity": (1,)}, "velocity: expected two numbers"),
        ({"acceleration": (math.nan, 0)}, "acceleration: expected two finite"),
        ({"angular_velocity": math.inf}, "angular_velocity: expected a finite"),
    ],
)
def test_bad_motion(kwargs, message):
    with pytest.raises(ValueError, match=message):
        Motion(**kwargs)


@pytest.mark.parametrize(
    "kwargs, message",
    [
        ({"angular_acceleration": "x"}, "angular_acceleration: expected a real number, got str"),
        ({"velocity": "ab"}, "velocity: expected real numbers, got str"),
        ({"angular_velocity": True}, "angular_velocity: expected a real number, got bool"),
    ],
)
def test_motion_numbers_of_the_wrong_type(kwargs, message):
    with pytest.raises(TypeError, match=message):
        Motion(**kwargs)


def test_motion_is_frozen_and_normalised():
    m = Motion(velocity=[1, 2])
    assert m.velocity == (1.0, 2.0)
    with pytest.raises(AttributeError):
        m.velocity = (0, 0)
