"""polycontact: whether, when and where two 2D polygons collide.

Built on the entrance block of Shi's Contact Theory. The public names are re-exported
here; they are loaded on first use so that ``import polycontact`` stays fast (no Numba,
no matplotlib, no compilation at import).

Examples
--------
>>> import polycontact as pc
>>> a = pc.Shape([(0, 0), (1, 0), (1, 1), (0, 1)])
>>> b = pc.Shape([(1, 0), (2, 0), (2, 1), (1, 1)])
>>> pc.classify(a, b).state
<State.CONTACT: 'contact'>
"""

from __future__ import annotations

import importlib
import os
from typing import Any

# Numba's OpenMP threads sleep between parallel calls unless the environment says
# otherwise (read when Numba starts them): spinning threads take the cores the calling
# thread needs on a busy machine (the threading policy, :mod:`polycontact._threads`).
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

from .errors import (DepthTooLargeError, EntranceBlockTooLargeError, InvalidSceneError,
                     InvalidShapeError, NfpTooLargeError, PolycontactError, WorkLimitError)
from .shape import Shape, ShapeLike

__version__ = "0.1.0"

# public name -> module that defines it
_LAZY = {
    "RELATIVE_TOLERANCE": "tolerances",
    "default_tolerance": "tolerances",
    # classification of a pair
    "State": "relation",
    "Feature": "relation",
    "Relation": "relation",
    "classify": "relation",
    "classify_many": "relation",
    "RelationBatch": "relation",
    # compiling the kernels
    "warmup": "compiling",
    # entrance block
    "EntranceBlock": "entrance",
    "Component": "entrance",
    "entrance_block": "entrance",
    # motion and time of impact
    "Motion": "motion",
    "broad_phase_intervals": "broad_phase",
    "Impact": "impact",
    "ImpactStatus": "impact",
    "time_of_impact": "impact",
    # many moving bodies
    "time_of_impact_many": "impacts",
    "ImpactBatch": "impacts",
    "first_impacts": "impacts",
    "first_impact": "impacts",
    "PairImpact": "impacts",
    "PairImpacts": "impacts",
    "Scene": "scene",
    "SceneBody": "scene",
    "load_scene": "scene",
    # no-fit polygon
    "NoFitPolygon": "nfp",
    "no_fit_polygon": "nfp",
    "inner_fit_polygon": "nfp",
    # many bodies
    "World": "world",
    "WorldBody": "world",
    "Contacts": "world",
    "Query": "world",
    "Sweep": "world",
    # nesting instances and NFP tables
    "Instance": "esicup",
    "read_esicup": "esicup",
    "NfpTable": "nfp_tables",
    "nfp_table": "nfp_tables",
}

__all__ = [
    "PolycontactError",
    "InvalidShapeError",
    "WorkLimitError",
    "NfpTooLargeError",
    "DepthTooLargeError",
    "EntranceBlockTooLargeError",
    "InvalidSceneError",
    "Shape",
    "ShapeLike",
    *_LAZY,
]


def __getattr__(name: str) -> Any:
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'polycontact' has no attribute {name!r}")
    value = getattr(importlib.import_module(f".{module}", __name__), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(__all__)
