"""Operations on the faces of a shape that keep it one shape: ``convexify``, ``cleanupGeometry`` and
``deleteHoles``; and what the face operations share (``offsets``, ``setbacks``, ``roofing``): the batch's
faces as shapely polygons in their scopes' units (``face_polygons``), pieces back as shapes
(``piece_shapes``, ``pieces_by_parent``), in-plane points as world points (``world_points``).

Reads: the scope (``size``), ``geom`` and what their expressions read. Writes: ``geom``.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from grammarc.backend import mesh_shapes
from grammarc.backend.box_rings import corners, piece_corners, with_corners
from grammarc.backend.context import Context
from grammarc.backend.evaluate import evaluate_array
from grammarc.backend.operations.table import operation
from grammarc.backend.outlines import polygons_of
from grammarc.backend.shapes import Shapes
from grammarc.backend.streams import piece_keys, remade_keys
from grammarc.constants import TOL
from grammarc.geometry import components as comp_kernels
from grammarc.geometry.clip import scope_polygons
from grammarc.geometry.convexify import convex_parts
from grammarc.geometry.meshes import MESH_BASE, is_mesh, is_polygon
from grammarc.geometry.polygons import plane_to_scope
from grammarc.ir import nodes as ir
from grammarc.ragged import ragged_take, rank_within


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



def piece_shapes(ctx: Context, cursor: Shapes, pieces, site: int, remade: bool = False) -> Shapes:
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



def pieces_by_parent(ctx: Context, cursor: Shapes, pieces, sites) -> tuple[Shapes, np.ndarray]:
    """Shapes of several kinds of pieces (kind k: ``pieces[k]``, numbered in stream ``sites[k]``),
    each parent's pieces together in kind order, and each shape's kind."""
    shapes = Shapes.concat([piece_shapes(ctx, cursor, p, site) for p, site in zip(pieces, sites)])
    kind = np.concatenate([np.full(len(p.source), k, dtype=np.int64) for k, p in enumerate(pieces)])
    source = np.concatenate([p.source for p in pieces])
    order = np.argsort(source, kind="stable")
    shapes = shapes.take(order)
    if ctx.plan.sequential_random:  # PRT numbers a parent's pieces over all kinds, in kind order
        parent = source[order]
        shapes = replace(shapes, key=piece_keys(True, cursor.key[parent], rank_within(parent), 0))
    return shapes, kind[order]


def world_points(ctx: Context, cursor: Shapes, row: np.ndarray, plane: np.ndarray, points) -> tuple:
    """In-plane points (k, 2) in the scope units of the shapes ``row`` (k,) of ``cursor``, whose
    polygons lie in ``plane`` (n,), as world points (k, 3)."""
    axes = ctx.chunk.frames[cursor.frame[row]]
    return tuple(cursor.origin[row] + np.einsum("ki,kij->kj", plane_to_scope(p, plane[row]), axes)
                 for p in points)
