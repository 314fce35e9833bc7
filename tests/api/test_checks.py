"""Argument checks: the fast path for plain floats says what the general path says."""

from __future__ import annotations

import math

import numpy as np
import pytest

from polycontact._checks import finite_number


@pytest.mark.parametrize("value", [0.0, -0.0, 1e-300, -5.0, 3.5, 1e308, math.inf, -math.inf,
                                   math.nan, 5e-324])
@pytest.mark.parametrize("bounds", [{}, {"minimum": 0.0}, {"positive": True},
                                    {"minimum": -1.0, "positive": True}])
def test_float_fast_path_matches_the_general_path(value, bounds):
    # np.float64 takes the general path (type is not float): both must agree
    def outcome(v):
        try:
            return ("ok", finite_number(v, "x", **bounds))
        except ValueError as exc:
            return ("error", str(exc))

    fast, general = outcome(value), outcome(np.float64(value))
    assert fast[0] == general[0]
    if fast[0] == "ok":
        assert type(fast[1]) is float and math.copysign(1, fast[1]) == math.copysign(1, value)
        assert fast[1] == value
    else:
        assert fast[1] == general[1]
