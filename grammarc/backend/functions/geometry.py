"""Geometry queries: ``geometry.area()``, ``geometry.nVertices``... of each shape's geometry."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from grammarc.backend.functions.table import function
from grammarc.geometry.measure import area_and_volume, is_rectangular, vertex_and_face_counts

if TYPE_CHECKING:
    from grammarc.backend.env import Env


@function("geometry.nVertices", "geometry.nFaces")
def counts(call, args, env: Env):
    vertices, faces = vertex_and_face_counts(env.shapes.size, env.shapes.geom, env.chunk.polygons, env.chunk.meshes)
    return vertices if call.func == "geometry.nVertices" else faces


@function("geometry.isRectangular")
def rectangular(call, args, env: Env):
    return is_rectangular(env.shapes.size, env.shapes.geom, env.chunk.polygons,
                          float(np.max(args[0])) if np.size(args[0]) else 0.0)


@function("geometry.area", "geometry.volume")
def measures(call, args, env: Env):
    area, volume = area_and_volume(env.shapes.size, env.shapes.geom, env.chunk.polygons, env.chunk.meshes)
    return area if call.func == "geometry.area" else volume
