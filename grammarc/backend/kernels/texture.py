"""Texture coordinates of instance records in one pass: each record's map of its unit box's points.

A record's texture map (``TerminalChunk.uv``) is its shape's map of world points (``backend.texture_space``)
composed with the record's transform. In numpy that is a gather of the maps, a copy, an ``einsum`` and a
stacked ``matmul`` of (2, 3) by (3, 4) matrices, each a pass over millions of rows; this kernel reads the
map table by id instead. It keeps numpy's bits: the sums are taken in the order, and the products fused or
rounded, as numpy's ``einsum`` and its BLAS ``matmul`` take them (``fused_multiply_add``), so the records
are those numpy makes.
"""

from __future__ import annotations

import numpy as np
from numba import njit, types
from numba.extending import intrinsic


@intrinsic
def fused_multiply_add(typingctx, a, b, c):
    """``a * b + c`` (float64) rounded once, LLVM's ``fma``: as the BLAS kernels of ``matmul`` sum their
    products (numba otherwise rounds the product, then the sum)."""
    sig = types.float64(types.float64, types.float64, types.float64)

    def codegen(context, builder, signature, args):
        return builder.fma(*args)

    return sig, codegen


@njit(cache=True, nogil=True)
def instance_maps(maps, map_id, rows, lot_origin, lot, xform):
    """(m, 2, 4) float32: texture maps of the unit box's points of records placed by ``xform`` (m, 3, 4)
    float32 relative to their lots' origins, for shapes ``rows`` (m,) of a batch whose maps are
    ``maps[map_id]`` ((M, 2, 4) float64 of world points, ids (n,)) and lots ``lot`` (n,) at ``lot_origin``
    (L, 3).

    A shape's map of points relative to its lot's origin is the map with ``map[:, :3] @ lot origin`` added
    to its offset, summed as ``np.einsum("nij,nj->ni")`` sums (axes 0 and 2, then 1); composed with the
    record's transform, each entry is the products of the (2, 3) by (3, 4) matrices fused into a sum from
    0.0 in axis order, as ``matmul`` sums them, and the offset added last.
    """
    out = np.empty((len(rows), 2, 4), np.float32)
    for c in range(len(rows)):
        i = rows[c]
        m = map_id[i]
        o = lot_origin[lot[i]]
        for r in range(2):
            a = maps[m, r]
            offset = _lot_offset(a, o)
            for k in range(4):
                placed = 0.0
                for j in range(3):
                    placed = fused_multiply_add(a[j], np.float64(xform[c, j, k]), placed)
                if k == 3:
                    placed += offset
                out[c, r, k] = placed
    return out


@njit(cache=True, nogil=True)
def vertex_maps(maps, map_id, lot_origin, lot, vertex_shape, vertices):
    """(V, 2) float32: texture coordinates of mesh vertices ``vertices`` (V, 3) float32, relative to their
    lots' origins, each of shape ``vertex_shape`` (V,) of a batch whose maps are ``maps[map_id]`` and lots
    ``lot`` (n,) at ``lot_origin`` (L, 3): the shape's map moved to its lot's origin (as ``instance_maps``
    moves it) applied to the point, its sum taken as ``np.einsum("vij,vj->vi")`` takes it and the offset
    added last."""
    out = np.empty((len(vertex_shape), 2), np.float32)
    for v in range(len(vertex_shape)):
        i = vertex_shape[v]
        o = lot_origin[lot[i]]
        x, y, z = np.float64(vertices[v, 0]), np.float64(vertices[v, 1]), np.float64(vertices[v, 2])
        for r in range(2):
            a = maps[map_id[i], r]
            out[v, r] = ((a[0] * x + a[2] * z) + a[1] * y) + _lot_offset(a, o)
    return out


@njit(cache=True, nogil=True, inline="always")
def _lot_offset(a, o):
    """The offset of map row ``a`` (4,) for points relative to the lot origin ``o`` (3,): ``a[3] + a[:3] @ o``,
    summed as ``np.einsum("nij,nj->ni")`` sums (axes 0 and 2, then 1)."""
    return a[3] + ((a[0] * o[0] + a[2] * o[2]) + a[1] * o[1])
