"""Shapes given new scope axes around their unchanged geometry, the scope fitted to it again.

``alignScopeToAxes``, ``alignScopeToGeometry`` and ``rotateScope`` turn every shape's scope; ``extrude`` and a
``comp(f)`` face turn some (a face whose normal is not the axis they want it along). Polygons and prisms
go through ``geometry.reframe`` while one new axis is their plane's normal; meshes, and polygons turned out
of their plane, through ``mesh_shapes.reframe_meshes`` (a box turned by quarter turns stays a box).
"""

from __future__ import annotations

import numpy as np

from grammarc.backend import mesh_shapes
from grammarc.backend.box_rings import corners, with_corners
from grammarc.backend.context import Context
from grammarc.backend.outlines import polygons_of
from grammarc.backend.shapes import Shapes
from grammarc.geometry.components import rect_corners
from grammarc.geometry.meshes import is_mesh
from grammarc.geometry.reframe import reframe
from grammarc.ragged import ragged_take


def turned(ctx: Context, shapes: Shapes, turn: np.ndarray, matrices: np.ndarray, axis: np.ndarray,
           span) -> Shapes:
    """``shapes`` with the shapes ``turn`` (n,) bool given the axes ``matrices[axis]`` (rows in their present
    frames: ``NORMAL_UP``, ``NORMAL_OUT``) around their unchanged geometry."""
    if not turn.any():
        return shapes
    rows = np.flatnonzero(turn)
    sub = shapes.take(turn)  # the batch itself where all turn (a comp(f)'s faces, extruded)
    frame, new_axes = ctx.chunk.frames.turned(matrices, sub.frame, axis[rows])  # a row per frame and axis
    if len(rows) == len(shapes):  # nothing to merge them with
        return reframed(ctx, sub, new_axes, span, frame)
    others = np.flatnonzero(~turn)
    return Shapes.merge([shapes.take(others), reframed(ctx, sub, new_axes, span, frame)], [others, rows])


def reframed(ctx: Context, shapes: Shapes, new_axes: np.ndarray, span, frame: np.ndarray | None = None) -> Shapes:
    """The same geometry in scopes with ``new_axes`` (n, 3, 3), fitted to it; fails the lots of inserted
    assets. ``frame`` (n,): the ids of ``new_axes`` where the caller has them in the chunk's table (shapes
    turned alike share a row: ``turned``); else each shape gets a row of its own."""
    chunk = ctx.chunk
    if frame is None:
        frame = chunk.frames.add(np.ascontiguousarray(new_axes))
    mesh = is_mesh(shapes.geom)
    if mesh.any():
        new_axes = np.asarray(new_axes)
        if mesh.all():
            return mesh_shapes.reframe_meshes(chunk, shapes, new_axes, frame)
        rows = np.flatnonzero(mesh)
        others = np.flatnonzero(~mesh)
        return Shapes.merge([mesh_shapes.reframe_meshes(chunk, shapes.take(rows), new_axes[rows], frame[rows]),
                             reframed(ctx, shapes.take(others), new_axes[others], span, frame[others])],
                            [rows, others])
    n = len(shapes)
    bad = shapes.geom < -1
    if bad.any():
        ctx.fail(shapes, bad, "aligning the scope of an inserted asset is not supported yet", span)
    coords, ring_offsets, shape_offsets, plane = polygons_of(chunk, shapes, corners(ctx.plan, shapes))
    ok, plane, origin, size, is_rect, new_coords = reframe(
        shapes.origin, shapes.size, chunk.frames[shapes.frame], coords, ring_offsets, shape_offsets,
        plane, new_axes)
    geom = np.full(n, -1, dtype=np.int32)
    poly = np.flatnonzero(~is_rect & ok)
    if len(poly):
        rings, packed_shapes = ragged_take(shape_offsets, poly)
        vertices, packed_rings = ragged_take(ring_offsets, rings)
        geom[poly] = chunk.polygons.add(new_coords[vertices], packed_rings, packed_shapes, plane[poly])
    result = shapes.with_scope(origin, size, frame, geom)
    if ctx.plan.ring_slot is not None:  # a rectangle kept as its box keeps its ring's first vertex
        result = with_corners(ctx.plan, result, np.where(
            is_rect, rect_corners(new_coords[ring_offsets[shape_offsets[:-1]]], plane), 0))
    if ok.all():
        return result
    # Turned out of their polygon's plane (a prism onto a side face, a face tilted): their faces as meshes.
    rows, others = np.flatnonzero(~ok), np.flatnonzero(ok)
    turned = mesh_shapes.reframe_meshes(chunk, shapes.take(rows), new_axes[rows], frame[rows])
    return Shapes.merge([result.take(others), turned], [others, rows])
