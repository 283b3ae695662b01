"""CityEngine's trim planes: where a component split's neighbouring faces meet, inserted geometry is cut.

A comp(f) gives each side face (one whose edges to its neighbours are steeper than 40 degrees to the x-z
plane of the split shape's scope) a plane at each of those edges, bisecting the angle between the two
faces; geometry inserted under that face keeps the side of both planes the face is on, so ledges and
cornices enlarged to run past a corner meet their neighbours in a mitre. Horizontal trim planes
(CityEngine's ``trim.horizontal``, off by default) are made alike at the shallower edges a face shares:
a wall's top with the roof, a roof face's hips and ridge. CityEngine measures the 40 degrees from the x-z
plane of the pivot; grammarc measures them from the split shape's scope, which is the same for the
solids of a footprint (y up) and, as PRT does, trims a pipe extruded sideways from a wall (candler's
VerticalPipes) at its four corners. ``side_face_planes`` and ``shallow_edge_planes`` find the planes of
many faces at once; ``trim_triangles`` cuts the triangles of many placed assets by them (numba);
``plane_coordinates`` gives each plane a frame in which the ``trim()`` operation cuts a shape's own
geometry as a split cuts a slab (``backend.operations.trims``).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from grammarc.ragged import group_bounds, rank_within, row_groups

#: A shared edge steeper than this (degrees from the horizontal) makes a vertical trim plane, a shallower
#: one a horizontal plane.
VERTICAL_DEGREES = 40.0
#: Vertical trim planes a side face has: at its start edge and at its end edge (``side_face_planes``).
VERTICAL_PLANES = 2
#: Horizontal trim planes a face keeps (a box's top face has four shallow edges, a hip roof's face its
#: eave, its hips and its ridge).
HORIZONTAL_PLANES = 4


def side_face_planes(axes: np.ndarray, origin: np.ndarray, size: np.ndarray, parent: np.ndarray,
                     up: np.ndarray) -> np.ndarray:
    """Trim planes (m, 8) of component faces: (nx, ny, nz, d) at the face's start edge, then at its end
    edge, keeping n . X + d >= 0; NaN where a face has no such neighbour or its edges are not steep.

    axes (m, 3, 3) world rows (x along the face's bottom edge, y up its side), origin (m, 3) the start of
    the bottom edge (from its lot's origin, as the planes are then), size (m, 3), parent (m,): faces of
    one parent meet where one's end is the next's start; up (m, 3) the split shape's scope y axis in
    world coordinates."""
    if not len(parent):
        return np.full((0, 8), np.nan)
    end = bottom_ends(origin, size, axes)
    (first, last), _ = _corner_cells(parent, origin, end)
    # the neighbour sharing each face's start / end
    before, after = _neighbours(np.argsort(parent, kind="stable"), parent, first, last)
    return _bisector_planes(axes, origin, end, size, up, before, after, np.sin(np.radians(VERTICAL_DEGREES)))


@njit(cache=True, nogil=True)
def bottom_ends(origin, size, axes):
    """The end of each face's bottom edge (m, 3), the edge from its ``origin`` (m, 3) along its x, ``axes``
    (m, 3, 3) rows: ``origin + size[:, 0:1] * axes[:, 0]`` in one pass."""
    end = np.empty((len(origin), 3))
    for i in range(len(origin)):
        for j in range(3):
            end[i, j] = origin[i, j] + size[i, 0] * axes[i, 0, j]
    return end


@njit(cache=True, nogil=True)
def _bisector_planes(axes, start, end, size, up, before, after, steepest):
    """``side_face_planes``' planes, once each face's neighbours ``before`` and ``after`` (m,) are known:
    where a face and its neighbour are both steep (their y axes at least ``steepest``, the sine, along
    ``up``; not flat), the plane through the shared corner (``start`` or ``end`` (m, 3)) whose normal
    bisects their x axes. The sums run in numpy's order (``einsum``'s from 0.0, ``norm``'s in axis
    order), so the planes have the bits they had when numpy computed them."""
    m = len(axes)
    out = np.full((m, 8), np.nan)
    steep = np.empty(m, np.bool_)
    for i in range(m):
        dot = 0.0
        for j in range(3):
            dot += axes[i, 1, j] * up[i, j]
        steep[i] = abs(dot) >= steepest and size[i, 0] > 0 and size[i, 1] > 0
    for i in range(m):
        if not steep[i]:
            continue
        for which in range(2):
            k = before[i] if which == 0 else after[i]
            if k < 0 or not steep[k]:
                continue
            b0 = axes[i, 0, 0] + axes[k, 0, 0]
            b1 = axes[i, 0, 1] + axes[k, 0, 1]
            b2 = axes[i, 0, 2] + axes[k, 0, 2]
            length = np.sqrt((b0 * b0 + b1 * b1) + b2 * b2)
            if not length > 1e-9:
                continue
            sign = 1.0 if which == 0 else -1.0
            n0, n1, n2 = sign * (b0 / length), sign * (b1 / length), sign * (b2 / length)
            corner = start if which == 0 else end
            d = 0.0
            d += n0 * corner[i, 0]
            d += n1 * corner[i, 1]
            d += n2 * corner[i, 2]
            out[i, 4 * which] = n0
            out[i, 4 * which + 1] = n1
            out[i, 4 * which + 2] = n2
            out[i, 4 * which + 3] = -d
    return out


def shallow_edge_planes(verts: np.ndarray, ring_offsets: np.ndarray, face_offsets: np.ndarray, parent: np.ndarray,
                        up: np.ndarray) -> np.ndarray:
    """Horizontal trim planes (m, 4 * HORIZONTAL_PLANES) of component faces: (nx, ny, nz, d) at each edge
    a face shares with a face of the same ``parent`` (m,) that is less steep than ``VERTICAL_DEGREES`` to
    the x-z plane of the split shape's scope (its ``up`` (m, 3)), in the order of its outline, keeping
    n . X + d >= 0; NaN after the last.

    verts (V, 3) the corners of the m faces (from their lots' origins, as the planes are then) (outline first: ``face_offsets`` (m+1,) into
    ``ring_offsets``). The plane holds the shared edge and bisects the angle between the
    faces: its normal is the direction into this face across the edge minus the one into the neighbour,
    so a wall's ledge meets the roof's or the next slope's in a mitre, as at the vertical corners."""
    m = len(parent)
    out = np.full((m, 4 * HORIZONTAL_PLANES), np.nan)
    if not m:
        return out
    outline = face_offsets[:-1]
    start, stop = ring_offsets[outline], ring_offsets[outline + 1]
    count = stop - start
    face = np.repeat(np.arange(m), count)
    at = np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count)
    p = verts[start[face] + at]
    q = verts[start[face] + (at + 1) % count[face]]
    # each face's unit normal (Newell's, over its outline)
    newell = np.zeros((m, 3))
    np.add.at(newell, face, np.cross(p, q))
    normal = newell / np.maximum(np.linalg.norm(newell, axis=1, keepdims=True), 1e-300)
    edge = q - p
    length = np.linalg.norm(edge, axis=1)
    direction = edge / np.maximum(length, 1e-300)[:, None]
    ends, scale = _corner_cells(parent[face], p, q)
    keys = np.concatenate([np.column_stack([parent[face], ends[0], ends[1]]),
                           np.column_stack([parent[face], ends[1], ends[0]])])
    group, _ = row_groups(keys)
    n_edges = len(face)
    forward = np.full(int(group.max()) + 1, -1)
    forward[group[:n_edges]] = np.arange(n_edges)
    neighbour = forward[group[n_edges:]]  # the edge running the other way along the same two corners
    shallow = np.abs(np.einsum("ij,ij->i", direction, up[face])) < np.sin(np.radians(VERTICAL_DEGREES))
    ok = (neighbour >= 0) & shallow & (length > scale[:, 0])
    ok[ok] &= face[neighbour[ok]] != face[ok]
    rows = np.flatnonzero(ok)
    # into each face across the edge: its normal cross the edge (outlines wind counter-clockwise)
    into = np.cross(normal[face[rows]], direction[rows])
    into_other = np.cross(normal[face[neighbour[rows]]], -direction[rows])
    plane = into - into_other
    size = np.linalg.norm(plane, axis=1)
    good = size > 1e-9
    rows, plane = rows[good], plane[good] / size[good, None]
    rank = rank_within(face[rows])
    keep = rank < HORIZONTAL_PLANES
    rows, plane, rank = rows[keep], plane[keep], rank[keep]
    columns = 4 * rank[:, None] + np.arange(3)
    out[face[rows, None], columns] = plane
    out[face[rows], 4 * rank + 3] = -np.einsum("ij,ij->i", plane, p[rows])
    return out


def _corner_cells(parent: np.ndarray, start: np.ndarray, end: np.ndarray) -> tuple[list[np.ndarray], np.ndarray]:
    """The grid cells (k, 3) int64 that corners ``start`` and ``end`` (each (k, 3)) of parents ``parent`` (k,)
    are matched on, and the grid's spacing (k, 1): 1e-7 of the parent's extent (1 at least), from the
    parent's lowest corner. Per parent and from its own corner, so that a lot far from the origin
    (national-grid coordinates) is matched as it would be at the origin and coarsens no other lot's
    matching in its chunk (a grid of its coordinates' magnitude, 0.8 m at 7.8e6, made the corners of
    complexpatterns' 0.6 m deep top floors one corner)."""
    parent = np.ascontiguousarray(parent, dtype=np.int64)
    start, end = np.ascontiguousarray(start, dtype=np.float64), np.ascontiguousarray(end, dtype=np.float64)
    low, high = group_bounds(parent, int(parent.max()) + 1, start, end)
    first, last, scale = _cells(parent, low, high, start, end)
    return [first, last], scale[parent][:, None]


@njit(cache=True, nogil=True)
def _cells(parent, low, high, start, end):
    """``_corner_cells`` from each parent's lowest and highest corner (n, 3): its spacing (n,), numpy's
    (the largest extent, a NaN winning, at least 1, times 1e-7), and ``round((points - low[parent]) /
    scale[parent])`` as int64, as numpy rounds (half to even) and casts (a value beyond int64, or not
    finite, is int64's least, as numpy's cast gives it here), for the starts and the ends."""
    scale = np.empty(len(low))
    for g in range(len(low)):
        extent = high[g, 0] - low[g, 0]
        for j in range(1, 3):
            d = high[g, j] - low[g, j]
            if not np.isnan(extent) and (d > extent or np.isnan(d)):
                extent = d
        scale[g] = (extent if extent > 1.0 or np.isnan(extent) else 1.0) * 1e-7
    first = np.empty(start.shape, np.int64)
    last = np.empty(end.shape, np.int64)
    for points, out in ((start, first), (end, last)):
        for k in range(len(parent)):
            g = parent[k]
            for j in range(3):
                cell = np.rint((points[k, j] - low[g, j]) / scale[g])
                out[k, j] = np.int64(cell) if abs(cell) < 9.2e18 else np.iinfo(np.int64).min
    return first, last, scale


@njit(cache=True, nogil=True)
def _neighbours(order, parent, first, last):
    """Each face's neighbour at its start, the face of its parent whose end is in the same grid cell as its
    start, and at its end, the one whose start is in its end's cell (-1: none; the last face, where
    several are). ``order`` (m,) lists the faces parent by parent (a stable sort: faces in their order);
    ``first`` and ``last`` (m, 3) int64 are the cells of their starts and ends (``_corner_cells``). A
    parent's faces are few (a box's six, a footprint's walls): each is matched against all of them."""
    m = len(order)
    before = np.full(m, -1, np.int64)
    after = np.full(m, -1, np.int64)
    group = 0
    while group < m:
        stop = group
        while stop < m and parent[order[stop]] == parent[order[group]]:
            stop += 1
        for a in range(group, stop):
            i = order[a]
            for b in range(group, stop):
                j = order[b]
                if last[j, 0] == first[i, 0] and last[j, 1] == first[i, 1] and last[j, 2] == first[i, 2]:
                    before[i] = j
                if first[j, 0] == last[i, 0] and first[j, 1] == last[i, 1] and first[j, 2] == last[i, 2]:
                    after[i] = j
        group = stop
    return before, after


def plane_coordinates(normal: np.ndarray) -> np.ndarray:
    """Orthonormal right-handed frames (k, 3, 3) whose first row is each unit ``normal`` (k, 3): in them a
    trim plane is a plane across the first axis, which the slab cuts of ``meshes.clip_slabs`` take."""
    # the world axis least along the normal completes it
    other = np.eye(3)[np.argmin(np.abs(normal), axis=1)]
    second = np.cross(normal, other)
    second /= np.linalg.norm(second, axis=1, keepdims=True)
    return np.stack([normal, second, np.cross(normal, second)], axis=1)


@njit(cache=True, nogil=True)
def boxes_crossing(planes, xform, eps):
    """Which unit boxes placed by xform (k, 3, 4) reach past one of their planes (k, 4 P; NaN: none) by
    more than eps: those are cut, the others stay instances."""
    out = np.zeros(len(xform), np.bool_)
    for k in range(len(xform)):
        for p in range(planes.shape[1] // 4):
            nx, ny, nz, d = planes[k, 4 * p], planes[k, 4 * p + 1], planes[k, 4 * p + 2], planes[k, 4 * p + 3]
            if np.isnan(nx):
                continue
            for c in range(8):
                fx, fy, fz = c & 1, c >> 1 & 1, c >> 2 & 1
                side = d
                for r in range(3):
                    coord = xform[k, r, 0] * fx + xform[k, r, 1] * fy + xform[k, r, 2] * fz + xform[k, r, 3]
                    side += coord * (nx if r == 0 else ny if r == 1 else nz)
                if side < -eps:
                    out[k] = True
                    break
            if out[k]:
                break
    return out


@njit(cache=True, nogil=True)
def trim_triangles(verts, tris, xform, planes, eps):
    """Triangles of an asset (verts (v, 3) in its unit box, tris (t, 3)) placed by xform (k, 3, 4) and
    cut by each placement's planes (k, 4 P; NaN: none): the kept polygons in the placements' coordinates.
    Returns vertices (V, 3), ring_offsets (F+1,) and each polygon's placement (F,)."""
    k_count, t_count = len(xform), len(tris)
    n_planes = planes.shape[1] // 4
    out = np.empty((k_count * t_count * (3 + n_planes) + 1, 3))
    offsets = np.zeros(k_count * t_count + 1, np.int64)
    owner = np.empty(k_count * t_count, np.int64)
    n_v = 0
    n_f = 0
    poly = np.empty((3 + 2 * n_planes, 3))
    clipped = np.empty((3 + 2 * n_planes, 3))
    # element by element, never through row views (each counts references) or temporary arrays
    for k in range(k_count):
        for t in range(t_count):
            count = 3
            for c in range(3):
                v = tris[t, c]
                for r in range(3):
                    poly[c, r] = (xform[k, r, 0] * verts[v, 0] + xform[k, r, 1] * verts[v, 1]
                                  + xform[k, r, 2] * verts[v, 2] + xform[k, r, 3])
            for p in range(n_planes):
                nx, ny, nz, d = planes[k, 4 * p], planes[k, 4 * p + 1], planes[k, 4 * p + 2], planes[k, 4 * p + 3]
                if np.isnan(nx) or count < 3:
                    continue
                kept = 0
                s = count - 1  # the edge from vertex s to vertex e
                ds = nx * poly[s, 0] + ny * poly[s, 1] + nz * poly[s, 2] + d
                for e in range(count):
                    de = nx * poly[e, 0] + ny * poly[e, 1] + nz * poly[e, 2] + d
                    if (de >= -eps) != (ds >= -eps):
                        f = ds / (ds - de)
                        for r in range(3):
                            clipped[kept, r] = poly[s, r] + f * (poly[e, r] - poly[s, r])
                        kept += 1
                    if de >= -eps:
                        for r in range(3):
                            clipped[kept, r] = poly[e, r]
                        kept += 1
                    s, ds = e, de
                count = kept
                for q in range(count):
                    for r in range(3):
                        poly[q, r] = clipped[q, r]
            if count < 3:
                continue
            for q in range(count):
                for r in range(3):
                    out[n_v + q, r] = poly[q, r]
            n_v += count
            owner[n_f] = k
            n_f += 1
            offsets[n_f] = n_v
    return out[:n_v], offsets[: n_f + 1], owner[:n_f]
