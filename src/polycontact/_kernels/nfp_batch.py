"""Kernel: the no-fit polygons of many pairs of one-ring shapes in one call, without the
GIL, in the stored form of an NFP table.

Each pair runs what :func:`polycontact.no_fit_polygon` runs for two shapes without
holes (:func:`polycontact._kernels.nfp.ring_entrance`, then the verification of the
exact fits and slides, :func:`polycontact._kernels.fits.touching_contacts`), with the
same arguments, and writes its region as ISO WKB (little-endian float64, the bytes of
``shapely.to_wkb(region, byte_order=1)`` for a one-ring polygon). A pair this kernel
does not finish is flagged, for the caller to compute through the public function: a
shape with holes, a ring too large for ear clipping, sums beyond their limit, an
outline that did not link into rings, a region of other than one kept ring, a
reference too far for the pair's size (checked as the public function checks it).

Shapes are packed as the World packs its bodies: ``xy`` (V, 2) holds every loop of
every shape; shape ``s`` has ``nl[s]`` loops whose rows start at ``ls[lo[s]:lo[s] +
nl[s]]`` and end at ``ls[lo[s] + nl[s]]``.
"""

from __future__ import annotations

import numpy as np

from .jit import njit
from .fits import touching_contacts
from .nfp import ring_entrance
from .tolerance import tolerance_for

#: Bytes of a one-ring polygon's WKB header: byte order, type, rings, points.
WKB_HEADER = 13


@njit(cache=True, nogil=True)
def _grown(buf, need):
    """``buf``, or a copy of it at least twice as long when it holds fewer than
    ``need`` entries (its first axis)."""
    if need <= buf.shape[0]:
        return buf
    out = np.empty((max(need, 2 * buf.shape[0]),) + buf.shape[1:], buf.dtype)
    out[: buf.shape[0]] = buf
    return out


@njit(cache=True, nogil=True)
def _put_u32(blob, at, value):
    for k in range(4):
        blob[at + k] = (value >> (8 * k)) & 255


@njit(cache=True, nogil=True)
def _put_ring_wkb(blob, at, buf, nv):
    """Write at ``at`` the WKB of the polygon of one closed ring of ``nv`` points, given
    as ``buf[:2 * nv]`` (x0, y0, x1, ...)."""
    blob[at] = 1  # little-endian
    _put_u32(blob, at + 1, 3)
    _put_u32(blob, at + 5, 1)
    _put_u32(blob, at + 9, nv)
    bits = buf[: 2 * nv].copy().view(np.uint64)
    w = at + WKB_HEADER
    for i in range(bits.shape[0]):
        v = bits[i]
        for k in range(8):
            blob[w + k] = (v >> np.uint64(8 * k)) & np.uint64(255)
        w += 8


@njit(cache=True, nogil=True)
def _ring(xy, ls, lo, s):
    """The one loop of shape ``s`` and its starts (0, n)."""
    r0 = ls[lo[s]]
    r1 = ls[lo[s] + 1]
    starts = np.empty(2, np.int64)
    starts[0] = 0
    starts[1] = r1 - r0
    return xy[r0:r1], starts


@njit(cache=True, nogil=True)
def nfp_pairs(shapes, pairs, refs, settings):
    """The no-fit polygons of shape ``pairs[k, 0]`` (A, orbiting, its reference point
    at ``refs[k]``) around shape ``pairs[k, 1]`` (B, fixed), k in order.

    ``shapes`` = ``(xy, ls, lo, nl, magnitude, extent)`` (the packing of the module's
    docstring, and each shape's largest |coordinate| and the larger side of its box);
    ``settings`` = ``(rel_tol, ulps, ang_tol, snap_f, near_f, max_ear, max_sum,
    max_tests, check_reference)``: the arguments of ``ring_entrance`` and whether the references
    are the origin, refused (flagged) as ``polycontact.nfp`` refuses them when float64
    cannot tell the region's features apart there.

    Returns ``(blob, wkb_ends, fits, fit_ends, slides, slide_ends, tolerances, flagged)``:
    the regions' WKB one after the other in ``blob`` (uint8) with each pair's end, the
    exact fits (F, 2) and slides (S, 2, 2) with each pair's end, each pair's tolerance,
    and the indices k of the pairs left to the caller (nothing written for them).
    """
    xy, ls, lo, nl, magnitude, extent = shapes
    rel_tol, ulps, ang_tol, snap_f, near_f, max_ear, max_sum, max_tests, check_reference = (
        settings)
    count = pairs.shape[0]
    blob = np.empty(count * 256, np.uint8)
    wkb_ends = np.empty(count, np.int64)
    fits = np.empty((16, 2))
    fit_ends = np.empty(count, np.int64)
    slides = np.empty((16, 2, 2))
    slide_ends = np.empty(count, np.int64)
    tolerances = np.zeros(count)
    flagged = np.empty(count, np.int64)
    n_flagged = 0
    w = 0
    nf = 0
    ns = 0
    for k in range(count):
        a = pairs[k, 0]
        b = pairs[k, 1]
        ax = refs[k, 0]
        ay = refs[k, 1]
        xa, sa = _ring(xy, ls, lo, a)
        xb, sb = _ring(xy, ls, lo, b)
        head = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
        buf = np.empty(0)
        eps = 0.0
        nv = 0
        ok = nl[a] == 1 and nl[b] == 1
        if ok and check_reference:
            reach = magnitude[a] + magnitude[b]
            ok = tolerance_for(0.0, reach, rel_tol, ulps) < min(extent[a], extent[b])
        if ok:
            head, buf = ring_entrance(xb, xa, ax, ay, -1.0, rel_tol, ulps, ang_tol, snap_f,
                                      near_f, max_ear, max_sum, max_tests)
            eps = head[1]
            nv = int(head[5])
            # done here: the sums made (ok), the outline linked (status 1), one ring that
            # is kept (not thinner than the width under which the region drops a ring)
            ok = (head[0] == 1.0 and head[2] == 1.0 and head[4] == 1.0
                  and 2.0 * buf[2 * nv + 2] > near_f * eps * buf[2 * nv + 3])
        if not ok:
            flagged[n_flagged] = k
            n_flagged += 1
        else:
            blob = _grown(blob, w + WKB_HEADER + 16 * nv)
            _put_ring_wkb(blob, w, buf, nv)
            w += WKB_HEADER + 16 * nv
            tolerances[k] = eps
            nc = int(head[6])
            if nc:
                n_pts = int(head[3])
                off = 2 * nv + 4  # the ring's coordinates, its starts (2), area and length
                cand = buf[off : off + 4 * nc].copy().reshape(nc, 4)
                near = near_f * eps
                got_fits, got_slides = touching_contacts(cand[:n_pts, :2].copy(),
                                                         cand[n_pts:], near, xa, sa, xb, sb,
                                                         ax, ay, near)
                fits = _grown(fits, nf + got_fits.shape[0])
                fits[nf : nf + got_fits.shape[0]] = got_fits
                nf += got_fits.shape[0]
                slides = _grown(slides, ns + got_slides.shape[0])
                slides[ns : ns + got_slides.shape[0]] = got_slides
                ns += got_slides.shape[0]
        wkb_ends[k] = w
        fit_ends[k] = nf
        slide_ends[k] = ns
    return (blob[:w], wkb_ends, fits[:nf], fit_ends, slides[:ns], slide_ends, tolerances,
            flagged[:n_flagged])
