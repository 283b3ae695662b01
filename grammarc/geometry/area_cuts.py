"""Where a plane across a scope axis cuts off a given area of a shape's faces: CityEngine's ``splitArea``.

``splitArea`` lays its parts out as ``split`` does, but in area: a part of ``'0.25`` takes a quarter of the
geometry's area, not of the scope's length. The derivation lays the parts out with the split's own kernel
over each shape's total area, then turns each cumulative area into the position along the axis where the
faces before it have that area. The area before a position only grows with it, so bisection finds it;
each step clips every face (outline and holes, Sutherland-Hodgman against ``coordinate[axis] <= t``) and
sums their vector areas (Newell), numba over all cuts at once. The reference means the operation for
flat shapes; on a solid it measures the surface, as ``geometry.area`` does.
"""

from __future__ import annotations

import numpy as np
from numba import njit

#: Bisection steps: the interval shrinks to 2^-60 of the shape's extent, below any tolerance.
STEPS = 60


@njit(cache=True, nogil=True)
def _area_before(verts, ring_offsets, face_offsets, f0, f1, axis, t):
    """The area of faces f0..f1 where ``coordinate[axis] <= t``."""
    total = 0.0
    for f in range(f0, f1):
        nx = ny = nz = 0.0
        for r in range(face_offsets[f], face_offsets[f + 1]):
            r0, r1 = ring_offsets[r], ring_offsets[r + 1]
            count = r1 - r0
            kept = np.empty((2 * count + 2, 3))
            k = 0
            for j in range(count):
                s_ = verts[r0 + (j - 1) % count]
                e_ = verts[r0 + j]
                s_in = s_[axis] <= t
                e_in = e_[axis] <= t
                if s_in != e_in:
                    kept[k] = s_ + (t - s_[axis]) / (e_[axis] - s_[axis]) * (e_ - s_)
                    k += 1
                if e_in:
                    kept[k] = e_
                    k += 1
            for j in range(k):
                p = kept[j]
                q = kept[(j + 1) % k]
                nx += (p[1] - q[1]) * (p[2] + q[2])
                ny += (p[2] - q[2]) * (p[0] + q[0])
                nz += (p[0] - q[0]) * (p[1] + q[1])
        total += 0.5 * np.sqrt(nx * nx + ny * ny + nz * nz)
    return total


@njit(cache=True, nogil=True)
def total_areas(verts, ring_offsets, face_offsets, shape_offsets):
    """The area of each shape's faces (n,): faces ``shape_offsets`` (n+1,) of ragged rings in scope units."""
    n = len(shape_offsets) - 1
    out = np.zeros(n)
    for g in range(n):
        out[g] = _area_before(verts, ring_offsets, face_offsets, shape_offsets[g], shape_offsets[g + 1], 0, np.inf)
    return out


@njit(cache=True, nogil=True)
def area_positions(verts, ring_offsets, face_offsets, shape_offsets, axis, shape, area, extent, total):
    """Positions (k,) along ``axis`` where the faces of ``shape`` (k,) before them have ``area`` (k,): 0 for
    no area, the scope's ``extent`` (k,) for the shape's ``total`` (k,) or more."""
    out = np.empty(len(shape))
    for c in range(len(shape)):
        g = shape[c]
        f0, f1 = shape_offsets[g], shape_offsets[g + 1]
        if area[c] <= 0.0 or f0 == f1:
            out[c] = 0.0
            continue
        if area[c] >= total[c]:
            out[c] = extent[c]
            continue
        lo, hi = np.inf, -np.inf
        for v in range(ring_offsets[face_offsets[f0]], ring_offsets[face_offsets[f1]]):
            lo = min(lo, verts[v, axis])
            hi = max(hi, verts[v, axis])
        for _ in range(STEPS):
            mid = 0.5 * (lo + hi)
            if _area_before(verts, ring_offsets, face_offsets, f0, f1, axis, mid) < area[c]:
                lo = mid
            else:
                hi = mid
        out[c] = 0.5 * (lo + hi)
    return out
