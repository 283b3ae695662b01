"""Geometry seen along an axis: CityEngine's ``footprint()``, the outline a shape casts on a plane.

Each face is projected (its in-plane coordinates dropped of the axis it is seen along), faces seen edge-on
cover no area and drop out, and each shape's projected faces are united (GEOS, all shapes at once) and
snapped to a nanometre grid, so that faces meeting at an edge leave no sliver between them.
"""

from __future__ import annotations

import numpy as np
import shapely

from grammarc.constants import TOL
from grammarc.geometry.overlay import union_by_group
from grammarc.ragged import offsets_from_counts, segment_of

#: The grid (metres) the projected outlines are snapped to.
_SNAP = 1e-9


def projected_outlines(points: np.ndarray, ring_offsets: np.ndarray, face_offsets: np.ndarray,
                       face_shape: np.ndarray, n: int) -> np.ndarray:
    """The outlines (n,) shapely (multi)polygons, empty where none, of n shapes' faces projected.

    points (V, 2) float64: the faces' vertices already projected (the two coordinates kept); ring_offsets
    (R+1,) and face_offsets (F+1,) int64 their open rings and faces, as ``geometry.queries.Faces``;
    face_shape (F,) the shape of each face.
    """
    faces = polygons_from_rings(points, ring_offsets, face_offsets)
    faces = shapely.make_valid(faces)
    keep = shapely.area(faces) > TOL.area_floor
    return shapely.set_precision(union_by_group(faces[keep], face_shape[keep], n), _SNAP)


def polygons_from_rings(points: np.ndarray, ring_offsets: np.ndarray, poly_offsets: np.ndarray) -> np.ndarray:
    """Shapely polygons (P,) of open rings: points (V, 2), ring_offsets (R+1,) into them, poly_offsets (P+1,)
    into the rings (each polygon's outer ring first); every ring has three points or more."""
    if len(poly_offsets) < 2:
        return np.empty(0, dtype=object)
    counts = np.diff(ring_offsets)
    # close every ring: its points, then its first again
    closed_offsets = offsets_from_counts(counts + 1)
    ring = segment_of(closed_offsets)
    step = np.arange(len(ring)) - closed_offsets[ring]
    index = ring_offsets[ring] + np.where(step < counts[ring], step, 0)
    return shapely.from_ragged_array(shapely.GeometryType.POLYGON, points[index], (closed_offsets, poly_offsets))
