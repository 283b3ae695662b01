"""Scope arithmetic fused into single passes: split children and instance transforms.

Gathering a (n, 3, 3) frame per shape in numpy costs more than the arithmetic; these kernels read the
frame table by id instead.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from grammarc.backend.random import mix1


@njit(cache=True)
def place_children(origin, size, key, frame, frames, axis, parent, pos, length, site, index):
    """Scopes and keys of split children.

    origin, size : (n, 3) float64 parents' scopes; key : (n,) uint64; frame : (n,) int32 into
    frames : (F, 3, 3) float64; axis : int; parent : (m,) int64; pos, length : (m,) float64 the
    children's offset and size along ``axis``; site : int; index : (m,) int64 the child's number.
    Returns child origin (m, 3), size (m, 3) and key (m,) uint64, allocated here.
    """
    m = len(parent)
    out_origin = np.empty((m, 3))
    out_size = np.empty((m, 3))
    out_key = np.empty(m, np.uint64)
    for c in range(m):
        p = parent[c]
        f = frame[p]
        for j in range(3):
            out_origin[c, j] = origin[p, j] + pos[c] * frames[f, axis, j]
            out_size[c, j] = size[p, j]
        out_size[c, axis] = length[c]
        out_key[c] = mix1(mix1(key[p], site), index[c])
    return out_origin, out_size, out_key


@njit(cache=True)
def xforms(frames, frame, size, origin):
    """Record transforms (n, 3, 4) float32: column j = scope axis j * size j, column 3 = origin."""
    n = len(frame)
    out = np.empty((n, 3, 4), np.float32)
    for i in range(n):
        f = frame[i]
        for r in range(3):
            for j in range(3):
                out[i, r, j] = frames[f, j, r] * size[i, j]
            out[i, r, 3] = origin[i, r]
    return out
