"""Every byte of the NFP cache that decides an answer is checked.

A shard's index (byte ranges, reference points, tolerances, exact fits, slides) and its
regions are covered by one checksum: a shard whose index or regions were changed after
it was written, or that cannot be read at all (JSON that is not an object, nested too
deep, a byte range off the file), is skipped with a ``CacheWarning`` and its entries
are recomputed, never served and never a crash.
"""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import numpy as np
import pytest
import shapely

import polycontact as pc
from polycontact.nfp_tables import MANIFEST, SHARDS, CacheWarning, NfpTable

SQUARE = [(0, 0), (1, 0), (1, 1), (0, 1)]
U = [(0, 0), (3, 0), (3, 3), (2, 3), (2, 1), (1, 1), (1, 3), (0, 3)]
ELL = [(0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)]


def _same(x: pc.NoFitPolygon, y: pc.NoFitPolygon) -> bool:
    return (shapely.to_wkb(x.region) == shapely.to_wkb(y.region)
            and np.array_equal(x.exact_fits, y.exact_fits)
            and np.array_equal(x.slides, y.slides)
            and np.array_equal(x.reference, y.reference) and x.tolerance == y.tolerance)


def _build(cache: Path) -> pc.NfpTable:
    return pc.nfp_table([SQUARE, U, ELL], [[0, 90], [0], [0, 180]], cache=cache,
                        progress=False, chunk_size=8)


def _swap_ranges(index: dict) -> None:
    a, b = index["entries"][:2]
    for k in ("offset", "length"):
        a[k], b[k] = b[k], a[k]


def _edit_tolerance(index: dict) -> None:
    index["entries"][0]["tolerance"] *= 1e6


def _edit_slide(index: dict) -> None:
    entry = next(e for e in index["entries"] if e["slides"])
    entry["slides"][0][1][1] += 0.5


def _edit_reference(index: dict) -> None:
    index["entries"][0]["reference"][0] += 1.0


def _add_exact_fit(index: dict) -> None:
    index["entries"][0]["exact_fits"].append([0.25, 0.25])


def _shift_offset(index: dict) -> None:
    index["entries"][1]["offset"] += 3


TAMPERED = {"swapped byte ranges": _swap_ranges, "edited tolerance": _edit_tolerance,
            "edited slide": _edit_slide, "edited reference": _edit_reference,
            "added exact fit": _add_exact_fit, "shifted offset": _shift_offset}


@pytest.mark.parametrize("how", list(TAMPERED))
def test_a_tampered_index_is_recomputed_not_served(tmp_path, how):
    cache = tmp_path / "cache"
    ref = _build(cache)
    shards = sorted((cache / SHARDS).glob("*.json"))
    # the shard holding a slide (the U's slot), so every edit has something to change
    path = next(p for p in shards if any(e["slides"] for e in json.loads(p.read_text())
                                        ["entries"]))
    index = json.loads(path.read_text())
    TAMPERED[how](index)
    path.write_text(json.dumps(index))
    with pytest.warns(CacheWarning, match="does not match its checksum"):
        table = _build(cache)
    assert table.computed == len(index["entries"])
    for key in ref:
        assert _same(ref[key], table[key]), key


BROKEN = {"an array": "[]", "null": "null", "deeply nested": "[" * 100_000 + "]" * 100_000,
          "nested past the limit": "[" * 40 + "]" * 40, "not JSON": "{",
          "a huge integer": '{"format": "polycontact-nfp-table", "format_version": 2, '
                            '"wkb": "x.wkb", "wkb_bytes": 1' + "0" * 400 + "}",
          "entries not a list": None, "an entry not an object": None}


@pytest.mark.parametrize("how", list(BROKEN))
def test_an_unreadable_index_is_a_warning_and_a_recomputation(tmp_path, how):
    cache = tmp_path / "cache"
    ref = _build(cache)
    path = sorted((cache / SHARDS).glob("*.json"))[0]
    count = len(json.loads(path.read_text())["entries"])
    text = BROKEN[how]
    if text is None:  # a well-formed index with a bad part (and its checksum recomputed)
        from polycontact.nfp_tables import _checksum

        index = json.loads(path.read_text())
        index["entries"] = {"a": 1} if how == "entries not a list" else [3, *index["entries"]]
        blob = (cache / SHARDS / index["wkb"]).read_bytes()
        index["blake2b"] = _checksum(index, blob)
        text = json.dumps(index)
    path.write_text(text)
    with pytest.warns(CacheWarning, match="ignoring shard"):
        table = _build(cache)
    assert table.computed == count
    for key in ref:
        assert _same(ref[key], table[key]), key
    with pytest.warns(CacheWarning):  # the damaged shard is still there, and skipped
        loaded = NfpTable.load(cache)
    assert loaded.loaded == ref.computed


def test_a_tampered_manifest_is_refused_by_load(tmp_path):
    cache = tmp_path / "cache"
    _build(cache)
    doc = json.loads((cache / MANIFEST).read_text())
    doc["orientations"][1] = [90.0]
    (cache / MANIFEST).write_text(json.dumps(doc))
    with pytest.raises(ValueError, match="does not match its checksum"):
        NfpTable.load(cache)
    (cache / MANIFEST).write_text("[" * 100_000)
    with pytest.raises(ValueError, match="no readable table.json"):
        NfpTable.load(cache)


def test_a_complete_cache_is_read_without_writing(tmp_path, monkeypatch):
    cache = tmp_path / "cache"
    ref = _build(cache)
    from polycontact import nfp_tables

    def refuse(path: Path, data: bytes) -> None:
        raise PermissionError(13, "Permission denied", str(path))

    monkeypatch.setattr(nfp_tables, "_atomic_write", refuse)  # a read-only directory
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        again = _build(cache)
    assert again.computed == 0 and again.loaded == ref.computed
