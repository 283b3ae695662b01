"""Scope operations: ``T``/``S``/``R`` (``t s r``), ``extrude``, ``alignScopeToAxes``/``alignScopeToGeometry``/
``rotateScope`` and ``mirror``; and ``center``, which the body runner calls (it centres on the scope the body
began with or last pushed, which only the runner holds).

They change the cursor's scope and return it. Reads: the scope (``origin``, ``size``, ``frame``), ``geom``
(extrude, align, mirror), and what their expressions read. Writes: ``T`` and ``center`` the ``origin``, ``S``
the ``size``, ``R`` the ``frame``, ``mirror`` the ``geom``; ``extrude`` and the alignments all four of the
scope and geometry, as they turn scopes around their geometry (``backend.reframing``).
"""

from __future__ import annotations

import numpy as np

from grammarc.backend.context import Context
from grammarc.backend.euler import rotation
from grammarc.backend.evaluate import evaluate, evaluate_array
from grammarc.backend.mesh_shapes import store_fitted
from grammarc.backend.operations.table import operation
from grammarc.backend.outlines import flat_axis, polygons_of
from grammarc.backend.reframing import reframed, turned
from grammarc.backend.shapes import Shapes, asset_geom, asset_of
from grammarc.constants import TOL
from grammarc.geometry import components as comp_kernels
from grammarc.geometry.extrusion import extruded_meshes
from grammarc.geometry.meshes import is_polygon
from grammarc.geometry.polygons import PLANE_U, PLANE_V, plane_to_scope
from grammarc.geometry.reframe import NORMAL_UP
from grammarc.ir import nodes as ir
from grammarc.ragged import segment_of, segment_reduce

_SCOPE = ("origin", "size", "frame", "geom")


@operation(ir.Translate, writes=("origin",), meshes=True)
def translate(ctx: Context, cursor: Shapes, op: ir.Translate) -> Shapes:
    env = ctx.env(cursor)
    local = np.stack([evaluate_array(e, env) for e in op.vector], axis=1)
    delta = np.einsum("ni,nij->nj", local, ctx.chunk.frames[cursor.frame])
    return cursor.with_scope(cursor.origin + delta, cursor.size, cursor.frame, cursor.geom)


@operation(ir.Scale, writes=("size",), meshes=True)
def scale(ctx: Context, cursor: Shapes, op: ir.Scale) -> Shapes:
    env = ctx.env(cursor)
    size = np.empty_like(cursor.size)
    for axis, s in enumerate(op.sizes):
        value = evaluate_array(s.value, env)
        size[:, axis] = value * cursor.size[:, axis] if s.kind is ir.SizeKind.RELATIVE else value
    ctx.fail_negative(cursor, size, "`S` gives a negative or NaN size", op.span)
    return cursor.with_scope(cursor.origin, size, cursor.frame, cursor.geom)


@operation(ir.Rotate, writes=("frame",), meshes=True)
def rotate(ctx: Context, cursor: Shapes, op: ir.Rotate) -> Shapes:
    env = ctx.env(cursor)
    angles = [evaluate(e, env) for e in op.angles]
    frames = ctx.chunk.frames
    if all(np.ndim(a) == 0 for a in angles):
        # One rotation for all: rotate each distinct frame once.
        unique, inverse = np.unique(cursor.frame, return_inverse=True)
        matrix = rotation(*(np.full(1, a, dtype=np.float64) for a in angles))[0]
        new = frames.add(np.einsum("ij,fjk->fik", matrix, frames[unique]))
        frame = new[inverse.reshape(-1)]
    else:
        n = len(cursor)
        matrices = rotation(*(np.broadcast_to(np.asarray(a, np.float64), (n,)) for a in angles))
        frame = frames.add(np.einsum("nij,njk->nik", matrices, frames[cursor.frame]))
    return cursor.with_scope(cursor.origin, cursor.size, frame, cursor.geom)


def center(ctx: Context, cursor: Shapes, op: ir.Center, base) -> Shapes:
    """Centre the scope on ``base`` (origin, size, frame: the body's first scope or the last push) along
    ``op.axes``."""
    base_origin, base_size, base_frame = base
    frames = ctx.chunk.frames
    base_axes = frames[base_frame]
    axes = frames[cursor.frame]
    base_center = base_origin + np.einsum("ni,nij->nj", base_size / 2, base_axes)
    middle = cursor.origin + np.einsum("ni,nij->nj", cursor.size / 2, axes)
    offset = base_center - middle
    origin = cursor.origin.copy()
    for k in op.axes:
        origin += np.einsum("nj,nj->n", offset, axes[:, k])[:, None] * axes[:, k]
    return cursor.with_scope(origin, cursor.size, cursor.frame, cursor.geom)


@operation(ir.Extrude, writes=_SCOPE)
def extrude(ctx: Context, cursor: Shapes, op: ir.Extrude) -> Shapes:
    """A face becomes a solid along its normal; a negative height extrudes behind the face. As in
    CityEngine, the solid's scope keeps x and has y along the extrusion: a face whose normal is
    another scope axis (a comp(f) face's z) is first re-expressed in such a scope.

    ``vertex.normal`` is ``face.normal``: a shape here is one plane, so all its vertex normals are its
    face's. ``world.up`` extrudes a face looking up as its normal would; any other face becomes a mesh
    in a scope with y up and x the old x laid level, each vertex moved straight up, and
    ``world.up.flatTop`` moves them to one level: ``h`` above the lowest vertex, at least up to the
    highest; with a negative ``h`` down from the highest, at least to the lowest."""
    height = evaluate_array(op.height, ctx.env(cursor))
    axis = flat_axis(ctx.chunk, cursor)
    bad = (axis < 0) | ~np.isfinite(height)
    if bad.any():
        ctx.fail(cursor, bad, "`extrude` needs a face (a flat shape) and a finite height", op.span)
    if op.direction in ("world.up", "world.up.flatTop"):
        height = np.broadcast_to(height, (len(cursor),))
        normal_y = ctx.chunk.frames[cursor.frame][np.arange(len(cursor)), np.maximum(axis, 0), 1]
        slanted = (normal_y < 1 - TOL.zero) & (axis >= 0)
        if slanted.any():
            rows, others = np.flatnonzero(slanted), np.flatnonzero(~slanted)
            meshes = _extruded_upwards(ctx, cursor.take(rows), height[rows], op.direction == "world.up")
            level = _extruded_along_normal(ctx, cursor.take(others), height[others], axis[others], op.span)
            return Shapes.merge([level, meshes], [others, rows])
    return _extruded_along_normal(ctx, cursor, height, axis, op.span)


def _extruded_along_normal(ctx: Context, cursor: Shapes, height, axis: np.ndarray, span) -> Shapes:
    cursor = turned(ctx, cursor, axis != 1, NORMAL_UP, axis, span)
    size = cursor.size.copy()
    size[:, 1] = np.abs(height)
    up = ctx.chunk.frames[cursor.frame][:, 1]
    origin = cursor.origin + np.minimum(height, 0.0)[:, None] * up
    return cursor.with_scope(origin, size, cursor.frame, cursor.geom)


def _upright_axes(axes: np.ndarray) -> np.ndarray:
    """Scope axes (n, 3, 3) with y the world's up and x the old x laid level (the old z where x is
    upright), as CityEngine keeps "the x-axis direction as much as possible"."""
    up = np.array([0.0, 1.0, 0.0])
    x = axes[:, 0] - axes[:, 0, 1:2] * up
    flat = np.linalg.norm(x, axis=1) < 1e-9
    x[flat] = axes[flat, 2] - axes[flat, 2, 1:2] * up
    x /= np.linalg.norm(x, axis=1, keepdims=True)
    return np.stack([x, np.broadcast_to(up, x.shape), np.cross(x, up)], axis=1)


def _extruded_upwards(ctx: Context, cursor: Shapes, height: np.ndarray, straight: bool) -> Shapes:
    """Faces that are not level extruded along the world's up axis into meshes in upright scopes:
    every vertex by ``height`` (``straight``) or to one level (flatTop)."""
    chunk = ctx.chunk
    axes = chunk.frames[cursor.frame]
    coords, ring_offsets, shape_offsets, plane = polygons_of(chunk, cursor)
    vertex_shape = segment_of(shape_offsets)[segment_of(ring_offsets)]
    rows = np.arange(len(cursor))
    scaled = coords * np.stack([cursor.size[rows, PLANE_U[plane]], cursor.size[rows, PLANE_V[plane]]], 1)[
        vertex_shape]
    in_scope = plane_to_scope(scaled, plane[vertex_shape])
    new_axes = _upright_axes(axes)
    # a vertex in the upright scope, from the old origin: its scope point turned into the new axes
    bottom = np.einsum("vi,vij,vkj->vk", in_scope, axes[vertex_shape], new_axes[vertex_shape])
    if straight:
        lift = height[vertex_shape]
    else:
        vertex_offsets = ring_offsets[shape_offsets]
        low = segment_reduce(np.minimum, bottom[:, 1], vertex_offsets, 0.0)
        high = segment_reduce(np.maximum, bottom[:, 1], vertex_offsets, 0.0)
        level = np.where(height >= 0, np.maximum(low + height, high), np.minimum(high + height, low))
        lift = level[vertex_shape] - bottom[:, 1]
    top = bottom.copy()
    top[:, 1] += lift
    normal_y = axes[rows, plane, 1]
    verts, rings, faces, meshes = extruded_meshes(bottom, top, ring_offsets, shape_offsets,
                                                  (normal_y >= 0) == (height >= 0))
    geom, low, size = store_fitted(chunk, verts, rings, faces, meshes)
    origin = cursor.origin + np.einsum("ni,nij->nj", low, new_axes)
    return cursor.with_scope(origin, size, chunk.frames.add(np.ascontiguousarray(new_axes)), geom)


@operation(ir.AlignScope, writes=_SCOPE, meshes=True)
def align_scope(ctx: Context, cursor: Shapes, op: ir.AlignScope) -> Shapes:
    """New scope axes around unchanged geometry (``backend.reframing``)."""
    axes = ctx.chunk.frames[cursor.frame]
    n = len(cursor)
    if op.mode == "world":
        new_axes = np.broadcast_to(np.eye(3), (n, 3, 3))
    elif op.mode == "y":
        new_axes = _upright_axes(axes)
    elif op.mode == "rotate":
        env = ctx.env(cursor)
        angles = [np.broadcast_to(evaluate_array(e, env), (n,)) for e in op.angles]
        new_axes = np.einsum("nij,njk->nik", rotation(*angles), axes)
    else:
        new_axes = _geometry_axes(ctx, cursor, op, axes)
    return reframed(ctx, cursor, new_axes, op.span)


def _geometry_axes(ctx: Context, cursor: Shapes, op: ir.AlignScope, axes: np.ndarray):
    """Axes of ``alignScopeToGeometry``: up along the face's normal, x along its edge ``k``."""
    flat = cursor.size <= TOL.zero
    bad = flat.sum(axis=1) != 1
    if bad.any():
        ctx.fail(cursor, bad, "alignScopeToGeometry of a solid is not supported yet (only faces)", op.span)
    coords, ring_offsets, shape_offsets, plane = polygons_of(ctx.chunk, cursor)
    rows = np.arange(len(cursor))
    edge = np.round(evaluate_array(op.angles[0], ctx.env(cursor))).astype(np.int64)
    start = ring_offsets[shape_offsets[:-1]]
    count = ring_offsets[shape_offsets[:-1] + 1] - start
    j = start + np.mod(edge, count)
    k = start + np.mod(edge + 1, count)
    a, b = PLANE_U[plane], PLANE_V[plane]

    def world(v):
        return ((coords[v, 0] * cursor.size[rows, a])[:, None] * axes[rows, a]
                + (coords[v, 1] * cursor.size[rows, b])[:, None] * axes[rows, b])

    x = world(k) - world(j)
    x /= np.linalg.norm(x, axis=1, keepdims=True)
    normal = axes[rows, plane]
    if op.mode == "geometry-y":
        return np.stack([x, normal, np.cross(x, normal)], axis=1)
    return np.stack([x, np.cross(normal, x), normal], axis=1)


@operation(ir.Mirror, writes=("geom",))
def mirror(ctx: Context, cursor: Shapes, op: ir.Mirror) -> Shapes:
    """Mirror the geometry inside its scope: assets flip (a bit of their geometry code), polygons
    are stored flipped with their rings reversed (so they still wind around their normal); a scope
    box is its own mirror image."""
    env = ctx.env(cursor)
    flips = [np.broadcast_to(evaluate_array(f, env, dtype=bool), (len(cursor),)) for f in op.axes]
    bits = flips[0] * 1 + flips[1] * 2 + flips[2] * 4
    geom = cursor.geom.copy()
    assets = (geom < -1) & (bits > 0)
    if assets.any():
        asset, mirrored = asset_of(geom[assets])
        geom[assets] = asset_geom(asset, mirrored ^ bits[assets])
    poly = np.flatnonzero(is_polygon(geom) & (bits > 0))
    if len(poly):
        store = ctx.chunk.polygons
        coords, ring_offsets, poly_offsets = store.gather(geom[poly])
        plane = store.plane[geom[poly]]
        vertex_poly = np.repeat(np.repeat(np.arange(len(poly)), np.diff(poly_offsets)),
                                np.diff(ring_offsets))
        a = np.where(plane == 0, 1, 0)[vertex_poly]  # the plane's in-plane axes
        b = np.where(plane == 2, 1, 2)[vertex_poly]
        shape_bits = bits[poly][vertex_poly]
        flip_u = (shape_bits >> a) & 1
        flip_v = (shape_bits >> b) & 1
        coords = coords.copy()
        coords[:, 0] = np.where(flip_u, 1.0 - coords[:, 0], coords[:, 0])
        coords[:, 1] = np.where(flip_v, 1.0 - coords[:, 1], coords[:, 1])
        once = (flip_u ^ flip_v).astype(bool)  # one flip turns the winding round
        coords = np.where(once[:, None], comp_kernels.reverse_rings(coords, ring_offsets), coords)
        geom[poly] = store.add(coords, ring_offsets, poly_offsets, plane)
    return cursor.with_scope(cursor.origin, cursor.size, cursor.frame, geom)
