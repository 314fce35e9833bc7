"""Shared pytest setup: hypothesis profiles, the non-interactive matplotlib backend, no
command-line notices of long steps unless a test asks."""

import os

from hypothesis import HealthCheck, settings

os.environ.setdefault("MPLBACKEND", "Agg")
# The command line says on stderr when a step runs long; a loaded test machine would make
# that depend on timing: tests that check those notices ask for them (0 s).
os.environ.setdefault("POLYCONTACT_NOTICE_AFTER", "inf")

# "default" for local runs (fresh random examples each run); "ci" is selected by .ci/run,
# which passes --hypothesis-seed derived from the commit: the same commit replays the same
# examples (a CI verdict can be reproduced), a new commit draws new ones (no example set
# is replayed forever); no example database, so nothing but the seed decides. "deep" draws
# many more examples for a search before a release; "nojit" for the pure-Python run of the
# kernels (NUMBA_DISABLE_JIT=1), which is slower, so it draws fewer examples. Tests that
# need another count say so with profiles.examples(n), which scales with the profile.
settings.register_profile(
    "default", max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow]
)
settings.register_profile(
    "ci",
    max_examples=300,
    database=None,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow],
)
settings.register_profile(
    "deep", max_examples=3000, deadline=None, suppress_health_check=[HealthCheck.too_slow]
)
settings.register_profile(
    "nojit", max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow]
)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "default"))
