"""CityEngine's ``trim()``: the shape's own geometry cut by its trim planes.

A ``comp(f)`` leaves each side face a plane at each edge it shares with a steep neighbour, and, where the
grammar turns them on, each face one at each shallow edge it shares (``geometry.trim``); inserts are cut by them as they are placed (``backend.terminals``), and ``trim()``
cuts the shape's geometry itself, so that a wall or a cornice extruded from a face and stretched past its
corners meets its neighbours in a mitre. Each plane is a plane across the first axis of a frame of its
own (``geometry.trim.plane_coordinates``): the shape's faces go into that frame, are cut to the slab in
front of the plane and closed as a split closes a cut roof (``mesh_shapes.cut_to_slabs``), and come
back. A trimmed shape's geometry becomes a mesh in its unchanged scope (CityEngine keeps the scope, as an
insert does); a shape no plane cuts keeps its geometry, and an inserted asset is left to be trimmed
where it is placed. Reads: the scope, ``geom`` and the trim planes' id (``dynamic``). Writes: ``geom``.
"""

from __future__ import annotations

import numpy as np

from grammarc.backend.context import Context
from grammarc.backend.mesh_shapes import cut_to_slabs
from grammarc.backend.operations.table import operation
from grammarc.backend.shapes import Shapes
from grammarc.backend.terminals import trim_planes
from grammarc.constants import TOL
from grammarc.geometry.meshes import MESH_BASE
from grammarc.geometry.queries import shape_faces
from grammarc.geometry.trim import plane_coordinates
from grammarc.ir import nodes as ir
from grammarc.ragged import segment_of


@operation(ir.Trim, writes=("geom",), meshes=True)
def trim(ctx: Context, cursor: Shapes, op: ir.Trim) -> Shapes:
    plan = ctx.plan
    if plan.trim_slot is None or not len(cursor):  # no comp(f) in the grammar: no shape has planes
        return cursor
    chunk = ctx.chunk
    planes = trim_planes(plan, chunk, cursor)
    planes[cursor.geom < -1] = np.nan  # an asset is trimmed where it is placed
    rows = np.flatnonzero(~np.isnan(planes[:, 0::4]).all(axis=1))
    if not len(rows):
        return cursor
    shapes = cursor.take(rows)
    faces = shape_faces(shapes.size, shapes.geom, chunk.polygons, chunk.meshes)
    verts, ring_offsets, face_offsets = faces.verts, faces.ring_offsets, faces.face_offsets
    mesh_offsets = faces.shape_offsets
    axes = chunk.frames[shapes.frame]
    cut_any = np.zeros(len(rows), dtype=bool)
    for which in range(planes.shape[1] // 4):
        plane = planes[rows, 4 * which:4 * which + 4]
        present = ~np.isnan(plane[:, 0])
        normal = np.where(present[:, None], plane[:, :3], (1.0, 0.0, 0.0))
        # the plane in scope units: its normal along the scope's axes, its offset from the scope's origin
        frame = plane_coordinates(np.einsum("nij,nj->ni", axes, normal))
        origin = shapes.origin - chunk.lot_origin[shapes.lot]  # the planes are relative to the lot's origin
        offset = np.where(present, np.einsum("nj,nj->n", normal, origin) + plane[:, 3], 0.0)
        vertex_shape = segment_of(mesh_offsets)[segment_of(face_offsets)][segment_of(ring_offsets)]
        local = np.einsum("nij,nj->ni", frame[vertex_shape], verts)
        local[:, 0] += offset[vertex_shape]
        side = np.full(len(rows), np.inf)
        np.minimum.at(side, vertex_shape, local[:, 0])
        cutting = present & (side < -TOL.zero)
        if not cutting.any():
            continue
        cut_any |= cutting
        lo = np.where(cutting, 0.0, -np.inf)
        local, ring_offsets, face_offsets, mesh_offsets = cut_to_slabs(
            local, ring_offsets, face_offsets, mesh_offsets, np.arange(len(rows)), 0, lo, np.full(len(rows), np.inf))
        vertex_shape = segment_of(mesh_offsets)[segment_of(face_offsets)][segment_of(ring_offsets)]
        local[:, 0] -= offset[vertex_shape]
        verts = np.einsum("nji,nj->ni", frame[vertex_shape], local)
    if not cut_any.any():
        return cursor
    vertex_shape = segment_of(mesh_offsets)[segment_of(face_offsets)][segment_of(ring_offsets)]
    size = shapes.size[vertex_shape]
    normalized = np.divide(verts, size, out=np.zeros_like(verts), where=size > TOL.zero)
    ids = chunk.meshes.add(normalized, ring_offsets, face_offsets, mesh_offsets)
    geom = cursor.geom.copy()
    geom[rows[cut_any]] = (MESH_BASE + ids[cut_any]).astype(np.int32)
    return cursor.with_scope(cursor.origin, cursor.size, cursor.frame, geom)
