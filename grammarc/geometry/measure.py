"""Areas, volumes and counts of shapes, for CityEngine's ``geometry.area``, ``geometry.volume``,
``geometry.nVertices`` and ``geometry.nFaces`` (the queries that look at faces one by one are in
``geometry.queries``).

A flat shape's area is its face's; a solid's area is its surface (as CityEngine reports it), its volume
the prism's. Boxes and inserted assets measure as their scope box; polygons from the store, scaled by
the scope, for all shapes at once.
"""

from __future__ import annotations

import numpy as np

from grammarc.constants import TOL
from grammarc.geometry import meshes as mesh_store
from grammarc.geometry.meshes import MESH_BASE, MeshStore, is_mesh, is_polygon
from grammarc.geometry.polygons import PLANE_U, PLANE_V, PolygonStore
from grammarc.ragged import next_in_segment, segment_of, segment_reduce


def area_and_volume(size: np.ndarray, geom: np.ndarray, store: PolygonStore,
                    meshes: MeshStore) -> tuple[np.ndarray, np.ndarray]:
    """Per shape: area (n,) and volume (n,) float64, from scope sizes (n, 3) and geometry ids (n,)."""
    flat = size <= TOL.zero
    n_flat = flat.sum(axis=1)
    sx, sy, sz = size[:, 0], size[:, 1], size[:, 2]
    box_area = np.where(n_flat == 0, 2 * (sx * sy + sy * sz + sx * sz),
                        np.where(n_flat == 1, np.prod(np.where(flat, 1.0, size), axis=1), 0.0))
    area = box_area
    volume = sx * sy * sz
    poly = np.flatnonzero(is_polygon(geom))
    if len(poly):
        ids = geom[poly]
        coords, ring_offsets, poly_offsets = store.gather(ids)
        plane = store.plane[ids]
        a_axis, b_axis = PLANE_U[plane], PLANE_V[plane]
        sa, sb, h = size[poly, a_axis], size[poly, b_axis], size[poly, plane]
        vertex_ring = segment_of(ring_offsets)
        vertex_poly = segment_of(poly_offsets)[vertex_ring]
        nxt = next_in_segment(ring_offsets)
        u = coords[:, 0] * sa[vertex_poly]
        v = coords[:, 1] * sb[vertex_poly]
        cross = u * v[nxt] - u[nxt] * v
        vertex_offsets = ring_offsets[poly_offsets]
        face = np.abs(segment_reduce(np.add, cross, vertex_offsets, 0.0)) / 2
        perimeter = segment_reduce(np.add, np.hypot(u[nxt] - u, v[nxt] - v), vertex_offsets, 0.0)
        solid = h > TOL.zero
        area = area.copy()
        volume = volume.copy()
        area[poly] = np.where(solid, 2 * face + perimeter * h, face)
        volume[poly] = np.where(solid, face * h, 0.0)
    mesh = np.flatnonzero(is_mesh(geom))
    if len(mesh):
        area, volume = area.copy(), volume.copy()
        area[mesh], volume[mesh] = mesh_store.area_and_volume(meshes, geom[mesh] - MESH_BASE, size[mesh])
    return area, volume


def vertex_and_face_counts(size: np.ndarray, geom: np.ndarray, store: PolygonStore, meshes: MeshStore):
    """CityEngine's ``geometry.nVertices`` and ``geometry.nFaces`` per shape, (n,) float64 each: a box
    has 8 and 6, a rectangle 4 and 1, a polygon its vertices and 1 face, a prism twice its vertices and
    its edges plus 2 faces; a mesh the vertices of its face rings and its faces; an inserted asset
    counts as its box."""
    flat = (size <= TOL.zero).sum(axis=1)
    vertices = np.where(flat == 0, 8.0, np.where(flat == 1, 4.0, np.where(flat == 2, 2.0, 1.0)))
    faces = np.where(flat == 0, 6.0, np.where(flat == 1, 1.0, 0.0))
    poly = np.flatnonzero(is_polygon(geom))
    if len(poly):
        ids = geom[poly]
        per_poly = segment_reduce(np.add, np.diff(store.ring_offsets), store.poly_offsets, 0)[ids].astype(np.float64)
        solid = size[poly, store.plane[ids]] > TOL.zero
        vertices = vertices.copy()
        faces = faces.copy()
        vertices[poly] = np.where(solid, 2 * per_poly, per_poly)
        faces[poly] = np.where(solid, per_poly + 2, 1.0)
    mesh = np.flatnonzero(is_mesh(geom))
    if len(mesh):
        coords, ring_offsets, face_offsets, mesh_offsets = meshes.gather(geom[mesh] - MESH_BASE)
        vertex_mesh = np.repeat(np.arange(len(mesh)), np.diff(ring_offsets[face_offsets[mesh_offsets]]))
        distinct = np.unique(np.column_stack([vertex_mesh, np.round(coords, 9)]), axis=0)[:, 0]
        vertices, faces = vertices.copy(), faces.copy()
        vertices[mesh] = np.bincount(distinct.astype(np.int64), minlength=len(mesh))
        faces[mesh] = np.diff(mesh_offsets)
    return vertices, faces
