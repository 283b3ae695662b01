"""The boundary edges of polygons as columns, the data every setback rule reads (``geometry.setback``):
each edge with its inward normal, its polygon, its neighbours along its ring and whether it lies on a hole.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import shapely

from grammarc.constants import TOL
from grammarc.ragged import offsets_from_counts


@dataclass(frozen=True)
class Edges:
    """The boundary edges of m polygons: ``start``, ``end`` (E, 2); ``inward`` (E, 2) unit normals
    pointing into the polygon; ``poly`` (E,) the polygon of each edge; ``prev``, ``next`` (E,) the
    neighbouring edges along the same ring; ``vertex`` (E,) each one's start among the vertices of the
    polygons' open rings, all rings one after the other (as ``shapely.to_ragged_array`` lists them);
    ``hole`` (E,) whether the edge lies on a hole."""

    start: np.ndarray
    end: np.ndarray
    inward: np.ndarray
    poly: np.ndarray
    prev: np.ndarray
    next: np.ndarray
    vertex: np.ndarray
    hole: np.ndarray


def polygon_edges(polygons: np.ndarray) -> Edges:
    """The edges of shapely polygons (m,), exterior rings and holes, zero-length edges dropped."""
    rings, ring_poly = shapely.get_rings(polygons, return_index=True)
    hole = np.r_[False, ring_poly[1:] == ring_poly[:-1]] if len(rings) else np.zeros(0, dtype=bool)
    points, point_ring = shapely.get_coordinates(rings, return_index=True)
    last = np.r_[point_ring[1:] != point_ring[:-1], True] if len(points) else np.zeros(0, dtype=bool)
    first = np.flatnonzero(~last)
    step = points[first + 1] - points[first]
    length = np.hypot(step[:, 0], step[:, 1])
    first = first[length > TOL.zero]
    start, end, ring = points[first], points[first + 1], point_ring[first]
    step = end - start
    tangent = step / np.hypot(step[:, 0], step[:, 1])[:, None]
    signed_area = np.bincount(ring, weights=start[:, 0] * end[:, 1] - end[:, 0] * start[:, 1],
                              minlength=len(rings))
    left = np.stack([-tangent[:, 1], tangent[:, 0]], axis=1)
    # the interior lies left of a counter-clockwise exterior ring and right of a counter-clockwise hole
    inward = np.where(((signed_area[ring] > 0) != hole[ring])[:, None], left, -left)
    counts = np.bincount(ring, minlength=len(rings))
    offsets = offsets_from_counts(counts)
    local = np.arange(len(ring)) - offsets[ring]
    size = np.maximum(counts[ring], 1)
    return Edges(start, end, inward, ring_poly[ring], offsets[ring] + (local - 1) % size,
                 offsets[ring] + (local + 1) % size, first - ring, hole[ring])


def cosines(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The cosines (k,) of the angles between the vectors a and b (k, 2)."""
    norms = np.hypot(a[:, 0], a[:, 1]) * np.hypot(b[:, 0], b[:, 1])
    return np.einsum("ij,ij->i", a, b) / np.where(norms > 0, norms, 1.0)
