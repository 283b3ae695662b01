"""The distance between two oriented boxes, many pairs at once (CityEngine's ``minimumDistance``, which
measures from a shape's scope to the scopes of labelled shapes).

A box is an origin, three orthonormal axes (rows) and a size along each, any of which may be 0 (a face's
rectangle, an edge's segment, a point). The distance is the least distance between a point of one box and
a point of the other, solids included: 0 when they meet.

Exact for every pair: two convex polytopes meet unless an axis separates them, and for boxes the 15 axes
of their faces and edge pairs suffice (``_meet``, the separating-axis test). Apart, their nearest points
lie on a corner of one and anywhere in the other (a corner clamped into the other box's frame) or on an
edge of each: a face against a face or an edge is parallel to it, so a corner or an edge pair reaches the
same distance. So the distance is the least of 16 corner-to-box and 144 edge-to-edge distances.
"""

from __future__ import annotations

import numpy as np
from numba import njit

#: Corners of the unit box and its 12 edges (corner pairs).
_CORNERS = np.array([[i & 1, i >> 1 & 1, i >> 2 & 1] for i in range(8)], dtype=np.float64)
_EDGES = np.array([[a, b] for a in range(8) for b in range(a + 1, 8) if (a ^ b).bit_count() == 1], dtype=np.int64)
#: Cross products of parallel axes shorter than this are no separating axis (the face axes stand for them).
_PARALLEL = 1e-9


def box_distances(a_origin: np.ndarray, a_axes: np.ndarray, a_size: np.ndarray,
                  b_origin: np.ndarray, b_axes: np.ndarray, b_size: np.ndarray) -> np.ndarray:
    """The least distance (p,) float64 between the boxes of p pairs: origins (p, 3), axes (p, 3, 3)
    (rows, orthonormal) and sizes (p, 3) of the first and of the second box of each pair; 0 where they
    meet."""
    out = np.empty(len(a_origin))
    if len(out):
        _distances(*(np.ascontiguousarray(x, dtype=np.float64) for x in (a_origin, a_axes, a_size, b_origin,
                                                                        b_axes, b_size)), _CORNERS, _EDGES, out)
    return out


@njit(cache=True, nogil=True)
def _distances(ao, aa, asz, bo, ba, bsz, unit, edges, out):  # pragma: no cover - numba
    for i in range(len(out)):
        ca, cb = _corners(ao[i], aa[i], asz[i], unit), _corners(bo[i], ba[i], bsz[i], unit)
        if _meet(ao[i], aa[i], asz[i], bo[i], ba[i], bsz[i]):
            out[i] = 0.0
            continue
        best = np.inf
        for k in range(8):
            best = min(best, _point_box(ca[k], bo[i], ba[i], bsz[i]), _point_box(cb[k], ao[i], aa[i], asz[i]))
        for e in range(len(edges)):
            for f in range(len(edges)):
                best = min(best, _segments(ca[edges[e, 0]], ca[edges[e, 1]], cb[edges[f, 0]], cb[edges[f, 1]]))
        out[i] = best


@njit(cache=True, nogil=True)
def _corners(origin, axes, size, unit):  # pragma: no cover - numba
    corners = np.empty((8, 3))
    for k in range(8):
        for d in range(3):
            corners[k, d] = origin[d] + unit[k, 0] * size[0] * axes[0, d] + unit[k, 1] * size[1] * axes[1, d] \
                + unit[k, 2] * size[2] * axes[2, d]
    return corners


@njit(cache=True, nogil=True)
def _meet(ao, aa, asz, bo, ba, bsz):  # pragma: no cover - numba
    """Whether no face or edge-pair axis separates the boxes (closed: touching boxes meet)."""
    centre = np.empty(3)
    for d in range(3):
        centre[d] = bo[d] - ao[d]
        for k in range(3):
            centre[d] += 0.5 * (bsz[k] * ba[k, d] - asz[k] * aa[k, d])
    axis = np.empty(3)
    for n in range(15):
        if n < 3:
            axis[:] = aa[n]
        elif n < 6:
            axis[:] = ba[n - 3]
        else:
            u, v = aa[(n - 6) // 3], ba[(n - 6) % 3]
            axis[0] = u[1] * v[2] - u[2] * v[1]
            axis[1] = u[2] * v[0] - u[0] * v[2]
            axis[2] = u[0] * v[1] - u[1] * v[0]
            if np.sqrt(axis[0] ** 2 + axis[1] ** 2 + axis[2] ** 2) < _PARALLEL:
                continue
        reach = 0.0
        for k in range(3):
            reach += 0.5 * asz[k] * abs(aa[k, 0] * axis[0] + aa[k, 1] * axis[1] + aa[k, 2] * axis[2])
            reach += 0.5 * bsz[k] * abs(ba[k, 0] * axis[0] + ba[k, 1] * axis[1] + ba[k, 2] * axis[2])
        if abs(centre[0] * axis[0] + centre[1] * axis[1] + centre[2] * axis[2]) > reach:
            return False
    return True


@njit(cache=True, nogil=True)
def _point_box(point, origin, axes, size):  # pragma: no cover - numba
    """The distance from ``point`` to the box (solid): its offsets outside the box along each axis."""
    total = 0.0
    for k in range(3):
        w = (point[0] - origin[0]) * axes[k, 0] + (point[1] - origin[1]) * axes[k, 1] \
            + (point[2] - origin[2]) * axes[k, 2]
        outside = max(0.0, -w, w - size[k])
        total += outside * outside
    return np.sqrt(total)


@njit(cache=True, nogil=True)
def _segments(p1, q1, p2, q2):  # pragma: no cover - numba
    """The distance between segments p1-q1 and p2-q2 (either may be a point): the nearest parameters of
    the two lines, clamped to the segments in turn (Ericson, Real-Time Collision Detection, 5.1.9)."""
    d1, d2, r = q1 - p1, q2 - p2, p1 - p2
    a, e, f = d1 @ d1, d2 @ d2, d2 @ r
    if a <= 1e-18 and e <= 1e-18:
        s = t = 0.0
    elif a <= 1e-18:
        s, t = 0.0, min(max(f / e, 0.0), 1.0)
    else:
        c = d1 @ r
        if e <= 1e-18:
            s, t = min(max(-c / a, 0.0), 1.0), 0.0
        else:
            b = d1 @ d2
            denom = a * e - b * b
            s = min(max((b * f - c * e) / denom, 0.0), 1.0) if denom > 1e-18 else 0.0
            t = (b * s + f) / e
            if t < 0.0:
                s, t = min(max(-c / a, 0.0), 1.0), 0.0
            elif t > 1.0:
                s, t = min(max((b - c) / a, 0.0), 1.0), 1.0
    gap = p1 + d1 * s - (p2 + d2 * t)
    return np.sqrt(gap @ gap)
