"""The face and edge that CityEngine's ``alignScopeToGeometry(upAxis, face, edge)`` turns a scope to.

Every shape's faces are given in world space (``geometry.queries.shape_faces`` moved by the scopes), in the
order ``comp(f)`` numbers them; one kernel picks, per shape, a face (by index, the largest, the lowest, or
``any``: the face of the extremal edge) and an edge of that face's outline (by index, the longest, the
lowest). The new axes follow from them: x along the edge, the up axis (y or z) along the face's normal.

Where the reference is silent: "lowest" compares the mean world y of a face's outline vertices (so a box's
bottom beats its sides, which reach as low) and an edge's midpoint; ties go to the first face or edge
(within 1e-9); zero-length edges are never picked by a selector; ``any`` with an edge index picks the edge
of that index on the first face (the reference allows ``any`` only with an edge selector).
"""

from __future__ import annotations

import numpy as np
import shapely
from numba import njit

#: Face selectors of ``alignScopeToGeometry`` (codes of ``pick_edges``).
FACE_MODES = {"index": 0, "largest": 1, "world.lowest": 2, "any": 3}
#: Edge selectors of ``alignScopeToGeometry``.
EDGE_MODES = {"index": 0, "longest": 1, "world.lowest": 2}


@njit(cache=True, nogil=True)
def _edge_value(verts, j, q, edge_mode):
    """What an edge selector minimizes: minus the length (longest) or the midpoint's y (lowest)."""
    if edge_mode == 1:
        d = verts[q] - verts[j]
        return -np.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
    return (verts[j, 1] + verts[q, 1]) / 2


@njit(cache=True, nogil=True)
def _pick_face(verts, ring_offsets, face_offsets, f0, f1, area, face_mode, index):
    """The face of one shape (faces f0..f1) that a face selector other than ``any`` picks."""
    if face_mode == 0:
        return f0 + index % (f1 - f0)
    best, face = np.inf, -1
    for f in range(f0, f1):
        if face_mode == 1:
            value = -area[f]
        else:
            outline = face_offsets[f]
            r0, r1 = ring_offsets[outline], ring_offsets[outline + 1]
            value = verts[r0:r1, 1].sum() / max(r1 - r0, 1)
        if value < best - 1e-9:
            best, face = value, f
    return face


@njit(cache=True, nogil=True)
def pick_edges(verts, ring_offsets, face_offsets, shape_offsets, area, face_mode, face_index, edge_mode,
               edge_index):
    """Each shape's face and the edge of its outline that ``alignScopeToGeometry`` aligns to.

    verts (V, 3) float64 in world space, ring_offsets (R+1,), face_offsets (F+1,), shape_offsets (n+1,)
    as ``geometry.queries.Faces``; area (F,) float64 each face's area; face_mode, edge_mode codes of
    ``FACE_MODES``/``EDGE_MODES``; face_index, edge_index (n,) int64 (read with the index modes; negative
    indices count from the end).

    Returns face (n,), and the edge's start and end vertices (n,) int64, -1 where a shape has no face or
    its face no edge.
    """
    n = len(shape_offsets) - 1
    face = np.full(n, -1, np.int64)
    start = np.full(n, -1, np.int64)
    end = np.full(n, -1, np.int64)
    for i in range(n):
        f0, f1 = shape_offsets[i], shape_offsets[i + 1]
        if f1 == f0:
            continue
        if face_mode == 3 and edge_mode != 0:
            first, last = f0, f1
        else:
            f = _pick_face(verts, ring_offsets, face_offsets, f0, f1, area, 0 if face_mode == 3 else face_mode,
                           0 if face_mode == 3 else face_index[i])
            first, last = f, f + 1
        best = np.inf
        for f in range(first, last):
            outline = face_offsets[f]
            r0 = ring_offsets[outline]
            count = ring_offsets[outline + 1] - r0
            if count < 2:
                continue
            if edge_mode == 0:
                j = r0 + edge_index[i] % count
                face[i], start[i], end[i] = f, j, r0 + (j - r0 + 1) % count
                continue
            for j in range(r0, r0 + count):
                q = r0 + (j - r0 + 1) % count
                d = verts[q] - verts[j]
                if d[0] * d[0] + d[1] * d[1] + d[2] * d[2] <= 1e-18:
                    continue
                value = _edge_value(verts, j, q, edge_mode)
                if value < best - 1e-9:
                    best = value
                    face[i], start[i], end[i] = f, j, q
    return face, start, end


def aligned_axes(edge: np.ndarray, normal: np.ndarray, frame: np.ndarray, up: str):
    """New scope axes (n, 3, 3) (rows x, y, z) from each shape's picked edge vector (n, 3) and its face's
    normal (n, 3) (unit, NaN where there is none): x along the edge (made orthogonal to the normal), y
    (``up`` "yUp") or z ("zUp") the normal. A normal within 1e-9 of an axis of the shape's present scope
    ``frame`` (n, 3, 3) is that axis exactly, so that a face in a scope plane keeps its plane. Also whether
    each shape has its axes (n,) bool (a face with an area, an edge with a length)."""
    rows = np.arange(len(edge))
    along = np.einsum("nj,nkj->nk", normal, frame)
    k = np.argmax(np.abs(np.nan_to_num(along)), axis=1)
    snap = np.abs(along[rows, k]) > 1 - 1e-9
    normal = np.where(snap[:, None], np.sign(along[rows, k])[:, None] * frame[rows, k], normal)
    dot = np.einsum("ni,ni->n", edge, normal)
    x = np.where((np.abs(dot) > 1e-12)[:, None], edge - dot[:, None] * normal, edge)
    length = np.linalg.norm(x, axis=1)
    ok = np.isfinite(normal).all(axis=1) & (length > 1e-12)
    x = np.where(ok[:, None], x / np.where(ok, length, 1.0)[:, None], 0.0)
    normal = np.where(ok[:, None], normal, 0.0)
    if up == "yUp":
        return np.stack([x, normal, np.cross(x, normal)], axis=1), ok
    return np.stack([x, np.cross(normal, x), normal], axis=1), ok



def bbox_turns(points: np.ndarray, owner: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """For ``alignScopeToGeometryBBox``: the turn of each of n shapes' first in-plane axis onto the longer
    side of the smallest rectangle around its ``points`` (V, 2) (coordinates along the two axes; ``owner``
    (V,) each one's shape, ascending), as (cos, sin) (n, 2) of the angle from the first axis towards the
    second, and (n,) whether the shape has such a side. Of a side's two senses the one within a quarter
    turn of the first axis is taken; points along a line give the line, a single point no side.
    """
    hulls = shapely.minimum_rotated_rectangle(
        shapely.multipoints(points, indices=owner, out=np.empty(n, dtype=object)))
    # a rectangle's ring (its first two sides follow each other), a line's two ends, a point, or nothing
    coords, ring = shapely.get_coordinates(hulls, return_index=True)
    counts = np.bincount(ring, minlength=n)
    first = np.searchsorted(ring, np.arange(n))
    at = np.minimum(first[:, None] + np.arange(3), max(len(coords) - 1, 0))
    corner = coords[at] if len(coords) else np.zeros((n, 3, 2))
    side = np.where((counts >= 2)[:, None], corner[:, 1] - corner[:, 0], 0.0)
    across = np.where((counts >= 3)[:, None], corner[:, 2] - corner[:, 1], 0.0)
    longer = np.where((np.hypot(*side.T) >= np.hypot(*across.T))[:, None], side, across)
    length = np.hypot(*longer.T)
    ok = length > 1e-12
    turn = np.where(ok[:, None], longer / np.where(ok, length, 1.0)[:, None], [1.0, 0.0])
    return turn * np.where(turn[:, :1] < 0, -1.0, 1.0), ok
