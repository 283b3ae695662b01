"""Component splits: the paper's ``Comp`` and CityEngine's ``comp(f|e|v)`` on boxes, prisms, polygons and
meshes (roofs), with the face scopes, selectors, context (``comp.index``, ``comp.total``, ``comp.sel``) and
trim planes they set.

A component split makes a shape per component (its own scope in the parent's frame, a key, the parent's
parameters and attributes) and returns them as ``Parts`` for its bodies; the parent, a solid taken apart,
becomes an occluder where the grammar asks occlusion queries. Reads: every column (the children inherit
``lot``, ``depth``, ``params``, ``dynamic``), and the selector frames (lot, street). Writes: no column of the
cursor.
"""

from __future__ import annotations

import functools
from dataclasses import replace

import numpy as np

from grammarc.backend import mesh_shapes
from grammarc.backend.box_rings import corners, with_corners
from grammarc.backend.children import with_context
from grammarc.backend.context import Context
from grammarc.backend.evaluate import evaluate_array
from grammarc.backend.kernels.order import group_by
from grammarc.backend.kernels.scope import component_origins
from grammarc.backend.occlusion import take_apart
from grammarc.backend.operations.offsets import offset_faces
from grammarc.backend.operations.table import Parts, operation
from grammarc.backend.outlines import flat_axis, polygons_of, side_turns
from grammarc.backend.reframing import turned
from grammarc.backend.selectors import classify_edges, classify_faces, index_masks, selector_frames
from grammarc.backend.shapes import Shapes
from grammarc.backend.streams import piece_keys
from grammarc.constants import TOL
from grammarc.geometry import components as comp_kernels
from grammarc.geometry.meshes import is_mesh, is_polygon
from grammarc.geometry.queries import shape_faces
from grammarc.geometry.reframe import NORMAL_OUT
from grammarc.geometry.trim import bottom_ends, shallow_edge_planes, side_face_planes
from grammarc.ir import nodes as ir
from grammarc.ir.printer import comp_selectors
from grammarc.ragged import rank_within


@operation(ir.Comp, meshes=True, consumes=True)
def comp(ctx: Context, cursor: Shapes, op: ir.Comp) -> Parts:
    if comp_kernels.KIND_CODES[op.kind] not in mesh_shapes.MESH_KINDS:
        ctx.refuse_meshes(op, cursor)
    index_of = None
    if op.index is not None:
        index_of = evaluate_array(op.index, ctx.env(cursor))
    shapes, _, index, parent, _, _, _ = components(ctx, comp_kernels.KIND_CODES[op.kind], cursor, op.site,
                                                   op.span, index_of)
    shapes = take_apart(ctx, cursor, shapes, parent)
    ctx.count(shapes, op.span)
    order, offsets = group_by(index % len(op.parts), len(op.parts))
    return Parts(op.parts, shapes.take(order), offsets)


@operation(ir.CompFaces, meshes=True, consumes=True)
def comp_faces(ctx: Context, cursor: Shapes, op: ir.CompFaces) -> Parts:
    """CityEngine ``comp(f|e|v)``: components to the first selector they match."""
    if op.offset is not None:
        ctx.refuse_meshes(op, cursor)
        return offset_faces(ctx, cursor, op)
    bad = cursor.geom < -1
    if bad.any():
        ctx.fail(cursor, bad, "`comp` of an inserted asset is not supported yet", op.span)
    chunk = ctx.chunk
    kind = {"f": "faces", "e": "edges", "v": "vertices"}[op.kind]
    borders = bool({"border", "inside"} & set(op.selectors))
    shapes, normal, _, parent, roof, border, axes = components(ctx, comp_kernels.KIND_CODES[kind], cursor,
                                                               op.site, op.span, borders=borders)
    shapes = take_apart(ctx, cursor, shapes, parent)
    if op.kind == "f":
        framed = shapes.frame
        shapes = _face_scopes(ctx, shapes, cursor, parent, op.span)
        if shapes.frame is not framed:  # faces turned: their new axes
            axes = chunk.frames[shapes.frame]
    slot = ctx.plan.trim_slot
    if op.kind == "f" and slot is not None and op.site not in ctx.plan.unread_planes:
        # the faces' trim planes where they meet their neighbours (``geometry.trim``), where something reads
        # them (``backend.trim_reads``; elsewhere the faces keep their shape's, which nothing reads either)
        # relative to the lot's origin, so that a lot far from the origin is trimmed as it is there
        up = chunk.frames.data[cursor.frame, 1][parent]
        origin = shapes.origin - chunk.lot_origin[shapes.lot]
        planes = side_face_planes(axes, origin, shapes.size, parent, up)
        if ctx.plan.horizontal_planes:
            # each component is one face (none for a degenerate one): its outline from the lot's origin
            faces = shape_faces(shapes.size, shapes.geom, chunk.polygons, chunk.meshes)
            owner, at = faces.face_shape(), faces.vertex_shape()
            verts = origin[at] + np.einsum("vi,vij->vj", faces.verts, chunk.frames[shapes.frame[at]])
            found = shallow_edge_planes(verts, faces.ring_offsets, faces.face_offsets, parent[owner], up[owner])
            shallow = np.full((len(shapes), found.shape[1]), np.nan)
            shallow[owner] = found
            planes = np.concatenate([planes, shallow], axis=1)
        # a row of the chunk's table for each face with a plane; the others none (row 0)
        ids = np.zeros(len(shapes), dtype=np.int32)
        some = ~np.isnan(planes).all(axis=1)
        ids[some] = chunk.trim_planes.add(planes[some])
        dynamic = list(shapes.dynamic)
        dynamic[slot] = ids
        shapes = replace(shapes, dynamic=tuple(dynamic))
    env = ctx.env(cursor) if op.picks else None
    picks = [np.broadcast_to(np.asarray(evaluate_array(e, env), dtype=np.float64), (len(cursor),))
             for e in op.picks]
    picked = index_masks(op.selectors, parent, picks)
    if borders:
        picked.update({"border": border, "inside": ~border})
    if op.kind == "f":
        base = (shapes.origin, bottom_ends(shapes.origin, shapes.size, axes))  # each face's bottom edge
        which = classify_faces(normal, op.selectors, selector_frames(chunk, normal, cursor, parent, op.selectors,
                                                                      base), picked)
    else:
        direction = axes[:, 0] if op.kind == "e" else None
        which = classify_edges(direction, op.selectors, len(shapes), picked, roof)
    # the selected components grouped by body part, taken in one gather: numbered in face order first
    kept = np.flatnonzero(which < len(op.selectors))
    which, parent = which[kept], parent[kept]
    order, offsets = group_by(which, len(op.parts))
    shapes = shapes.take(kept[order])
    if ctx.plan.sequential_random:  # PRT makes shapes of the selected faces only, numbered in face order
        number = rank_within(parent)[order]
        shapes = replace(shapes, key=piece_keys(True, cursor.key[parent[order]], number, op.site))
    if {"comp.index", "comp.total", "comp.sel"} & set(ctx.plan.dynamic):
        # CityEngine numbers the components of each selector: the front face is 0 of 1
        group = parent * (len(op.selectors) + 1) + which
        rank, n_groups = rank_within(group)[order], int(group.max(initial=0)) + 1
        ids = np.array([ctx.plan.strings.ids[s] for s in comp_selectors(op)], dtype=np.int32)
        shapes = with_context(ctx.plan, shapes, "comp", rank, group[order], n_groups, selector=ids[which[order]])
    ctx.count(shapes, op.span)
    return Parts(op.parts, shapes, offsets)


def components(ctx: Context, kind: int, cursor: Shapes, site: int, span, wanted=None, borders: bool = False):
    """Component shapes of ``cursor``, their normals in the parents' frames (m, 3), their indices
    among their parent's components (m,), their parents (m,), each one's place on a roof (m,)
    (``geometry.meshes.roof_edge_kinds``: an edge of a roof's mesh; -1 for the rest) and whether it is
    on its shape's border (m,), as the reference defines ``border`` and ``inside`` for shapes no
    ``offset`` made: a border edge meets one face, a border face or vertex touches a border edge. A flat
    shape is one face, all of it border; a solid (a box, a prism) and a roof or other mesh that is
    closed have no border, all of them inside (found only with ``borders``; else no component is on a
    border); and their scopes' axes (m, 3, 3), the rows of their frames. ``wanted`` (n,) keeps, per
    shape, only that index. Roofs (meshes) have faces and edges (``comp_faces`` and ``comp`` check)."""
    chunk = ctx.chunk
    mesh = is_mesh(cursor.geom)
    pieces = []
    if not mesh.all():
        pieces.append(_solid_components(chunk, kind, cursor, ~mesh, corners(ctx.plan, cursor)))
    if mesh.any():
        which = np.flatnonzero(mesh)
        parent, index, origin, axes, size, geom, roof, border = mesh_shapes.mesh_components(
            chunk, cursor.take(which), kind, borders)
        pieces.append((which[parent], index, origin, axes, size, geom, axes[:, 2], roof, border,
                       np.zeros(len(parent), dtype=np.int64)))
    parent, index, origin, axes, size, geom, normal, roof, border, corner = (
        pieces[0] if len(pieces) == 1 else
        (np.concatenate(columns) for columns in zip(*pieces)))
    if len(pieces) > 1:
        order = np.argsort(parent, kind="stable")
        parent, index, origin, axes, size, geom, normal, roof, border, corner = (
            a[order] for a in (parent, index, origin, axes, size, geom, normal, roof, border, corner))
    if wanted is not None:
        keep = index == np.round(wanted[parent])
        parent, index, origin, axes, size, geom, normal, roof, border, corner = (
            a[keep] for a in (parent, index, origin, axes, size, geom, normal, roof, border, corner))
    child = cursor.take(parent)
    world_origin, bad = component_origins(chunk.frames.data, child.frame, child.origin, origin, axes, 1e-6)
    if bad.any():  # a scope of sizes no float can square has no component frames (``refuse_far`` fails such a
        # scope where it is made: this guards the kernel's output)
        ctx.fail_lots(child.lot[bad], "a component of a scope whose size is beyond any geometry", span)
    frame, world_axes = chunk.frames.turned(axes, child.frame)  # the same face of many boxes in a frame: one row
    shapes = Shapes(world_origin, size, frame, geom.astype(np.int32), child.lot,
                    piece_keys(ctx.plan.sequential_random, child.key, index, site), child.depth, child.params,
                    child.dynamic)
    shapes = with_corners(ctx.plan, shapes, corner)
    return (with_context(ctx.plan, shapes, "comp", index, parent, len(cursor)), normal, index, parent, roof,
            border, world_axes)


def _solid_components(chunk, kind: int, cursor: Shapes, solid: np.ndarray, corner: np.ndarray | None):
    """Components of the boxes, polygons and prisms ``solid`` (n,) bool of ``cursor`` (whose box rings start
    at ``corner`` (n,), None for corner 0): parent (into cursor), index, origin, axes, size (in the parents'
    frames), geom, normal, roof (-1: no roof edges), border (the components of flat shapes), and the
    corner each box component's ring starts at."""
    shapes, which = cursor.take(solid), np.flatnonzero(solid)  # all of them taken as they are
    corner = None if corner is None else corner[solid]
    coords, ring_offsets, shape_offsets, plane = polygons_of(chunk, shapes, corner)
    parent, index, origin, axes, size, poly = comp_kernels.components(
        kind, coords, ring_offsets, shape_offsets, plane, shapes.size, TOL.zero,
        side_turns(chunk, shapes, ring_offsets, shape_offsets))
    geom = np.full(len(parent), -1, dtype=np.int32)
    same = poly == comp_kernels.SAME_POLY
    geom[same] = shapes.geom[parent[same]]
    for code, cap in ((comp_kernels.BOTTOM_POLY, "bottom"), (comp_kernels.TOP_POLY, "top")):
        sel = (poly == code) & is_polygon(shapes.geom[parent])
        if sel.any():
            geom[sel] = _cap_polygons(chunk, shapes.geom[parent[sel]], cap)
    # a flat shape's only face is itself: its normal is its plane's axis, not its frame's z
    normal = axes[:, 2].copy()
    normal[same] = np.eye(3)[plane[parent[same]]]
    border = ((shapes.size <= TOL.zero).sum(axis=1) >= 1)[parent]
    no_roof = np.full(len(parent), -1, dtype=np.int32)
    return (which[parent], index, origin, axes, size, geom, normal, no_roof, border,
            _box_corners(poly, plane, shapes.geom, parent, corner))


def _box_corners(poly: np.ndarray, plane: np.ndarray, geom: np.ndarray, parent: np.ndarray,
                 corner: np.ndarray | None) -> np.ndarray:
    """The corners (m,) that components' box rings start at: a flat box's face is the box itself; a box's
    top and bottom start at its ring's first vertex, as a prism's (``_cap_polygons``); side faces and
    edges at corner 0."""
    out = np.zeros(len(poly), dtype=np.int64)
    if corner is None:
        return out
    same = poly == comp_kernels.SAME_POLY
    out[same] = corner[parent[same]]
    for cap, code in enumerate((comp_kernels.TOP_POLY, comp_kernels.BOTTOM_POLY)):
        rows = np.flatnonzero(poly == code)
        rows = rows[geom[parent[rows]] == -1]
        out[rows] = _cap_corners()[cap, plane[parent[rows]], corner[parent[rows]] % 4]
    return out


@functools.cache
def _cap_corners() -> np.ndarray:
    """The corner (2, 3, 4) int64 a box's top (0) and bottom (1) face's ring starts at, by the box's plane
    and its ring's corner: the box ring's first vertex, seen in the cap's plane (y flipped where the cap
    runs against the box's second axis, as ``_cap_polygons`` flips a prism's)."""
    plane, corner = np.repeat(np.arange(3), 4), np.tile(np.arange(4), 3)
    first = comp_kernels.rect_rings(plane, corner)[::4]
    table = np.empty((2, 3, 4), dtype=np.int64)
    for cap, flip_where in enumerate((True, False)):
        seen = first.copy()
        flip = (plane == 1) == flip_where
        seen[flip, 1] = 1.0 - seen[flip, 1]
        table[cap] = comp_kernels.rect_corners(seen, np.full(len(plane), 2)).reshape(3, 4)
    return table


def _cap_polygons(chunk, geom: np.ndarray, which: str) -> np.ndarray:
    """New store polygons for the bottom or top faces of prisms ``geom`` (in the face's own plane).

    The face's x is the polygon's first axis; its y runs along the second axis or against it, and
    the bottom face sees the rings from below, so they are reversed (see components.py).
    """
    polygons = chunk.polygons
    coords, ring_offsets, poly_offsets = polygons.gather(geom)
    plane = polygons.plane[geom]
    flip = (plane == 1) if which == "top" else (plane != 1)
    vertex_poly = np.repeat(np.repeat(np.arange(len(geom)), np.diff(poly_offsets)),
                            np.diff(ring_offsets))
    coords = coords.copy()
    coords[:, 1] = np.where(flip[vertex_poly], 1.0 - coords[:, 1], coords[:, 1])
    if which == "bottom":
        coords = comp_kernels.reverse_rings(coords, ring_offsets)
    return polygons.add(coords, ring_offsets, poly_offsets, np.full(len(geom), 2, dtype=np.int8))


def _face_scopes(ctx: Context, shapes: Shapes, cursor: Shapes, parent: np.ndarray, span) -> Shapes:
    """A flat shape's face component is the shape itself; as every CityEngine face scope, it gets z
    along the face's normal (x kept, y = z cross x)."""
    axis = flat_axis(ctx.chunk, cursor)[parent]
    turn = (axis >= 0) & (axis != 2) & (shapes.geom > -2) & ~is_mesh(shapes.geom)
    rows = np.flatnonzero(turn)  # only these are asked whether they are flat (the faces of solids are not)
    turn[rows] = (shapes.size[rows] <= TOL.zero).sum(axis=1) == 1
    return turned(ctx, shapes, turn, NORMAL_OUT, axis, span)
