"""The ragged mesh store: shapes whose geometry is faces in space, not one polygon (roofs).

Like the polygon store, vertices are kept relative to the shape's scope: (x, y, z) in [0, 1]^3, the
fractions of the scope size along its axes (0 on an axis of size 0), so ``T``, ``R`` and ``S`` never
touch the store. A face is an outline and its holes; its outward normal is the one its outline winds
counter-clockwise around.

Layout (Arrow-style offsets, each starting at 0): ``coords`` (V, 3) float64, ``ring_offsets`` (R+1,)
into coords, ``face_offsets`` (F+1,) into rings (outline first), ``mesh_offsets`` (M+1,) into faces.

A shape's ``geom`` code is ``MESH_BASE + id`` for mesh ``id`` (``backend.shapes``).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from grammarc.ragged import grow, next_in_segment, ragged_take, row_groups, segment_of, segment_reduce

#: ``geom`` codes from here up are meshes; polygons of the store are 0 .. MESH_BASE - 1.
MESH_BASE = 1 << 30


def is_polygon(geom: np.ndarray) -> np.ndarray:
    """Shapes whose geometry is a polygon (or prism) of the polygon store."""
    return (geom >= 0) & (geom < MESH_BASE)


def is_mesh(geom: np.ndarray) -> np.ndarray:
    """Shapes whose geometry is a mesh of the mesh store."""
    return geom >= MESH_BASE


class MeshStore:
    """Append-only ragged storage of normalized meshes for one chunk of lots."""

    def __init__(self) -> None:
        self.coords = np.empty((0, 3))
        self.ring_offsets = np.zeros(1, dtype=np.int64)
        self.face_offsets = np.zeros(1, dtype=np.int64)
        self.mesh_offsets = np.zeros(1, dtype=np.int64)

    def __len__(self) -> int:
        return len(self.mesh_offsets) - 1

    def add(self, coords, ring_offsets, face_offsets, mesh_offsets) -> np.ndarray:
        """Append meshes given as ragged arrays (offsets from 0); returns their ids (k,) int64."""
        first = len(self)
        self.ring_offsets = np.concatenate([self.ring_offsets, ring_offsets[1:] + len(self.coords)])
        self.face_offsets = np.concatenate(
            [self.face_offsets, face_offsets[1:] + (len(self.ring_offsets) - len(ring_offsets))])
        self.mesh_offsets = np.concatenate(
            [self.mesh_offsets, mesh_offsets[1:] + (len(self.face_offsets) - len(face_offsets))])
        self.coords = np.concatenate([self.coords, coords])
        return np.arange(first, len(self), dtype=np.int64)

    def vertex_counts(self, ids: np.ndarray) -> np.ndarray:
        """The vertices (k,) int64 of meshes ``ids``, every ring's counted."""
        rings = self.face_offsets[self.mesh_offsets]
        vertices = self.ring_offsets[rings]
        ids = np.asarray(ids, np.int64)
        return vertices[ids + 1] - vertices[ids]

    def gather(self, ids: np.ndarray):
        """Meshes ``ids`` as new ragged arrays: (coords, ring_offsets, face_offsets, mesh_offsets)."""
        faces, mesh_offsets = ragged_take(self.mesh_offsets, np.asarray(ids, np.int64))
        rings, face_offsets = ragged_take(self.face_offsets, faces)
        vertices, ring_offsets = ragged_take(self.ring_offsets, rings)
        return self.coords[vertices], ring_offsets, face_offsets, mesh_offsets


def face_vertices(store: MeshStore, ids: np.ndarray, size: np.ndarray):
    """The faces of meshes ``ids`` in their scopes' units: vertices (V, 3), ring_offsets, face_offsets,
    mesh_offsets, and each vertex's mesh (V,)."""
    coords, ring_offsets, face_offsets, mesh_offsets = store.gather(ids)
    vertex_mesh = segment_of(mesh_offsets)[segment_of(face_offsets)[segment_of(ring_offsets)]]
    return coords * size[vertex_mesh], ring_offsets, face_offsets, mesh_offsets, vertex_mesh


def area_and_volume(store: MeshStore, ids: np.ndarray, size: np.ndarray):
    """Surface area (k,) and enclosed volume (k,) of meshes ``ids`` scaled by their scope sizes (k, 3):
    the length of each face's vector area, and the divergence theorem over the faces (the volume a
    roof closes with its bottom face; an overhang's open eaves make it approximate)."""
    verts, ring_offsets, face_offsets, mesh_offsets, _ = face_vertices(store, ids, size)
    ring_vector = ring_vector_areas(verts, ring_offsets)
    # a planar ring's cone to the origin: a third of its vector area dotted with any of its points
    ring_volume = np.einsum("ij,ij->i", verts[ring_offsets[:-1]], ring_vector) / 3
    # holes wind the other way: the vector areas of a face's rings add up to the face's
    face_vector = np.stack([segment_reduce(np.add, ring_vector[:, j], face_offsets, 0.0) for j in range(3)], 1)
    face_area = np.linalg.norm(face_vector, axis=1)
    area = segment_reduce(np.add, face_area, mesh_offsets, 0.0)
    volume = segment_reduce(np.add, segment_reduce(np.add, ring_volume, face_offsets, 0.0), mesh_offsets, 0.0)
    return area, volume


def ring_vector_areas(verts: np.ndarray, ring_offsets: np.ndarray) -> np.ndarray:
    """Vector area (R, 3) of each ring of points (V, 3) in space (Newell): its length is the ring's
    area, its direction the normal the ring winds counter-clockwise around."""
    a, b = verts, verts[next_in_segment(ring_offsets)]
    # np.cross's products and differences, without its copies (a tenth of a second for a city's lots)
    cross = (a[:, 1] * b[:, 2] - a[:, 2] * b[:, 1], a[:, 2] * b[:, 0] - a[:, 0] * b[:, 2],
             a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0])
    return np.stack([segment_reduce(np.add, cross[j], ring_offsets, 0.0) for j in range(3)], 1) / 2


@njit(cache=True, nogil=True)
def face_frames(verts, ring_offsets, face_offsets, eps):
    """Scopes and polygons of faces in space (``comp(f)`` of a mesh), as CityEngine places them: x along
    the face's first edge, z its normal (the outline winds counter-clockwise around it), y = z x x;
    the origin at the corner of the face's extent.

    verts (V, 3) in the parent scope's units. Returns origin (F, 3), axes (F, 3, 3) rows in the parent's
    frame, size (F, 3), the polygon (V, 2) normalized in each face's (x, y), and ok (F,): False for
    faces without area.
    """
    n_faces = len(face_offsets) - 1
    origin = np.zeros((n_faces, 3))
    axes = np.zeros((n_faces, 3, 3))
    size = np.zeros((n_faces, 3))
    uv = np.zeros((len(verts), 2))
    ok = np.ones(n_faces, np.bool_)
    for f in range(n_faces):
        r0 = face_offsets[f]
        o0, o1 = ring_offsets[r0], ring_offsets[r0 + 1]
        m = o1 - o0
        normal = np.zeros(3)
        for j in range(o0, o1):
            q = o0 + (j - o0 + 1) % m
            normal[0] += (verts[j, 1] - verts[q, 1]) * (verts[j, 2] + verts[q, 2])
            normal[1] += (verts[j, 2] - verts[q, 2]) * (verts[j, 0] + verts[q, 0])
            normal[2] += (verts[j, 0] - verts[q, 0]) * (verts[j, 1] + verts[q, 1])
        length = np.sqrt((normal ** 2).sum())
        if length <= eps * eps:
            ok[f] = False
            continue
        z = normal / length
        x = np.zeros(3)
        for j in range(o0, o1):  # the first edge that is not along the normal
            q = o0 + (j - o0 + 1) % m
            d = verts[q] - verts[j]
            d = d - (d * z).sum() * z
            dl = np.sqrt((d ** 2).sum())
            if dl > eps:
                x = d / dl
                break
        y = np.array([z[1] * x[2] - z[2] * x[1], z[2] * x[0] - z[0] * x[2], z[0] * x[1] - z[1] * x[0]])
        p0 = verts[o0]
        lo_u, lo_v, hi_u, hi_v = np.inf, np.inf, -np.inf, -np.inf
        v_end = ring_offsets[face_offsets[f + 1]]
        for j in range(o0, v_end):
            d = verts[j] - p0
            u, v = (d * x).sum(), (d * y).sum()
            uv[j, 0], uv[j, 1] = u, v
            lo_u, lo_v, hi_u, hi_v = min(lo_u, u), min(lo_v, v), max(hi_u, u), max(hi_v, v)
        su, sv = hi_u - lo_u, hi_v - lo_v
        for j in range(o0, v_end):
            uv[j, 0] = (uv[j, 0] - lo_u) / su if su > 0 else 0.0
            uv[j, 1] = (uv[j, 1] - lo_v) / sv if sv > 0 else 0.0
        origin[f] = p0 + lo_u * x + lo_v * y
        axes[f, 0], axes[f, 1], axes[f, 2] = x, y, z
        size[f, 0], size[f, 1] = su, sv
    return origin, axes, size, uv, ok


def mesh_edges(verts, ring_offsets, face_offsets, mesh_offsets, eps: float):
    """The distinct edges of meshes (an edge two faces share counts once), as the paper's component
    split places them: x along the edge, y the mean of the normals of the faces that meet there, z = x
    cross y, size (length, 0, 0).

    verts (V, 3) in the scopes' units, with y the roof's up. Returns mesh (E,), origin (E, 3), axes
    (E, 3, 3), size (E, 3), kind (E,): 0 for bottom edges (horizontal, at or below the base: the
    footprint and the eaves), 1 for side edges (sloped: hips and valleys), 2 for top edges (horizontal
    above the base: ridges), roof (E,) int8, the edge's place on a roof (``roof_edge_kinds``), and
    border (E,) bool, whether one face only has the edge (``comp(e){ border }``); each mesh's edges in
    the order they first appear in its faces.
    """
    face, mesh, nxt, face_normal = _ring_walk(verts, ring_offsets, face_offsets, mesh_offsets)
    p, q = verts, verts[nxt]
    key, keep = _undirected_edges(verts, nxt, mesh, eps)
    inverse, first = row_groups(key[keep])
    order = np.argsort(first, kind="stable")  # first appearance, which keeps meshes in order
    rank = np.empty(len(order), dtype=np.int64)
    rank[order] = np.arange(len(order))
    kept = np.flatnonzero(keep)
    edge = kept[first[order]]
    start, end = p[edge], q[edge]
    x = end - start
    length = np.linalg.norm(x, axis=1)
    x /= length[:, None]
    normal_sum = np.zeros((len(order), 3))
    np.add.at(normal_sum, rank[inverse], face_normal[face[kept]])
    y = normal_sum - np.einsum("ij,ij->i", normal_sum, x)[:, None] * x
    norm = np.linalg.norm(y, axis=1)
    # no face normal across the edge (a fold back on itself): any axis across it
    fallback = np.where(np.abs(x[:, 1:2]) < 0.9, [[0.0, 1.0, 0.0]], [[1.0, 0.0, 0.0]])
    fallback -= np.einsum("ij,ij->i", fallback, x)[:, None] * x
    y = np.where((norm > 1e-9)[:, None], y, fallback)
    y /= np.linalg.norm(y, axis=1, keepdims=True)
    axes = np.stack([x, y, np.cross(x, y)], axis=1)
    size = np.zeros((len(order), 3))
    size[:, 0] = length
    horizontal = np.abs(x[:, 1]) <= 1e-9
    low = np.maximum(start[:, 1], end[:, 1]) <= eps
    kind = np.where(~horizontal, 1, np.where(low, 0, 2))
    roof = roof_edge_kinds(verts, ring_offsets, face_offsets, mesh_offsets, face[kept], rank[inverse], face_normal,
                           mesh[edge], start, end, eps)
    return mesh[edge], start, axes, size, kind, roof, np.bincount(rank[inverse], minlength=len(order)) == 1


#: The sine of the slope below which a face counts as flat, or above which as vertical, for a roof's edges.
_SLOPED = 1e-6


def roof_edge_kinds(verts, ring_offsets, face_offsets, mesh_offsets, edge_face, edge_of, face_normal, edge_mesh,
                    start, end, eps: float) -> np.ndarray:
    """Each distinct edge's place on a roof, as ``comp(e)``'s selectors name it: 0 eave, 1 ridge, 2 hip,
    3 valley (``ir.ROOF_EDGE_SELECTORS``), -1 none of them (E,) int8.

    The reference says only that these selectors are meant for roofs; grammarc reads them off the faces
    that meet at the edge, as a roofer names them. A mesh's first face is its base (a roof's bottom),
    whose normal points down: up is against it, whatever the scope's axes (a roof on a lot has y up, one
    on a face from ``comp(f)`` the face's z). A sloped face is one neither flat nor vertical, facing up.
    An eave is a horizontal edge at or below the base along a sloped face; a ridge a horizontal edge
    above the base where two sloped faces meet convexly; a hip a sloped edge where two sloped faces meet
    convexly; a valley any edge where two sloped faces meet concavely. The sloped edges along a gable's
    vertical face and those of a flat cap are none of them.

    verts (V, 3) in the scopes' units; edge_face (k,) and edge_of (k,): the face of each ring edge and its
    distinct edge (E of them); face_normal (F, 3) unit normals; edge_mesh (E,) each edge's mesh; start,
    end (E, 3) its points.
    """
    n_edges = len(start)
    vertex_start = ring_offsets[face_offsets]
    count = np.maximum(np.diff(vertex_start), 1)
    centroid = np.stack([segment_reduce(np.add, verts[:, j], vertex_start, 0.0) for j in range(3)], 1)
    centroid /= count[:, None]
    base = mesh_offsets[:-1]
    up = -face_normal[np.minimum(base, len(face_normal) - 1)]  # per mesh
    floor = np.einsum("ij,ij->i", verts[np.minimum(vertex_start[base], len(verts) - 1)], up)
    edge_up, edge_floor = up[edge_mesh], floor[edge_mesh]
    direction = end - start
    direction /= np.maximum(np.linalg.norm(direction, axis=1, keepdims=True), 1e-300)
    horizontal = np.abs(np.einsum("ij,ij->i", direction, edge_up)) <= _SLOPED
    low = np.maximum(np.einsum("ij,ij->i", start, edge_up), np.einsum("ij,ij->i", end, edge_up)) <= edge_floor + eps
    rise = np.einsum("ij,ij->i", face_normal, up[segment_of(mesh_offsets)])
    sloped = (rise > _SLOPED) & (rise < 1 - _SLOPED)
    faces = np.bincount(edge_of, minlength=n_edges)
    first = np.full(n_edges, len(face_normal), dtype=np.int64)
    last = np.full(n_edges, -1, dtype=np.int64)
    np.minimum.at(first, edge_of, edge_face)
    np.maximum.at(last, edge_of, edge_face)
    along_slope = np.zeros(n_edges, dtype=bool)
    np.logical_or.at(along_slope, edge_of, sloped[edge_face])
    two = faces == 2
    a, b = np.where(two, first, 0), np.where(two, last, 0)
    between_slopes = two & sloped[a] & sloped[b]
    # convex: each face's centroid behind the other's plane (the edge's start lies on both planes)
    behind = np.einsum("ij,ij->i", face_normal[a], centroid[b] - start)
    scale = mesh_magnitudes(verts, ring_offsets, face_offsets, mesh_offsets)[edge_mesh]
    convex, concave = behind < -eps * scale, behind > eps * scale
    roof = np.full(n_edges, -1, dtype=np.int8)
    roof[horizontal & low & along_slope] = 0
    roof[between_slopes & convex & horizontal & ~low] = 1
    roof[between_slopes & convex & ~horizontal] = 2
    roof[between_slopes & concave] = 3
    return roof


def border_ring_edges(verts, ring_offsets, face_offsets, mesh_offsets, eps: float) -> np.ndarray:
    """Whether the ring edge from each ring vertex (V,) is on its mesh's border: no other face of the
    mesh has it (the reference's border edge, which meets one face only). A closed mesh (a roof with
    its bottom, an envelope, a split's slab) has none."""
    _, mesh, nxt, _ = _ring_walk(verts, ring_offsets, face_offsets, mesh_offsets)
    key, keep = _undirected_edges(verts, nxt, mesh, eps)
    inverse, _ = row_groups(key[keep])
    border = np.zeros(len(verts), dtype=bool)
    border[keep] = np.bincount(inverse)[inverse] == 1
    return border


def _undirected_edges(verts, nxt, mesh, eps: float):
    """Each ring edge (from each vertex to ``nxt``) as an undirected key (V, 7): its mesh and its
    endpoints in lexicographic order, on a grid of eps; and whether it has a length (V,)."""
    a, b = np.round(verts / eps), np.round(verts[nxt] / eps)
    step = b - a
    swap = step[np.arange(len(step)), np.argmax(step != 0, axis=1)] < 0
    lo, hi = np.where(swap[:, None], b, a), np.where(swap[:, None], a, b)
    return np.column_stack([mesh, lo, hi]), (lo != hi).any(axis=1)


def mesh_corners(verts, ring_offsets, face_offsets, mesh_offsets, eps: float):
    """The distinct vertices of meshes (a vertex its faces share counts once), as ``comp(v)`` places
    them: y the mean of the normals of the faces that meet there, x along the first edge that leaves
    it (across y), size 0. Returns mesh (K,), origin (K, 3), axes (K, 3, 3) and border (K,) bool, whether
    a border edge (``border_ring_edges``) touches it, each mesh's vertices in the order they first
    appear in its faces."""
    face, mesh, nxt, face_normal = _ring_walk(verts, ring_offsets, face_offsets, mesh_offsets)
    inverse, first = row_groups(np.column_stack([mesh, np.round(verts / eps)]).astype(np.int64))
    order = np.argsort(first, kind="stable")
    rank = np.empty(len(order), dtype=np.int64)
    rank[order] = np.arange(len(order))
    corner = first[order]
    normal_sum = np.zeros((len(order), 3))
    np.add.at(normal_sum, rank[inverse], face_normal[face])
    y = normal_sum / np.maximum(np.linalg.norm(normal_sum, axis=1, keepdims=True), 1e-300)
    x = verts[nxt[corner]] - verts[corner]
    x -= np.einsum("ij,ij->i", x, y)[:, None] * y
    norm = np.linalg.norm(x, axis=1)
    fallback = np.where(np.abs(y[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 0.0, 1.0]])
    fallback -= np.einsum("ij,ij->i", fallback, y)[:, None] * y
    x = np.where((norm > 1e-9)[:, None], x, fallback)
    x /= np.linalg.norm(x, axis=1, keepdims=True)
    border = border_ring_edges(verts, ring_offsets, face_offsets, mesh_offsets, eps)
    touches = np.zeros(len(order), dtype=bool)
    np.logical_or.at(touches, rank[inverse], border)  # the edge that leaves the vertex
    np.logical_or.at(touches, rank[inverse[nxt]], border)  # and the one that arrives
    return mesh[corner], verts[corner], np.stack([x, y, np.cross(x, y)], axis=1), touches


def _ring_walk(verts, ring_offsets, face_offsets, mesh_offsets):
    """Per ring vertex: its face and mesh, the next vertex of its ring; and each face's unit normal
    (Newell's, from all its rings)."""
    ring = segment_of(ring_offsets)
    face = segment_of(face_offsets)[ring]
    mesh = segment_of(mesh_offsets)[face]
    nxt = next_in_segment(ring_offsets)
    cross = np.cross(verts, verts[nxt])
    face_normal = np.stack([segment_reduce(np.add, cross[:, j], ring_offsets[face_offsets], 0.0)
                            for j in range(3)], 1)
    face_normal /= np.maximum(np.linalg.norm(face_normal, axis=1, keepdims=True), 1e-300)
    return face, mesh, nxt, face_normal


def is_convex(verts, ring_offsets, face_offsets, mesh_offsets) -> np.ndarray:
    """Whether each mesh (gathered, in its scope's units: ``face_vertices``) is convex: all its vertices
    lie behind the plane of every one of its faces."""
    return _convex(verts, ring_offsets, face_offsets, mesh_offsets,
                   mesh_magnitudes(verts, ring_offsets, face_offsets, mesh_offsets))


def mesh_magnitudes(verts, ring_offsets, face_offsets, mesh_offsets) -> np.ndarray:
    """(M,) the largest coordinate (absolute) of each mesh, 1 at least: the scale of its tolerances.

    Per mesh, never over the batch: a batch holds the meshes of several lots, and a large or far one
    must not coarsen the tolerances of the others (their records would depend on the chunking)."""
    vertex_mesh = segment_of(mesh_offsets)[segment_of(face_offsets)[segment_of(ring_offsets)]]
    out = np.ones(len(mesh_offsets) - 1)
    np.maximum.at(out, vertex_mesh, np.abs(verts).max(axis=1, initial=0.0))
    return out


@njit(cache=True, nogil=True)
def _convex(verts, ring_offsets, face_offsets, mesh_offsets, scale):
    out = np.ones(len(mesh_offsets) - 1, np.bool_)
    for g in range(len(mesh_offsets) - 1):
        v0, v1 = ring_offsets[face_offsets[mesh_offsets[g]]], ring_offsets[face_offsets[mesh_offsets[g + 1]]]
        for f in range(mesh_offsets[g], mesh_offsets[g + 1]):
            o0, o1 = ring_offsets[face_offsets[f]], ring_offsets[face_offsets[f] + 1]
            normal = np.zeros(3)
            for j in range(o0, o1):
                q = o0 + (j - o0 + 1) % (o1 - o0)
                normal[0] += (verts[j, 1] - verts[q, 1]) * (verts[j, 2] + verts[q, 2])
                normal[1] += (verts[j, 2] - verts[q, 2]) * (verts[j, 0] + verts[q, 0])
                normal[2] += (verts[j, 0] - verts[q, 0]) * (verts[j, 1] + verts[q, 1])
            length = np.sqrt((normal ** 2).sum())
            if length == 0.0:
                continue
            normal /= length
            for v in range(v0, v1):
                if ((verts[v] - verts[o0]) * normal).sum() > 1e-9 * scale[g]:
                    out[g] = False
                    break
            if not out[g]:
                break
    return out


@njit(cache=True, nogil=True)
def clip_slabs(verts, ring_offsets, face_offsets, mesh_offsets, child_mesh, axis, lo, hi, convex, eps):
    """Meshes cut to slabs ``lo <= coordinate[axis] <= hi``, convex ones closed by their cut faces.

    verts (V, 3) in the parents' scope units; child_mesh (m,) the mesh each slab cuts. Every face ring
    is clipped to the slab (Sutherland-Hodgman, both planes; a concave face cut apart stays one ring,
    joined along the plane). Where ``convex[c]`` the points where faces cross a
    plane make that plane's cap, their convex hull, facing out of the slab; other slabs are left open
    for ``sections`` to close.
    Returns verts (V', 3), ring_offsets, face_offsets, mesh_offsets (m+1,): an empty mesh for a slab
    the mesh does not reach.
    """
    m = len(child_mesh)
    out_v = np.empty((max(16, 4 * len(verts)), 3))
    out_r = np.zeros(max(16, 4 * len(ring_offsets)), np.int64)
    out_f = np.zeros(max(16, 4 * len(face_offsets)), np.int64)
    out_m = np.zeros(m + 1, np.int64)
    n_v = 0
    n_r = 0
    n_f = 0
    a, b = (axis + 1) % 3, (axis + 2) % 3
    for c in range(m):
        g = child_mesh[c]
        caps = np.empty((2, 4 * (ring_offsets[face_offsets[mesh_offsets[g + 1]]]
                                 - ring_offsets[face_offsets[mesh_offsets[g]]]) + 8, 3))
        n_cap = np.zeros(2, np.int64)
        closed = np.zeros(2, np.bool_)  # a face of the mesh already lies on the plane
        for f in range(mesh_offsets[g], mesh_offsets[g + 1]):
            face_start = n_r
            for r in range(face_offsets[f], face_offsets[f + 1]):
                ring = verts[ring_offsets[r]:ring_offsets[r + 1]].copy()
                for side in range(2):  # keep >= lo, then <= hi
                    plane = lo[c] if side == 0 else hi[c]
                    sign = 1.0 if side == 0 else -1.0
                    count = len(ring)
                    clipped = np.empty((2 * count + 2, 3))
                    k = 0
                    for j in range(count):
                        s_ = ring[(j - 1) % count]
                        e_ = ring[j]
                        s_in = sign * (s_[axis] - plane) >= -eps
                        e_in = sign * (e_[axis] - plane) >= -eps
                        if e_in != s_in:
                            t = (plane - s_[axis]) / (e_[axis] - s_[axis])
                            p = s_ + t * (e_ - s_)
                            p[axis] = plane
                            clipped[k] = p
                            k += 1
                            caps[side, n_cap[side]] = p
                            n_cap[side] += 1
                        if e_in:
                            clipped[k] = e_
                            k += 1
                            if abs(e_[axis] - plane) <= eps:
                                caps[side, n_cap[side]] = e_
                                n_cap[side] += 1
                    ring = clipped[:k]
                    if k < 3:
                        break
                if len(ring) < 3:
                    continue
                for side in range(2):
                    plane = lo[c] if side == 0 else hi[c]
                    # a face on the plane closes it; a ring cut down to an edge on it does not
                    if np.abs(ring[:, axis] - plane).max() <= eps and _ring_width(ring) > eps:
                        closed[side] = True
                out_v = grow(out_v, n_v + len(ring))
                out_r = grow(out_r, n_r + 2)
                out_v[n_v:n_v + len(ring)] = ring
                n_v += len(ring)
                n_r += 1
                out_r[n_r] = n_v
            if n_r > face_start:
                out_f = grow(out_f, n_f + 4)
                n_f += 1
                out_f[n_f] = n_r
        any_face = n_f > out_m[c]
        for side in range(2):
            if not convex[c] or not any_face or n_cap[side] < 3 or closed[side]:
                continue
            hull = _hull(caps[side, :n_cap[side]], a, b, eps)
            if len(hull) < 3:
                continue
            if side == 0:  # the lo cap faces -axis: reverse the hull's (counter-clockwise in (a, b)) turn
                hull = hull[::-1].copy()
            out_v = grow(out_v, n_v + len(hull))
            out_r = grow(out_r, n_r + 2)
            out_f = grow(out_f, n_f + 2)
            out_v[n_v:n_v + len(hull)] = hull
            n_v += len(hull)
            n_r += 1
            out_r[n_r] = n_v
            n_f += 1
            out_f[n_f] = n_r
        out_m[c + 1] = n_f
    return out_v[:n_v], out_r[: n_r + 1], out_f[: n_f + 1], out_m


@njit(cache=True, nogil=True)
def _ring_width(ring):
    """A planar ring's (k, 3) area over its half perimeter: about its width, 0 for a ring that is an edge
    run there and back."""
    nx = ny = nz = 0.0
    perimeter = 0.0
    k = len(ring)
    for j in range(k):
        p, q = ring[j], ring[(j + 1) % k]
        nx += (p[1] - q[1]) * (p[2] + q[2])
        ny += (p[2] - q[2]) * (p[0] + q[0])
        nz += (p[0] - q[0]) * (p[1] + q[1])
        perimeter += np.sqrt(((q - p) ** 2).sum())
    return np.sqrt(nx * nx + ny * ny + nz * nz) / max(perimeter, 1e-300)


@njit(cache=True, nogil=True)
def _hull(points, a, b, eps):
    """Convex hull of points on a plane, by their coordinates a and b, counter-clockwise in (a, b)
    (Andrew's monotone chain); repeated points, and points within eps of each other, count once."""
    n = len(points)
    order = np.argsort(points[:, a].copy(), kind="mergesort")
    for i in range(1, n):  # ties in a: by b (insertion sort; the points are few)
        j = i
        while j > 0 and abs(points[order[j], a] - points[order[j - 1], a]) <= eps and \
                points[order[j], b] < points[order[j - 1], b]:
            order[j], order[j - 1] = order[j - 1], order[j]
            j -= 1
    # points within eps of the one before (a crossing and a vertex on the plane, computed apart) count once
    unique = np.empty(n, np.int64)
    m = 0
    for idx in range(n):
        i = order[idx]
        if m and abs(points[i, a] - points[unique[m - 1], a]) <= eps \
                and abs(points[i, b] - points[unique[m - 1], b]) <= eps:
            continue
        unique[m] = i
        m += 1
    order, n = unique[:m], m
    hull = np.empty(2 * n + 1, np.int64)
    k = 0
    for idx in range(n):
        i = order[idx]
        while k >= 2 and _turn(points, hull[k - 2], hull[k - 1], i, a, b) <= eps * eps:
            k -= 1
        hull[k] = i
        k += 1
    lower = k + 1
    for idx in range(n - 2, -1, -1):
        i = order[idx]
        while k >= lower and _turn(points, hull[k - 2], hull[k - 1], i, a, b) <= eps * eps:
            k -= 1
        hull[k] = i
        k += 1
    k = max(k - 1, 0)
    out = np.empty((k, 3))
    for i in range(k):
        out[i] = points[hull[i]]
    return out


@njit(cache=True, nogil=True)
def _turn(points, p, q, r, a, b):
    return ((points[q, a] - points[p, a]) * (points[r, b] - points[p, b])
            - (points[q, b] - points[p, b]) * (points[r, a] - points[p, a]))
