"""Geometry queries: ``geometry.area()``, ``geometry.nVertices``, ``geometry.isConcave``... of each shape's
geometry (CityEngine's reference, "geometry functions").

Areas, volumes and counts come from ``geometry.measure``; the queries that look at faces one by one
(selected areas, orientations, angles, holes, concave or planar faces, shared edges) from the faces
``geometry.queries`` makes of every shape. A selector argument (``top``, ``world.up``, ``maxSlope``) is a
constant string the lowering checked.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from grammarc.backend.functions.table import function
from grammarc.backend.selectors import classify_faces, selector_frames
from grammarc.geometry.measure import area_and_volume, vertex_and_face_counts
from grammarc.geometry.meshes import is_mesh, is_polygon
from grammarc.geometry.queries import (
    face_shapes,
    planar_faces,
    rectangular_faces,
    shape_any,
    shape_faces,
    shared_edges,
)

if TYPE_CHECKING:
    from grammarc.backend.env import Env

#: A face of less area than this has no normal: it matches no selector and has no slope.
_NO_AREA = 1e-12


@function("geometry.nVertices", "geometry.nFaces")
def counts(call, args, env: Env):
    vertices, faces = vertex_and_face_counts(env.shapes.size, env.shapes.geom, env.chunk.polygons, env.chunk.meshes)
    return vertices if call.func == "geometry.nVertices" else faces


@function("geometry.isRectangular")
def rectangular(call, args, env: Env):
    """``geometry.isRectangular(tolerance)``: the shape has a face and all its faces are rectangles
    (``queries.rectangular_faces``). An inserted asset's faces are not known here: it is not."""
    faces = shape_faces(env.shapes.size, env.shapes.geom, env.chunk.polygons, env.chunk.meshes)
    square = rectangular_faces(faces.verts, faces.ring_offsets, faces.face_offsets, _tolerance(args[0]))
    return ~shape_any(~square, faces) & (np.diff(faces.shape_offsets) > 0) & (env.shapes.geom >= -1)


@function("geometry.area", "geometry.volume")
def measures(call, args, env: Env):
    if call.args and call.args[0].value not in ("all", "surface"):
        return _selected(call, env)
    area, volume = area_and_volume(env.shapes.size, env.shapes.geom, env.chunk.polygons, env.chunk.meshes)
    return area if call.func == "geometry.area" else volume


@function("geometry.isOriented")
def oriented(call, args, env: Env):
    return _selected(call, env)


def _selected(call, env: Env):
    """``geometry.area(selector)``: the summed area of the faces the selector takes (their normals as
    ``comp(f)`` classifies them, in the shape's own scope or the frame the selector names); and
    ``geometry.isOriented(selector)``: whether it takes any face. The ``street.`` selectors see the
    street's frame only: a face along a street is not ``street.front`` for being there."""
    faces, vector, _, _ = _faces(env)
    area = np.linalg.norm(vector, axis=1)
    parent = faces.face_shape()
    normal = vector / np.maximum(area, _NO_AREA)[:, None]
    selectors = (call.args[0].value,)
    taken = classify_faces(normal, selectors, selector_frames(env.chunk, normal, env.shapes, parent, selectors))
    taken = (taken == 0) & (area > _NO_AREA)
    if call.func == "geometry.isOriented":
        return shape_any(taken, faces)
    return np.bincount(parent, weights=np.where(taken, area, 0.0), minlength=len(env.shapes))


@function("geometry.angle")
def angle(call, args, env: Env):
    """``geometry.angle(maxSlope|azimuth|zenith)`` of the shape's steepest face: its slope is the angle
    between its plane and the world's xz-plane (0 to 90 degrees), its azimuth the compass bearing its
    normal faces, clockwise from north (world -z) in [0, 360[, 0 for a level face; zenith is 90 minus
    the slope. A face with a normal (the common case, after ``comp(f)``) is measured exactly; of a solid,
    the steepest face counts, the first of equally steep ones. No face: 0."""
    faces, vector, _, _ = _faces(env)
    n = len(env.shapes)
    parent = faces.face_shape()
    area = np.linalg.norm(vector, axis=1)
    world = np.einsum("fi,fij->fj", vector / np.maximum(area, _NO_AREA)[:, None],
                      env.chunk.frames[env.shapes.frame][parent])
    slope = np.where(area > _NO_AREA, np.degrees(np.arccos(np.minimum(np.abs(world[:, 1]), 1.0))), -1.0)
    # per shape its steepest face, the first of ties (slopes compared to 1e-9 degrees)
    order = np.lexsort((np.arange(len(slope)), -np.round(slope, 9), parent))
    has = np.diff(faces.shape_offsets) > 0
    steepest = order[faces.shape_offsets[:-1][has]]
    out = np.zeros(n)
    kind = call.args[0].value
    if kind == "azimuth":
        x, z = world[steepest, 0], world[steepest, 2]
        bearing = np.degrees(np.arctan2(x, -z)) % 360.0
        out[has] = np.where((np.hypot(x, z) > 1e-12) & (bearing < 360.0), bearing, 0.0)
        return out
    out[has] = np.maximum(slope[steepest], 0.0)
    return 90.0 - out if kind == "zenith" else out


@function("geometry.isConcave", "geometry.nHoles")
def face_kinds(call, args, env: Env):
    """``geometry.isConcave``: a face of the shape is concave (a corner turns against its normal) or has
    a hole (a face with a hole is not convex); ``geometry.nHoles``: the holes of all its faces (a
    courtyard prism has two, in its bottom and its top)."""
    faces, _, holes, concave = _faces(env)
    if call.func == "geometry.isConcave":
        return shape_any(concave, faces)
    return np.bincount(faces.face_shape(), weights=holes, minlength=len(env.shapes))


@function("geometry.isPlanar")
def planar(call, args, env: Env):
    """``geometry.isPlanar(tolerance)``: the shape has a face and all its faces are planar within
    ``tolerance`` degrees (``queries.planar_faces``)."""
    faces, vector, _, _ = _faces(env)
    flat = planar_faces(faces.verts, faces.ring_offsets, faces.face_offsets, vector, _tolerance(args[0]))
    return ~shape_any(~flat, faces) & (np.diff(faces.shape_offsets) > 0)


@function("geometry.nEdges", "geometry.boundaryLength", "geometry.isClosedSurface")
def edges(call, args, env: Env):
    faces = shape_faces(env.shapes.size, env.shapes.geom, env.chunk.polygons, env.chunk.meshes)
    count, boundary, closed = shared_edges(faces, len(env.shapes))
    return {"geometry.nEdges": count, "geometry.boundaryLength": boundary}.get(call.func, closed)


@function("geometry.height")
def height(call, args, env: Env):
    """The extent of the shape's geometry along the world's y axis: its scope box's, or its faces' for
    a polygon or a mesh (a face turned in its box spans less of it)."""
    shapes = env.shapes
    axes = env.chunk.frames[shapes.frame]
    out = np.abs(axes[:, :, 1] * shapes.size).sum(axis=1)
    drawn = np.flatnonzero(is_polygon(shapes.geom) | is_mesh(shapes.geom))
    if len(drawn):
        faces = shape_faces(shapes.size[drawn], shapes.geom[drawn], env.chunk.polygons, env.chunk.meshes)
        owner = faces.vertex_shape()
        y = np.einsum("vj,vj->v", faces.verts, axes[drawn][owner, :, 1])
        low, high = np.full(len(drawn), np.inf), np.full(len(drawn), -np.inf)
        np.minimum.at(low, owner, y)
        np.maximum.at(high, owner, y)
        out[drawn] = np.where(high >= low, high - low, 0.0)
    return out


@function("geometry.isInstanced")
def instanced(call, args, env: Env):
    """An inserted asset, unchanged since its insert (grammarc changes none in place)."""
    return env.shapes.geom < -1


def _tolerance(value) -> float:
    """A tolerance in degrees for the whole batch: the largest asked (CityEngine's are constants)."""
    return float(np.max(value)) if np.size(value) else 0.0


def _faces(env: Env):
    """The shapes' faces and, per face, its vector area (F, 3), holes (F,) and concavity (F,)."""
    faces = shape_faces(env.shapes.size, env.shapes.geom, env.chunk.polygons, env.chunk.meshes)
    return (faces, *face_shapes(faces.verts, faces.ring_offsets, faces.face_offsets))
