"""Mesh shapes on the shape columns: roofs and faces of several parts (``convexify``), built, split into
faces and edges, cleaned (``cleanupGeometry``), and emitted as leaves.

A roof is a mesh (``geometry.meshes``) built over a face's polygon by ``geometry.roofs``. Its scope
keeps the face's axes, the box fitted to the mesh (an overhang widens it and moves its origin below the
eaves): the roof rises along the face's normal axis, y for a footprint, z for a face from a component
split. PRT keeps them so: candler's ``envelope`` on a comp(f) face then splits along the face's
in-plane y (``scope.sy``), not along the envelope's height.
"""

from __future__ import annotations

import numpy as np

from grammarc.backend.chunk import Chunk
from grammarc.backend.shapes import Shapes
from grammarc.constants import STRICT, TOL
from grammarc.geometry.cleanup import cleanup_meshes
from grammarc.geometry.clip import oriented_rings
from grammarc.geometry.meshes import (
    MESH_BASE,
    border_ring_edges,
    clip_slabs,
    face_frames,
    face_vertices,
    is_convex,
    mesh_corners,
    mesh_edges,
)
from grammarc.geometry.polygons import PLANE_U, PLANE_V, plane_to_scope
from grammarc.geometry.queries import shape_faces
from grammarc.geometry.roofs import ROOF_KINDS, roof_meshes
from grammarc.geometry.sections import append_caps, plane_segments, section_caps
from grammarc.model.records import MeshChunk
from grammarc.ragged import ragged_take, rank_within, segment_of, segment_reduce


def store_fitted(chunk: Chunk, verts: np.ndarray, ring_offsets, face_offsets, mesh_offsets):
    """Add meshes given in their scopes' units, each fitted to its own box: the box's low corner (k, 3)
    and size (k, 3) (0 along a flat axis) become the scope, the vertices are stored relative to it.
    Returns the meshes' ``geom`` codes (k,), low corners and sizes."""
    vertex_mesh = segment_of(mesh_offsets)[segment_of(face_offsets)[segment_of(ring_offsets)]]
    vertex_offsets = ring_offsets[face_offsets[mesh_offsets]]
    low = np.stack([segment_reduce(np.minimum, verts[:, j], vertex_offsets, 0.0) for j in range(3)], 1)
    high = np.stack([segment_reduce(np.maximum, verts[:, j], vertex_offsets, 0.0) for j in range(3)], 1)
    size = high - low
    scale = np.where(size > TOL.zero, size, np.inf)
    ids = chunk.meshes.add((verts - low[vertex_mesh]) / scale[vertex_mesh], ring_offsets, face_offsets,
                           mesh_offsets)
    return (MESH_BASE + ids).astype(np.int32), low, np.where(size > TOL.zero, size, 0.0)


def build_roofs(chunk: Chunk, shapes: Shapes, kind: str, polygons, value, by_height: bool, overhang,
                index, cap=None, even=None, edges=None) -> tuple[Shapes, np.ndarray]:
    """Roof shapes over ``shapes``' polygons (``polygons``: coords, ring_offsets, shape_offsets and the
    plane of each, as ``outlines.polygons_of`` gives them) and a mask (n,) of the shapes whose roof
    could not be built (their shapes keep their old geometry and must be reported). ``even`` (n,) bool
    levels the ridges of hip and gable roofs; ``edges``, an envelope's base height and angle under the
    edge from each vertex of ``polygons`` (two (V,) arrays), where they differ by side."""
    coords, ring_offsets, shape_offsets, plane = polygons
    n = len(shapes)
    rows = np.arange(n)
    size_a = shapes.size[rows, PLANE_U[plane]]
    size_b = shapes.size[rows, PLANE_V[plane]]
    edge_base, edge_angle = (None, None) if edges is None else edges
    verts, rings, faces, meshes, ok = roof_meshes(
        ROOF_KINDS[kind], coords, ring_offsets, shape_offsets, plane.astype(np.int8), size_a, size_b,
        value, by_height, overhang, index.astype(np.int64),
        np.full(n, np.inf) if cap is None else np.asarray(cap, dtype=np.float64),
        np.zeros(n, dtype=bool) if even is None else even, edge_base, edge_angle)
    return roof_shapes(chunk, shapes, plane, verts, rings, faces, meshes), ~ok


def roof_shapes(chunk: Chunk, shapes: Shapes, plane: np.ndarray, verts, rings, faces, meshes) -> Shapes:
    """``shapes`` whose geometry becomes the roof meshes (``geometry.roofs`` layout: (u, v, h) in each
    shape's plane ``plane`` (n,)), their scopes fitted to them."""
    vertex_shape = segment_of(meshes)[segment_of(faces)[segment_of(rings)]]
    vplane = plane[vertex_shape].astype(np.int64)
    roofed = plane_to_scope(verts[:, :2], vplane, verts[:, 2])
    geom, low, size = store_fitted(chunk, roofed, rings, faces, meshes)
    origin = shapes.origin + np.einsum("ni,nij->nj", low, chunk.frames[shapes.frame])
    return shapes.with_scope(origin, size, shapes.frame, geom)


def flat_meshes(chunk: Chunk, shapes: Shapes, parts: np.ndarray, source: np.ndarray, plane: np.ndarray) -> Shapes:
    """``shapes`` (flat) whose geometry becomes its ``parts``: shapely polygons (k,) in scope units, each
    of the shape ``source`` (k,), in the plane ``plane`` (n,). A shape of one part keeps its geometry
    (the part is its face); one of several becomes a mesh of them in its own scope."""
    several = np.bincount(source, minlength=len(shapes)) > 1
    pick = several[source]
    if not pick.any():
        return shapes
    parts, source = parts[pick], source[pick]
    part_plane = plane[source]
    _, coords, ring_offsets, face_offsets = oriented_rings(parts, part_plane)
    vertex_part = segment_of(face_offsets)[segment_of(ring_offsets)]
    owner = source[vertex_part]
    local = plane_to_scope(coords, part_plane[vertex_part])
    size = np.where(shapes.size > TOL.zero, shapes.size, np.inf)
    mesh_offsets = np.r_[0, np.cumsum(np.bincount(source, minlength=len(shapes))[several])]
    ids = chunk.meshes.add(local / size[owner], ring_offsets, face_offsets, mesh_offsets)
    geom = shapes.geom.copy()
    geom[several] = (MESH_BASE + ids).astype(np.int32)
    return shapes.with_scope(shapes.origin, shapes.size, shapes.frame, geom)


def face_piece_meshes(chunk: Chunk, shapes: Shapes, parts: np.ndarray, source: np.ndarray, origin: np.ndarray,
                      axes: np.ndarray) -> Shapes:
    """One mesh shape per row of ``shapes`` from ``parts``: shapely polygons (k,) each in the x-y plane of
    its own face scope (``origin`` (k, 3) and ``axes`` (k, 3, 3) in the frame of its shape ``source``
    (k,), grouped by row), as ``offset`` cuts a roof's faces; the scope fitted around each row's parts
    (a row without parts gets an empty mesh)."""
    _, coords, ring_offsets, part_offsets = oriented_rings(parts, np.full(len(parts), 2, dtype=np.int8))
    vertex_part = segment_of(part_offsets)[segment_of(ring_offsets)]
    local = (origin[vertex_part] + coords[:, :1] * axes[vertex_part, 0]
             + coords[:, 1:] * axes[vertex_part, 1])
    mesh_offsets = np.r_[0, np.cumsum(np.bincount(source, minlength=len(shapes)))]
    geom, low, size = store_fitted(chunk, local, ring_offsets, part_offsets, mesh_offsets)
    return shapes.with_scope(shapes.origin + np.einsum("ni,nij->nj", low, chunk.frames[shapes.frame]), size,
                             shapes.frame, geom)


def flat_mesh_faces(chunk: Chunk, shapes: Shapes) -> tuple[np.ndarray, np.ndarray]:
    """The faces of flat mesh shapes (each with one scope size 0) stored as polygons in that plane of
    their scopes: the polygons' ids (F,), mesh by mesh, and each mesh's number of faces (n,)."""
    coords, ring_offsets, face_offsets, mesh_offsets = chunk.meshes.gather(shapes.geom - MESH_BASE)
    plane = np.argmax(shapes.size <= TOL.zero, axis=1)
    n_faces = len(face_offsets) - 1
    ids = _add_polygons(chunk, coords, ring_offsets, face_offsets, np.arange(n_faces),
                        plane[segment_of(mesh_offsets)].astype(np.int8))
    return ids, np.diff(mesh_offsets)


def piece_meshes(chunk: Chunk, shapes: Shapes, pieces) -> Shapes:
    """One shape per row of ``shapes`` from its several ``pieces`` (``geometry.clip.Clipped``, every
    piece's source among the rows): the scope fitted around all of them, the pieces its mesh's faces."""
    n = len(shapes)
    src = pieces.source
    low = np.full((n, 3), np.inf)
    high = np.full((n, 3), -np.inf)
    np.minimum.at(low, src, pieces.low)
    np.maximum.at(high, src, pieces.low + pieces.extent)
    size = high - low
    rings, poly_offsets = ragged_take(pieces.poly_offsets, np.arange(len(src)))
    vertices, ring_offsets = ragged_take(pieces.ring_offsets, rings)
    vertex_piece = segment_of(poly_offsets)[segment_of(ring_offsets)]
    plane = pieces.plane[vertex_piece].astype(np.int64)
    at = np.arange(len(vertices))
    local = pieces.low[vertex_piece] - low[src[vertex_piece]]
    for axis, which in ((PLANE_U[plane], 0), (PLANE_V[plane], 1)):
        local[at, axis] += pieces.coords[vertices, which] * pieces.extent[vertex_piece, axis]
    scale = np.where(size > TOL.zero, size, np.inf)
    if STRICT:
        assert (np.diff(src) >= 0).all(), "pieces must come grouped by row"
    mesh_offsets = np.r_[0, np.cumsum(np.bincount(src, minlength=n))]
    ids = chunk.meshes.add(local / scale[src[vertex_piece]], ring_offsets, poly_offsets, mesh_offsets)
    origin = shapes.origin + np.einsum("ni,nij->nj", low, chunk.frames[shapes.frame])
    return shapes.with_scope(origin, np.where(size > TOL.zero, size, 0.0), shapes.frame,
                             (MESH_BASE + ids).astype(np.int32))


#: Component kinds of roofs (``components.KIND_CODES``): faces, edges, vertices. The bottom is face 0.
FACES, SIDEFACES, BOTTOM, EDGES, SIDEEDGES, TOPEDGES, BOTTOMEDGES, VERTICES = 0, 1, 3, 4, 5, 6, 7, 8
MESH_KINDS = frozenset({FACES, SIDEFACES, BOTTOM, EDGES, SIDEEDGES, TOPEDGES, BOTTOMEDGES, VERTICES})
#: mesh_edges' edge kinds wanted by each edge component kind.
_EDGE_KINDS = {EDGES: (0, 1, 2), BOTTOMEDGES: (0,), SIDEEDGES: (1,), TOPEDGES: (2,)}


def mesh_components(chunk: Chunk, shapes: Shapes, kind: int, borders: bool = False):
    """Components of mesh shapes: parent (m,), index (m,) among the parent's components of this kind,
    origin (m, 3) and axes (m, 3, 3) in the parent's frame, size (m, 3), geom (m,): faces become
    polygons (plane z) with CityEngine's face scopes, edges scope edges (``meshes.mesh_edges``),
    vertices points (``meshes.mesh_corners``); roof (m,) int32, each edge's place on the roof
    (``meshes.roof_edge_kinds``; -1 for faces and vertices); and border (m,) bool, with ``borders`` the
    components on the mesh's border (``meshes.border_ring_edges``: none on a closed mesh), else none."""
    verts, ring_offsets, face_offsets, mesh_offsets, _ = face_vertices(
        chunk.meshes, shapes.geom - MESH_BASE, shapes.size)
    if kind == VERTICES:
        parent, origin, axes, border = mesh_corners(verts, ring_offsets, face_offsets, mesh_offsets, TOL.zero)
        none = np.full(len(parent), -1, dtype=np.int32)
        return parent, rank_within(parent), origin, axes, np.zeros((len(parent), 3)), none, none, border
    if kind in _EDGE_KINDS:
        parent, origin, axes, size, edge_kind, roof, border = mesh_edges(verts, ring_offsets, face_offsets,
                                                                         mesh_offsets, TOL.zero)
        keep = np.isin(edge_kind, _EDGE_KINDS[kind])
        parent, origin, axes, size, roof = parent[keep], origin[keep], axes[keep], size[keep], roof[keep]
        return (parent, rank_within(parent), origin, axes, size, np.full(len(parent), -1, dtype=np.int32),
                roof.astype(np.int32), border[keep])
    origin, axes, size, uv, ok = face_frames(verts, ring_offsets, face_offsets, TOL.zero)
    face_mesh = segment_of(mesh_offsets)
    index = np.arange(len(face_mesh)) - mesh_offsets[face_mesh]
    geom = chunk.polygons.add(uv, ring_offsets, face_offsets, np.full(len(face_mesh), 2, dtype=np.int8))
    keep = ok & {FACES: index >= 0, SIDEFACES: index > 0, BOTTOM: index == 0}[kind]
    if kind == SIDEFACES:
        index = index - 1
    border = np.zeros(len(face_mesh), dtype=bool)
    if borders:
        edges = border_ring_edges(verts, ring_offsets, face_offsets, mesh_offsets, TOL.zero)
        border = np.bincount(segment_of(face_offsets)[segment_of(ring_offsets)], weights=edges,
                             minlength=len(face_mesh)) > 0
    return (face_mesh[keep], index[keep], origin[keep], axes[keep], size[keep], geom[keep],
            np.full(int(keep.sum()), -1, dtype=np.int32), border[keep])


def clip_meshes(chunk: Chunk, shapes: Shapes, parent: np.ndarray, axis: int, pos: np.ndarray,
                length: np.ndarray):
    """Split children of mesh shapes, each its parent's mesh cut to its slab [pos, pos + length] along
    ``axis`` and closed: a convex mesh by the hull of its crossings (``meshes.clip_slabs``), any other
    by its sections (``geometry.sections``). Returns the children's new geometry codes (m,), their
    boxes' low corners and extents (m, 3) in the parents' scopes, and which children have any mesh
    left (m,)."""
    parents, child_mesh = np.unique(parent, return_inverse=True)  # each parent's mesh gathered once
    verts, ring_offsets, face_offsets, mesh_offsets, _ = face_vertices(
        chunk.meshes, shapes.geom[parents] - MESH_BASE, shapes.size[parents])
    cut = cut_to_slabs(verts, ring_offsets, face_offsets, mesh_offsets, child_mesh.reshape(-1), axis, pos,
                       pos + length)
    geom, low, extent = store_fitted(chunk, *cut)
    return geom, low, extent, np.diff(cut[3]) > 0


def cut_to_slabs(verts, ring_offsets, face_offsets, mesh_offsets, child_mesh, axis: int, lo, hi):
    """Meshes (ragged, in scope units) cut to slabs ``lo <= coordinate[axis] <= hi`` (m,), the mesh
    ``child_mesh`` (m,) for each, and closed: a convex mesh by the hull of its crossings
    (``meshes.clip_slabs``), any other by its sections (``geometry.sections``). Returns the cut meshes as
    ragged arrays (verts, ring_offsets, face_offsets, mesh_offsets (m+1,)), an empty one where a slab
    misses its mesh."""
    hull = is_convex(verts, ring_offsets, face_offsets, mesh_offsets)[child_mesh]
    cut = clip_slabs(verts, ring_offsets, face_offsets, mesh_offsets, child_mesh, axis, lo, hi, hull, TOL.zero)
    if not hull.all():
        ends, cap = plane_segments(verts, ring_offsets, face_offsets, mesh_offsets, child_mesh,
                                   np.flatnonzero(~hull), axis, lo, hi)
        parts, which = section_caps(ends, cap, axis)
        cut = append_caps(*cut, parts, which, axis, lo, hi)
    return cut


def reframe_meshes(chunk: Chunk, shapes: Shapes, new_axes: np.ndarray, frame: np.ndarray) -> Shapes:
    """Shapes in scopes with ``new_axes`` (n, 3, 3), the rows of the frames ``frame`` (n,), around unchanged
    geometry (``alignScopeToAxes``, ``rotateScope``, ``alignScopeToGeometry``): any turn, their faces
    (``geometry.queries.shape_faces``: a polygon or a prism its faces, a mesh its own) stored as a mesh
    fitted to the new scope. A scope box turned by quarter turns (each new axis an old one or its opposite)
    stays a box."""
    faces = shape_faces(shapes.size, shapes.geom, chunk.polygons, chunk.meshes)
    vertex_shape = faces.vertex_shape()
    old_axes = chunk.frames[shapes.frame]
    # world offsets from the old origin, then coordinates along the new axes
    world = np.einsum("vi,vij->vj", faces.verts, old_axes[vertex_shape])
    local = np.einsum("vj,vij->vi", world, new_axes[vertex_shape])
    geom, low, size = store_fitted(chunk, local, faces.ring_offsets, faces.face_offsets, faces.shape_offsets)
    turns = np.abs(np.einsum("nij,nkj->nik", new_axes, old_axes))
    box = (shapes.geom == -1) & (np.abs(turns.max(axis=2) - 1) < 1e-9).all(axis=1)
    geom[box] = -1
    origin = shapes.origin + np.einsum("ni,nij->nj", low, new_axes)
    return shapes.with_scope(origin, size, frame, geom)


def clean_meshes(chunk: Chunk, shapes: Shapes, tolerance: np.ndarray, component: str) -> np.ndarray:
    """``cleanupGeometry`` of mesh shapes in their scopes: their new ``geom`` codes (n,). A flat shape
    left with one face (convexify's parts joined back) is a face again, a polygon in its scope's plane,
    which the face operations take."""
    verts, ring_offsets, face_offsets, mesh_offsets, _ = face_vertices(
        chunk.meshes, shapes.geom - MESH_BASE, shapes.size)
    verts, ring_offsets, face_offsets, mesh_offsets = cleanup_meshes(
        verts, ring_offsets, face_offsets, mesh_offsets, tolerance, component)
    normalized = _normalized(verts, ring_offsets, face_offsets, mesh_offsets, shapes.size)
    geom = (MESH_BASE + chunk.meshes.add(normalized, ring_offsets, face_offsets, mesh_offsets)).astype(np.int32)
    flat = shapes.size <= TOL.zero
    face = np.flatnonzero((np.diff(mesh_offsets) == 1) & (flat.sum(axis=1) == 1))
    if len(face):
        geom[face] = _add_polygons(chunk, normalized, ring_offsets, face_offsets, mesh_offsets[face],
                                   np.argmax(flat[face], axis=1))
    return geom


def clean_polygons(chunk: Chunk, shapes: Shapes, polygons, tolerance: np.ndarray, component: str) -> np.ndarray:
    """``cleanupGeometry`` of polygon shapes (``polygons`` as ``outlines.polygons_of`` gives them), each
    its one face, in their scopes: their new ``geom`` codes (n,). A polygon that changed is stored anew,
    one whose face went becomes an empty mesh (its scope stays, for the operations after it), the others
    keep their codes (a flat rectangle its fast path). A prism is cleaned through its base, which is not
    its only face, so it keeps its small faces."""
    coords, ring_offsets, shape_offsets, plane = polygons
    n = len(shapes)
    rows = np.arange(n)
    vertex_shape = segment_of(shape_offsets)[segment_of(ring_offsets)]
    in_plane = np.stack([shapes.size[rows, PLANE_U[plane]], shapes.size[rows, PLANE_V[plane]]], axis=1)
    points = plane_to_scope(coords * in_plane[vertex_shape], plane[vertex_shape])
    cleaned, cleaned_rings, cleaned_faces, cleaned_shapes = cleanup_meshes(
        points, ring_offsets, shape_offsets, np.arange(n + 1, dtype=np.int64), tolerance, component,
        keep_small=shapes.size[rows, plane] > TOL.zero)
    # the same vertices in the same rings, unmoved: nothing changed (cleaning only drops and merges)
    before = ring_offsets[shape_offsets]
    after = cleaned_rings[cleaned_faces[cleaned_shapes]]
    changed = np.diff(before) != np.diff(after)
    same = np.flatnonzero(~changed)
    old, _ = ragged_take(before, same)
    new, counts = ragged_take(after, same)
    moved = (points[old] != cleaned[new]).any(axis=1)
    changed[same] = segment_reduce(np.maximum, moved, counts, False)
    geom = shapes.geom.copy()
    empty = np.diff(cleaned_shapes) == 0
    if empty.any():
        none = np.zeros(int(empty.sum()) + 1, dtype=np.int64)
        geom[empty] = MESH_BASE + chunk.meshes.add(np.empty((0, 3)), none[:1], none[:1], none)
    store = np.flatnonzero(changed & ~empty)
    if len(store):
        normalized = _normalized(cleaned, cleaned_rings, cleaned_faces, cleaned_shapes, shapes.size)
        geom[store] = _add_polygons(chunk, normalized, cleaned_rings, cleaned_faces, cleaned_shapes[store],
                                    plane[store])
    return geom


def _normalized(verts, ring_offsets, face_offsets, mesh_offsets, size):
    """Mesh vertices (V, 3) in their scopes' units as fractions of the scope sizes (n, 3) (0 on a
    flat axis), as the stores keep them."""
    vertex_mesh = segment_of(mesh_offsets)[segment_of(face_offsets)[segment_of(ring_offsets)]]
    return verts / np.where(size > TOL.zero, size, np.inf)[vertex_mesh]


def _add_polygons(chunk: Chunk, normalized, ring_offsets, face_offsets, faces, plane) -> np.ndarray:
    """Store faces ``faces`` (k,) of meshes (normalized vertices, lying in the planes ``plane`` (k,) of
    their scopes) as polygons; returns their ids (k,)."""
    rings, poly_offsets = ragged_take(face_offsets, faces)
    vertices, polygon_rings = ragged_take(ring_offsets, rings)
    vertex_plane = plane[segment_of(poly_offsets)[segment_of(polygon_rings)]]
    uv = np.stack([normalized[vertices, PLANE_U[vertex_plane]], normalized[vertices, PLANE_V[vertex_plane]]], 1)
    return chunk.polygons.add(uv, polygon_rings, poly_offsets, plane)


def mesh_leaves(chunk: Chunk, shapes: Shapes, symbol: int, colors) -> tuple[MeshChunk, np.ndarray]:
    """The faces of leaf mesh shapes relative to their lots' origins (``model.records.LotOrigins``), and the
    shape each face comes from."""
    verts, ring_offsets, face_offsets, mesh_offsets, vertex_shape = face_vertices(
        chunk.meshes, shapes.geom - MESH_BASE, shapes.size)
    axes = chunk.frames[shapes.frame][vertex_shape]
    placed = (shapes.origin - chunk.lot_origin[shapes.lot])[vertex_shape]
    for j in range(3):
        placed += verts[:, j, None] * axes[:, j]
    face_shape = segment_of(mesh_offsets)
    return MeshChunk(
        vertices=placed.astype(np.float32), ring_offsets=ring_offsets, face_offsets=face_offsets,
        lot=shapes.lot[face_shape].astype(np.int32), symbol=np.full(len(face_shape), symbol, dtype=np.int32),
        color=colors[face_shape] if colors is not None else None), face_shape
