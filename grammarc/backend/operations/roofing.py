"""The roofs of faces: ``roofGable/Hip/Pyramid/Shed/Ridge``, ``envelope`` (and the paper's ``Roof``), and
``taper``, the pyramid of a face.

Each takes the batch's faces as outlines in their scopes' units (``outlines.polygons_of``) and makes one
mesh per face (``backend.mesh_shapes``; ``geometry.roofs`` and ``geometry.ridges`` make the faces).
Reads: the scope (``origin``, ``size``, ``frame``), ``geom``, ``lot`` (an envelope's street selectors) and
what their expressions read. Writes: ``origin``, ``size`` and ``geom`` (``taper`` the ``frame`` too: its y
turns to the face's normal).
"""

from __future__ import annotations

import numpy as np
import shapely

from grammarc.backend import mesh_shapes
from grammarc.backend.box_rings import corners
from grammarc.backend.context import Context
from grammarc.backend.evaluate import evaluate_array
from grammarc.backend.operations.faces import face_polygons, world_points
from grammarc.backend.operations.table import operation
from grammarc.backend.outlines import flat_axis, polygons_of
from grammarc.backend.reframing import turned
from grammarc.backend.selectors import classify_faces, selector_frames
from grammarc.backend.shapes import Shapes
from grammarc.constants import TOL
from grammarc.geometry.polygons import PLANE_U, PLANE_V, plane_to_scope
from grammarc.geometry.reframe import NORMAL_UP
from grammarc.geometry.ridges import ridge_roofs
from grammarc.geometry.roofs import PYRAMID, roof_meshes
from grammarc.ir import nodes as ir
from grammarc.ragged import next_in_segment, segment_of


@operation(ir.Roof, writes=("origin", "size", "geom"))
def roof(ctx: Context, cursor: Shapes, op: ir.Roof) -> Shapes:
    """A roof over each face (``geometry.roofs``). CityEngine roofs faces; the paper's ``Roof`` roofs
    the footprint of a solid (its polygon, or the scope's x-z rectangle)."""
    env = ctx.env(cursor)
    n = len(cursor)
    value, overhang, index = (np.ascontiguousarray(np.broadcast_to(
        np.asarray(evaluate_array(e, env), dtype=np.float64), (n,))) for e in (op.value, op.overhang, op.index))
    checks = [
        (cursor.geom < -1, "of an inserted asset"),
        (~np.isfinite(value) | ~np.isfinite(overhang) | ~np.isfinite(index), "with a value that is not finite"),
        # (``by_height`` is a bool of the node, not of the shapes: ``~`` of it would be -1 or -2)
        ((not op.by_height) & (np.abs(value) >= 90), "with an angle of 90 degrees or more"),
    ]
    # CityEngine roofs faces. A face that ``s`` gave a size across it stays flat in CityEngine but is a
    # box here: an envelope (candler sizes its ventilation faces so) takes the box's base
    if ctx.plan.leaf_bodies and op.kind != "envelope":
        checks.append((flat_axis(ctx.chunk, cursor) < 0, "of a solid (CityEngine roofs faces)"))
    cap = edges = even = None
    polygons = polygons_of(ctx.chunk, cursor, corners(ctx.plan, cursor))
    if op.cap is not None:
        cap = np.broadcast_to(np.asarray(evaluate_array(op.cap, env), float), (n,))
        sides = [(overhang, value), *((evaluate_array(h, env), evaluate_array(a, env)) for h, a in op.sides)]
        checks[2] = (np.any([(a <= 0) | (a > 90) for _, a in sides], axis=0), "with an angle outside (0, 90]")
        checks.append((np.any([~np.isfinite(h) | ~np.isfinite(a) for h, a in sides], axis=0),
                       "with a base height or angle that is not finite"))
        edges = envelope_edges(ctx, cursor, polygons, sides)
    if op.even is not None:
        even = np.ascontiguousarray(np.broadcast_to(np.asarray(evaluate_array(op.even, env), bool), (n,)))
    if op.overhang_y is not None and not op.indexed:
        overhang_y = evaluate_array(op.overhang_y, env)
        checks.append((np.abs(overhang_y - overhang) > TOL.zero,
                       "with overhangY other than overhangX (gable ends overhang as eaves do)"))
    for bad, what in checks:
        if np.any(bad):
            ctx.fail(cursor, np.broadcast_to(bad, (n,)), f"`{op.kind}` {what}", op.span)
    ridge = np.full(n, op.kind == "roofRidge")
    if op.indexed:
        ridge = _convex_faces(ctx, cursor, op)
    if ridge.any():
        roofed, failed = _ridge_roofs(ctx, cursor, op, ridge, value, overhang, index)
    else:
        roofed, failed = mesh_shapes.build_roofs(ctx.chunk, cursor, op.kind, polygons, value, op.by_height,
                                                 overhang, index, cap, even, edges)
    if failed.any():
        ctx.fail(cursor, failed, f"`{op.kind}` found no roof for this polygon (its straight skeleton "
                 "did not close, or the overhang's outline crosses itself at a sharp corner)", op.span)
    return roofed


def envelope_edges(ctx: Context, cursor: Shapes, polygons, sides: list) -> tuple[np.ndarray, np.ndarray]:
    """An envelope's base height and angle (V,) under the edge from each vertex of ``polygons``
    (``outlines.polygons_of``), from ``sides``: the (baseHeight, angle) pairs (each (n,) or a scalar) of
    front; front and back; front, back and sides; or front, back, right and left. Edges are classified
    by their outward normals as ``street.front``, ``street.back``, ``street.right`` and ``street.left``
    (which fall back to ``object.`` on lots without streets), as the reference says. Where a side is not
    given (the sides of ``envelope(dir, h, front, angle, back, angle)``), and on edges that face up or
    down (an envelope on a wall), the front's pair serves: one pair means the same all round."""
    coords, ring_offsets, shape_offsets, plane = polygons
    n = len(cursor)
    ring_shape = segment_of(shape_offsets)
    vertex_ring = segment_of(ring_offsets)
    owner = ring_shape[vertex_ring]
    rows = np.arange(n)
    scale = np.stack([cursor.size[rows, PLANE_U[plane]], cursor.size[rows, PLANE_V[plane]]], axis=1)
    points = coords * scale[owner]
    after = next_in_segment(ring_offsets)
    step = points[after] - points
    cross = points[:, 0] * points[after, 1] - points[after, 0] * points[:, 1]
    exterior = vertex_ring == shape_offsets[:-1][owner]
    turn = np.sign(np.bincount(owner[exterior], weights=cross[exterior], minlength=n))
    # the interior lies left of the exterior ring where it turns counter-clockwise in (u, v)
    normal = plane_to_scope(turn[owner][:, None] * np.stack([step[:, 1], -step[:, 0]], axis=1), plane[owner])
    names = ("street.front", "street.back", "street.right", "street.left")
    frames = selector_frames(ctx.chunk, normal, cursor, owner, names,
                             world_points(ctx, cursor, owner, plane, (points, points[after])))
    which = classify_faces(normal, names, frames)
    order = {1: (0, 0, 0, 0, 0), 2: (0, 1, 0, 0, 0), 3: (0, 1, 2, 2, 0), 4: (0, 1, 2, 3, 0)}[len(sides)]
    pick = np.asarray(order)[which]
    base = np.stack([np.broadcast_to(h, (n,)) for h, _ in sides])
    angle = np.stack([np.broadcast_to(a, (n,)) for _, a in sides])
    return (np.ascontiguousarray(base[pick, owner], dtype=np.float64),
            np.ascontiguousarray(angle[pick, owner], dtype=np.float64))


def _convex_faces(ctx: Context, cursor: Shapes, op: ir.Roof) -> np.ndarray:
    """The faces (n,) bool that ``roofGable`` with an edge index roofs along that edge: convex ones
    without holes (the reference: the index works on convex shapes of one face). The others get the
    gable of their straight skeleton, the index ignored."""
    polygons, _ = face_polygons(ctx, cursor, op.kind, op.span)
    hull = shapely.area(shapely.convex_hull(polygons))
    return (shapely.get_num_interior_rings(polygons) == 0) & (
        hull - shapely.area(polygons) <= TOL.area_floor + 1e-9 * hull)


def _ridge_roofs(ctx: Context, cursor: Shapes, op: ir.Roof, ridge: np.ndarray, value, overhang, index):
    """``roofRidge`` (every face: the ridge along the scope's x laid onto the face) and ``roofGable``
    with an edge index (the faces ``ridge``: the ridge along that edge of the outer ring, the others
    the skeleton's gable) (``geometry.ridges``): the roofed shapes and the mask (n,) of failures."""
    rows, others = np.flatnonzero(ridge), np.flatnonzero(~ridge)
    sub = cursor.take(rows)
    polygons, plane = face_polygons(ctx, sub, op.kind, op.span)
    if op.indexed:
        ring = shapely.get_exterior_ring(polygons)
        coords, owner = shapely.get_coordinates(ring, return_index=True)
        closed = np.bincount(owner, minlength=len(rows))  # each ring's vertices and its closing repeat
        start = np.r_[0, np.cumsum(closed)[:-1]]
        edge = start + np.mod(index[rows], closed - 1).astype(np.int64)
        direction = coords[edge + 1] - coords[edge]
    else:  # the scope's x in the face's plane, or the plane's u where x is its normal
        direction = np.zeros((len(rows), 2))
        direction[:, 0] = (PLANE_U[plane] == 0) | (PLANE_V[plane] != 0)
        direction[:, 1] = PLANE_V[plane] == 0
    overhang_y = overhang if op.overhang_y is None else np.broadcast_to(
        np.asarray(evaluate_array(op.overhang_y, ctx.env(cursor)), float), (len(cursor),))
    overhang_x = overhang if op.indexed else np.zeros(len(cursor))
    overhang_y = overhang_y if op.indexed else np.zeros(len(cursor))
    verts, rings, faces, meshes, ok = ridge_roofs(polygons, plane, direction, value[rows], op.by_height,
                                                  overhang_x[rows], overhang_y[rows], TOL.zero)
    roofed = mesh_shapes.roof_shapes(ctx.chunk, sub, plane, verts, rings, faces, meshes)
    failed = np.zeros(len(cursor), dtype=bool)
    failed[rows] = ~ok
    if not len(others):
        return roofed, failed
    rest = cursor.take(others)
    outlines = polygons_of(ctx.chunk, rest, corners(ctx.plan, rest))
    gables, failed[others] = mesh_shapes.build_roofs(ctx.chunk, rest, op.kind, outlines, value[others],
                                                     op.by_height, overhang[others], np.zeros(len(others)), None)
    return Shapes.merge([roofed, gables], [rows, others]), failed



@operation(ir.Taper, writes=("origin", "size", "frame", "geom", "dynamic"))
def taper(ctx: Context, cursor: Shapes, op: ir.Taper) -> Shapes:
    """``taper(height)``: each face becomes a pyramid, a triangle from each edge of its outline to the apex
    ``height`` along the face's normal over the face's centre of gravity (holes stay in the bottom face, as
    roofPyramid's, which lifts the vertices' average instead). The scope fits the pyramid, its x as it was
    (projected into the face's plane), its y along the normal (``NORMAL_UP``, as ``extrude``'s); a negative
    height tapers behind the face, the scope's sizes staying positive as every scope's does in grammarc. A
    height of 0 leaves the face."""
    n = len(cursor)
    height = np.ascontiguousarray(np.broadcast_to(np.asarray(evaluate_array(op.height, ctx.env(cursor)), float),
                                                  (n,)))
    bad = ~np.isfinite(height)
    if bad.any():
        ctx.fail(cursor, bad, "`taper` with a height that is not finite", op.span)
    polygons, plane = face_polygons(ctx, cursor, "taper", op.span)
    rows = np.flatnonzero(np.abs(height) > TOL.zero)
    sub, face = cursor.take(rows), plane[rows]
    coords, ring_offsets, shape_offsets, _ = polygons_of(ctx.chunk, sub, corners(ctx.plan, sub))
    # behind the face: the pyramid of the face mirrored in u, turned a half turn about v (so its faces
    # still face out)
    behind = height[rows] < 0
    mirror = np.where(behind[segment_of(shape_offsets)[segment_of(ring_offsets)]], -1.0, 1.0)
    coords = np.column_stack([coords[:, 0] * mirror, coords[:, 1]])
    k = np.arange(len(rows))
    verts, rings, faces, meshes, _ = roof_meshes(
        PYRAMID, coords, ring_offsets, shape_offsets, face.astype(np.int8), sub.size[k, PLANE_U[face]],
        sub.size[k, PLANE_V[face]], np.abs(height[rows]), True, np.zeros(len(rows)),
        np.zeros(len(rows), dtype=np.int64), np.full(len(rows), np.inf), np.zeros(len(rows), dtype=bool),
        None, None)
    owner = segment_of(meshes)[segment_of(faces)[segment_of(rings)]]
    verts[behind[owner]] *= np.array([-1.0, 1.0, -1.0])
    apex = verts[:, 2] != 0
    verts[apex, :2] = shapely.get_coordinates(shapely.centroid(polygons[rows]))[owner[apex]]
    tapered = mesh_shapes.roof_shapes(ctx.chunk, sub, face, verts, rings, faces, meshes)
    # y along the normal, x kept where it can be, as extrude turns a face's scope
    tapered = turned(ctx, tapered, face != 1, NORMAL_UP, face, op.span)
    kept = np.setdiff1d(np.arange(n), rows)
    return Shapes.merge([cursor.take(kept), tapered], [kept, rows])
