"""Triangles of planar polygons with holes in 3D, facing along each outline's normal.

The record's mesh table holds faces that could not be instances (outlines with holes, concave roofs), in
world coordinates. The renderer draws them and the mesh writers (baked meshes, the instanced formats' mesh
of each tile) write them as triangles; they share this one triangulation, so a face looks the same in a
picture and in every file. A convex face without holes becomes a fan (vectorized over all such faces); any
other face goes through mapbox-earcut (one call per face) in the plane of its outline's Newell normal, and
its triangles are turned to face along that normal.
"""

from __future__ import annotations

import numpy as np

from grammarc.errors import UsageError
from grammarc.ragged import fan_out, segment_reduce

__all__ = ["triangulate_polygons"]

#: A polygon's turn at a vertex counts as convex above ``-_CONVEX * |e_prev| |e_next| |n|`` (collinear
#: vertices, and rounding of float32 world coordinates, are not concavities).
_CONVEX = 1e-7


def triangulate_polygons(vertices: np.ndarray, ring_offsets: np.ndarray,
                         face_offsets: np.ndarray) -> np.ndarray:
    """Triangles of planar polygons with holes, facing along each outline's Newell normal.

    Parameters
    ----------
    vertices : (V, 3) float
        Ring vertices, ring after ring.
    ring_offsets : (R+1,) int64
        Ring ``r`` is ``vertices[ring_offsets[r]:ring_offsets[r+1]]``.
    face_offsets : (F+1,) int64
        Face ``f`` is rings ``face_offsets[f]:face_offsets[f+1]``: its outline, then its holes.

    Returns
    -------
    (T, 3) int64
        Indices into ``vertices``; the convex faces without holes first (fans), then the others
        (mapbox-earcut), each group in face order. A face whose outline has no area gives none.

    Examples
    --------
    >>> square = np.array([[0, 0, 0], [0, 0, 4], [4, 0, 4], [4, 0, 0],   # outline, normal +y
    ...                    [1, 0, 1], [3, 0, 1], [3, 0, 3], [1, 0, 3]], float)  # hole
    >>> triangulate_polygons(square, np.array([0, 4, 8]), np.array([0, 2])).shape
    (8, 3)
    """
    vertices = np.asarray(vertices, np.float64)
    ring_offsets = np.asarray(ring_offsets, np.int64)
    face_offsets = np.asarray(face_offsets, np.int64)
    n_faces = len(face_offsets) - 1
    if n_faces == 0:
        return np.zeros((0, 3), np.int64)
    ring_counts = np.diff(ring_offsets)
    n_rings = len(ring_counts)
    ring = np.repeat(np.arange(n_rings), ring_counts)  # (V,) ring of each vertex
    start = ring_offsets[:-1][ring]
    at = np.arange(len(vertices))
    after = np.where(at + 1 < start + ring_counts[ring], at + 1, start)  # successor in the ring
    before = np.where(at > start, at - 1, start + ring_counts[ring] - 1)
    local = vertices - vertices[start]  # relative to each ring's first vertex: no loss far from 0
    newell = segment_reduce(np.add, np.cross(local, local[after]), ring_offsets, 0.0)  # (R, 3)
    outline = face_offsets[:-1]  # (F,) the outline ring of each face
    normal = newell[outline]  # (F, 3), twice the outline's vector area
    face_of_ring = np.repeat(np.arange(n_faces), np.diff(face_offsets))
    has_area = np.linalg.norm(normal, axis=1) > 0

    # Convex: every turn of the outline is to the left of the normal (or straight).
    e_in = vertices[at] - vertices[before]
    e_out = vertices[after] - vertices[at]
    n_vertex = normal[face_of_ring[ring]]
    turn = np.einsum("vi,vi->v", np.cross(e_in, e_out), n_vertex)
    slack = _CONVEX * np.linalg.norm(e_in, axis=1) * np.linalg.norm(e_out, axis=1)
    slack *= np.linalg.norm(n_vertex, axis=1)
    concave_ring = segment_reduce(np.add, (turn < -slack).astype(np.int64), ring_offsets, 0) > 0
    single = np.diff(face_offsets) == 1
    fan = has_area & single & ~concave_ring[outline] & (ring_counts[outline] >= 3)
    triangles = [_fans(ring_offsets[outline[fan]], ring_counts[outline[fan]])]

    rest = np.flatnonzero(has_area & ~fan)
    if len(rest):
        triangles.append(_earcut_faces(vertices, ring_offsets, face_offsets, normal, rest))
    return np.concatenate(triangles)


def _fans(starts: np.ndarray, counts: np.ndarray) -> np.ndarray:
    """(sum(counts - 2), 3) int64 fan triangles (s, s+i+1, s+i+2) of rings at ``starts``, ``counts``."""
    parent, index = fan_out(counts - 2)
    first = starts[parent]
    return np.stack([first, first + index + 1, first + index + 2], axis=1)


def _earcut_faces(vertices: np.ndarray, ring_offsets: np.ndarray, face_offsets: np.ndarray,
                  normal: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Triangles of ``faces`` (k,) by mapbox-earcut, in each face's plane, turned along its normal."""
    try:
        import mapbox_earcut
    except ImportError as error:
        raise UsageError("triangulating concave polygons and polygons with holes needs mapbox-earcut: "
                         "pip install mapbox-earcut") from error
    unit = normal[faces] / np.linalg.norm(normal[faces], axis=1, keepdims=True)  # (k, 3)
    # In-plane axes u, v with u x v = n: cross n with the world axis it is least aligned with.
    helper = np.eye(3)[np.argmin(np.abs(unit), axis=1)]
    u = np.cross(unit, helper)
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    v = np.cross(unit, u)
    out = []
    for k, f in enumerate(faces):
        first, last = ring_offsets[face_offsets[f]], ring_offsets[face_offsets[f + 1]]
        points = vertices[first:last] - vertices[first]
        plane = np.stack([points @ u[k], points @ v[k]], axis=1)
        ends = (ring_offsets[face_offsets[f] + 1 : face_offsets[f + 1] + 1] - first).astype(np.uint32)
        tris = mapbox_earcut.triangulate_float64(plane, ends).astype(np.int64).reshape(-1, 3)
        a, b, c = plane[tris[:, 0]], plane[tris[:, 1]], plane[tris[:, 2]]
        clockwise = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0]) < 0
        tris[clockwise] = tris[clockwise][:, [0, 2, 1]]
        out.append(tris + first)
    return np.concatenate(out)
