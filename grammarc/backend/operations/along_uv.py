"""CityEngine's ``insertAlongUV``: an asset laid along a shape's texture coordinates, cut to its faces.

The reference maps the asset's x onto u, one copy per unit of u, its z onto -v and its y onto the given
height, then cuts the copies to the shape's faces (it maps onto their triangles and quads) and bends them
with the surface. A shape's texture coordinates are one affine map of world space (``backend.texture_space``),
so on each planar triangle of the shape the point of given (u, v) is an affine function of (u, v): a copy
over one triangle is the asset under one affine map, no bending needed. So each triangle of the shape's
faces (``geometry.triangulation``) takes one placement per unit of u its coordinates cross; the placement
maps the asset's unit box (x, y, z) to the point of the triangle's plane at u = k + x, v = 1 - z (the
asset's front at v = 0, its back at v = 1), lifted y times the height along the height direction; the
asset's triangles under it are cut by the three planes through the triangle's edges along that direction
(``geometry.trim.trim_triangles``, the same cut the trim planes make), so neighbouring triangles meet
where their coordinates do.

The decision, and why: the result is the shape's new geometry, a mesh in the mesh table fitted to the
scope's axes (the scope keeps its axes and fits the asset's pieces, as an extrusion's does), not an
instance: the reference says the operation makes new geometry and breaks instancing, and the pieces cut at
the faces' edges are no copies of the asset. The shape goes on, as after ``i()``; its leaf writes the mesh.
Where grammarc differs: ``vertex.normal`` lifts each triangle along its own normal (not along normals
interpolated between faces), so on a curved surface the pieces of neighbouring faces do not join in height;
the asset's own texture coordinates and normals are not kept (as for ``i()``); a texture space that turns
clockwise seen along the height direction mirrors the asset, as the map says, and its faces are turned to
face out. A triangle on which u and v do not span its plane (a projection seen edge-on) takes no asset;
a shape without coordinates of the set fails its lot.

Reads: the scope, ``geom``, ``dynamic`` (the texture set) and what the height and the asset name read.
Writes: the scope's ``origin`` and ``size``, and ``geom``.
"""

from __future__ import annotations

import numpy as np

from grammarc.backend.context import Context
from grammarc.backend.evaluate import evaluate_array
from grammarc.backend.mesh_shapes import store_fitted
from grammarc.backend.operations.inserts import asset_ids, scope_at
from grammarc.backend.operations.table import operation
from grammarc.backend.shapes import Shapes
from grammarc.backend.texture_space import texture_maps
from grammarc.constants import TOL
from grammarc.geometry.components import reverse_rings
from grammarc.geometry.meshes import ring_vector_areas
from grammarc.geometry.queries import shape_faces
from grammarc.geometry.triangulation import triangulate_polygons
from grammarc.geometry.trim import trim_triangles
from grammarc.ir import nodes as ir
from grammarc.ragged import (
    fan_out,
    next_in_segment,
    offsets_from_counts,
    ragged_take,
    segment_of,
    segment_reduce,
)


@operation(ir.InsertAlongUV, writes=("origin", "size", "geom"), meshes=True)
def insert_along_uv(ctx: Context, cursor: Shapes, op: ir.InsertAlongUV) -> Shapes:
    n = len(cursor)
    if not n:
        return cursor
    chunk = ctx.chunk
    asset = asset_ids(ctx, cursor, op, "insertAlongUV")
    height = np.broadcast_to(evaluate_array(op.height, ctx.env(cursor)), (n,)).astype(np.float64)
    maps = texture_maps(ctx.plan, chunk, cursor, op.uv_set)
    bad = np.isnan(maps).any(axis=(1, 2))
    if bad.any():
        ctx.fail(cursor, bad, f"`insertAlongUV` of a shape without texture coordinates of set {op.uv_set} "
                 "(projectUV first)", op.span)
    axes = chunk.frames[cursor.frame]
    world, ring_offsets, shape = _pieces(chunk, cursor, axes)
    normal = _ring_normals(world, ring_offsets)
    lift = axes[shape, 1] if op.direction == "scope.y" else normal
    xform, planes, owner = placements(world, ring_offsets, normal, maps[shape], lift * height[shape, None],
                                      lambda count: ctx.check_fan_out(cursor, np.bincount(
                                          shape, weights=count, minlength=n), op.span))
    owner = shape[owner]
    order = np.argsort(owner, kind="stable")  # by shape, so that the pieces come grouped by shape
    xform, planes, owner = xform[order], planes[order], owner[order]
    pieces = []
    for a in np.unique(asset[owner]).tolist():
        mesh = ctx.asset_mesh(a)
        if mesh is None:  # a missing asset: nothing is inserted, as in CityEngine (compiling warned)
            continue
        rows = np.flatnonzero(asset[owner] == a)
        placed = xform[rows]
        if op.alignment == "keepPosition":  # the asset's own origin on the faces, not its lowest point
            low, high = mesh.bounds[0, 1], mesh.bounds[1, 1]
            placed[:, :, 3] += placed[:, :, 1] * (low / (high - low) if high > low else 0.0)
        verts, ring_offsets, which = trim_triangles(mesh.vertices, mesh.faces, placed, planes[rows], TOL.zero)
        pieces.append((verts, ring_offsets, rows[which]))
    verts, ring_offsets, placement = _gathered(pieces)
    # the faces of mirroring placements wind the other way: turn them to face out
    mirrored = (np.linalg.det(xform[:, :, :3]) < 0)[placement]
    if mirrored.any():
        turned = reverse_rings(verts, ring_offsets)
        verts = np.where(mirrored[segment_of(ring_offsets)][:, None], turned, verts)
    poly_shape = owner[placement]
    vertex_shape = poly_shape[segment_of(ring_offsets)]
    local = np.einsum("vij,vj->vi", axes[vertex_shape], verts - cursor.origin[vertex_shape])
    geom, low, size = store_fitted(chunk, local, ring_offsets, np.arange(len(placement) + 1, dtype=np.int64),
                                   offsets_from_counts(np.bincount(poly_shape, minlength=n)))
    return scope_at(ctx, cursor, low, size, geom)


def _pieces(chunk, shapes: Shapes, axes: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The convex pieces of the shapes' faces, in world coordinates: a convex face without holes is one,
    the others are their triangles (``geometry.triangulation``). Returns the vertices (V, 3), the pieces'
    ring_offsets (P+1,), each winding counter-clockwise around its face's outward normal, and the shape of
    each piece (P,)."""
    faces = shape_faces(shapes.size, shapes.geom, chunk.polygons, chunk.meshes)
    vertex_shape = faces.vertex_shape()
    world = shapes.origin[vertex_shape] + np.einsum("vj,vjk->vk", faces.verts, axes[vertex_shape])
    ring_offsets, face_offsets = faces.ring_offsets, faces.face_offsets
    outline = face_offsets[:-1]
    at = np.arange(len(world))
    ring = segment_of(ring_offsets)
    after = next_in_segment(ring_offsets)
    before = np.where(at > ring_offsets[:-1][ring], at - 1, ring_offsets[1:][ring] - 1)
    normal = _ring_normals(world, ring_offsets)[ring]
    turn = np.einsum("vi,vi->v", np.cross(world - world[before], world[after] - world), normal)
    concave = segment_reduce(np.add, (turn < -TOL.zero).astype(np.int64), ring_offsets, 0) > 0
    whole = (np.diff(face_offsets) == 1) & ~concave[outline]
    kept, kept_offsets = ragged_take(ring_offsets, outline[whole])
    face_vertex = segment_of(face_offsets)[ring]
    tris = triangulate_polygons(world, ring_offsets, face_offsets)
    tris = tris[~whole[face_vertex[tris[:, 0]]]]
    index = np.concatenate([kept, tris.reshape(-1)])
    piece_offsets = offsets_from_counts(np.concatenate([np.diff(kept_offsets), np.full(len(tris), 3)]))
    return world[index], piece_offsets, faces.face_shape()[face_vertex[index[piece_offsets[:-1]]]]


def _ring_normals(world: np.ndarray, ring_offsets: np.ndarray) -> np.ndarray:
    """(R, 3) unit Newell normals of rings (zero for a ring without area), each ring taken from its first
    vertex (world coordinates lose their digits far from the origin)."""
    normal = ring_vector_areas(world - world[ring_offsets[:-1][segment_of(ring_offsets)]], ring_offsets)
    length = np.linalg.norm(normal, axis=1, keepdims=True)
    return np.divide(normal, length, out=np.zeros_like(normal), where=length > 0)


def placements(world: np.ndarray, ring_offsets: np.ndarray, normal: np.ndarray, maps: np.ndarray,
               lift: np.ndarray, check=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The asset's placements over convex pieces, one per whole unit of u each crosses where its v meets
    [0, 1].

    Parameters
    ----------
    world : (V, 3) float64
        The pieces' vertices.
    ring_offsets : (P+1,) int64
        Piece ``p`` is ``world[ring_offsets[p]:ring_offsets[p+1]]``, a convex ring counter-clockwise
        around ``normal[p]``.
    normal : (P, 3) float64
        The pieces' unit normals.
    maps : (P, 2, 4) float64
        Each piece's texture map (u and v of a world point ``X``: ``maps[:, :, :3] @ X + maps[:, :, 3]``).
    lift : (P, 3) float64
        The asset's height as a vector: where its unit box's y = 1 goes from the surface.
    check : callable, optional
        Given the placements per piece (P,) float64 before they are made: it raises to refuse them (a
        texture scale of almost nothing would lay billions, or more than int64 counts).

    Returns
    -------
    xform : (k, 3, 4) float64
        Each placement's map of the asset's unit box (``TerminalChunk``'s layout).
    planes : (k, 4 E) float64
        The planes (nx, ny, nz, d) through its piece's edges along ``lift``, facing in (NaN for an edge
        along ``lift`` and past the piece's E edges); a point is kept where ``n . X + d >= 0``.
    owner : (k,) int64
        The piece of each placement.
    """
    ring = segment_of(ring_offsets)
    first = world[ring_offsets[:-1]]
    # (u, v, n . X) of a point X of the piece's plane, inverted: the plane's point of given (u, v)
    system = np.concatenate([maps[:, :, :3], normal[:, None, :]], axis=1)
    scale = np.linalg.norm(maps[:, :, :3], axis=2).prod(axis=1)
    usable = np.abs(np.linalg.det(system)) > 1e-9 * np.maximum(scale, 1e-300)
    inverse = np.linalg.inv(np.where(usable[:, None, None], system, np.eye(3)))
    uv = np.einsum("vij,vj->vi", maps[ring, :, :3], world) + maps[ring, :, 3]
    low = np.stack([segment_reduce(np.minimum, uv[:, j], ring_offsets, 0.0) for j in range(2)], axis=1)
    high = np.stack([segment_reduce(np.maximum, uv[:, j], ring_offsets, 0.0) for j in range(2)], axis=1)
    start = np.floor(low[:, 0] + TOL.zero)
    count = np.maximum(np.ceil(high[:, 0] - TOL.zero) - start, 0)
    count[~usable | (high[:, 1] <= TOL.zero) | (low[:, 1] >= 1 - TOL.zero)] = 0
    if check is not None:
        check(count)
    owner, index = fan_out(count.astype(np.int64))
    inv = inverse[owner]
    along_u, along_v = inv[:, :, 0], inv[:, :, 1]
    # the point of (u, v) = (0, 0): the inverse applied to (-u0, -v0, n . X0)
    rhs = np.concatenate([-maps[owner, :, 3], np.einsum("pi,pi->p", normal, first)[owner, None]], axis=1)
    at_zero = np.einsum("kij,kj->ki", inv, rhs)
    xform = np.empty((len(owner), 3, 4))
    xform[:, :, 0] = along_u
    xform[:, :, 1] = lift[owner]
    xform[:, :, 2] = -along_v
    xform[:, :, 3] = at_zero + along_u * (start[owner] + index)[:, None] + along_v
    return xform, _edge_planes(world, ring_offsets, normal, lift)[owner], owner


def _edge_planes(world: np.ndarray, ring_offsets: np.ndarray, normal: np.ndarray,
                 lift: np.ndarray) -> np.ndarray:
    """(P, 4 E): the planes through each piece's edges containing ``lift`` (P, 3), facing into the piece
    (its ring winds counter-clockwise around ``normal``); NaN where an edge runs along ``lift`` and past
    a piece's edges."""
    ring = segment_of(ring_offsets)
    at = np.arange(len(world))
    edge = world[next_in_segment(ring_offsets)] - world
    m = np.cross(edge, lift[ring])
    m *= np.sign(np.einsum("vi,vi->v", m, np.cross(normal[ring], edge)))[:, None]  # towards the inside
    length = np.linalg.norm(m, axis=1)
    ok = length > TOL.zero * np.linalg.norm(edge, axis=1) * np.linalg.norm(lift[ring], axis=1)
    m = np.divide(m, length[:, None], out=np.zeros_like(m), where=ok[:, None])
    counts = np.diff(ring_offsets)
    planes = np.full((len(counts), 4 * max(int(counts.max(initial=0)), 1)), np.nan)
    column = 4 * (at - ring_offsets[:-1][ring])
    for j in range(3):
        planes[ring[ok], column[ok] + j] = m[ok, j]
    planes[ring[ok], column[ok] + 3] = -np.einsum("vi,vi->v", m, world)[ok]
    return planes


def _gathered(pieces) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The polygons of every asset's placements in placement order: vertices (V, 3), ring_offsets, and the
    placement of each polygon."""
    if not pieces:
        return np.empty((0, 3)), np.zeros(1, np.int64), np.zeros(0, np.int64)
    verts = np.concatenate([p[0] for p in pieces])
    counts = np.concatenate([np.diff(p[1]) for p in pieces])
    placement = np.concatenate([p[2] for p in pieces])
    order = np.argsort(placement, kind="stable")
    taken, ring_offsets = ragged_take(offsets_from_counts(counts), order)
    return verts[taken], ring_offsets, placement[order]
