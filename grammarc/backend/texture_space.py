"""Texture space: a shape's texture coordinates as affine maps from world coordinates to (u, v).

CityEngine's projections (``setupProjection``) are planar: u and v are affine functions of a point's position.
``projectUV`` gives every vertex of the shape's faces the projection's coordinates, and ``translateUV``,
``scaleUV``, ``rotateUV``, ``tileUV`` and ``normalizeUV`` change them by affine maps of texture space. So a
shape's coordinates of a set are one 2 x 4 map ``M`` (``uv = M[:, :3] @ X + M[:, 3]`` for a world point
``X``) in the chunk's ``TextureMaps``, whose id is in one of its ``dynamic`` columns (``slots.uv_slots``), its
projection's in another: children inherit both, and since the geometry of a split or a component split
stays where it was, their coordinates stay continuous across the cut without any work. Map 0 is NaN: the
shape has none. Two id columns per set, not the maps' 16 numbers, keep the cost of a split low.

A lot starts with coordinates of set 0 in metres along its scope's x (u) and z (v), from its scope's origin,
the parameterization CityEngine gives a street shape (u along it, v across), so that the street rules'
``split(v, unitSpace, 0)`` derive on footprints too.

The geometry's extent in texture space (``geometry.uMin``..., ``normalizeUV``, ``tileUV`` with ``~``) is the
map applied to the vertices of its faces (``geometry.queries``).

Where this differs from CityEngine, which keeps coordinates per vertex: the coordinates stay in the world
when an operation moves the geometry after ``projectUV`` (``t``, ``r``, ``s``, ``mirror``: the texture does
not follow it), and new faces (an extrusion's sides, a roof's) take the affine map of the shape they grow
from rather than coordinates of their own. Projected where the rules project, as they mostly do just
before the leaves, the two agree.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from grammarc.backend.chunk import Chunk
from grammarc.backend.plan import Plan
from grammarc.backend.shapes import Shapes
from grammarc.backend.slots import uv_slots
from grammarc.geometry.queries import shape_faces
from grammarc.ragged import segment_reduce

#: Which of a set's two columns: its projection, or its texture coordinates.
PROJECTION, COORDINATES = 0, 1


def texture_maps(plan: Plan, chunk: Chunk, shapes: Shapes, uv_set: int, which: int = COORDINATES) -> np.ndarray:
    """(n, 2, 4) float64: the shapes' map ``which`` of texture set ``uv_set`` (NaN where none; all NaN when
    the grammar names no such set)."""
    start = plan.uv_slots.get(uv_set)
    if start is None:
        return np.full((len(shapes), 2, 4), np.nan)
    if len(shapes.dynamic) <= start:  # the lots, while their attributes are evaluated: their own
        return lot_maps(shapes, chunk) if (uv_set, which) == (0, COORDINATES) else \
            np.full((len(shapes), 2, 4), np.nan)
    return chunk.texture_maps[shapes.dynamic[start + which]]


def with_texture_maps(plan: Plan, chunk: Chunk, shapes: Shapes, uv_set: int, maps: np.ndarray,
                      which: int = COORDINATES) -> Shapes:
    """``shapes`` with their map ``which`` of texture set ``uv_set`` replaced by ``maps`` (n, 2, 4)."""
    start = plan.uv_slots[uv_set] + which
    dynamic = list(shapes.dynamic)
    dynamic[start] = chunk.texture_maps.add(maps)
    return replace(shapes, dynamic=tuple(dynamic))


def planar_map(origin: np.ndarray, u_axis: np.ndarray, v_axis: np.ndarray) -> np.ndarray:
    """(n, 2, 4): u and v in metres along the unit vectors ``u_axis`` and ``v_axis`` (n, 3) from ``origin``."""
    out = np.empty((len(origin), 2, 4))
    for row, axis in enumerate((u_axis, v_axis)):
        out[:, row, :3] = axis
        out[:, row, 3] = -np.einsum("ni,ni->n", axis, origin)
    return out


def initial_column(plan: Plan, name: str, chunk: Chunk, shapes: Shapes) -> np.ndarray | None:
    """A lot's starting value of texture column ``name`` (None: ``name`` is no texture column): no
    projection, and coordinates of set 0 along its scope's x and z."""
    for uv_set in plan.uv_slots:
        names = uv_slots(uv_set)
        if name in names:
            if uv_set != 0 or name == names[PROJECTION]:
                return np.zeros(len(shapes), dtype=np.int32)
            return chunk.texture_maps.add(lot_maps(shapes, chunk))
    return None


def lot_maps(shapes: Shapes, chunk: Chunk) -> np.ndarray:
    """(n, 2, 4): lots' own texture coordinates, metres along their scope's x and z from its origin."""
    axes = chunk.frames[shapes.frame]
    return planar_map(shapes.origin, axes[:, 0], axes[:, 2])


def texture_bounds(chunk: Chunk, shapes: Shapes, maps: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The least and greatest (u, v) (n, 2) of the shapes' geometry under ``maps`` (n, 2, 4); NaN for a
    shape without coordinates or faces. A box's (or an inserted asset's, as its box) come from its size;
    polygons' and meshes' from the vertices of their faces."""
    # the maps of scope points, (n, 2, 3) and (n, 2): a scope point p is the world point origin + axes^T p
    linear = maps[:, :, :3] @ chunk.frames[shapes.frame].transpose(0, 2, 1)
    offset = (maps[:, :, :3] @ shapes.origin[:, :, None])[:, :, 0] + maps[:, :, 3]
    span = linear * shapes.size[:, None, :]
    low, high = offset + np.minimum(span, 0).sum(axis=2), offset + np.maximum(span, 0).sum(axis=2)
    rows = np.flatnonzero(shapes.geom >= 0)
    if len(rows):
        sub = shapes.take(rows)
        faces = shape_faces(sub.size, sub.geom, chunk.polygons, chunk.meshes)
        vertex_offsets = faces.ring_offsets[faces.face_offsets[faces.shape_offsets]]
        owner = rows[np.repeat(np.arange(len(rows)), np.diff(vertex_offsets))]
        uv = (linear[owner] * faces.verts[:, None, :]).sum(axis=2) + offset[owner]  # elementwise: no tiny matmuls
        low[rows] = segment_reduce(np.minimum, uv, vertex_offsets, np.nan)
        high[rows] = segment_reduce(np.maximum, uv, vertex_offsets, np.nan)
    return low, high


def metres_per_unit(maps: np.ndarray, normal: np.ndarray | None = None) -> np.ndarray:
    """(n, 2): metres on the surface per unit of u and of v: the inverse length of each row's gradient,
    within the plane of unit ``normal`` (n, 3) when given."""
    grad = maps[:, :, :3]
    if normal is not None:
        grad = grad - np.einsum("nij,nj->ni", grad, normal)[:, :, None] * normal[:, None, :]
    length = np.linalg.norm(grad, axis=2)
    with np.errstate(divide="ignore"):
        return np.where(length > 0, 1.0 / length, np.nan)
