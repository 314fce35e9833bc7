"""Dask: a LocalCluster of 2 worker processes gives the same NFP tables, classifications
and times of impact as the local run; kernels are warmed once per worker; a killed worker
loses nothing; tasks are sized from a first one."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely

import polycontact as pc
from polycontact import distributed as pd
from polycontact import impacts
from polycontact.esicup import turned

from .test_pose_arguments import BAD_NUMBERS, BAD_POINTS

distributed = pytest.importorskip("distributed")

pytestmark = pytest.mark.slow  # a cluster of worker processes

SQUARE = [[0, 0], [1, 0], [1, 1], [0, 1]]
ELL = [[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]]
U = [[0, 0], [3, 0], [3, 3], [2, 3], [2, 1], [1, 1], [1, 3], [0, 3]]
PIECES = [pc.Shape(SQUARE), pc.Shape(ELL), pc.Shape(U)]
ANGLES = [[0, 90, 180, 270], [0, 90, 180, 270], [0, 180]]


@pytest.fixture(scope="module")
def client():
    # the kernels compiled here first, so the workers load them from Numba's cache
    pc.warmup(["classification", "no-fit polygon", "no-fit polygon table", "many moving bodies"])
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
        with distributed.Client(cluster) as c:
            yield c


def here(fn):
    """``fn()`` with the calls that give no ``client=`` run in this process, though the
    cluster's client is the default one."""
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(pd, "current_client", lambda client=None: client)
        return fn()


def same_entry(x: pc.NoFitPolygon, y: pc.NoFitPolygon) -> bool:
    return (shapely.to_wkb(x.region) == shapely.to_wkb(y.region)
            and np.array_equal(x.exact_fits, y.exact_fits)
            and np.array_equal(x.slides, y.slides) and x.tolerance == y.tolerance)


def test_table_on_the_cluster_is_identical_to_the_local_one(client, tmp_path):
    local = here(lambda: pc.nfp_table(PIECES, ANGLES, progress=False))
    remote = pc.nfp_table(PIECES, ANGLES, client=client, progress=False, chunk_size=15,
                          cache=tmp_path)
    assert remote.computed == local.computed and len(remote) == 100
    for key in local:
        assert same_entry(local[key], remote[key])
    assert same_entry(remote[0, 0, 2, 0], pc.no_fit_polygon(PIECES[0], PIECES[2], "origin"))
    assert pc.nfp_table(PIECES, ANGLES, cache=tmp_path, client=client).computed == 0


def test_the_default_client_is_used(client):
    seen = []
    table = pc.nfp_table(PIECES[:2], [[0, 90]] * 2, chunk_size=4,
                         progress=lambda d, n: seen.append(d))
    assert pd.current_client() is client
    assert len(seen) == 4 and table.computed == 16  # four tasks of 4 entries, on the cluster
    assert all(pd.plugin_name("no-fit polygon table") in p
               for p in client.run(pd.worker_plugins).values())


def test_kernels_are_warmed_once_per_worker(client):
    pc.nfp_table(PIECES[:1], progress=False, client=client)
    name = pd.plugin_name("no-fit polygon table")
    assert all(name in p for p in client.run(pd.worker_plugins).values())
    before = client.run(_setup_id, name)
    pd.ensure_warm(client, ["no-fit polygon table"])
    pc.nfp_table(PIECES[:2], progress=False, client=client)
    assert client.run(_setup_id, name) == before  # no new registration, no warm-up per task
    # a batch warms only its own family
    assert pd.plugin_name("time of impact") not in next(iter(client.run(pd.worker_plugins).values()))


def _setup_id(name, dask_worker=None) -> int:
    return id(dask_worker.plugins[name])


def test_classify_many_on_the_cluster_is_identical(client):
    rng = np.random.default_rng(7)
    base = np.array(SQUARE, dtype=float)
    count = 3000
    a = base[None] * rng.uniform(0.5, 2, (count, 1, 1)) + rng.uniform(-2, 2, (count, 1, 2))
    b = base[None] * rng.uniform(0.5, 2, (count, 1, 1)) + rng.uniform(-2, 2, (count, 1, 2))
    b[::7] = a[::7] + [1e-3, 0]  # some overlapping, some touching
    width = a[1::7, 1, 0] - a[1::7, 0, 0]
    b[1::7] = a[1::7] + np.stack([width, 0 * width], axis=-1)[:, None, :]
    local = here(lambda: pc.classify_many(a, b))
    remote = pc.classify_many(a, b, client=client, chunk_size=700)
    assert np.array_equal(local.states, remote.states)
    assert np.array_equal(local.tolerances, remote.tolerances)
    assert np.array_equal(local.distances, remote.distances)
    assert set(local.states.tolist()) == {0, 1, 2}
    shapes_a = [pc.Shape(r) for r in a[:50]]
    listed = pc.classify_many(shapes_a, list(b[:50]), client=client, chunk_size=9)
    assert np.array_equal(listed.states, local.states[:50])


def test_ring_arrays_on_the_cluster_are_checked_and_copied_at_the_call(client):
    # checked and classified in one kernel pass in the tasks (not ring by ring in Python
    # here), refused as locally when a ring is invalid, and never read after the call
    a = np.array([SQUARE] * 6, dtype=float) + np.arange(6)[:, None, None] * 3.0
    b = a + 0.5
    bad = a.copy()
    bad[4] = [(0, 0), (1, 1), (1, 0), (0, 1)]  # a bowtie
    with pytest.raises(pc.InvalidShapeError, match=r"shapes_a\[4\]") as there:
        pc.classify_many(bad, b, client=client)
    with pytest.raises(pc.InvalidShapeError) as here_:
        pc.classify_many(bad, b)
    assert str(there.value) == str(here_.value)
    batch = pc.classify_many(a, b, client=client)
    a += 100.0  # the caller reuses its array before reading the distances
    assert batch.states.tolist() == [2] * 6
    assert batch.distances.tolist() == pytest.approx([-0.5] * 6)
    # a repeated vertex: a valid ring the tasks' one-pass check leaves to Shape, here
    again = a.copy()
    again[2] = again[2][[0, 1, 1, 2]]
    remote = pc.classify_many(again, b, client=client)
    local = here(lambda: pc.classify_many(again, b))
    assert np.array_equal(remote.states, local.states)
    assert np.array_equal(remote.distances, local.distances)


def impact_pairs(count: int, seed: int) -> tuple[list, list, list, list]:
    """Pairs that hit, touch, miss, penetrate at the start, in and around a body with a
    hole, then ``count`` random ones (some bodies shared by many pairs, some not)."""
    sq, ell, u = PIECES
    frame = pc.Shape([(0, 0), (6, 0), (6, 6), (0, 6)], [[(2, 2), (4, 2), (4, 4), (2, 4)]])
    small = pc.Shape([(2.5, 2.5), (3, 2.5), (3, 3), (2.5, 3)])  # inside the hole of frame
    still = pc.Motion()
    cases = [
        (sq, pc.Motion(velocity=(1, 0)), sq.moved((3, 0)), still),           # hit at t=2
        (sq, pc.Motion(velocity=(0, 1)), sq.moved((1, 2)), still),           # slides flush
        (sq, pc.Motion(velocity=(1, 0)), sq.moved((0, 5)), still),           # miss
        (ell, still, sq.moved((0.5, 0.5)), pc.Motion(velocity=(1, 1))),      # overlap at 0
        (small, pc.Motion(velocity=(0.5, 0)), frame, still),                 # hits the hole
        (small, still, frame, still),                                        # in the hole
        (small.moved((1, 0)), pc.Motion(velocity=(0, 0.25)), frame, still),  # slides on it
        (u, pc.Motion(angular_velocity=1), small.moved((-1.25, -0.5)), still),  # U turns
    ]
    rng = np.random.default_rng(seed)
    for k in range(count):
        a = PIECES[k % 3] if k % 2 else PIECES[k % 3].moved(rng.uniform(-3, 3, 2))
        b = frame if k % 5 == 0 else PIECES[(k // 3) % 3].moved(rng.uniform(-3, 3, 2),
                                                                rng.uniform(0, 6.3))
        ma = pc.Motion(velocity=rng.uniform(-2, 2, 2), angular_velocity=rng.uniform(-1, 1),
                       acceleration=rng.uniform(-1, 1, 2) if k % 4 == 0 else (0, 0))
        cases.append((a, ma, b, still if k % 2 else pc.Motion(velocity=rng.uniform(-1, 1, 2))))
    return tuple(list(c) for c in zip(*cases))


def same_batch(x: pc.ImpactBatch, y: pc.ImpactBatch) -> bool:
    return (np.array_equal(x.statuses, y.statuses) and np.array_equal(x.collides, y.collides)
            and np.array_equal(x.times, y.times, equal_nan=True)
            and np.array_equal(x.first_contacts, y.first_contacts, equal_nan=True)
            and all(x.impact(k) == y.impact(k) and x.impact(k).features == y.impact(k).features
                    for k in range(len(x))))


@pytest.mark.parametrize("method", ["exact", "sampled"])
def test_time_of_impact_many_on_the_cluster_is_identical(client, method):
    a, ma, b, mb = impact_pairs(400, seed=11)
    local = here(lambda: pc.time_of_impact_many(a, ma, b, mb, t_max=3, method=method,
                                                 threads=1))
    remote = pc.time_of_impact_many(a, ma, b, mb, t_max=3, method=method, client=client,
                                    chunk_size=37)
    assert len(remote) == len(a) and same_batch(local, remote)
    # the chosen cases: hit, slide, miss, overlap at the start, through a hole
    assert remote.statuses[:8].tolist() == [1, 0, 0, 2, 1, 0, 0, 1]
    assert np.isnan(remote.first_contacts[[2, 5]]).all()  # they never touch
    assert not np.isnan(remote.first_contacts[[1, 6]]).any()  # they slide, touching
    assert remote.impact(4) == pc.time_of_impact(a[4], ma[4], b[4], mb[4], t_max=3,
                                                 method=method)
    assert set(remote.statuses.tolist()) == {0, 1, 2}


def test_time_of_impact_many_of_ring_arrays_on_the_cluster_is_identical(client):
    rng = np.random.default_rng(12)
    t = np.linspace(0, 2 * np.pi, 8, endpoint=False)
    star = np.c_[np.cos(t), np.sin(t)] * np.where(np.arange(8) % 2, 0.4, 1.0)[:, None]
    a = star[None] * rng.uniform(0.5, 1.5, (300, 1, 1)) + rng.uniform(-3, 3, (300, 1, 2))
    b = a + rng.uniform(-1.5, 1.5, (300, 1, 2))
    ma = np.c_[rng.uniform(-2, 2, (300, 2)), np.zeros((300, 2)), rng.uniform(-1, 1, 300),
               np.zeros(300)]
    mb = np.zeros((300, 6))
    local = here(lambda: pc.time_of_impact_many(a, ma, b, mb, t_max=3, threads=1))
    remote = pc.time_of_impact_many(a, ma, b, mb, t_max=3, client=client, chunk_size=37)
    assert same_batch(local, remote) and set(remote.statuses.tolist()) == {0, 1, 2}
    bad = a.copy()
    bad[40, 2] = bad[40, 7]  # (two vertices at one point: refused, named, at the call)
    with pytest.raises(pc.InvalidShapeError, match=r"shapes_a\[40\]: "):
        pc.time_of_impact_many(bad, ma, b, mb, t_max=3, client=client)


def test_time_of_impact_many_uses_the_default_client_and_its_warm_up(client):
    a, ma, b, mb = impact_pairs(40, seed=5)
    arrays = [np.asarray(s.exterior) for s in a]  # every pair its own shape objects
    local = here(lambda: pc.time_of_impact_many(arrays, ma, b, mb, t_max=2))
    assert pd.current_client() is client
    remote = pc.time_of_impact_many(arrays, ma, b, mb, t_max=2)  # a default chunk size
    assert same_batch(local, remote)
    name = pd.plugin_name("many moving bodies")
    assert all(name in p for p in client.run(pd.worker_plugins).values())
    empty = pc.time_of_impact_many([], [], [], [], t_max=1, client=client)
    assert len(empty) == 0 and empty.times.shape == (0,)


@pytest.mark.parametrize("change, error, message", [
    (lambda a, ma, b, mb: (a, ma, b[:-1], mb), ValueError,
     r"shapes_a and shapes_b differ in length \(48 and 47\)"),
    (lambda a, ma, b, mb: (a, ma[:30] + [(1, 0)] + ma[31:], b, mb), TypeError,
     r"motions_a\[30\]: expected a polycontact.Motion, got tuple"),
    (lambda a, ma, b, mb: (a, ma, b[:44] + [[(0, 0), (1, 1)]] + b[45:], mb),
     pc.InvalidShapeError, r"shapes_b\[44\]: .*fewer than 3"),
    (lambda a, ma, b, mb: (a, ma, b, mb[:41] + [pc.Motion(angular_velocity=1e120)] + mb[42:]),
     ValueError, r"motions_b\[41\]: the body's (points' speeds|angular speed) reach"),
])
def test_time_of_impact_many_errors_name_the_caller_s_index(client, change, error, message):
    a, ma, b, mb = change(*impact_pairs(40, seed=5))
    with pytest.raises(error, match=message) as local:
        here(lambda: pc.time_of_impact_many(a, ma, b, mb, t_max=1))
    with pytest.raises(error, match=message) as remote:
        pc.time_of_impact_many(a, ma, b, mb, t_max=1, client=client, chunk_size=7)
    assert str(remote.value) == str(local.value)
    with pytest.raises(ValueError, match="chunk_size: expected a positive integer"):
        pc.time_of_impact_many(a, ma, b, mb, t_max=1, client=client, chunk_size=0)


def test_impact_tasks_send_shapes_of_several_tasks_once():
    # shape 0 is in every task, shape 1 in the first two, shapes 2.. in one task each
    sa = np.array([0, 0, 0, 0, 0])
    sb = np.array([1, 2, 1, 3, 4])
    uniq = [pc.Shape(np.array(SQUARE, float) + [3 * k, 0]) for k in range(5)]
    rows, eps = np.zeros((5, 6)), np.ones(5)
    packs = [s._kernel for s in uniq]  # each shape's kernel pack
    shared, tasks = impacts._impact_tasks(packs, sa, sb, rows, rows, eps, [(0, 2), (2, 4), (4, 5)])
    kernel = {p: k for k, p in enumerate(packs)}
    assert [kernel[p] for p in shared.kernels] == [0, 1]
    assert [[kernel[p] for p in t[2].kernels] for t in tasks] == [[2], [3], [4]]
    # a task numbers the shared shapes first, then its own
    assert [[kernel[(shared.kernels + t[2].kernels)[i]] for i in t[1]] for t in tasks] == [
        [1, 2], [1, 3], [4]]
    assert [t[0].tolist() for t in tasks] == [[0, 0], [0, 0], [0]]


def test_impact_tasks_of_part_of_the_pairs_share_only_the_shapes_of_those_pairs():
    # the pairs 0..1 are in no task (as before the spans of the tasks after a first
    # probing task): shape 0, which pair 0 shares with the last task, is that task's own
    sa = np.array([0, 1, 2, 2, 0])
    sb = np.array([1, 3, 3, 4, 4])
    uniq = [pc.Shape(np.array(SQUARE, float) + [3 * k, 0]) for k in range(5)]
    rows, eps = np.zeros((5, 6)), np.ones(5)
    packs = [s._kernel for s in uniq]
    shared, tasks = impacts._impact_tasks(packs, sa, sb, rows, rows, eps, [(2, 3), (3, 4),
                                                                         (4, 5)])
    kernel = {p: k for k, p in enumerate(packs)}
    assert [kernel[p] for p in shared.kernels] == [2, 4]
    assert [[kernel[p] for p in t[2].kernels] for t in tasks] == [[3], [], [0]]


def test_map_batches_keeps_the_order(client):
    out = pd.map_batches(_sum_pairs, np.arange(10), np.arange(10, 20), client=client,
                         chunk_size=3, scale=2)
    assert out == [2 * (0 + 1 + 2 + 10 + 11 + 12), 2 * (3 + 4 + 5 + 13 + 14 + 15),
                   2 * (6 + 7 + 8 + 16 + 17 + 18), 2 * (9 + 19)]
    with pytest.raises(ValueError, match="argument 1 has 2 items"):
        pd.map_batches(_sum_pairs, [1, 2, 3], [1, 2], client=client)


def _sum_pairs(x, y, scale):
    return int(scale * (np.sum(x) + np.sum(y)))


def test_a_killed_worker_loses_no_entry(client, tmp_path):
    pieces = [turned(p, 0) for p in PIECES]
    local = here(lambda: pc.nfp_table(pieces, ANGLES, progress=False))
    killed = []

    def kill_one(done, total):
        if not killed:  # after the first batch: one worker process dies
            worker = sorted(client.scheduler_info()["workers"])[0]
            client.run(_exit, workers=[worker], wait=False)
            killed.append(worker)

    remote = pc.nfp_table(pieces, ANGLES, client=client, progress=kill_one, chunk_size=5,
                          cache=tmp_path)
    assert killed
    for key in local:
        assert same_entry(local[key], remote[key])
    client.wait_for_workers(2)  # the nanny restarts it


def test_a_task_the_scheduler_forgets_is_run_again(client, tmp_path):
    # a task cancelled on the scheduler (as when a dead worker held what it needed)
    pieces = [turned(p, 0) for p in PIECES]
    local = here(lambda: pc.nfp_table(pieces, ANGLES, progress=False))
    submit = client.submit

    def build(cancel_third: bool, cache) -> tuple[pc.NfpTable, int]:
        submitted = []

        def submitting(fn, *args, **kwargs):
            future = submit(fn, *args, **kwargs)
            if fn.__name__ == "_compute_chunk":
                submitted.append(future.key)
                if cancel_third and len(submitted) == 3:
                    client.cancel([future])
            return future

        with pytest.MonkeyPatch.context() as mp:
            mp.setattr(client, "submit", submitting)
            table = pc.nfp_table(pieces, ANGLES, client=client, progress=False, chunk_size=5,
                                 cache=cache)
        return table, len(submitted)

    _, tasks = build(False, tmp_path / "plain")
    remote, submitted = build(True, tmp_path / "cancelled")
    assert submitted == tasks + 1  # the third task run again
    for key in local:
        assert same_entry(local[key], remote[key])


async def _exit() -> None:
    import asyncio
    import os

    await asyncio.sleep(0.05)  # after the reply that the call started
    os._exit(1)


def test_cli_on_a_scheduler_builds_the_same_table(client, tmp_path, capsys):
    # last in this file: the command's own client replaces the default client
    from polycontact.cli import main

    path = tmp_path / "three.json"
    items = [{"id": k, "demand": 1, "allowed_orientations": a,
              "shape": {"type": "simple_polygon", "data": p.exterior.tolist()}}
             for k, (p, a) in enumerate(zip(PIECES, ANGLES))]
    path.write_text(__import__("json").dumps({"strip_height": 9, "items": items}))
    out = tmp_path / "table"
    assert main(["nfp-table", str(path), "--out", str(out), "--no-progress",
                 "--scheduler", client.scheduler.address, "--chunk-size", "30"]) == 0
    captured = capsys.readouterr()
    assert "2 workers" in captured.err
    assert captured.out.startswith("three: 100 entries (")
    local = here(lambda: pc.nfp_table(PIECES, ANGLES, progress=False))
    loaded = pc.NfpTable.load(out)
    for key in local:
        assert same_entry(local[key], loaded[key])


def test_tasks_are_sized_from_a_first_task(client):
    # a first task of PROBE_ITEMS items, then tasks of at least TASK_SECONDS of work each
    # (here: every item left in one task)
    spans = []

    def tasks_of(got):
        spans.extend(got)
        return None, [np.arange(p0, p1) for p0, p1 in got]

    parts = dict(((p0, p1), r) for p0, p1, r in pd.run_spans(client, _total, 1000, tasks_of))
    assert spans[0] == (0, pd.PROBE_ITEMS) and spans[1:] == [(pd.PROBE_ITEMS, 1000)]
    assert sum(parts.values()) == sum(range(1000))


def test_task_sizes_fill_whole_rounds_of_worker_threads():
    # at least TASK_SECONDS (0.05 s) of work per task, at most four tasks per worker
    # thread, and where there are more tasks than threads a whole number of rounds (five
    # tasks of 0.05 s on four threads would take 0.1 s; four of 0.0625 s take 0.0625 s)
    assert pd.task_size(10**6, 1e-6, 4) == 10**6 // 16  # 1 s: four per worker thread
    assert pd.task_size(10**8, 1e-6, 4) == 10**8 // 16
    assert pd.task_size(9 * 10**4, 3e-5, 2) == 9 * 10**4 // 8  # 2.7 s: four rounds
    assert pd.task_size(9 * 10**4, 3e-5, 16) == math.ceil(9 * 10**4 / 48)  # three rounds
    assert pd.task_size(70_000, 2e-5, 16) == 70_000 // 16  # 1.4 s still fills 16 workers
    assert pd.task_size(2500, 1e-4, 16) == 500  # 0.25 s: five tasks of 0.05 s
    assert pd.task_size(1000, 1e-6, 4) == 1000  # 1 ms: one task
    assert pd.task_size(10, 1.0, 4) == 1  # never an empty task


def _total(_, task):
    return int(np.sum(task))


def test_poses_and_motions_given_to_the_cluster_are_checked_before_any_task(client):
    """The property of the pose checks (every value that is not a finite real number in
    range refused, naming the argument) holds with a client too, and nothing is sent."""
    sq = pc.Shape(SQUARE)
    tasks = client.run_on_scheduler(lambda dask_scheduler: len(dask_scheduler.tasks))
    for bad in BAD_POINTS:
        with pytest.raises((TypeError, ValueError), match="motions_a"):
            pc.time_of_impact_many([sq], [bad], [sq.moved((3, 0))], [pc.Motion()], t_max=5.0,
                                   client=client)
    for bad in BAD_NUMBERS:
        with pytest.raises((TypeError, ValueError), match="motions_a"):
            pc.time_of_impact_many([sq], [[bad, 0, 0, 0, 0, 0]], [sq.moved((3, 0))],
                                   [pc.Motion()], t_max=5.0, client=client)
        with pytest.raises((TypeError, ValueError), match="t_max"):
            pc.time_of_impact_many([sq], [pc.Motion(velocity=(1, 0))], [sq.moved((3, 0))],
                                   [pc.Motion()], t_max=bad, client=client)
        if isinstance(bad, float) and abs(bad) > 1e100:
            continue  # a finite angle of any size is one
        with pytest.raises((TypeError, ValueError), match="orientations"):
            pc.nfp_table([sq], [[bad]], client=client, progress=False)
    assert client.run_on_scheduler(lambda dask_scheduler: len(dask_scheduler.tasks)) <= tasks
