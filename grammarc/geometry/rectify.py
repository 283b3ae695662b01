"""CityEngine's ``rectify(angle)``: edges nearly parallel to a scope axis made parallel to it.

Each edge of a face's rings (in the face's plane, its two scope axes u and v) whose direction lies within
``angle`` degrees of u or of v is snapped: it becomes a line along that axis. Consecutive snapped edges along
one axis form a run that becomes one line, at the length-weighted mean of their midpoints across it (a
slightly bent wall becomes one straight wall); other edges keep their lines. Each vertex becomes the meeting
point of its two edges' lines (where they are parallel, its projection onto the second), and vertices
inside a run go. As the reference warns, a large angle can fold a ring over itself or close a hole: the
result is made valid and may fall apart. All rings of a batch are done at once with numpy.
"""

from __future__ import annotations

import numpy as np
import shapely

from grammarc.constants import TOL
from grammarc.geometry.projection import polygons_from_rings
from grammarc.ragged import offsets_from_counts

#: Pointer-jumping rounds that find each run's first edge (enough for runs of 2**40 edges).
_JUMPS = 40


def rectified(polygons: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """The polygons (n,) (shapely, in their planes' (u, v)) rectified with ``angle`` (n,) degrees: shapely
    geometries (n,), polygons or multipolygons, empty where nothing is left."""
    n = len(polygons)
    rings, ring_poly = shapely.get_rings(polygons, return_index=True)
    points, point_ring = shapely.get_coordinates(rings, return_index=True)
    closing = np.r_[point_ring[1:] != point_ring[:-1], True] if len(points) else np.zeros(0, dtype=bool)
    pts, ring = points[~closing], point_ring[~closing]
    counts = np.bincount(ring, minlength=len(rings))
    offsets = offsets_from_counts(counts)
    local = np.arange(len(ring)) - offsets[ring]
    size = np.maximum(counts[ring], 1)
    nxt, prv = offsets[ring] + (local + 1) % size, offsets[ring] + (local - 1) % size
    step = pts[nxt] - pts
    length = np.hypot(step[:, 0], step[:, 1])
    phi = np.degrees(np.arctan2(step[:, 1], step[:, 0]))
    along_u = np.rint(phi / 90.0) % 2 == 0
    snap = (np.abs(phi - 90.0 * np.rint(phi / 90.0)) < angle[ring_poly[ring]]) & (length > TOL.zero)
    # a snapped edge continues the run of its previous edge along the same axis
    same = snap & snap[prv] & (along_u == along_u[prv])
    first = np.where(same, prv, np.arange(len(ring)))
    for _ in range(_JUMPS):
        first = first[first]
    mid = 0.5 * (pts + pts[nxt])
    across = np.where(along_u, mid[:, 1], mid[:, 0])
    weight = np.bincount(first, weights=length, minlength=len(ring))
    level = np.bincount(first, weights=length * across, minlength=len(ring)) / np.where(weight > 0, weight, 1.0)
    # each edge's line: a point and a unit direction
    base = np.where(snap[:, None], np.where(along_u[:, None], np.stack([mid[:, 0], level[first]], 1),
                                            np.stack([level[first], mid[:, 1]], 1)), pts)
    axis = np.where(along_u[:, None], [1.0, 0.0], [0.0, 1.0])
    direction = np.where(snap[:, None], axis, step / np.where(length > 0, length, 1.0)[:, None])
    a, da, b, db = base[prv], direction[prv], base, direction
    cross = da[:, 0] * db[:, 1] - da[:, 1] * db[:, 0]
    parallel = np.abs(cross) < 1e-9
    gap = b - a
    s = (gap[:, 0] * db[:, 1] - gap[:, 1] * db[:, 0]) / np.where(parallel, 1.0, cross)
    onto = np.einsum("ij,ij->i", pts - b, db)
    moved = np.where(parallel[:, None], b + onto[:, None] * db, a + s[:, None] * da)
    keep = ~same
    kept_counts = np.bincount(ring[keep], minlength=len(rings))
    # a ring left with fewer than three vertices goes, and with an outer ring its polygon's holes
    whole = kept_counts >= 3
    outer = np.r_[True, ring_poly[1:] != ring_poly[:-1]] if len(rings) else np.zeros(0, dtype=bool)
    alive = np.ones(n, dtype=bool)
    alive[ring_poly[outer & ~whole]] = False
    use = whole & alive[ring_poly]
    out = np.full(n, shapely.Polygon(), dtype=object)
    if not use.any():
        return out
    vertex = keep & use[ring]
    poly_counts = np.bincount(ring_poly[use], minlength=n)
    made = polygons_from_rings(moved[vertex], offsets_from_counts(kept_counts[use]),
                               offsets_from_counts(poly_counts[poly_counts > 0]))
    out[poly_counts > 0] = shapely.make_valid(made)
    return out
