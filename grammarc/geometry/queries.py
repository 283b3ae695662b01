"""The faces of shapes in space, and what CityEngine's geometry queries ask of them: each face's area and
normal, its holes, whether it is concave or planar, and the edges the faces share.

Every shape is turned into its faces, in its scope's units: a box its six rectangles (a flat scope its one
rectangle, a line or a point none), a polygon its face, a prism (a polygon extruded along its plane's
normal axis) its bottom, a side quad per ring edge and its top, a roof or another mesh its own faces. An
outline winds counter-clockwise around the face's outward normal, its holes the other way, as in the
stores (``geometry.polygons``, ``geometry.meshes``). The queries then run on those faces, all shapes at
once: ``geometry.isConcave``, ``isPlanar``, ``nHoles`` per face, ``nEdges``, ``boundaryLength`` and
``isClosedSurface`` on the edges the faces share (their ends welded on a grid of ``TOL.zero``), the
selected areas and orientations on the faces' normals (``backend.selectors`` classifies them).

Layout of ``Faces`` (Arrow-style offsets, each starting at 0): ``verts`` (V, 3) float64 in scope units,
``ring_offsets`` (R+1,) into verts, ``face_offsets`` (F+1,) into rings (outline first), ``shape_offsets``
(n+1,) into faces, one segment per shape of the batch in its order.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from grammarc.constants import TOL
from grammarc.geometry.components import rect_plane, rect_rings
from grammarc.geometry.meshes import MESH_BASE, MeshStore, face_vertices, is_mesh, is_polygon
from grammarc.geometry.polygons import PLANE_U, PLANE_V, PolygonStore
from grammarc.ragged import offsets_from_counts, ragged_take, row_groups, segment_of, segment_reduce


@dataclass(frozen=True, eq=False)
class Faces:
    """The faces of a batch of shapes, in their scopes' units (see the module's layout)."""

    verts: np.ndarray
    ring_offsets: np.ndarray
    face_offsets: np.ndarray
    shape_offsets: np.ndarray

    def face_shape(self) -> np.ndarray:
        """The shape of each face (F,) int64."""
        return segment_of(self.shape_offsets)

    def vertex_shape(self) -> np.ndarray:
        """The shape of each vertex (V,) int64."""
        return self.face_shape()[segment_of(self.face_offsets)][segment_of(self.ring_offsets)]


def shape_faces(size: np.ndarray, geom: np.ndarray, store: PolygonStore, meshes: MeshStore) -> Faces:
    """The faces of shapes with scope sizes (n, 3) and geometry codes (n,): boxes, faces and prisms of the
    polygon store, meshes of the mesh store; an inserted asset is its box, as ``geometry.area`` has it."""
    n = len(geom)
    poly = np.flatnonzero(is_polygon(geom))
    mesh = np.flatnonzero(is_mesh(geom))
    box = np.flatnonzero(~is_polygon(geom) & ~is_mesh(geom) & ((size <= TOL.zero).sum(axis=1) <= 1))
    pieces = []
    if len(poly) or len(box):
        coords, ring_offsets, poly_offsets = store.gather(geom[poly])
        plane = np.concatenate([store.plane[geom[poly]], rect_plane(size[box], TOL.zero)]).astype(np.int8)
        # the scope boxes' implicit rectangles after the polygons, one ring each
        coords = np.concatenate([coords, rect_rings(plane[len(poly):])])
        ring_offsets = np.concatenate([ring_offsets, ring_offsets[-1] + 4 * np.arange(1, len(box) + 1)])
        poly_offsets = np.concatenate([poly_offsets, poly_offsets[-1] + np.arange(1, len(box) + 1)])
        rows = np.concatenate([poly, box])
        verts, rings, faces, owner = _prism_faces(coords, ring_offsets, poly_offsets, plane, size[rows], TOL.zero)
        pieces.append((verts, rings, faces, rows[owner]))
    if len(mesh):
        verts, rings, faces, mesh_offsets, _ = face_vertices(meshes, geom[mesh] - MESH_BASE, size[mesh])
        pieces.append((verts, rings, faces, mesh[segment_of(mesh_offsets)]))
    if not pieces:
        return Faces(np.empty((0, 3)), np.zeros(1, np.int64), np.zeros(1, np.int64), np.zeros(n + 1, np.int64))
    verts, ring_offsets, face_offsets, face_shape = pieces[0] if len(pieces) == 1 else _concatenate(pieces)
    # faces grouped by shape, each shape's in the order they were made
    order = np.argsort(face_shape, kind="stable")
    rings, face_offsets = ragged_take(face_offsets, order)
    vertices, ring_offsets = ragged_take(ring_offsets, rings)
    return Faces(verts[vertices], ring_offsets, face_offsets,
                 offsets_from_counts(np.bincount(face_shape, minlength=n)))


def _concatenate(pieces):
    """Ragged faces (verts, ring_offsets, face_offsets, face_shape) one after another."""
    verts, rings, faces, shapes = [], [np.zeros(1, np.int64)], [np.zeros(1, np.int64)], []
    n_verts = n_rings = 0
    for v, r, f, s in pieces:
        verts.append(v)
        rings.append(r[1:] + n_verts)
        faces.append(f[1:] + n_rings)
        shapes.append(s)
        n_verts, n_rings = n_verts + len(v), n_rings + len(r) - 1
    return np.concatenate(verts), np.concatenate(rings), np.concatenate(faces), np.concatenate(shapes)


@njit(cache=True, nogil=True)
def _point(coords, j, a, b, nrm, size_row, height):
    p = np.zeros(3)
    p[a] = coords[j, 0] * size_row[a]
    p[b] = coords[j, 1] * size_row[b]
    p[nrm] = height
    return p


@njit(cache=True, nogil=True)
def _prism_faces(coords, ring_offsets, poly_offsets, plane, size, tol):
    """Faces of k polygons (normalized rings, one polygon per row) in their planes ``plane`` (k,), scaled
    by ``size`` (k, 3) and extruded along the plane's axis where the size there is above ``tol``.

    Returns verts (V, 3), ring_offsets (R+1,), face_offsets (F+1,) and each face's row (F,): a flat
    polygon is its one face; a prism its bottom (rings reversed, facing -axis), a quad per ring edge
    longer than ``tol`` (facing out of the solid), and its top.
    """
    k = len(plane)
    n_faces = 0
    n_rings = 0
    n_verts = 0
    for i in range(k):
        count = ring_offsets[poly_offsets[i + 1]] - ring_offsets[poly_offsets[i]]
        rings = poly_offsets[i + 1] - poly_offsets[i]
        if size[i, plane[i]] > tol:
            n_faces += 2 + count
            n_rings += 2 * rings + count
            n_verts += 6 * count
        else:
            n_faces += 1
            n_rings += rings
            n_verts += count
    verts = np.empty((n_verts, 3))
    out_rings = np.zeros(n_rings + 1, np.int64)
    out_faces = np.zeros(n_faces + 1, np.int64)
    owner = np.empty(n_faces, np.int64)
    v = 0
    r = 0
    f = 0
    for i in range(k):
        a, b, nrm = PLANE_U[plane[i]], PLANE_V[plane[i]], plane[i]
        h = size[i, nrm]
        solid = h > tol
        # bottom (reversed) then top of a prism; the face itself when flat
        for cap in range(2):
            if not solid and cap == 0:
                continue
            if solid and cap == 1:
                # the side quads come between the bottom and the top
                for ring in range(poly_offsets[i], poly_offsets[i + 1]):
                    r0 = ring_offsets[ring]
                    count = ring_offsets[ring + 1] - r0
                    for j in range(r0, r0 + count):
                        q = r0 + (j - r0 + 1) % count
                        p0 = _point(coords, j, a, b, nrm, size[i], 0.0)
                        p1 = _point(coords, q, a, b, nrm, size[i], 0.0)
                        if np.sqrt(((p1 - p0) ** 2).sum()) <= tol:
                            continue
                        verts[v] = p0
                        verts[v + 1] = p1
                        verts[v + 2] = _point(coords, q, a, b, nrm, size[i], h)
                        verts[v + 3] = _point(coords, j, a, b, nrm, size[i], h)
                        v += 4
                        r += 1
                        out_rings[r] = v
                        owner[f] = i
                        f += 1
                        out_faces[f] = r
            height = h if (solid and cap == 1) else 0.0
            for ring in range(poly_offsets[i], poly_offsets[i + 1]):
                r0 = ring_offsets[ring]
                count = ring_offsets[ring + 1] - r0
                for q in range(count):
                    j = r0 + ((count - q) % count if cap == 0 else q)
                    verts[v] = _point(coords, j, a, b, nrm, size[i], height)
                    v += 1
                r += 1
                out_rings[r] = v
            owner[f] = i
            f += 1
            out_faces[f] = r
    return verts[:v], out_rings[:r + 1], out_faces[:f + 1], owner[:f]


@njit(cache=True, nogil=True)
def face_shapes(verts, ring_offsets, face_offsets):
    """Each face's vector area (F, 3) (Newell's, over its outline and holes: its length is the face's
    area, its direction the outward normal), its holes (F,) int64, and whether it is concave (F,): a
    hole, or a corner of its outline turning against its normal."""
    n_faces = len(face_offsets) - 1
    vector = np.zeros((n_faces, 3))
    holes = np.zeros(n_faces, np.int64)
    concave = np.zeros(n_faces, np.bool_)
    for f in range(n_faces):
        for ring in range(face_offsets[f], face_offsets[f + 1]):
            r0, r1 = ring_offsets[ring], ring_offsets[ring + 1]
            for j in range(r0, r1):
                vector[f] += np.cross(verts[j], verts[r0 + (j - r0 + 1) % (r1 - r0)]) / 2
        holes[f] = face_offsets[f + 1] - face_offsets[f] - 1
        length = np.sqrt((vector[f] ** 2).sum())
        if holes[f] > 0 or length == 0.0:
            concave[f] = holes[f] > 0
            continue
        normal = vector[f] / length
        r0, r1 = ring_offsets[face_offsets[f]], ring_offsets[face_offsets[f] + 1]
        count = r1 - r0
        for j in range(r0, r1):
            before = verts[j] - verts[r0 + (j - r0 - 1) % count]
            after = verts[r0 + (j - r0 + 1) % count] - verts[j]
            scale = np.sqrt((before ** 2).sum() * (after ** 2).sum())
            if (np.cross(before, after) * normal).sum() < -1e-9 * scale:
                concave[f] = True
                break
    return vector, holes, concave


@njit(cache=True, nogil=True)
def planar_faces(verts, ring_offsets, face_offsets, vector, degrees):
    """Whether each face is planar within ``degrees`` (F,): at every corner of its rings, the line of the
    cross product of the edges that meet there (the corner's own normal) is within ``degrees`` of the
    face's normal (``vector``, from ``face_shapes``). A straight corner has no normal of its own and
    passes; a reflex one is taken by its line, not its sense, so that a concave face is planar."""
    bound = np.cos(np.radians(degrees))
    n_faces = len(face_offsets) - 1
    out = np.ones(n_faces, np.bool_)
    for f in range(n_faces):
        length = np.sqrt((vector[f] ** 2).sum())
        if length == 0.0:
            continue
        normal = vector[f] / length
        for ring in range(face_offsets[f], face_offsets[f + 1]):
            r0, r1 = ring_offsets[ring], ring_offsets[ring + 1]
            count = r1 - r0
            for j in range(r0, r1):
                corner = np.cross(verts[j] - verts[r0 + (j - r0 - 1) % count],
                                verts[r0 + (j - r0 + 1) % count] - verts[j])
                size = np.sqrt((corner ** 2).sum())
                if size > 1e-12 and abs((corner * normal).sum()) < bound * size * (1 - 1e-12):
                    out[f] = False
            if not out[f]:
                break
    return out


@njit(cache=True, nogil=True)
def rectangular_faces(verts, ring_offsets, face_offsets, degrees):
    """Whether each face is a rectangle (F,): one ring of 4 corners, without holes, each a right angle
    within ``degrees`` (the cosine between the edges that meet there at most the sine of ``degrees``)."""
    bound = np.sin(np.radians(degrees)) + 1e-9
    n_faces = len(face_offsets) - 1
    out = np.zeros(n_faces, np.bool_)
    for f in range(n_faces):
        r0, r1 = ring_offsets[face_offsets[f]], ring_offsets[face_offsets[f] + 1]
        if face_offsets[f + 1] - face_offsets[f] != 1 or r1 - r0 != 4:
            continue
        out[f] = True
        for j in range(r0, r1):
            before = verts[j] - verts[r0 + (j - r0 - 1) % 4]
            after = verts[r0 + (j - r0 + 1) % 4] - verts[j]
            scale = max(np.sqrt((before ** 2).sum() * (after ** 2).sum()), 1e-300)
            if abs((before * after).sum()) / scale > bound:
                out[f] = False
                break
    return out


def shared_edges(faces: Faces, n: int):
    """The edges of each of ``n`` shapes' faces, an edge two faces share counted once: their number (n,)
    float64, the summed length of the boundary edges (n,) (those of one face only), and whether every
    edge is shared by exactly two faces (n,) bool."""
    verts, ring_offsets = faces.verts, faces.ring_offsets
    ring = segment_of(ring_offsets)
    at = np.arange(len(verts))
    nxt = np.where(at + 1 < ring_offsets[1:][ring], at + 1, ring_offsets[:-1][ring])
    shape = faces.face_shape()[segment_of(faces.face_offsets)][ring]
    # an undirected edge is its shape and its ends in lexicographic order, on a grid of TOL.zero
    a, b = np.round(verts / TOL.zero), np.round(verts[nxt] / TOL.zero)
    step = b - a
    backwards = step[at, np.argmax(step != 0, axis=1)] < 0
    lo, hi = np.where(backwards[:, None], b, a), np.where(backwards[:, None], a, b)
    keep = (lo != hi).any(axis=1)
    group, first = row_groups(np.column_stack([shape, lo, hi])[keep])
    uses = np.bincount(group, minlength=len(first))
    edge_shape = shape[keep][first]
    length = np.linalg.norm(verts[nxt][keep][first] - verts[keep][first], axis=1)
    count = np.bincount(edge_shape, minlength=n).astype(np.float64)
    boundary = np.bincount(edge_shape, weights=np.where(uses == 1, length, 0.0), minlength=n)
    unshared = np.bincount(edge_shape, weights=uses != 2, minlength=n)
    return count, boundary, (unshared == 0) & (np.diff(faces.shape_offsets) > 0)


def shape_any(flags: np.ndarray, faces: Faces) -> np.ndarray:
    """Per shape (n,): whether any of its faces is flagged (``flags`` (F,) bool)."""
    return segment_reduce(np.maximum, flags, faces.shape_offsets, False)
