"""A new scope for unchanged geometry: CityEngine's ``alignScopeToAxes`` and ``rotateScope``.

The geometry stays where it is in the world; the scope turns to the new axes and becomes the geometry's
bounding box in them. grammarc keeps a shape's geometry relative to its scope, so the polygon is
expressed anew in the new scope (a rectangle that lines up with the new axes takes the box fast path
again). One of the new axes must be the polygon's normal (turning a footprint about the vertical,
putting z up with ``alignScopeToGeometry(zUp, ...)``); other turns need the general geometry of the
polygon issue.
"""

from __future__ import annotations

import numpy as np

from grammarc.constants import TOL
from grammarc.geometry.polygons import PLANE_U, PLANE_V
from grammarc.ragged import next_in_segment, segment_of, segment_reduce

#: Per normal axis n: new scope axes, as rows in the old frame, that put y along axis n and keep x where
#: they can (CityEngine's extrude and roofs: "x kept, y along the normal, z = x cross y").
NORMAL_UP = np.array([
    [[0, 0, 1], [1, 0, 0], [0, 1, 0]],   # n = x: (z, x, y), a cyclic turn
    [[1, 0, 0], [0, 1, 0], [0, 0, 1]],   # n = y: unchanged
    [[1, 0, 0], [0, 0, 1], [0, -1, 0]],  # n = z: (x, z, -y), a turn about x
], dtype=np.float64)

#: The same for z along axis n (a comp(f) face: x kept where it can, z its normal, y = z cross x).
NORMAL_OUT = np.array([
    [[0, 1, 0], [0, 0, 1], [1, 0, 0]],   # n = x: (y, z, x), a cyclic turn
    [[1, 0, 0], [0, 0, -1], [0, 1, 0]],  # n = y: (x, -z, y), a turn about x
    [[1, 0, 0], [0, 1, 0], [0, 0, 1]],   # n = z: unchanged
], dtype=np.float64)

def reframe(origin, size, axes, coords, ring_offsets, shape_offsets, plane, new_axes):
    """Scopes of the same polygons in new axes.

    origin, size (n, 3), axes, new_axes (n, 3, 3) (rows are the scope axes); the shapes' polygons as
    normalized ragged arrays (coords (V, 2), ring_offsets, shape_offsets (n+1,)) with plane (n,) codes.

    Returns ``ok`` (n,) bool (a new axis is the polygon's normal), the new plane codes (n,), origin and
    size (n, 3), ``is_rect`` (n,) bool, and the new normalized coords (V, 2) (meaningful where ``ok``).
    """
    n = len(plane)
    rows = np.arange(n)
    a, b = PLANE_U[plane], PLANE_V[plane]
    normal_old = axes[rows, plane]
    alignment = np.einsum("nj,nkj->nk", normal_old, new_axes)
    new_plane = np.argmax(alignment, axis=1)
    ok = alignment[rows, new_plane] > 1 - 1e-9
    height = size[rows, plane]
    vertex_shape = segment_of(shape_offsets)[segment_of(ring_offsets)]
    s = vertex_shape
    # each shape's in-plane axes, scaled by its size, in the new axes: a vertex is u, v along them
    along_u = np.einsum("nj,nij->ni", axes[rows, a] * size[rows, a, None], new_axes)
    along_v = np.einsum("nj,nij->ni", axes[rows, b] * size[rows, b, None], new_axes)
    local = coords[:, 0, None] * along_u[s] + coords[:, 1, None] * along_v[s]  # from the old origin
    vertex_offsets = ring_offsets[shape_offsets]
    low = segment_reduce(np.minimum, local, vertex_offsets, 0.0)
    high = segment_reduce(np.maximum, local, vertex_offsets, 0.0)
    plane = new_plane
    a, b = PLANE_U[plane], PLANE_V[plane]
    new_size = high - low
    new_size[rows, plane] = height
    shift = low.copy()
    shift[rows, plane] = 0.0
    new_origin = origin + np.einsum("ni,nij->nj", shift, new_axes)
    u = local[np.arange(len(s)), a[s]] - low[s, a[s]]
    v = local[np.arange(len(s)), b[s]] - low[s, b[s]]
    extent_a = np.where(new_size[rows, a] > TOL.zero, new_size[rows, a], 1.0)
    extent_b = np.where(new_size[rows, b] > TOL.zero, new_size[rows, b], 1.0)
    new_coords = np.stack([u / extent_a[s], v / extent_b[s]], axis=1)
    # a rectangle lined up with the new axes: one ring of 4 vertices filling its box
    nxt = next_in_segment(ring_offsets)
    cross = new_coords[:, 0] * new_coords[nxt, 1] - new_coords[nxt, 0] * new_coords[:, 1]
    area = np.abs(segment_reduce(np.add, cross, vertex_offsets, 0.0)) / 2
    one_ring = np.diff(shape_offsets) == 1
    four = np.diff(vertex_offsets) == 4
    is_rect = one_ring & four & (np.abs(area - 1.0) <= TOL.rect)
    return ok, new_plane.astype(np.int8), new_origin, new_size, is_rect, new_coords
