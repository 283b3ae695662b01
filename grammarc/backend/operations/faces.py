"""Operations on the outlines of faces: ``offset``, ``setback``, ``setbackPerEdge``, ``setbackToArea`` and
``shapeL/U/O``, ``innerRectangle``, ``convexify``, the roofs and ``taper``, ``footprint``, ``rectify``,
``cleanupGeometry`` (and ``comp(f)`` after an ``offset``, for ``operations.component_splits``).

They share one pattern: the batch's faces as shapely polygons in their scopes' units (``face_polygons``), one
vectorized geometry step, then the pieces back as shapes (``Parts`` for the bodies of ``setback`` and
``innerRectangle``) or the face's geometry replaced (a mesh of pieces, a roof: ``backend.mesh_shapes``).
Reads: the scope (``origin``, ``size``, ``frame``), ``geom``, ``lot`` (street selectors), and what their
expressions read. Writes: the roofs ``origin``, ``size`` and ``geom`` (``taper`` the ``frame`` too: its y
turns to the face's normal); ``convexify`` and ``cleanupGeometry`` the ``geom``; ``offset``, ``footprint``
and ``rectify`` every column, as they make the shapes of their pieces anew (new keys; a shape with no piece
left goes, but ``offset`` keeps it as it was). ``offset`` also takes a shape of several faces in one plane (a mesh of an earlier offset's
pieces or of convexify's parts) or a roof, and offsets each face.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import shapely

from grammarc.backend import mesh_shapes
from grammarc.backend.box_rings import corners, piece_corners, with_corners
from grammarc.backend.children import with_context
from grammarc.backend.context import Context
from grammarc.backend.evaluate import evaluate_array
from grammarc.backend.kernels.order import group_by
from grammarc.backend.operations.table import Parts, operation
from grammarc.backend.outlines import flat_axis, polygons_of
from grammarc.backend.reframing import reframed, turned
from grammarc.backend.selectors import classify_faces, selector_frames
from grammarc.backend.shapes import COLUMNS, Shapes
from grammarc.backend.streams import piece_keys, remade_keys
from grammarc.constants import TOL
from grammarc.geometry import components as comp_kernels
from grammarc.geometry.clip import fit_pieces, scope_polygons
from grammarc.geometry.closed_arms import closed_arm_insets
from grammarc.geometry.convexify import convex_parts
from grammarc.geometry.inner_rectangle import largest_rectangles
from grammarc.geometry.insets import mitred_insets
from grammarc.geometry.meshes import MESH_BASE, is_mesh, is_polygon
from grammarc.geometry.polygons import PLANE_U, PLANE_V, plane_to_scope
from grammarc.geometry.projection import projected_outlines
from grammarc.geometry.queries import shape_faces
from grammarc.geometry.rectify import rectified
from grammarc.geometry.reframe import NORMAL_UP
from grammarc.geometry.ridges import ridge_roofs
from grammarc.geometry.roofs import PYRAMID, roof_meshes
from grammarc.geometry.setback import distances_to_area, polygon_edges, setback_regions
from grammarc.ir import nodes as ir
from grammarc.ragged import next_in_segment, ragged_take, rank_within, segment_of


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
                             _world_points(ctx, cursor, owner, plane, (points, points[after])))
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


@operation(ir.Offset, writes=COLUMNS, meshes=True)
def offset(ctx: Context, cursor: Shapes, op: ir.Offset) -> Shapes:
    """``offset(d, inside|border|all)``: the shape's face becomes its inset, the ring around it, or both
    (the faces of one shape); a shape of several faces in one plane (an earlier offset's pieces,
    convexify's parts) has each face offset, as CityEngine offsets every face of a geometry, and so has
    a roof, each face in its own plane (``_roof_offsets``).

    A shape of which nothing is left (``inside`` of a face narrower than twice the distance) stays as it
    was: PRT warns "no face selected, ignoring operation" and goes on with the shape unchanged, so
    candler's ``offset(-1.4, inside) PipeEdges`` rims a small roof's whole outline."""
    roof = is_mesh(cursor.geom) & ((cursor.size <= TOL.zero).sum(axis=1) != 1)
    if roof.any():
        flat_rows, roof_rows = np.flatnonzero(~roof), np.flatnonzero(roof)
        flat = cursor.take(flat_rows)
        pieces = _offset_selected(ctx, flat, op)
        roofs, kept = _roof_offsets(ctx, cursor.take(roof_rows), op)
        made = [flat_rows[np.unique(pieces.source)], roof_rows[kept]]
        shapes = Shapes.merge([_shape_each(ctx, flat, pieces), roofs], made)
        made = np.sort(np.concatenate(made))
    else:
        pieces = _offset_selected(ctx, cursor, op)
        shapes, made = _shape_each(ctx, cursor, pieces), np.unique(pieces.source)
    if len(made) == len(cursor):
        return shapes
    ignored = np.setdiff1d(np.arange(len(cursor)), made)
    return Shapes.merge([shapes, cursor.take(ignored)], [made, ignored])


def _offset_selected(ctx: Context, cursor: Shapes, op: ir.Offset):
    """The pieces ``offset`` keeps of flat shapes: their insets, borders or both, each shape's inside
    pieces before its border's."""
    if op.select == "all":
        inset, border, plane, polygons, faces, owner, moves = _offset_polygons(ctx, op.distance, cursor, op.span)
        pieces = fit_pieces(np.concatenate([inset, border]), np.tile(plane, 2), np.tile(faces.size, (2, 1)),
                            np.tile(polygons, 2), insets=np.arange(2 * len(inset)) < len(inset),
                            moves=np.concatenate([moves, np.full(len(moves), np.nan)]))
        # each shape's inside pieces, then its border's
        pieces = replace(pieces, source=owner[pieces.source % len(faces)])
        pieces = pieces.take(np.argsort(pieces.source, kind="stable"))
    else:
        inside, border = _offset_pieces(ctx, op.distance, cursor, op.span)
        pieces = inside if op.select == "inside" else border
    return pieces


def _roof_offsets(ctx: Context, roofs: Shapes, op: ir.Offset) -> tuple[Shapes, np.ndarray]:
    """``offset`` of roofs (meshes whose faces lie in several planes): every face, the bottom too, offset
    in its own plane (its comp(f) scope), as CityEngine offsets each face of a geometry; the pieces
    ``op.select`` keeps (each roof's inside pieces face by face, then its border's) become one mesh in a
    scope fitted to them. Returns the shapes and the mask (n,) of the roofs with any piece left."""
    d = _distances(ctx, op.distance, roofs, op.span)
    parent, _, origin, axes, size, geom, _, _ = mesh_shapes.mesh_components(ctx.chunk, roofs, mesh_shapes.FACES)
    bad = ~np.isfinite(size).all(axis=1) | ~np.isfinite(origin).all(axis=1)
    if bad.any():  # a scope scaled beyond any coordinate: GEOS takes no ring of such faces
        ctx.fail_lots(roofs.lot[parent[bad]], "`offset` of a geometry whose coordinates are not finite", op.span)
    polygons = scope_polygons(ctx.chunk.polygons, geom, size)
    inset, border = _inset_and_border(polygons, d[parent])
    chosen = {"inside": [inset], "border": [border]}
    chosen["all"] = chosen["inside"] + chosen["border"]
    parts, which = shapely.get_parts(np.concatenate(chosen[op.select]), return_index=True)
    face = which % len(polygons)
    keep = shapely.area(parts) > TOL.zero
    parts, face = parts[keep], face[keep]
    order = np.argsort(parent[face], kind="stable")
    shapes = mesh_shapes.face_piece_meshes(ctx.chunk, roofs, parts[order], parent[face[order]],
                                           origin[face[order]], axes[face[order]])
    kept = np.bincount(parent[face], minlength=len(roofs)) > 0
    shapes = shapes.take(kept)
    return replace(shapes, key=remade_keys(ctx.plan.sequential_random, shapes.key)), kept


@operation(ir.Footprint, writes=COLUMNS, meshes=True)
def footprint(ctx: Context, cursor: Shapes, op: ir.Footprint) -> Shapes:
    """``footprint()``: each shape's geometry seen along its scope's y, flat in the plane y = 0 of its
    scope (``geometry.projection``): a polygon, or a mesh of its parts where it falls apart, in a scope
    fitted to it (x and z as they were). An inserted asset is its scope box here, as for ``geometry.area``;
    a shape whose geometry covers no area seen from above (a wall) is left out, as ``offset`` leaves out a
    face with nothing left."""
    faces = shape_faces(cursor.size, cursor.geom, ctx.chunk.polygons, ctx.chunk.meshes)
    outlines = projected_outlines(faces.verts[:, [0, 2]], faces.ring_offsets, faces.face_offsets,
                                  faces.face_shape(), len(cursor))
    flat = cursor.with_scope(cursor.origin, cursor.size * [1.0, 0.0, 1.0], cursor.frame, cursor.geom)
    return _shape_each(ctx, flat, fit_pieces(outlines, np.ones(len(cursor), dtype=np.int8), flat.size))


@operation(ir.Rectify, writes=COLUMNS)
def rectify(ctx: Context, cursor: Shapes, op: ir.Rectify) -> Shapes:
    """``rectify(angle)``: each face's edges within ``angle`` degrees (the reference's range [0, 45]; others
    are taken as its nearer end) of one of the face's scope axes made parallel to it
    (``geometry.rectify``), in a scope fitted to the result; a face that falls apart becomes a mesh of its
    parts, as an offset's does, and one with nothing left goes."""
    angle = np.clip(np.broadcast_to(np.asarray(evaluate_array(op.angle, ctx.env(cursor)), float), (len(cursor),)),
                    0.0, 45.0)
    bad = np.isnan(angle)
    if bad.any():
        ctx.fail(cursor, bad, "`rectify` with an angle that is not a number", op.span)
    polygons, plane = face_polygons(ctx, cursor, "rectify", op.span)
    return _shape_each(ctx, cursor, fit_pieces(rectified(polygons, angle), plane, cursor.size, polygons))


def _shape_each(ctx: Context, cursor: Shapes, pieces) -> Shapes:
    """A shape for each row of ``cursor`` with ``pieces`` (``geometry.clip.Clipped``): its one piece, or a
    mesh of its several in one fitted scope."""
    several = np.bincount(pieces.source, minlength=len(cursor)) > 1
    if not several.any():
        return _piece_shapes(ctx, cursor, pieces, 0, remade=True)
    # a face the offset parts into pieces stays one shape: a mesh of the pieces in one fitted scope
    rows = np.flatnonzero(several)
    mine = several[pieces.source]
    single = _piece_shapes(ctx, cursor, pieces.take(~mine), 0, remade=True)
    grouped = pieces.take(mine)
    grouped = replace(grouped, source=np.searchsorted(rows, grouped.source))
    meshes = mesh_shapes.piece_meshes(ctx.chunk, cursor.take(rows), grouped)
    meshes = replace(meshes, key=remade_keys(ctx.plan.sequential_random, meshes.key))
    return Shapes.merge([single, meshes], [pieces.source[~mine], rows])


def offset_faces(ctx: Context, cursor: Shapes, op: ir.CompFaces) -> Parts:
    """``offset(d) comp(f){ inside: ... | border: ... }``: the offset's faces as components."""
    pieces = _offset_pieces(ctx, op.offset, cursor, op.span)
    border_site = (op.site << 20) + 1  # another stream than the inside faces'
    shapes, kind = _pieces_by_parent(ctx, cursor, pieces, [op.site, border_site])
    shapes = _along_first_edges(ctx, shapes, pieces, op.span)
    names = ("inside", "border")
    which = np.full(len(kind), len(op.selectors), dtype=np.int64)
    for i in range(len(op.selectors) - 1, -1, -1):
        selector = op.selectors[i]
        which[(selector == "all") | (np.array(names)[kind] == selector)] = i
    keep = which < len(op.selectors)
    shapes, which = shapes.take(keep), which[keep]
    ctx.count(shapes, op.span)
    order, offsets = group_by(which, len(op.parts))
    return Parts(op.parts, shapes.take(order), offsets)


def _along_first_edges(ctx: Context, shapes: Shapes, pieces: list, span) -> Shapes:
    """Face components whose scope x runs along their first edge, as the reference gives every ``comp(f)``
    face: the scopes of ``shapes`` (the ``pieces`` (``Clipped``) in ``_pieces_by_parent``'s order) turned
    about their normal where their first edge leaves the x axis (an inset whose vertex 0 the offset made
    vanish starts further on, and PRT's massing splits it along that edge). A rectangle keeps no vertex
    order in its shape, so its first edge is read off its piece: one that starts elsewhere than its box's
    implicit ring turns by quarter turns and stays a box."""
    step, plane = [], []
    for p in pieces:
        first = p.ring_offsets[p.poly_offsets[:-1]]
        u, v = PLANE_U[p.plane], PLANE_V[p.plane]
        k = np.arange(len(first))
        scale = np.stack([p.extent[k, u], p.extent[k, v]], axis=1)
        step.append((p.coords[first + 1] - p.coords[first]) * scale)
        plane.append(p.plane)
    order = np.argsort(np.concatenate([p.source for p in pieces]), kind="stable")
    step, plane = np.concatenate(step)[order], np.concatenate(plane)[order]
    angle = np.arctan2(step[:, 1], step[:, 0])
    turn = np.abs(angle) > 1e-9
    if not turn.any():
        return shapes
    rows, u, v, angle = np.flatnonzero(turn), PLANE_U[plane[turn]], PLANE_V[plane[turn]], angle[turn]
    others = np.setdiff1d(np.arange(len(shapes)), rows)
    axes = ctx.chunk.frames[shapes.frame[rows]]
    k = np.arange(len(rows))
    cos, sin = np.cos(angle)[:, None], np.sin(angle)[:, None]
    new_axes = axes.copy()
    new_axes[k, u] = cos * axes[k, u] + sin * axes[k, v]
    new_axes[k, v] = cos * axes[k, v] - sin * axes[k, u]
    return Shapes.merge([shapes.take(others), reframed(ctx, shapes.take(rows), new_axes, span)], [others, rows])


@operation(ir.Setback, consumes=True)
def setback(ctx: Context, cursor: Shapes, op: ir.Setback) -> Parts:
    """``setback`` and ``shapeL/U/O``: the face's edge strips and its remainder to their parts."""
    face = _SetbackFaces(ctx, cursor, op, "setback", (*op.selectors, *(s for s, _ in op.distances)))
    distance = face.distances(ctx, cursor, op.distances, op.per_edge, 0.0)
    # an outline moved out beyond any coordinate (``Tol.far``) makes no record, and beyond float64's GEOS
    # raises; a NaN distance stays what it was: no setback, as PRT takes massing's (``setbackToArea``'s
    # maximums may be inf: it checks none)
    far = distance > TOL.far
    if far.any():
        ctx.fail_lots(cursor.lot[face.edges.poly[far]], f"`setback` by {distance[far][0]:g}, beyond any coordinate",
                      op.span)
    return face.parts(ctx, cursor, op, distance)


@operation(ir.SetbackToArea, consumes=True)
def setback_to_area(ctx: Context, cursor: Shapes, op: ir.SetbackToArea) -> Parts:
    """``setbackToArea``: the setback of the selected edges whose remainder has the area asked
    (``geometry.setback.distances_to_area``), its strips and remainder to the parts as ``setback``'s."""
    names = (*op.selectors, *(s for s, _ in op.minimum), *(s for s, _ in op.maximum))
    face = _SetbackFaces(ctx, cursor, op, "setbackToArea", names)
    area = np.broadcast_to(np.asarray(evaluate_array(op.area, ctx.env(cursor)), float), (len(cursor),))
    bad = ~(area > 0) | ~np.isfinite(area)
    if bad.any():
        ctx.fail(cursor, bad, "`setbackToArea` with an area that is not a positive number", op.span)
    minimum = face.distances(ctx, cursor, op.minimum, True, 0.0)
    maximum = face.distances(ctx, cursor, op.maximum, True, np.inf)
    moving = face.owner < len(face.owners)
    distance = distances_to_area(face.polygons, face.edges, np.where(moving, minimum, 0.0), maximum, moving,
                                 area)
    return face.parts(ctx, cursor, op, distance)


class _SetbackFaces:
    """What ``setback`` and ``setbackToArea`` find of a batch of faces: their polygons and planes, their
    edges (``geometry.setback.Edges``) with their normals and the frames of the selectors ``names``, and
    the part (``owners``) each edge's strip goes to (``owner``, len(owners) for none)."""

    def __init__(self, ctx: Context, cursor: Shapes, op: ir.Setback | ir.SetbackToArea, what: str,
                 names: tuple[str, ...]):
        self.polygons, self.plane = face_polygons(ctx, cursor, what, op.span)
        self.edges = edges = polygon_edges(self.polygons)
        self.normal = plane_to_scope(-edges.inward, self.plane[edges.poly])
        self.frames = selector_frames(ctx.chunk, self.normal, cursor, edges.poly, names,
                                      _world_points(ctx, cursor, edges.poly, self.plane, (edges.start, edges.end)))
        self.owners = tuple(s for s in op.selectors if s != "remainder")
        # only the outline's edges move: PRT sets back no hole edge of a courtyard, whatever the selectors
        # or the per-edge distances (measured through PyPRT on massing's shapeL/U on holed faces and
        # tiers on holed footprints), and its strips stop at the holes
        self.owner = np.where(edges.hole, len(self.owners), classify_faces(self.normal, self.owners, self.frames))

    def distances(self, ctx: Context, cursor: Shapes, distances, per_edge: bool, fill: float) -> np.ndarray:
        """(E,) each edge's distance: that of the first selector of ``distances`` (pairs of a selector and
        an expression) it matches, ``fill`` where none does; the expressions evaluated per face, or per
        edge (``comp.index`` of ``comp.total`` in the face's edges)."""
        poly = self.edges.poly
        if per_edge:
            shapes = with_context(ctx.plan, cursor.take(poly), "comp", rank_within(poly), poly, len(cursor))
            column = np.arange(len(poly))
        else:
            shapes, column = cursor, poly
        env = ctx.env(shapes)
        table = np.full((len(distances) + 1, len(shapes)), fill)
        for k, (_, expr) in enumerate(distances):
            table[k] = evaluate_array(expr, env)
        return table[classify_faces(self.normal, tuple(s for s, _ in distances), self.frames), column]

    def parts(self, ctx: Context, cursor: Shapes, op, distance: np.ndarray) -> Parts:
        """The parts of ``op`` on the strips of the edges moved by ``distance`` (E,) and the remainder."""
        regions, remainder = setback_regions(self.polygons, self.edges, distance, self.owner, len(self.owners))
        by_owner = dict(zip(self.owners, regions))
        # a region of strips starts at the first edge it sets back, as PRT's shapeL and shapeU
        vertices = len(shapely.get_coordinates(self.polygons)) - len(shapely.get_rings(self.polygons))
        moved = (distance > 0) & np.isfinite(distance)
        starts = {}
        for k, owner in enumerate(self.owners):
            starts[owner] = np.zeros(vertices, dtype=bool)
            starts[owner][self.edges.vertex[moved & (self.owner == k)]] = True
        # the remainder's edges come from the parent edges moved by their distances (of two parallel edges,
        # not the nearer one: a jog's far side's moved line beside the near side's, PRT's tier on
        # massing.tartu.8); an edge of no length keeps none known
        moves = np.full(vertices, np.nan)
        moves[self.edges.vertex] = np.where(moved & (self.owner < len(self.owners)), distance, 0.0)
        return _regions(ctx, op, cursor, [by_owner[s] if s != "remainder" else remainder for s in op.selectors],
                        self.plane, self.polygons, [starts.get(s) for s in op.selectors],
                        [moves if s == "remainder" else None for s in op.selectors])


@operation(ir.InnerRectangle, consumes=True)
def inner_rectangle(ctx: Context, cursor: Shapes, op: ir.InnerRectangle) -> Parts:
    """``innerRectangle``: the face's largest inner rectangle (``geometry.inner_rectangle``) and the
    rest of the face, in the face's own scope frame (CityEngine keeps the scope's orientation)."""
    polygons, plane = face_polygons(ctx, cursor, "innerRectangle", op.span)
    rectangle = largest_rectangles(polygons, op.align)
    remainder = shapely.difference(polygons, rectangle)
    return _regions(ctx, op, cursor, [rectangle if s == "shape" else remainder for s in op.selectors], plane,
                    polygons)


@operation(ir.Convexify, writes=("geom",))
def convexify(ctx: Context, cursor: Shapes, op: ir.Convexify) -> Shapes:
    """``convexify``: the face becomes its convex parts (``geometry.convexify``), one shape whose
    faces they are (a mesh; a convex face stays as it is)."""
    polygons, plane = face_polygons(ctx, cursor, "convexify", op.span)
    limit = None
    if op.max_length is not None:
        limit = np.broadcast_to(np.asarray(evaluate_array(op.max_length, ctx.env(cursor)), float),
                                (len(cursor),))
    parts, source = convex_parts(polygons, limit, plane == 1)
    return mesh_shapes.flat_meshes(ctx.chunk, cursor, parts, source, plane)


@operation(ir.CleanupGeometry, writes=("geom",), meshes=True)
def cleanup_geometry(ctx: Context, cursor: Shapes, op: ir.CleanupGeometry) -> Shapes:
    """``cleanupGeometry``: polygons (faces, prisms through their base, flat rectangles) and meshes
    cleaned (``geometry.cleanup``) in their scopes, which stay: the operation is meant to keep a
    model's look, and the geometry only loses vertices and faces, so it stays inside its scope.
    A tolerance outside [0, 1] is taken as the nearer end. Scope boxes and inserted assets stay as
    they are: a box has no repeated or collinear vertices and no duplicate faces (that its faces
    could be too small or its edges too short to keep is ignored: as a mesh it would leave the
    instancing path), and an asset is an instance whose mesh grammarc does not open."""
    tolerance = np.broadcast_to(np.asarray(evaluate_array(op.tolerance, ctx.env(cursor)), float),
                                (len(cursor),))
    bad = ~np.isfinite(tolerance)
    if bad.any():
        ctx.fail(cursor, bad, "`cleanupGeometry` with a tolerance that is not finite", op.span)
    tolerance = np.clip(tolerance, 0.0, 1.0)
    flat = (cursor.size <= TOL.zero).sum(axis=1) == 1
    geom = cursor.geom.copy()
    polygon = np.flatnonzero(is_polygon(geom) | ((geom == -1) & flat))
    if len(polygon):
        shapes = cursor.take(polygon)
        outlines = polygons_of(ctx.chunk, shapes, corners(ctx.plan, shapes))
        geom[polygon] = mesh_shapes.clean_polygons(ctx.chunk, shapes, outlines, tolerance[polygon],
                                                   op.component)
    mesh = np.flatnonzero(is_mesh(cursor.geom))
    if len(mesh):
        geom[mesh] = mesh_shapes.clean_meshes(ctx.chunk, cursor.take(mesh), tolerance[mesh], op.component)
    return cursor.with_scope(cursor.origin, cursor.size, cursor.frame, geom)


@operation(ir.DeleteHoles, writes=("geom",), meshes=True)
def delete_holes(ctx: Context, cursor: Shapes, op: ir.DeleteHoles) -> Shapes:
    """``deleteHoles``: each face keeps its outer ring. A flat polygon or a mesh (a roof) with holes is
    stored again without its hole rings, in the same scope (holes lie inside the outer ring); boxes,
    rectangles and assets have none. A prism with holes is refused: CityEngine keeps its hole walls, faces
    that a prism here has only as the rings of its base."""
    geom = cursor.geom.copy()
    polygon = np.flatnonzero(is_polygon(geom))
    store = ctx.chunk.polygons
    rings = store.poly_offsets[geom[polygon] + 1] - store.poly_offsets[geom[polygon]]
    holed = polygon[rings > 1]
    solid = cursor.size[holed, store.plane[geom[holed]]] > TOL.zero
    if solid.any():
        bad = np.zeros(len(cursor), dtype=bool)
        bad[holed[solid]] = True
        ctx.fail(cursor, bad, "`deleteHoles` of a solid with holes is not supported yet (delete the holes "
                 "of its face before `extrude`)", op.span)
    if len(holed):
        coords, ring_offsets, poly_offsets = store.gather(geom[holed])
        vertices, outer = ragged_take(ring_offsets, poly_offsets[:-1])
        geom[holed] = store.add(coords[vertices], outer, np.arange(len(holed) + 1), store.plane[geom[holed]])
    mesh = np.flatnonzero(is_mesh(geom))
    if len(mesh):
        coords, ring_offsets, face_offsets, mesh_offsets = ctx.chunk.meshes.gather(geom[mesh] - MESH_BASE)
        if len(face_offsets) < len(ring_offsets):  # some face has a hole
            vertices, outer = ragged_take(ring_offsets, face_offsets[:-1])
            ids = ctx.chunk.meshes.add(coords[vertices], outer, np.arange(len(face_offsets)), mesh_offsets)
            geom[mesh] = MESH_BASE + ids
    return cursor.with_scope(cursor.origin, cursor.size, cursor.frame, geom)


def face_polygons(ctx: Context, cursor: Shapes, what: str, span) -> tuple[np.ndarray, np.ndarray]:
    """Shapely polygons (n,) of flat shapes in their scope units, and each one's plane (n,); fails the
    lots of solids."""
    bad = (cursor.size <= TOL.zero).sum(axis=1) != 1
    if bad.any():
        ctx.fail(cursor, bad, f"`{what}` of a solid is not supported yet (only of faces)", span)
    store = ctx.chunk.polygons
    geom = cursor.geom.copy()
    rects = np.flatnonzero(geom < 0)
    if len(rects):
        plane = comp_kernels.rect_plane(cursor.size[rects], TOL.zero)
        corner = corners(ctx.plan, cursor)
        geom[rects] = store.add(comp_kernels.rect_rings(plane, None if corner is None else corner[rects]),
                                np.arange(0, 4 * len(rects) + 1, 4, dtype=np.int64),
                                np.arange(len(rects) + 1, dtype=np.int64), plane)
    return scope_polygons(store, geom, cursor.size), store.plane[geom]


def _offset_polygons(ctx: Context, distance: ir.Expr, cursor: Shapes, span):
    """Each flat shape's faces (``_faces_in_plane``) offset by ``distance``: the insets and the borders
    (k,) (shapely, in the scopes' units), the faces' planes (k,) and polygons (k,), the faces as shapes,
    each face's row in ``cursor`` and how far each face's edges moved (one per vertex of its rings, as
    ``fit_pieces`` takes them)."""
    d = _distances(ctx, distance, cursor, span)
    faces, owner = _faces_in_plane(cursor, ctx.chunk)
    polygons, plane = face_polygons(ctx, faces, "offset", span)
    vertices = shapely.get_num_coordinates(polygons) - shapely.get_num_interior_rings(polygons) - 1
    moves = np.repeat(np.abs(d[owner]), np.maximum(vertices, 0))
    return *_inset_and_border(polygons, d[owner]), plane, polygons, faces, owner, moves


def _distances(ctx: Context, distance: ir.Expr, cursor: Shapes, span) -> np.ndarray:
    """``offset``'s distance (n,) float64 per shape; a lot whose outline it moves out beyond any coordinate
    (``Tol.far``: no record holds it, and beyond float64's GEOS raises) fails, as does one whose distance is
    not a number. Moved in that far (by -inf too), nothing is left of an outline: that is no error, and the
    distance is ``-Tol.far`` (GEOS takes no infinite distance)."""
    d = np.broadcast_to(np.asarray(evaluate_array(distance, ctx.env(cursor)), float), (len(cursor),))
    nan = np.isnan(d)
    if nan.any():
        ctx.fail(cursor, nan, "`offset` by a distance that is not a number", span)
    far = d > TOL.far
    if far.any():
        ctx.fail(cursor, far, f"`offset` by {d[far][0]:g}, beyond any coordinate", span)
    return np.maximum(d, -TOL.far)


def _inset_and_border(polygons: np.ndarray, distance: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``offset``'s two regions of each face (k,) (shapely): its outline moved by ``distance`` (k,) (in
    when negative) with sharp corners kept, a nearly collapsing one kept as PRT keeps it
    (``geometry.insets``), an arm it closes leaving its vertex where PRT does (``geometry.closed_arms``),
    and the ring between that and the face."""
    inset = closed_arm_insets(mitred_insets(polygons, distance), polygons, -distance)
    return inset, shapely.difference(polygons, inset)


def _offset_pieces(ctx: Context, distance: ir.Expr, cursor: Shapes, span):
    """The inside and border pieces of each flat shape's faces offset by ``distance``, each piece's
    ``source`` its shape's row."""
    inset, border, plane, polygons, faces, owner, moves = _offset_polygons(ctx, distance, cursor, span)
    return tuple(replace(p, source=owner[p.source]) for p in (
        fit_pieces(inset, plane, faces.size, polygons, insets=np.ones(len(inset), dtype=bool), moves=moves),
        fit_pieces(border, plane, faces.size, polygons)))


def _faces_in_plane(cursor: Shapes, chunk) -> tuple[Shapes, np.ndarray]:
    """Each flat shape's faces as shapes in its scope: a flat mesh's faces each a polygon shape, any other
    shape itself; and each face's row in ``cursor`` (ascending). Roofs do not get here: ``offset`` takes
    them apart (``_roof_offsets``), and its comp(f) form refuses meshes."""
    mesh = is_mesh(cursor.geom)
    if not mesh.any():
        return cursor, np.arange(len(cursor))
    rows = np.flatnonzero(mesh)
    geom, counts = mesh_shapes.flat_mesh_faces(chunk, cursor.take(rows))
    per_shape = np.ones(len(cursor), dtype=np.int64)
    per_shape[rows] = counts
    owner = np.repeat(np.arange(len(cursor)), per_shape)
    faces = cursor.take(owner)
    face_geom = faces.geom.copy()
    face_geom[is_mesh(face_geom)] = geom
    return faces.with_scope(faces.origin, faces.size, faces.frame, face_geom), owner


def _piece_shapes(ctx: Context, cursor: Shapes, pieces, site: int, remade: bool = False) -> Shapes:
    """Shapes of clipped or offset pieces: the parent's frame, the piece's box and polygon; the keys of
    pieces made at ``site``, numbered per parent, or of a shape ``remade`` as its one piece."""
    chunk = ctx.chunk
    child = cursor.take(pieces.source)
    geom = np.full(len(pieces.source), -1, dtype=np.int32)
    shaped = np.flatnonzero(~pieces.is_rect)
    if len(shaped):
        rings, poly_offsets = ragged_take(pieces.poly_offsets, shaped)
        vertices, ring_offsets = ragged_take(pieces.ring_offsets, rings)
        geom[shaped] = chunk.polygons.add(pieces.coords[vertices], ring_offsets, poly_offsets, pieces.plane[shaped])
    origin = child.origin + np.einsum("ni,nij->nj", pieces.low, chunk.frames[child.frame])
    sequential = ctx.plan.sequential_random
    key = remade_keys(sequential, child.key) if remade else piece_keys(sequential, child.key,
                                                                         rank_within(pieces.source), site)
    shapes = Shapes(origin, pieces.extent, child.frame, geom, child.lot, key, child.depth, child.params,
                    child.dynamic)
    return with_corners(ctx.plan, shapes, piece_corners(pieces))


def _regions(ctx: Context, op: ir.Setback | ir.SetbackToArea | ir.InnerRectangle, cursor: Shapes, regions: list, plane,
             polygons, start_edges: list | None = None, moves: list | None = None) -> Parts:
    """Part k of ``op`` on the pieces of ``regions[k]`` (n,) (polygons in the shapes' scope units, cut
    from ``polygons``), each parent's pieces together, numbered in stream ``op.site`` part by part;
    ``start_edges[k]``: the parent edges its pieces start at, ``moves[k]`` how far each parent edge moved
    (``fit_pieces``), or None."""
    starts = start_edges or [None] * len(regions)
    distances = moves or [None] * len(regions)
    pieces = [fit_pieces(region, plane, cursor.size, polygons, start_edges=edges, moves=moved)
              for region, edges, moved in zip(regions, starts, distances)]
    shapes, kind = _pieces_by_parent(ctx, cursor, pieces, [(op.site << 20) + k for k in range(len(pieces))])
    ctx.count(shapes, op.span)
    order, offsets = group_by(kind, len(op.parts))
    return Parts(op.parts, shapes.take(order), offsets)


def _pieces_by_parent(ctx: Context, cursor: Shapes, pieces, sites) -> tuple[Shapes, np.ndarray]:
    """Shapes of several kinds of pieces (kind k: ``pieces[k]``, numbered in stream ``sites[k]``),
    each parent's pieces together in kind order, and each shape's kind."""
    shapes = Shapes.concat([_piece_shapes(ctx, cursor, p, site) for p, site in zip(pieces, sites)])
    kind = np.concatenate([np.full(len(p.source), k, dtype=np.int64) for k, p in enumerate(pieces)])
    source = np.concatenate([p.source for p in pieces])
    order = np.argsort(source, kind="stable")
    shapes = shapes.take(order)
    if ctx.plan.sequential_random:  # PRT numbers a parent's pieces over all kinds, in kind order
        parent = source[order]
        shapes = replace(shapes, key=piece_keys(True, cursor.key[parent], rank_within(parent), 0))
    return shapes, kind[order]


def _world_points(ctx: Context, cursor: Shapes, row: np.ndarray, plane: np.ndarray, points) -> tuple:
    """In-plane points (k, 2) in the scope units of the shapes ``row`` (k,) of ``cursor``, whose
    polygons lie in ``plane`` (n,), as world points (k, 3)."""
    axes = ctx.chunk.frames[cursor.frame[row]]
    return tuple(cursor.origin[row] + np.einsum("ki,kij->kj", plane_to_scope(p, plane[row]), axes)
                 for p in points)
