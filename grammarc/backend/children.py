"""The children of a split: scopes placed along the split axis, polygons and meshes cut to their slabs,
and the split or component context (``split.index``, ``comp.total``...) of new children.

A split operation computes where its children lie along one axis (parent, position, length, and a number:
their cell or index); ``clip`` cuts the geometry of polygon and mesh parents to those slabs (dropping the
children left empty), and ``children`` makes the child shapes: the parent's scope moved and cut, a new
random key, the parent's parameters and attributes, the context the grammar reads.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from grammarc.backend import mesh_shapes
from grammarc.backend.box_rings import piece_corners, with_corners
from grammarc.backend.chunk import Chunk
from grammarc.backend.context import Context
from grammarc.backend.kernels import scope as scope_kernels
from grammarc.backend.kernels.order import group_by
from grammarc.backend.plan import Plan
from grammarc.backend.shapes import Shapes
from grammarc.backend.streams import piece_keys
from grammarc.constants import TOL
from grammarc.geometry.clip import clip_to_slabs
from grammarc.geometry.components import rect_rings
from grammarc.geometry.meshes import MESH_BASE, is_mesh, is_polygon
from grammarc.geometry.polygons import PLANE_U, PLANE_V
from grammarc.geometry.queries import shape_faces
from grammarc.ragged import ragged_take, segment_of


def children(ctx: Context, shapes: Shapes, axis: int, parent, index, pos, length, site: int, order=None,
             geometry=None) -> Shapes:
    """Children of a split along ``axis``: the parent's scope moved by ``pos`` and cut to ``length``.

    ``order`` (default: as given) picks and orders the children; ``geometry`` (from ``clip``) gives
    the clipped pieces their own boxes and polygons, and the corners the rings of pieces kept as boxes
    start at (``box_rings``).
    """
    frames = ctx.chunk.frames
    if order is None:
        order = np.arange(len(parent))
    origin, size, key, frame, geom, lot, depth, parents = scope_kernels.place_children(
        shapes.origin, shapes.size, shapes.key, shapes.frame, shapes.geom, shapes.lot, shapes.depth,
        frames.data, axis, order, parent, pos, length, site, index,
    )
    if geometry is not None:
        is_piece, piece_geom, low, extent, piece_corner = (g[order] for g in geometry)
        rows = np.flatnonzero(is_piece)
        axes = frames[frame[rows]]
        origin[rows] = shapes.origin[parents[rows]] + np.einsum("ni,nij->nj", low[rows], axes)
        size[rows] = extent[rows]
        geom[rows] = piece_geom[rows]
    if ctx.plan.sequential_random:  # PRT's stream: the child's state from its parent's and its number
        key = piece_keys(True, shapes.key[parents], index[order], site)
    made = Shapes(origin, size, frame, geom, lot, key, depth, tuple(p.take(parents) for p in shapes.params),
                  tuple(d.take(parents) for d in shapes.dynamic))
    if geometry is not None and len(rows) and ctx.plan.ring_slot is not None:
        corner = made.dynamic[ctx.plan.ring_slot].copy()
        corner[rows] = piece_corner[rows]
        made = with_corners(ctx.plan, made, corner)
    return with_context(ctx.plan, made, "split", index[order], parents, len(shapes))


def grouped_children(ctx: Context, shapes: Shapes, axis: int, parent, cell, pos, length, site: int,
                     n_parts: int, geometry=None) -> tuple[Shapes, np.ndarray]:
    """``children`` ordered by body part (cell mod parts), each part's batch then a slice, and where each
    part's slice starts (``offsets`` (n_parts+1,))."""
    order, offsets = by_part(cell, n_parts)
    return children(ctx, shapes, axis, parent, cell, pos, length, site, order, geometry), offsets


def by_part(cell: np.ndarray, n_parts: int) -> tuple[np.ndarray, np.ndarray]:
    """Children ordered by body part (cell mod parts), and where each part's run starts (``group_by``)."""
    return group_by(cell % n_parts if n_parts > 1 else np.zeros_like(cell), n_parts)


def with_context(plan: Plan, shapes: Shapes, kind: str, index, parents, n_parents: int, selector=None) -> Shapes:
    """Set ``split.index``/``split.total`` (or ``comp.*``) of new children, where the grammar reads
    them: the child's number and its parent's number of children."""
    dynamic = list(shapes.dynamic)
    slots = plan.dynamic
    if f"{kind}.index" in slots:
        dynamic[slots[f"{kind}.index"]] = index.astype(np.float64)
    if f"{kind}.total" in slots:
        dynamic[slots[f"{kind}.total"]] = np.bincount(parents, minlength=n_parents)[parents].astype(np.float64)
    if selector is not None and "comp.sel" in slots:
        dynamic[slots["comp.sel"]] = selector
    return replace(shapes, dynamic=tuple(dynamic))


def clip(chunk: Chunk, shapes: Shapes, axis: int, parent, step, pos, length, index, adjust: bool = True,
         turn_cuts: bool = False):
    """``clip_pieces``; with ``adjust`` false (CityEngine's ``split(axis, noAdjust)``) the pieces keep
    their slabs as their scopes (``fill_slabs``), so the children's scopes fill the parent's without gaps."""
    if adjust:
        return clip_pieces(chunk, shapes, axis, parent, step, pos, length, index, turn_cuts)
    # the children's row numbers go through in place of their numbers: their slabs are taken by them
    parent, step, _, _, source, geometry = clip_pieces(chunk, shapes, axis, parent, step, pos, length,
                                                       np.arange(len(parent)), turn_cuts)
    if geometry is not None:
        geometry = fill_slabs(chunk, shapes, axis, parent, pos[source], length[source], geometry)
    return parent, step, pos[source], length[source], index[source], geometry


def fill_slabs(chunk: Chunk, shapes: Shapes, axis: int, parent, pos, length, geometry):
    """The geometry of ``clip_pieces`` with each piece's box its slab of the parent's scope: a piece that
    does not fill its slab gets its polygon or mesh again, normalized to the slab (a rectangle piece
    becomes a polygon)."""
    is_piece, geom, low, extent, corner = (g.copy() for g in geometry)
    slab_low = np.zeros((len(parent), 3))
    slab_low[:, axis] = pos
    slab_extent = shapes.size[parent].copy()
    slab_extent[:, axis] = length
    fits = (np.abs(low - slab_low) <= TOL.zero).all(axis=1) & (np.abs(extent - slab_extent) <= TOL.zero).all(axis=1)
    moved = np.flatnonzero(is_piece & ~fits)
    if not len(moved):
        return geometry
    meshes = moved[is_mesh(geom[moved])]
    polygons = moved[~is_mesh(geom[moved])]
    if len(polygons):
        store = chunk.polygons
        plane = np.where(geom[polygons] >= 0, store.plane[np.maximum(geom[polygons], 0)],
                         store.plane[shapes.geom[parent[polygons]]]).astype(np.int8)
        rects = np.flatnonzero(geom[polygons] < 0)
        ids = geom[polygons].astype(np.int64)
        if len(rects):
            ids[rects] = store.add(rect_rings(plane[rects], corner[polygons[rects]]),
                                   np.arange(0, 4 * len(rects) + 1, 4, dtype=np.int64),
                                   np.arange(len(rects) + 1, dtype=np.int64), plane[rects])
        coords, ring_offsets, poly_offsets = store.gather(ids)
        vertex_piece = segment_of(poly_offsets)[segment_of(ring_offsets)]
        of = polygons[vertex_piece][:, None]
        uv = np.stack([PLANE_U[plane], PLANE_V[plane]], axis=1)[vertex_piece]  # (V, 2): the scope axes of u, v
        coords = _renormalized(coords, low[of, uv], extent[of, uv], slab_low[of, uv], slab_extent[of, uv])
        geom[polygons] = store.add(coords, ring_offsets, poly_offsets, plane)
    if len(meshes):
        coords, ring_offsets, face_offsets, mesh_offsets = chunk.meshes.gather(geom[meshes] - MESH_BASE)
        of = meshes[segment_of(mesh_offsets)[segment_of(face_offsets)[segment_of(ring_offsets)]]]
        coords = _renormalized(coords, low[of], extent[of], slab_low[of], slab_extent[of])
        geom[meshes] = (MESH_BASE + chunk.meshes.add(coords, ring_offsets, face_offsets, mesh_offsets)).astype(np.int32)
    low[moved], extent[moved] = slab_low[moved], slab_extent[moved]
    return is_piece, geom, low, extent, corner


def _renormalized(coords, low, extent, slab_low, slab_extent) -> np.ndarray:
    """Coordinates normalized to a piece's box (``low``, ``extent``) normalized to its slab instead, per
    vertex and axis (an axis of no extent at 0)."""
    scope = low + coords * extent
    return np.divide(scope - slab_low, slab_extent, out=np.zeros_like(scope), where=slab_extent > TOL.zero)


def clip_pieces(chunk: Chunk, shapes: Shapes, axis: int, parent, step, pos, length, index, turn_cuts: bool = False):
    """Children of polygons split across their plane become the pieces of the polygon in their slabs
    (``geometry.clip``): empty ones go, a slab that cuts a polygon apart gives one child a piece, one that
    cuts a prism apart one child all its pieces (``_join_prism_pieces``).
    Children of meshes (roofs, envelopes) become the mesh cut to their slab and closed
    (``mesh_shapes.clip_meshes``).

    Takes and returns the split's children as (parent, step, pos, length, index) arrays, and the
    pieces' geometry for ``children`` (None when no child is a polygon split across its plane).
    """
    if len(chunk.meshes) and is_mesh(shapes.geom[parent]).any():
        parent, step, pos, length, index, meshes = _clip_meshes(chunk, shapes, axis, parent, step, pos, length,
                                                                index)
    else:
        meshes = None
    store = chunk.polygons
    geom = shapes.geom[parent]
    poly = np.flatnonzero(is_polygon(geom))
    poly = poly[store.plane[geom[poly]] != axis]
    if not len(poly):
        return parent, step, pos, length, index, meshes
    clipped = clip_to_slabs(store, geom[poly], shapes.size[parent[poly]], axis, pos[poly], length[poly],
                            turn_cuts)
    whole = np.ones(len(parent), dtype=bool)
    whole[poly] = False
    rows = np.concatenate([np.flatnonzero(whole), poly[clipped.source]])
    piece = np.concatenate([np.full(int(whole.sum()), -1), np.arange(len(clipped.source))])
    order = np.lexsort((piece, rows))  # pieces take their child's place, in GEOS's order
    rows, piece = rows[order], piece[order]
    new_geom = np.full(len(clipped.source), -1, dtype=np.int32)
    shaped = np.flatnonzero(~clipped.is_rect)
    if len(shaped):
        rings, poly_offsets = ragged_take(clipped.poly_offsets, shaped)
        vertices, ring_offsets = ragged_take(clipped.ring_offsets, rings)
        new_geom[shaped] = store.add(clipped.coords[vertices], ring_offsets, poly_offsets, clipped.plane[shaped],
                                     clipped.turn[vertices])
    is_piece = piece >= 0
    pos, length = pos[rows].copy(), length[rows].copy()
    pos[is_piece] = clipped.low[piece[is_piece], axis]
    length[is_piece] = clipped.extent[piece[is_piece], axis]
    if len(clipped.source):
        geometry = (is_piece, new_geom[piece], clipped.low[piece], clipped.extent[piece],
                    piece_corners(clipped)[piece])
    else:  # every slab missed its polygon (the parents' holes): only the other children are left
        geometry = (is_piece, np.full(len(rows), -1, dtype=np.int32), np.zeros((len(rows), 3)),
                    np.zeros((len(rows), 3)), np.zeros(len(rows), dtype=np.int64))
    if meshes is not None:  # the mesh children keep their cut meshes
        from_mesh = ~is_piece & meshes[0][rows]
        for mine, theirs in zip(geometry, meshes):
            mine[from_mesh] = theirs[rows][from_mesh]
    keep = _join_prism_pieces(chunk, shapes, axis, parent[rows], rows, pos, length, geometry)
    return (parent[rows][keep], step[rows][keep], pos[keep], length[keep], index[rows][keep],
            tuple(g[keep] for g in geometry))


def _join_prism_pieces(chunk: Chunk, shapes: Shapes, axis: int, parent, child, pos, length, geometry) -> np.ndarray:
    """A slab that cuts a prism (an extruded concave footprint) apart leaves its child all the pieces, one
    mesh in the box around them, as PRT does (a balcony's ``s()`` then scales the pieces together:
    complexpatterns' railings on a U's two arms stand where PRT's do). The first piece of each child
    takes the mesh, in place (``pos``, ``length`` and ``geometry``, rows (k,) of children ``child`` (k,)
    of parents ``parent`` (k,)); returns which rows stay."""
    is_piece, geom, low, extent, corner = geometry
    keep = np.ones(len(child), dtype=bool)
    store = chunk.polygons
    parent_geom = shapes.geom[parent]
    prism = is_piece & is_polygon(parent_geom)
    at = np.flatnonzero(prism)
    flat_axis = store.plane[parent_geom[at]]
    prism[at] = (flat_axis != axis) & (shapes.size[parent[at], flat_axis] > TOL.zero)
    # rows of a child follow each other: the later pieces of a prism's child join its first
    later = np.zeros(len(child), dtype=bool)
    later[1:] = prism[1:] & prism[:-1] & (child[1:] == child[:-1])
    if not later.any():
        return keep
    joined = later.copy()
    joined[:-1] |= later[1:]
    rows = np.flatnonzero(joined)
    faces = shape_faces(extent[rows], geom[rows], store, chunk.meshes, corner[rows])
    verts = faces.verts + low[rows][faces.vertex_shape()]  # in the parent's scope
    first = rows[~later[rows]]
    mesh_offsets = faces.shape_offsets[np.append(np.flatnonzero(~later[rows]), len(rows))]
    new_geom, new_low, new_extent = mesh_shapes.store_fitted(chunk, verts, faces.ring_offsets, faces.face_offsets,
                                                             mesh_offsets)
    geom[first], low[first], extent[first], corner[first] = new_geom, new_low, new_extent, 0
    pos[first], length[first] = new_low[:, axis], new_extent[:, axis]
    keep[later] = False
    return keep


def _clip_meshes(chunk: Chunk, shapes: Shapes, axis: int, parent, step, pos, length, index):
    """``clip`` for the children of mesh shapes: each gets its parent's mesh cut to its slab, a child
    whose slab misses the mesh goes. Returns the children and their geometry (as ``clip``'s)."""
    mesh_rows = np.flatnonzero(is_mesh(shapes.geom[parent]))
    geom, low, extent, keep = mesh_shapes.clip_meshes(chunk, shapes, parent[mesh_rows], axis,
                                                      pos[mesh_rows], length[mesh_rows])
    n = len(parent)
    kept = np.ones(n, dtype=bool)
    kept[mesh_rows[~keep]] = False
    is_piece = np.zeros(n, dtype=bool)
    piece_geom = np.full(n, -1, dtype=np.int32)
    piece_low = np.zeros((n, 3))
    piece_extent = np.zeros((n, 3))
    piece_corner = np.zeros(n, dtype=np.int64)
    is_piece[mesh_rows] = True
    piece_geom[mesh_rows], piece_low[mesh_rows], piece_extent[mesh_rows] = geom, low, extent
    pos, length = pos.copy(), length.copy()
    pos[mesh_rows], length[mesh_rows] = low[:, axis], extent[:, axis]
    geometry = tuple(a[kept] for a in (is_piece, piece_geom, piece_low, piece_extent, piece_corner))
    return parent[kept], step[kept], pos[kept], length[kept], index[kept], geometry
