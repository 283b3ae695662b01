"""Component splits (``Comp``): faces, edges and vertices of many shapes in one numba pass.

Every shape is seen as a polygon (with holes) in one plane of its scope, extruded along the plane's
normal axis by the scope size on that axis: a box is its implicit rectangle in the scope's x-z plane
extruded along y, a footprint prism is its stored polygon extruded along y, a flat face is its polygon
not extruded. So one kernel serves boxes, prisms and faces.

Component scopes follow the paper (section 2, "Component split") and CityEngine:

- side face of ring edge p -> q: x along the edge, y along the extrusion axis, z = x cross y pointing
  out of the solid, origin at p on the base, size (|q - p|, height, 0); but where the polygon's ``turn``
  says the face's ring starts elsewhere (``UP``, ``DOWN``: the faces a split cut through a hole,
  ``geometry.clip.cap_turns``), x runs along its first edge, up or down the extrusion axis;
- top face: z along the extrusion axis, x along the polygon's first axis; bottom face: z against it;
- ring edge: x along the edge, y the polygon's normal, z outward in the polygon's plane, size (|q-p|, 0, 0);
- side edge at a ring vertex: x along the extrusion axis, z the mean of the outward normals of the two
  side faces that meet there (the reference: "the average of the neighboring face normals"); vertex: the
  frame of the ring edge that starts there, size 0.

Order: faces are bottom, side faces in ring order (exterior ring first, then holes), top; edges are
bottom ring, top ring, side edges; vertices are bottom ring, then top ring.
"""

from __future__ import annotations

import numpy as np
from numba import njit

#: Component kinds of the kernel; the indexed selectors of the grammar map onto these.
KIND_CODES = {
    "faces": 0, "sidefaces": 1, "top": 2, "bottom": 3, "edges": 4, "sideedges": 5, "topedges": 6,
    "bottomedges": 7, "vertices": 8,
    "face": 0, "sideface": 1, "edge": 4, "vertex": 8,
}

#: ``poly`` codes of the kernel output: what geometry a component has.
RECT, BOTTOM_POLY, TOP_POLY, SAME_POLY = 0, 1, 2, 3

#: ``turn``: where a side face's ring starts, and so which way its scope's x runs (a polygon's per-vertex ``turn``,
#: ``geometry.polygons``): at its bottom's start (x along the edge, the rule), at its bottom's end (x up
#: the extrusion axis, y back along the edge), at its top's start (x down, y along the edge).
ALONG, UP, DOWN = 0, 1, 2


@njit(cache=True, nogil=True)
def _axes_of(plane):
    """(a, b) in-plane axes and the normal axis n of a polygon plane code."""
    if plane == 0:
        return 1, 2, 0
    if plane == 1:
        return 0, 2, 1
    return 0, 1, 2


@njit(cache=True, nogil=True)
def _cross_into(a, b, out):
    """a cross b, written into ``out`` (3,): the kernel's loops over edges allocate nothing."""
    out[0] = a[1] * b[2] - a[2] * b[1]
    out[1] = a[2] * b[0] - a[0] * b[2]
    out[2] = a[0] * b[1] - a[1] * b[0]


@njit(cache=True, nogil=True)
def _edge_into(coords, j, r0, count, a, b, size_row, p, d):
    """Ring edge from vertex j to its successor in local coordinates, written into ``p`` (its start) and
    ``d`` (3,) (its unit direction, zero for a zero-length edge); returns its length."""
    k = r0 + (j - r0 + 1) % count
    for c in range(3):
        p[c] = 0.0
        d[c] = 0.0
    p[a] = coords[j, 0] * size_row[a]
    p[b] = coords[j, 1] * size_row[b]
    d[a] = coords[k, 0] * size_row[a] - p[a]
    d[b] = coords[k, 1] * size_row[b] - p[b]
    length = np.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
    if length > 0.0:
        for c in range(3):
            d[c] = d[c] / length
    return length


@njit(cache=True, nogil=True)
def _side_edge_normal(coords, j, r0, count, a, b, size_row, d, nvec, tol, scratch, z):
    """The z axis of the side edge at ring vertex j, whose outgoing edge has direction ``d``, written into
    ``z`` (3,): the mean of the outward normals of the side faces before and after it, as CityEngine points
    an edge's z along the mean of its faces' normals (PRT: a prism's corner edges look along the corner's
    bisector); the normal after it where the two cancel (a spike) or no edge before it has a length.
    ``scratch`` (4, 3) holds the normal after, the edge before (start, direction) and its normal."""
    after, p, before, mean = scratch[0], scratch[1], scratch[2], scratch[3]
    _cross_into(d, nvec, after)
    for back in range(1, count):
        q = r0 + (j - r0 - back) % count
        length = _edge_into(coords, q, r0, count, a, b, size_row, p, before)
        if length > tol:
            _cross_into(before, nvec, mean)
            for c in range(3):
                mean[c] = mean[c] + after[c]
            norm = np.sqrt(mean[0] * mean[0] + mean[1] * mean[1] + mean[2] * mean[2])
            for c in range(3):
                z[c] = mean[c] / norm if norm > tol else after[c]
            return
    for c in range(3):
        z[c] = after[c]


@njit(cache=True, nogil=True)
def _put(out, m, i, o, x, y, z, s, code):
    """Write component m: parent i, origin o, axes x, y, z (rows), size s (3,), geometry code."""
    parent, origin, axes, csize, poly = out
    parent[m] = i
    for c in range(3):  # element by element: a row assigned whole costs a broadcast each time
        origin[m, c] = o[c]
        axes[m, 0, c] = x[c]
        axes[m, 1, c] = y[c]
        axes[m, 2, c] = z[c]
        csize[m, c] = s[c]
    poly[m] = code
    return m + 1


@njit(cache=True, nogil=True)
def _sized(s, sx, sy):
    """The size (sx, sy, 0) written into ``s`` (3,)."""
    s[0] = sx
    s[1] = sy
    s[2] = 0.0
    return s


@njit(cache=True, nogil=True)
def _count(kind, n_edges, volume):
    if volume:
        if kind == 0:
            return n_edges + 2
        if kind == 1 or kind == 5 or kind == 6 or kind == 7:
            return n_edges
        if kind == 2 or kind == 3:
            return 1
        if kind == 4:
            return 3 * n_edges
        return 2 * n_edges
    if kind == 0:
        return 1
    if kind == 4 or kind == 8:
        return n_edges
    return 0


@njit(cache=True, nogil=True)
def components(kind, coords, ring_offsets, shape_offsets, plane, size, tol, turn):
    """Component scopes of n shapes, in each shape's local frame.

    kind : int, a value of KIND_CODES.
    coords : (V, 2) float64 normalized polygon vertices; turn : (V,) int8 where the side face over the
    edge from each vertex starts its ring (``ALONG``, ``UP``, ``DOWN``); ring_offsets : (R+1,) int64 into coords;
    shape_offsets : (n+1,) int64 into rings (one polygon per shape); plane : (n,) int8 normal axis;
    size : (n, 3) float64 scope sizes; tol : lengths at or below it are zero.

    Returns parent (m,) int64, index (m,) int64 (position among the shape's components), origin (m, 3)
    and axes (m, 3, 3) in the parent's local frame (rows are unit axes), csize (m, 3), and poly (m,) int8
    (RECT, BOTTOM_POLY, TOP_POLY or SAME_POLY). Zero-length edges are skipped. All allocated here.
    """
    n = len(plane)
    total = 0
    for i in range(n):
        a, b, nrm = _axes_of(plane[i])
        volume = size[i, nrm] > tol
        n_edges = ring_offsets[shape_offsets[i + 1]] - ring_offsets[shape_offsets[i]]
        total += _count(kind, n_edges, volume)
    parent = np.empty(total, np.int64)
    index = np.empty(total, np.int64)
    origin = np.empty((total, 3))  # every component's row is written whole (``_put``)
    axes = np.empty((total, 3, 3))
    csize = np.empty((total, 3))
    poly = np.empty(total, np.int8)
    out = (parent, origin, axes, csize, poly)
    # one edge's start, direction, outward normal, size and lifted start, and one shape's axes (its
    # normal, then negated, and its in-plane axes), a cap's y and origin: used again, nothing allocated
    p, d, outward, s, lifted = np.zeros(3), np.zeros(3), np.zeros(3), np.zeros(3), np.zeros(3)
    nvec, negn, avec, bvec, y, o = np.zeros(3), np.zeros(3), np.zeros(3), np.zeros(3), np.zeros(3), np.zeros(3)
    z, scratch = np.zeros(3), np.zeros((4, 3))  # a side edge's z, and what finding it needs
    m = 0
    for i in range(n):
        a, b, nrm = _axes_of(plane[i])
        h = size[i, nrm]
        volume = h > tol
        nvec[:] = 0.0
        nvec[nrm] = 1.0
        avec[:] = 0.0
        avec[a] = 1.0
        bvec[:] = 0.0
        bvec[b] = 1.0
        for c in range(3):
            negn[c] = -nvec[c]
        first = m
        if kind == 0 and not volume:
            # a flat shape's only face is itself
            e = np.eye(3)
            m = _put(out, m, i, np.zeros(3), e[0], e[1], e[2], size[i], SAME_POLY)
        if volume and (kind == 0 or kind == 3):
            # bottom: z = -n, x = a, y = z cross x; origin keeps the polygon in the positive quadrant
            _cross_into(negn, avec, y)
            for c in range(3):
                o[c] = bvec[c] * size[i, b] if y[b] < 0 else 0.0
            m = _put(out, m, i, o, avec, y, negn, _sized(s, size[i, a], size[i, b]), BOTTOM_POLY)
        for ring in range(shape_offsets[i], shape_offsets[i + 1]):
            r0 = ring_offsets[ring]
            count = ring_offsets[ring + 1] - r0
            for j in range(r0, r0 + count):
                length = _edge_into(coords, j, r0, count, a, b, size[i], p, d)
                if length <= tol:
                    continue
                _cross_into(d, nvec, outward)
                if volume and (kind == 0 or kind == 1):
                    if turn[j] == UP:
                        m = _put(out, m, i, p + d * length, nvec, -d, outward, _sized(s, h, length), RECT)
                    elif turn[j] == DOWN:
                        m = _put(out, m, i, p + nvec * h, -nvec, d, outward, _sized(s, h, length), RECT)
                    else:
                        m = _put(out, m, i, p, d, nvec, outward, _sized(s, length, h), RECT)
                if kind == 4 or (kind == 7 and volume):
                    m = _put(out, m, i, p, d, nvec, outward, _sized(s, length, 0.0), RECT)
                if kind == 8:
                    m = _put(out, m, i, p, d, nvec, outward, _sized(s, 0.0, 0.0), RECT)
        if volume and (kind == 4 or kind == 6 or kind == 8):
            # the top ring: ring edges (or vertices) lifted by the extrusion height
            for ring in range(shape_offsets[i], shape_offsets[i + 1]):
                r0 = ring_offsets[ring]
                count = ring_offsets[ring + 1] - r0
                for j in range(r0, r0 + count):
                    length = _edge_into(coords, j, r0, count, a, b, size[i], p, d)
                    if length <= tol:
                        continue
                    edge_length = length if kind != 8 else 0.0
                    for c in range(3):
                        lifted[c] = p[c] + nvec[c] * h
                    _cross_into(d, nvec, outward)
                    m = _put(out, m, i, lifted, d, nvec, outward, _sized(s, edge_length, 0.0), RECT)
        if volume and (kind == 4 or kind == 5):
            # side edges: x up the extrusion, z between the normals of the two side faces that meet there
            for ring in range(shape_offsets[i], shape_offsets[i + 1]):
                r0 = ring_offsets[ring]
                count = ring_offsets[ring + 1] - r0
                for j in range(r0, r0 + count):
                    length = _edge_into(coords, j, r0, count, a, b, size[i], p, d)
                    if length <= tol:
                        continue
                    _side_edge_normal(coords, j, r0, count, a, b, size[i], d, nvec, tol, scratch, z)
                    _cross_into(z, nvec, outward)
                    m = _put(out, m, i, p, nvec, outward, z, _sized(s, h, 0.0), RECT)
        if volume and (kind == 0 or kind == 2):
            # top: z = n, x = a, y = z cross x
            _cross_into(nvec, avec, y)
            for c in range(3):
                o[c] = nvec[c] * h + (bvec[c] * size[i, b] if y[b] < 0 else 0.0)
            m = _put(out, m, i, o, avec, y, nvec, _sized(s, size[i, a], size[i, b]), TOP_POLY)
        for c in range(first, m):
            index[c] = c - first
    return parent[:m], index[:m], origin[:m], axes[:m], csize[:m], poly[:m]


#: Implicit rectangles of shapes whose geometry is their scope, per plane code: counter-clockwise
#: around the +normal axis, the first edge along the in-plane x (or y) axis. For a box (plane 1) the
#: first side face is the one facing +z.
RECT_RINGS = np.array([
    [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]],
    [[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]],
    [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]],
])


def rect_rings(plane: np.ndarray, corner: np.ndarray | None = None) -> np.ndarray:
    """The implicit rectangles of shapes in planes ``plane`` (n,), one after another: (4 n, 2); each ring
    starting at its ``corner`` (n,) (an index into its ``RECT_RINGS``; None: all at corner 0)."""
    if corner is None:
        return RECT_RINGS[plane].reshape(-1, 2)
    return _turned_rings(RECT_RINGS, np.asarray(plane, dtype=np.int64), np.asarray(corner, dtype=np.int64))


@njit(cache=True, nogil=True)
def _turned_rings(rings, plane, corner):
    """``rect_rings`` with corners: ring i is ``rings[plane[i]]`` from its corner ``corner[i]`` (mod 4)."""
    out = np.empty((4 * len(plane), 2))
    for i in range(len(plane)):
        for k in range(4):
            c = (k + corner[i]) % 4
            out[4 * i + k, 0] = rings[plane[i], c, 0]
            out[4 * i + k, 1] = rings[plane[i], c, 1]
    return out


def rect_corners(first: np.ndarray, plane: np.ndarray) -> np.ndarray:
    """The corners (n,) int64 of the implicit rectangles of planes ``plane`` (n,) nearest the points
    ``first`` (n, 2) (normalized coordinates): where a rectangle's ring whose first vertex that is starts."""
    return _nearest_corners(RECT_RINGS, np.asarray(plane, dtype=np.int64),
                            np.ascontiguousarray(first, dtype=np.float64))


@njit(cache=True, nogil=True)
def _nearest_corners(rings, plane, first):
    """``rect_corners`` in one pass: the first corner at the least squared distance (a NaN one first, as
    ``np.argmin`` takes it)."""
    out = np.zeros(len(plane), np.int64)
    for i in range(len(plane)):
        best = np.inf
        for c in range(4):
            dx = rings[plane[i], c, 0] - first[i, 0]
            dy = rings[plane[i], c, 1] - first[i, 1]
            d = dx * dx + dy * dy
            if np.isnan(d):
                out[i] = c
                break
            if d < best or c == 0:
                best = d
                out[i] = c
    return out


def rect_plane(size: np.ndarray, tol: float) -> np.ndarray:
    """Plane code of scope rectangles (n,) int8: the flat axis of a face, y for volumes."""
    flat = size <= tol
    plane = np.ones(len(size), dtype=np.int8)
    plane[flat[:, 2]] = 2
    plane[flat[:, 0] & ~flat[:, 2]] = 0
    return plane


@njit(cache=True, nogil=True)
def reverse_rings(coords, ring_offsets):
    """Each ring in reverse order, keeping its first vertex first: (V, 2) float64, a new array."""
    out = np.empty_like(coords)
    for r in range(len(ring_offsets) - 1):
        s = ring_offsets[r]
        e = ring_offsets[r + 1]
        count = e - s
        for q in range(count):
            out[s + q] = coords[s + (count - q) % count]
    return out
