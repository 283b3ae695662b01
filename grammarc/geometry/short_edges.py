"""Short edges of lot rings collapsed as PRT collapses them in its initial shapes.

GIS footprints carry near-duplicate vertices (digitising twice, snapping, reprojection). PRT drops them
before a rule sees the lot, and which vertex goes decides the lot's first edge, hence its scope: measured
through PyPRT, an edge shorter than 0.8 mm (``TOL.merge``; 0.7999 mm collapses, 0.8 mm stays, at any
coordinate magnitude and lot size) loses one of its two ends, the one whose removal changes the ring
less (the triangle it makes with its other neighbour is smaller), the later one in the ring's order when
both are as small (three vertices on one line, or a ring closed by repeating its first vertex, whose
repetition goes). A lot whose first vertex goes starts at its successor. Collinear vertices
on edges of 0.8 mm or more stay, as PRT keeps them.

The rings are collapsed one after the other in a numba kernel, each in one walk around it: after a
removal the walk re-checks the edge that took the removed one's place, so a fine arc of 10^5 short
edges loses every other vertex in linear time rather than all of them.
"""

from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["collapse_short_edges"]


def collapse_short_edges(vertices: np.ndarray, ring_offsets: np.ndarray, tol: float
                         ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The rings with their short edges collapsed: which vertices stay, in which order, and where the edge
    of each vertex that goes is absorbed.

    Parameters
    ----------
    vertices : (V, 3) float64
        Ring vertices, ring after ring, open rings.
    ring_offsets : (R+1,) int64
        Ring ``r`` is ``vertices[ring_offsets[r]:ring_offsets[r+1]]``.
    tol : float
        Edges shorter than this collapse (metres).

    Returns
    -------
    order : (K,) int64
        The staying vertices, ring after ring, each ring from its first vertex: the original first, or,
        when it went, the vertex it collapsed into.
    counts : (R,) int64
        Vertices staying per ring; 2 (or fewer, as given) for a ring of fewer than 3 distinct vertices,
        which the caller reports.
    owner : (V,) int64
        For each vertex, the position in ``order`` of the staying vertex whose edge (to its successor)
        now covers the vertex's own edge: itself when it stays, else the staying vertex before it.
    """
    return _collapse(np.ascontiguousarray(vertices, dtype=np.float64),
                     np.ascontiguousarray(ring_offsets, dtype=np.int64), float(tol))


@njit(cache=True, nogil=True)
def _triangle(vertices, a, b, c):
    """Twice the area of the triangle (a, b, c) of vertex indices."""
    u0 = vertices[b, 0] - vertices[a, 0]
    u1 = vertices[b, 1] - vertices[a, 1]
    u2 = vertices[b, 2] - vertices[a, 2]
    w0 = vertices[c, 0] - vertices[a, 0]
    w1 = vertices[c, 1] - vertices[a, 1]
    w2 = vertices[c, 2] - vertices[a, 2]
    x = u1 * w2 - u2 * w1
    y = u2 * w0 - u0 * w2
    z = u0 * w1 - u1 * w0
    return np.sqrt(x * x + y * y + z * z)


@njit(cache=True, nogil=True)
def _collapse(vertices, ring_offsets, tol):
    n_vertices, n_rings = len(vertices), len(ring_offsets) - 1
    keep = np.ones(n_vertices, dtype=np.bool_)
    owner = np.arange(n_vertices)
    following = np.empty(n_vertices, dtype=np.int64)
    previous = np.empty(n_vertices, dtype=np.int64)
    first = ring_offsets[:-1].copy()
    counts = np.empty(n_rings, dtype=np.int64)
    for r in range(n_rings):
        start, stop = ring_offsets[r], ring_offsets[r + 1]
        for v in range(start, stop):
            following[v] = v + 1 if v + 1 < stop else start
            previous[v] = v - 1 if v > start else stop - 1
        alive = stop - start
        current = start
        unchanged = 0  # edges checked since the last removal: a whole turn without one ends the ring
        while alive > 2 and unchanged < alive:
            a = current
            b = following[a]
            d0 = vertices[b, 0] - vertices[a, 0]
            d1 = vertices[b, 1] - vertices[a, 1]
            d2 = vertices[b, 2] - vertices[a, 2]
            if d0 * d0 + d1 * d1 + d2 * d2 >= tol * tol:
                current = b
                unchanged += 1
                continue
            area_a, area_b = _triangle(vertices, previous[a], a, b), _triangle(vertices, a, b, following[b])
            gone = a if area_a < area_b or (area_a == area_b and a > b) else b
            if gone == first[r]:
                first[r] = b if gone == a else a
            before = previous[gone]
            keep[gone] = False
            owner[gone] = before
            following[before] = following[gone]
            previous[following[gone]] = before
            alive -= 1
            current = before
            unchanged = 0
        counts[r] = alive
    order = np.empty(counts.sum(), dtype=np.int64)
    position = np.empty(n_vertices, dtype=np.int64)
    k = 0
    for r in range(n_rings):
        v = first[r]
        for _ in range(counts[r]):
            order[k] = v
            position[v] = k
            k += 1
            v = following[v]
    # a vertex that went may have gone into one that went later: follow to the one that stays (into a new
    # array: positions written over ``owner`` would be followed as vertices by the vertices after)
    absorbed = np.empty(n_vertices, dtype=np.int64)
    for v in range(n_vertices):
        o = owner[v]
        while not keep[o]:
            o = owner[o]
        absorbed[v] = position[o]
    return order, counts, absorbed
