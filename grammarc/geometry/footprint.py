"""Lots to initial shapes: the scope CityEngine gives a footprint, and its polygon in the store.

A lot's scope has x along its first edge (v0 -> v1), y along the footprint's normal (up for a
counter-clockwise map ring), z = x cross y, and its origin where the footprint's bounding box in that frame
starts, so that the footprint lies in the positive quadrant and the scope size is (extent x, 0, extent z).
A footprint that is exactly its scope rectangle takes the box fast path (``geom = -1``); any other
(concave, holes, not a rectangle) is stored normalized in the chunk's ``PolygonStore``. Everything is
computed for all lots at once over the ragged rings.
"""

from __future__ import annotations

import numpy as np

from grammarc.constants import TOL
from grammarc.model.lots import Lots
from grammarc.ragged import ragged_take, segment_of, segment_reduce


def lot_scopes(lots: Lots):
    """Scopes of all lots and their vertices in scope coordinates.

    Returns origin (L, 3), axes (L, 3, 3) (rows x, y, z), size (L, 3), all float64, and ``local``
    (V, 3) float64: every ring vertex in its lot's scope coordinates (the origin subtracted).
    """
    vertices = lots.vertices
    ring_of_lot_start = lots.lot_offsets[:-1]
    first = lots.ring_offsets[ring_of_lot_start]
    v0, v1 = vertices[first], vertices[first + 1]
    # Newell normal of each exterior ring: sum over edges of (p - q) x (p + q) / 2, componentwise.
    ext_vertices, ext_offsets = ragged_take(lots.ring_offsets, ring_of_lot_start)
    p = vertices[ext_vertices]
    ring_index = segment_of(ext_offsets)
    nxt = np.arange(len(p)) + 1
    last = ext_offsets[1:] - 1
    nxt[last] = ext_offsets[:-1]
    q = p[nxt]
    terms = np.stack([
        (p[:, 1] - q[:, 1]) * (p[:, 2] + q[:, 2]),
        (p[:, 2] - q[:, 2]) * (p[:, 0] + q[:, 0]),
        (p[:, 0] - q[:, 0]) * (p[:, 1] + q[:, 1]),
    ], axis=1)
    normal = segment_reduce(np.add, terms, ext_offsets, 0.0)
    del ring_index
    y = normal / np.linalg.norm(normal, axis=1, keepdims=True)
    x = v1 - v0
    x -= np.einsum("ij,ij->i", x, y)[:, None] * y
    x /= np.linalg.norm(x, axis=1, keepdims=True)
    z = np.cross(x, y)
    axes = np.stack([x, y, z], axis=1)

    vertex_lot = segment_of(lots.lot_offsets)[segment_of(lots.ring_offsets)]
    local = np.einsum("vj,vij->vi", vertices - v0[vertex_lot], axes[vertex_lot])
    lot_vertex_offsets = lots.ring_offsets[lots.lot_offsets]
    low = segment_reduce(np.minimum, local, lot_vertex_offsets, 0.0)
    high = segment_reduce(np.maximum, local, lot_vertex_offsets, 0.0)
    origin = v0 + np.einsum("li,lij->lj", low, axes)
    size = high - low
    size[:, 1] = 0.0
    return origin, axes, size, local - low[vertex_lot]


def footprint_polygons(lots: Lots, size: np.ndarray, local: np.ndarray):
    """Which lots are their scope rectangle, and the normalized polygons of the others.

    Returns ``is_rect`` (L,) bool and, for the lots that are not, ``coords`` (V', 2) float64 (u, v) in
    [0, 1] along scope (x, z), ``ring_offsets`` (R'+1,) int64 and ``poly_offsets`` (P+1,) int64.
    """
    ring_counts = np.diff(lots.ring_offsets)
    rings_per_lot = np.diff(lots.lot_offsets)
    ext = lots.lot_offsets[:-1]
    four = (rings_per_lot == 1) & (ring_counts[ext] == 4)
    # Shoelace area of every lot's rings in scope (x, z); holes have the opposite sign.
    vertex_ring = segment_of(lots.ring_offsets)
    start = lots.ring_offsets[:-1][vertex_ring]
    at = np.arange(len(local))
    nxt = np.where(at + 1 < lots.ring_offsets[1:][vertex_ring], at + 1, start)
    cross = local[:, 0] * local[nxt, 2] - local[nxt, 0] * local[:, 2]
    area = np.abs(segment_reduce(np.add, cross, lots.ring_offsets[lots.lot_offsets], 0.0)) / 2
    box = size[:, 0] * size[:, 2]
    is_rect = four & (np.abs(area - box) <= TOL.rect * np.maximum(box, 1.0))

    poly_lots = np.flatnonzero(~is_rect)
    rings, poly_offsets = ragged_take(lots.lot_offsets, poly_lots)
    vertex, ring_offsets = ragged_take(lots.ring_offsets, rings)
    vertex_lot = segment_of(lots.lot_offsets)[vertex_ring]
    extent = np.where(size[:, [0, 2]] > TOL.zero, size[:, [0, 2]], 1.0)
    coords = local[vertex][:, [0, 2]] / extent[vertex_lot[vertex]]
    return is_rect, coords, ring_offsets, poly_offsets
