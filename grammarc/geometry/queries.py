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
from grammarc.ragged import offsets_from_counts, ragged_take, segment_of, segment_reduce


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


def shape_faces(size: np.ndarray, geom: np.ndarray, store: PolygonStore, meshes: MeshStore,
                corner: np.ndarray | None = None) -> Faces:
    """The faces of shapes with scope sizes (n, 3) and geometry codes (n,): boxes, faces and prisms of the
    polygon store, meshes of the mesh store; an inserted asset is its box, as ``geometry.area`` has it. A
    box's ring starts at its ``corner`` (n,) (``rect_rings``; None: corner 0)."""
    n = len(geom)
    poly = np.flatnonzero(is_polygon(geom))
    mesh = np.flatnonzero(is_mesh(geom))
    box = np.flatnonzero(~is_polygon(geom) & ~is_mesh(geom) & ((size <= TOL.zero).sum(axis=1) <= 1))
    pieces = []
    if len(poly) or len(box):
        coords, ring_offsets, poly_offsets = store.gather(geom[poly])
        plane = np.concatenate([store.plane[geom[poly]], rect_plane(size[box], TOL.zero)]).astype(np.int8)
        # the scope boxes' implicit rectangles after the polygons, one ring each
        box_corner = None if corner is None else corner[box]
        coords = np.concatenate([coords, rect_rings(plane[len(poly):], box_corner)])
        ring_offsets = np.concatenate([ring_offsets, ring_offsets[-1] + 4 * np.arange(1, len(box) + 1)])
        poly_offsets = np.concatenate([poly_offsets, poly_offsets[-1] + np.arange(1, len(box) + 1)])
        rows = np.concatenate([poly, box])
        if len(poly) and len(box):  # the polygons in the shapes' order, so that their faces come in it
            order = np.argsort(rows, kind="stable")
            coords, ring_offsets, poly_offsets = _take(order, coords, ring_offsets, poly_offsets)
            plane, rows = plane[order], rows[order]
        verts, rings, faces, owner = _prism_faces(coords, ring_offsets, poly_offsets, plane, size[rows], TOL.zero)
        pieces.append((verts, rings, faces, rows[owner]))
    if len(mesh):
        verts, rings, faces, mesh_offsets, _ = face_vertices(meshes, geom[mesh] - MESH_BASE, size[mesh])
        pieces.append((verts, rings, faces, mesh[segment_of(mesh_offsets)]))
    if not pieces:
        return Faces(np.empty((0, 3)), np.zeros(1, np.int64), np.zeros(1, np.int64), np.zeros(n + 1, np.int64))
    verts, ring_offsets, face_offsets, face_shape = pieces[0] if len(pieces) == 1 else _concatenate(pieces)
    if (np.diff(face_shape) < 0).any():  # meshes among the others: faces grouped by shape, in their order
        order = np.argsort(face_shape, kind="stable")
        verts, ring_offsets, face_offsets = _take(order, verts, ring_offsets, face_offsets)
        face_shape = face_shape[order]
    return Faces(verts, ring_offsets, face_offsets, offsets_from_counts(np.bincount(face_shape, minlength=n)))


def _take(order, points, ring_offsets, offsets):
    """Polygons (or faces) ``order`` of ragged rings: their points, ring_offsets and offsets anew."""
    rings, offsets = ragged_take(offsets, order)
    vertices, ring_offsets = ragged_take(ring_offsets, rings)
    return points[vertices], ring_offsets, offsets


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
def _put(verts, v, coords, j, a, b, nrm, su, sv, height):
    """Write ring vertex ``j`` scaled by (su, sv) and lifted by ``height`` as point ``v``; returns v + 1."""
    verts[v, a] = coords[j, 0] * su
    verts[v, b] = coords[j, 1] * sv
    verts[v, nrm] = height
    return v + 1


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
        su, sv, h = size[i, a], size[i, b], size[i, nrm]
        solid = h > tol
        # a prism's bottom (its rings reversed), its sides, its top; a flat polygon's face
        for part in range(0 if solid else 2, 3):
            if part == 1:
                for ring in range(poly_offsets[i], poly_offsets[i + 1]):
                    r0 = ring_offsets[ring]
                    count = ring_offsets[ring + 1] - r0
                    for j in range(r0, r0 + count):
                        q = r0 + (j - r0 + 1) % count
                        du = (coords[q, 0] - coords[j, 0]) * su
                        dv = (coords[q, 1] - coords[j, 1]) * sv
                        if np.sqrt(du * du + dv * dv) <= tol:
                            continue
                        v = _put(verts, v, coords, j, a, b, nrm, su, sv, 0.0)
                        v = _put(verts, v, coords, q, a, b, nrm, su, sv, 0.0)
                        v = _put(verts, v, coords, q, a, b, nrm, su, sv, h)
                        v = _put(verts, v, coords, j, a, b, nrm, su, sv, h)
                        r += 1
                        out_rings[r] = v
                        owner[f] = i
                        f += 1
                        out_faces[f] = r
                continue
            height = h if (solid and part == 2) else 0.0
            for ring in range(poly_offsets[i], poly_offsets[i + 1]):
                r0 = ring_offsets[ring]
                count = ring_offsets[ring + 1] - r0
                for q in range(count):
                    j = r0 + ((count - q) % count if part == 0 else q)
                    v = _put(verts, v, coords, j, a, b, nrm, su, sv, height)
                r += 1
                out_rings[r] = v
            owner[f] = i
            f += 1
            out_faces[f] = r
    return verts[:v], out_rings[:r + 1], out_faces[:f + 1], owner[:f]


@njit(cache=True, nogil=True)
def _corner(verts, p, j, q):
    """The edges p -> j and j -> q that meet at corner j: their cross product (three numbers), their dot
    product and the product of their lengths."""
    ax, ay, az = verts[j, 0] - verts[p, 0], verts[j, 1] - verts[p, 1], verts[j, 2] - verts[p, 2]
    bx, by, bz = verts[q, 0] - verts[j, 0], verts[q, 1] - verts[j, 1], verts[q, 2] - verts[j, 2]
    scale = np.sqrt((ax * ax + ay * ay + az * az) * (bx * bx + by * by + bz * bz))
    return ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx, ax * bx + ay * by + az * bz, scale


@njit(cache=True, nogil=True)
def _around(ring_offsets, ring, j):
    """The vertices before and after vertex ``j`` of ``ring``."""
    r0, count = ring_offsets[ring], ring_offsets[ring + 1] - ring_offsets[ring]
    return r0 + (j - r0 - 1) % count, r0 + (j - r0 + 1) % count


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
        nx = ny = nz = 0.0
        for ring in range(face_offsets[f], face_offsets[f + 1]):
            for j in range(ring_offsets[ring], ring_offsets[ring + 1]):
                q = _around(ring_offsets, ring, j)[1]
                nx += (verts[j, 1] - verts[q, 1]) * (verts[j, 2] + verts[q, 2])
                ny += (verts[j, 2] - verts[q, 2]) * (verts[j, 0] + verts[q, 0])
                nz += (verts[j, 0] - verts[q, 0]) * (verts[j, 1] + verts[q, 1])
        vector[f, 0], vector[f, 1], vector[f, 2] = nx / 2, ny / 2, nz / 2
        holes[f] = face_offsets[f + 1] - face_offsets[f] - 1
        length = np.sqrt(nx * nx + ny * ny + nz * nz)
        if holes[f] > 0 or length == 0.0:
            concave[f] = holes[f] > 0
            continue
        outline = face_offsets[f]
        for j in range(ring_offsets[outline], ring_offsets[outline + 1]):
            p, q = _around(ring_offsets, outline, j)
            cx, cy, cz, _, scale = _corner(verts, p, j, q)
            if (cx * nx + cy * ny + cz * nz) / length < -1e-9 * scale:
                concave[f] = True
                break
    return vector, holes, concave


@njit(cache=True, nogil=True)
def planar_faces(verts, ring_offsets, face_offsets, vector, degrees):
    """Whether each face is planar within ``degrees`` (F,): at every corner of its rings, the line of the
    cross product of the edges that meet there (the corner's own normal) is within ``degrees`` of the
    face's normal (``vector``, from ``face_shapes``). A straight corner has no normal of its own and
    passes; a reflex one is taken by its line, not its sense, so that a concave face is planar."""
    bound = np.cos(np.radians(degrees)) * (1 - 1e-12)
    n_faces = len(face_offsets) - 1
    out = np.ones(n_faces, np.bool_)
    for f in range(n_faces):
        length = np.sqrt((vector[f] ** 2).sum())
        if length == 0.0:
            continue
        for ring in range(face_offsets[f], face_offsets[f + 1]):
            for j in range(ring_offsets[ring], ring_offsets[ring + 1]):
                p, q = _around(ring_offsets, ring, j)
                cx, cy, cz, _, _ = _corner(verts, p, j, q)
                size = np.sqrt(cx * cx + cy * cy + cz * cz)
                along = abs(cx * vector[f, 0] + cy * vector[f, 1] + cz * vector[f, 2]) / length
                if size > 1e-12 and along < bound * size:
                    out[f] = False
                    break
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
        outline = face_offsets[f]
        if face_offsets[f + 1] - outline != 1 or ring_offsets[outline + 1] - ring_offsets[outline] != 4:
            continue
        out[f] = True
        for j in range(ring_offsets[outline], ring_offsets[outline + 1]):
            p, q = _around(ring_offsets, outline, j)
            _, _, _, dot, scale = _corner(verts, p, j, q)
            if abs(dot) / max(scale, 1e-300) > bound:
                out[f] = False
                break
    return out


def shared_edges(faces: Faces, n: int, eps: float = TOL.zero):
    """The edges of each of ``n`` shapes' faces, an edge two faces share counted once (its ends the same
    on a grid of ``eps``): their number (n,) float64, the summed length of the boundary edges (n,) (those
    of one face only), and whether the shape has a face and every edge is shared by exactly two faces
    (n,) bool."""
    quantized = np.round(faces.verts / eps).astype(np.int64)
    return _shared_edges(faces.verts, quantized, faces.ring_offsets, faces.face_offsets, faces.shape_offsets)


@njit(cache=True, nogil=True)
def _shared_edges(verts, quantized, ring_offsets, face_offsets, shape_offsets):
    """``shared_edges`` shape by shape: each ring edge is matched with the earlier edges of its shape
    (a shape's edges are few: tens for a prism, hundreds for a roof)."""
    n = len(shape_offsets) - 1
    count = np.zeros(n)
    boundary = np.zeros(n)
    closed = np.zeros(n, np.bool_)
    for s in range(n):
        r_first, r_last = face_offsets[shape_offsets[s]], face_offsets[shape_offsets[s + 1]]
        v0, v1 = ring_offsets[r_first], ring_offsets[r_last]
        keys = np.empty((v1 - v0, 6), np.int64)  # each edge's ends, the lower one first
        ends = np.empty((v1 - v0, 2), np.int64)
        m = 0
        for ring in range(r_first, r_last):
            for j in range(ring_offsets[ring], ring_offsets[ring + 1]):
                q = _around(ring_offsets, ring, j)[1]
                axis = 0
                while axis < 3 and quantized[j, axis] == quantized[q, axis]:
                    axis += 1
                if axis == 3:  # no length
                    continue
                lo, hi = (j, q) if quantized[j, axis] < quantized[q, axis] else (q, j)
                keys[m, :3], keys[m, 3:] = quantized[lo], quantized[hi]
                ends[m, 0], ends[m, 1] = j, q
                m += 1
        uses = np.zeros(m, np.int64)
        for e in range(m):
            first = e
            for other in range(e):
                if uses[other] > 0:
                    c = 0
                    while c < 6 and keys[other, c] == keys[e, c]:
                        c += 1
                    if c == 6:
                        first = other
                        break
            uses[first] += 1
        closed[s] = shape_offsets[s + 1] > shape_offsets[s]
        for e in range(m):
            if uses[e] == 0:
                continue
            count[s] += 1
            closed[s] &= uses[e] == 2
            if uses[e] == 1:
                boundary[s] += np.sqrt(((verts[ends[e, 1]] - verts[ends[e, 0]]) ** 2).sum())
    return count, boundary, closed


def shape_any(flags: np.ndarray, faces: Faces) -> np.ndarray:
    """Per shape (n,): whether any of its faces is flagged (``flags`` (F,) bool)."""
    return segment_reduce(np.maximum, flags, faces.shape_offsets, False)
