"""The cut faces of concave meshes: where a split's planes cross a roof or any closed mesh.

``meshes.clip_slabs`` closes a cut convex mesh with the convex hull of the points where its faces cross
the plane. A concave mesh (a hip roof over an L or a courtyard) crosses a plane in a section that may be
concave or have holes, so here each face contributes the segments where it meets the plane (its
crossing points along the line of the face and the plane, paired inside the face, numba over all
faces at once) and GEOS builds each cap's area from its segments (``shapely.build_area``: nested
loops alternate between area and hole, as the section of a closed surface does). Caps are appended
to the clipped meshes, each facing out of its slab.
"""

from __future__ import annotations

import numpy as np
import shapely
from numba import njit

from grammarc.constants import TOL
from grammarc.ragged import grow, offsets_from_counts, ragged_take, rank_within, segment_of


@njit(cache=True, nogil=True)
def plane_segments(verts, ring_offsets, face_offsets, mesh_offsets, child_mesh, cut, axis, lo, hi):
    """Segments where the faces of the meshes ``child_mesh[c]`` (for the children ``cut``) meet the
    planes ``coordinate[axis] = lo[c]`` and ``= hi[c]``.

    A vertex on a plane counts as inside the slab, so a face that touches the plane at a vertex or an
    edge from inside (a ridge at the top of the slab) does not cross it, and one crossing it through a
    vertex crosses it once. The crossings of one face are
    ordered along the line where its plane meets the cut plane and paired, first with second, third
    with fourth: the pieces of that line inside the face (holes included). Returns the segments' ends
    (S, 2, 3) and each one's cap (S,) int64: 2 c for the lo plane, 2 c + 1 for the hi plane.
    """
    ends = np.empty((64, 2, 3))
    cap = np.empty(64, np.int64)
    n = 0
    points = np.empty((16, 3))
    for c in cut:
        g = child_mesh[c]
        for side in range(2):
            plane = lo[c] if side == 0 else hi[c]
            sign = 1.0 if side == 0 else -1.0
            for f in range(mesh_offsets[g], mesh_offsets[g + 1]):
                normal = np.zeros(3)
                k = 0
                for r in range(face_offsets[f], face_offsets[f + 1]):
                    r0, r1 = ring_offsets[r], ring_offsets[r + 1]
                    for j in range(r0, r1):
                        p = verts[r0 + (j - r0 - 1) % (r1 - r0)]
                        q = verts[j]
                        if r == face_offsets[f]:  # Newell's normal of the outer ring
                            normal[0] += (p[1] - q[1]) * (p[2] + q[2])
                            normal[1] += (p[2] - q[2]) * (p[0] + q[0])
                            normal[2] += (p[0] - q[0]) * (p[1] + q[1])
                        if (sign * (p[axis] - plane) >= 0.0) != (sign * (q[axis] - plane) >= 0.0):
                            if p[axis] > q[axis]:  # from the lower end: the faces on both sides of an
                                p, q = q, p        # edge get the same point, so their segments join
                            t = (plane - p[axis]) / (q[axis] - p[axis])
                            points = grow(points, k + 1)
                            points[k] = p + t * (q - p)
                            points[k, axis] = plane
                            k += 1
                if k < 2:
                    continue
                direction = np.zeros(3)  # along normal x axis: the line of the face in the plane
                direction[(axis + 1) % 3] = normal[(axis + 2) % 3]
                direction[(axis + 2) % 3] = -normal[(axis + 1) % 3]
                order = np.argsort(points[:k] @ direction)
                for i in range(0, k - 1, 2):
                    ends = grow(ends, n + 1)
                    cap = grow(cap, n + 1)
                    ends[n, 0] = points[order[i]]
                    ends[n, 1] = points[order[i + 1]]
                    cap[n] = 2 * c + side
                    n += 1
    return ends[:n], cap[:n]


def section_caps(ends: np.ndarray, cap: np.ndarray, axis: int):
    """The cap polygons of each cap's segments: shapely polygons (k,) in the plane's (a, b) coordinates
    (a = axis + 1, b = axis + 2), exteriors turned to face out of the slab (-axis for a lo cap), and the
    cap of each (k,)."""
    if not len(cap):
        return np.empty(0, dtype=object), np.empty(0, dtype=np.int64)
    a, b = (axis + 1) % 3, (axis + 2) % 3
    caps, group = np.unique(cap, return_inverse=True)
    lines = shapely.linestrings(ends[:, :, [a, b]])
    grid = np.full((len(caps), int(rank_within(group).max()) + 1), None, dtype=object)
    grid[group, rank_within(group)] = lines
    areas = shapely.build_area(shapely.union_all(grid, axis=1))
    parts, which = shapely.get_parts(areas, return_index=True)
    keep = (shapely.get_type_id(parts) == shapely.GeometryType.POLYGON) & (shapely.area(parts) > TOL.area_floor)
    parts, which = parts[keep], caps[which[keep]]
    lo = which % 2 == 0
    if lo.any():
        parts[lo] = shapely.orient_polygons(parts[lo], exterior_cw=True)
    if (~lo).any():
        parts[~lo] = shapely.orient_polygons(parts[~lo], exterior_cw=False)
    return parts, which


def append_caps(verts, ring_offsets, face_offsets, mesh_offsets, parts, which, axis: int, lo, hi):
    """The clipped meshes (one per child, ``mesh_offsets`` (m+1,)) with the cap polygons ``parts`` (k,)
    of the caps ``which`` (k,) appended to their children's faces, as 3D rings on their planes."""
    if not len(parts):
        return verts, ring_offsets, face_offsets, mesh_offsets
    a, b = (axis + 1) % 3, (axis + 2) % 3
    _, flat, (closed, part_offsets) = shapely.to_ragged_array(parts)
    flat = np.asarray(flat)[:, :2]
    closed = np.asarray(closed, dtype=np.int64)
    keep = np.ones(len(flat), dtype=bool)
    keep[closed[1:] - 1] = False  # rings repeat their first point at the end
    child = which // 2
    plane = np.where(which % 2 == 0, lo[child], hi[child])
    ring_part = segment_of(np.asarray(part_offsets, dtype=np.int64))
    cap_verts = np.zeros((int(keep.sum()), 3))
    cap_verts[:, a], cap_verts[:, b] = flat[keep, 0], flat[keep, 1]
    cap_verts[:, axis] = plane[ring_part[segment_of(closed)[keep]]]
    cap_rings = offsets_from_counts(np.diff(closed) - 1)
    # one table of rings and faces, clipped ones then caps; each child's faces in that order
    all_rings = np.concatenate([ring_offsets, len(verts) + cap_rings[1:]])
    all_faces = np.concatenate([face_offsets, len(ring_offsets) - 1 + np.asarray(part_offsets[1:], np.int64)])
    face_child = np.concatenate([segment_of(mesh_offsets), child])
    rings, new_faces = ragged_take(all_faces, np.argsort(face_child, kind="stable"))
    vertex, new_rings = ragged_take(all_rings, rings)
    new_mesh = offsets_from_counts(np.bincount(face_child, minlength=len(mesh_offsets) - 1))
    return np.concatenate([verts, cap_verts])[vertex], new_rings, new_faces, new_mesh
