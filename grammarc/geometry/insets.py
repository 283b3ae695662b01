"""Mitred insets of polygons that do not vanish before they should.

``offset(-d)`` keeps what lies at least d inside a face, with sharp corners: GEOS's mitred buffer. GEOS
(3.14 as measured) finds some nearly collapsing insets of rings of fewer than 9 coordinates empty although
the face's largest inscribed circle is wider than 2d (it takes the ring's offset curve for an inverted one
and drops it); the same outline with a point added on its edges comes out right. PRT keeps that sliver
(candler's roof on fuzz lot candler.tiny.44289, whose ``offset(-0.8)`` leaves the inside face its roof
pipes stand on: their corners as grammarc now places them within 1e-4 m of PRT's). An inset found empty is
taken again on the outline cut into ``PIECES`` pieces; the points this leaves on the inset's straight runs
are taken out again.

GEOS's mitred buffer also cuts the whole mitre of every reflex corner out of the inset, where PRT's inset
is a wavefront's (a straight skeleton's): a reflex corner whose edge the wavefront closes before it has
moved the distance is gone from then on, and the neighbours' lines meet instead. A narrow arm's reflex
root then leaves GEOS's inset a notch past the other moved edge's line that PRT's has not (massing's
concave.57869, a 3 cm notch that made the inset's edges, and so its per-edge setbacks, three too many;
concave.57617: 0.1 m^2). Where a face's wavefront ends a reflex corner before the distance and the inset
of its skeleton's faces (each face kept beyond the distance from its edge's line) covers more than GEOS's,
the two are united; a face whose skeleton cannot be completed
keeps GEOS's inset, as does one of more than ``SKELETON_VERTICES`` vertices.
"""

from __future__ import annotations

import numpy as np
import shapely
from numba import njit

from grammarc.geometry.overlay import union_by_group
from grammarc.geometry.skeleton import skeleton_faces
from grammarc.ragged import grow

#: How many pieces an outline is at least cut into where its inset comes out empty: GEOS checks rings of
#: fewer than 9 coordinates only.
PIECES = 16

#: How far (scope units, metres) a vertex may lie off the straight run through its neighbours and still be
#: taken out.
COLLINEAR = 1e-9

#: The area (scope units squared) beyond GEOS's inset that the skeleton's must cover to be taken.
NOTCH = 1e-6

#: The most vertices of a face whose skeleton is taken: the skeleton's tables of split candidates grow as
#: the square of a face's vertices (6 n x n per table); a larger face keeps GEOS's inset.
SKELETON_VERTICES = 512


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
    return _notches_filled(polygons, distance, inset)


def _notches_filled(polygons: np.ndarray, distance: np.ndarray, inset: np.ndarray) -> np.ndarray:
    """The insets (k,) united with the wavefront's insets of the non-convex polygons (k,) moved in by
    ``-distance`` (k,) where those cover more (``NOTCH``): the notches of reflex corners the wavefront
    closed before the distance filled."""
    rows = np.flatnonzero((distance < 0) & ~shapely.is_empty(inset))
    rows = rows[(shapely.area(shapely.convex_hull(polygons[rows])) > shapely.area(polygons[rows]) * (1 + 1e-12))
                & (shapely.get_num_coordinates(polygons[rows]) <= SKELETON_VERTICES)]
    if not len(rows):
        return inset
    # (the skeleton takes no collinear or repeated vertices)
    clean = shapely.orient_polygons(shapely.simplify(polygons[rows], 0.0))
    polygon_rows = (shapely.get_type_id(clean) == shapely.GeometryType.POLYGON) & ~shapely.is_empty(clean)
    rows, clean = rows[polygon_rows], clean[polygon_rows]
    if not len(rows):
        return inset
    _, coords, (ring_offsets, poly_offsets) = shapely.to_ragged_array(clean)
    face_xy, face_offsets, start, end, polygon = _skeleton_faces(
        np.ascontiguousarray(np.asarray(coords)[:, :2]), np.asarray(ring_offsets, dtype=np.int64),
        np.asarray(poly_offsets, dtype=np.int64), -distance[rows])
    if not len(polygon):
        return inset
    faces = shapely.make_valid(shapely.polygons(shapely.linearrings(
        face_xy, indices=np.repeat(np.arange(len(polygon)), np.diff(face_offsets)))))
    # each face beyond the distance from its edge's line: cut by a half-plane, a quad reaching past the face
    length = np.hypot(*(end - start).T)
    tangent = (end - start) / length[:, None]
    inward = np.stack([-tangent[:, 1], tangent[:, 0]], axis=1)  # (counter-clockwise exterior, clockwise holes)
    near = start - distance[rows][polygon][:, None] * inward
    reach = (shapely.length(faces) + length - distance[rows][polygon] + 1.0)[:, None]
    half = shapely.polygons(np.stack([near - reach * tangent, near + reach * tangent,
                                      near + reach * (tangent + inward), near - reach * (tangent - inward)], axis=1))
    kept = shapely.set_precision(shapely.intersection(faces, half), 1e-9)
    skeleton = union_by_group(kept, polygon, len(rows))
    wider = np.zeros(len(rows), dtype=bool)
    wider[polygon] = True
    wider &= (shapely.area(shapely.difference(skeleton, inset[rows])) > NOTCH)
    out = inset.copy()
    # (the faces' seams and the points where the two meet on a straight run taken out)
    out[rows[wider]] = shapely.simplify(shapely.union(inset[rows[wider]], skeleton[wider]), COLLINEAR,
                                        preserve_topology=False)
    return out


@njit(cache=True, nogil=True)
def _skeleton_faces(coords, ring_offsets, poly_offsets, depth):
    """The straight-skeleton faces of the polygons (m,) given as ragged closed rings (exteriors
    counter-clockwise, holes clockwise, as ``shapely.to_ragged_array`` lists them) where the wavefront
    ends a reflex corner before it moves ``depth`` (m,) in (elsewhere GEOS's mitres are the wavefront's,
    and a polygon whose skeleton is not completed keeps them): the faces' vertices (V, 2) and offsets
    (F+1,), one face per edge that reaches past the distance, and each face's edge's start and end (F, 2)
    and polygon (F,)."""
    m = len(poly_offsets) - 1
    n_edges = 0
    for r in range(len(ring_offsets) - 1):
        n_edges += ring_offsets[r + 1] - ring_offsets[r] - 1
    start = np.empty((n_edges, 2))
    end = np.empty((n_edges, 2))
    polygon = np.empty(n_edges, np.int64)
    face_offsets = np.zeros(n_edges + 1, np.int64)
    face_xy = np.empty((max(8 * n_edges, 16), 2))
    f = 0
    for g in range(m):
        r0, r1 = poly_offsets[g], poly_offsets[g + 1]
        local = np.zeros(r1 - r0 + 1, np.int64)
        for r in range(r0, r1):
            local[r - r0 + 1] = local[r - r0] + ring_offsets[r + 1] - ring_offsets[r] - 1
        n = local[-1]
        xy = np.empty((n, 2))
        for r in range(r0, r1):
            xy[local[r - r0]:local[r - r0 + 1]] = coords[ring_offsets[r]:ring_offsets[r + 1] - 1]
        node_xy, node_t, fnodes, foff, done = skeleton_faces(xy, local, 0.0, None)
        if not done:
            continue
        ended = False  # a reflex corner's first event (the last node of its edge's face) comes first
        for r in range(r1 - r0):
            for e in range(local[r], local[r + 1]):
                before = local[r] + (e - local[r] - 1) % (local[r + 1] - local[r])
                after = local[r] + (e - local[r] + 1) % (local[r + 1] - local[r])
                turn = ((xy[e, 0] - xy[before, 0]) * (xy[after, 1] - xy[e, 1])
                        - (xy[e, 1] - xy[before, 1]) * (xy[after, 0] - xy[e, 0]))
                if turn < 0.0 and node_t[fnodes[foff[e + 1] - 1]] < depth[g] * (1.0 - 1e-9):
                    ended = True
        if not ended:
            continue
        for r in range(r1 - r0):
            for e in range(local[r], local[r + 1]):
                top = 0.0
                for j in range(foff[e], foff[e + 1]):
                    top = max(top, node_t[fnodes[j]])
                if top <= depth[g]:
                    continue  # (the face ends before the distance: nothing of it is left)
                start[f] = xy[e]
                end[f] = xy[local[r] + (e - local[r] + 1) % (local[r + 1] - local[r])]
                polygon[f] = g
                used, count = face_offsets[f], foff[e + 1] - foff[e]
                face_xy = grow(face_xy, used + count)
                for j in range(count):
                    face_xy[used + j] = node_xy[fnodes[foff[e] + j]]
                face_offsets[f + 1] = used + count
                f += 1
    return face_xy[:face_offsets[f]].copy(), face_offsets[:f + 1].copy(), start[:f].copy(), end[:f].copy(), \
        polygon[:f].copy()
