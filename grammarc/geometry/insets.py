"""Mitred insets of polygons that do not vanish before they should.

``offset(-d)`` keeps what lies at least d inside a face, with sharp corners: GEOS's mitred buffer. GEOS
(3.14 as measured) finds some nearly collapsing insets of rings of fewer than 9 coordinates empty although
the face's largest inscribed circle is wider than 2d (it takes the ring's offset curve for an inverted one
and drops it); the same outline with a point added on its edges comes out right. PRT keeps that sliver
(candler's roof on fuzz lot candler.tiny.44289, whose ``offset(-0.8)`` leaves the inside face its roof
pipes stand on: their corners as grammarc now places them within 1e-4 m of PRT's). An inset found empty is
taken again on the outline cut into ``PIECES`` pieces; the points this leaves on the inset's straight runs
are taken out again.
"""

from __future__ import annotations

import numpy as np
import shapely

#: How many pieces an outline is at least cut into where its inset comes out empty: GEOS checks rings of
#: fewer than 9 coordinates only.
PIECES = 16

#: How far (scope units, metres) a vertex may lie off the straight run through its neighbours and still be
#: taken out.
COLLINEAR = 1e-9


def mitred_insets(polygons: np.ndarray, distance: np.ndarray) -> np.ndarray:
    """Each polygon (k,) (shapely) moved out by ``distance`` (k,) (in when negative) with sharp corners: its
    mitred buffer, a buffer GEOS wrongly finds empty taken again on the outline cut into pieces."""
    distance = np.broadcast_to(np.asarray(distance, float), polygons.shape)
    inset = shapely.buffer(polygons, distance, join_style="mitre", mitre_limit=1e6)
    again = np.flatnonzero((distance < 0) & shapely.is_empty(inset) & ~shapely.is_empty(polygons))
    if len(again):
        cut = shapely.segmentize(polygons[again], shapely.length(polygons[again]) / PIECES)
        redone = shapely.buffer(cut, distance[again], join_style="mitre", mitre_limit=1e6)
        inset = inset.copy()
        inset[again] = shapely.simplify(redone, COLLINEAR, preserve_topology=False)
    return inset
