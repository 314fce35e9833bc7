"""Convex pieces of a shape, for the convex Minkowski sums of the no-fit polygon and of
the penetration depth.

A ring (no holes) that is convex is its own piece; one of up to
:data:`~polycontact.limits.EAR_CLIPPING_MAX` vertices is cut by ear clipping
(:func:`polycontact._kernels.decompose.ring_pieces`). Larger rings and shapes with holes
are triangulated by GEOS (its constrained Delaunay triangulation: no vertex added) and
the triangles merged into convex pieces
(:func:`polycontact._kernels.decompose.convex_pieces`). Decompositions are cached by
coordinates, so that many queries on the same shapes decompose each once.

Examples
--------
>>> import numpy as np
>>> ell = np.array([(0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)], float)
>>> xy, starts = pieces_packed(ell, np.array([0, 6]))
>>> len(starts) - 1, len(xy)
(2, 8)
"""

from __future__ import annotations

import functools
from typing import Any

import numpy as np
import shapely

from .limits import EAR_CLIPPING_MAX, PIECES_CACHE_SIZE, RELATIVE_TOLERANCE, ROUNDING_ULPS

__all__ = ["pieces_packed", "pieces_of_geometry", "clear_cache"]

_CACHE: dict[tuple[bytes, bytes], tuple[np.ndarray, np.ndarray]] = {}


@functools.cache
def _decompose() -> Any:
    """The decomposition kernels, imported on first use (Numba loads only when needed)."""
    from ._kernels import decompose

    return decompose


def pieces_packed(xy: np.ndarray, starts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Convex CCW pieces of packed loops (the first the outer one, CCW; then the holes,
    CW), packed like a shape's loops: ``(xy, starts)``; cached by coordinates."""
    key = (xy.tobytes(), starts.tobytes())
    hit = _CACHE.get(key)
    if hit is not None:
        return hit
    ok = False
    if len(starts) == 2:
        ok, pxy, pst = _decompose().ring_pieces(
            xy, RELATIVE_TOLERANCE, ROUNDING_ULPS, EAR_CLIPPING_MAX)
        pieces = (pxy, pst)
    if not ok:
        # (shapely.Polygon is slow with an empty hole list)
        loops = [xy[starts[k] : starts[k + 1]] for k in range(len(starts) - 1)]
        geom = (shapely.Polygon(loops[0], loops[1:]) if len(loops) > 1
                else shapely.polygons(shapely.linearrings(loops[0])))
        pieces = pieces_of_geometry(geom)
    if len(_CACHE) >= PIECES_CACHE_SIZE:
        _CACHE.pop(next(iter(_CACHE)))
    _CACHE[key] = pieces
    return pieces


def pieces_of_geometry(geom: Any) -> tuple[np.ndarray, np.ndarray]:
    """Convex pieces of a shapely (Multi)Polygon: GEOS triangulation, then merging."""
    tris = shapely.get_parts(shapely.constrained_delaunay_triangles(geom))
    coords = shapely.get_coordinates(tris).reshape(-1, 4, 2)[:, :3, :]
    # GEOS adds no vertex: triangles share exact coordinates, hence vertex indices
    vxy, idx = np.unique(coords.reshape(-1, 2), axis=0, return_inverse=True)
    pieces: tuple[np.ndarray, np.ndarray] = _decompose().convex_pieces(
        vxy, idx.reshape(-1, 3), RELATIVE_TOLERANCE, ROUNDING_ULPS)
    return pieces


def clear_cache() -> None:
    """Forget every cached decomposition (for benchmarks that time a cold call)."""
    _CACHE.clear()
