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

from grammarc.ragged import ragged_take, segment_of, segment_reduce

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
    ring = segment_of(ring_offsets)
    at = np.arange(len(verts))
    nxt = np.where(at + 1 < ring_offsets[1:][ring], at + 1, ring_offsets[:-1][ring])
    cross = np.cross(verts, verts[nxt])
    ring_vector = np.stack([segment_reduce(np.add, cross[:, j], ring_offsets, 0.0) for j in range(3)], 1) / 2
    # a planar ring's cone to the origin: a third of its vector area dotted with any of its points
    ring_volume = np.einsum("ij,ij->i", verts[ring_offsets[:-1]], ring_vector) / 3
    # holes wind the other way: the vector areas of a face's rings add up to the face's
    face_vector = np.stack([segment_reduce(np.add, ring_vector[:, j], face_offsets, 0.0) for j in range(3)], 1)
    face_area = np.linalg.norm(face_vector, axis=1)
    area = segment_reduce(np.add, face_area, mesh_offsets, 0.0)
    volume = segment_reduce(np.add, segment_reduce(np.add, ring_volume, face_offsets, 0.0), mesh_offsets, 0.0)
    return area, volume


@njit(cache=True)
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
    (E, 3, 3), size (E, 3) and kind (E,): 0 for bottom edges (horizontal, at or below the base: the
    footprint and the eaves), 1 for side edges (sloped: hips and valleys), 2 for top edges (horizontal
    above the base: ridges), each mesh's edges in the order they first appear in its faces.
    """
    ring = segment_of(ring_offsets)
    face = segment_of(face_offsets)[ring]
    mesh = segment_of(mesh_offsets)[face]
    at = np.arange(len(verts))
    nxt = np.where(at + 1 < ring_offsets[1:][ring], at + 1, ring_offsets[:-1][ring])
    p, q = verts, verts[nxt]
    # each face's unit normal (Newell), for the edges' y axes
    cross = np.cross(p, q)
    face_normal = np.stack([segment_reduce(np.add, cross[:, j], ring_offsets[face_offsets], 0.0)
                            for j in range(3)], 1)
    face_normal /= np.maximum(np.linalg.norm(face_normal, axis=1, keepdims=True), 1e-300)
    # an undirected edge is its mesh and its endpoints in lexicographic order, on a grid of eps
    a, b = np.round(p / eps), np.round(q / eps)
    step = b - a
    swap = step[np.arange(len(step)), np.argmax(step != 0, axis=1)] < 0
    lo, hi = np.where(swap[:, None], b, a), np.where(swap[:, None], a, b)
    keep = (lo != hi).any(axis=1)
    key = np.column_stack([mesh, lo, hi])[keep]
    _, first, inverse = np.unique(key, axis=0, return_index=True, return_inverse=True)
    inverse = inverse.reshape(-1)
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
    return mesh[edge], start, axes, size, kind
