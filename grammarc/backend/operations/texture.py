"""Texture space: ``setupProjection``, ``projectUV``/``deleteUV``, ``copyUV``, ``translateUV``, ``scaleUV``,
``rotateUV``, ``tileUV``, ``normalizeUV``, and the frame of a split in texture space (``split(u|v, ...)``).

A shape's projection and texture coordinates of a set are affine maps from world coordinates to (u, v) in
its ``dynamic`` columns (``backend.texture_space``): each operation here computes new maps for the whole
batch. Reads: the scope (``origin``, ``size``, ``frame``), ``geom`` (the extent of the geometry in texture
space), ``dynamic``, and what the arguments read. Writes: ``dynamic``.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from grammarc.backend.context import Context
from grammarc.backend.evaluate import evaluate_array
from grammarc.backend.operations.table import operation
from grammarc.backend.reframing import reframed
from grammarc.backend.shapes import Shapes
from grammarc.backend.texture_space import (
    COORDINATES,
    PROJECTION,
    metres_per_unit,
    texture_bounds,
    texture_maps,
    with_texture_maps,
)
from grammarc.constants import TOL
from grammarc.geometry.meshes import is_polygon
from grammarc.ir import nodes as ir


@operation(ir.SetupProjection, writes=("dynamic",), meshes=True)
def setup_projection(ctx: Context, cursor: Shapes, op: ir.SetupProjection) -> Shapes:
    """The projection: u along the frame's axis ``u_axis`` one texture width per unit from the frame's
    origin moved by the offset, v alike. In the world's frame, relative and floating sizes measure the
    extent of the scope's box along the world's axis."""
    n = len(cursor)
    env = ctx.env(cursor)
    axes = ctx.chunk.frames[cursor.frame]
    if op.frame == "scope":
        frame, origin, extent = axes, cursor.origin, cursor.size
    else:
        frame, origin = np.broadcast_to(np.eye(3), (n, 3, 3)), np.zeros((n, 3))
        extent = np.einsum("nj,njk->nk", cursor.size, np.abs(axes))
    projection = np.empty((n, 2, 4))
    for row, (axis, size, offset) in enumerate(zip((op.u_axis, op.v_axis), op.sizes, op.offsets)):
        width = _tile_size(evaluate_array(size.value, env), size.kind, extent[:, axis])
        direction = frame[:, axis]
        with np.errstate(divide="ignore", invalid="ignore"):
            scale = np.where(width != 0, 1.0 / width, np.nan)  # a texture of no size: no coordinates
        projection[:, row, :3] = direction * scale[:, None]
        shift = evaluate_array(offset.value, env)
        if offset.kind is ir.SizeKind.RELATIVE:
            shift = shift * extent[:, axis]
        projection[:, row, 3] = -(np.einsum("ni,ni->n", direction, origin) + shift) * scale
    return with_texture_maps(ctx.plan, ctx.chunk, cursor, op.uv_set, projection, PROJECTION)


@operation(ir.ProjectUV, writes=("dynamic",), meshes=True)
def project_uv(ctx: Context, cursor: Shapes, op: ir.ProjectUV) -> Shapes:
    """The projection becomes the texture coordinates (``deleteUV``: there are none)."""
    start = ctx.plan.uv_slots[op.uv_set]
    dynamic = list(cursor.dynamic)
    dynamic[start + COORDINATES] = np.zeros(len(cursor), np.int32) if op.delete else dynamic[start + PROJECTION]
    return replace(cursor, dynamic=tuple(dynamic))


@operation(ir.CopyUV, writes=("dynamic",), meshes=True)
def copy_uv(ctx: Context, cursor: Shapes, op: ir.CopyUV) -> Shapes:
    """Set ``uv_set`` takes set ``source``'s coordinates (their map's id: the table is not touched)."""
    slots = ctx.plan.uv_slots
    dynamic = list(cursor.dynamic)
    dynamic[slots[op.uv_set] + COORDINATES] = dynamic[slots[op.source] + COORDINATES]
    return replace(cursor, dynamic=tuple(dynamic))


@operation(ir.TransformUV, writes=("dynamic",), meshes=True)
def transform_uv(ctx: Context, cursor: Shapes, op: ir.TransformUV) -> Shapes:
    """``translateUV`` adds to u and v, ``scaleUV`` multiplies them, ``rotateUV`` turns them
    counter-clockwise about (0, 0) by degrees."""
    env = ctx.env(cursor)
    values = [evaluate_array(v, env) for v in op.values]
    maps = texture_maps(ctx.plan, ctx.chunk, cursor, op.uv_set)
    if op.kind == "translate":
        maps[:, 0, 3] += values[0]
        maps[:, 1, 3] += values[1]
    elif op.kind == "scale":
        maps *= np.stack(values, axis=1)[:, :, None]
    else:
        angle = np.radians(values[0])
        cos, sin = np.cos(angle)[:, None], np.sin(angle)[:, None]
        maps = np.stack([cos * maps[:, 0] - sin * maps[:, 1], sin * maps[:, 0] + cos * maps[:, 1]], axis=1)
    return with_texture_maps(ctx.plan, ctx.chunk, cursor, op.uv_set, maps)


@operation(ir.TileUV, writes=("dynamic",), meshes=True)
def tile_uv(ctx: Context, cursor: Shapes, op: ir.TileUV) -> Shapes:
    """One texture tile per ``width`` metres of u on the surface (per ``height`` of v); 0 leaves that
    direction alone. Floating and relative sizes measure the geometry's extent in metres along u (v), and
    their tiles start where the geometry does."""
    n = len(cursor)
    env = ctx.env(cursor)
    maps = texture_maps(ctx.plan, ctx.chunk, cursor, op.uv_set)
    metres = metres_per_unit(maps)
    low, high = texture_bounds(ctx.chunk, cursor, maps)
    for row, size in enumerate(op.sizes):
        value = evaluate_array(size.value, env)
        tile = _tile_size(value, size.kind, (high[:, row] - low[:, row]) * metres[:, row])
        keep = (value == 0) | (tile == 0)
        start = low[:, row] if size.kind is not ir.SizeKind.ABSOLUTE else np.zeros(n)
        with np.errstate(divide="ignore", invalid="ignore"):
            scaled = (maps[:, row] - start[:, None] * _CONSTANT) * (metres[:, row] / tile)[:, None]
        maps[:, row] = np.where(keep[:, None], maps[:, row], scaled)
    return with_texture_maps(ctx.plan, ctx.chunk, cursor, op.uv_set, maps)


@operation(ir.NormalizeUV, writes=("dynamic",), meshes=True)
def normalize_uv(ctx: Context, cursor: Shapes, op: ir.NormalizeUV) -> Shapes:
    """The geometry's texture coordinates moved and scaled onto [0, 1] (``u``, ``v``: that direction only;
    ``uvUniform``: both by the larger extent). A direction of no extent is only moved."""
    maps = texture_maps(ctx.plan, ctx.chunk, cursor, op.uv_set)
    low, high = texture_bounds(ctx.chunk, cursor, maps)
    extent = high - low
    if op.mode == "uvUniform":
        extent = np.repeat(extent.max(axis=1, keepdims=True), 2, axis=1)
    scale = np.where(extent > TOL.zero, 1.0 / np.where(extent > TOL.zero, extent, 1.0), 1.0)
    for row in {"uv": (0, 1), "uvUniform": (0, 1), "u": (0,), "v": (1,)}[op.mode]:
        maps[:, row, 3] -= low[:, row]
        maps[:, row] *= scale[:, row, None]
    return with_texture_maps(ctx.plan, ctx.chunk, cursor, op.uv_set, maps)


def texture_axis(ctx: Context, cursor: Shapes, op: ir.GroupSplit) -> tuple[Shapes, np.ndarray, np.ndarray]:
    """A split in texture space as a split along x: the shapes turned about their surface's normal so that
    their x runs the way u (v) grows on it, the scope fitted to the geometry (so the split starts where
    the geometry's u does), the metres per size unit, and the frames (n,) the children return to (the
    shapes' own).

    The surface's normal is a polygon's or prism's plane axis, a flat scope's flat axis, else the scope
    axis across which u changes least. A shape on which u does not change fails its lot.
    """
    chunk = ctx.chunk
    axes = chunk.frames[cursor.frame]
    rows = np.arange(len(cursor))
    grad = texture_maps(ctx.plan, ctx.chunk, cursor, op.uv_set)[:, op.axis, :3]
    normal_axis = np.argmin(np.abs(np.einsum("nji,ni->nj", axes, grad)), axis=1)
    flat = cursor.size <= TOL.zero
    normal_axis = np.where((cursor.geom == -1) & flat.any(axis=1), np.argmax(flat, axis=1), normal_axis)
    polygon = is_polygon(cursor.geom)
    normal_axis[polygon] = chunk.polygons.plane[cursor.geom[polygon]]
    normal = axes[rows, normal_axis]
    along = grad - np.einsum("ni,ni->n", grad, normal)[:, None] * normal
    length = np.linalg.norm(along, axis=1)
    bad = ~(length > TOL.zero)
    if bad.any():
        name = "uv"[op.axis]
        ctx.fail(cursor, bad, f"`split({name}, ...)` of a shape whose texture set {op.uv_set} has no {name} "
                 "across its surface (projectUV first)", op.span)
    direction = along / length[:, None]
    turned = reframed(ctx, cursor, np.stack([direction, np.cross(normal, direction), normal], axis=1), op.span)
    return turned, np.ones(len(cursor)) if op.unit_space else 1.0 / length, cursor.frame


#: The constant term of a map's row: what moving u or v by a number changes.
_CONSTANT = np.array([0.0, 0.0, 0.0, 1.0])


def _tile_size(value: np.ndarray, kind: ir.SizeKind, extent: np.ndarray) -> np.ndarray:
    """A texture's size (n,) in metres: ``value`` itself, times ``extent`` (relative), or the extent
    divided into whole tiles of about ``value`` (floating, at least one)."""
    if kind is ir.SizeKind.ABSOLUTE:
        return value
    if kind is ir.SizeKind.RELATIVE:
        return value * extent
    with np.errstate(divide="ignore", invalid="ignore"):
        count = np.maximum(1.0, np.round(extent / np.abs(value)))
    return np.where(value != 0, np.sign(value) * extent / count, 0.0)
