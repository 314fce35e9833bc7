"""Example counts that follow the hypothesis profile.

A test that needs fewer (or more) examples than the profile's default says so relative
to the "default" profile's 200; ``examples(n)`` scales that with the active profile, so
``HYPOTHESIS_PROFILE=deep`` searches 15 times harder everywhere and ``nojit`` less,
instead of a fixed ``max_examples`` overriding every profile.

>>> examples(100).max_examples >= 1
True
"""

from __future__ import annotations

from hypothesis import settings

#: max_examples of the "default" profile (conftest.py): the unit of ``examples``.
DEFAULT_EXAMPLES = 200


def examples(n: int) -> settings:
    """Settings drawing ``n`` examples under the default profile, scaled for the others."""
    return settings(max_examples=max(1, round(n * settings().max_examples / DEFAULT_EXAMPLES)))
