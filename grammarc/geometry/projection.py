"""Geometry seen along an axis: CityEngine's ``footprint()``, the outline a shape casts on a plane.

Each face is projected (its in-plane coordinates dropped of the axis it is seen along), faces seen edge-on
cover no area and drop out, and each shape's projected faces are united (GEOS, all shapes at once) and
snapped to a nanometre grid, so that faces meeting at an edge leave no sliver between them.
"""

from __future__ import annotations

import numpy as np
import shapely

from grammarc.constants import TOL
from grammarc.geometry.setback import union_by_group
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
    counts = np.diff(ring_offsets)
    # close every ring: its vertices, then its first again
    closed_offsets = offsets_from_counts(counts + 1)
    ring = segment_of(closed_offsets)
    step = np.arange(len(ring)) - closed_offsets[ring]
    index = ring_offsets[ring] + np.where(step < counts[ring], step, 0)
    faces = shapely.from_ragged_array(shapely.GeometryType.POLYGON, points[index], (closed_offsets, face_offsets)) \
        if len(face_offsets) > 1 else np.empty(0, dtype=object)
    faces = shapely.make_valid(faces)
    keep = shapely.area(faces) > TOL.area_floor
    return shapely.set_precision(union_by_group(faces[keep], face_shape[keep], n), _SNAP)
