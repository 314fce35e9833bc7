"""Reading JSON files and texts: every defect is a ValueError that says what is wrong.

``json.loads`` raises ``RecursionError`` on deeply nested arrays and a plain
``ValueError`` on an integer longer than Python converts; the structures polycontact
reads (bodies, scenes, layouts, instances, cache indexes) are never more than a few
levels deep, so anything deeper than :data:`polycontact.limits.JSON_MAX_DEPTH` is refused
before it is walked.

>>> load_json('{"t_max": 5, "bodies": []}')
{'t_max': 5, 'bodies': []}
>>> load_json("[" * 100 + "]" * 100)
Traceback (most recent call last):
...
ValueError: nested deeper than 32 levels
"""

from __future__ import annotations

import json
from typing import Any

from .limits import JSON_MAX_DEPTH

__all__ = ["load_json"]


def load_json(text: str | bytes) -> Any:
    """The value of JSON ``text``; ``ValueError`` with the reason if it is not JSON, holds
    an integer too long to convert, or is nested deeper than
    :data:`polycontact.limits.JSON_MAX_DEPTH`."""
    try:
        data = json.loads(text)
    except RecursionError:
        raise ValueError(f"nested deeper than {JSON_MAX_DEPTH} levels") from None
    except ValueError as exc:  # a JSONDecodeError, or an integer too long to convert
        raise ValueError(str(exc)) from None
    level = [data] if isinstance(data, (list, dict)) else []
    depth = 0
    while level:
        depth += 1
        if depth > JSON_MAX_DEPTH:
            raise ValueError(f"nested deeper than {JSON_MAX_DEPTH} levels")
        level = [v for item in level for v in (item.values() if isinstance(item, dict) else item)
                 if isinstance(v, (list, dict))]
    return data
