"""Polygons divided by a line through a point on each of two of their edges (Stiny's ice-ray grammar).

A ring (its vertices in order, the last joined to the first) is cut by the segment from the point at
fraction ``t1`` of its edge ``e1`` (from vertex ``e1`` to the next) to the point at ``t2`` of edge ``e2``
(edges numbered modulo the ring's length). The first piece runs from the first point forward along the
ring to the second, the second piece from the second point on to the first: both keep the ring's
winding. A point at an end of its edge is that vertex (it is not repeated). The cut is meant for convex
rings (an ice-ray's cells are); the segment of a concave ring may leave it.
"""

from __future__ import annotations

import numpy as np
from numba import njit

#: Points closer than this (in the rings' units) are one vertex of a piece.
SAME_POINT = 1e-9


def cut_rings(xy: np.ndarray, offsets: np.ndarray, e1: np.ndarray, t1: np.ndarray, e2: np.ndarray,
              t2: np.ndarray):
    """Cut rings ``xy`` (V, 2) float64 with ``offsets`` (n+1,) by the segments of ``e1``, ``t1``, ``e2``,
    ``t2`` (n,) each (edge numbers, any integers; fractions, clipped to [0, 1]).

    Returns the first pieces and the second pieces as ragged rings, ``(xy, offsets)`` each, one piece per
    ring, and ``bad`` (n,) bool: the rings whose two edges are one edge, or whose cut leaves a piece of
    fewer than three vertices (a cut along an edge, or through one vertex only); their pieces are empty.
    """
    count = np.diff(offsets)
    first = np.mod(np.asarray(e1, np.int64), count)
    second = np.mod(np.asarray(e2, np.int64), count)
    return _cut(np.ascontiguousarray(xy, np.float64), np.asarray(offsets, np.int64), first,
                np.clip(np.asarray(t1, np.float64), 0.0, 1.0), second, np.clip(np.asarray(t2, np.float64), 0.0, 1.0))


@njit(cache=True, nogil=True)
def _cut(xy, offsets, e1, t1, e2, t2):
    n = len(offsets) - 1
    # at most every vertex and the two points in each piece
    bound = 0
    for i in range(n):
        bound += offsets[i + 1] - offsets[i] + 2
    out = np.empty((2, bound, 2))
    counts = np.zeros((2, n), np.int64)
    bad = np.zeros(n, np.bool_)
    at = np.zeros(2, np.int64)
    point = np.empty((2, 2))
    for i in range(n):
        start, m = offsets[i], offsets[i + 1] - offsets[i]
        if e1[i] == e2[i]:
            bad[i] = True
            continue
        for k in range(2):
            e, t = (e1[i], t1[i]) if k == 0 else (e2[i], t2[i])
            a, b = start + e, start + (e + 1) % m
            point[k, 0] = xy[a, 0] + t * (xy[b, 0] - xy[a, 0])
            point[k, 1] = xy[a, 1] + t * (xy[b, 1] - xy[a, 1])
        for piece in range(2):
            ea, eb = (e1[i], e2[i]) if piece == 0 else (e2[i], e1[i])
            begin = at[piece]
            _push(out[piece], at, piece, begin, point[piece, 0], point[piece, 1])
            v = (ea + 1) % m
            while True:
                _push(out[piece], at, piece, begin, xy[start + v, 0], xy[start + v, 1])
                if v == eb:
                    break
                v = (v + 1) % m
            _push(out[piece], at, piece, begin, point[1 - piece, 0], point[1 - piece, 1])
            # the ring closes: its last point may be its first
            last = at[piece] - 1
            if last > begin and abs(out[piece, last, 0] - out[piece, begin, 0]) <= SAME_POINT \
                    and abs(out[piece, last, 1] - out[piece, begin, 1]) <= SAME_POINT:
                at[piece] = last
            counts[piece, i] = at[piece] - begin
        if counts[0, i] < 3 or counts[1, i] < 3:
            bad[i] = True
            at[0] -= counts[0, i]
            at[1] -= counts[1, i]
            counts[0, i] = 0
            counts[1, i] = 0
    return out[0, :at[0]].copy(), _offsets(counts[0]), out[1, :at[1]].copy(), _offsets(counts[1]), bad


@njit(cache=True, nogil=True, inline="always")
def _push(dest, at, piece, begin, x, y):
    """Append (x, y) to the piece that starts at ``begin`` unless it is the piece's last point again."""
    k = at[piece]
    if k > begin and abs(dest[k - 1, 0] - x) <= SAME_POINT and abs(dest[k - 1, 1] - y) <= SAME_POINT:
        return
    dest[k, 0] = x
    dest[k, 1] = y
    at[piece] = k + 1


@njit(cache=True, nogil=True)
def _offsets(counts):
    out = np.zeros(len(counts) + 1, np.int64)
    for i in range(len(counts)):
        out[i + 1] = out[i] + counts[i]
    return out
