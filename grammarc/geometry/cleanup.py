"""CityEngine's ``cleanupGeometry``: merged vertices, no collinear vertices, no degenerate, duplicate or
small faces, coplanar neighbours joined; all meshes of a batch at once.

The operation tidies a shape's mesh without meaning to change how it looks. Every component merges
vertices; then ``vertices`` removes collinear vertices, ``edges`` removes the edges that coplanar faces
share (the faces become one), ``faces`` removes duplicate faces and faces of small area, ``all`` does
all of it (``STEPS``). The tolerance, 0 to 1, scales CityEngine's limits linearly: at 1 vertices up to
1 m apart merge, edges whose lines meet within 10 degrees are collinear, faces whose normals are within
10 degrees are coplanar and faces up to 1 m^2 go; at 0 only exact matches (here: within ``TOL.zero``,
``TOL.area_floor`` and float noise).

Meshes are ragged arrays in metres (``geometry.meshes``): ``coords`` (V, 3) float64, ``ring_offsets``
(R+1,), ``face_offsets`` (F+1,) into rings (outline first), ``mesh_offsets`` (M+1,) into faces.

- **Merging.** A ring holds its own copy of each vertex, so merging gives every vertex of a mesh the
  position of its cluster's representative: taken in order of x, a vertex joins the nearest (in x)
  representative within the distance, else represents itself, so no cluster is wider than the
  distance and a merged vertex moves at most that far. A vertex that repeats the one before it in its
  ring then goes, and a ring left with fewer than 3 vertices goes (a face with its outline).
- **Collinear vertices.** A vertex goes where the lines of its two edges meet within the angle (a spike
  that turns straight back counts: both edges lie on one line). Each vertex is measured from the last
  one kept, so a fine arc loses every other vertex, not all of them.
- **Coplanar faces** that share an edge (the same two vertices, run in opposite directions) join: the
  group's rings less the edges its faces share, chained into rings, make its new face. A group whose
  boundary is not one outline with holes keeps its faces. Edges are matched after every vertex of the
  mesh that lies on an edge is put into it: grammarc's convexify cuts leave T-junctions (a cut's end on
  a neighbour's longer edge) where CityEngine's meshes share the vertex.
- **Duplicate faces** have the same rings in the same cyclic order, either way round (a face and its
  back); the first stays.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from grammarc.constants import TOL
from grammarc.geometry.meshes import ring_vector_areas
from grammarc.ragged import grow, offsets_from_counts, row_groups, segment_of, segment_reduce

#: What each component does after merging vertices.
STEPS = {
    "vertices": frozenset({"collinear"}),
    "edges": frozenset({"coplanar"}),
    "faces": frozenset({"duplicates", "small"}),
    "all": frozenset({"collinear", "coplanar", "duplicates", "small"}),
}
#: CityEngine's limits at tolerance 1: merge distance (m), collinear and coplanar angle (degrees), face
#: area (m^2); a tolerance t in [0, 1] takes t times each.
FULL_DISTANCE, FULL_DEGREES, FULL_AREA = 1.0, 10.0, 1.0
#: Sine and 1 - cosine of the angle that counts as none at tolerance 0: float noise of unit vectors.
NOISE = 1e-9


class Mesh(NamedTuple):
    """Meshes while they are cleaned: each vertex's representative ``ids`` (V,) int64 beside the
    ragged arrays."""

    ids: np.ndarray
    coords: np.ndarray
    ring_offsets: np.ndarray
    face_offsets: np.ndarray
    mesh_offsets: np.ndarray

    def ring_mesh(self) -> np.ndarray:
        """Each ring's mesh (R,) int64."""
        return segment_of(self.mesh_offsets)[segment_of(self.face_offsets)]


def cleanup_meshes(coords, ring_offsets, face_offsets, mesh_offsets, tolerance, component: str,
                   keep_small=None):
    """Meshes cleaned as ``cleanupGeometry(component, tolerance)`` cleans them.

    coords (V, 3) float64 in metres; ring_offsets (R+1,), face_offsets (F+1,), mesh_offsets (M+1,)
    int64; tolerance (M,) float64 in [0, 1]; keep_small (M,) bool or None: meshes whose small faces
    stay (a prism's base is not its only face). Returns the cleaned (coords, ring_offsets, face_offsets,
    mesh_offsets), each mesh's faces in their order, the merged face of coplanar ones where its first
    was; a mesh may be left without faces.
    """
    steps = STEPS[component]
    angle = np.radians(tolerance * FULL_DEGREES)
    distance = np.maximum(tolerance * FULL_DISTANCE, TOL.zero)
    ids = _merge_vertices(coords, ring_offsets[face_offsets[mesh_offsets]], distance)
    mesh = Mesh(ids, coords[ids], ring_offsets, face_offsets, mesh_offsets)
    repeats_only = np.full(len(ring_offsets) - 1, -1.0)
    mesh = _compact(mesh, _ring_keep(mesh.ids, mesh.coords, mesh.ring_offsets, repeats_only))
    if "duplicates" in steps:
        mesh = _compact(mesh, keep_face=~_duplicate_faces(mesh))
    if "coplanar" in steps:
        mesh = _join_coplanar(mesh, distance, np.minimum(np.cos(angle), 1.0 - NOISE))
    if "collinear" in steps:
        sine = np.maximum(np.sin(angle), NOISE)[mesh.ring_mesh()]
        mesh = _compact(mesh, _ring_keep(mesh.ids, mesh.coords, mesh.ring_offsets, sine))
    if "small" in steps:
        limit = np.maximum(tolerance * FULL_AREA, TOL.area_floor)
        if keep_small is not None:
            limit = np.where(keep_small, -np.inf, limit)
        area = np.linalg.norm(_face_vectors(mesh), axis=1)
        mesh = _compact(mesh, keep_face=area > limit[segment_of(mesh.mesh_offsets)])
    return mesh.coords, mesh.ring_offsets, mesh.face_offsets, mesh.mesh_offsets


def _join_coplanar(mesh: Mesh, distance: np.ndarray, cosine: np.ndarray) -> Mesh:
    """Coplanar faces that share an edge joined (distance (M,), cosine (M,): the angle's, per mesh);
    edges are matched on rings with their T-junctions split (``_split_edges``)."""
    split_ids, split_coords, split_rings = _split_edges(*mesh, distance)
    normal = _face_vectors(mesh)
    normal /= np.maximum(np.linalg.norm(normal, axis=1, keepdims=True), 1e-300)
    group = _coplanar_groups(split_ids, split_rings, mesh.face_offsets, normal,
                             cosine[segment_of(mesh.mesh_offsets)])
    return Mesh(*_join_groups(*mesh, split_ids, split_coords, split_rings, normal, group))


def _face_vectors(mesh: Mesh) -> np.ndarray:
    """Vector area (F, 3) of each face: its rings' summed (a hole winds the other way)."""
    rings = ring_vector_areas(mesh.coords, mesh.ring_offsets)
    return np.stack([segment_reduce(np.add, rings[:, j], mesh.face_offsets, 0.0) for j in range(3)], 1)


def _compact(mesh: Mesh, keep_vertex=None, keep_face=None) -> Mesh:
    """The mesh without the vertices ``keep_vertex`` (V,) drops, the rings left with fewer than 3, the
    faces whose outline went and those ``keep_face`` (F,) drops."""
    if keep_vertex is None:
        keep_vertex = np.ones(len(mesh.ids), dtype=bool)
    kept = segment_reduce(np.add, keep_vertex.astype(np.int64), mesh.ring_offsets, 0)
    ring_ok = kept >= 3
    face_ok = ring_ok[mesh.face_offsets[:-1]]
    if keep_face is not None:
        face_ok &= keep_face
    ring_face = segment_of(mesh.face_offsets)
    ring_ok &= face_ok[ring_face]
    vertex_ok = keep_vertex & ring_ok[segment_of(mesh.ring_offsets)]
    rings_per_face = np.bincount(ring_face[ring_ok], minlength=len(face_ok))[face_ok]
    faces_per_mesh = np.bincount(segment_of(mesh.mesh_offsets)[face_ok], minlength=len(mesh.mesh_offsets) - 1)
    return Mesh(mesh.ids[vertex_ok], mesh.coords[vertex_ok], offsets_from_counts(kept[ring_ok]),
                offsets_from_counts(rings_per_face), offsets_from_counts(faces_per_mesh))


def _duplicate_faces(mesh: Mesh) -> np.ndarray:
    """Faces (F,) bool that repeat an earlier face of their mesh. Candidates share their mesh, vertex
    count, smallest and summed vertex ids (one ``row_groups``); only they are compared vertex by vertex."""
    face_vertices = mesh.ring_offsets[mesh.face_offsets]
    key = np.column_stack([
        segment_of(mesh.mesh_offsets), np.diff(face_vertices),
        segment_reduce(np.minimum, mesh.ids, face_vertices, 0),
        segment_reduce(np.add, mesh.ids, face_vertices, 0)])
    group, _ = row_groups(key)
    return _repeats(mesh.ids, mesh.ring_offsets, mesh.face_offsets, np.argsort(group, kind="stable"), group)


@njit(cache=True, nogil=True)
def _merge_vertices(coords, vertex_offsets, distance):
    """Each vertex's representative (V,) int64: per mesh g (vertices vertex_offsets[g] to [g + 1]),
    taken in order of x, a vertex joins the nearest-in-x earlier representative within distance[g],
    else represents itself."""
    rep = np.arange(len(coords))
    for g in range(len(vertex_offsets) - 1):
        v0, v1 = vertex_offsets[g], vertex_offsets[g + 1]
        d = distance[g]
        order = v0 + np.argsort(coords[v0:v1, 0].copy(), kind="mergesort")
        for i in range(len(order)):
            a = order[i]
            for k in range(i - 1, -1, -1):
                b = order[k]
                if coords[a, 0] - coords[b, 0] > d:
                    break
                if rep[b] == b and ((coords[a] - coords[b]) ** 2).sum() <= d * d:
                    rep[a] = b
                    break
    return rep


@njit(cache=True, nogil=True)
def _ring_keep(ids, coords, ring_offsets, sine):
    """Vertices (V,) bool that stay in their rings: a vertex goes when it repeats the one before it,
    or, where sine[r] >= 0, when the lines of its edges meet at an angle whose sine is at most sine[r]
    (measured from the last vertex kept). Stops when a ring is down to 2 vertices."""
    keep = np.ones(len(ids), np.bool_)
    for r in range(len(ring_offsets) - 1):
        r0, n = ring_offsets[r], ring_offsets[r + 1] - ring_offsets[r]
        prev = (np.arange(n) - 1) % n
        nxt = (np.arange(n) + 1) % n
        left = n
        changed = True
        while changed and left >= 3:
            changed = False
            for j in range(n):
                if not keep[r0 + j] or left < 3:
                    continue
                p, q = prev[j], nxt[j]
                drop = ids[r0 + j] == ids[r0 + p]
                if not drop and sine[r] >= 0:
                    e1 = coords[r0 + j] - coords[r0 + p]
                    e2 = coords[r0 + q] - coords[r0 + j]
                    cross = np.array([e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                                      e1[0] * e2[1] - e1[1] * e2[0]])
                    drop = np.sqrt((cross ** 2).sum()) <= sine[r] * np.sqrt((e1 ** 2).sum() * (e2 ** 2).sum())
                if drop:
                    keep[r0 + j] = False
                    nxt[p], prev[q] = q, p
                    left -= 1
                    changed = True
    return keep


@njit(cache=True, nogil=True)
def _repeats(ids, ring_offsets, face_offsets, order, group):
    """Faces (F,) bool equal to an earlier face of their candidate group (``order`` sorts faces by
    ``group``, keeping their order within it)."""
    repeat = np.zeros(len(face_offsets) - 1, np.bool_)
    start = 0
    while start < len(order):
        stop = start + 1
        while stop < len(order) and group[order[stop]] == group[order[start]]:
            stop += 1
        for i in range(start + 1, stop):
            for k in range(start, i):
                if not repeat[order[k]] and _same_face(ids, ring_offsets, face_offsets, order[k], order[i]):
                    repeat[order[i]] = True
                    break
        start = stop
    return repeat


@njit(cache=True, nogil=True)
def _same_face(ids, ring_offsets, face_offsets, e, f):
    """Whether faces e and f have the same rings in turn, each the same cycle either way round."""
    if face_offsets[e + 1] - face_offsets[e] != face_offsets[f + 1] - face_offsets[f]:
        return False
    for k in range(face_offsets[e + 1] - face_offsets[e]):
        a, b = face_offsets[e] + k, face_offsets[f] + k
        a0, b0, n = ring_offsets[a], ring_offsets[b], ring_offsets[a + 1] - ring_offsets[a]
        if ring_offsets[b + 1] - b0 != n:
            return False
        same = False
        for s in range(n):
            if ids[b0 + s] != ids[a0]:
                continue
            forward, backward = True, True
            for i in range(n):
                forward = forward and ids[a0 + i] == ids[b0 + (s + i) % n]
                backward = backward and ids[a0 + i] == ids[b0 + (s - i) % n]
            if forward or backward:
                same = True
                break
        if not same:
            return False
    return True


@njit(cache=True, nogil=True)
def _split_edges(ids, coords, ring_offsets, face_offsets, mesh_offsets, distance):
    """The rings with every vertex of their mesh that lies on one of their edges (within distance[g],
    strictly between its ends) put into that edge, in order along it: where a face's edge meets two
    edges of its neighbours (a T-junction, as convexify's cuts leave them), the edges then match.
    Returns ids (V',), coords (V', 3) and ring_offsets (R+1,); rings and faces are the same."""
    out_ids = np.empty(len(ids) + 16, np.int64)
    out_coords = np.empty((len(ids) + 16, 3))
    out_r = np.zeros(len(ring_offsets), np.int64)
    n = 0
    for g in range(len(mesh_offsets) - 1):
        v0 = ring_offsets[face_offsets[mesh_offsets[g]]]
        v1 = ring_offsets[face_offsets[mesh_offsets[g + 1]]]
        order = v0 + np.argsort(ids[v0:v1], kind="mergesort")
        distinct = np.empty(len(order), np.int64)  # one vertex of each id
        k = 0
        for i in range(len(order)):
            if i == 0 or ids[order[i]] != ids[order[i - 1]]:
                distinct[k] = order[i]
                k += 1
        distinct = distinct[:k]
        along = np.empty(k)
        found = np.empty(k, np.int64)
        d2 = distance[g] * distance[g]
        for r in range(face_offsets[mesh_offsets[g]], face_offsets[mesh_offsets[g + 1]]):
            r0, r1 = ring_offsets[r], ring_offsets[r + 1]
            for j in range(r0, r1):
                q = r0 + (j - r0 + 1) % (r1 - r0)
                edge = coords[q] - coords[j]
                length2 = (edge ** 2).sum()
                m = 0
                for u in distinct:
                    if ids[u] == ids[j] or ids[u] == ids[q] or length2 == 0.0:
                        continue
                    t = ((coords[u] - coords[j]) * edge).sum() / length2
                    if 0.0 < t < 1.0 and ((coords[u] - coords[j] - t * edge) ** 2).sum() <= d2:
                        along[m], found[m] = t, u
                        m += 1
                out_ids = grow(out_ids, n + m + 1)
                out_coords = grow(out_coords, n + m + 1)
                out_ids[n], out_coords[n] = ids[j], coords[j]
                n += 1
                for i in np.argsort(along[:m]):
                    out_ids[n], out_coords[n] = ids[found[i]], coords[found[i]]
                    n += 1
            out_r[r + 1] = n
    return out_ids[:n], out_coords[:n], out_r


@njit(cache=True, nogil=True)
def _coplanar_groups(ids, ring_offsets, face_offsets, normal, cosine):
    """Each face's group (F,) int64, numbered by its first face: faces that share an edge (its two
    vertices, run in opposite directions) and whose unit normals (F, 3) meet at an angle whose cosine
    is at least cosine[f] are one group."""
    n_faces = len(face_offsets) - 1
    n_verts = len(ids)
    root = np.arange(n_faces)
    # every edge by its two vertices, smaller first: equal keys are one edge of several faces
    face = np.empty(n_verts, np.int64)
    forward = np.empty(n_verts, np.bool_)
    key = np.empty(n_verts, np.int64)
    span = ids.max() + 1 if n_verts else 1
    for f in range(n_faces):
        for r in range(face_offsets[f], face_offsets[f + 1]):
            r0, r1 = ring_offsets[r], ring_offsets[r + 1]
            for j in range(r0, r1):
                a, b = ids[j], ids[r0 + (j - r0 + 1) % (r1 - r0)]
                face[j], forward[j] = f, a < b
                key[j] = min(a, b) * span + max(a, b)
    order = np.argsort(key, kind="mergesort")
    start = 0
    while start < n_verts:
        stop = start + 1
        while stop < n_verts and key[order[stop]] == key[order[start]]:
            stop += 1
        for x in range(start, stop):
            for y in range(x + 1, stop):
                f, g = face[order[x]], face[order[y]]
                if f != g and forward[order[x]] != forward[order[y]] and \
                        (normal[f] * normal[g]).sum() >= cosine[f]:
                    rf, rg = _find(root, f), _find(root, g)
                    root[max(rf, rg)] = min(rf, rg)  # the group's first face is its root
        start = stop
    for f in range(n_faces):
        root[f] = _find(root, f)
    return root


@njit(cache=True, nogil=True)
def _join_groups(ids, coords, ring_offsets, face_offsets, mesh_offsets, split_ids, split_coords,
                 split_rings, normal, group):
    """The mesh with each group of several faces (``group`` (F,), numbered by its first face) one face,
    traced on the split rings (``_split_edges``, ``_boundary``) where its first face was; the faces of
    a group that does not join, and single faces, as they were. Returns (ids, coords, ring_offsets,
    face_offsets, mesh_offsets)."""
    n_faces = len(face_offsets) - 1
    size = np.zeros(n_faces, np.int64)
    for f in range(n_faces):
        size[group[f]] += 1
    joined = np.zeros(n_faces, np.bool_)
    out_ids = np.empty_like(split_ids)
    out_coords = np.empty_like(split_coords)
    out_r = np.zeros(len(ring_offsets) + len(split_ids) // 3 + 1, np.int64)  # a traced ring has 3 edges
    out_f = np.zeros(n_faces + 1, np.int64)
    out_m = np.zeros(len(mesh_offsets), np.int64)
    n_v, n_r, n_f = 0, 0, 0
    for g in range(len(mesh_offsets) - 1):
        for f in range(mesh_offsets[g], mesh_offsets[g + 1]):
            if size[group[f]] > 1 and group[f] == f:
                members = np.flatnonzero(group[f:mesh_offsets[g + 1]] == f) + f
                up = np.zeros(3)
                for m in members:
                    up += normal[m]
                vertices, rings, ok = _boundary(split_ids, split_coords, split_rings, face_offsets, members, up)
                joined[f] = ok
                if ok:
                    for k in range(len(rings) - 1):
                        for j in range(rings[k], rings[k + 1]):
                            out_ids[n_v], out_coords[n_v] = split_ids[vertices[j]], split_coords[vertices[j]]
                            n_v += 1
                        n_r += 1
                        out_r[n_r] = n_v
                    n_f += 1
                    out_f[n_f] = n_r
            if not joined[group[f]]:
                for r in range(face_offsets[f], face_offsets[f + 1]):
                    for j in range(ring_offsets[r], ring_offsets[r + 1]):
                        out_ids[n_v], out_coords[n_v] = ids[j], coords[j]
                        n_v += 1
                    n_r += 1
                    out_r[n_r] = n_v
                n_f += 1
                out_f[n_f] = n_r
        out_m[g + 1] = n_f
    return out_ids[:n_v], out_coords[:n_v], out_r[:n_r + 1], out_f[:n_f + 1], out_m


@njit(cache=True, nogil=True)
def _find(root, f):
    while root[f] != f:
        root[f] = root[root[f]]
        f = root[f]
    return f


@njit(cache=True, nogil=True)
def _boundary(ids, coords, ring_offsets, face_offsets, faces, up):
    """The boundary of a group of faces: their rings' edges less the pairs that run between the same
    vertices in opposite directions, chained into rings. Returns the rings' vertices (indices into
    coords), their offsets, and whether they are one outline winding counter-clockwise around ``up``
    with holes winding the other way; the outline comes first."""
    n_edges = 0
    for f in faces:
        n_edges += ring_offsets[face_offsets[f + 1]] - ring_offsets[face_offsets[f]]
    tail = np.empty(n_edges, np.int64)
    head = np.empty(n_edges, np.int64)
    k = 0
    for f in faces:
        for r in range(face_offsets[f], face_offsets[f + 1]):
            r0, r1 = ring_offsets[r], ring_offsets[r + 1]
            for j in range(r0, r1):
                tail[k], head[k] = j, r0 + (j - r0 + 1) % (r1 - r0)
                k += 1
    used = np.zeros(n_edges, np.bool_)  # shared, or already chained
    for i in range(n_edges):
        for m in range(i + 1, n_edges):
            if not used[i] and not used[m] and ids[tail[m]] == ids[head[i]] and ids[head[m]] == ids[tail[i]]:
                used[i], used[m] = True, True
                break
    vertices = np.empty(n_edges, np.int64)
    offsets = np.zeros(n_edges + 1, np.int64)
    n, n_rings = 0, 0
    for i in range(n_edges):
        if used[i]:
            continue
        edge = i
        while True:
            used[edge] = True
            vertices[n] = tail[edge]
            n += 1
            at = ids[head[edge]]
            if at == ids[tail[i]]:
                break
            edge = -1
            for m in range(n_edges):
                if not used[m] and ids[tail[m]] == at:
                    edge = m
                    break
            if edge < 0:
                return vertices[:n], offsets[:n_rings + 1], False
        n_rings += 1
        offsets[n_rings] = n
    # one ring winds around `up` (the outline), the others the other way (holes)
    outline = -1
    for r in range(n_rings):
        turn = 0.0
        for j in range(offsets[r], offsets[r + 1]):
            p = coords[vertices[j]]
            q = coords[vertices[offsets[r] + (j - offsets[r] + 1) % (offsets[r + 1] - offsets[r])]]
            turn += (up[0] * (p[1] * q[2] - p[2] * q[1]) + up[1] * (p[2] * q[0] - p[0] * q[2])
                     + up[2] * (p[0] * q[1] - p[1] * q[0]))
        if turn > 0:
            if outline >= 0:
                return vertices[:n], offsets[:n_rings + 1], False
            outline = r
        elif turn == 0:
            return vertices[:n], offsets[:n_rings + 1], False
    if outline < 0:
        return vertices[:n], offsets[:n_rings + 1], False
    # the outline first
    ordered = np.empty(n, np.int64)
    ordered_offsets = np.zeros(n_rings + 1, np.int64)
    k = 0
    for rank in range(n_rings):
        r = outline if rank == 0 else (rank - 1 if rank - 1 < outline else rank)
        for j in range(offsets[r], offsets[r + 1]):
            ordered[k] = vertices[j]
            k += 1
        ordered_offsets[rank + 1] = k
    return ordered, ordered_offsets, True
