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
from numba import njit

from grammarc.constants import TOL
from grammarc.geometry.polygons import PLANE_U, PLANE_V
from grammarc.ragged import ragged_take, segment_reduce

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
    # each shape's in-plane axes, scaled by its size, in the new axes: a vertex is u, v along them
    along_u = np.einsum("nj,nij->ni", axes[rows, a] * size[rows, a, None], new_axes)
    along_v = np.einsum("nj,nij->ni", axes[rows, b] * size[rows, b, None], new_axes)
    ring_offsets = np.asarray(ring_offsets, dtype=np.int64)
    shape_offsets = np.asarray(shape_offsets, dtype=np.int64)
    local, low, high, tied = _local(np.ascontiguousarray(coords, dtype=np.float64), ring_offsets, shape_offsets,
                                    along_u, along_v)  # from the old origin
    vertex_offsets = ring_offsets[shape_offsets]
    tied = np.flatnonzero(tied)
    if len(tied):  # which of -0.0 and 0.0, or which NaN, numpy's bounds keep: as numpy finds them
        items, packed = ragged_take(vertex_offsets, tied)
        low[tied] = segment_reduce(np.minimum, local[items], packed, 0.0)
        high[tied] = segment_reduce(np.maximum, local[items], packed, 0.0)
    plane = new_plane
    new_size = high - low
    new_size[rows, plane] = height
    shift = low.copy()
    shift[rows, plane] = 0.0
    new_origin = origin + np.einsum("ni,nij->nj", shift, new_axes)
    a, b = PLANE_U[plane], PLANE_V[plane]
    extent_a = np.where(new_size[rows, a] > TOL.zero, new_size[rows, a], 1.0)
    extent_b = np.where(new_size[rows, b] > TOL.zero, new_size[rows, b], 1.0)
    new_coords, cross = _normalized(local, ring_offsets, shape_offsets, low[rows, a], low[rows, b], a, b,
                                    extent_a, extent_b)
    # a rectangle lined up with the new axes: one ring of 4 vertices filling its box
    area = np.abs(segment_reduce(np.add, cross, vertex_offsets, 0.0)) / 2
    one_ring = np.diff(shape_offsets) == 1
    four = np.diff(vertex_offsets) == 4
    is_rect = one_ring & four & (np.abs(area - 1.0) <= TOL.rect)
    return ok, new_plane.astype(np.int8), new_origin, new_size, is_rect, new_coords


@njit(cache=True, nogil=True)
def _local(coords, ring_offsets, shape_offsets, along_u, along_v):
    """Each vertex (V, 3) in its shape's new axes from its old origin, ``u along_u + v along_v`` of its
    shape (n, 3), and each shape's lowest and highest (n, 3) (0 for a shape without vertices), in one
    pass instead of a gather of each shape's row per vertex and two ``reduceat``.

    Where a shape's values on an axis hold both -0.0 and 0.0, or a NaN, the bound's bits depend on the
    order numpy's reduction compares them in: such shapes are ``tied`` (n,) bool, for numpy to bound."""
    n = len(shape_offsets) - 1
    local = np.empty((len(coords), 3))
    low = np.zeros((n, 3))
    high = np.zeros((n, 3))
    tied = np.zeros(n, np.bool_)
    for i in range(n):
        start, stop = ring_offsets[shape_offsets[i]], ring_offsets[shape_offsets[i + 1]]
        for k in range(3):
            positive_zero = negative_zero = False
            for v in range(start, stop):
                x = coords[v, 0] * along_u[i, k] + coords[v, 1] * along_v[i, k]
                local[v, k] = x
                if v == start or x < low[i, k]:
                    low[i, k] = x
                if v == start or x > high[i, k]:
                    high[i, k] = x
                if x == 0.0:
                    if np.signbit(x):
                        negative_zero = True
                    else:
                        positive_zero = True
                elif np.isnan(x):
                    tied[i] = True
            if positive_zero and negative_zero:
                tied[i] = True
    return local, low, high, tied


@njit(cache=True, nogil=True)
def _normalized(local, ring_offsets, shape_offsets, low_a, low_b, a, b, extent_a, extent_b):
    """The new normalized coordinates (V, 2) of the vertices ``local`` (V, 3): their shape's new in-plane
    axes ``a`` and ``b`` (n,) from its lowest corner (``low_a``, ``low_b`` (n,)) over its extents (n,);
    and each vertex's term of its shape's doubled signed area (V,), x_k y_k+1 - x_k+1 y_k along its ring."""
    coords = np.empty((len(local), 2))
    cross = np.empty(len(local))
    for i in range(len(shape_offsets) - 1):
        for v in range(ring_offsets[shape_offsets[i]], ring_offsets[shape_offsets[i + 1]]):
            coords[v, 0] = (local[v, a[i]] - low_a[i]) / extent_a[i]
            coords[v, 1] = (local[v, b[i]] - low_b[i]) / extent_b[i]
        for ring in range(shape_offsets[i], shape_offsets[i + 1]):
            first, last = ring_offsets[ring], ring_offsets[ring + 1]
            for v in range(first, last):
                w = v + 1 if v + 1 < last else first
                cross[v] = coords[v, 0] * coords[w, 1] - coords[w, 0] * coords[v, 1]
    return coords, cross
