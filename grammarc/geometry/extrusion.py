"""Faces extruded into closed meshes, each vertex moved its own way: CityEngine's ``extrude(world.up, h)``
and ``extrude(world.up.flatTop, h)`` of a face that is not level (a roof plane, a slanted comp(f) face),
whose solid is not a prism of its scope and so is stored as a mesh (``geometry.meshes``).

A mesh has the face itself, the face moved (its top) and a quad per edge of each ring: holes give the
inner walls. All its faces wind outwards.
"""

from __future__ import annotations

import numpy as np

from grammarc.ragged import offsets_from_counts, segment_of


def extruded_meshes(bottom: np.ndarray, top: np.ndarray, ring_offsets: np.ndarray, shape_offsets: np.ndarray,
                    outward: np.ndarray):
    """Closed meshes between faces and their moved copies.

    Parameters
    ----------
    bottom, top : (V, 3) float64
        Each ring vertex before and after the extrusion, rings wound around the face's normal (holes the
        other way).
    ring_offsets : (R+1,) int64
        Vertices of each ring.
    shape_offsets : (n+1,) int64
        Rings of each face, the outer ring first.
    outward : (n,) bool
        Whether the extrusion goes along the face's normal: then the face is the mesh's bottom turned
        over and its copy keeps the face's winding; else the face keeps its winding and its copy turns.

    Returns
    -------
    verts (6V, 3) float64, ring_offsets (2R+V+1,), face_offsets (2n+V+1,) and mesh_offsets (n+1,) int64,
    as ``geometry.meshes.MeshStore.add`` takes them: per face its bottom, its top, then its side quads.
    """
    n = len(shape_offsets) - 1
    ring_len = np.diff(ring_offsets)
    ring_shape = segment_of(shape_offsets)
    vertex_ring = segment_of(ring_offsets)
    vertex_shape = ring_shape[vertex_ring]
    n_vert = np.diff(ring_offsets[shape_offsets])
    n_ring = np.diff(shape_offsets)
    v_start = ring_offsets[shape_offsets[:-1]]
    r_start = shape_offsets[:-1]

    local = np.arange(len(bottom)) - v_start[vertex_shape]  # a vertex's index within its face
    pos = np.arange(len(bottom)) - ring_offsets[vertex_ring]
    reverse = ring_offsets[vertex_ring] + (ring_len[vertex_ring] - pos) % ring_len[vertex_ring]
    following = ring_offsets[vertex_ring] + (pos + 1) % ring_len[vertex_ring]
    up = outward[vertex_shape]

    base = 6 * v_start[vertex_shape]
    verts = np.empty((6 * len(bottom), 3))
    verts[base + local] = np.where(up[:, None], bottom[reverse], bottom)
    verts[base + n_vert[vertex_shape] + local] = np.where(up[:, None], top, top[reverse])
    a, b = np.where(up, np.arange(len(bottom)), following), np.where(up, following, np.arange(len(bottom)))
    side = base + 2 * n_vert[vertex_shape] + 4 * local
    verts[side] = bottom[a]
    verts[side + 1] = bottom[b]
    verts[side + 2] = top[b]
    verts[side + 3] = top[a]

    ring_base = 2 * r_start + v_start
    new_ring_len = np.empty(2 * len(ring_len) + len(bottom), dtype=np.int64)
    ring_local = np.arange(len(ring_len)) - r_start[ring_shape]
    new_ring_len[ring_base[ring_shape] + ring_local] = ring_len
    new_ring_len[ring_base[ring_shape] + n_ring[ring_shape] + ring_local] = ring_len
    new_ring_len[ring_base[vertex_shape] + 2 * n_ring[vertex_shape] + local] = 4

    face_base = 2 * np.arange(n) + v_start
    face_rings = np.ones(2 * n + len(bottom), dtype=np.int64)
    face_rings[face_base] = n_ring
    face_rings[face_base + 1] = n_ring
    mesh_offsets = np.append(face_base, 2 * n + len(bottom)).astype(np.int64)
    return verts, offsets_from_counts(new_ring_len), offsets_from_counts(face_rings), mesh_offsets
