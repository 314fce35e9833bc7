"""NFP tables: ESICUP reading, entries against single NFPs, the cache, interruption, CLI."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
import threading
import warnings
from concurrent.futures import Future
from pathlib import Path

import numpy as np
import pytest
import shapely
import shapely.affinity

import polycontact as pc
from polycontact.cli import main
from polycontact.esicup import InvalidInstanceError, turned
from polycontact import nfp_tables
from polycontact.nfp_tables import SHARDS, CacheWarning, NfpTable

SRC = str(Path(__file__).resolve().parents[2] / "src")

SQUARE = [[0, 0], [1, 0], [1, 1], [0, 1]]
BAR = [[0, 0], [2, 0], [2, 1], [0, 1], [0, 0]]  # closed ring, as some ESICUP files have
ELL = [[0, 0], [2, 0], [2, 1], [1, 1], [1, 2], [0, 2]]
# a U whose slot is exactly one unit wide: the square slides in it and fits at its bottom
U = [[0, 0], [3, 0], [3, 3], [2, 3], [2, 1], [1, 1], [1, 3], [0, 3]]
# a square frame: its entries go through no_fit_polygon, which holds the GIL
FRAME = ([[0, 0], [3, 0], [3, 3], [0, 3]], [[[1, 1], [1, 2], [2, 2], [2, 1]]])


def write_instance(path: Path, items: list | None = None) -> Path:
    items = items or [
        {"id": 0, "demand": 3, "allowed_orientations": [0, 90, 180, 270],
         "shape": {"type": "simple_polygon", "data": SQUARE}},
        {"id": 1, "demand": 1, "allowed_orientations": [0, 90],
         "shape": {"type": "simple_polygon", "data": BAR}},
        {"id": 2, "demand": 2, "allowed_orientations": [0, 90, 180, 270],
         "shape": {"type": "simple_polygon", "data": ELL}},
        {"id": 3, "demand": 1, "allowed_orientations": [0],
         "shape": {"type": "simple_polygon", "data": U}},
    ]
    path.write_text(json.dumps({"name": "small", "strip_height": 6, "items": items}))
    return path


@pytest.fixture
def instance(tmp_path):
    return pc.read_esicup(write_instance(tmp_path / "small.json"))


def same_entry(x: pc.NoFitPolygon, y: pc.NoFitPolygon) -> bool:
    return (shapely.to_wkb(x.region) == shapely.to_wkb(y.region)
            and np.array_equal(x.exact_fits, y.exact_fits)
            and np.array_equal(x.slides, y.slides)
            and np.array_equal(x.reference, y.reference) and x.tolerance == y.tolerance)


# -- reading instances ---------------------------------------------------------------------


def test_read_esicup_gives_pieces_orientations_demand_and_height(instance):
    assert instance.name == "small"
    assert [p.n_vertices for p in instance.pieces] == [4, 4, 6, 8]  # closing point dropped
    assert instance.orientations[1] == (0.0, 90.0)
    assert instance.demand == (3, 1, 2, 1)
    assert instance.strip_height == 6.0


@pytest.mark.parametrize("doc, message", [
    ("not json", "not JSON"),
    ({"items": []}, "'items' is empty"),
    ({"strip_height": -1, "items": [{}]}, "'strip_height'"),
    ({"strip_height": 1, "items": [{"demand": -2}]}, "items[0]: 'demand'"),
    ({"strip_height": 1, "items": [{"allowed_orientations": [0, 0]}]}, "repeated"),
    ({"strip_height": 1, "items": [{"shape": {"type": "polygon"}}]}, "got type 'polygon'"),
])
def test_read_esicup_names_what_is_wrong(tmp_path, doc, message):
    path = tmp_path / "bad.json"
    path.write_text(doc if isinstance(doc, str) else json.dumps(doc))
    with pytest.raises(InvalidInstanceError) as err:
        pc.read_esicup(path)
    assert message in str(err.value) and "bad.json" in str(err.value)


def test_read_esicup_names_the_item_of_an_invalid_polygon(tmp_path):
    items = [{"shape": {"type": "simple_polygon", "data": [[0, 0], [1, 1], [1, 0], [0, 1]]}}]
    path = tmp_path / "bow.json"
    path.write_text(json.dumps({"strip_height": 1, "items": items}))
    with pytest.raises(pc.InvalidShapeError, match=r"items\[0\]"):
        pc.read_esicup(path)


def test_turned_is_about_the_origin_and_exact_at_quarter_turns():
    piece = pc.Shape(ELL) .moved((5, 3))
    for deg in (90, 180, 270, -90, 450, 30):
        ref = shapely.affinity.rotate(piece.to_shapely(), deg, origin=(0, 0))
        assert turned(piece, deg).to_shapely().equals_exact(ref, 1e-12)
    assert turned(piece, 90).exterior[:, 0].tolist() == (-piece.exterior[:, 1]).tolist()


# -- the table -------------------------------------------------------------------------------


def test_every_entry_is_the_nfp_of_the_turned_pieces(instance):
    table = pc.nfp_table(instance, progress=False)
    assert len(table) == (4 + 2 + 4 + 1) ** 2
    count = 0
    for i, ai, j, aj in table:
        a = turned(instance.pieces[i], ai)
        b = turned(instance.pieces[j], aj)
        assert same_entry(table[i, ai, j, aj], pc.no_fit_polygon(a, b, "origin"))
        count += 1
    assert count == len(table)
    # the square fits exactly at the bottom of the U's slot and slides up along it
    slot = table[0, 0, 3, 0]
    assert slot.slides.tolist() == [[[1.0, 1.0], [1.0, 3.0]]]
    s = table.summary()
    assert (s["entries"], s["computed"], s["loaded"]) == (121, s["distinct"], 0)
    assert s["slides"] >= 1


def test_centroid_reference_and_lists_for_every_piece():
    sq, bar = pc.Shape(SQUARE), pc.Shape(BAR)
    table = pc.nfp_table([sq, bar], [0, 90], reference="centroid", progress=False)
    entry = table[1, 90, 0, 0]
    assert np.allclose(entry.reference, turned(bar, 90).centroid)
    assert same_entry(entry, pc.no_fit_polygon(turned(bar, 90), sq))


def test_lookup_errors_name_the_piece_and_its_orientations(instance):
    table = pc.nfp_table(instance, progress=False)
    assert same_entry(table[1, 450, 0, -90], table[1, 90, 0, 270])  # angles modulo 360
    with pytest.raises(KeyError, match=r"piece 1: 45 degrees .* \[0.0, 90.0\]"):
        table[1, 45, 0, 0]
    with pytest.raises(KeyError, match="piece 7 out of range"):
        table[7, 0, 0, 0]
    with pytest.raises(KeyError, match="table\\[i, ai, j, aj\\]"):
        table[0, 0]


@pytest.mark.parametrize("kwargs, message", [
    ({"orientations": [[0], [0]]}, "one list of angles per piece"),
    ({"orientations": [[0, 360]] * 4}, "repeated"),
    ({"orientations": [[]] * 4}, r"orientations\[0\]"),
    ({"reference": "middle"}, "reference"),
    ({"chunk_size": 0}, "chunk_size"),
    ({"workers": 1.5}, "workers"),
])
def test_bad_arguments_are_refused(instance, kwargs, message):
    with pytest.raises(ValueError, match=message):
        pc.nfp_table(instance.pieces, **{"progress": False, **kwargs})


# -- the cache -------------------------------------------------------------------------------


def test_cache_round_trip_keeps_regions_exact_fits_and_slides(instance, tmp_path):
    cache = tmp_path / "cache"
    first = pc.nfp_table(instance, cache=cache, progress=False, chunk_size=10)
    again = pc.nfp_table(instance, cache=cache, progress=False)
    loaded = NfpTable.load(cache)
    assert again.computed == 0 and again.loaded == first.computed
    for index in first:
        assert same_entry(first[index], again[index])
        assert same_entry(first[index], loaded[index])
    assert loaded.summary()["slides"] == first.summary()["slides"] > 0
    # every shard is a WKB file and a JSON index that any WKB reader can use
    index = json.loads(next((cache / SHARDS).glob("*.json")).read_text())
    blob = (cache / SHARDS / index["wkb"]).read_bytes()
    e = index["entries"][0]
    assert shapely.from_wkb(blob[e["offset"]:e["offset"] + e["length"]]).is_valid


def test_a_table_built_without_cache_saves_and_loads(instance, tmp_path):
    table = pc.nfp_table(instance, progress=False)
    table.save(tmp_path / "saved")
    loaded = NfpTable.load(tmp_path / "saved")
    assert loaded.loaded == table.computed
    for index in table:
        assert same_entry(table[index], loaded[index])
    with pytest.raises(ValueError, match="table.json"):
        NfpTable.load(tmp_path / "nothing")


def test_rebuild_with_a_new_orientation_computes_only_its_entries(instance, tmp_path):
    cache = tmp_path / "cache"
    pc.nfp_table(instance, cache=cache, progress=False)
    more = [list(o) for o in instance.orientations]
    more[3] = [0, 180]  # the U turned: 11 old slots, 1 new
    table = pc.nfp_table(instance.pieces, more, cache=cache, progress=False)
    assert len(table) == 144
    assert table.computed == 144 - 121  # the new slot with every slot, both ways
    assert same_entry(table[3, 180, 0, 0],
                      pc.no_fit_polygon(turned(instance.pieces[3], 180), instance.pieces[0],
                                        "origin"))


def test_damaged_or_unfinished_shards_are_never_read(instance, tmp_path):
    cache = tmp_path / "cache"
    ref = pc.nfp_table(instance, cache=cache, progress=False, chunk_size=16)
    shards = sorted((cache / SHARDS).glob("*.json"))
    # a build stopped between the two renames: a .wkb without its index, a temp file
    (cache / SHARDS / "stopped.wkb").write_bytes(b"\x01\x03")
    (cache / SHARDS / ".x.json.tmp").write_text("{")
    # a shard damaged after it was written
    index = json.loads(shards[0].read_text())
    wkb = cache / SHARDS / index["wkb"]
    wkb.write_bytes(wkb.read_bytes()[:-8])
    with pytest.warns(CacheWarning, match="does not match its checksum"):
        table = pc.nfp_table(instance, cache=cache, progress=False)
    assert table.computed == len(index["entries"])
    for key in ref:
        assert same_entry(ref[key], table[key])
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the damaged shard is still there, and skipped
        with pytest.warns(CacheWarning):
            again = pc.nfp_table(instance, cache=cache, progress=False)
    assert again.computed == 0


INTERRUPTED_BUILD = """
import os, signal, sys
import polycontact as pc

# Ctrl-C as in a terminal: a process started in the background of a non-interactive
# shell inherits SIGINT ignored, and Python then leaves it so (no KeyboardInterrupt)
signal.signal(signal.SIGINT, signal.default_int_handler)
inst = pc.read_esicup(sys.argv[1])

def progress(done, total):
    if done >= 30:  # Ctrl-C after some batches are in the cache
        os.kill(os.getpid(), signal.SIGINT)

pc.nfp_table(inst, cache=sys.argv[2], progress=progress, chunk_size=10, workers=1)
"""


def test_ctrl_c_leaves_a_consistent_cache_and_the_rerun_completes_it(instance, tmp_path):
    path = write_instance(tmp_path / "small.json")
    cache = tmp_path / "cache"
    run = subprocess.run([sys.executable, "-c", textwrap.dedent(INTERRUPTED_BUILD),
                          str(path), str(cache)], capture_output=True, text=True,
                         env={**os.environ, "PYTHONPATH": SRC}, timeout=600)
    assert run.returncode != 0 and "KeyboardInterrupt" in run.stderr
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        part = NfpTable.load(cache)
    assert part.loaded == 30
    seen = []
    table = pc.nfp_table(instance, cache=cache, progress=lambda d, n: seen.append((d, n)))
    ref = pc.nfp_table(instance, progress=False)
    assert table.loaded == 30 and table.computed == ref.computed - 30
    assert seen[-1] == (ref.computed - 30, ref.computed - 30)
    for key in ref:
        assert same_entry(ref[key], table[key])


def pools_started(monkeypatch) -> list[int]:
    """The sizes of the process pools the builds start from now on (recorded)."""
    pools: list[int] = []
    start = nfp_tables._run_processes
    monkeypatch.setattr(nfp_tables, "_run_processes",
                        lambda n, *args: (pools.append(n), start(n, *args))[1])
    return pools


def test_local_processes_give_the_same_table(instance, monkeypatch):
    # the frame's entries, first, hold the GIL, and processes start at no cost here: the
    # build takes a pool of two processes
    pieces = [pc.Shape(*FRAME), *instance.pieces]
    angles = [[0, 90], *instance.orientations]
    serial = pc.nfp_table(pieces, angles, progress=False, workers=1, threads=1)
    monkeypatch.setattr(nfp_tables, "PROCESS_START", 1e-9)
    pools = pools_started(monkeypatch)
    pooled = pc.nfp_table(pieces, angles, progress=False, workers=2, chunk_size=20)
    assert pools == [2]
    for key in serial:
        assert same_entry(serial[key], pooled[key])


@pytest.mark.parametrize("holes, workers", [(False, 2), (True, 1)])
def test_workers_start_no_process_where_processes_cannot_pay(monkeypatch, holes, workers):
    # pieces without holes are computed in compiled code that releases the GIL: threads
    # share that work, and processes would only add their start, however cheap; and
    # workers=1 keeps even work that holds the GIL in this process
    pieces = ([pc.Shape(*FRAME)] if holes else []) + [pc.Shape(SQUARE), pc.Shape(ELL),
                                                      pc.Shape(U)]
    one = pc.nfp_table(pieces, [0, 90, 180], progress=False, workers=1, threads=1)
    monkeypatch.setattr(nfp_tables, "PROCESS_START", 1e-9)

    def no_pool(*args):
        raise AssertionError("a process pool was started")

    monkeypatch.setattr(nfp_tables, "_run_processes", no_pool)
    built = pc.nfp_table(pieces, [0, 90, 180], progress=False, workers=workers, threads=2,
                         chunk_size=8)
    assert built.computed == one.computed
    for key in one:
        assert same_entry(one[key], built[key])


def test_importing_the_table_imports_neither_dask_nor_tqdm():
    code = ("import sys, polycontact; polycontact.nfp_table; polycontact.read_esicup; "
            "import polycontact.distributed; "
            "print(sorted(m for m in ('dask', 'distributed', 'tqdm') if m in sys.modules))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env={**os.environ, "PYTHONPATH": SRC}, check=True).stdout
    assert out.strip() == "[]"


# -- command line ----------------------------------------------------------------------------


def test_cli_builds_then_completes_from_the_cache(tmp_path, capsys):
    path = str(write_instance(tmp_path / "small.json"))
    out = str(tmp_path / "table")
    assert main(["nfp-table", path, "--out", out, "--no-progress", "--orientations", "0"]) == 0
    first = capsys.readouterr().out
    assert first.startswith("small: 16 entries (") and "0 from the cache" in first
    assert main(["nfp-table", path, "--out", out, "--json", "--no-progress"]) == 0
    s = json.loads(capsys.readouterr().out)
    assert s["entries"] == 121 and s["slides"] >= 1 and s["exact_fits"] >= 0
    assert s["computed"] + s["loaded"] == s["distinct"] and s["loaded"] > 0


def test_cli_reports_a_bad_instance_in_one_line(tmp_path, capsys):
    assert main(["nfp-table", str(tmp_path / "none.json"), "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("polycontact nfp-table: error:") and "none.json" in err


def test_a_build_whose_processes_never_start_finishes_in_this_process(monkeypatch):
    # the calling process works alongside its pool, and computes the tasks it handed to
    # processes that never take them: the build ends, with the table of one process
    pools = []

    class IdlePool:
        def __init__(self, n, *args, **kwargs):
            pools.append(n)

        def submit(self, *args):
            return Future()  # never run

        def shutdown(self, **kwargs):
            pass

    # the frame's entries hold the GIL, and processes start at no cost here: the build
    # takes a pool
    pieces = [pc.Shape(*FRAME), pc.Shape(SQUARE), pc.Shape(ELL)]
    one = pc.nfp_table(pieces, [0, 90], progress=False, workers=1)
    monkeypatch.setattr(nfp_tables, "PROCESS_START", 1e-9)
    monkeypatch.setattr(nfp_tables, "ProcessPoolExecutor", IdlePool)
    built = []
    build = threading.Thread(target=lambda: built.append(pc.nfp_table(
        pieces, [0, 90], progress=False, workers=2, chunk_size=2)), daemon=True)
    build.start()
    build.join(120)
    assert pools == [2]
    assert built, "the build waited for processes that never started"
    assert {k: shapely.to_wkb(built[0][k].region) for k in built[0]} == {
        k: shapely.to_wkb(one[k].region) for k in one}
