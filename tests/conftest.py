"""Shared pytest setup: hypothesis profiles and the non-interactive matplotlib backend."""

import os

from hypothesis import HealthCheck, settings

os.environ.setdefault("MPLBACKEND", "Agg")

# "default" for local runs; "ci" is selected by .ci/run; "nojit" for the pure-Python
# run of the kernels (NUMBA_DISABLE_JIT=1), which is slower, so it draws fewer examples.
settings.register_profile(
    "default", max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow]
)
settings.register_profile(
    "ci", max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow]
)
settings.register_profile(
    "nojit", max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow]
)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "default"))
