"""The sweep's proof that two moving bodies stay apart along the line of their centres,
against dense sampling of the motions measured by Shapely."""

from __future__ import annotations

import math

import numpy as np
import shapely
from hypothesis import given
from hypothesis import strategies as st
from profiles import examples

from polycontact._kernels.world_sweep import _axis_apart

SAMPLES = 801


def ring(radii: list[float], scale: float) -> np.ndarray:
    """A star-shaped polygon about the origin, vertex k at angle 2πk/n, radius radii[k]."""
    n = len(radii)
    t = 2.0 * math.pi * np.arange(n) / n
    return scale * np.c_[np.cos(t), np.sin(t)] * np.array(radii)[:, None]


def placed(r: np.ndarray, c: np.ndarray, m: np.ndarray, t: float) -> shapely.Polygon:
    th = m[4] * t + 0.5 * m[5] * t * t
    cs, sn = math.cos(th), math.sin(th)
    x = c[0] + m[0] * t + 0.5 * m[2] * t * t + cs * r[:, 0] - sn * r[:, 1]
    y = c[1] + m[1] * t + 0.5 * m[3] * t * t + sn * r[:, 0] + cs * r[:, 1]
    return shapely.Polygon(np.c_[x, y])


radii = st.lists(st.floats(0.3, 1.0), min_size=3, max_size=9)
motions = st.lists(st.floats(-1.0, 1.0), min_size=6, max_size=6)


@examples(200)
@given(radii, radii, motions, motions, st.floats(0.9, 1.3), st.floats(0.0, 2 * math.pi),
       st.sampled_from([1e-6, 1.0, 1e6]), st.sampled_from([0.0, 0.02]))
def test_bodies_proved_apart_along_their_centres_line_stay_apart(ra, rb, va, vb, f, phi,
                                                               scale, margin):
    """Wherever the check says two turning, translating, accelerating bodies stay more
    than ``margin`` apart over the step, no sample of the step brings them closer. The
    centres start ``f`` times the sum of the bodies' radii apart: near misses."""
    r1 = ring(ra, scale)
    r2 = ring(rb, scale)
    ca = np.array([3.0, -2.0]) * scale
    l1 = np.hypot(r1[:, 0], r1[:, 1])
    l2 = np.hypot(r2[:, 0], r2[:, 1])
    cb = ca + f * (l1.max() + l2.max()) * np.array([math.cos(phi), math.sin(phi)])
    ma = np.array(va) * np.array([0.2 * scale] * 4 + [2.0, 2.0])
    mb = np.array(vb) * np.array([0.2 * scale] * 4 + [2.0, 2.0])
    gap = margin * scale
    if not _axis_apart((r1, l1, ca, l1.max()), ma, (r2, l2, cb, l2.max()), mb, 1.0, gap):
        return
    for t in np.linspace(0.0, 1.0, SAMPLES):
        apart = placed(r1, ca, ma, t).distance(placed(r2, cb, mb, t))
        assert apart > gap * (1.0 - 1e-9), (t, apart, gap)


def test_the_check_proves_apart_what_stays_apart_and_no_more():
    """Two squares side by side, the second turning by a quarter of a turn: apart while
    the corner it brings round halfway stays short of the first, not once it reaches."""
    sq = np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]])
    lengths = np.full(4, math.sqrt(2.0))
    still = np.zeros(6)
    turn = np.array([0.0, 0.0, 0.0, 0.0, math.pi / 2.0, 0.0])
    reach = 1.0 + math.sqrt(2.0)
    for x, want in ((reach + 1e-9, True), (reach - 1e-9, False)):
        got = _axis_apart((sq, lengths, np.zeros(2), math.sqrt(2.0)), still,
                          (sq, lengths, np.array([x, 0.0]), math.sqrt(2.0)), turn, 1.0, 0.0)
        assert got == want
