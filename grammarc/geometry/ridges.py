"""Roofs with one ridge along a given direction: CityEngine's ``roofRidge`` and ``roofGable`` with an edge
index, many polygons at once (shapely and numpy).

Unlike the skeleton roofs (``roofs.py``), whose planes rise from every edge, these have two planes only,
rising towards each other from the two lines along the ridge direction that bound the polygon: the ridge
runs over the middle of the polygon's extent across it, and the outline, wherever it lies, becomes part
of the two planes, with a wall under every edge up to the roof (none where the roof meets the edge).
On a rectangle with the ridge along an edge this is the gable roof; on other shapes it is what
CityEngine's reference describes for ``roofRidge``: no hips and no gables, the outline part of two
angled planes. ``roofGable(..., index)`` takes the ridge along edge ``index`` (the reference: the ridge's
direction is forced to the edge's) and its overhangs: the outline grown by ``overhangX`` across the
ridge and by ``overhangY`` along it, each edge moved by the one of the direction it is closer to.

Output is the layout of ``roofs.roof_meshes``: per polygon the bottom (the polygon seen from below), the
roof faces, then the walls, in (u, v, h) coordinates of the polygon's plane with h along its normal.
"""

from __future__ import annotations

import numpy as np
import shapely

from grammarc.geometry.clip import oriented_rings
from grammarc.ragged import offsets_from_counts, segment_of

#: How far beyond a polygon (relative to its extent) the half-planes that cut it at the ridge reach.
_REACH = 4.0


def ridge_roofs(polygons, plane, direction, value, by_height, overhang_x, overhang_y, eps):
    """Ridge roofs of k polygons.

    polygons (k,): shapely polygons in their planes' units (u, v); plane (k,) their plane codes;
    direction (k, 2) the ridge's direction in (u, v); value (k,) the angle in degrees or (``by_height``)
    the ridge's height; overhang_x, overhang_y (k,) measured on the roof (across the ridge) and along it.
    Returns verts (V', 3) as (u, v, h), ring_offsets, face_offsets, mesh_offsets (k+1,) and ok (k,):
    False where the polygon is not valid or has no extent across the ridge.
    """
    k = len(polygons)
    valid = shapely.is_valid(polygons) & ~shapely.is_empty(polygons)
    polygons = np.where(valid, polygons, shapely.Polygon([(0, 0), (1, 0), (0, 1)]))
    pts, vertex_poly = shapely.get_coordinates(polygons, return_index=True)
    # each polygon's own extent: a chunk-wide one would cut a small roof with other half-planes when a
    # large lot shares its chunk, and its vertices would differ in the last bits with the chunking
    low_pt, high_pt = np.full((k, 2), np.inf), np.full((k, 2), -np.inf)
    np.minimum.at(low_pt, vertex_poly, pts)
    np.maximum.at(high_pt, vertex_poly, pts)
    size = (high_pt - low_pt).max(axis=1) if k else np.zeros(0)
    d = direction / np.maximum(np.linalg.norm(direction, axis=1, keepdims=True), 1e-300)
    n = np.stack([-d[:, 1], d[:, 0]], axis=1)
    across = np.einsum("vi,vi->v", pts, n[vertex_poly])
    low = np.full(k, np.inf)
    high = np.full(k, -np.inf)
    np.minimum.at(low, vertex_poly, across)
    np.maximum.at(high, vertex_poly, across)
    mid, half = (low + high) / 2, (high - low) / 2
    angle = np.radians(value)
    slope = np.where(by_height, value / np.maximum(half, 1e-300), np.tan(angle))
    # overhangs are measured on the roof: horizontally they are shorter by the slope's cosine
    flat = np.where(by_height, 1.0, np.cos(angle))
    ok = valid & (half > eps) & (by_height | (np.abs(angle) < np.pi / 2))
    grown = _grown(polygons, d, overhang_x * flat, overhang_y)
    # the roof faces: the grown outline on either side of the ridge, lifted onto its plane
    reach = _REACH * (size + np.abs(overhang_x) + np.abs(overhang_y) + 1.0)
    centre = np.stack([shapely.get_x(shapely.centroid(grown)), shapely.get_y(shapely.centroid(grown))], 1)
    centre = np.nan_to_num(centre)
    along = np.einsum("ki,ki->k", centre, d)
    sides = []
    for sign in (-1.0, 1.0):
        a0, a1 = along - reach, along + reach
        t0, t1 = mid, mid + sign * reach
        corners = np.stack([d * a[:, None] + n * t[:, None] for a, t in ((a0, t0), (a1, t0), (a1, t1), (a0, t1))],
                           axis=1)
        sides.append(shapely.intersection(grown, shapely.polygons(corners)))
    parts, source = shapely.get_parts(np.concatenate(sides), return_index=True)
    source = source % max(k, 1)
    keep = (shapely.get_type_id(parts) == shapely.GeometryType.POLYGON) & (shapely.area(parts) > eps * eps)
    parts, source = parts[keep], source[keep]
    order = np.argsort(source, kind="stable")
    parts, source = parts[order], source[order]
    _, top_uv, top_rings, top_faces = oriented_rings(parts, plane[source])
    top_vertex = source[segment_of(top_faces)[segment_of(top_rings)]]
    top_h = slope[top_vertex] * (half[top_vertex] - np.abs(
        np.einsum("vi,vi->v", top_uv, n[top_vertex]) - mid[top_vertex]))
    # the bottom is the polygon turned over; the walls stand under its edges
    _, base_uv, base_rings, base_faces = oriented_rings(polygons, plane)
    base_vertex = segment_of(base_faces)[segment_of(base_rings)]
    bottom_uv = base_uv[_reversed(base_rings)]
    wall_uv, wall_h, wall_rings, wall_poly = _walls(base_uv, base_rings, base_vertex, n, mid, half, slope, eps)
    # assemble per polygon: bottom (one face), roof faces, walls
    face_poly = np.concatenate([np.arange(k), source, wall_poly])
    face_kind = np.concatenate([np.zeros(k), np.ones(len(source)), np.full(len(wall_poly), 2)])
    order = np.lexsort((face_kind, face_poly))
    face_rings = np.concatenate([np.diff(base_faces), np.diff(top_faces), np.ones(len(wall_poly), np.int64)])
    ring_counts = [np.diff(base_rings), np.diff(top_rings), np.diff(wall_rings)]
    ring_face = np.concatenate([np.repeat(np.arange(len(f) - 1), np.diff(f)) + base
                                for f, base in ((base_faces, 0), (top_faces, k),
                                                (np.arange(len(wall_poly) + 1), k + len(source)))])
    verts = np.concatenate([np.column_stack([bottom_uv, np.zeros(len(bottom_uv))]),
                            np.column_stack([top_uv, top_h]), np.column_stack([wall_uv, wall_h])])
    vertex_ring = np.repeat(np.arange(sum(len(c) for c in ring_counts)), np.concatenate(ring_counts))
    # faces in order, their rings in order, their vertices in order
    rank = np.empty(len(order), np.int64)
    rank[order] = np.arange(len(order))
    ring_order = np.lexsort((np.arange(len(ring_face)), rank[ring_face]))
    ring_rank = np.empty(len(ring_order), np.int64)
    ring_rank[ring_order] = np.arange(len(ring_order))
    vertex_order = np.lexsort((np.arange(len(vertex_ring)), ring_rank[vertex_ring]))
    counts = np.concatenate(ring_counts)[ring_order]
    faces_per_poly = np.bincount(face_poly, minlength=k)
    return (verts[vertex_order], offsets_from_counts(counts), offsets_from_counts(face_rings[order]),
            offsets_from_counts(faces_per_poly), ok)


def _grown(polygons, d, out_x, out_y):
    """Each polygon's outline with every exterior edge moved outwards by ``out_x`` (k,) if it runs
    closer to the ridge's direction ``d`` (k, 2), else by ``out_y`` (k,): the new corners where the
    moved lines of neighbouring edges cross (holes are left out of the roof's outline)."""
    grow = (np.abs(out_x) > 0) | (np.abs(out_y) > 0)
    if not grow.any():
        return polygons
    out = polygons.copy()
    rows = np.flatnonzero(grow)
    ext = shapely.get_exterior_ring(shapely.orient_polygons(polygons[rows]))  # counter-clockwise in (u, v)
    coords, index = shapely.get_coordinates(ext, return_index=True)
    starts = np.r_[0, np.flatnonzero(np.diff(index)) + 1]
    ends = np.r_[starts[1:], len(index)]
    keep = np.ones(len(coords), bool)
    keep[ends - 1] = False  # the closing repeat of each ring
    coords, index = coords[keep], index[keep]
    counts = np.bincount(index, minlength=len(rows))
    first = offsets_from_counts(counts)[:-1]
    pos = np.arange(len(coords)) - first[index]
    nxt = first[index] + (pos + 1) % counts[index]
    prv = first[index] + (pos - 1) % counts[index]
    edge = coords[nxt] - coords
    edge /= np.maximum(np.linalg.norm(edge, axis=1, keepdims=True), 1e-300)
    normal = np.stack([edge[:, 1], -edge[:, 0]], axis=1)  # outwards of a counter-clockwise ring
    dist = np.where(np.abs(np.einsum("vi,vi->v", edge, d[rows][index])) >= np.sqrt(0.5),
                    out_x[rows][index], out_y[rows][index])
    c = np.einsum("vi,vi->v", normal, coords) + dist
    # corner v: the crossing of the moved lines of edges prv(v) -> v and v -> nxt(v)
    m = np.stack([normal[prv], normal], axis=1)
    rhs = np.stack([c[prv], c], axis=1)
    det = np.linalg.det(m)
    parallel = np.abs(det) < 1e-12
    m[parallel] = np.eye(2)
    rhs[parallel] = (coords + normal * dist[:, None])[parallel]
    corner = np.linalg.solve(m, rhs[..., None])[..., 0]
    out[rows] = shapely.polygons(shapely.linearrings(corner, indices=index))
    return out


def _reversed(ring_offsets):
    """Indices that reverse every ring in place."""
    ring = segment_of(ring_offsets)
    pos = np.arange(ring_offsets[-1]) - ring_offsets[:-1][ring]
    return ring_offsets[1:][ring] - 1 - pos


def _walls(uv, ring_offsets, vertex_poly, n, mid, half, slope, eps):
    """A wall under each ring edge a -> b up to the roof: (a, b, b lifted, the ridge above the edge where
    it crosses the ridge line, a lifted), without lifted corners that stay on the ground and without
    walls of no height. Returns their vertices (W, 2), heights (W,), ring offsets and polygons."""
    ring = segment_of(ring_offsets)
    pos = np.arange(len(uv)) - ring_offsets[:-1][ring]
    b = ring_offsets[:-1][ring] + (pos + 1) % np.diff(ring_offsets)[ring]
    t = np.einsum("vi,vi->v", uv, n[vertex_poly]) - mid[vertex_poly]
    h = slope[vertex_poly] * (half[vertex_poly] - np.abs(t))
    crosses = ((t < -eps) & (t[b] > eps)) | ((t > eps) & (t[b] < -eps))
    f = np.where(crosses, t / np.where(crosses, t - t[b], 1.0), 0.0)
    ridge_uv = uv + f[:, None] * (uv[b] - uv)
    ground = np.zeros(len(uv))
    slots_uv = np.stack([uv, uv[b], uv[b], ridge_uv, uv], axis=1)
    slots_h = np.stack([ground, ground, h[b], slope[vertex_poly] * half[vertex_poly], h], axis=1)
    used = np.stack([np.ones(len(uv), bool), np.ones(len(uv), bool), h[b] > eps, crosses, h > eps], axis=1)
    wall = used.sum(axis=1) >= 3
    used &= wall[:, None]
    return slots_uv[used], slots_h[used], offsets_from_counts(used[wall].sum(axis=1)), vertex_poly[wall]
