"""Other projects' polygon test suites, run as external suites: JTS's XML tests and
Boost.Geometry's overlay and relate cases (``../shared/datasets/ext3/``, sources and
licences in its README). Skipped in a clone without ``shared/`` beside it.

Every polygon of the suites that GEOS calls valid must be accepted (no refusal), and
every polygon GEOS calls invalid refused, unless exact rational arithmetic
(:func:`exact_overlap.is_valid`) says GEOS is wrong. Each pair of GEOS-valid polygons
(a MultiPolygon part by part, as in ``test_geos_relate``) is classified in both orders
and must get GEOS's state: the interiors meet (DE-9IM entry II not ``F``) ->
penetrating; else the boundaries meet -> contact; else separate. For Boost's relate
cases Boost's own expected matrix is a second oracle, read the same way.

Our states are decided within a tolerance and GEOS's answers are not; where they
differ, the difference must be one of these, each checked independently of both:

- *thin overlap*: GEOS says the interiors meet, we say contact, and the overlap holds
  no disc wider than the tolerance: exactly (:func:`exact_overlap.widest_section`),
  its longest vertical and its longest horizontal section are not both above twice
  the tolerance (a disc of radius r inside has both sections 2r long through its
  centre). Real data is full of these: the isochrones' and the robustness cases'
  polygons share edges up to a few float spacings.
- *GEOS wrong*: GEOS says the interiors meet where, exactly, they do not overlap at all
  (widest sections zero): Boost's ``case_81``, a polygon whose triangular hole touches
  the edge it shares with another; GEOS's relate reports II = 2 where the exact area of
  the overlap is 0 (and GEOS's own intersection is empty).
- *thin gap*: GEOS says separate, we say contact, and GEOS's distance is at most the
  tolerance.

The full run is marked slow; a sample of named cases (the ones real data refused
before: the OpenStreetMap isochrones, Boost's ``issue_690`` and
``ggl_list_20110716_enrico``, the tolerance cases above) runs always.
"""

from __future__ import annotations

import json
from collections import Counter
from pathlib import Path

import pytest
import shapely
from exact_overlap import is_valid, widest_section

import polycontact as pc

EXT3 = Path(__file__).resolve().parents[3] / "shared" / "datasets" / "ext3"
_CODE = {pc.State.SEPARATE: 0, pc.State.CONTACT: 1, pc.State.PENETRATING: 2}


def _matrix_state(matrix: str) -> int:
    if matrix[0] != "F":
        return 2
    return 1 if any(matrix[k] != "F" for k in (1, 3, 4)) else 0


def _load() -> list[tuple[str, str, str, str | None]]:
    """``(name, wkt a, wkt b, expected DE-9IM or None)`` of every case of the suites."""
    out: list[tuple[str, str, str, str | None]] = []
    jts = json.loads((EXT3 / "jts" / "polygon_pairs.json").read_text())
    out += [(f"jts:{c['file']}#{c['case']}", c["a"], c["b"], None) for c in jts["cases"]]
    boost = json.loads((EXT3 / "boost_geometry" / "overlay_cases.json").read_text())
    out += [(f"boost:{k}", w[0], w[1], None) for k, w in boost["cases"].items() if len(w) >= 2]
    relate = json.loads((EXT3 / "boost_geometry" / "relate_areal_areal.json").read_text())
    out += [(f"boost-relate:{c['line']}", c["a"], c["b"], c["matrix"]) for c in relate["cases"]]
    return out


CASES = _load() if EXT3.is_dir() else []
needs_data = pytest.mark.skipif(not EXT3.is_dir(), reason="no ../shared/datasets/ext3")


def _parts(wkt: str) -> list[shapely.Geometry] | None:
    """The polygons of a WKT (None if it is not a (Multi)Polygon shapely reads)."""
    try:
        geom = shapely.from_wkt(wkt)
    except shapely.errors.ShapelyError:
        return None
    if geom.geom_type not in ("Polygon", "MultiPolygon"):
        return None
    return [p for p in shapely.get_parts(geom) if not p.is_empty]


def _without_empty_rings(p: shapely.Geometry) -> shapely.Geometry:
    """``p`` less its empty interior rings (``POLYGON ((...), EMPTY)``), which hold
    nothing and make GEOS's relate crash."""
    if all(not r.is_empty for r in p.interiors):
        return p
    return shapely.Polygon(p.exterior, [r for r in p.interiors if not r.is_empty])


def _accepted(poly: shapely.Geometry) -> bool:
    try:
        pc.Shape(poly)
    except pc.InvalidShapeError:
        return False
    return True


def _verdict(x: shapely.Geometry, y: shapely.Geometry, want: int) -> str:
    """How our state of x against y stands to ``want`` (see the module docstring);
    ``"wrong: ..."`` when it is none of the accepted kinds."""
    r = pc.classify(x, y)
    got = _CODE[r.state]
    if got == want:
        return "same"
    eps = r.tolerance
    if got == 1 and want == 2:
        v, h = widest_section(x, y), widest_section(x, y, swap=True)
        if v == 0 or h == 0:
            return "GEOS wrong"
        if min(v, h) <= 2 * eps:
            return "thin overlap"
        return f"wrong: contact, overlap sections {float(v):.3g}, {float(h):.3g} > 2 x {eps:.3g}"
    if got == 1 and want == 0 and shapely.distance(x, y) <= eps:
        return "thin gap"
    return f"wrong: {r.state.value}, expected state {want} (tolerance {eps:.3g})"


def check_case(a_wkt: str, b_wkt: str, matrix: str | None, seen: set[bytes]) -> Counter[str]:
    """Every check of one case, counted by verdict; ``seen`` skips polygons whose
    acceptance an earlier case checked."""
    counts: Counter[str] = Counter()
    pa, pb = _parts(a_wkt), _parts(b_wkt)
    if pa is None or pb is None:
        counts["not polygons"] += 1
        return counts
    for p in pa + pb:
        if p.wkb in seen:
            continue
        seen.add(p.wkb)
        want = p.is_valid
        if _accepted(p) == want:
            counts["accepted" if want else "refused"] += 1
        elif is_valid(p) != want:
            counts["GEOS wrong on validity"] += 1
        else:
            counts[f"wrong: {'refused' if want else 'accepted'} {p.wkt[:80]}"] += 1
    pa, pb = [_without_empty_rings(p) for p in pa], [_without_empty_rings(p) for p in pb]
    valid_a = [p for p in pa if p.is_valid]
    valid_b = [p for p in pb if p.is_valid]
    for x in valid_a:
        for y in valid_b:
            for u, v in ((x, y), (y, x)):
                counts[_verdict(u, v, _matrix_state(shapely.relate(u, v)))] += 1
    if matrix is not None and len(valid_a) == len(pa) and len(valid_b) == len(pb):
        # Boost's matrix of the whole geometries: the worst state over the part pairs
        got = max(_CODE[pc.classify(x, y).state] for x in pa for y in pb)
        want = _matrix_state(matrix)
        counts["same as Boost" if got == want else f"wrong: Boost says {want}, got {got}"] += 1
    return counts


_NAMED = [
    "boost:issue_690", "boost:ggl_list_20110716_enrico", "boost:case_81",
    "boost:ggl_list_20110820_christophe", "boost:issue_1100", "boost:ticket_9081",
    "jts:robust/overlay/TestOverlay-geos-234.xml#0", "jts:robust/MagnifyTopology.xml#8",
    "jts:robust/overlay/TestOverlay-misc-2.xml#1",
] + [f"jts:robust/overlay/TestOverlay-isochrone.xml#{k}" for k in (6, 17, 57, 85, 86, 91)]
SAMPLE = [c for c in CASES if c[0] in _NAMED] + CASES[::40]


@needs_data
@pytest.mark.parametrize(("name", "a", "b", "matrix"), SAMPLE, ids=[c[0] for c in SAMPLE])
def test_sample_of_the_suites(name, a, b, matrix):
    counts = check_case(a, b, matrix, set())
    assert not [k for k in counts if k.startswith("wrong")], counts


@needs_data
def test_the_polygons_real_data_had_refused_are_accepted_and_classified():
    assert {c[0] for c in SAMPLE} >= set(_NAMED)
    seen: set[bytes] = set()
    counts = sum((check_case(*c[1:], seen) for c in CASES if c[0] in _NAMED), Counter())
    # issue_690 (vertex 11 2.6e-14 from edge 12), enrico (an edge of 7.35e-14 at
    # coordinates up to 300), the isochrones (vertices 6e-15 apart), the empty hole of
    # geos-234: all accepted; case_81 is where GEOS is wrong
    assert counts["refused"] == 0 and counts["GEOS wrong"] == 2, counts
    assert not [k for k in counts if k.startswith("wrong")], counts


@needs_data
@pytest.mark.slow
def test_every_case_of_the_suites():
    seen: set[bytes] = set()
    counts: Counter[str] = Counter()
    for name, a, b, matrix in CASES:
        for key, n in check_case(a, b, matrix, seen).items():
            counts[f"{key} ({name})" if key.startswith("wrong") else key] += n
    assert not [k for k in counts if k.startswith("wrong")], counts
    # 2 457 distinct polygons, 37 of them invalid for GEOS and exactly; 16 420 states
    # checked against GEOS, 64 against Boost's own matrices
    assert counts["accepted"] + counts["refused"] == 2457, counts
    assert counts["refused"] == 37, counts
    checks = ("same", "thin overlap", "GEOS wrong", "thin gap")
    assert sum(counts[k] for k in checks) == 16420, counts
    assert counts["same as Boost"] == 64, counts
