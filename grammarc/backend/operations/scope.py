"""Scope operations: ``T``/``S``/``R`` (``t s r``), CityEngine's ``translate`` and ``rotate`` in a coordinate
system, ``extrude``, ``alignScopeToAxes``/``alignScopeToGeometry``/``rotateScope`` and ``mirror``; and
``center``, which the body runner calls (it centres on the scope the body began with or last pushed, which
only the runner holds).

They change the cursor's scope and return it. Reads: the scope (``origin``, ``size``, ``frame``), ``geom``
(extrude, align, mirror), and what their expressions read. Writes: ``T``, ``translate`` and ``center`` the
``origin``, ``S`` the ``size``, ``R`` and ``rotate`` the ``frame`` (and ``r(scopeCenter, ...)`` the
``origin``, to keep the centre), ``mirror`` the ``geom``; ``extrude`` and the alignments all four of the
scope and geometry, as they turn scopes around their geometry (``backend.reframing``).
"""

from __future__ import annotations

import numpy as np

from grammarc.backend.context import Context
from grammarc.backend.euler import angles as euler_angles
from grammarc.backend.euler import orientation, rotation
from grammarc.backend.evaluate import evaluate, evaluate_array
from grammarc.backend.functions.coordinates import system
from grammarc.backend.operations.table import operation
from grammarc.backend.outlines import flat_axis, polygons_of
from grammarc.backend.reframing import reframed, turned
from grammarc.backend.shapes import Shapes, asset_geom, asset_of
from grammarc.constants import TOL
from grammarc.geometry import components as comp_kernels
from grammarc.geometry.meshes import is_polygon
from grammarc.geometry.polygons import PLANE_U, PLANE_V
from grammarc.geometry.reframe import NORMAL_UP
from grammarc.ir import nodes as ir

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


@operation(ir.Rotate, writes=("origin", "frame"), meshes=True)
def rotate(ctx: Context, cursor: Shapes, op: ir.Rotate) -> Shapes:
    """``R``/``r(x, y, z)`` about the scope's own axes around its origin; ``r(scopeCenter, x, y, z)``
    turns the same way and moves the origin so that the scope's centre stays where it was."""
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
    origin = cursor.origin
    if op.center:
        half = cursor.size / 2
        origin = origin + np.einsum("ni,nij->nj", half, frames[cursor.frame] - frames[frame])
    return cursor.with_scope(origin, cursor.size, frame, cursor.geom)


@operation(ir.Transform, writes=("origin", "frame"), meshes=True)
def transform(ctx: Context, cursor: Shapes, op: ir.Transform) -> Shapes:
    """CityEngine ``translate`` and ``rotate`` in a coordinate system (``functions.coordinates.system``;
    the pivot is the object system, as grammarc does not apply ``setPivot``).

    ``translate``: ``rel`` adds the vector along the system's axes, ``abs`` puts the scope origin at the
    position in the system. ``rotate``: the scope's orientation in the system, as the angles ``scope.r``
    reads (about the system's x, then y, then z: ``backend.euler``), becomes the given angles (``abs``) or
    those angles plus the given ones (``rel``, as the reference says: the angles are added); the scope turns
    around its origin. In the scope system the scope's own angles are 0, so ``rel`` and ``abs`` agree there:
    a turn about the scope's axes in that order.

    The reference calls ``r(x, y, z)`` the same as ``rotate(rel, pivot, x, y, z)``; grammarc's ``R`` turns
    about the scope's own axes instead (x, then the new y, then the new z), which gives the same scope when
    the scope's axes are the pivot's and one angle is not 0, and when the angles come in z, y, x order of
    calls, but not in general (``r(10, 20, 0)`` reads back as ``scope.r`` (10.6, 19.7, 3.6), not (10, 20,
    0)). The records of ``r`` stay as they were; ``rotate`` follows the reference.
    """
    env = ctx.env(cursor)
    n = len(cursor)
    values = np.stack([np.broadcast_to(evaluate_array(e, env), (n,)) for e in op.values], axis=1)
    origin, axes = system(op.system, env)
    frames = ctx.chunk.frames
    if op.kind == "translate":
        base = cursor.origin if op.relative else origin  # the scope system's origin is the scope's
        new_origin = base + np.einsum("ni,nij->nj", values, axes)
        return cursor.with_scope(new_origin, cursor.size, cursor.frame, cursor.geom)
    if op.relative and op.system != "scope":
        # rows: the scope's axes in the system's coordinates
        values = values + euler_angles(np.einsum("nij,nkj->nik", frames[cursor.frame], axes))
    frame = frames.add(np.einsum("nij,njk->nik", orientation(*values.T), axes))
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
    another scope axis (a comp(f) face's z) is first re-expressed in such a scope."""
    height = evaluate_array(op.height, ctx.env(cursor))
    axis = flat_axis(ctx.chunk, cursor)
    bad = (axis < 0) | ~np.isfinite(height)
    if bad.any():
        ctx.fail(cursor, bad, "`extrude` needs a face (a flat shape) and a finite height", op.span)
    cursor = turned(ctx, cursor, axis != 1, NORMAL_UP, axis, op.span)
    size = cursor.size.copy()
    size[:, 1] = np.abs(height)
    up = ctx.chunk.frames[cursor.frame][:, 1]
    origin = cursor.origin + np.minimum(height, 0.0)[:, None] * up
    return cursor.with_scope(origin, size, cursor.frame, cursor.geom)


@operation(ir.AlignScope, writes=_SCOPE, meshes=True)
def align_scope(ctx: Context, cursor: Shapes, op: ir.AlignScope) -> Shapes:
    """New scope axes around unchanged geometry (``backend.reframing``)."""
    axes = ctx.chunk.frames[cursor.frame]
    n = len(cursor)
    if op.mode == "world":
        new_axes = np.broadcast_to(np.eye(3), (n, 3, 3))
    elif op.mode == "y":
        up = np.array([0.0, 1.0, 0.0])
        x = axes[:, 0] - axes[:, 0, 1:2] * up
        flat = np.linalg.norm(x, axis=1) < 1e-9
        x[flat] = axes[flat, 2] - axes[flat, 2, 1:2] * up
        x /= np.linalg.norm(x, axis=1, keepdims=True)
        new_axes = np.stack([x, np.broadcast_to(up, x.shape), np.cross(x, up)], axis=1)
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
