"""The threading policy, and every parallel path giving the same answer, entry by entry,
on one thread and on two (chunks made even for small inputs: no work is too small to
share here)."""

from __future__ import annotations

import math
import os
import subprocess
import sys

import numba
import numpy as np
import pytest
import shapely

import polycontact as pc
from polycontact import _threads
from polycontact import world as world_module
from polycontact._kernels import world as kw

SQ = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])


def stars(rng: np.random.Generator, count: int, n: int = 12) -> np.ndarray:
    """``count`` concave n-gons (stars of radii 0.62 and 0.38, each turned and scaled at
    random) about the points of a grid of unit spacing: each meets a few neighbours."""
    spikes = np.where(np.arange(n) % 2 == 0, 0.62, 0.38) * np.exp(
        2j * np.pi * np.arange(n) / n)
    turns = np.exp(2j * np.pi * rng.uniform(0, 1, (count, 1))) * rng.uniform(0.9, 1.1,
                                                                               (count, 1))
    side = math.isqrt(count - 1) + 1
    centres = (np.arange(count) % side + 1j * (np.arange(count) // side))[:, None]
    z = centres + rng.uniform(-0.1, 0.1, (count, 1)) + spikes[None, :] * turns
    return np.ascontiguousarray(np.stack([z.real, z.imag], axis=2))


@pytest.fixture
def share_everything(monkeypatch):
    """Any work is worth a thread: two threads really run two (when Numba has them)."""
    monkeypatch.setattr(_threads, "THREAD_WORK", 1e-12)
    before = numba.get_num_threads()
    yield
    numba.set_num_threads(before)


def on(threads: int, fn):
    """``fn()`` with Numba's threads set to ``threads`` (at most what Numba has)."""
    numba.set_num_threads(min(threads, numba.config.NUMBA_NUM_THREADS))
    return fn()


def same(x, y) -> bool:
    return x.shape == y.shape and np.array_equal(x, y, equal_nan=x.dtype.kind == "f")


# -- the policy ----------------------------------------------------------------------------
def test_requested_threads_follow_numba_and_the_argument():
    before = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        assert _threads.requested(None) == 1
        assert _threads.requested(3) == 3
    finally:
        numba.set_num_threads(before)


@pytest.mark.parametrize("bad", [0, -1, True, 1.5, "2"])
def test_threads_must_be_a_positive_integer(bad):
    with pytest.raises(ValueError, match="threads: expected an integer >= 1 or None"):
        pc.classify_many(np.stack([SQ]), np.stack([SQ + 2]), threads=bad)
    with pytest.raises(ValueError, match="threads"):
        pc.nfp_table([SQ], progress=False, threads=bad)


def test_small_work_starts_no_thread(monkeypatch):
    def refuse(size):
        raise AssertionError("a thread was started for a few pairs")

    monkeypatch.setattr(_threads._POOL, "executor", refuse)
    batch = pc.classify_many(np.stack([SQ] * 10), np.stack([SQ + 0.5] * 10), threads=8)
    assert batch.states.tolist() == [2] * 10


def test_one_numba_thread_means_one_thread(monkeypatch, share_everything):
    def refuse(size):
        raise AssertionError("a thread was started though Numba has one")

    monkeypatch.setattr(_threads._POOL, "executor", refuse)
    rng = np.random.default_rng(0)
    a = stars(rng, 300)
    on(1, lambda: pc.classify_many(a, a + 0.3))
    on(1, lambda: pc.nfp_table([SQ, SQ * 2], [0, 90], progress=False))


def test_map_chunks_keeps_the_order_and_raises_the_error(share_everything):
    assert _threads.map_chunks(lambda p0, p1: (p0, p1), 10, 3, chunks=4) == [
        (0, 2), (2, 5), (5, 7), (7, 10)]

    def fail(p0, p1):
        if p0:
            raise RuntimeError("chunk failed")
        return p1

    with pytest.raises(RuntimeError, match="chunk failed"):
        _threads.map_chunks(fail, 10, 2, chunks=4)
    done = dict(_threads.as_done(lambda t: t * t, [1, 2, 3, 4], 2))
    assert done == {0: 1, 1: 4, 2: 9, 3: 16}


# -- the World -----------------------------------------------------------------------------
def test_contacts_on_two_threads_equal_one_thread(share_everything):
    rng = np.random.default_rng(1)
    world = pc.World(container=pc.Shape([(-2, -2), (30, -2), (30, 30), (-2, 30)]))
    world.add_many(stars(rng, 600))
    for margin in (0.0, 0.05):
        one = on(1, lambda: world.contacts(margin=margin))
        two = on(2, lambda: world.contacts(margin=margin))
        assert len(one) > 500
        for name in ("pairs", "states", "container_ids", "container_states", "distances",
                     "normals", "points"):
            assert same(getattr(one, name), getattr(two, name)), name


def test_contacts_of_chunks_that_find_more_pairs_than_their_buffer(monkeypatch):
    # 40 squares in one place: the first bodies find almost every other one, far more
    # than the four pairs per body a chunk's buffer holds
    world = pc.World()
    world.add_many(np.stack([SQ + 0.001 * k for k in range(40)]))
    one = world.contacts()
    monkeypatch.setattr(world_module, "_chunks", lambda count, work=1.0: 3)
    many = world.contacts()
    assert len(one) == 40 * 39 // 2
    assert same(one.pairs, many.pairs) and same(one.states, many.states)


@pytest.mark.parametrize("n, chunks", [(0, 2), (5, 2), (64, 2), (1000, 3), (100_003, 64)])
def test_parallel_blocks_cover_every_item_once_and_interleave_the_chunks(n, chunks):
    from polycontact._kernels.spread import SPREAD, block

    spans = [block(n, chunks, b) for b in range(SPREAD * chunks)]
    assert spans[0][0] == 0 and spans[-1][1] == n
    assert all(spans[b][1] == spans[b + 1][0] for b in range(len(spans) - 1))
    owners = [b % chunks for b in range(SPREAD * chunks)]  # chunk c: blocks c, c + chunks, ...
    assert owners[:chunks] == list(range(chunks)) and owners[-chunks:] == list(range(chunks))


def test_a_crowd_in_the_first_bodies_is_shared_among_the_chunks():
    # the first half of the bodies meet their neighbours, the second half stand apart:
    # each of two chunks (so each thread) gets a share of the crowd's pairs
    rng = np.random.default_rng(3)
    rings = stars(rng, 400)
    centres = rings[200:].mean(axis=1, keepdims=True)
    rings[200:] += 2.0 * centres + 1000.0
    world = pc.World()
    world.add_many(rings)
    alive = world._alive()
    settings = (-1.0, float(world._eps[alive].max()), 0.0, world._next, kw.TOUCHING)
    cap = 8 * len(alive)
    counts = []
    for c in range(2):
        out = (np.empty(cap, np.int64), np.empty(cap, np.int64), np.empty(cap, np.int8),
               np.empty(cap))
        counts.append(kw._chunk_pairs(world._grid(), world._bodies(), (world._pos, world._rad),
                                      settings, alive, c, 2, out, cap, world._vmax,
                                      world._lmax))
    total = len(world.contacts())
    assert total > 200 and sum(counts) == total
    assert min(counts) > 0.3 * total


def test_sorted_pairs_in_buckets_equal_one_sort():
    rng = np.random.default_rng(2)
    n_ids = 1000
    keys = rng.choice(n_ids * n_ids, 5000, replace=False)
    pi, pj = keys // n_ids, keys % n_ids
    states = rng.integers(0, 3, 5000).astype(np.int8)
    used = rng.uniform(0, 1, 5000)
    order = np.lexsort((pj, pi))
    for chunks in (1, 3, 8):
        pairs, st, us = kw.sorted_pairs(pi, pj, states, used, n_ids, chunks)
        assert pairs.tolist() == np.c_[pi, pj][order].tolist()
        assert same(st, states[order]) and same(us, used[order])


def test_set_poses_on_two_threads_equal_one_thread(share_everything):
    rng = np.random.default_rng(3)
    rings = stars(rng, 500)
    worlds = []
    for threads in (1, 2):
        w = pc.World()
        ids = w.add_many(rings)
        pos, ang = w.poses()
        moved = pos + rng.uniform(-0.6, 0.6, pos.shape) * 0 + 0.37  # half leave their cell
        on(threads, lambda: w.set_poses(ids, moved, ang + 0.3))
        on(threads, lambda: w.set_poses(ids[::3], moved[::3] - 0.1))
        worlds.append(w)
    one, two = worlds
    for name in ("_xy", "_box", "_eps", "_pos", "_ang", "_slot", "_level"):
        assert same(getattr(one, name), getattr(two, name)), name
    assert same(on(1, one.contacts).pairs, on(2, two.contacts).pairs)


def test_sweep_and_its_points_on_two_threads_equal_one_thread(share_everything):
    rng = np.random.default_rng(5)
    world = pc.World()
    world.add_many(stars(rng, 400))
    vel = rng.normal(0.0, 12.0, (400, 2))
    spin = rng.uniform(-20.0, 20.0, 400)
    one = on(1, lambda: world.sweep(0.01, vel, spin))
    two = on(2, lambda: world.sweep(0.01, vel, spin))
    assert len(one) > 300 and np.any(one.times > 0.0)
    for name in ("pairs", "times", "states"):
        assert same(getattr(one, name), getattr(two, name)), name
    points = [on(t, lambda s=s: (s.points, s.normals)) for t, s in ((1, one), (2, two))]
    assert same(points[0][0], points[1][0]) and same(points[0][1], points[1][1])


def test_query_many_on_two_threads_equals_one_thread(share_everything):
    rng = np.random.default_rng(6)
    world = pc.World(container=pc.Shape([(-2, -2), (22, -2), (22, 22), (-2, 22)]))
    world.add_many(stars(rng, 300))
    poses = rng.uniform(-3.0, 23.0, (2000, 2))
    angles = rng.uniform(0.0, 6.3, 2000)
    star = stars(rng, 1)[0]
    one = on(1, lambda: world.query_many(star, poses, angles))
    two = on(2, lambda: world.query_many(star, poses, angles))
    assert {0, 2} <= set(one.tolist())  # free places and blocked ones
    assert same(one, two)


GRID = ("_keys", "_heads", "_nxt", "_prv", "_slot", "_level", "_lvl_count")


def regrid_one_by_one(left, grid, box, origin, filled):
    """Each body of ``left`` taken out of its cell and put in the cell of its box, in
    turn, stopping before the table would be more than half full: (cells made, bodies
    done)."""
    keys, heads, nxt, prv, slot, level, lvl_count = grid
    made = 0
    for k, b in enumerate(left.tolist()):
        if filled + made + 1 > len(keys) // 2:
            return made, k
        kw.grid_remove(heads, nxt, prv, slot, level, lvl_count, b)
        made += kw.grid_insert(keys, heads, nxt, prv, slot, level, lvl_count, box, origin, b)
    return made, len(left)


def test_regrid_in_chunks_equals_moving_each_body_in_turn():
    """The grid after the bodies that left their cells are moved in parallel chunks: the
    same table, cell lists (in the same order), slots, levels and level counts as moving
    them one by one; and the same stop when the table would be more than half full."""
    rng = np.random.default_rng(8)
    w = pc.World()
    ids = w.add_many(stars(rng, 400))
    box = w._box.copy()
    box[ids[::2]] += 0.37  # half move, many leaving their cell
    grown = ids[1::7]  # some grow: another level
    box[grown, 1] += 3.0
    box[grown, 3] += 3.0
    left = np.array([b for b in ids.tolist()
                     if w._keys[w._slot[b]] != kw.cell_key(box, b, w._origin)[1]])
    assert 50 < len(left) < 400
    for filled in (w._filled, len(w._keys) // 2 - 3):
        want_grid = [getattr(w, name).copy() for name in GRID]
        want = regrid_one_by_one(left, want_grid, box, w._origin, filled)
        for chunks in (1, 3, 8):
            grid = [getattr(w, name).copy() for name in GRID]
            got = kw.regrid(left, *grid, box, w._origin, filled, chunks)
            assert tuple(int(x) for x in got) == want
            if want[1] == len(left):  # (a stop leaves the table to be rebuilt)
                for name, x, y in zip(GRID, want_grid, grid):
                    assert same(x, y), name
    assert want[1] < len(left)


def test_set_poses_in_parallel_chunks_refuses_an_id_listed_twice(share_everything):
    w = pc.World()
    ids = w.add_many(np.stack([SQ + 2 * k for k in range(200)]))
    pos, _ = w.poses()
    twice = ids.copy()
    twice[150] = twice[20]
    for threads in (1, 2):
        with pytest.raises(ValueError, match=r"ids\[150\]: body 20 is listed twice"):
            on(threads, lambda: w.set_poses(twice, pos))
    with pytest.raises(KeyError, match=r"ids\[3\]: no body 999"):
        on(2, lambda: w.set_poses(np.r_[ids[:3], 999], pos[:4]))
    far = pos.copy()
    far[7] = 2e100
    with pytest.raises(ValueError, match=r"positions\[7\]: 2e\+100 is beyond"):
        on(2, lambda: w.set_poses(ids, far))
    with pytest.raises(ValueError, match=r"angles\[9\]: expected a finite number"):
        on(2, lambda: w.set_poses(ids, pos, np.r_[np.zeros(9), np.nan, np.zeros(190)]))
    assert same(w.poses()[0], pos)  # nothing was moved by the refused calls


# -- batches -------------------------------------------------------------------------------
def test_classify_many_on_two_threads_equals_one_thread(share_everything):
    rng = np.random.default_rng(4)
    a = stars(rng, 3000)
    b = a + rng.uniform(-0.8, 0.8, (3000, 1, 2))
    for args in ((a, b), ([pc.Shape(x) for x in a[:500]], list(b[:500]))):
        one = on(1, lambda: pc.classify_many(*args, threads=1))
        two = on(2, lambda: pc.classify_many(*args, threads=2))
        assert same(one.states, two.states) and same(one.tolerances, two.tolerances)
        assert same(on(1, lambda: one.distances), on(2, lambda: two.distances))


def test_time_of_impact_many_on_two_threads_equals_one_thread(share_everything):
    rng = np.random.default_rng(5)
    ell = pc.Shape([(0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)])
    frame = pc.Shape([(0, 0), (6, 0), (6, 6), (0, 6)], [[(2, 2), (4, 2), (4, 4), (2, 4)]])
    a = [ell.moved(rng.uniform(-3, 3, 2), rng.uniform(0, 6)) for _ in range(400)]
    b = [frame if k % 3 == 0 else ell for k in range(400)]
    ma = [pc.Motion(velocity=rng.uniform(-2, 2, 2), angular_velocity=rng.uniform(-1, 1))
          for _ in a]
    mb = [pc.Motion()] * 400
    one = on(1, lambda: pc.time_of_impact_many(a, ma, b, mb, t_max=3, threads=1))
    two = on(2, lambda: pc.time_of_impact_many(a, ma, b, mb, t_max=3, threads=2))
    for name in ("statuses", "times", "first_contacts"):
        assert same(getattr(one, name), getattr(two, name)), name
    assert np.count_nonzero(one.collides) > 50
    single = pc.time_of_impact(a[7], ma[7], b[7], mb[7], t_max=3)
    assert one.impact(7).status is single.status


def test_time_of_impact_many_of_ring_arrays_on_two_threads_equals_one_thread(share_everything):
    rng = np.random.default_rng(9)
    a = stars(rng, 3000)
    b = a + rng.uniform(-1.5, 1.5, (3000, 1, 2))
    ma = np.c_[rng.uniform(-2, 2, (3000, 2)), np.zeros((3000, 2)), rng.uniform(-1, 1, 3000),
               np.zeros(3000)]
    mb = np.zeros((3000, 6))
    one = on(1, lambda: pc.time_of_impact_many(a, ma, b, mb, t_max=3, threads=1))
    two = on(2, lambda: pc.time_of_impact_many(a, ma, b, mb, t_max=3, threads=2))
    for name in ("statuses", "times", "first_contacts"):
        assert same(getattr(one, name), getattr(two, name)), name
    assert np.count_nonzero(one.collides) > 300
    assert one.impact(11) == two.impact(11)


@pytest.mark.parametrize("count, n_chunks", [(1, 2), (64, 2), (65, 3), (1000, 7),
                                             (40_000, 256), (40_001, 32)])
def test_pairs_shared_among_threads_in_whole_blocks_each_once(count, n_chunks):
    """The time-of-impact chunks: every pair once, and a chunk owns whole blocks of
    pairs (their results side by side), the last block cut at the end."""
    from polycontact.impacts import _RESULT_BLOCK, _interleaved_blocks

    chunks = _interleaved_blocks(count, n_chunks)
    assert len(chunks) == n_chunks
    assert sorted(np.concatenate(chunks).tolist()) == list(range(count))
    owner = np.empty(count, np.int64)
    for c, todo in enumerate(chunks):
        owner[todo] = c
    blocks = owner[: count // _RESULT_BLOCK * _RESULT_BLOCK].reshape(-1, _RESULT_BLOCK)
    assert (blocks == blocks[:, :1]).all()


def test_motions_as_rows_give_the_answers_of_motions(share_everything):
    rng = np.random.default_rng(8)
    ell = pc.Shape([(0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)])
    a = [ell.moved(rng.uniform(-3, 3, 2), rng.uniform(0, 6)) for _ in range(300)]
    b = [ell] * 300
    ma = [pc.Motion(velocity=rng.uniform(-2, 2, 2), angular_velocity=rng.uniform(-1, 1),
                    acceleration=rng.uniform(-1, 1, 2)) for _ in a]
    mb = [pc.Motion()] * 300
    rows_a = np.array([m.array for m in ma])
    rows_b = np.zeros((300, 6))
    objects = pc.time_of_impact_many(a, ma, b, mb, t_max=3)
    for threads in (1, 2):
        rows = on(threads, lambda: pc.time_of_impact_many(a, rows_a, b, rows_b, t_max=3,
                                                           threads=threads))
        for name in ("statuses", "times", "first_contacts"):
            assert same(getattr(objects, name), getattr(rows, name)), name
    assert rows.impact(5) == objects.impact(5)
    events = [(e.i, e.j, e.impact.time) for e in pc.first_impacts(a, ma, t_max=1)]
    assert events == [(e.i, e.j, e.impact.time) for e in pc.first_impacts(a, rows_a, t_max=1)]
    bad = rows_a.copy()
    bad[17, 4] = np.inf
    with pytest.raises(ValueError, match=r"motions_a\[17\]: expected finite numbers"):
        pc.time_of_impact_many(a, bad, b, rows_b, t_max=3)
    with pytest.raises(ValueError, match=r"motions_b: expected 300 motions .* shape \(300, 6\)"):
        pc.time_of_impact_many(a, rows_a, b, rows_b[:, :4], t_max=3)


def test_first_impacts_on_two_threads_equal_one_thread(share_everything):
    rng = np.random.default_rng(6)
    shapes = [pc.Shape(x) for x in stars(rng, 300)]
    motions = [pc.Motion(velocity=rng.uniform(-1, 1, 2), angular_velocity=rng.uniform(-1, 1))
               for _ in shapes]

    def events(threads):
        return [(e.i, e.j, e.impact.status, e.impact.time)
                for e in on(threads, lambda: pc.first_impacts(shapes, motions, t_max=0.5,
                                                                threads=threads))]

    one = events(1)
    assert len(one) > 100 and one == events(2)


def test_first_impacts_of_a_ring_array_on_two_threads_equal_one_thread(share_everything):
    rng = np.random.default_rng(10)
    rings = stars(rng, 300)
    rows = np.c_[rng.uniform(-1, 1, (300, 2)), np.zeros((300, 2)), rng.uniform(-1, 1, 300),
                 np.zeros(300)]

    def events(threads):
        return [(e.i, e.j, e.impact.status, e.impact.time)
                for e in on(threads, lambda: pc.first_impacts(rings, rows, t_max=0.5,
                                                                threads=threads))]

    one = events(1)
    assert len(one) > 100 and one == events(2)


def test_time_of_impact_many_refuses_as_the_pair_would(share_everything):
    far = pc.Motion(velocity=(1e60, 0))
    a = [pc.Shape(SQ)] * 300
    ma = [pc.Motion()] * 300
    mb = [pc.Motion()] * 300
    mb[123] = far
    with pytest.raises(ValueError, match=r"motions_b\[123\]: the body's coordinates reach"):
        on(2, lambda: pc.time_of_impact_many(a, ma, a, mb, t_max=1e50))


# -- NFP tables ----------------------------------------------------------------------------
U = [(0, 0), (3, 0), (3, 3), (2, 3), (2, 1), (1, 1), (1, 3), (0, 3)]
# a box with a unit cavity reached through a narrower slit: the unit square fits exactly
KEYHOLE = [(0, 0), (5, 0), (5, 5), (2.75, 5), (2.75, 3), (3, 3), (3, 2), (2, 2), (2, 3),
           (2.25, 3), (2.25, 5), (0, 5)]
FRAME = pc.Shape([(0, 0), (4, 0), (4, 4), (0, 4)], [[(1, 1), (3, 1), (3, 3), (1, 3)]])


def entries_equal(x, y) -> bool:
    return (shapely.to_wkb(x.region) == shapely.to_wkb(y.region)
            and same(x.exact_fits, y.exact_fits) and same(x.slides, y.slides)
            and same(x.reference, y.reference) and x.tolerance == y.tolerance)


@pytest.mark.parametrize("reference", ["origin", "centroid"])
def test_nfp_table_on_two_threads_equals_one_thread_and_single_nfps(share_everything,
                                                                     reference):
    # squares sliding in the U and fitting in the keyhole, a frame with a hole (left to
    # no_fit_polygon), stars whose no-fit polygons have holes
    rng = np.random.default_rng(7)
    pieces = [SQ, U, KEYHOLE, FRAME, *stars(rng, 3, 10)]
    one = on(1, lambda: pc.nfp_table(pieces, [0, 90, 180], reference=reference,
                                     progress=False, threads=1, chunk_size=7))
    two = on(2, lambda: pc.nfp_table(pieces, [0, 90, 180], reference=reference,
                                     progress=False, threads=2, chunk_size=7))
    s = one.summary()
    assert s["slides"] > 0 and s["exact_fits"] > 0 and s["holes"] > 0
    for key in one:
        assert entries_equal(one[key], two[key]), key
        i, ai, j, aj = key
        single = pc.no_fit_polygon(one._shape(one._slot(i, ai, "i")),
                                   one._shape(one._slot(j, aj, "j")), reference)
        assert entries_equal(one[key], single), key


@pytest.mark.parametrize(("given", "expected"), [(None, "PASSIVE"), ("active", "active")])
def test_numba_threads_sleep_between_calls_unless_the_environment_says(given, expected):
    # the policy is read when Numba starts its OpenMP threads: set on import, before any
    # kernel runs
    env = {k: v for k, v in os.environ.items() if k != "OMP_WAIT_POLICY"}
    if given is not None:
        env["OMP_WAIT_POLICY"] = given
    code = "import os, polycontact; print(os.environ['OMP_WAIT_POLICY'])"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env=env, check=True).stdout
    assert out.strip() == expected
