"""Split and repeat fan-out along one scope axis, for a whole batch of shapes.

Both kernels return the children of n parents as flat arrays ``parent`` (m,) int64, ``part`` (m,) int64,
``position`` (m,) float64 (offset of the child along the axis from the parent's origin) and ``length``
(m,) float64 (the child's size on the axis). They count first and allocate once.
"""

from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True)
def subdiv(extent, values, relative, tol):
    """Sizes of ``Subdiv`` parts (paper section 2, "Basic split rule" and "Scaling of rules").

    extent : (n,) float64 scope size on the split axis; values : (n, P) or (1, P) float64 the sizes as
    written (one row for all shapes when they do not vary);
    relative : (P,) bool, True for ``r`` sizes; tol : float, parts of this length or less are dropped.

    A relative size r_i becomes r_i * (extent - sum(absolute)) / sum(r) (zero when the absolute sizes
    already fill the scope). Parts are laid end to end; a part that starts beyond the scope is dropped and
    the last one is cut at the scope's end, as CityEngine does.
    """
    n = len(extent)
    count = values.shape[1]
    shared = values.shape[0] == 1
    keep = np.zeros((n, count), np.bool_)
    pos = np.zeros((n, count))
    length = np.zeros((n, count))
    total = 0
    for i in range(n):
        row = 0 if shared else i
        absolute = 0.0
        rel = 0.0
        for j in range(count):
            if relative[j]:
                rel += values[row, j]
            else:
                absolute += values[row, j]
        free = extent[i] - absolute
        free = max(free, 0.0)
        at = 0.0
        for j in range(count):
            if relative[j]:
                size = values[row, j] * free / rel if rel > 0.0 else 0.0
            else:
                size = values[row, j]
            end = at + size
            end = min(end, extent[i])
            if end - at > tol:
                keep[i, j] = True
                pos[i, j] = at
                length[i, j] = end - at
                total += 1
            at = at + size
    parent = np.empty(total, np.int64)
    part = np.empty(total, np.int64)
    out_pos = np.empty(total)
    out_len = np.empty(total)
    m = 0
    for i in range(n):
        for j in range(count):
            if keep[i, j]:
                parent[m] = i
                part[m] = j
                out_pos[m] = pos[i, j]
                out_len[m] = length[i, j]
                m += 1
    return parent, part, out_pos, out_len


@njit(cache=True)
def repeat_counts(extent, size, tol):
    """Elements of ``Repeat``: ceil(extent / size) per shape (paper section 2, "Repeat"), (n,) int64.

    A scope of zero extent has no element. ``size`` must be positive (the caller checks).
    """
    n = len(extent)
    counts = np.zeros(n, np.int64)
    for i in range(n):
        if extent[i] > tol:
            c = np.ceil(extent[i] / size[i] - 1e-9)
            counts[i] = max(int(c), 1)
    return counts


@njit(cache=True)
def repeat(extent, counts):
    """Children of ``Repeat``: each shape's extent cut into counts[i] equal elements.

    extent : (n,) float64; counts : (n,) int64 from ``repeat_counts``.
    Returns parent, part (the element's index), position and length, each (sum(counts),).
    """
    total = 0
    for i in range(len(counts)):
        total += counts[i]
    parent = np.empty(total, np.int64)
    part = np.empty(total, np.int64)
    pos = np.empty(total)
    length = np.empty(total)
    m = 0
    for i in range(len(counts)):
        c = counts[i]
        if c == 0:
            continue
        step = extent[i] / c
        for j in range(c):
            parent[m] = i
            part[m] = j
            pos[m] = j * step
            length[m] = step
            m += 1
    return parent, part, pos, length

