"""Dask: a LocalCluster of 2 worker processes gives the same NFP tables and classifications
as the local run; kernels are warmed once per worker; a killed worker loses nothing."""

from __future__ import annotations

import numpy as np
import pytest
import shapely

import polycontact as pc
from polycontact import distributed as pd
from polycontact.esicup import turned

distributed = pytest.importorskip("distributed")

SQUARE = [[0, 0], [1, 0], [1, 1], [0, 1]]
ELL = [[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]]
U = [[0, 0], [3, 0], [3, 3], [2, 3], [2, 1], [1, 1], [1, 3], [0, 3]]
PIECES = [pc.Shape(SQUARE), pc.Shape(ELL), pc.Shape(U)]
ANGLES = [[0, 90, 180, 270], [0, 90, 180, 270], [0, 180]]


@pytest.fixture(scope="module")
def client():
    # the kernels compiled here first, so the workers load them from Numba's cache
    pc.warmup(["classification", "no-fit polygon"])
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
        with distributed.Client(cluster) as c:
            yield c


def same_entry(x: pc.NoFitPolygon, y: pc.NoFitPolygon) -> bool:
    return (shapely.to_wkb(x.region) == shapely.to_wkb(y.region)
            and np.array_equal(x.exact_fits, y.exact_fits)
            and np.array_equal(x.slides, y.slides) and x.tolerance == y.tolerance)


def test_table_on_the_cluster_is_identical_to_the_local_one(client, tmp_path):
    local = pc.nfp_table(PIECES, ANGLES, progress=False)
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
    assert all(pd.plugin_name("no-fit polygon") in p for p in client.run(pd._plugins).values())


def test_kernels_are_warmed_once_per_worker(client):
    pc.nfp_table(PIECES[:1], progress=False, client=client)
    name = pd.plugin_name("no-fit polygon")
    assert all(name in p for p in client.run(pd._plugins).values())
    before = client.run(_setup_id, name)
    pd.ensure_warm(client, ["no-fit polygon"])
    pc.nfp_table(PIECES[:2], progress=False, client=client)
    assert client.run(_setup_id, name) == before  # no new registration, no warm-up per task
    # a batch warms only its own family
    assert pd.plugin_name("time of impact") not in next(iter(client.run(pd._plugins).values()))


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
    local = pc.classify_many(a, b)
    remote = pd.classify_many(a, b, client=client, chunk_size=700)
    assert np.array_equal(local.states, remote.states)
    assert np.array_equal(local.tolerances, remote.tolerances)
    assert np.array_equal(local.distances, remote.distances)
    assert set(local.states.tolist()) == {0, 1, 2}
    shapes_a = [pc.Shape(r) for r in a[:50]]
    listed = pd.classify_many(shapes_a, list(b[:50]), client=client, chunk_size=9)
    assert np.array_equal(listed.states, local.states[:50])


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
    local = pc.nfp_table(pieces, ANGLES, progress=False)
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
    local = pc.nfp_table(PIECES, ANGLES, progress=False)
    loaded = pc.NfpTable.load(out)
    for key in local:
        assert same_entry(local[key], loaded[key])
