"""Scope arithmetic fused into single passes: split children and instance transforms.

Gathering a (n, 3, 3) frame per shape in numpy costs more than the arithmetic; these kernels read the
frame table by id instead.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from grammarc.backend.random import mix1


@njit(cache=True, nogil=True)
def place_children(origin, size, key, frame, geom, lot, depth, frames, axis, order, parent, pos, length,
                   site, index):
    """Columns of split children, in the order ``order`` (children grouped by body part).

    Parents: origin, size (n, 3) float64; key (n,) uint64; frame, geom, lot, depth (n,) int32; frames
    (F, 3, 3) float64 the frame table; axis: int. Children, as the split kernel made them: parent (m,)
    int64, pos and length (m,) float64 (offset and size along ``axis``), index (m,) int64 (the child's
    number, for its key); order (m,) int64 picks them. site: int.
    Returns origin (m, 3), size (m, 3), key (m,) uint64, frame, geom, lot, depth (m,) int32 and the
    parent of each placed child (m,) int64, all allocated here.
    """
    m = len(order)
    out_origin = np.empty((m, 3))
    out_size = np.empty((m, 3))
    out_key = np.empty(m, np.uint64)
    out_frame = np.empty(m, np.int32)
    out_geom = np.empty(m, np.int32)
    out_lot = np.empty(m, np.int32)
    out_depth = np.empty(m, np.int32)
    out_parent = np.empty(m, np.int64)
    for c in range(m):
        k = order[c]
        p = parent[k]
        f = frame[p]
        for j in range(3):
            out_origin[c, j] = origin[p, j] + pos[k] * frames[f, axis, j]
            out_size[c, j] = size[p, j]
        out_size[c, axis] = length[k]
        out_key[c] = mix1(mix1(key[p], site), index[k])
        out_frame[c] = f
        out_geom[c] = geom[p]
        out_lot[c] = lot[p]
        out_depth[c] = depth[p]
        out_parent[c] = p
    return out_origin, out_size, out_key, out_frame, out_geom, out_lot, out_depth, out_parent


@njit(cache=True, nogil=True)
def xforms(frames, frame, size, origin, lot, lot_origin, rows, flat):
    """Record transforms (m, 3, 4) float32 of shapes ``rows`` (m,) of a batch (``frame``, ``size``,
    ``origin``, ``lot`` (n, ...)): column j = scope axis j * size j, column 3 = origin - the origin of the
    shape's lot (``lot_origin`` (L, 3), ``model.records.LotOrigins``). A flat scope, ``flat`` (m,) its
    flat axis k (-1: a box), is a face (``builtin:quad``): its columns are axes k + 1 and k + 2 (mod 3)
    with their sizes, then axis k times 0, as ``shapes.face_axes`` orders them: the quad's normal is axis
    k. Rows are read where they are: a leaf batch's columns are not gathered for its records."""
    m = len(rows)
    out = np.empty((m, 3, 4), np.float32)
    for c in range(m):
        i = rows[c]
        f = frame[i]
        k = flat[c]
        for j in range(3):
            a = j if k < 0 else (k + 1 + j) % 3
            s = size[i, a] if k < 0 or j < 2 else 0.0
            for r in range(3):
                out[c, r, j] = frames[f, a, r] * s
        base = lot_origin[lot[i]]
        for r in range(3):
            out[c, r, 3] = origin[i, r] - base[r]
    return out


@njit(cache=True, nogil=True)
def leaf_kinds(geom, size, tol):
    """What each leaf shape is, (n,) int8: a scope box's flat axis k (0-2, its one axis of size ``tol``
    or less: a face), -1 for a box of none, 3 for an edge or a vertex (two or more: no surface); -2
    for a shape whose geometry is not its scope (a polygon, a mesh, an asset)."""
    out = np.empty(len(geom), np.int8)
    for i in range(len(geom)):
        if geom[i] != -1:
            out[i] = -2
            continue
        kind = -1
        for a in range(3):
            if size[i, a] <= tol:
                kind = a if kind == -1 else 3
        out[i] = kind
    return out


@njit(cache=True, nogil=True)
def leaf_xforms(origin, base, size, frame, frames, axis, rows, parent, pos, length, new_size, relative, offset):
    """Record transforms (m, 3, 4) float32 of split children ``rows`` whose symbol only places an asset
    after a constant ``S`` and ``T`` (``leaf_parts``): the child's scope as ``place_children`` makes it,
    sized as ``operations.scope.scale`` and moved as ``operations.scope.translate`` would (the same
    operations in the same order, so the same bits), then as ``xforms``. ``new_size`` (3,): NaN keeps the axis' size, else an
    absolute size or, where ``relative``, a factor; ``offset`` (3,) along the scope axes, or empty;
    ``base`` (n, 3) the parents' lot origins."""
    m = len(rows)
    out = np.empty((m, 3, 4), np.float32)
    o = np.empty(3)
    s = np.empty(3)
    for c in range(m):
        k = rows[c]
        p = parent[k]
        f = frame[p]
        for j in range(3):
            o[j] = origin[p, j] + pos[k] * frames[f, axis, j]
            s[j] = size[p, j]
        s[axis] = length[k]
        for j in range(3):
            if not np.isnan(new_size[j]):
                s[j] = new_size[j] * s[j] if relative[j] else new_size[j]
        if len(offset):
            for j in range(3):
                delta = 0.0
                for i in range(3):
                    delta += offset[i] * frames[f, i, j]
                o[j] = o[j] + delta
        for r in range(3):
            for j in range(3):
                out[c, r, j] = frames[f, j, r] * s[j]
            out[c, r, 3] = o[r] - base[p, r]
    return out


@njit(cache=True, nogil=True)
def translated(origin, local, frames, frame):
    """Origins (n, 3) moved by ``local`` (n, 3) along their scopes' axes (``frame`` (n,) int32 ids into the
    table ``frames``): ``origin + np.einsum("ni,nij->nj", local, frames[frame])``, each sum from 0.0 in axis
    order as einsum's (the same bits), without gathering a frame per shape."""
    out = np.empty((len(frame), 3))
    for c in range(len(frame)):
        f = frame[c]
        for j in range(3):
            delta = 0.0
            for i in range(3):
                delta += local[c, i] * frames[f, i, j]
            out[c, j] = origin[c, j] + delta
    return out


@njit(cache=True, nogil=True)
def centred(origin, size, frame, base_origin, base_size, base_frame, frames, axes):
    """Origins (n, 3) of scopes ``origin``, ``size`` (n, 3) in frames ``frame`` (n,) moved along their axes
    ``axes`` (k,) int64 so that their centres meet those of ``base_origin``, ``base_size`` in ``base_frame``
    (CityEngine's ``center``): the offset of the centres projected on each axis in turn. The arithmetic is
    numpy's (einsum) as the operation was first written, to the bit: the centres as ``translated`` sums,
    each projection as einsum's two lanes sum a product of three (x and z, then y) - the fused kernels
    write the same sums (``fusion.codegen``)."""
    out = origin.copy()
    offset = np.empty(3)
    for c in range(len(frame)):
        f, g = frame[c], base_frame[c]
        for j in range(3):
            to_base = 0.0
            to_middle = 0.0
            for i in range(3):
                to_base += base_size[c, i] / 2 * frames[g, i, j]
                to_middle += size[c, i] / 2 * frames[f, i, j]
            offset[j] = (base_origin[c, j] + to_base) - (origin[c, j] + to_middle)
        for k in axes:
            along = ((0.0 + offset[0] * frames[f, k, 0]) + offset[2] * frames[f, k, 2]) + (
                0.0 + offset[1] * frames[f, k, 1])
            for j in range(3):
                out[c, j] += along * frames[f, k, j]
    return out


@njit(cache=True, nogil=True)
def component_origins(frames, frame, origin, local_origin, local_axes, tol):
    """World origins of components, ``origin + local_origin @ frames[frame]`` (m, 3) (``translated``:
    einsum's bits), and whether each component's local axes are not orthonormal within ``tol`` (m,) bool
    (a scope of sizes no float can square). ``frame`` (m,) int32 the parents' frame ids, ``origin`` (m, 3)
    their origins, ``local_origin`` and ``local_axes`` in the parents' frames."""
    m = len(frame)
    out_origin = translated(origin, local_origin, frames, frame)
    bad = np.zeros(m, np.bool_)
    for c in range(m):
        for r in range(3):
            for k in range(r, 3):  # axis k . axis r is axis r . axis k
                dot = 0.0
                for j in range(3):
                    dot += local_axes[c, r, j] * local_axes[c, k, j]
                if not abs(dot - (1.0 if r == k else 0.0)) < tol:
                    bad[c] = True
    return out_origin, bad


@njit(cache=True, nogil=True)
def turned_frames(local_axes, frames, frame):
    """``local_axes @ frames[frame]`` (m, 3, 3): axes given in their shapes' frames (``frame`` (m,) int32
    ids into the table ``frames``), in the world (``_times_frame``: einsum's bits)."""
    out = np.empty((len(frame), 3, 3))
    for c in range(len(frame)):
        _times_frame(local_axes, c, frames, frame[c], out)
    return out


@njit(cache=True, nogil=True)
def _times_frame(local_axes, c, frames, f, out):
    """Row c of ``out`` = ``local_axes[c] @ frames[f]``, each sum from 0.0 in axis order, as
    ``np.einsum("nij,njk->nik")`` sums (the same bits, signed zeros too)."""
    for r in range(3):
        for j in range(3):
            turned = 0.0
            for i in range(3):
                turned += local_axes[c, r, i] * frames[f, i, j]
            out[c, r, j] = turned
