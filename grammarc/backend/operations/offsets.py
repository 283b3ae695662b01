"""Operations that remake a face's outline: ``offset`` (and ``comp(f)`` after an ``offset``, for
``operations.component_splits``), ``footprint`` and ``rectify``.

The batch's faces as shapely polygons in their scopes' units (``faces.face_polygons``), one vectorized
geometry step, then the pieces back as shapes: a face's one piece, or a mesh of its several in one fitted
scope. Reads: the scope (``origin``, ``size``, ``frame``), ``geom`` and what their expressions read.
Writes every column, as they make the shapes of their pieces anew (new keys); a shape with no piece left
goes, but ``offset`` keeps it as it was. ``offset`` also takes a shape of several faces in one plane (a
mesh of an earlier offset's pieces or of convexify's parts) or a roof, and offsets each face.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import shapely

from grammarc.backend import mesh_shapes
from grammarc.backend.context import Context
from grammarc.backend.evaluate import evaluate_array
from grammarc.backend.kernels.order import group_by
from grammarc.backend.operations.faces import face_polygons, piece_shapes, pieces_by_parent
from grammarc.backend.operations.table import Parts, operation
from grammarc.backend.reframing import reframed
from grammarc.backend.shapes import COLUMNS, Shapes
from grammarc.backend.streams import remade_keys
from grammarc.constants import TOL
from grammarc.geometry.clip import fit_pieces, scope_polygons
from grammarc.geometry.closed_arms import closed_arm_insets
from grammarc.geometry.insets import mitred_insets
from grammarc.geometry.meshes import is_mesh
from grammarc.geometry.polygons import PLANE_U, PLANE_V
from grammarc.geometry.projection import projected_outlines
from grammarc.geometry.queries import shape_faces
from grammarc.geometry.rectify import rectified
from grammarc.ir import nodes as ir


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
    pieces, _ = _fitted_pieces(ctx, op.distance, cursor, op.span, op.select)
    if op.select == "all":  # each shape's inside pieces, then its border's
        return pieces.take(np.argsort(pieces.source, kind="stable"))
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
    parts, which = shapely.get_parts(np.concatenate(_offset_regions(polygons, d[parent], op.select)),
                                     return_index=True)
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
        return piece_shapes(ctx, cursor, pieces, 0, remade=True)
    # a face the offset parts into pieces stays one shape: a mesh of the pieces in one fitted scope
    rows = np.flatnonzero(several)
    mine = several[pieces.source]
    single = piece_shapes(ctx, cursor, pieces.take(~mine), 0, remade=True)
    grouped = pieces.take(mine)
    grouped = replace(grouped, source=np.searchsorted(rows, grouped.source))
    meshes = mesh_shapes.piece_meshes(ctx.chunk, cursor.take(rows), grouped)
    meshes = replace(meshes, key=remade_keys(ctx.plan.sequential_random, meshes.key))
    return Shapes.merge([single, meshes], [pieces.source[~mine], rows])


def offset_faces(ctx: Context, cursor: Shapes, op: ir.CompFaces) -> Parts:
    """``offset(d) comp(f){ inside: ... | border: ... }``: the offset's faces as components."""
    pieces = _offset_pieces(ctx, op.offset, cursor, op.span)
    border_site = (op.site << 20) + 1  # another stream than the inside faces'
    shapes, kind = pieces_by_parent(ctx, cursor, pieces, [op.site, border_site])
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
    face: the scopes of ``shapes`` (the ``pieces`` (``Clipped``) in ``faces.pieces_by_parent``'s order) turned
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



def _offset_polygons(ctx: Context, distance: ir.Expr, cursor: Shapes, span, select: str):
    """Each flat shape's faces (``_faces_in_plane``) offset by ``distance``: the regions ``select`` keeps
    (``_offset_regions``: (k,) each, shapely, in the scopes' units), the faces' planes (k,) and polygons
    (k,), the faces as shapes, each face's row in ``cursor`` and how far each face's edges moved (one per
    vertex of its rings, as ``fit_pieces`` takes them)."""
    d = _distances(ctx, distance, cursor, span)
    faces, owner = _faces_in_plane(cursor, ctx.chunk)
    polygons, plane = face_polygons(ctx, faces, "offset", span)
    vertices = shapely.get_num_coordinates(polygons) - shapely.get_num_interior_rings(polygons) - 1
    moves = np.repeat(np.abs(d[owner]), np.maximum(vertices, 0))
    return _offset_regions(polygons, d[owner], select), plane, polygons, faces, owner, moves


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
        ctx.fail_each(cursor, far, lambda i: f"`offset` by {d[i]:g}, beyond any coordinate", span)
    return np.maximum(d, -TOL.far)


def _offset_regions(polygons: np.ndarray, distance: np.ndarray, select: str) -> list[np.ndarray]:
    """``offset``'s regions of each face (k,) (shapely) that ``select`` keeps: ``inside``, its outline moved
    by ``distance`` (k,) (in when negative) with sharp corners kept, a nearly collapsing one kept as PRT
    keeps it (``geometry.insets``), an arm it closes leaving its vertex where PRT does
    (``geometry.closed_arms``); ``border``, the ring between that and the face; ``all``, both, in that
    order."""
    # a face that crosses itself (a shed roof's side under a concave outline's reflex corner is a bow tie)
    # is taken as its valid parts: GEOS's overlay refuses it
    invalid = ~shapely.is_valid(polygons)
    if invalid.any():
        polygons = polygons.copy()
        polygons[invalid] = shapely.make_valid(polygons[invalid], method="structure", keep_collapsed=False)
    inset = closed_arm_insets(mitred_insets(polygons, distance), polygons, -distance)
    border = [] if select == "inside" else [shapely.difference(polygons, inset)]
    return border if select == "border" else [inset, *border]


def _offset_pieces(ctx: Context, distance: ir.Expr, cursor: Shapes, span):
    """The inside and border pieces of each flat shape's faces offset by ``distance``, each piece's
    ``source`` its shape's row."""
    pieces, border = _fitted_pieces(ctx, distance, cursor, span, "all")
    return pieces.take(~border), pieces.take(border)


def _fitted_pieces(ctx: Context, distance: ir.Expr, cursor: Shapes, span, select: str):
    """The pieces of each flat shape's faces offset by ``distance`` that ``select`` keeps, fitted in one
    pass: all the insides' pieces, then all the borders' (whose edges moved by no distance known), each
    piece's ``source`` its shape's row; and which pieces are of a border (k,) bool."""
    regions, plane, polygons, faces, owner, moves = _offset_polygons(ctx, distance, cursor, span, select)
    of_border = {"inside": [False], "border": [True], "all": [False, True]}[select]
    border = np.repeat(of_border, len(faces))
    pieces = fit_pieces(np.concatenate(regions), np.tile(plane, len(regions)),
                        np.tile(faces.size, (len(regions), 1)), np.tile(polygons, len(regions)), insets=~border,
                        moves=np.concatenate([np.full(len(moves), np.nan) if b else moves for b in of_border]))
    return replace(pieces, source=owner[pieces.source % len(faces)]), border[pieces.source]


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
