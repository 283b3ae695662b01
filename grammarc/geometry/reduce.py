"""Fewer vertices for polygons: CityEngine's ``reduceGeometry(tolerance)`` on faces.

The reference removes the share ``tolerance`` of the geometry's vertices by edge collapses that change
its look the least. On a polygon's rings an edge collapse that keeps one end is the removal of a vertex,
and the removal that changes the face least is the vertex whose triangle with its neighbours is the
smallest (Visvalingam and Whyatt's order): each ring loses ``floor(tolerance * n)`` of its ``n`` vertices
that way, one at a time with its neighbours' triangles measured again, and keeps three at least. A
triangle or a quadrilateral is left whole, as a scope's rectangle is: taking a corner off a rectangle
makes another shape, not a simpler one.
``reduce_rings`` does it for all the rings of a batch (numba).
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, nogil=True)
def reduce_rings(coords, ring_offsets, fraction):
    """Which vertices (V,) bool the rings keep: coords (V, 2) in metres, ring_offsets (R+1,), the share of
    each ring's vertices to remove (R,)."""
    keep = np.ones(len(coords), np.bool_)
    for r in range(len(ring_offsets) - 1):
        r0, r1 = ring_offsets[r], ring_offsets[r + 1]
        n = r1 - r0
        if n <= 4:
            continue
        drop = min(int(np.floor(fraction[r] * n + 1e-9)), n - 3)
        if drop <= 0:
            continue
        prev = np.empty(n, np.int64)
        nxt = np.empty(n, np.int64)
        for j in range(n):
            prev[j] = (j - 1) % n
            nxt[j] = (j + 1) % n
        alive = np.ones(n, np.bool_)
        for _ in range(drop):
            best, smallest = -1, np.inf
            for j in range(n):
                if not alive[j]:
                    continue
                a, b, c = coords[r0 + prev[j]], coords[r0 + j], coords[r0 + nxt[j]]
                area = abs((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))
                if area < smallest:
                    best, smallest = j, area
            alive[best] = False
            nxt[prev[best]] = nxt[best]
            prev[nxt[best]] = prev[best]
        for j in range(n):
            keep[r0 + j] = alive[j]
    return keep
