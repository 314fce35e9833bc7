"""Every named limit and default of polycontact, each with its unit and why.

The public functions read these and pass them to the compiled kernels as arguments
(Numba freezes a module global into the compiled code, so a kernel never reads one of
these). The limits on work (``MAX_SUM_VERTICES``, ``MAX_CLIP_TESTS``,
``MAX_EDGE_PAIRS``) are read at each call, so a program that means to wait longer or to
use more memory may raise them: ``polycontact.limits.MAX_CLIP_TESTS = 10**9``. A call
that would exceed one estimates its work before starting and raises a
:class:`~polycontact.WorkLimitError` that names the estimate and the limit; the time of
impact's budget is its ``max_iterations`` argument. Constants that belong to one algorithm's proof or to the layout of its
buffers (a grid's size, a threshold between two ways of getting the same answer, a
rounding allowance derived in a kernel's docstring) stay beside that kernel in
``polycontact._kernels``.

Units: "length" is the unit of the coordinates, "time" that of ``t_max``; "ulps"
counts units of 2**-52 of a magnitude (the float spacing of numbers of that size is
at most one of them).

Examples
--------
>>> from polycontact import limits
>>> limits.RELATIVE_TOLERANCE, limits.TIME_TOLERANCE
(1e-12, 0.0001)
"""

from __future__ import annotations

__all__ = [
    "RELATIVE_TOLERANCE",
    "ROUNDING_ULPS",
    "COORDINATE_LIMIT",
    "EXTENT_FLOOR",
    "TIME_TOLERANCE",
    "SAMPLES",
    "CONTACT_RESOLUTION",
    "MAX_ITERATIONS",
    "BROAD_PHASE_INFLATION",
    "MAX_SLICES",
    "SWEPT_ROUNDING_ULPS",
    "ANGLE_TOLERANCE",
    "HOLE_WIDTH_FACTOR",
    "SNAP_FACTOR",
    "MAX_SUM_VERTICES",
    "MAX_CLIP_TESTS",
    "MAX_EDGE_PAIRS",
    "EAR_CLIPPING_MAX",
    "PIECES_CACHE_SIZE",
    "THREAD_WORK",
    "TASK_SECONDS",
    "JSON_MAX_DEPTH",
    "NOTICE_AFTER",
]

# -- distances (see polycontact.tolerances) ------------------------------------------

#: Fraction of a body's extent (dimensionless): 1e-12 of the larger side of the largest
#: body counts as zero. Far below any gap a user means (a shift of 1e-9 of a body's
#: size is seen, 1000 times the tolerance), far above the rounding of arithmetic on
#: coordinates of that size.
RELATIVE_TOLERANCE = 1e-12

#: Ulps of the largest absolute coordinate (64 × 2**-52 ≈ 1.4e-14 of it): the tolerance never
#: falls below this. A translation or rotation of a small body far from the origin
#: moves its vertices by rounding errors of a few ulps of its coordinates; 64 is well
#: above that and still resolves 1e-4 at 1e9.
ROUNDING_ULPS = 64.0

#: Largest absolute coordinate accepted (length). The kernels form products of up to three
#: coordinate differences (areas, centroids, Minkowski sums): (2e100)**3 = 8e300 stays
#: finite in float64 (max ~1.8e308).
COORDINATE_LIMIT = 1e100

#: Smallest body extent accepted (length): products of three lengths (1e-300) stay
#: normal floats.
EXTENT_FLOOR = 1e-100

# -- time of impact ------------------------------------------------------------------

#: Default accuracy of an impact time (time): the paper's threshold. It decides how
#: precisely ``time`` is reported, never whether a hit is found.
TIME_TOLERANCE = 1e-4

#: Default number of time points per broad-phase interval of the sampled method
#: (count): the paper's n.
SAMPLES = 10

#: Contact resolution of the exact method (fraction of L_A + L_B, the sum of the
#: bounding radii): near contact the search probes in steps during which no point of
#: either body moves more than this relative to the other. One millionth of the
#: bodies' size is far below any gap a user draws (the paper's own resolution, 1e-4 s
#: at 10–25 m/s on 300 m bodies, is 3e-6 of the size) and keeps a sliding contact
#: affordable to follow.
CONTACT_RESOLUTION = 1e-6

#: Default iteration budget of the exact method (iterations: a step, or a
#: classification at the end of a probe). Reached only by long contacts that last
#: while the bodies turn; the result then says so (``OUT_OF_ITERATIONS``).
MAX_ITERATIONS = 1_000_000

#: Relative enlargement of the sum of the bounding radii in the broad phase
#: (dimensionless), so that rounding cannot drop an instant at which the circles
#: exactly graze (a double root): the intervals are conservative, never too short.
BROAD_PHASE_INFLATION = 1e-12

#: Most time slices (space–time boxes) per body in the swept bounds of many moving
#: bodies (count). A body gets one slice per bounding radius its centroid travels;
#: past this many, the boxes of a long, fast path grow longer instead of more numerous.
MAX_SLICES = 16

#: Growth of the swept boxes beyond each body's bounding radius (ulps of the body's
#: reach: its radius plus the absolute terms of its centroid's path over [0, t_max]). 16 of
#: them are the pairwise broad phase's own widening
#: (``_kernels.broad_phase.rounding_allowance``, which sums the same terms of both
#: bodies); the rest cover the rounding of the centroids' distance there and of the boxes
#: (a few each), so the boxes never leave out a pair the pairwise call would search.
#: Far from the origin this is the float spacing of the positions, not a fraction of
#: them: a unit body at 1e9 is grown by ~3e-5.
SWEPT_ROUNDING_ULPS = 64.0

# -- no-fit polygon and penetration depth --------------------------------------------

#: Angular gap (radians) below which the convex sums around a point are taken to close
#: up: edge directions of sums computed in float64 carry errors near 1e-15 rad.
ANGLE_TOLERANCE = 1e-9

#: Width under which a hole or part of a no-fit region is dropped (distance
#: tolerances; twice the area over the perimeter): narrower holes are rounding
#: artefacts where closed sums meet exactly (an exact fit shows up as a pinhole of
#: about 1e-15 of the coordinates), not positions where A fits. Also the tolerance of
#: the check that a candidate exact fit or slide touches without overlapping.
HOLE_WIDTH_FACTOR = 16.0

#: Distance (distance tolerances) within which candidate exact fits and slide ends are
#: snapped to the convex sums' vertices and edge crossings: they are found within a
#: few tolerances of those.
SNAP_FACTOR = 64.0

#: Most vertices of convex sums built for one no-fit polygon or one penetration depth
#: (vertices). Beyond, the call is refused with an error (``NfpTooLargeError``,
#: ``DepthTooLargeError``) instead of being killed by the system for want of memory:
#: a no-fit polygon costs about 100 bytes per vertex of sums with the outline's work
#: arrays (1 GB here), a depth about 80 with its frames and sort keys, so this one
#: limit keeps both within a few GB. The depth's count is estimated before its bodies
#: are decomposed (a lower bound: the vertex-edge contacts nearer than a known escape).
#: Read at each call.
MAX_SUM_VERTICES = 10_000_000

#: Most tests of an edge against a convex sum that the outline of one no-fit polygon
#: may take (tests): the sums listed near each sum edge that can lie on the outline,
#: counted once the sums are built and before any is clipped. A test costs 20 ns to a
#: few microseconds (a long sum that the edge enters is read whole), so this is about
#: 5 to 10 s of clipping; beyond, ``NfpTooLargeError``. Two interlocking regular combs
#: of 400 vertices need 5e7, of 800 vertices 4e8. Read at each call.
MAX_CLIP_TESTS = 100_000_000

#: Most components one entrance block built with ``method="pairs"`` may have
#: (parallelograms, one per pair of edges: m n for bodies of m and n edges). Each costs
#: a Shapely geometry and a Python object, about 1 kB and 25 µs, so this is about
#: 0.25 GB and 6 s; beyond, ``EntranceBlockTooLargeError`` (``method="swept"`` makes
#: one component per edge of B). Read at each call.
MAX_EDGE_PAIRS = 250_000

#: Rings of up to this many vertices are cut into convex pieces by ear clipping
#: (vertices): quadratic, but cheaper than a GEOS triangulation up to this size.
#: Larger rings, and shapes with holes, are triangulated by GEOS.
EAR_CLIPPING_MAX = 64

#: Convex decompositions kept, keyed by coordinates (entries): a nesting code that
#: asks about many pairs of the same pieces decomposes each piece once.
PIECES_CACHE_SIZE = 4096

# -- threads and distributed batches -----------------------------------------------

#: Work per thread (seconds) below which a parallel call starts no further thread:
#: starting a thread and handing it its share costs tens of microseconds, under 2 % of
#: this (see :mod:`polycontact._threads`).
THREAD_WORK = 2e-3

#: Least work of one Dask task (seconds): a task costs the scheduler and the transfers
#: about a millisecond, and the results a round trip, so a task of this much work loses
#: about 2 % to them, while a table of 1.5 s of work still fills 16 workers (tasks of
#: 0.2 s would leave nine of them idle); tasks are made larger only to keep at most
#: four per worker thread in whole rounds (:func:`polycontact.distributed.task_size`).
TASK_SECONDS = 0.05

# -- files and the command line ------------------------------------------------------

#: Deepest nesting of arrays and objects accepted in a JSON file or text (levels): the
#: structures polycontact reads (bodies, scenes, layouts, instances, cache indexes) are
#: a few levels deep (a GeoJSON polygon is 4), and anything deeper is refused before it
#: is walked, not left to Python's recursion limit.
JSON_MAX_DEPTH = 32

#: Seconds a step of a command may run before it says so on stderr (the environment
#: variable ``POLYCONTACT_NOTICE_AFTER`` overrides it): a few seconds is past any step
#: of an ordinary call, so a notice means large input.
NOTICE_AFTER = 3.0
